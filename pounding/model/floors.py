"""Floors and the planes between them: drift weights, and a building's matrices by virtual work.

Pure functions on plain numbers and arrays (no YAML, no pydantic): the schema checks
models with them and :class:`pounding.model.building.Building` builds its matrices with
them.  One description serves every building (docs/architecture.md):

* a floor is a rigid body with ``dofs`` degrees of freedom at its centre of mass: one
  (``u_x``: the floor of a planar shear building) or three (``u_x``, ``u_y`` in m and
  ``θ`` in rad, counter-clockwise about +z: a rigid diaphragm in plan), at positions
  ``dofs·(i−1) + (0, 1, 2)`` of the building's vector q (floor i, 1-based, from the ground up);
* small rotations: the material point p of a floor moves ``u_x − θ (p_y − y_c)`` along x
  and ``u_y + θ (p_x − x_c)`` along y (a one-DOF floor moves ``u_x`` everywhere);
* the ground (floor 0) does not move and does not rotate;
* a storey resists through its planes: a plane along x at y = c resists the x-drift of
  the line y = c, ``Δ = [u_x,i − θ_i (c − y_c,i)] − [u_x,i−1 − θ_i−1 (c − y_c,i−1)] = a·q``
  (along y at x = c likewise); by virtual work it adds ``k a aᵀ`` to K and its force F
  acts on the floors as ``a F``.  A planar building's storey is one plane along x: its
  drift is ``u_i − u_i−1`` and K is the shear building's tridiagonal matrix.

Plan geometry (docs/plan-models.md): one global plan frame (x, y), m, shared by every
building; an outline is an axis-aligned rectangle ``((x0, y0), (x1, y1))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.units import STANDARD_GRAVITY

__all__ = ["PLAN_DOFS", "PLANAR_DOFS", "DOF_NAMES", "DOF_PER_FLOOR", "DIRECTIONS", "Plane", "Storey", "Outline",
           "outline_centroid", "outline_contains", "slab_radius_of_gyration", "point_weights", "drift_weights",
           "plane_weights", "plane_drift_ratio_weights", "storey_gravity_load", "mass_matrix", "stiffness_matrix",
           "influence", "natural_modes", "rayleigh_coefficients", "coincident_modes", "geometric_stiffness",
           "geometric_terms", "storey_stiffness_defect", "COINCIDENT_MODES"]

#: Degrees of freedom of a rigid floor in plan (u_x, u_y, θ) and of a planar building's floor (u_x).
PLAN_DOFS, PLANAR_DOFS = 3, 1
#: Names of a floor's degrees of freedom, by their number.
DOF_NAMES = {PLANAR_DOFS: ("x",), PLAN_DOFS: ("x", "y", "rz")}
#: Degrees of freedom of a rigid floor in plan (kept for readers of plan archives: u_x, u_y, θ per floor).
DOF_PER_FLOOR = PLAN_DOFS
#: A plane's direction and the index of its translation DOF.
DIRECTIONS = {"x": 0, "y": 1}
#: Two targeted Rayleigh modes closer than this (relative) in frequency draw a warning.
COINCIDENT_MODES = 0.01

Outline = tuple[tuple[float, float], tuple[float, float]]


@dataclass(frozen=True)
class Plane:
    """A lateral-load-resisting frame or wall of one storey: a spring on the drift of its line.

    Attributes
    ----------
    direction : {"x", "y"}
        The direction it resists (and runs along).
    at : float
        Its line: y = at for a plane along x, x = at for a plane along y, m (a planar
        building's storey: 0, any line drifts alike).
    stiffness : float
        Elastic lateral stiffness, N/m.
    hysteresis : StoreyHysteresis or None
        Its yielding model (as a storey's); None: elastic.
    """

    direction: str
    at: float
    stiffness: float
    hysteresis: Any = None

    @property
    def initial_stiffness(self) -> float:
        """Tangent stiffness at rest, N/m (the elastic one without hysteresis)."""
        return float(self.stiffness) if self.hysteresis is None else self.hysteresis.initial_stiffness(self.stiffness)


@dataclass(frozen=True)
class Storey:
    """One storey of a building and the floor on top of it.

    Attributes
    ----------
    mass : float
        Floor mass, kg.
    height : float
        Storey height, m.
    centre : (float, float)
        The floor's centre of mass in the plan frame, m ((0, 0) for a planar building).
    radius_of_gyration : float
        The floor's radius of gyration about its centre of mass, m (I = m r²; 0 for a
        planar building, whose floors do not rotate).
    planes : tuple of Plane
    """

    mass: float
    height: float
    centre: tuple[float, float]
    radius_of_gyration: float
    planes: tuple[Plane, ...]


# --------------------------------------------------------------------------- #
# Outlines
# --------------------------------------------------------------------------- #


def outline_centroid(outline: Outline) -> tuple[float, float]:
    """Centroid of an outline ``((x0, y0), (x1, y1))``, m."""
    (x0, y0), (x1, y1) = outline
    return 0.5 * (x0 + x1), 0.5 * (y0 + y1)


def outline_contains(outline: Outline, point: tuple[float, float]) -> bool:
    """True if *point* lies in the closed outline."""
    (x0, y0), (x1, y1) = outline
    return x0 <= point[0] <= x1 and y0 <= point[1] <= y1


def slab_radius_of_gyration(outline: Outline) -> float:
    """Radius of gyration of a uniform rectangular slab about its centroid, m: ``r² = (Lx² + Ly²)/12``."""
    (x0, y0), (x1, y1) = outline
    return math.sqrt(((x1 - x0) ** 2 + (y1 - y0) ** 2) / 12.0)


# --------------------------------------------------------------------------- #
# Weight vectors: displacement = w · q
# --------------------------------------------------------------------------- #


def point_weights(centre: tuple[float, float], point: tuple[float, float], direction: str,
                  dofs: int = PLAN_DOFS) -> np.ndarray:
    """(dofs,) weights of a floor's DOF giving the displacement of its material *point* along *direction*.

    Three DOF (u_x, u_y, θ): ``x``: ``u_x − θ (p_y − y_c)``; ``y``: ``u_y + θ (p_x − x_c)`` (small
    rotation).  One DOF (u_x): ``x``: ``u_x`` at every point.
    """
    if direction not in DIRECTIONS:
        raise ValueError(f"direction must be 'x' or 'y' (got {direction!r})")
    if dofs == PLANAR_DOFS:
        if direction != "x":
            raise ValueError("a floor with one degree of freedom moves along x only")
        return np.array([1.0])
    if direction == "x":
        return np.array([1.0, 0.0, -(point[1] - centre[1])])
    return np.array([0.0, 1.0, point[0] - centre[0]])


def drift_weights(centres: list[tuple[float, float]], storey: int, point: tuple[float, float],
                  direction: str, dofs: int = PLAN_DOFS) -> np.ndarray:
    """(dofs·n,) weights giving the drift along *direction* of the vertical line through *point* in *storey*.

    The displacement of the point of floor *storey* minus that of floor *storey* − 1
    (the ground for storey 1), each floor about its own centre of mass.

    Parameters
    ----------
    centres : list of (float, float)
        Every floor's centre of mass, m, floor 1 first.
    storey : int
        1-based storey number.
    point : (float, float)
        A point in plan, m.
    direction : {"x", "y"}
    dofs : int
        Degrees of freedom per floor (1 or 3).
    """
    w = np.zeros(dofs * len(centres))
    top = dofs * (storey - 1)
    w[top:top + dofs] = point_weights(centres[storey - 1], point, direction, dofs)
    if storey > 1:
        w[top - dofs:top] -= point_weights(centres[storey - 2], point, direction, dofs)
    return w


def plane_weights(storeys: list[Storey], storey: int, plane: Plane, dofs: int = PLAN_DOFS) -> np.ndarray:
    """(dofs·n,) weights *a* of a plane's drift, ``Δ = a · q`` (m): the drift of its line along its direction.

    Along x at y = c the line's point is taken at x = 0 (the x-drift of the line does
    not depend on x); along y at x = c, at y = 0.
    """
    point = (0.0, plane.at) if plane.direction == "x" else (plane.at, 0.0)
    return drift_weights([s.centre for s in storeys], storey, point, plane.direction, dofs)


def plane_drift_ratio_weights(storeys: list[Storey], dofs: int = PLAN_DOFS) -> list[tuple[int, int, np.ndarray]]:
    """``(storey, plane index, a / h)`` for every plane: its drift ratio is ``(a / h) · q``.

    A run's collapse (``solver.stop_drift_ratio``) is any plane's |drift ratio| beyond the limit.
    """
    return [(i + 1, j, plane_weights(storeys, i + 1, plane, dofs) / storeys[i].height)
            for i, storey in enumerate(storeys) for j, plane in enumerate(storey.planes)]


# --------------------------------------------------------------------------- #
# Matrices
# --------------------------------------------------------------------------- #


def storey_gravity_load(mass: Any) -> np.ndarray:
    """(n,) axial load ``P_i = g·Σ_(j≥i) m_j`` carried by each storey, N, of floor masses *mass* (kg, from the ground up)."""
    return STANDARD_GRAVITY * np.cumsum(np.asarray(mass, dtype=float)[::-1])[::-1]


def mass_matrix(storeys: list[Storey], dofs: int = PLAN_DOFS) -> np.ndarray:
    """(dofs·n, dofs·n) diagonal mass matrix: ``diag(m, m, m r²)`` per floor in plan (kg, kg, kg·m²), ``diag(m)``
    for one-DOF floors."""
    if dofs == PLANAR_DOFS:
        return np.diag(np.array([s.mass for s in storeys], dtype=float))
    diagonal = [value for s in storeys for value in (s.mass, s.mass, s.mass * s.radius_of_gyration ** 2)]
    return np.diag(np.array(diagonal, dtype=float))


def _add_rank_one(k: np.ndarray, stiffness: float, a: np.ndarray) -> None:
    """``k += stiffness · a aᵀ`` on the nonzero entries of *a* only (a drift touches two floors)."""
    nonzero = np.flatnonzero(a)
    block = a[nonzero]
    k[np.ix_(nonzero, nonzero)] += stiffness * np.outer(block, block)


def stiffness_matrix(storeys: list[Storey], dofs: int = PLAN_DOFS, *, initial: bool = True) -> np.ndarray:
    """(dofs·n, dofs·n) stiffness matrix ``Σ k a aᵀ`` over every plane of every storey (virtual work).

    For one-DOF floors (one plane per storey) this is the shear building's tridiagonal K,
    ``K[i, i] = k_i + k_(i+1)``, ``K[i, i+1] = −k_(i+1)``, to the last bit.

    Parameters
    ----------
    initial : bool
        Each plane's tangent at rest (:attr:`Plane.initial_stiffness`; what Rayleigh
        damping uses); False: its elastic stiffness.
    """
    n = dofs * len(storeys)
    k = np.zeros((n, n))
    for i, storey in enumerate(storeys):
        for plane in storey.planes:
            a = plane_weights(storeys, i + 1, plane, dofs)
            _add_rank_one(k, plane.initial_stiffness if initial else float(plane.stiffness), a)
    return k


def influence(n_floors: int, direction: str, dofs: int = PLAN_DOFS) -> np.ndarray:
    """(dofs·n,) ground-influence vector: 1 on every floor's translation along *direction*, 0 elsewhere (no rotation input)."""
    r = np.zeros(dofs * n_floors)
    if dofs == PLANAR_DOFS and direction != "x":
        return r
    r[DIRECTIONS[direction]::dofs] = 1.0
    return r


