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

from pounding import __version__
from pounding.records.fingerprint import catalogue_entries, record_fingerprint

__all__ = ["PARTS_FORMAT", "content_key", "record_fingerprint", "code_fingerprint", "scenario_key",
           "catalogue_entries"]

#: Version of the part-file layout; part files of another version are ignored.
PARTS_FORMAT = 1


def content_key(identity: str, record: str, code: str) -> str:
    """The part key: a scenario's identity with the fingerprints of its record and of the code."""
    blob = json.dumps({"format": PARTS_FORMAT, "identity": identity, "record": record, "code": code},
                      sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


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
