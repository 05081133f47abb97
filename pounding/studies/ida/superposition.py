"""Runs of a linear building in an IDA: one run of the unscaled record, scaled to every factor.

An IDA runs each template (a variant and a record) at many scale factors.  In the variant without
contacts each building runs alone (:func:`pounding.studies.ida.runs.buildings_alone`).  A building
whose equations of motion are linear with constant coefficients
(:attr:`pounding.solver.integrator.System.responds_linearly`: linear elastic storeys without P-Delta
or collapse limit, no gap, wall, link or friction face) starts from rest, so by superposition its
response to the record scaled by λ is λ times its response to the record itself.  Its peak drift
ratios (of storeys and, in plan, of planes) and residual drift ratios at factor λ are λ times those
of one *unit run* (the factor 1: the record as stored, or both components of a pair), and the run
completes: one solver run per worker, template and building gives every stripe.

Accuracy.  The unit run is made with ``rtol``, ``atol`` and ``atol_velocity`` over
:data:`UNIT_TIGHTENING`, so λ times its error, ``λ·atol/10 + rtol/10·|u_λ|``, is within a direct
run's own ``atol + rtol·|u_λ|`` for every λ up to :data:`UNIT_TIGHTENING`; a larger factor, and a
unit run that did not complete (``energy_inconsistent``), are run directly.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from pounding.recently_used import RecentlyUsed

__all__ = ["UNIT_TIGHTENING", "SCALED", "unit_factor", "superposed_peaks", "scaled_peaks", "unit_result",
           "tightened"]

#: The unit run's tolerances are the model's over this; factors above it are run directly.
UNIT_TIGHTENING = 10.0
#: What scales with the factor (signed values: a positive factor keeps their sign).
SCALED = ("peak_drift_ratio", "residual_drift_ratio", "peak_plane_drift_ratio")

#: This worker's unit results by ``(what, template key)`` (:func:`unit_result`): a building's peaks, a risk
#: study's separations (None: not linear, or the unit run did not complete).  A handful of templates are in
#: flight at once on a worker.
_UNIT_RUNS: RecentlyUsed[dict | None] = RecentlyUsed(16)


def _plain_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def unit_factor(document: dict[str, Any]) -> tuple[float | None, dict[str, Any] | None]:
    """``(factor, unit document)``: the one plain factor a run's *document* scales its record by (one record:
    ``ground_motion.scale``; a pair: ``x.scale`` and ``y.scale``, equal, with no scale of its own) and the
    document with that factor 1; ``(None, None)`` for anything else (a target, components scaled apart)."""
    motion = document.get("ground_motion") if isinstance(document, dict) else None
    if not isinstance(motion, dict):
        return None, None
    if "x" not in motion and "y" not in motion:
        scale = motion.get("scale")
        return (float(scale), dict(document, ground_motion=dict(motion, scale=1.0))) if _plain_number(scale) \
            else (None, None)
    x, y = motion.get("x"), motion.get("y")
    if not (isinstance(x, dict) and isinstance(y, dict)) or "scale" in motion:
        return None, None
    sx, sy = x.get("scale"), y.get("scale")
    if not (_plain_number(sx) and _plain_number(sy) and sx == sy):
        return None, None
    return float(sx), dict(document, ground_motion=dict(motion, x=dict(x, scale=1.0), y=dict(y, scale=1.0)))


def superposed_peaks(key: str, model: Callable[[], Any], scale: float) -> dict[str, Any] | None:
    """The peaks of a building alone at factor *scale*, by superposition from its unit run (*key*: the
    template's and the building's, *model*: its unit model, validated on the first call); None where they are
    not given so (the caller runs it): a factor outside ``(0, UNIT_TIGHTENING]``, a building that does not
    respond linearly, a unit run that did not complete."""
    if not 0.0 < scale <= UNIT_TIGHTENING:
        return None
    unit = unit_result(("peaks", key), lambda: _unit_run(model()))
    return None if unit is None else scaled_peaks(unit, scale)


def unit_result(key: Any, compute: Callable[[], Any]) -> Any:
    """This worker's unit result under *key* (``(what, template key)``), computed by *compute* the first time."""
    return _UNIT_RUNS.get(key, compute)


def tightened(model):
    """*model* with ``rtol``, ``atol`` and ``atol_velocity`` over :data:`UNIT_TIGHTENING` (a unit run's)."""
    solver = model.solver
    return model.with_solver(rtol=solver.rtol / UNIT_TIGHTENING, atol=solver.atol / UNIT_TIGHTENING,
                             atol_velocity=solver.atol_velocity / UNIT_TIGHTENING)


def _unit_run(model) -> dict[str, Any] | None:
    """The peaks of the unit *model* (its record as stored) at tolerances :data:`UNIT_TIGHTENING` times
    tighter; None if it does not respond linearly or the run did not complete."""
    from pounding.simulation import responds_linearly, simulate_peaks

    if not responds_linearly(model):
        return None
    peaks = simulate_peaks(tightened(model))
    return peaks if peaks["status"] == "completed" else None


def scaled_peaks(unit: dict[str, Any], scale: float) -> dict[str, Any]:
    """The unit run's peaks *unit* at factor *scale* > 0: the drift ratios (:data:`SCALED`) and the factor on
    the record as stored times *scale*, no solver time (``wall_time`` 0), everything else the unit run's."""
    out = dict(unit, record_scale=float(unit["record_scale"]) * scale, wall_time=0.0)
    for name in SCALED:
        if name in unit:
            out[name] = np.asarray(unit[name], dtype=float) * scale
    return out
