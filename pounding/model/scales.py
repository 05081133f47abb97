"""Time scales of a model and the work a run will take, estimated before anything is solved.

The integrator is an explicit Runge-Kutta method (Dormand-Prince): its step
cannot exceed about :data:`STABILITY` / λ, λ the largest rate of the system
(rad/s or 1/s).  A model with one very fast element therefore takes
``end_time · λ / STABILITY`` steps, however smooth its response: a Maxwell
link with c/k = 1e-9 s takes ~2e9 steps (hours) for 8 s of record.  The rates
are bounded from the data without an eigensolver (Gershgorin bounds, valid
for any number of storeys):

* a building: ``ω_max² ≤ max_i 2 (k_i + k_i+1) / m_i``; its Rayleigh damping
  adds the rates ``a0`` and ``a1 ω_max²``;
* a link between floors of masses m_L and m_R (``1/m = 1/m_L + 1/m_R``):
  viscous ``c/m``; Kelvin ``c/m`` and ``√(k/m)``; Maxwell ``k/c`` (the
  inverse relaxation time) and ``√(k/m)``.

Contacts are stiff only while they touch, which the event handling takes
care of; they are not counted here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["STABILITY", "MAX_SOLVER_STEPS", "TimeScale", "stiffest_time_scale", "shortest_period", "check_work"]

#: Stability limit of Dormand-Prince 5(4) on the negative real axis, |h·λ| (Hairer & Wanner, fig. IV.2.1).
STABILITY = 3.3
#: Steps a run may be expected to take; measured ~1 µs per step on a 5-floor pair, so 1e8 steps is
#: minutes for a small model and far longer for a large one.  A shipped model takes 1e3-1e5.
MAX_SOLVER_STEPS = 1e8


@dataclass(frozen=True)
class TimeScale:
    """The fastest rate of one element.

    Attributes
    ----------
    rate : float
        1/s (or rad/s).
    what : str
        The element, e.g. ``maxwell link A:2-B:2``.
    kind : str
        ``structure``, ``rayleigh``, ``viscous``, ``spring`` or ``relaxation``.
    """

    rate: float
    what: str
    kind: str

    @property
    def seconds(self) -> float:
        """The time scale 1/rate, s."""
        return 1.0 / self.rate if self.rate > 0 else math.inf


def _building_rate(building) -> float:
    """Gershgorin bound of ω_max of a shear building, rad/s (P-Delta only lowers it)."""
    k = np.abs(np.asarray(building.stiffness, dtype=float))
    above = np.append(k[1:], 0.0)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        bound = np.max(2.0 * (k + above) / np.asarray(building.mass, dtype=float))
    return float(math.sqrt(bound)) if np.isfinite(bound) else math.inf


def shortest_period(model) -> float:
    """A lower bound of the shortest natural period of the model's buildings, s (within a factor √2)."""
    rate = max(_building_rate(b) for b in model.buildings)
    return 2.0 * math.pi / rate if rate > 0 else math.inf


def _scales(model) -> list[TimeScale]:
    found = []
    for building in model.buildings:
        omega = _building_rate(building)
        found.append(TimeScale(omega, f"building {building.name}", "structure"))
        if building.damping.kind == "rayleigh" and math.isfinite(omega):
            a0, a1 = building.rayleigh_coefficients
            found.append(TimeScale(max(a0, a1 * omega ** 2), f"building {building.name} (Rayleigh damping)",
                                   "rayleigh"))
    names = [b.name for b in model.buildings]
    for link in model.links:
        left, right = model.buildings[link.left], model.buildings[link.right]
        inverse_mass = 1.0 / float(left.mass[link.level_left - 1]) + 1.0 / float(right.mass[link.level_right - 1])
        k = float(getattr(link.law, "stiffness", 0.0))
        c = float(getattr(link.law, "damping", 0.0))
        what = f"{link.law.name} link {names[link.left]}:{link.level_left}-{names[link.right]}:{link.level_right}"
        if link.law.name == "maxwell":
            found.append(TimeScale(k / c, what, "relaxation"))
        else:
            found.append(TimeScale(c * inverse_mass, f"{what} (c = {c:.3g} N s/m)", "viscous"))
        if k > 0:
            found.append(TimeScale(math.sqrt(k * inverse_mass), f"{what} (k = {k:.3g} N/m)", "spring"))
    return found


def stiffest_time_scale(model) -> TimeScale:
    """The fastest rate of the model's buildings and links (:class:`TimeScale`)."""
    return max(_scales(model), key=lambda s: s.rate)


def check_work(model, end_time: float, *, where: str = "") -> float:
    """Estimate the solver steps of a run of *end_time* s and refuse beyond :data:`MAX_SOLVER_STEPS`.

    Returns
    -------
    float
        The estimated number of steps.

    Raises
    ------
    ModelError
        One line with the element, its time scale, the shortest period, the
        estimated steps and the fix.
    """
    from pounding.errors import ModelError

    fastest = stiffest_time_scale(model)
    steps = end_time * fastest.rate / STABILITY
    if steps <= MAX_SOLVER_STEPS:
        return steps
    period = shortest_period(model)
    tau = fastest.seconds
    ratio = period / tau if math.isfinite(period) and tau > 0 else math.inf
    shorter = (f"shortest period {period:.3g} s" if fastest.kind == "structure" else
               f"{ratio:.2g} times shorter than the shortest period {period:.3g} s")
    fixes = {
        "relaxation": f"relaxation time c/k = {tau:.3g} s is {shorter}: model it as a viscous link "
                      "(law: viscous, the same damping) or give the brace its real stiffness",
        "viscous": f"relaxes the floors' relative motion in m/c = {tau:.3g} s, {shorter}: the floors move "
                   "together; lower the damping, or model the joined floors as one building",
        "spring": f"its spring makes a period of {2 * math.pi * tau:.3g} s, {shorter}: lower its stiffness "
                  "(a rigid connection is one building)",
        "structure": f"storey stiffness over floor mass gives a {shorter}; check the units of mass (kg) and "
                     "stiffness (N/m)",
        "rayleigh": f"its stiffness-proportional damping acts in {tau:.3g} s, {shorter}: use modal damping or "
                    "damp lower modes",
    }
    raise ModelError(f"{where}{fastest.what}: {fixes[fastest.kind]}; the solver would take about {steps:.2g} "
                     f"steps for {end_time:g} s (at most {MAX_SOLVER_STEPS:.0e} allowed)")
