"""μ_T of a building for FEMA P695 (§6.3): its pushover, or for floors in plan its pushover along each axis.

A planar building is pushed as it is (:func:`pounding.studies.pushover.pushover_building`, FEMA P695
§6.3 quantities by :func:`pounding.studies.pushover.fema_p695_quantities`).  A building in plan is pushed
along each of its axes x and y as a **torsion-free shear chain**: the load at the floors' centres of mass
along the axis, the floors held against rotation, so every plane of a storey along the axis takes the
storey's drift and the planes act in parallel (storey stiffness Σk, the same floor masses and storey
heights, P-Delta as the building's).  Planes in parallel make one storey spring when they are elastic,
when the storey has one plane along the axis, or when they share one yielding law whose forces scale with
the stiffness (given by ``yield_drift_ratio``: F_p(Δ) = k_p f(Δ), so Σ F_p = (Σ k_p) f(Δ)); any other
storey is refused in one line.  μ_T is the smaller of the two axes' (the smaller spectral shape factor:
the conservative one), and the axis is reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pounding.errors import PoundingError

__all__ = ["Ductility", "axis_chains", "building_ductility"]


@dataclass(frozen=True)
class Ductility:
    """The period-based ductility μ_T of a building (FEMA P695 eq. 6-6) and how it was found.

    Attributes
    ----------
    mu : float
        μ_T = δ_u / δ_y,eff; a lower bound (the roof displacement at the pushover's end over δ_y,eff) when
        the pushover ended before a 20 % loss of strength.
    lower_bound : bool
        True for such a lower bound.
    axis : str
        The axis pushed (``x``; for floors in plan the axis of the smaller μ_T).
    """

    mu: float
    lower_bound: bool
    axis: str


def _storey_law(building, storey: int, planes: list) -> object | None:
    """The one yielding law of a storey's *planes* along an axis in parallel (None: elastic), or a one-line refusal."""
    laws = [p.hysteresis for p in planes if p.hysteresis is not None]
    if not laws:
        return None
    if len(planes) == 1:
        return laws[0]
    scalable = all(getattr(law, "yield_force", None) is None and
                   getattr(getattr(law, "negative", None), "yield_force", None) is None for law in laws)
    if len(laws) == len(planes) and scalable and all(law.model_dump() == laws[0].model_dump() for law in laws):
        return laws[0]
    raise PoundingError(f"building {building.name}, storey {storey}: its planes along {planes[0].direction} have "
                        "different yielding laws (or one with yield_force in N); the pushover of a building in plan "
                        "puts each storey's planes along an axis in parallel as one storey spring, which needs them "
                        "elastic, a single plane, or one law given by yield_drift_ratio")


def axis_chains(building) -> dict[str, object]:
    """The shear chain(s) a building's pushover pushes: ``{"x": building}`` for a planar building; for floors in
    plan ``{"x": chain, "y": chain}``, each a planar :class:`pounding.model.building.Building` (module docstring)."""
    from pounding.model.building import Building, Damping

    if not building.in_plan:
        return {"x": building}
    chains = {}
    for axis in ("x", "y"):
        stiffness, laws = [], []
        for i, storey in enumerate(building.storeys):
            planes = [p for p in storey.planes if p.direction == axis]
            if not planes:
                raise PoundingError(f"building {building.name}, storey {i + 1}: no plane resists {axis}; its "
                                    "pushover along that axis has no resistance")
            stiffness.append(sum(float(p.stiffness) for p in planes))
            laws.append(_storey_law(building, i + 1, planes))
        chains[axis] = Building.shear(f"{building.name}-{axis}", building.mass, stiffness, building.height,
                                      Damping("modal", modal_ratios=(0.05,)), laws, p_delta=building.p_delta)
    return chains


def building_ductility(building, *, pattern: str, period: float, drift_limit: float | None) -> Ductility:
    """μ_T of *building* (module docstring): the pushover of each of its chains with *pattern*, T of eq. 6-7 =
    max(*period*, the chain's T1), up to *drift_limit* (a storey drift ratio; None: the pushover's default)."""
    from pounding.studies.pushover import DEFAULT_DRIFT_LIMIT, fema_p695_quantities, pushover_building

    found = []
    for axis, chain in axis_chains(building).items():
        curve = pushover_building(chain, pattern, drift_limit_ratio=float(drift_limit or DEFAULT_DRIFT_LIMIT))
        quantities = fema_p695_quantities(chain, curve, period=period)
        mu, bound = float(quantities["ductility"]), False
        if not math.isfinite(mu):   # no 20 % strength loss before the end: a lower bound
            roof = np.asarray(curve["roof_displacement"], dtype=float)
            mu, bound = float(roof[np.isfinite(roof)][-1]) / float(quantities["yield_roof"]), True
        found.append(Ductility(mu, bound, axis))
    return min(found, key=lambda d: d.mu)
