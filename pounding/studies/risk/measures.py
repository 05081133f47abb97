"""The intensity measures of ``pounding risk``: ``pga``, ``sa:T`` and ``sa-avg:T1,T2``, on the IDA's plan.

``sa:T`` is the 5 %-damped pseudo-spectral acceleration at a period T given outright (a site's hazard
curve is computed at a fixed period, not at a building's); ``sa-avg:T1,T2`` the geometric mean of Sa at
:data:`AVG_PERIODS` periods evenly spaced in ln T from T1 to T2 (the average spectral acceleration of
Eads, Miranda & Lignos 2015, "Average spectral acceleration as an intensity measure for collapse risk
assessment", Earthquake Engng Struct. Dyn. 44, which uses the same geometric mean over a period range).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pounding.errors import PoundingError
from pounding.studies.ida.schedule import SA_DAMPING, IntensityMeasure, ground_records, resolve_scaling

__all__ = ["RiskMeasure", "parse_risk_im", "with_measure", "AVG_PERIODS"]

#: Periods of Sa_avg between T1 and T2 (both included).
AVG_PERIODS = 10


@dataclasses.dataclass(frozen=True)
class RiskMeasure(IntensityMeasure):
    """An IM of :mod:`pounding.studies.ida.schedule` at periods given outright (s): one (``sa``) or a range
    (``sa-avg``, :data:`AVG_PERIODS` periods geometrically spaced, the geometric mean of their Sa)."""

    periods: tuple[float, ...] = ()

    def of(self, record) -> float:
        """The IM of a record, m/s²."""
        from pounding.records.spectra import spectral_acceleration

        values = [spectral_acceleration(record, period=t, damping=SA_DAMPING) for t in self.periods]
        return float(math.exp(np.mean(np.log(values))))

    def describe(self) -> str:
        mean = ", geometric mean of the pair" if self.pair else ""
        if len(self.periods) == 1:
            return f"Sa(T = {self.periods[0]:.3g} s, 5 %{mean})"
        return (f"Sa_avg(T = {self.periods[0]:.3g}-{self.periods[-1]:.3g} s, geometric mean of {len(self.periods)} "
                f"periods, 5 %{mean})")


def _periods(text: str, what: str) -> list[float]:
    try:
        values = [float(p) for p in text.split(",")]
    except ValueError:
        raise PoundingError(f"{what}: periods must be numbers in s, e.g. sa:1.0 or sa-avg:0.2,3.0") from None
    if not all(math.isfinite(t) and 0 < t <= 10 for t in values):
        raise PoundingError(f"{what}: periods must be in (0, 10] s")
    return values


def parse_risk_im(text: str | None) -> tuple[str, tuple[float, ...]]:
    """``--im``: ``pga``, ``sa-t1`` (Sa at the first building's T1), ``sa:T`` or ``sa-avg:T1,T2``:
    (the IDA's IM name, the periods, s: none for pga and sa-t1)."""
    raw = (text or "sa-t1").strip().lower()
    what = f"--im {text!r}"
    if raw in ("pga", "sa-t1"):
        return raw, ()
    if raw.startswith("sa:"):
        values = _periods(raw[3:], what)
        if len(values) != 1:
            raise PoundingError(f"{what}: sa:T takes one period, e.g. sa:1.0")
        return "sa", tuple(values)
    if raw.startswith("sa-avg:"):
        values = _periods(raw[7:], what)
        if len(values) != 2 or not values[0] < values[1]:
            raise PoundingError(f"{what}: sa-avg:T1,T2 takes two periods T1 < T2, e.g. sa-avg:0.2,3.0")
        return "sa-avg", tuple(np.geomspace(values[0], values[1], AVG_PERIODS))
    raise PoundingError(f"{what}: choose pga, sa-t1, sa:T (e.g. sa:1.0) or sa-avg:T1,T2 (e.g. sa-avg:0.2,3.0); "
                        "it must be the IM of the hazard curve")


def with_measure(plan, name: str, periods: tuple[float, ...]):
    """The IDA *plan* (built with ``sa-t1``) measured instead by Sa at *periods*: every record's IM as stored,
    its scaling and factors recomputed (:func:`pounding.studies.ida.schedule.resolve_scaling`)."""
    from pounding.model.model import model_from_data

    measure = RiskMeasure(name, plan.im.building, float(periods[0]), pair=plan.im.pair, periods=tuple(periods))
    stored, errors = [], list(plan.errors)
    for r, document in enumerate(plan.documents):
        if errors[r] is not None:
            stored.append(float("nan"))
            continue
        model = model_from_data(document, name=plan.model_name, base_dir=plan.sweep.base_dir)
        stored.append(measure.of_records(ground_records(model)))
    im_stored = np.array(stored)
    fema = plan.scaling == "fema-p695"
    normalisation = plan.normalisation if fema else np.full(im_stored.shape, np.nan)
    scaling, normalisation, unit = resolve_scaling(plan.scaling, im_stored, normalisation, errors)
    plan.im, plan.im_stored, plan.normalisation, plan.unit_factor, plan.scaling = \
        measure, im_stored, normalisation, unit, scaling
    return plan
