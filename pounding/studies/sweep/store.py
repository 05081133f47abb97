"""The parts store of a sweep: one JSON file per finished scenario, written atomically."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any

from pounding.studies.sweep.spec import PARTS_FORMAT, Scenario

__all__ = ["PARTS_SUFFIX", "parts_dir", "save_part", "load_parts", "history_name"]

#: Suffix of the directory that holds one JSON file per finished scenario.
PARTS_SUFFIX = ".parts"

# --------------------------------------------------------------------------- #
# The parts store
# --------------------------------------------------------------------------- #


def parts_dir(output: str | os.PathLike) -> Path:
    """``SWEEP.nc`` → ``SWEEP.nc.parts``."""
    return Path(os.fspath(output) + PARTS_SUFFIX)


def _write_atomic(path: Path, data: bytes) -> None:
    from pounding.results.archive import atomic_path

    with atomic_path(path) as temporary:
        Path(temporary).write_bytes(data)


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
    record = {k: v for k, v in result.items() if k != "dataset"}
    path = directory / f"{result['key']}.json"
    _write_atomic(path, json.dumps(record).encode())
    _fsync_dir(directory)
    return path


def load_parts(directory: Path) -> dict[str, dict[str, Any]]:
    """Every readable part in *directory*, by scenario key (stale temporaries are removed)."""
    found: dict[str, dict[str, Any]] = {}
    if not directory.is_dir():
        return found
    for entry in directory.iterdir():
        if entry.name.startswith(".") and entry.name.endswith(".tmp"):
            try:
                entry.unlink()
            except OSError:
                pass
            continue
        if entry.suffix != ".json":
            continue
        try:
            part = json.loads(entry.read_text())
        except (OSError, ValueError):
            continue   # unreadable: the scenario is simply run again
        if isinstance(part, dict) and part.get("format") == PARTS_FORMAT and part.get("key") == entry.stem:
            found[entry.stem] = part
    return found


def history_name(scenario: Scenario) -> str:
    """File name of a scenario's full results under ``--keep-histories``."""
    text = "_".join(f"{k}={v}" for k, v in scenario.coords.items())
    text = re.sub(r"[^A-Za-z0-9.=+-]+", "_", text).strip("_")[:150]
    return f"{text}_{scenario.key[:8]}.nc"