def natural_modes(stiffness: np.ndarray, mass: np.ndarray, dofs: int = PLAN_DOFS) -> tuple[np.ndarray, np.ndarray]:
    """Undamped modes of ``K φ = ω² M φ`` with diagonal M: ``(omega, phi)``.

    ``omega`` (N,) rad/s ascending (sorted by frequency); ``phi`` (N, N) mass-normalised in
    columns, each signed so that the largest-magnitude component of the roof floor (its last *dofs*
    entries) is positive: the roof moves along +x in every mode of a planar building.  Solved as the
    symmetric problem ``(M^-1/2 K M^-1/2) ψ = ω² ψ`` with ``φ = M^-1/2 ψ`` (numpy's ``eigh``).
    """
    scale = 1.0 / np.sqrt(np.diag(mass))
    eigenvalues, psi = np.linalg.eigh(stiffness * scale[:, None] * scale[None, :])
    phi = psi * scale[:, None]
    roof = phi[-dofs:]
    largest = roof[np.argmax(np.abs(roof), axis=0), np.arange(phi.shape[1])]
    phi = phi * np.where(largest < 0, -1.0, 1.0)
    return np.sqrt(np.clip(eigenvalues, 0.0, None)), phi


def rayleigh_coefficients(omega_i: float, omega_j: float, ratio: float) -> tuple[float, float]:
    """Rayleigh ``(a0, a1)`` (1/s, s) for ``C = a0 M + a1 K`` with damping *ratio* at ω_i and ω_j (rad/s)."""
    return 2.0 * ratio * omega_i * omega_j / (omega_i + omega_j), 2.0 * ratio / (omega_i + omega_j)


