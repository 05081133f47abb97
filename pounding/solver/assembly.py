"""A model flattened into the solver's arrays: :func:`assemble` builds the :class:`Assembly`.

This is the one place that reads a :class:`~pounding.model.model.Model` for the solver,
whatever its buildings' floors (docs/architecture.md).  Every degree of freedom of every
building is a solver *floor* (its mass: kg, or kg·m² for a rotation), building after
building, floor after floor, the floor's DOF in order (u_x; or u_x, u_y, θ in plan).  The
description decides how each part is stored, not the kind of model:

* a building whose floors have one DOF and whose storeys each have one plane along x is a
  chain of storey springs: stored tridiagonally (``storey_stiffness`` and ``below`` per
  floor; Rayleigh damping per floor, or a dense modal block) — cost linear in the storeys;
* any other building's planes go into its stiffness matrix K = Σ k a aᵀ (virtual work on
  every plane's drift ``a · q``), with P-Delta's rank-one terms folded in, applied as a
  dense banded block beside its damping block (Rayleigh at its own modes, or modal); each
  plane is then also a *plane row* (its drift recorded at full resolution) and, when a
  plane yields or the building has a collapse drift ratio, a *storey row* whose drift is the
  weighted sum ``a · q`` (:class:`pounding.solver.layout.StoreyTerms`);
* every contact point is a gap element whose two sides are weighted floor terms
  (:func:`side_terms`): a floor's displacement along the contact normal at the point (u_x of
  a one-DOF floor; u_n and θ·lever of a floor in plan), or a point of a column (the Hermite
  shape functions on the floors below and above); the low side on the left;
* links follow the contact points, a face with ``friction: μ`` is a friction face
  (:class:`pounding.solver.layout.Friction`);
* each degree of freedom takes the ground row of its building along its direction (a
  rotation: the zero row), each contact side its building's row along the contact normal
  (a wall: the row of the building it faces): :class:`GroundRows`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding import hysteresis
from pounding.contact import laws as contact_laws
from pounding.model.floors import PLANAR_DOFS, geometric_terms, point_weights
from pounding.model.model import WALL, Model, column_weights
from pounding.solver import imk
from pounding.solver.integrator import System
from pounding.solver.kinematics import SIDE_TERMS
from pounding.solver.tolerances import floor_tolerance_factors

__all__ = ["Assembly", "GroundRows", "assemble", "is_chain", "building_arrays", "storey_arrays", "hysteresis_arrays",
           "storey_stop_ratios", "element_arrays", "side_terms", "contact_side_terms", "side_mass",
           "tolerance_factors", "refusal", "xy_ground"]


@dataclass(frozen=True)
class GroundRows:
    """Which row of the ground-acceleration array moves each building.

    Attributes
    ----------
    x : tuple of int
        Per building, the row of its ground acceleration along x.
    y : tuple of int
        Per building, along y (two horizontal components); empty: one component.
    zero : int
        A row of zeros (the rotations' ground), −1 when there is none.
    """

    x: tuple[int, ...]
    y: tuple[int, ...] = ()
    zero: int = -1

    def of(self, building: int, direction: str) -> int:
        """The row of *building*'s ground along *direction* (``x``, ``y``; anything else: the zero row)."""
        if direction == "x":
            return self.x[building]
        if direction == "y" and self.y:
            return self.y[building]
        return self.zero


@dataclass(frozen=True)
class Assembly:
    """The solver's arrays of a model and what the results need to read them.

    Attributes
    ----------
    system : System
    n_points : int
        Contact points (the gap elements; the links follow them in the system's contacts).
    chain : bool
        True if every building is a chain of storey springs (one row per floor, drift ``u_j − u_below``);
        False: the planes are rows with weights (``plane_weights``).
    plane_stiffness : (R,) N/m
        Elastic stiffness of each plane row (empty for a chain).
    plane_weights : (R, N)
        Each plane's drift ``a · q`` over all degrees of freedom (empty for a chain).
    p_delta_stiffness, p_delta_weights : (m,) and (m, N)
        The P-Delta terms folded into the dense stiffness blocks: K_G = Σ k_G a aᵀ (none for a chain).
    """

    system: System
    n_points: int
    chain: bool
    plane_stiffness: np.ndarray
    plane_weights: np.ndarray
    p_delta_stiffness: np.ndarray
    p_delta_weights: np.ndarray


def is_chain(building: Any) -> bool:
    """True if *building* is a chain of storey springs: floors of one DOF, one plane along x per storey, a fixed
    base (a founded building's storey deformations also involve its base mat's rocking: weighted rows)."""
    return building.dofs_per_floor == PLANAR_DOFS and getattr(building, "foundation", None) is None and \
        all(len(s.planes) == 1 and s.planes[0].direction == "x" for s in building.storeys)


def refusal(model: Model) -> str | None:
    """Why *model* cannot be assembled (one line), or None."""
    faces = getattr(model, "faces", ())
    if any(f.friction for f in faces) and any(g.law.instantaneous for g in model.gaps):
        return ("friction with an instantaneous contact law (stereo-mechanical) elsewhere in the model is not "
                "supported: its stuck contacts are not solved together with the sticking faces; use a compliant "
                "law such as hertz-damp on every contact")
    return None


# --------------------------------------------------------------------------- #
# Buildings: masses, stiffness, damping
# --------------------------------------------------------------------------- #


def _half_bandwidth(*matrices: np.ndarray) -> int:
    """Largest |i − k| of a nonzero entry of any of *matrices* (square, same size; 0 when all are diagonal)."""
    rows, cols = np.nonzero(sum(m != 0.0 for m in matrices))
    return int(np.max(np.abs(rows - cols), initial=0))


def building_arrays(model: Model) -> dict[str, np.ndarray]:
    """Masses, storey springs, the floor below (−1: ground or none) and damping of every degree of freedom.

    A chain building's Rayleigh damping stays per floor (``a0·M + a1·K`` acts storey by storey),
    its modal damping one dense block; any other building has a dense damping block and a
    dense stiffness block (its planes and P-Delta), banded.  In a model where any building is not
    a chain, every building is stored the second way (the planes are rows for all of them).  A
    founded building's block spans its floors and its base mat's sway and rocking
    (:mod:`pounding.model.foundation`).
    """
    all_chain = all(is_chain(b) for b in model.buildings)
    masses, stiffness, below, a0, a1 = [], [], [], [], []
    dense_start, dense_size, dense_offset, dense_values, dense_band, dense_stiffness = [], [], [], [], [], []
    offset = used = 0
    for building in model.buildings:
        n = building.n_model_dof
        chain = all_chain
        masses.append(building.model_mass)
        stiffness.append(building.stiffness if chain else np.zeros(n))
        below.append(np.r_[-1, np.arange(offset, offset + n - 1)] if chain else np.full(n, -1))
        dense_start.append(offset)
        dense_offset.append(used)
        rayleigh = chain and building.damping.kind == "rayleigh"
        c_mass, c_stiff = building.rayleigh_coefficients if rayleigh else (0.0, 0.0)
        a0.append(np.full(n, c_mass) if rayleigh else np.zeros(n))
        a1.append(c_stiff * _tangent_ratios(building) if rayleigh else np.zeros(n))
        dense_size.append(0 if rayleigh else n)
        if not rayleigh:
            damping = np.asarray(building.model_damping_matrix(), dtype=float)
            # The springs act with their elastic stiffness (a yielding plane's row adds F − kΔ); damping is on the
            # initial tangent (the building's damping matrix).  P-Delta is refused on a founded building.
            k = (np.zeros((n, n)) if chain else np.asarray(building.model_stiffness_matrix(initial=False), dtype=float)
                 + (building.geometric_stiffness() if building.foundation is None else 0.0))
            dense_values.append(damping.ravel())
            dense_stiffness.append(k.ravel())
            dense_band.append(n - 1 if chain else _half_bandwidth(damping, k))
            used += n * n
        offset += n
    arrays = dict(
        mass=np.ascontiguousarray(np.concatenate(masses), dtype=float),
        storey_stiffness=np.ascontiguousarray(np.concatenate(stiffness), dtype=float),
        below=np.ascontiguousarray(np.concatenate(below), dtype=np.int64),
        rayleigh_mass=np.ascontiguousarray(np.concatenate(a0), dtype=float),
        rayleigh_stiffness=np.ascontiguousarray(np.concatenate(a1), dtype=float),
        dense_start=np.asarray(dense_start, dtype=np.int64),
        dense_size=np.asarray(dense_size, dtype=np.int64),
        dense_offset=np.asarray(dense_offset, dtype=np.int64),
        dense_values=np.ascontiguousarray(np.concatenate(dense_values) if dense_values else np.zeros(0)),
    )
    if not all_chain:
        # Blocks of every building (a chain's modal block carries a zero stiffness: its springs are per floor).
        arrays["dense_band"] = _bands(dense_size, dense_band)
        arrays["dense_stiffness"] = np.ascontiguousarray(np.concatenate(dense_stiffness) if dense_stiffness
                                                         else np.zeros(0))
    return arrays


def _tangent_ratios(building: Any) -> np.ndarray:
    """(n,) each storey's tangent stiffness at rest over its elastic stiffness: 1 exactly, but for a Bouc–Wen
    storey with A ≠ 1, so that the chain's Rayleigh term ``a1·k`` acts on the initial tangent as the damping
    matrix does (docs/physics.md §7)."""
    return np.array([1.0 if p.hysteresis is None or p.initial_stiffness == float(p.stiffness)
                     else p.initial_stiffness / float(p.stiffness) for s in building.storeys for p in s.planes])


def _bands(sizes: list[int], bands: list[int]) -> np.ndarray:
    """Each block's half-bandwidth (size 0 blocks: −1), the blocks in building order."""
    found = iter(bands)
    return np.array([next(found) if size else -1 for size in sizes], dtype=np.int64)


def storey_stop_ratios(model: Model) -> np.ndarray:
    """(N,) each storey's collapse drift ratio: its building's (:meth:`Model.collapse_drift_ratios`), 0: none."""
    return np.ascontiguousarray(np.concatenate(
        [np.full(b.n_floors, float(ratio or 0.0)) for b, ratio in zip(model.buildings, model.collapse_drift_ratios())]))


def hysteresis_arrays(laws: list[tuple[Any, float, float]]) -> dict[str, np.ndarray]:
    """``storey_model``, ``storey_parameters``, ``storey_state`` and ``storey_imk`` of storey rows given as
    ``(hysteresis or None, stiffness N/m, height m)``: the kernel id and vector of each row, the yielding
    rows numbered in order (−1: elastic), and each IMK row's initial discrete state (zeros for the others)."""
    models, parameters, discrete = [], [], []
    for law, k, h in laws:
        models.append(hysteresis.MODEL_ELASTIC if law is None else law.model_id)
        parameters.append(np.zeros(hysteresis.N_HYSTERESIS_PARAMETERS) if law is None
                          else law.kernel_parameters(k, h))
        if law is not None:
            discrete.append(imk.initial_state(law, k, h) if isinstance(law, hysteresis.ImkStorey)
                            else np.zeros(imk.N_STATE))
    yielding = np.asarray(models, dtype=np.int64) != hysteresis.MODEL_ELASTIC
    return dict(
        storey_model=np.asarray(models, dtype=np.int64),
        storey_parameters=np.ascontiguousarray(np.array(parameters, dtype=float)
                                               .reshape(len(models), hysteresis.N_HYSTERESIS_PARAMETERS)),
        storey_state=np.where(yielding, np.cumsum(yielding) - 1, -1).astype(np.int64),
        storey_imk=np.array(discrete, dtype=float).reshape(len(discrete), imk.N_STATE),
    )


def storey_arrays(model: Model) -> dict[str, Any]:
    """A chain model's storey rows, one per floor: hysteresis kernel id and parameters, height (m), P-Delta
    stiffness (N/m) and collapse drift ratio.

    ``storey_state`` numbers the yielding storeys (their hysteretic states in the
    solver's state vector), −1 for an elastic storey; ``storey_imk`` holds the
    initial discrete state of each IMK storey among them (:mod:`pounding.solver.imk`).
    """
    heights, p_delta, laws = [], [], []
    for building in model.buildings:
        laws += list(zip(building.hysteresis, building.stiffness, building.height))
        heights.append(building.height)
        p_delta.append(building.p_delta_stiffness)
    return dict(
        **hysteresis_arrays(laws),
        p_delta_stiffness=np.ascontiguousarray(np.concatenate(p_delta), dtype=float),
        storey_height=np.ascontiguousarray(np.concatenate(heights), dtype=float),
        storey_stop_ratio=storey_stop_ratios(model),
    )


# --------------------------------------------------------------------------- #
# Planes as weighted rows (buildings that are not chains)
# --------------------------------------------------------------------------- #


def _floor_terms(offset: int, weights: np.ndarray) -> list[tuple[int, float]]:
    """A floor's ``(DOF, weight)`` terms from its weights over its own DOF (after *offset*), nonzero only."""
    return [(offset + k, float(w)) for k, w in enumerate(weights) if w != 0.0]


def _pad(terms: list[tuple[int, float]]) -> list[tuple[int, float]]:
    """Pad a side's terms to SIDE_TERMS/2 with absent terms ``(−1, 0)``; one line if there are too many."""
    if len(terms) > SIDE_TERMS // 2:
        raise ValueError(f"a side has {len(terms)} terms; the solver takes {SIDE_TERMS // 2}")
    return terms + [(-1, 0.0)] * (SIDE_TERMS // 2 - len(terms))


def _drift_sides(offset: int, per: int, a: np.ndarray, storey: int) -> tuple[list, list]:
    """A storey drift ``a · q`` (a over one building's DOF) as two sides: the floor above, and the rest (the floor
    below; on a foundation, also the base mat's sway and rocking)."""
    top = per * (storey - 1)
    upper = _floor_terms(offset + top, a[top:top + per])
    rest = np.array(a, dtype=float)
    rest[top:top + per] = 0.0
    return _pad(upper), _pad(_floor_terms(offset, rest))


def _global(offset: int, a: np.ndarray, n: int) -> np.ndarray:
    """A building's weights *a* over all *n* DOF (its own from *offset*)."""
    out = np.zeros(n)
    out[offset:offset + a.size] = a
    return out


def _rows(sides: list[tuple[list, list]]) -> dict[str, np.ndarray]:
    floors = np.array([[f for f, _ in up + low] for up, low in sides], dtype=np.int64).reshape(len(sides), SIDE_TERMS)
    weights = np.array([[w for _, w in up + low] for up, low in sides], dtype=float).reshape(len(sides), SIDE_TERMS)
    return {"floors": floors, "weights": weights}


def plane_rows(model: Model) -> tuple[list, dict[str, np.ndarray]]:
    """Every plane of every building as ``(stiffness N/m, a, DOF offset, storey, plane, building)`` and the
    :class:`System` fields of the planes' rows (``plane_floors``, ``plane_weights``, and the storey rows)."""
    offsets = model.dof_offsets
    planes = [(float(p.stiffness), a, offset, storey, b.storeys[storey - 1].planes[j], b)
              for b, offset in zip(model.buildings, offsets) for (storey, j, a), (_, _, p)
              in zip(b.model_plane_weights(), b.planes())]
    sides = _rows([_drift_sides(offset, b.dofs_per_floor, a, storey) for _, a, offset, storey, _, b in planes])
    fields = {"plane_floors": sides["floors"], "plane_weights": sides["weights"]}
    ratios = dict(zip([b.name for b in model.buildings], model.collapse_drift_ratios()))
    if any(p.hysteresis is not None or ratios[b.name] for *_, p, b in planes):
        fields.update(**hysteresis_arrays([(p.hysteresis, p.stiffness, b.storeys[storey - 1].height)
                                           for _, _, _, storey, p, b in planes]),
                      p_delta_stiffness=np.zeros(model.n_dof),  # per DOF; the P-Delta terms are in the blocks
                      storey_height=np.array([b.storeys[storey - 1].height for _, _, _, storey, _, b in planes],
                                             dtype=float),
                      storey_stop_ratio=np.array([float(ratios[b.name] or 0.0) for *_, b in planes]),
                      storey_floors=sides["floors"], storey_weights=sides["weights"],
                      storey_row_stiffness=np.array([float(p.stiffness) for *_, p, _ in planes]))
    return planes, fields


# --------------------------------------------------------------------------- #
# Contact points and links
# --------------------------------------------------------------------------- #


def side_terms(model: Model, building: int, level: int, at: float | None, point: tuple[float, float] | None,
               normal: str = "x") -> tuple[list[tuple[int, float]], int]:
    """One contact side as ``(DOF, weight)`` terms (padded with ``(−1, 0)``) and its main DOF (−1: a wall).

    The side's displacement along *normal* at *point*: a floor's (u_x for a floor of one DOF;
    ``u_n`` and ``θ``·lever in plan, :func:`pounding.model.floors.point_weights`), or at
    fraction *at* of storey *level*'s column ``N1·(floor below) + N2·(floor above)`` with the
    Hermite shape functions of :func:`pounding.model.model.column_weights` (the floor below
    storey 1 is the ground).  The main DOF is the side's first term of its floor (above, for a
    column point).
    """
    if building == WALL:
        return _pad([]), -1
    b = model.buildings[building]
    per = b.dofs_per_floor
    offset = model.dof_offsets[building]

    def floor(lv: int, scale: float) -> list[tuple[int, float]]:
        """The terms of floor *lv*'s point, times *scale*: nonzero weights only (the ground: none)."""
        if lv < 1:
            return []
        w = point_weights(b.storeys[lv - 1].centre, point or (0.0, 0.0), normal, per)
        return [(offset + per * (lv - 1) + k, scale * float(v)) for k, v in enumerate(w) if v != 0.0]

    if at is None:
        own = floor(level, 1.0)
        return _pad(own), own[0][0]
    n1, n2 = column_weights(at)
    # The floor below first (a planar column keeps its place even on the ground: (−1, 0)), then the floor above.
    below = floor(level - 1, n1) or ([(-1, 0.0)] if per == PLANAR_DOFS else [])
    above = floor(level, n2)
    if b.foundation is None:
        return _pad(below + above), above[0][0]
    # On a foundation the column's chord rotates with the base mat: x(ξ) = N1 x_below + N2 x_above + h (ξ − N2) θ_b,
    # and the floor below storey 1 is the base mat's sway (docs/foundations.md).
    sway, rocking = offset + b.n_dof, offset + b.n_dof + 1
    if level == 1:
        below = [(sway, n1)]
    return _pad(below + above + [(rocking, b.storeys[level - 1].height * (float(at) - n2))]), above[0][0]


def contact_side_terms(model: Model, building: int, level: int, at: float | None) -> list[tuple[int, float]]:
    """The terms of one side of a planar row's contact (:func:`side_terms` at no point, normal x)."""
    return side_terms(model, building, level, at, None)[0]


def side_mass(terms: list[tuple[int, float]], mass: np.ndarray) -> float:
    """Generalised mass of a contact side, kg: ``1/Σ w²/m`` (a floor: its mass; a wall: inf)."""
    compliance = sum(w * w / mass[f] for f, w in terms if f >= 0 and w != 0.0)
    return 1.0 / compliance if compliance > 0.0 else float("inf")


def element_arrays(model: Model, mass: np.ndarray, ground: GroundRows) -> dict[str, np.ndarray]:
    """Contact points, then links: floor terms and weights, gap (m), law id and parameters, ground rows.

    *mass* is every DOF's mass (for the laws' generalised side masses).  Each side moves with its
    building's ground along the contact's normal (a column point too); a wall moves with the ground
    of the building it faces (docs/physics.md §11), so a wall contact sees no differential ground
    motion.  A link is an element engaged from the start: gap 0, never open.
    """
    left, right, gaps, laws, params, floors, weights, ground_left, ground_right = [], [], [], [], [], [], [], [], []
    for gap in model.gaps:
        terms_left, main_left = side_terms(model, gap.left, gap.level_left, gap.at_left, gap.point, gap.normal)
        terms_right, main_right = side_terms(model, gap.right, gap.level_right, gap.at_right, gap.point, gap.normal)
        left.append(main_left)
        right.append(main_right)
        floors.append([f for f, _ in terms_left] + [f for f, _ in terms_right])
        weights.append([w for _, w in terms_left] + [-w for _, w in terms_right])
        ground_left.append(ground.of(gap.right if gap.left == WALL else gap.left, gap.normal))
        ground_right.append(ground.of(gap.left if gap.right == WALL else gap.right, gap.normal))
        gaps.append(gap.gap)
        laws.append(gap.law.law_id)
        params.append(gap.law.kernel_parameters(side_mass(terms_left, mass), side_mass(terms_right, mass)))
    for link in model.links:
        terms_left, main_left = side_terms(model, link.left, link.level_left, None, link.point, link.normal)
        terms_right, main_right = side_terms(model, link.right, link.level_right, None, link.point, link.normal)
        left.append(main_left)
        right.append(main_right)
        floors.append([f for f, _ in terms_left] + [f for f, _ in terms_right])
        weights.append([w for _, w in terms_left] + [0.0 - w for _, w in terms_right])
        ground_left.append(ground.of(link.left, link.normal))
        ground_right.append(ground.of(link.right, link.normal))
        gaps.append(0.0)
        laws.append(link.law.law_id)
        params.append(link.law.kernel_parameters())
    return dict(
        contact_left=np.asarray(left, dtype=np.int64),
        contact_right=np.asarray(right, dtype=np.int64),
        contact_gap=np.asarray(gaps, dtype=float),
        contact_law=np.asarray(laws, dtype=np.int64),
        contact_parameters=np.ascontiguousarray(
            np.array(params, dtype=float).reshape(len(params), contact_laws.N_PARAMETERS)),
        contact_ground_left=np.asarray(ground_left, dtype=np.int64),
        contact_ground_right=np.asarray(ground_right, dtype=np.int64),
        contact_floors=np.ascontiguousarray(np.array(floors, dtype=np.int64).reshape(len(floors), SIDE_TERMS)),
        contact_weights=np.ascontiguousarray(np.array(weights, dtype=float).reshape(len(weights), SIDE_TERMS)),
    )


def _face_sides(model: Model, face: Any, rows: np.ndarray) -> tuple[list, list]:
    """A face's (2, 3) weight *rows* (its first side's floor, its second's: a point's penetration or the
    face's slip) as the solver's two sides, the low side on the left."""
    first = model.floor_slice(face.first, face.level_first).start
    one = _pad(_floor_terms(first, rows[0]))
    two = _pad([]) if face.second == WALL else \
        _pad(_floor_terms(model.floor_slice(face.second, face.level_second).start, rows[1]))
    return (one, two) if face.face.first_low else (two, one)


def friction_arrays(model: Model) -> dict[str, np.ndarray]:
    """The :class:`System` friction fields of the faces with ``friction`` (μ > 0), or {} without.

    A face's slip terms are its points' (shared) slip weights, the low side first as its contact
    points' sides; its points are consecutive gap elements.
    """
    point_face = [g.face for g in model.gaps]
    floors, weights, coefficient, first, count = [], [], [], [], []
    for index, face in enumerate(model.faces):
        if not face.friction:
            continue
        left, right = _face_sides(model, face, face.points[0].slip)
        floors.append([f for f, _ in left + right])
        weights.append([w for _, w in left + right])
        coefficient.append(float(face.friction))
        first.append(point_face.index(index))
        count.append(point_face.count(index))
    if not coefficient:
        return {}
    nf = len(coefficient)
    return dict(friction_floors=np.array(floors, dtype=np.int64).reshape(nf, SIDE_TERMS),
                friction_weights=np.array(weights, dtype=float).reshape(nf, SIDE_TERMS),
                friction_coefficient=np.array(coefficient, dtype=float),
                friction_first_point=np.array(first, dtype=np.int64), friction_point_count=np.array(count, dtype=np.int64))


# --------------------------------------------------------------------------- #
# Grounds, tolerances, the assembly
# --------------------------------------------------------------------------- #


def dof_ground(model: Model, ground: GroundRows) -> np.ndarray:
    """(N,) the ground row of every degree of freedom: its building's along its direction (θ: the zero row); a
    base mat's sway its building's row along x, its rocking the zero row (no ground forcing: the mat's
    mass centre moves with the free field at rest)."""
    if any(b.foundation is not None for b in model.buildings) and ground.zero < 0:
        raise ValueError("a founded building's rocking needs a zero ground row: give GroundRows a zero row")
    rows = [np.array([ground.of(i, name) for _ in range(b.n_floors) for name in b.dof_names]
                     + ([ground.of(i, "x"), ground.zero] if b.foundation is not None else []), dtype=np.int64)
            for i, b in enumerate(model.buildings)]
    return np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)


def tolerance_factors(model: Model, system: System, peak_ground_acceleration: float, atol: float) -> np.ndarray:
    """(N,) factors on atol per degree of freedom (:func:`pounding.solver.tolerances.floor_tolerance_factors`).

    Translations at their building's static scale (its stiffest storey, every plane summed, against
    the model's lightest floor); rotations further over the floor's radius of gyration (atol/r rad,
    r ≥ 1 m).
    """
    if all(is_chain(b) for b in model.buildings):
        return floor_tolerance_factors(system.mass, system.storey_stiffness, system.below,
                                       peak_ground_acceleration, atol)
    mass, stiffness, below, radius, rotation = [], [], [], [], []
    for b in model.buildings:
        per, base = b.dofs_per_floor, b.n_base_dof
        # A base mat: its sway at the building's static scale, its rocking further over the building's height.
        mass.append(np.r_[np.repeat(b.mass, per), np.full(base, b.mass.min())])
        stiffness.append(np.r_[np.repeat(b.stiffness, per), np.full(base, b.stiffness.max())])
        below.append(np.r_[-1, np.zeros(b.n_model_dof - 1, dtype=np.int64)])
        radius.append(np.r_[np.repeat([s.radius_of_gyration if per > PLANAR_DOFS else 1.0 for s in b.storeys], per),
                            np.full(base, float(b.height.sum()))])
        rotation.append(np.r_[np.tile([name == "rz" for name in b.dof_names], b.n_floors), [False, True][:base]])
    factors = floor_tolerance_factors(np.concatenate(mass), np.concatenate(stiffness), np.concatenate(below),
                                      peak_ground_acceleration, atol)
    rotation = np.concatenate(rotation).astype(bool)
    factors[rotation] *= np.minimum(1.0, 1.0 / np.concatenate(radius)[rotation])
    return factors


def assemble(model: Model, ground: GroundRows | None = None) -> Assembly:
    """Flatten *model* into the arrays the compiled integrator works on (module docstring).

    *ground* gives each building's ground rows (default: one common ground along x, row 0).
    """
    ground = ground or GroundRows(tuple([0] * len(model.buildings)))
    buildings = building_arrays(model)
    chain = all(is_chain(b) for b in model.buildings)
    n = buildings["mass"].size
    if chain:
        storeys, planes = storey_arrays(model), []
    else:
        planes, storeys = plane_rows(model)
    p_delta = [(k, _global(offset, a, n)) for b, offset in zip(model.buildings, model.dof_offsets)
               if b.p_delta and not chain for _, k, a in geometric_terms(list(b.storeys), b.dofs_per_floor)]
    system = System(**buildings, **storeys, **element_arrays(model, buildings["mass"], ground),
                    floor_ground=dof_ground(model, ground), **friction_arrays(model))
    return Assembly(system, len(model.gaps), chain,
                    np.array([k for k, *_ in planes], dtype=float),
                    np.array([_global(offset, a, n) for _, a, offset, *_ in planes]).reshape(len(planes), n),
                    np.array([k for k, _ in p_delta], dtype=float),
                    np.array([a for _, a in p_delta]).reshape(len(p_delta), n))


def xy_ground(a_gx: np.ndarray, a_gy: np.ndarray, buildings: int = 1) -> tuple[np.ndarray, GroundRows]:
    """One ground moving along x and y: its ``(3, ns)`` rows (a_gx, a_gy and the zero row of rotations; m/s²)
    and the :class:`GroundRows` of *buildings* standing on it."""
    a_gx = np.asarray(a_gx, dtype=float)
    rows = np.ascontiguousarray(np.stack([a_gx, np.asarray(a_gy, dtype=float), np.zeros_like(a_gx)]))
    return rows, GroundRows((0,) * buildings, (1,) * buildings, 2)
