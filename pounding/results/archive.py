"""NetCDF archives of runs: atomic writing, reopening, and rerunning.

An archive is the results dataset written with the netCDF4 engine, numeric
variables zlib-compressed.  It carries, as global attributes, the model YAML
as written, the effective model actually run (``run_spec``), the record's
source, scale and SHA-256 of its samples: enough for :func:`rerun` to
reproduce every variable.

Writing is atomic: the dataset goes to a temporary file in the target
directory, is flushed to disk and then renamed over the target, so a crash
never leaves a truncated archive; an existing file is never replaced unless
``overwrite=True``.
"""

from __future__ import annotations

import errno
import os
import re
import signal
import sys
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import numpy as np
import xarray as xr

from pounding.errors import ArchiveError
from pounding.results.lazy_dask import defer_dask_import
from pounding.results.output_place import check_regular_file, check_writable

defer_dask_import()   # xarray's variables without importing dask.array (lazy_dask)

__all__ = ["save_run", "open_run", "load_within_memory", "atomic_path", "write_error", "write_reason", "check_archive",
           "clean_stale_temporaries", "output_lock", "lock_path", "INTERRUPT_GRACE",
           "REQUIRED_VARIABLES", "REQUIRED_PLANE_VARIABLES",
           "REQUIRED_ATTRIBUTES", "RUN_SPEC_KEYS"]

#: Seconds an interrupted archive write may still take before the process exits regardless.
INTERRUPT_GRACE = 0.8

_COMPRESSION = {"zlib": True, "complevel": 4}

#: Serialises this module's NetCDF reads and writes across threads.  HDF5 (under netCDF4) is
#: not thread-safe, and xarray does not route every call into it through its own lock: a file
#: its cache evicted is closed in whichever thread releases it last, which can overlap another
#: thread's read (seen as a segmentation fault with archives opened from two threads at once).
_NETCDF_LOCK = threading.RLock()


_TEMPORARY = re.compile(r"^\..+\.pounding-(?P<pid>\d+)-[A-Za-z0-9_]+\.tmp$")


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # exists, owned by someone else
    return True


def clean_stale_temporaries(folder: str | os.PathLike) -> int:
    """Remove temporary files of writers that died (killed mid-write); return how many.

    Temporary files are named ``.NAME.pounding-PID-RANDOM.tmp``; one whose
    writer process no longer exists is removed, live writers' files are left.
    """
    removed = 0
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return 0
    for entry in entries:
        match = _TEMPORARY.match(entry.name)
        if match is None or _alive(int(match["pid"])):
            continue
        try:
            if entry.is_file(follow_symlinks=False):
                os.unlink(entry.path)
                removed += 1
        except OSError:
            pass
    return removed


def lock_path(output: str | os.PathLike) -> Path:
    """``DIR/OUT.nc`` → ``DIR/.OUT.nc.lock``, the lock file of an output being written."""
    output = Path(output)
    return output.with_name(f".{output.name}.lock")


@contextmanager
def output_lock(output: str | os.PathLike, *, writer: str = "pounding run") -> Iterator[None]:
    """Hold an exclusive claim on *output* while it is computed and written (``.OUTPUT.lock`` beside it).

    Two commands writing the same output at once would each replace the
    other's file; the second one fails at once, naming the holder.  The claim
    is an ``flock``: the kernel releases it when the process ends, however it
    ends, so a crashed or killed writer never leaves a claim that blocks the
    next one.  The lock file is removed on release; a process that locked a
    file that was meanwhile removed (and replaced) tries again on the new one.

    Parameters
    ----------
    writer : str
        What this process is called in the lock file, and so in another
        writer's error (``"pounding run"``, ``"sweep"``...).

    Raises
    ------
    ArchiveError
        Another live process holds the claim, or the lock file cannot be
        created.
    """
    import fcntl
    import socket
    import time

    path = lock_path(output)
    for _ in range(100):
        try:
            handle = open(path, "a+")
        except OSError as exc:
            raise ArchiveError(f"cannot create the lock file {path}: {exc.strerror or exc}") from None
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.seek(0)
            holder = " ".join(handle.read(200).split()) or "process"
            handle.close()
            raise ArchiveError(f"{output} is being written by another {holder}; wait for it to finish or "
                               "choose another output") from None
        try:
            same = os.path.samestat(os.fstat(handle.fileno()), os.stat(path))
        except OSError:   # removed by its previous holder between our open and flock
            same = False
        if same:
            break
        handle.close()
    else:   # pragma: no cover - 100 holders in a row released under us
        raise ArchiveError(f"cannot claim {output}: its lock file {path} keeps changing; try again")
    try:
        handle.seek(0)
        handle.truncate()
        handle.write(f"{writer} (pid {os.getpid()} on {socket.gethostname()} since "
                     f"{time.strftime('%Y-%m-%d %H:%M:%S')})\n")
        handle.flush()
        yield
    finally:
        try:
            os.unlink(path)
        except OSError:
            pass
        handle.close()


