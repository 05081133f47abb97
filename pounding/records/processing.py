"""Record processing and scaling: what ``ground_motion.processing`` and ``ground_motion.scale`` ask for.

Processing (optional, in this order; each step is recorded in the record's metadata)::

    processing: {trim: significant-duration, baseline: true}

``trim: significant-duration``
    Keep the 5–95 % Arias-intensity window (Trifunac & Brady 1975): from the
    last sample where the cumulative ∫a² dt is still ≤ 5 % of its total to
    the first where it reaches 95 %; the kept samples start at t = 0.
``baseline: true``
    Remove the least-squares trend ``c1·t + c2·t²`` from the velocity
    (trapezoidal integral of the acceleration), i.e. subtract ``c1 + 2·c2·t``
    from the acceleration: the corrected velocity has no mean drift and no
    linear trend, and a constant or linearly drifting acceleration offset is
    removed exactly.

Scaling (after processing)::

    scale: 1.5                          # a factor
    scale: {pga: 0.4g}                  # to a peak ground acceleration
    scale: {sa: 0.8g, period: 1.0}      # to Sa(T = 1.0 s, 5 %) (pseudo-spectral acceleration)
    scale: {sa: 0.8g, period: building A, damping: 0.05}   # at building A's first period
    scale: {fema-p695: true}            # the FEMA P695 normalisation factor of the record

Accelerations carry their units: ``0.4g``, ``3.9 m/s2``, ``390 gal``,
``390 cm/s2``.  The factor resolved from a target is exact by linearity: the
scaled record's PGA or Sa equals the target to round-off.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.errors import RecordError, did_you_mean
from pounding.records.record import Record
from pounding.units import NUMBER, NUMBER_TEXT, STANDARD_GRAVITY, UNIT_CHOICES, UNITS, canonical_unit, number_from_text

__all__ = [
    "Scaling", "Processing", "SpecProblem", "parse_scale", "parse_processing", "parse_acceleration",
    "scale_record", "process", "trim_significant_duration", "baseline_correct", "arias_intensity",
    "fema_normalisation_factor", "pair_scale_factor", "TRIM_METHODS",
]

SCALE_METHODS = ("pga", "sa", "fema-p695")

#: Longest period of a spectral-acceleration target, s (ASCE 7 and NGA-West2
#: spectra stop at 10-20 s; a period of 1e6 s asks for a factor of ~1e10).
SA_PERIOD_MAX = 20.0

#: A resolved scale factor (target PGA, Sa or FEMA P695) must lie within
#: [1/SCALE_FACTOR_MAX, SCALE_FACTOR_MAX]: amplifying a record a thousand
#: times means it cannot represent the target (usually wrong units).
SCALE_FACTOR_MAX = 1000.0
SCALE_KEYS = ("pga", "sa", "period", "damping", "fema-p695")
PROCESSING_KEYS = ("trim", "baseline")
TRIM_METHODS = ("significant-duration",)
_ACCELERATION = re.compile(rf"^\s*({NUMBER})\s*([A-Za-z][A-Za-z0-9/^*]*)\s*$")
_PERIOD_SECONDS = re.compile(rf"^\s*({NUMBER})\s*s?\s*$")
_BUILDING = re.compile(r"^\s*building\s+(.+?)\s*$", re.IGNORECASE)


class SpecProblem(Exception):
    """A bad ``scale`` / ``processing`` value.

    Attributes
    ----------
    where : tuple
        Location below the section (e.g. ``('pga',)``; ``()`` for the section itself).
    text : str
        ``must ...`` predicate (``kind == 'must'``) or a full sentence (``'error'``).
    kind : str
    hint : str
    """

    def __init__(self, where: tuple, text: str, kind: str = "must", hint: str = "", at: tuple | None = None):
        super().__init__(text)
        self.where, self.text, self.kind, self.hint = tuple(where), text, kind, hint
        self.at = self.where if at is None else tuple(at)   # where the line is taken from

    def message(self, section: str, got: Any = None) -> str:
        """One-line message without file and line (for programmatic use)."""
        where = section + "".join(f".{w}" for w in self.where)
        if self.kind == "must":
            text = f"{where} {self.text}" + ("" if got is None else f" (got {got!r})")
            return text + (f"; {self.hint}" if self.hint else "")
        return f"{where}: {self.text}"


# --------------------------------------------------------------------------- #
# Specifications
# --------------------------------------------------------------------------- #


def parse_acceleration(value: Any, where: tuple = ()) -> tuple[float, str]:
    """``'0.4g'`` → ``(3.92266, '0.4g')``: a positive acceleration with units, in m/s².

    Raises
    ------
    SpecProblem
        No units, unknown units, or a value ≤ 0.
    """
    example = "e.g. 0.4g, 3.9 m/s2 or 390 gal"
    if isinstance(value, bool) or value is None:
        raise SpecProblem(where, f"must be an acceleration with units, {example}")
    if isinstance(value, (int, float)) or (isinstance(value, str) and NUMBER_TEXT.match(value)):
        raise SpecProblem(where, f"must be an acceleration with units, {example}",
                          hint="a number alone is ambiguous (g or m/s2?)")
    match = _ACCELERATION.match(str(value))
    if not match:
        raise SpecProblem(where, f"must be an acceleration with units, {example}")
    number = float(match[1])
    unit = canonical_unit(match[2])
    if unit is None:
        raise SpecProblem(where, "must be in g, m/s2, cm/s2 or gal",
                          hint=did_you_mean(match[2].lower(), list(UNIT_CHOICES)).strip())
    if not math.isfinite(number) or number <= 0:
        raise SpecProblem(where, "must be > 0")
    return number * UNITS[unit], str(value).strip()


@dataclass(frozen=True)
class Scaling:
    """How a record is scaled.

    Attributes
    ----------
    method : str
        ``factor``, ``pga``, ``sa`` or ``fema-p695``.
    factor : float
        The factor of method ``factor``.
    target : float, optional
        PGA or Sa target, m/s².
    target_text : str, optional
        The target as written (``'0.4g'``), kept for the YAML round trip.
    period : float, optional
        Period of ``sa``, s (None with ``building``).
    building : str, optional
        ``sa`` at this building's first period.
    damping : float
        Damping ratio of ``sa`` (default 5 %).
    """

    method: str
    factor: float = 1.0
    target: float | None = None
    target_text: str | None = None
    period: float | None = None
    building: str | None = None
    damping: float = 0.05

    def to_document(self) -> float | dict:
        """The YAML form: a number, or ``{pga: ...}`` / ``{sa: ..., period: ...}`` / ``{fema-p695: true}``."""
        if self.method == "factor":
            return float(self.factor)
        if self.method == "fema-p695":
            return {"fema-p695": True}
        out: dict[str, Any] = {self.method: self.target_text}
        if self.method == "sa":
            out["period"] = f"building {self.building}" if self.building is not None else float(self.period)
            if self.damping != 0.05:
                out["damping"] = float(self.damping)
        return out

    def describe(self, period: float | None = None) -> str:
        """E.g. ``sa 0.8g at T = 0.912 s (building A, mode 1), 5% damping``."""
        if self.method == "factor":
            return f"factor {self.factor:g}"
        if self.method == "fema-p695":
            return "FEMA P695 normalisation factor"
        if self.method == "pga":
            return f"pga {self.target_text}"
        t = self.period if period is None else period
        where = f"T = {t:.6g} s" if t is not None else "T = ?"
        if self.building is not None:
            where += f" (building {self.building}, mode 1)"
        return f"sa {self.target_text} at {where}, {100 * self.damping:g}% damping"


@dataclass(frozen=True)
class Processing:
    """Processing steps: ``trim`` (None or ``significant-duration``), then ``baseline``."""

    trim: str | None = None
    baseline: bool = False

    @property
    def active(self) -> bool:
        return self.trim is not None or self.baseline

    def to_document(self) -> dict:
        out: dict[str, Any] = {}
        if self.trim is not None:
            out["trim"] = self.trim
        if self.baseline:
            out["baseline"] = True
        return out


def _as_number(value: Any) -> float | None:
    if isinstance(value, bool) or value is None:
        return None
    if isinstance(value, (int, float)):
        return float(value)
    return number_from_text(value)


def parse_scale(value: Any, buildings: Sequence[str] | None = None) -> float | Scaling:
    """A ``ground_motion.scale`` value: a positive number or a :class:`Scaling` from a mapping.

    Parameters
    ----------
    value : number or mapping
    buildings : list of str, optional
        Building names, to check ``period: building X`` (not checked if None).

    Raises
    ------
    SpecProblem
    """
    if not isinstance(value, Mapping):
        number = _as_number(value)
        if number is None or not math.isfinite(number):
            raise SpecProblem((), "must be a number")
        if number <= 0:
            raise SpecProblem((), "must be > 0")
        return number
    data = {str(k): v for k, v in value.items()}
    for key in data:
        if key not in SCALE_KEYS:
            hint = did_you_mean(key, SCALE_KEYS) or f"; allowed keys: {', '.join(SCALE_KEYS)}"
            raise SpecProblem((), f"unknown key '{key}'{hint}", "error", at=(key,))
    methods = [m for m in SCALE_METHODS if m in data]
    if not methods:
        raise SpecProblem((), "give one of pga, sa or fema-p695, e.g. {pga: 0.4g}, {sa: 0.8g, period: 1.0} or "
                              "{fema-p695: true}", "error")
    if len(methods) > 1:
        raise SpecProblem((), f"give one of pga, sa or fema-p695, not {' and '.join(methods)}", "error")
    method = methods[0]
    if method != "sa":
        for extra in ("period", "damping"):
            if extra in data:
                raise SpecProblem((extra,), f"applies only to sa; remove it (scaling to {method})", "error")
    if method == "fema-p695":
        if data["fema-p695"] is not True:
            raise SpecProblem(("fema-p695",), "must be true",
                              hint="remove scale to keep the record's own amplitude")
        return Scaling("fema-p695")
    target, text = parse_acceleration(data[method], (method,))
    if method == "pga":
        return Scaling("pga", target=target, target_text=text)
    if "period" not in data:
        raise SpecProblem((), "sa needs a period: {sa: " + text + ", period: 1.0} (seconds) or {sa: " + text
                          + ", period: building A} (that building's first period)", "error")
    period_value = data["period"]
    period: float | None = None
    building: str | None = None
    match = _BUILDING.match(period_value) if isinstance(period_value, str) else None
    if match:
        building = match[1]
        if buildings is not None and building not in buildings:
            raise SpecProblem(("period",), f"unknown building '{building}'{did_you_mean(building, list(buildings))}; "
                                           f"buildings are: {', '.join(buildings)}", "error")
    else:
        seconds = _PERIOD_SECONDS.match(period_value) if isinstance(period_value, str) else None
        number = float(seconds[1]) if seconds else _as_number(period_value)
        if number is None or not math.isfinite(number) or number <= 0:
            raise SpecProblem(("period",), "must be a period > 0 s or 'building <name>'")
        period = number
    damping = 0.05
    if "damping" in data:
        number = _as_number(data["damping"])
        if number is None or not 0.0 <= number < 1.0:
            raise SpecProblem(("damping",), "must be a damping ratio in [0, 1)")
        damping = number
    return Scaling("sa", target=target, target_text=text, period=period, building=building, damping=damping)


def parse_processing(value: Any) -> Processing | None:
    """A ``ground_motion.processing`` mapping → :class:`Processing` (None when it asks for nothing)."""
    if value is None:
        return None
    if isinstance(value, Processing):
        return value if value.active else None
    if not isinstance(value, Mapping):
        raise SpecProblem((), "must be a mapping, e.g. {trim: significant-duration, baseline: true}")
    data = {str(k): v for k, v in value.items()}
    for key in data:
        if key not in PROCESSING_KEYS:
            hint = did_you_mean(key, PROCESSING_KEYS) or f"; allowed keys: {', '.join(PROCESSING_KEYS)}"
            raise SpecProblem((), f"unknown key '{key}'{hint}", "error", at=(key,))
    trim = data.get("trim")
    if trim is not None and trim is not False:
        if not isinstance(trim, str) or trim.strip().lower() not in TRIM_METHODS:
            hint = did_you_mean(str(trim).lower(), TRIM_METHODS).strip() if isinstance(trim, str) else ""
            raise SpecProblem(("trim",), "must be significant-duration (the 5-95% Arias-intensity window)", hint=hint)
        trim = trim.strip().lower()
    else:
        trim = None
    baseline = data.get("baseline", False)
    if baseline is None:
        baseline = False
    if not isinstance(baseline, bool):
        raise SpecProblem(("baseline",), "must be true or false")
    result = Processing(trim=trim, baseline=baseline)
    return result if result.active else None


# --------------------------------------------------------------------------- #
# Processing
# --------------------------------------------------------------------------- #


def _steps(record: Record) -> list[str]:
    text = record.metadata.get("processing")
    return list(json.loads(text)) if isinstance(text, str) and text else []


def _with(record: Record, acceleration: np.ndarray, step: str, **metadata: Any) -> Record:
    merged = dict(record.metadata, **metadata)
    merged["processing"] = json.dumps(_steps(record) + [step])
    return dataclasses.replace(record, acceleration=acceleration, metadata=merged)


def arias_intensity(record: Record) -> np.ndarray:
    """Cumulative Arias intensity ``π/(2g) ∫₀ᵗ a² dt`` at every sample, m/s (trapezoidal rule)."""
    a2 = record.acceleration ** 2
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (a2[1:] + a2[:-1]) * record.time_step)])
    return math.pi / (2.0 * STANDARD_GRAVITY) * cumulative


def trim_significant_duration(record: Record, low: float = 0.05, high: float = 0.95) -> Record:
    """Keep the samples of the *low*–*high* Arias-intensity window; they start again at t = 0."""
    if not 0.0 <= low < high <= 1.0:
        raise RecordError(f"the Arias window must satisfy 0 <= low < high <= 1 (got {low}, {high})")
    arias = arias_intensity(record)
    total = float(arias[-1])
    if total <= 0.0:
        raise RecordError("the record is all zeros: there is no significant-duration window to trim to; "
                          "remove trim from ground_motion.processing", file=record.source or None)
    start = int(np.flatnonzero(arias <= low * total)[-1])
    end = int(np.flatnonzero(arias >= high * total)[0])
    end = max(end, start + 1)
    dt = record.time_step
    step = (f"trim: {100 * low:g}-{100 * high:g}% Arias significant duration, samples {start}-{end} "
            f"(t = {start * dt:.6g}-{end * dt:.6g} s of the input)")
    return _with(record, record.acceleration[start:end + 1], step,
                 trim_start_s=start * dt, trim_end_s=end * dt, significant_duration_s=(end - start) * dt,
                 arias_intensity_m_s=total)


def baseline_correct(record: Record) -> Record:
    """Subtract ``c1 + 2·c2·t`` from the acceleration, (c1, c2) the least-squares fit of ``c1·t + c2·t²`` to
    the trapezoidal velocity."""
    acc = record.acceleration
    dt = record.time_step
    t = record.time
    velocity = np.concatenate([[0.0], np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt)])
    basis = np.column_stack([t, t * t])
    (c1, c2), *_ = np.linalg.lstsq(basis, velocity, rcond=None)
    corrected = acc - (c1 + 2.0 * c2 * t)
    step = f"baseline: velocity trend c1*t + c2*t^2 removed (c1 = {c1:.6g} m/s2, c2 = {c2:.6g} m/s3)"
    return _with(record, corrected, step, baseline_c1_m_s2=float(c1), baseline_c2_m_s3=float(c2))


def process(record: Record, processing: Processing | None) -> Record:
    """Apply *processing* (trim, then baseline); the steps go to ``metadata['processing']`` (JSON list)."""
    if processing is None or not processing.active:
        return record
    if processing.trim == "significant-duration":
        record = trim_significant_duration(record)
    if processing.baseline:
        record = baseline_correct(record)
    return record


# --------------------------------------------------------------------------- #
# Scaling
# --------------------------------------------------------------------------- #


def fema_normalisation_factor(record: Record) -> float:
    """The FEMA P695 normalisation factor NM_i = median(PGV_PEER) / PGV_PEER,i of a FEMA P695 record."""
    factor = record.metadata.get("normalization_factor")
    if not isinstance(factor, (int, float)) or not factor > 0:
        raise RecordError(f"scale {{fema-p695: true}} needs a FEMA P695 record (fema-p695:<set>/<id><a|b> or its "
                          f"catalogue key); {record.name} is not one: use pga or sa scaling instead",
                          file=record.source or None)
    return float(factor)


def pair_scale_factor(records: list[Record], scaling: float | Scaling, *, period: float | None = None) -> float:
    """The one factor that takes a record pair (both horizontal components) to *scaling*'s target.

    A factor is itself; a target PGA or Sa(T) applies to the pair's geometric mean
    ``√(IM_a · IM_b)`` of the components' intensities (FEMA P695 §A.8 normalises and scales
    record pairs by their geometric-mean spectrum); ``fema-p695`` is the pair's normalisation
    factor (one per pair in FEMA P695 Table A-4C: both components carry it).  One component
    present: its own intensity.
    """
    from pounding.records.spectra import spectral_acceleration

    if not isinstance(scaling, Scaling):
        scaling = Scaling("factor", factor=float(scaling))
    if scaling.method == "factor":
        return float(scaling.factor)
    if scaling.method == "fema-p695":
        return fema_normalisation_factor(records[0])
    t = scaling.period if period is None else period
    if scaling.method == "pga":
        measures = [r.pga for r in records]
    else:
        if t is None or not t > 0:
            raise RecordError(f"scale {scaling.describe()}: the period is unknown; give period in seconds")
        measures = [spectral_acceleration(r, period=t, damping=scaling.damping) for r in records]
    mean = math.prod(measures) ** (1.0 / len(measures))
    factor = scaling.target / mean if mean > 0 else math.inf
    if not math.isfinite(factor):
        raise RecordError(f"cannot scale a record pair of zero amplitude to {scaling.describe(t)}",
                          file=records[0].source or None)
    return float(factor)


def scale_record(record: Record, scaling: float | Scaling, *, period: float | None = None,
                 factor: float | None = None) -> Record:
    """Scale a (processed) record and record how in its metadata.

    Parameters
    ----------
    record : Record
    scaling : float or Scaling
    period : float, optional
        The period of ``sa`` scaling at a building's first period (resolved by the caller).
    factor : float, optional
        Use this factor instead of resolving the method again (rerun of an archive).

    Returns
    -------
    Record
        ``scale`` multiplied by the factor; metadata ``scale_method``,
        ``scale_description``, ``scale_factor`` and, for targets,
        ``scale_target_m_s2``, ``scale_period_s``, ``scale_damping``.
    """
    from pounding.records.spectra import spectral_acceleration

    if not isinstance(scaling, Scaling):
        scaling = Scaling("factor", factor=float(scaling))
    extra: dict[str, Any] = {}
    t = scaling.period if period is None else period
    if scaling.method == "sa":
        if t is None or not t > 0:
            raise RecordError(f"scale {scaling.describe()}: the period is unknown; give period in seconds")
        if t > SA_PERIOD_MAX:
            raise RecordError(f"scale {scaling.describe(t)}: a period of {t:g} s is beyond {SA_PERIOD_MAX:g} s, the "
                              "longest of published design and NGA spectra; give the period in seconds",
                              file=record.source or None)
        extra.update(scale_period_s=float(t), scale_damping=float(scaling.damping))
        if scaling.building is not None:
            extra["scale_building"] = scaling.building
    if scaling.target is not None:
        extra["scale_target_m_s2"] = float(scaling.target)
    if factor is None:
        if scaling.method == "factor":
            factor = scaling.factor
        elif scaling.method == "fema-p695":
            factor = fema_normalisation_factor(record)
        elif scaling.method == "pga":
            factor = scaling.target / record.pga if record.pga > 0 else math.inf
        else:
            sa = spectral_acceleration(record, period=t, damping=scaling.damping)
            extra["sa_unscaled_m_s2"] = sa
            factor = scaling.target / sa if sa > 0 else math.inf
        if not math.isfinite(factor):
            raise RecordError(f"cannot scale a record of zero amplitude to {scaling.describe(t)}",
                              file=record.source or None)
        if scaling.method != "factor" and not 1.0 / SCALE_FACTOR_MAX <= factor <= SCALE_FACTOR_MAX:
            raise RecordError(f"scaling to {scaling.describe(t)} needs a factor of {factor:.3g}, beyond "
                              f"{1.0 / SCALE_FACTOR_MAX:g}-{SCALE_FACTOR_MAX:g}; this record cannot represent that "
                              "target: check the target's units, the period, or choose another record",
                              file=record.source or None)
    metadata = dict(record.metadata, scale_method=scaling.method, scale_description=scaling.describe(t),
                    scale_factor=float(factor), **extra)
    scaled = record.scaled(factor) if factor != 1.0 else record
    return scaled.with_metadata(metadata)   # the samples validated once, not copied again
