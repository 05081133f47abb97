"""The parts store of a study: one JSON file per finished scenario, written atomically."""

from __future__ import annotations

import json
import math
import os
import re
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

from pounding.errors import PoundingError
from pounding.studies.engine.keys import PARTS_FORMAT
from pounding.studies.engine.tasks import Scenario

__all__ = ["PARTS_SUFFIX", "parts_dir", "save_part", "save_parts", "load_parts", "history_name", "check_part",
           "prepare_store", "sweep_lock", "BAD_SUFFIX"]

#: Suffix given to a part file that failed validation (kept for inspection, never loaded).
BAD_SUFFIX = ".bad"

#: Suffix of the directory that holds one JSON file per finished scenario.
PARTS_SUFFIX = ".parts"

# --------------------------------------------------------------------------- #
# The parts store
# --------------------------------------------------------------------------- #


def parts_dir(output: str | os.PathLike) -> Path:
    """``SWEEP.nc`` → ``SWEEP.nc.parts``."""
    return Path(os.fspath(output) + PARTS_SUFFIX)


def _write_atomic(path: Path, data: bytes) -> None:
    """Write one part; a failure (a full disk) is one line naming the parts folder, whose parts are kept."""
    from pounding.errors import ArchiveError
    from pounding.results.archive import atomic_path, write_reason

    try:
        # The parts folder is cleaned of killed writers' temporaries once, by prepare_store.
        with atomic_path(path, clean_stale=False) as temporary:
            Path(temporary).write_bytes(data)
    except ArchiveError as exc:
        reason = write_reason(exc.__cause__) if isinstance(exc.__cause__, OSError) else str(exc)
        raise PoundingError(f"cannot store a finished scenario in the parts folder {path.parent}: {reason}; the "
                            "scenarios stored there so far are kept: free some space (or choose another output) and "
                            "run the same command again to resume") from None


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def save_part(directory: Path, result: dict[str, Any]) -> Path:
    """Persist one finished scenario (atomic: a crash leaves the old state or the new file)."""
    return save_parts(directory, [result])[0]


def save_parts(directory: Path, results: list[dict[str, Any]]) -> list[Path]:
    """Persist finished scenarios, each file atomically, then the folder's entries once.

    Every part is written to a temporary file, flushed to disk and renamed
    into place, so a kill at any moment leaves each part absent or whole;
    the folder is flushed once for the batch (a task's results arrive
    together), not once per part.
    """
    paths = []
    for result in results:
        record = {k: v for k, v in result.items() if k != "dataset"}
        path = directory / f"{result['key']}.json"
        _write_atomic(path, json.dumps(record).encode())
        paths.append(path)
    if paths:
        _fsync_dir(directory)
    return paths


def prepare_store(directory: Path) -> Path:
    """Create the parts folder, or fail in one line if the name is taken by a file."""
    if directory.exists() and not directory.is_dir():
        raise PoundingError(f"{directory} is a file, but the sweep keeps its finished scenarios in a folder of that "
                            "name; move the file away or choose another output")
    try:
        directory.mkdir(exist_ok=True)
    except OSError as exc:
        raise PoundingError(f"cannot create {directory}: {exc.strerror or exc}") from None
    from pounding.results.archive import clean_stale_temporaries

    clean_stale_temporaries(directory)  # of a run that was killed mid-write (parts are written without it)
    return directory


#: Lists of a part that describe storeys, floors and contacts (each group has one length).
_GROUPS = {
    "storey": ("storey", "storey_building", "storey_level", "height", "peak_drift_ratio"),
    "floor": ("floor", "building", "level", "elevation", "peak_displacement"),
    "contact": ("contact", "building_left", "building_right", "level_left", "level_right", "peak_contact_force",
                "impact_count"),
}
_NUMBERS = ("height", "peak_drift_ratio", "elevation", "peak_displacement", "peak_contact_force")
_INTEGERS = ("storey_level", "level", "level_left", "level_right", "impact_count")