def _link_beside(temporary: str, target: Path) -> Path:
    """Link *temporary* to a new name beside *target* (``NAME.PID.SUFFIX``, then ``NAME.PID-2.SUFFIX``...)."""
    for attempt in range(1, 100):
        tag = f"{os.getpid()}" if attempt == 1 else f"{os.getpid()}-{attempt}"
        kept = target.with_name(f"{target.stem}.{tag}{target.suffix}")
        try:
            _link_new(temporary, kept)
            return kept
        except FileExistsError:
            continue
    raise ArchiveError(f"{target} was written by another process while this one computed, and no free name "
                       "was found beside it to keep this run's archive")


def _link_new(temporary: str, target: Path) -> None:
    """Give *temporary* the name *target* only if nothing has that name (never replaces).

    Raises
    ------
    FileExistsError
        *target* exists.
    """
    try:
        os.link(temporary, target)
    except FileExistsError:
        raise
    except OSError:   # a file system without hard links: the best it offers
        if os.path.lexists(target):
            raise FileExistsError(target) from None
        os.rename(temporary, target)
        return
    os.unlink(temporary)


@contextmanager
def atomic_path(target: Path, *, clean_stale: bool = True, replace: bool = True) -> Iterator[str]:
    """Yield a temporary file name beside *target* to write to.

    On success the file is flushed to disk and renamed over *target* (an
    atomic replacement on POSIX); on any failure, including KeyboardInterrupt,
    it is removed and *target* is left as it was.  Every file pounding writes
    goes through here (archives, CSV tables, parts, exported scripts); a
    writer's ``OSError`` (a full disk) is re-raised as the one line of
    :func:`write_error`.  The temporary name carries
    the writer's pid (``.NAME.pounding-PID-XXXX.tmp``) so that temporaries of
    writers that were killed are removed by the next writer in that folder
    (*clean_stale*; a writer of many files in one folder, such as a sweep's
    parts, cleans the folder once instead of listing it before every file).

    With ``replace=False`` the file is linked to *target* only if no file has
    that name: if one appeared while this one was computed (another process
    wrote it), nothing is replaced, the finished file is kept as
    ``NAME.PID.SUFFIX`` beside it and :class:`ArchiveError` says so.
    """
    folder = target.parent if str(target.parent) else Path(".")
    if clean_stale:
        clean_stale_temporaries(folder)
    try:
        descriptor, temporary = tempfile.mkstemp(prefix=f".{target.name}.pounding-{os.getpid()}-", suffix=".tmp",
                                                 dir=folder)
    except OSError as exc:
        raise write_error(target, exc) from exc
    os.close(descriptor)
    try:
        try:
            yield temporary
        except OSError as exc:   # the writer failed: a full disk, a file too large, an I/O error
            raise write_error(target, exc) from exc
        try:
            with open(temporary, "rb+") as handle:
                os.fsync(handle.fileno())
            os.chmod(temporary, 0o666 & ~_umask())   # mkstemp makes 0600; give the mode any new file gets
            if replace:
                os.replace(temporary, target)
            else:
                _link_new(temporary, target)
        except FileExistsError:
            kept = _link_beside(temporary, target)
            raise ArchiveError(f"{target} was written by another process while this one computed; nothing was "
                               f"replaced and this run's archive is kept as {kept} (rename it, or pass "
                               "--overwrite to replace)") from None
        except OSError as exc:
            raise write_error(target, exc) from exc
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


#: errno of a write that failed for want of space.
_FULL = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})


def write_reason(exc: OSError) -> str:
    """Why a write failed, in words: ``No space left on device (the disk is full)``."""
    reason = exc.strerror or str(exc)
    if exc.errno in _FULL:
        reason += " (the disk is full)" if exc.errno != errno.EFBIG else " (the file is larger than allowed)"
    return reason


def write_error(target: str | os.PathLike, exc: OSError) -> ArchiveError:
    """The one line of a write of *target* that failed with *exc* (the file written atomically, so the
    old one is kept): ``cannot write T: No space left on device (the disk is full); the old file...``.
    Raised ``from exc``: the cause stays readable (``__cause__``) and the command line prints this line."""
    return ArchiveError(f"cannot write {target}: {write_reason(exc)}; the old file, if any, is unchanged")