def coincident_modes(omega: np.ndarray, modes: tuple[int, int], tolerance: float = COINCIDENT_MODES) -> str | None:
    """A warning when the two targeted (1-based) modes' frequencies are within *tolerance* of each other, else None.

    Rayleigh damping through two (nearly) equal frequencies is (nearly) singular: a symmetric
    plan's x and y modes come in such pairs; target a torsional or a higher mode instead.
    """
    wi, wj = float(omega[modes[0] - 1]), float(omega[modes[1] - 1])
    if abs(wi - wj) > tolerance * max(wi, wj):
        return None
    return (f"Rayleigh damping targets modes {modes[0]} and {modes[1]}, whose frequencies {wi:.6g} and {wj:.6g} rad/s "
            f"are within {100 * tolerance:g} % of each other (a symmetric plan's x/y pair); damping then rises "
            "with frequency almost from the first mode: target two distinct modes, e.g. [1, 3]")


def geometric_stiffness(storeys: list[Storey], dofs: int = PLAN_DOFS) -> np.ndarray:
    """(dofs·n, dofs·n) P-Delta (leaning-column) geometric stiffness K_G (N/m, N, N·m), to be added to K.

    Storey i carries the weight ``P_i = g Σ_(j≥i) m_j`` of the floors above it,
    spread in plan like their masses: centroid ``c̄ = Σ m_j c_j / Σ m_j`` and polar
    radius of gyration ``r̄² = Σ m_j (r_j² + |c_j − c̄|²) / Σ m_j`` about it.  A load p
    at a point whose storey drift is d lowers the potential by ``p |d|² / (2h)``;
    summed over the distributed load (first moments vanish about c̄),
    ``K_G = −(P/h) (a_x a_xᵀ + a_y a_yᵀ + r̄² a_θ a_θᵀ)`` with a_x, a_y the drift
    weights of the point c̄ and a_θ = e_θ,i − e_θ,i−1: per direction P/h, and the
    torsional term P r̄²/h (docs/plan-models.md); one-DOF floors keep ``−(P/h) a_x a_xᵀ``
    (the shear building's ``−P_i/h_i`` on each storey drift).  The sum of :func:`geometric_terms`.
    """
    n = dofs * len(storeys)
    kg = np.zeros((n, n))
    for _, stiffness, a in geometric_terms(storeys, dofs):
        _add_rank_one(kg, stiffness, a)
    return kg


