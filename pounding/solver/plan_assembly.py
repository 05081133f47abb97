"""A plan model lowered into the solver's arrays: every DOF a solver floor, planes in a banded stiffness block.

The compiled integrator needs no plan-specific code beyond storey rows whose drift is a
weighted sum (:class:`pounding.solver.layout.StoreyTerms`; docs/plan-models.md, "What is
integrated now"):

* every DOF (u_x, u_y, θ of each floor; :mod:`pounding.model.plan_model`'s
  numbering) is a solver *floor* of mass m, m or I = m r²; it has no storey
  spring (stiffness 0, floor below −1);
* the planes are each building's stiffness matrix K = Σ k a aᵀ (virtual work on every
  plane's drift ``a · q``; :meth:`pounding.model.plan_model.PlanBuilding.stiffness_matrix`),
  with P-Delta its geometric stiffness (the three rank-one terms of
  :func:`pounding.model.plan.plan_geometric_terms` per storey) folded in: the solver's
  dense stiffness block, applied as ``K·u`` beside the damping block in the right-hand
  side.  K couples a floor only to the floors above and below, so the block is banded
  (half-bandwidth 5 DOF) and the right-hand side skips the zeros.  Every plane's drift
  ``a · q`` is also a *plane row* (``System.plane_floors``) whose peak |drift| the
  solver records at full resolution; the archive takes the planes' strain energy
  ``½ k (a · q)²`` and the P-Delta potential from the stored states
  (:mod:`pounding.results.plan_dataset`);
* damping is the building's dense damping matrix (Rayleigh at its own 3-D modes, or
  modal), the solver's dense damping block (banded with K under Rayleigh damping);
* the ground acceleration per DOF comes from three ground rows: a_gx (row 0),
  a_gy (row 1) and a zero row (2) for the rotations (the several-ground mechanism);
  every contact takes the zero row on both sides, so no differential
  ground motion enters them: in coordinates relative to one rigid ground the
  penetration of a point is exactly ``w · q − gap``;
* every contact point is a gap element whose two sides are the (u_n, θ) terms of
  its two floors (its penetration weights), the low side on the left;
* with a hysteretic plane or a collapse drift ratio (``solver.stop_drift_ratio``, a
  building's ``collapse``), the planes are also the solver's storey rows
  (:func:`plane_storey_arrays`): a row's drift is its weighted sum ``a · q``
  (:class:`pounding.solver.layout.StoreyTerms`), a yielding plane adds ``F − kΔ`` to
  the stiffness block's ``kΔ`` through the same weights (its state, events, work and error-norm
  entry those of a yielding storey), and every plane's drift ratio is watched.

* a face with ``friction: μ`` is a friction face (:class:`pounding.solver.layout.Friction`): its
  slip terms are the face's slip weights (each side's u_t and θ, the low side on the left), its
  points the face's consecutive contacts.

Refused in one line (:func:`plan_refusal`): friction in a model with an instantaneous contact law
(stereo-mechanical) anywhere, whose stuck contacts are constraints of their own not solved jointly
with the sticking faces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pounding.contact import laws as contact_laws
from pounding.model.model import WALL
from pounding.model.plan import DOF_PER_FLOOR, plan_geometric_terms
from pounding.model.plan_model import PlanModel
from pounding.solver.assembly import hysteresis_arrays, side_mass
from pounding.solver.integrator import System
from pounding.solver.kinematics import SIDE_TERMS
from pounding.solver.tolerances import floor_tolerance_factors

__all__ = ["GROUND_X", "GROUND_Y", "GROUND_NONE", "PlanSystem", "plan_refusal", "plan_system", "plane_storey_arrays",
           "plan_ground_rows", "plan_tolerance_factors"]

#: Ground rows of a plan run: a_gx, a_gy and the zero row (rotations; contacts).
GROUND_X, GROUND_Y, GROUND_NONE = 0, 1, 2


@dataclass(frozen=True)
class PlanSystem:
    """A plan model's solver arrays and what the results need to label them.

    Attributes
    ----------
    system : System
        The contact points are its gap elements (``n_points``), the planes its plane rows.
    n_points, n_planes : int
    plane_stiffness : (n_planes,) N/m
    point_face : (n_points,) int, index of each point's face in ``PlanModel.contacts``
    point_location : (n_points, 2) m, the point at rest
    plane_weights : (n_planes, N) each plane's drift ``a · q`` over all DOF, m per DOF unit
    p_delta_stiffness : (m,) N/m or N·m, the P-Delta terms' k_G (≤ 0; none without P-Delta)
    p_delta_weights : (m, N) their drifts' weights: K_G = Σ k_G a aᵀ
    """

    system: System
    n_points: int
    n_planes: int
    plane_stiffness: np.ndarray
    point_face: np.ndarray
    point_location: np.ndarray
    plane_weights: np.ndarray
    p_delta_stiffness: np.ndarray
    p_delta_weights: np.ndarray


def plan_refusal(model: PlanModel) -> str | None:
    """Why *model* cannot be run yet (one line), or None."""
    if any(c.friction for c in model.contacts) and any(c.law.instantaneous for c in model.contacts):
        return ("friction with an instantaneous contact law (stereo-mechanical) elsewhere in the model is not "
                "supported: its stuck contacts are not solved together with the sticking faces; use a compliant "
                "law such as hertz-damp on every contact")
    return None


def _floor_terms(offset: int, weights: np.ndarray) -> list[tuple[int, float]]:
    """A side's ``(DOF, weight)`` terms from one floor's (3,) weights (the DOF after *offset*), nonzero only."""
    return [(offset + k, float(w)) for k, w in enumerate(weights) if w != 0.0]


def _side(terms: list[tuple[int, float]]) -> list[tuple[int, float]]:
    """Pad a side's terms to SIDE_TERMS/2 with absent terms ``(−1, 0)``."""
    if len(terms) > SIDE_TERMS // 2:
        raise ValueError(f"a side has {len(terms)} terms; the solver takes {SIDE_TERMS // 2}")
    return terms + [(-1, 0.0)] * (SIDE_TERMS // 2 - len(terms))


def _face_sides(contact, offsets: list[int], rows: np.ndarray) -> tuple[list, list]:
    """A face's (2, 3) weight *rows* (its first side's floor, its second's; a point's penetration or the
    face's slip) as the solver's two sides, the low side on the left."""
    first = offsets[contact.first] + DOF_PER_FLOOR * (contact.level_first - 1)
    one = _side(_floor_terms(first, rows[0]))
    if contact.second == WALL:
        two = _side([])
    else:
        two = _side(_floor_terms(offsets[contact.second] + DOF_PER_FLOOR * (contact.level_second - 1), rows[1]))
    return (one, two) if contact.face.first_low else (two, one)


def _drift_sides(offset: int, a: np.ndarray, storey: int) -> tuple[list, list]:
    """A storey drift ``a · q`` (a over one building's DOF) as two sides: the floor above, the floor below."""
    top = DOF_PER_FLOOR * (storey - 1)
    upper = _floor_terms(offset + top, a[top:top + DOF_PER_FLOOR])
    lower = _floor_terms(offset + top - DOF_PER_FLOOR, a[top - DOF_PER_FLOOR:top]) if storey > 1 else []
    return _side(upper), _side(lower)


def _half_bandwidth(*matrices: np.ndarray) -> int:
    """Largest |i − k| of a nonzero entry of any of *matrices* (square, same size; 0 when all are diagonal)."""
    rows, cols = np.nonzero(sum(m != 0.0 for m in matrices))
    return int(np.max(np.abs(rows - cols), initial=0))


def _global(offset: int, a: np.ndarray, n: int) -> np.ndarray:
    """A building's (3n_b,) weights *a* over all *n* DOF (its own from *offset*)."""
    out = np.zeros(n)
    out[offset:offset + a.size] = a
    return out


def plan_system(model: PlanModel) -> PlanSystem:
    """Lower *model* into a :class:`PlanSystem` (call :func:`plan_refusal` first)."""
    mass = np.concatenate([np.diag(b.mass_matrix()) for b in model.buildings]).astype(float)
    n = mass.size
    offsets = model.dof_offsets
    floors, weights, gaps, laws, params = [], [], [], [], []
    point_face, locations = [], []
    for face_index, contact in enumerate(model.contacts):
        for point in contact.points:
            left, right = _face_sides(contact, offsets, point.weights)
            floors.append([f for f, _ in left + right])
            weights.append([w for _, w in left + right])
            gaps.append(contact.gap)
            laws.append(contact.law.law_id)
            params.append(contact.law.kernel_parameters(side_mass(left, mass), side_mass(right, mass)))
            point_face.append(face_index)
            locations.append(point.location)
    n_points = nc = len(gaps)
    planes = [(float(b.storeys[storey - 1].planes[j].stiffness), a, offset, storey)
              for b, offset in zip(model.buildings, offsets) for storey, j, a in b.plane_weights()]
    p_delta = [(k, a, offset) for b, offset in zip(model.buildings, offsets) if b.p_delta
               for _, k, a in plan_geometric_terms(list(b.storeys))]
    rows = plane_storey_arrays(model, [(offset, storey, a) for _, a, offset, storey in planes])
    plane_sides = [_drift_sides(offset, a, storey) for _, a, offset, storey in planes]
    friction = _friction_arrays(model, offsets, point_face)
    floors_arr = np.array(floors, dtype=np.int64).reshape(nc, SIDE_TERMS)
    damping = [np.asarray(b.damping_matrix(), dtype=float) for b in model.buildings]
    stiffness = [np.asarray(b.stiffness_matrix() + b.geometric_stiffness(), dtype=float) for b in model.buildings]
    dense = [c.ravel() for c in damping]
    sizes = [b.n_dof for b in model.buildings]
    floor_ground = np.tile(np.array([GROUND_X, GROUND_Y, GROUND_NONE], dtype=np.int64), n // DOF_PER_FLOOR)
    system = System(
        mass=np.ascontiguousarray(mass), storey_stiffness=np.zeros(n), below=np.full(n, -1, dtype=np.int64),
        rayleigh_mass=np.zeros(n), rayleigh_stiffness=np.zeros(n),
        dense_start=np.asarray(offsets, dtype=np.int64), dense_size=np.asarray(sizes, dtype=np.int64),
        dense_offset=np.asarray(np.cumsum([0] + [s * s for s in sizes])[:-1], dtype=np.int64),
        dense_values=np.ascontiguousarray(np.concatenate(dense) if dense else np.zeros(0)),
        contact_left=floors_arr[:, 0].copy(), contact_right=floors_arr[:, SIDE_TERMS // 2].copy(),
        contact_gap=np.asarray(gaps, dtype=float), contact_law=np.asarray(laws, dtype=np.int64),
        contact_parameters=np.ascontiguousarray(np.array(params, dtype=float).reshape(nc, contact_laws.N_PARAMETERS)),
        contact_floors=np.ascontiguousarray(floors_arr),
        contact_weights=np.ascontiguousarray(np.array(weights, dtype=float).reshape(nc, SIDE_TERMS)),
        floor_ground=floor_ground,
        contact_ground_left=np.full(nc, GROUND_NONE, dtype=np.int64),
        contact_ground_right=np.full(nc, GROUND_NONE, dtype=np.int64),
        dense_band=np.array([_half_bandwidth(c, k) for c, k in zip(damping, stiffness)], dtype=np.int64),
        dense_stiffness=np.ascontiguousarray(np.concatenate([k.ravel() for k in stiffness]) if stiffness
                                             else np.zeros(0)),
        plane_floors=np.array([[f for f, _ in up + low] for up, low in plane_sides], dtype=np.int64).reshape(
            len(planes), SIDE_TERMS),
        plane_weights=np.array([[w for _, w in up + low] for up, low in plane_sides], dtype=float).reshape(
            len(planes), SIDE_TERMS), **rows, **friction)
    return PlanSystem(system, n_points, len(planes), np.array([k for k, *_ in planes], dtype=float),
                      np.asarray(point_face, dtype=np.int64), np.asarray(locations, dtype=float).reshape(n_points, 2),
                      np.array([_global(offset, a, n) for _, a, offset, _ in planes]).reshape(len(planes), n),
                      np.array([k for k, _, _ in p_delta], dtype=float),
                      np.array([_global(offset, a, n) for _, a, offset in p_delta]).reshape(len(p_delta), n))


def _friction_arrays(model: PlanModel, offsets: list[int], point_face: list[int]) -> dict[str, np.ndarray]:
    """The :class:`System` friction fields of *model*'s faces with ``friction`` (μ > 0), or {} without.

    A face's slip terms are its points' (shared) slip weights, the low side first as its contacts'
    sides; *point_face* the face of every contact point, in the solver's contact order.
    """
    floors, weights, coefficient, first, count = [], [], [], [], []
    for face_index, contact in enumerate(model.contacts):
        if not contact.friction:
            continue
        left, right = _face_sides(contact, offsets, contact.points[0].slip)
        floors.append([f for f, _ in left + right])
        weights.append([w for _, w in left + right])
        coefficient.append(float(contact.friction))
        first.append(point_face.index(face_index))
        count.append(point_face.count(face_index))
    if not coefficient:
        return {}
    nf = len(coefficient)
    return dict(friction_floors=np.array(floors, dtype=np.int64).reshape(nf, SIDE_TERMS),
                friction_weights=np.array(weights, dtype=float).reshape(nf, SIDE_TERMS),
                friction_coefficient=np.array(coefficient, dtype=float),
                friction_first_point=np.array(first, dtype=np.int64), friction_point_count=np.array(count, dtype=np.int64))


def plane_storey_arrays(model: PlanModel, drifts: list[tuple[int, int, np.ndarray]]) -> dict[str, np.ndarray]:
    """The :class:`System` storey fields of *model*'s planes as storey rows, or {} when no plane yields and
    no building has a collapse drift ratio (the planes are then their links alone).

    *drifts*: ``(DOF offset of the building, storey, a)`` per plane in the archive's plane order.  Row p
    is plane p: its hysteresis kernel and parameters (at the plane's stiffness and storey height),
    state index (−1: elastic), height, its building's collapse drift ratio (0: none), drift terms
    (:func:`_drift_sides`, the floor above then the floor below) and stiffness; ``p_delta_stiffness``
    stays per solver floor and zero (the plan model's P-Delta terms are in its stiffness block).
    """
    planes = [(b, ratio, s.height, p) for b, ratio in zip(model.buildings, model.collapse_drift_ratios())
              for s in b.storeys for p in s.planes]
    if not any(p.hysteresis is not None or ratio for _, ratio, _, p in planes):
        return {}
    floors, weights = [], []
    for offset, storey, a in drifts:
        upper, lower = _drift_sides(offset, a, storey)
        floors.append([f for f, _ in upper + lower])
        weights.append([w for _, w in upper + lower])
    count = len(planes)
    return dict(
        **hysteresis_arrays([(p.hysteresis, p.stiffness, height) for _, _, height, p in planes]),
        p_delta_stiffness=np.zeros(model.n_dof),  # per solver floor; the plan's P-Delta terms are links
        storey_height=np.array([h for _, _, h, _ in planes], dtype=float),
        storey_stop_ratio=np.array([float(ratio or 0.0) for _, ratio, _, _ in planes]),
        storey_floors=np.array(floors, dtype=np.int64).reshape(count, SIDE_TERMS),
        storey_weights=np.array(weights, dtype=float).reshape(count, SIDE_TERMS),
        storey_row_stiffness=np.array([float(p.stiffness) for _, _, _, p in planes]))


def plan_ground_rows(a_gx: np.ndarray, a_gy: np.ndarray) -> np.ndarray:
    """(3, ns) ground rows of a plan run from the global components (m/s²): a_gx, a_gy, zeros."""
    a_gx = np.asarray(a_gx, dtype=float)
    return np.ascontiguousarray(np.stack([a_gx, np.asarray(a_gy, dtype=float), np.zeros_like(a_gx)]))


def plan_tolerance_factors(model: PlanModel, peak_ground_acceleration: float, atol: float) -> np.ndarray:
    """(N,) factors on atol per DOF: translations at the building's static scale
    (:func:`pounding.solver.tolerances.floor_tolerance_factors`, with a storey's total plane
    stiffness), rotations further over the floor's radius of gyration (atol/r rad, r ≥ 1 m)."""
    factors = []
    for b in model.buildings:
        mass = np.repeat([s.mass for s in b.storeys], DOF_PER_FLOOR)
        stiffness = np.repeat([sum(float(p.stiffness) for p in s.planes) for s in b.storeys], DOF_PER_FLOOR)
        below = np.r_[-1, np.arange(b.n_dof - 1)]
        own = floor_tolerance_factors(mass, stiffness, below, peak_ground_acceleration, atol)
        own[2::DOF_PER_FLOOR] *= np.minimum(1.0, 1.0 / np.array([s.radius_of_gyration for s in b.storeys]))
        factors.append(own)
    return np.concatenate(factors) if factors else np.zeros(0)