def _umask() -> int:
    """The process's umask, read without changing it (other threads may be creating files)."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)   # no /proc: the classic read-by-setting
    os.umask(mask)
    return mask


@contextmanager
def _interrupt_deferred(temporary: str) -> Iterator[None]:
    """Hold Ctrl-C off while a C library writes *temporary*, then raise KeyboardInterrupt.

    A KeyboardInterrupt raised inside netCDF/HDF5 leaves the library's lock
    held and the close deadlocks.  Here SIGINT only marks the interrupt; the
    write finishes (an archive takes well under a second) and the interrupt is
    raised after it, so the caller removes the temporary and keeps the old
    file.  If the write is still going :data:`INTERRUPT_GRACE` s later, or on
    a second Ctrl-C, the temporary is removed and the process exits at once
    with status 130.  Only in the main thread (signals are delivered there).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    state = {"interrupted": False, "writing": True}

    def leave() -> None:
        if state["writing"]:
            try:
                os.unlink(temporary)
            except OSError:
                pass
            try:
                sys.stderr.write("pounding: interrupted\n")
                sys.stderr.flush()
            except (OSError, ValueError):
                pass
            os._exit(130)

    def handler(signum, frame):  # noqa: ARG001
        if state["interrupted"]:
            leave()
        state["interrupted"] = True
        timer = threading.Timer(INTERRUPT_GRACE, leave)
        timer.daemon = True
        timer.start()

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        state["writing"] = False
        signal.signal(signal.SIGINT, previous)
    if state["interrupted"]:
        raise KeyboardInterrupt


def _encoding(ds: xr.Dataset) -> dict:
    encoding = {}
    for name, var in ds.variables.items():
        if np.issubdtype(var.dtype, np.number) and var.ndim > 0:
            encoding[name] = dict(_COMPRESSION)
    return encoding


def save_run(ds: xr.Dataset, path: str | os.PathLike, *, overwrite: bool = False,
             keep_beside: bool = False) -> Path:
    """Write a results dataset to NetCDF atomically.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`pounding.simulate`.
    path : path-like
        Target ``.nc`` file.  Written by a command line, the archive also records it (attributes
        ``command`` and ``command_directory``, :mod:`pounding.provenance`).
    overwrite : bool
        Replace an existing file.  Without it a file that appears under
        *path* while this one is written is not replaced either: the new
        archive is kept beside it as ``NAME.PID.nc`` (:func:`atomic_path`).
    keep_beside : bool
        Without *overwrite*, an existing file is not refused up front but
        treated as one that appeared meanwhile (the command line: *ds* took
        a whole run to compute and must not be lost).

    Returns
    -------
    pathlib.Path
        The written file.
    """
    from pounding.provenance import command_attributes

    target = check_writable(path, overwrite=overwrite or keep_beside)
    command = command_attributes()
    if command:   # the command line writing it, for `pounding report` (a rerun records the rerun)
        ds = ds.copy(deep=False)
        ds.attrs = {**ds.attrs, **command}
    with atomic_path(target, replace=overwrite) as temporary:
        try:
            with _interrupt_deferred(temporary), _NETCDF_LOCK:
                ds.to_netcdf(temporary, engine="netcdf4", format="NETCDF4", encoding=_encoding(ds))
        except (OSError, RuntimeError) as exc:   # disk full, file too large, HDF error
            detail = getattr(exc, "strerror", None) or " ".join(str(exc).split())[:160]
            raise ArchiveError(f"cannot write {target}: {detail} (is the disk full?); the old file, if any, "
                               "is unchanged") from None
    return target


def open_run(path: str | os.PathLike) -> xr.Dataset:
    """Open a results archive written by :func:`save_run` (loaded into memory).

    The file must be a regular file (a FIFO would block the open forever) and
    pass :func:`check_archive`.

    Raises
    ------
    ArchiveError
        If the file is missing, not a regular file, not NetCDF, not a pounding
        archive, or damaged (``damaged archive: …``).
    """
    source = check_regular_file(path)
    try:
        with _NETCDF_LOCK, xr.open_dataset(source, engine="netcdf4") as handle:
            if not str(handle.attrs.get("source", "")).startswith("pounding") or "run_spec" not in handle.attrs:
                raise ArchiveError(f"{source}: not a pounding run archive (no 'run_spec' attribute)")
            ds = load_within_memory(handle, source)
    except (OSError, ValueError, RuntimeError, KeyError, TypeError, IndexError) as exc:
        raise ArchiveError(f"{source}: not a readable NetCDF file ({type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:120]})") from None
    check_archive(ds, source)
    return ds


