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

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import numpy as np
import xarray as xr

from pounding.errors import ArchiveError

__all__ = ["save_run", "open_run", "check_writable", "atomic_path"]

_COMPRESSION = {"zlib": True, "complevel": 4}


def check_writable(path: str | os.PathLike, *, overwrite: bool = False) -> Path:
    """Fail early (before any computation) if *path* cannot be written.

    Raises
    ------
    ArchiveError
        If the file exists and *overwrite* is false, or its directory is missing.
    """
    target = Path(path)
    if target.exists() and not overwrite:
        raise ArchiveError(f"{target} already exists; pass --overwrite (overwrite=True) or choose another "
                           "output file")
    if target.is_dir():
        raise ArchiveError(f"{target} is a directory; give a file name such as {target / 'run.nc'}")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.exists():
        raise ArchiveError(f"{target}: directory {parent} does not exist; create it first")
    return target


@contextmanager
def atomic_path(target: Path) -> Iterator[str]:
    """Yield a temporary file name beside *target* to write to.

    On success the file is flushed to disk and renamed over *target* (an
    atomic replacement on POSIX); on any failure, including KeyboardInterrupt,
    it is removed and *target* is left as it was.
    """
    folder = target.parent if str(target.parent) else Path(".")
    descriptor, temporary = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    os.close(descriptor)
    try:
        yield temporary
        with open(temporary, "rb+") as handle:
            os.fsync(handle.fileno())
        os.chmod(temporary, 0o666 & ~_umask())   # mkstemp makes 0600; give the mode any new file gets
        os.replace(temporary, target)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


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


def _encoding(ds: xr.Dataset) -> dict:
    encoding = {}
    for name, var in ds.variables.items():
        if np.issubdtype(var.dtype, np.number) and var.ndim > 0:
            encoding[name] = dict(_COMPRESSION)
    return encoding


def save_run(ds: xr.Dataset, path: str | os.PathLike, *, overwrite: bool = False) -> Path:
    """Write a results dataset to NetCDF atomically.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`pounding.simulate`.
    path : path-like
        Target ``.nc`` file.
    overwrite : bool
        Replace an existing file.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    target = check_writable(path, overwrite=overwrite)
    with atomic_path(target) as temporary:
        ds.to_netcdf(temporary, engine="netcdf4", format="NETCDF4", encoding=_encoding(ds))
    return target


def open_run(path: str | os.PathLike) -> xr.Dataset:
    """Open a results archive written by :func:`save_run` (loaded into memory).

    Raises
    ------
    ArchiveError
        If the file is missing, not NetCDF, or not a pounding archive.
    """
    source = Path(path)
    if not source.exists():
        raise ArchiveError(f"{source}: no such file")
    try:
        with xr.open_dataset(source, engine="netcdf4") as handle:
            ds = handle.load()
    except (OSError, ValueError) as exc:
        raise ArchiveError(f"{source}: not a readable NetCDF file ({type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:120]})") from None
    if not str(ds.attrs.get("source", "")).startswith("pounding") or "run_spec" not in ds.attrs:
        raise ArchiveError(f"{source}: not a pounding run archive (no 'run_spec' attribute)")
    return ds
