"""A model flattened into the solver's arrays: :func:`assemble` builds the :class:`System`.

Floors of all buildings are concatenated left to right; every per-floor array
has one entry per floor (the storey under it), every per-element array one row
per gap element and then one per link.  Three parts, each a function:

* :func:`building_arrays` — masses, storey stiffnesses, the floor below, damping
  (Rayleigh coefficients per floor, or one dense modal block per building);
* :func:`storey_arrays` — hysteresis kernel ids and parameters, heights, P-Delta;
* :func:`element_arrays` — gap elements and links: their floor terms and weights
  (:func:`contact_side_terms`), gaps, law ids and parameters, and the ground row
  that moves each side.

This is the one place that reads a :class:`~pounding.model.model.Model` for the solver.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pounding import hysteresis
from pounding.contact import laws as contact_laws
from pounding.model.model import WALL, Model, column_weights
from pounding.solver import imk
from pounding.solver.integrator import System

__all__ = ["assemble", "building_arrays", "storey_arrays", "hysteresis_arrays", "storey_stop_ratios", "element_arrays", "contact_side_terms", "side_mass"]


def building_arrays(model: Model) -> dict[str, np.ndarray]:
    """Masses (kg), storey stiffnesses (N/m), floor below (−1: ground) and damping of every floor.

    Rayleigh damping stays tridiagonal (``a0·M + a1·K`` acts storey by storey);
    modal damping is stored as one dense block per building (N·s/m).
    """
    masses, stiffness, below, a0, a1 = [], [], [], [], []
    dense_start, dense_size, dense_offset, dense_values = [], [], [], []
    offset = 0
    dense_used = 0
    for building in model.buildings:
        n = building.n_floors
        masses.append(building.mass)
        stiffness.append(building.stiffness)
        below.append(np.r_[-1, np.arange(offset, offset + n - 1)])
        dense_start.append(offset)
        dense_offset.append(dense_used)
        if building.damping.kind == "rayleigh":
            c_mass, c_stiff = building.rayleigh_coefficients
            a0.append(np.full(n, c_mass))
            a1.append(np.full(n, c_stiff))
            dense_size.append(0)
        else:
            a0.append(np.zeros(n))
            a1.append(np.zeros(n))
            dense_size.append(n)
            dense_values.append(np.asarray(building.damping_matrix(), dtype=float).ravel())
            dense_used += n * n
        offset += n
    return dict(
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


def storey_stop_ratios(model: Model) -> np.ndarray:
    """(N,) each storey's collapse drift ratio: its building's (:meth:`Model.collapse_drift_ratios`), 0: none."""
    return np.ascontiguousarray(np.concatenate(
        [np.full(b.n_floors, float(ratio or 0.0)) for b, ratio in zip(model.buildings, model.collapse_drift_ratios())]))


def storey_arrays(model: Model) -> dict[str, Any]:
    """Hysteresis kernel id and parameters, height (m) and P-Delta stiffness (N/m) of every storey.

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


def element_arrays(model: Model, mass: np.ndarray, rows: list[int]) -> dict[str, np.ndarray]:
    """Gap elements, then links: floors, weights, gap (m), law id and parameters, ground rows.

    *mass* is every floor's mass (kg, for the laws' generalised side masses), *rows*
    the ground row of each building.  Each side moves with its building's ground (a
    column point too); a wall moves with the ground of the building it faces
    (docs/physics.md §11), so a wall contact sees no differential ground motion.
    A link is an element engaged from the start: gap 0, never open.
    """
    left, right, gaps, laws, params, floors, weights, ground_left, ground_right = [], [], [], [], [], [], [], [], []
    for gap in model.gaps:
        terms_left = contact_side_terms(model, gap.left, gap.level_left, gap.at_left)
        terms_right = contact_side_terms(model, gap.right, gap.level_right, gap.at_right)
        left.append(terms_left[-1][0] if terms_left[-1][1] != 0.0 else terms_left[0][0])
        right.append(terms_right[-1][0] if terms_right[-1][1] != 0.0 else terms_right[0][0])
        floors.append([f for f, _ in terms_left] + [f for f, _ in terms_right])
        weights.append([w for _, w in terms_left] + [-w for _, w in terms_right])
        ground_left.append(rows[gap.right if gap.left == WALL else gap.left])
        ground_right.append(rows[gap.left if gap.right == WALL else gap.right])
        gaps.append(gap.gap)
        laws.append(gap.law.law_id)
        params.append(gap.law.kernel_parameters(side_mass(terms_left, mass), side_mass(terms_right, mass)))
    for link in model.links:
        lf = model.floor_offset(link.left) + link.level_left - 1
        rf = model.floor_offset(link.right) + link.level_right - 1
        left.append(lf)
        right.append(rf)
        floors.append([lf, -1, rf, -1])
        weights.append([1.0, 0.0, -1.0, 0.0])
        ground_left.append(rows[link.left])
        ground_right.append(rows[link.right])
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
        contact_floors=np.ascontiguousarray(np.array(floors, dtype=np.int64).reshape(len(floors), 4)),
        contact_weights=np.ascontiguousarray(np.array(weights, dtype=float).reshape(len(weights), 4)),
    )


def assemble(model: Model, building_ground: Any = None) -> System:
    """Flatten a model into the arrays the compiled integrator works on.

    *building_ground* gives, per building, its row of the ground-acceleration
    array (default: one common ground, row 0); each gap element's two sides take
    the rows of their buildings (``System.contact_ground_left/right``): the place
    where a new kind of contact (a wall, a link) says which ground moves each of
    its ends.
    """
    rows = [0] * len(model.buildings) if building_ground is None else [int(r) for r in building_ground]
    buildings = building_arrays(model)
    floor_ground = np.repeat(np.asarray(rows, dtype=np.int64), [b.n_floors for b in model.buildings])
    return System(**buildings, **storey_arrays(model), **element_arrays(model, buildings["mass"], rows),
                  floor_ground=floor_ground)


def contact_side_terms(model: Model, building: int, level: int, at: float | None) -> list[tuple[int, float]]:
    """The two ``(floor index, weight)`` terms of one contact side (floor index −1: ground or wall, weight 0).

    A floor is ``[(floor, 1), (−1, 0)]``; a wall ``[(−1, 0), (−1, 0)]``; a point
    at fraction *at* of storey *level*'s column ``[(floor below, N1), (floor
    above, N2)]`` with the Hermite shape functions of
    :func:`pounding.model.model.column_weights` (the floor below of storey 1
    is the ground: its term has floor −1).
    """
    if building == WALL:
        return [(-1, 0.0), (-1, 0.0)]
    offset = model.floor_offset(building)
    if at is None:
        return [(offset + level - 1, 1.0), (-1, 0.0)]
    n1, n2 = column_weights(at)
    below = offset + level - 2 if level > 1 else -1
    return [(below, n1 if below >= 0 else 0.0), (offset + level - 1, n2)]


def side_mass(terms: list[tuple[int, float]], mass: np.ndarray) -> float:
    """Generalised mass of a contact side, kg: ``1/Σ w²/m`` (a floor: its mass; a wall: inf)."""
    compliance = sum(w * w / mass[f] for f, w in terms if f >= 0 and w != 0.0)
    return 1.0 / compliance if compliance > 0.0 else float("inf")