def load_within_memory(handle: xr.Dataset, source: str | os.PathLike) -> xr.Dataset:
    """Load an opened (lazy) NetCDF dataset into memory after checking that its variables fit.

    The size is read from the file's metadata (shape x item size), before
    anything is read: a foreign file with a 2.4 GB variable is refused in one
    line instead of being loaded whole.

    Raises
    ------
    PoundingError
        The variables need more than half of the memory available.
    """
    from pounding.memory import check_memory, format_bytes

    size = float(sum(var.size * var.dtype.itemsize for var in handle.variables.values()))
    check_memory(2.0 * size, what=f"{source}: reading its {len(handle.variables)} variables ({format_bytes(size)})",
                 fix="is it the right file? a run archive is a few MB; read it on a machine with more memory")
    return handle.load()


#: Variables every run archive has (the summary, plots and rerun read them).
REQUIRED_VARIABLES = ("displacement", "contact_force", "ground_acceleration", "peak_drift_ratio",
                      "peak_displacement", "peak_contact_force", "impact_count", "impact_velocity",
                      "impact_contact", "impact_time", "trace_contact", "trace_force", "trace_penetration",
                      "trace_time", "storey_building", "storey_level", "contact", "law", "xi_formula",
                      "building_left", "building_right", "level_left", "level_right", "gap", "time")
#: Variables every run archive of planes as weighted rows (floors in plan) has instead.
REQUIRED_PLANE_VARIABLES = ("displacement", "rotation", "contact_force", "peak_drift_ratio", "peak_plane_drift",
                            "peak_displacement", "peak_contact_force", "impact_count", "impact_contact", "impact_time",
                            "plane_building", "plane_storey", "point_between", "building", "level", "contact", "time")
#: Attributes, with the type they must have.
REQUIRED_ATTRIBUTES = {"title": str, "history": str, "model_name": str, "record_name": str, "run_spec": str,
                       "periods": str, "record_metadata": str, "record_scale": float, "duration": float,
                       "energy_closure_error": float, "solver_steps": int, "solver_rejected_steps": int,
                       "wall_time": float}
#: Keys of the JSON ``run_spec`` attribute, with their types.
RUN_SPEC_KEYS = {"model": str, "record": str, "scale": float, "duration": float}


def _damaged(source, what: str) -> ArchiveError:
    return ArchiveError(f"damaged archive: {source}: {what}; rerun the simulation to write it again")


def check_archive(ds: xr.Dataset, source: str | os.PathLike = "archive") -> None:
    """Check that an opened run archive has what the summary, plots and rerun read.

    Raises
    ------
    ArchiveError
        ``damaged archive: FILE: <what is missing or garbled>``.
    """
    import json

    required = REQUIRED_PLANE_VARIABLES if "plane" in ds.dims else REQUIRED_VARIABLES
    missing = [name for name in required if name not in ds.variables]
    if missing:
        raise _damaged(source, f"variable{'s' if len(missing) > 1 else ''} {', '.join(missing[:5])} missing")
    for name, kind in REQUIRED_ATTRIBUTES.items():
        value = ds.attrs.get(name)
        if kind is str:
            ok = isinstance(value, str)
        elif kind is int:
            ok = isinstance(value, (int, np.integer)) and not isinstance(value, bool)
        else:
            ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
        if not ok:
            shown = "missing" if value is None else f"{type(value).__name__} {str(value)[:40]!r}"
            raise _damaged(source, f"attribute '{name}' should be {kind.__name__} (found {shown})")
    for name in ("run_spec", "periods", "record_metadata"):
        try:
            parsed = json.loads(ds.attrs[name])
        except ValueError:
            raise _damaged(source, f"attribute '{name}' is not JSON") from None
        if not isinstance(parsed, dict):
            raise _damaged(source, f"attribute '{name}' is not a JSON object")
        if name == "run_spec":
            for key, kind in RUN_SPEC_KEYS.items():
                value = parsed.get(key)
                ok = isinstance(value, str) if kind is str else \
                    isinstance(value, (int, float)) and not isinstance(value, bool)
                if not ok:
                    raise _damaged(source, f"run_spec['{key}'] should be {kind.__name__} (found {value!r:.40})")
        if name == "periods":
            for building, values in parsed.items():
                if not isinstance(values, list) or not all(isinstance(v, (int, float)) for v in values):
                    raise _damaged(source, f"attribute 'periods' of building {building!r:.40} is not a list of "
                                           "numbers")