def check_part(part: Any, key: str) -> str | None:
    """Why a part file's content cannot be a stored result (None if it can).

    Checks the format and key, the status, and for a finished scenario that
    every list is present, of the length of its group (storeys, floors,
    contacts), of the right type and finite: a truncated list would
    otherwise be filled with NaN and reported ``ok``.
    """
    if not isinstance(part, dict):
        return "not a JSON object"
    if part.get("format") != PARTS_FORMAT:
        return f"format {part.get('format')!r}, expected {PARTS_FORMAT}"
    if part.get("key") != key:
        return "its key does not match its file name"
    status = part.get("status")
    if status == "error":
        return None if isinstance(part.get("error"), str) and part["error"] else "status error without a message"
    if status != "ok":
        return f"status {status!r}"
    if part.get("study") is not None:
        # another study's runner (pounding gap, pounding ida): its lists, at the top and in each group (a
        # mapping of lists such as "storeys"), have one length per group; numbers are finite (None: no value)
        groups = [("", part)] + [(f"{name}.", group) for name, group in part.items() if isinstance(group, dict)]
        found = False
        for prefix, group in groups:
            lists = {name: values for name, values in group.items() if isinstance(values, list)}
            found = found or bool(lists)
            if len({len(values) for values in lists.values()}) > 1:
                return f"its {prefix.rstrip('.') or 'top-level'} lists differ in length"
            for name, values in lists.items():
                if any(isinstance(v, float) and not math.isfinite(v) for v in values):
                    return f"'{prefix}{name}' holds a value that is not finite"
        return None if found else "its lists are missing"
    for group, names in _GROUPS.items():
        lengths = {}
        for name in names:
            values = part.get(name)
            if not isinstance(values, list):
                return f"'{name}' is missing or not a list"
            lengths[name] = len(values)
            for v in values:
                if name in _INTEGERS:
                    ok = isinstance(v, int) and not isinstance(v, bool) and v >= 0
                elif name in _NUMBERS:
                    ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                else:
                    ok = isinstance(v, str)
                if not ok:
                    return f"'{name}' holds {v!r:.40}"
        if len(set(lengths.values())) > 1:
            shown = ", ".join(f"{n} {k}" for n, k in lengths.items())
            return f"the {group} lists differ in length ({shown})"
    if not part["storey"] or not part["floor"]:
        return "no storeys or floors"
    closure = part.get("energy_closure_error")
    if not isinstance(closure, (int, float)) or isinstance(closure, bool) or not math.isfinite(closure):
        return f"'energy_closure_error' is {closure!r:.40}"
    return None


def _set_aside(entry: Path, why: str, bad: list[str] | None) -> None:
    target = entry.with_name(entry.name + BAD_SUFFIX)
    try:
        if target.exists() and target.is_dir():
            raise OSError(f"{target} is a folder")
        os.replace(entry, target)
    except OSError as exc:
        raise PoundingError(f"{entry} is not a valid part ({why}) and cannot be set aside ({exc}); remove it "
                            "and run again") from None
    if bad is not None:
        bad.append(f"{entry.name}: {why} (set aside as {target.name})")


def load_parts(directory: Path, *, bad: list[str] | None = None) -> dict[str, dict[str, Any]]:
    """Every valid part in *directory*, by scenario key.

    Temporaries of writers that died are removed; a part that fails
    :func:`check_part` (or is a folder, or is not JSON) is renamed to
    ``KEY.json.bad`` so that its scenario runs again, and described in *bad*.
    """
    from pounding.results.archive import clean_stale_temporaries

    found: dict[str, dict[str, Any]] = {}
    if not directory.is_dir():
        return found
    clean_stale_temporaries(directory)
    for entry in directory.iterdir():
        if entry.suffix != ".json" or entry.name.startswith("."):
            continue
        if entry.is_dir():
            _set_aside(entry, "a folder, not a file", bad)
            continue
        if not entry.is_file():
            _set_aside(entry, "not a regular file", bad)
            continue
        try:
            part = json.loads(entry.read_text())
        except (OSError, ValueError, UnicodeDecodeError) as exc:
            _set_aside(entry, f"unreadable ({type(exc).__name__})", bad)
            continue
        problem = check_part(part, entry.stem)
        if problem is not None:
            _set_aside(entry, problem, bad)
            continue
        found[entry.stem] = part
    return found


@contextmanager
def sweep_lock(output: Path) -> Iterator[None]:
    """Hold an exclusive lock on *output* for a whole sweep (``.OUTPUT.lock`` beside it).

    Two sweeps writing the same output would interleave parts and replace
    each other's results; the second one fails at once, naming the holder
    (:func:`pounding.results.archive.output_lock`, released however the
    process ends).

    Raises
    ------
    PoundingError
        Another process holds the lock.
    """
    from pounding.results.archive import output_lock

    with output_lock(output, writer="sweep"):
        yield


def history_name(scenario: Scenario) -> str:
    """File name of a scenario's full results under ``--keep-histories``."""
    text = "_".join(f"{k}={v}" for k, v in scenario.coords.items())
    text = re.sub(r"[^A-Za-z0-9.=+-]+", "_", text).strip("_")[:150]
    return f"{text}_{scenario.key[:8]}.nc"