def geometric_terms(storeys: list[Storey], dofs: int = PLAN_DOFS) -> list[tuple[int, float, np.ndarray]]:
    """``(storey, k_G, a)`` for the rank-one P-Delta terms of every storey: ``K_G = Σ k_G a aᵀ``.

    Per storey i (1-based), in plan: ``(−P/h, a_x)``, ``(−P/h, a_y)`` and ``(−P r̄²/h, a_θ)``
    (N/m, N/m, N·m; see :func:`geometric_stiffness`); one-DOF floors: ``(−P/h, a_x)``.  A solver
    applies each as a linear spring of stiffness k_G on the drift ``a · q``.
    """
    n = dofs * len(storeys)
    centres = [s.centre for s in storeys]
    loads = storey_gravity_load([s.mass for s in storeys])
    terms: list[tuple[int, float, np.ndarray]] = []
    for i in range(len(storeys)):
        above = storeys[i:]
        masses = np.array([s.mass for s in above])
        points = np.array([s.centre for s in above], dtype=float)
        centroid = tuple(masses @ points / float(masses.sum()))
        weight = -float(loads[i]) / storeys[i].height
        terms.append((i + 1, weight, drift_weights(centres, i + 1, centroid, "x", dofs)))
        if dofs == PLANAR_DOFS:
            continue
        spread = float(masses @ (np.array([s.radius_of_gyration ** 2 for s in above])
                                 + ((points - centroid) ** 2).sum(axis=1))) / float(masses.sum())
        a_theta = np.zeros(n)
        a_theta[dofs * i + 2] = 1.0
        if i > 0:
            a_theta[dofs * (i - 1) + 2] = -1.0
        terms += [(i + 1, weight, drift_weights(centres, i + 1, centroid, "y", dofs)),
                  (i + 1, weight * spread, a_theta)]
    return terms


