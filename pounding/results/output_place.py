"""Where a command's outputs go, checked before anything is computed: standard library only.

A run's archive, a figure folder, a CSV or a report: each is checked here (exists without
``--overwrite``, is one of the command's inputs, a folder that cannot be created or written, a name
NetCDF or the file system would refuse) so that a command refuses in one line before it computes,
and before it imports the numerical libraries (``pounding run -o existing.nc`` refuses at once).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from pounding.errors import ArchiveError

__all__ = ["check_writable", "make_folder", "nearest_existing", "check_output_place", "check_not_input",
           "check_regular_file"]


def nearest_existing(path: str | os.PathLike) -> Path:
    """*path* itself if it exists, else its closest ancestor that does (``.`` for a relative path)."""
    probe = Path(path)
    while not probe.exists() and not probe.is_symlink():
        if probe.parent == probe:
            break
        probe = probe.parent
    return probe


def check_output_place(path: str | os.PathLike, option: str, *, folder: bool, inputs: tuple | list = ()) -> None:
    """Before any computation: *path* (a folder if *folder*, else a file) can be made where it is asked,
    and a file is none of the command's *inputs*.

    One line naming *option* (``--plot``, ``--csv``, ``-o``) where the path is a file but a folder is asked
    (or a folder but a file is), where an ancestor is a file, where the closest existing folder is not
    writable, or where the file is one of *inputs* (:func:`check_not_input`: after resolving links and
    ``..``): found after the work, each was a traceback with the results lost, or an input destroyed.

    Raises
    ------
    ArchiveError
    """
    target = Path(path)
    if not folder:
        check_not_input(target, inputs, option)
    if folder and target.exists() and not target.is_dir():
        raise ArchiveError(f"{option} {target}: it is a file; {option} needs a directory")
    if not folder and target.is_dir():
        raise ArchiveError(f"{option} {target}: it is a directory; give a file name such as {target / 'results'}")
    probe = nearest_existing(target if folder else target.parent)
    if probe.exists() and not probe.is_dir():
        raise ArchiveError(f"{option} {target}: {probe} is a file, not a directory; choose another path")
    if probe.exists() and not os.access(probe, os.W_OK | os.X_OK):
        raise ArchiveError(f"{option} {target}: {probe} is not writable; choose another folder")


def make_folder(folder: str | os.PathLike, *, what: str) -> Path:
    """Create *folder* and its missing parents; one line naming *what* (the output) if it cannot be.

    Raises
    ------
    ArchiveError
        An ancestor is a file, or the closest existing one is not writable, or the system refuses.
    """
    folder = Path(folder)
    base = nearest_existing(folder)
    if base.exists() and not base.is_dir():
        raise ArchiveError(f"{what}: {base} is a file, not a directory; choose another output path")
    if base.exists() and not os.access(base, os.W_OK | os.X_OK):
        raise ArchiveError(f"{what}: directory {base} is not writable; choose another output folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ArchiveError(f"{what}: cannot create the folder {folder} ({exc.strerror or exc})") from None
    return folder


def check_writable(path: str | os.PathLike, *, overwrite: bool = False,
                   inputs: tuple | list = (), example: str = "run.nc") -> Path:
    """Fail early (before any computation) if *path* cannot be written.

    Parameters
    ----------
    inputs : sequence of path-like
        Files the command reads (model, record, sweep file, archive): the
        output must not be one of them, even with *overwrite*.
    example : str
        The file name suggested inside a folder given as *path* (``report.html`` for a report).

    Raises
    ------
    ArchiveError
        If the file exists and *overwrite* is false, is not a regular file,
        is one of *inputs*, or its directory is not a directory, not writable or
        cannot be created (a missing one is created, with its parents), or the
        name is too long.
    """
    target = Path(path)
    try:
        os.fspath(target).encode("utf-8")
    except UnicodeEncodeError:   # netCDF/HDF5 take UTF-8 names only: found after the run, too late
        shown = os.fsencode(target).decode("utf-8", "backslashreplace")
        raise ArchiveError(f"{shown}: the output name is not valid UTF-8 (NetCDF cannot create it); choose a "
                           "UTF-8 name") from None
    check_not_input(target, inputs)
    if target.is_dir():
        raise ArchiveError(f"{target} is a directory; give a file name such as {target / example}")
    if target.exists() or target.is_symlink():
        if not overwrite:
            raise ArchiveError(f"{target} already exists; pass --overwrite (overwrite=True) or choose another "
                               "output file")
        if target.exists() and not stat.S_ISREG(os.stat(target).st_mode):
            raise ArchiveError(f"{target} is not a regular file (a FIFO, device or socket); choose another "
                               "output file")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.exists():   # created, as --plot creates its folder
        make_folder(parent, what=str(target))
    if not parent.is_dir():
        raise ArchiveError(f"{target}: {parent} is a file, not a directory; choose another output path")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ArchiveError(f"{target}: directory {parent} is not writable; choose another output folder")
    try:
        limit = os.pathconf(parent, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    # the temporary file is named .NAME.pounding-PID-RANDOM.tmp: ~40 more bytes than NAME
    if len(os.fsencode(target.name)) + 40 > limit:
        raise ArchiveError(f"{target}: the file name is too long ({len(os.fsencode(target.name))} bytes; this "
                           f"file system allows {limit - 40} for an archive); choose a shorter name")
    return target


def check_not_input(output: str | os.PathLike, inputs: tuple | list = (), option: str = "") -> None:
    """Refuse an *output* that is the same file as one of *inputs*: the same path after resolving links
    and ``..`` (either may be a link), or the same file under another name (a hard link).

    *option* (``--csv``) names the output in the message.

    Raises
    ------
    ArchiveError
        Naming the input the output would destroy.
    """
    out = Path(output)
    for item in inputs:
        if item is None:
            continue
        source = Path(item)
        try:
            same = (out.exists() and source.exists() and os.path.samefile(out, source)) or \
                out.resolve() == source.resolve()
        except (OSError, RuntimeError):
            same = False
        if same:
            shown = f"{option} {out}" if option else str(out)
            raise ArchiveError(f"{shown} is an input of this command ({item}); writing there would destroy it: "
                               "choose another output file")


def check_regular_file(path: str | os.PathLike, what: str = "archive") -> Path:
    """*path* as a Path if it is an existing regular file (not a FIFO, device, socket or folder).

    Opening a FIFO blocks until a writer appears, so anything that is read
    checks this first.

    Raises
    ------
    ArchiveError
        Missing, a folder, or not a regular file.
    """
    source = Path(path)
    try:
        mode = os.stat(source).st_mode
    except FileNotFoundError:
        raise ArchiveError(f"{source}: no such file") from None
    except OSError as exc:
        raise ArchiveError(f"{source}: cannot read ({exc.strerror})") from None
    if stat.S_ISDIR(mode):
        raise ArchiveError(f"{source} is a folder, not an {what} file")
    if not stat.S_ISREG(mode):
        raise ArchiveError(f"{source} is not a regular file (a FIFO, device or socket); give an {what} file")
    return source