# --------------------------------------------------------------------------- #
# Checks
# --------------------------------------------------------------------------- #


def storey_stiffness_defect(planes: list[Plane] | tuple[Plane, ...], length: float) -> str | None:
    """Why a storey's planes leave it without stiffness in some motion, or None if they resist every one.

    The storey's relative motion (Δx, Δy, Δθ) of the floor above the floor below is
    resisted by ``Σ k a aᵀ`` (a about the planes' mean position); it is singular when every plane
    runs along one direction, or when every plane passes through one point (a twist
    about it is free).  *length* (m, e.g. the outline's diagonal) makes the rotation
    column commensurate for the rank test.
    """
    directions = {p.direction for p in planes}
    if len(directions) < 2:
        other = "y" if directions == {"x"} else "x"
        return f"every plane runs along {next(iter(directions), 'x')}: nothing resists drift along {other}; " \
               f"add a plane along {other}"
    # moments about the planes' mean position: about the plan origin, outlines in site coordinates (a UTM
    # easting of 500 km) make the rotation column 1e5 times the others and the rank test call it singular
    x0 = float(np.mean([p.at for p in planes if p.direction == "y"]))
    y0 = float(np.mean([p.at for p in planes if p.direction == "x"]))
    k = np.zeros((3, 3))
    for p in planes:
        a = (np.array([1.0, 0.0, -(p.at - y0) / length]) if p.direction == "x"
             else np.array([0.0, 1.0, (p.at - x0) / length]))
        k += float(p.stiffness) * np.outer(a, a)
    eigenvalues = np.linalg.eigvalsh(k)
    if eigenvalues[0] > 1e-10 * eigenvalues[-1]:
        return None
    xs = sorted({p.at for p in planes if p.direction == "y"})
    ys = sorted({p.at for p in planes if p.direction == "x"})
    return (f"every plane passes through the point ({xs[0]:g}, {ys[0]:g}): nothing resists a twist about it; "
            "add a plane along x or y away from that point")
