"""Storey events: a bilinear storey's yield onset and unloading, an IMK storey's branch changes, and the
collapse limit (locate; apply).

A bilinear storey's force has kinks where its drift reaches the yield
surface and where a yielding storey unloads; they are located on the step's
interpolant like gap closure, so no step straddles one
(:mod:`pounding.solver.storeys`).  A run stops, located, where a storey's
drift ratio first exceeds its building's collapse drift ratio (STATUS_COLLAPSED), and where a
storey with P-Delta loses its lateral resistance (STATUS_UNSTABLE,
:func:`instability_crossing`).  An IMK storey's events
are its drift crossing the lower or upper limit of its branch and, on a loading branch, its
drift turning back (:mod:`pounding.solver.imk`); one that loses its strength ends the run
as a collapse of its building (:func:`failed_storey`).
"""

from __future__ import annotations

from numba import njit

from pounding import hysteresis
from pounding.solver import imk, jit
from pounding.solver import storeys
from pounding.solver.dense import DELTA_ROUNDOFF, first_crossing, hermite
from pounding.solver.kinematics import storey_drift, storey_interpolant, storey_rate_scale, storey_stiffness

__all__ = ["STOREY_NONE", "STOREY_YIELD_POSITIVE", "STOREY_YIELD_NEGATIVE", "STOREY_UNLOAD", "STOREY_IMK_LOWER",
           "STOREY_IMK_UPPER", "STOREY_IMK_REVERSAL", "storey_event", "imk_event", "locate_storey_events",
           "apply_storey_events", "collapse_crossing", "failed_storey", "instability_crossing"]

# Kinds of storey events (bilinear storeys; IMK storeys: imk.KIND_* + STOREY_IMK_LOWER).
STOREY_NONE, STOREY_YIELD_POSITIVE, STOREY_YIELD_NEGATIVE, STOREY_UNLOAD = range(4)
STOREY_IMK_LOWER, STOREY_IMK_UPPER, STOREY_IMK_REVERSAL = 4 + imk.KIND_LOWER, 4 + imk.KIND_UPPER, 4 + imk.KIND_REVERSAL


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, inline="always", **jit.NO_REFCOUNT)
def storey_event(work, lay, j, terms, below, hi, model, uy, mode, h):
    """First switch of bilinear storey *j* inside a step: ``(fraction, STOREY_*)``, fraction −1 if none.

    Elastic mode: ``Δ − Δ_p`` reaching ``+u_y`` or ``−u_y`` (Δ_p is constant, so
    this is a crossing of the drift's Hermite cubic, found exactly by
    :func:`first_crossing`).  Yielding: the drift rate crossing 0 against
    the yield direction (the cubic of Δ̇ from Δ̇ and Δ̈ at the ends).  *uy*: its
    yield drift, m.  *terms*, *below*: the storey rows' drifts (:func:`pounding.solver.kinematics.storey_drift`).
    """
    if model != hysteresis.MODEL_BILINEAR:
        return -1.0, STOREY_NONE
    y, ynew, k1, k7 = work.y, work.ynew, work.K[0], work.K[6]
    n = lay.n_floors
    d0, r0, d1, r1, a0, a1 = storey_interpolant(y, ynew, k1, k7, n, terms, below, j)
    ih = lay.hysteretic
    if mode == storeys.ELASTIC:
        plastic = y[ih + hi]
        e0 = d0 - plastic
        e1 = d1 - plastic
        # The Hermite cubic stays within max(|e0|, |e1|) + (4/27)·h·(|r0| + |r1|) (its basis
        # functions' bounds): most steps are far from the yield surface and need no search.
        if max(abs(e0), abs(e1)) + 0.25 * h * (abs(r0) + abs(r1)) < uy:
            return -1.0, STOREY_NONE
        floor = DELTA_ROUNDOFF * (abs(d0) + abs(plastic) + uy)
        # A run-time bool (True here), not a literal: first_crossing is compiled once, not per literal.
        upward = mode == storeys.ELASTIC
        s = first_crossing(e0 - uy, r0, e1 - uy, r1, h, upward, floor)
        kind = STOREY_YIELD_POSITIVE
        s2 = first_crossing(e0 + uy, r0, e1 + uy, r1, h, not upward, floor)
        if s2 >= 0.0 and (s < 0.0 or s2 < s):
            s = s2
            kind = STOREY_YIELD_NEGATIVE
        return s, kind if s >= 0.0 else STOREY_NONE
    floor = DELTA_ROUNDOFF * storey_rate_scale(y, n, terms, below, j)
    s = first_crossing(r0, a0, r1, a1, h, mode < 0, floor)
    return s, STOREY_UNLOAD if s >= 0.0 else STOREY_NONE


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, inline="always", **jit.NO_REFCOUNT)
def imk_event(y, ynew, k1, k7, lay, j, terms, below, sprm, h):
    """First branch change of IMK storey *j* inside a step: ``(fraction, STOREY_IMK_*)``, −1 if none.

    The drift crossing its branch's lower limit downward or its upper limit
    upward (``sprm[j, P_LOWER]``, ``sprm[j, P_UPPER]``, m), and on a loading
    branch (``sprm[j, P_WATCH]`` = ±1) the drift rate crossing zero against
    that direction.
    """
    n = lay.n_floors
    d0, r0, d1, r1, a0, a1 = storey_interpolant(y, ynew, k1, k7, n, terms, below, j)
    lower, upper, watch = sprm[j, imk.P_LOWER], sprm[j, imk.P_UPPER], sprm[j, imk.P_WATCH]
    reach = max(abs(d0), abs(d1)) + 0.25 * h * (abs(r0) + abs(r1))
    best = -1.0
    kind = STOREY_NONE
    floor = DELTA_ROUNDOFF * (abs(d0) + reach)
    # The Hermite cubic stays within its ends ± (4/27)·h·(|r0| + |r1|): search only a limit within reach.
    if upper - max(d0, d1) < 0.25 * h * (abs(r0) + abs(r1)) + floor:
        s = first_crossing(d0 - upper, r0, d1 - upper, r1, h, True, floor + DELTA_ROUNDOFF * abs(upper))
        if s >= 0.0:
            best, kind = s, STOREY_IMK_UPPER
    if min(d0, d1) - lower < 0.25 * h * (abs(r0) + abs(r1)) + floor:
        s = first_crossing(d0 - lower, r0, d1 - lower, r1, h, False, floor + DELTA_ROUNDOFF * abs(lower))
        if s >= 0.0 and (best < 0.0 or s < best):
            best, kind = s, STOREY_IMK_LOWER
    if watch != 0.0:
        rate_floor = DELTA_ROUNDOFF * storey_rate_scale(y, n, terms, below, j)
        s = first_crossing(r0, a0, r1, a1, h, watch < 0.0, rate_floor)
        if s >= 0.0 and (best < 0.0 or s < best):
            best, kind = s, STOREY_IMK_REVERSAL
    return best, kind


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def locate_storey_events(work, h, lay, below, storey, sev_s, sev_kind) -> float:
    """Each yielding storey's first switch inside a step (:func:`storey_event`, inlined here) into
    ``sev_s`` and ``sev_kind``; returns the earliest fraction (2.0 if none).

    One call per attempted step for all the storeys: a call per storey passed
    its four state arrays each time, which measured ~6 % of an inelastic run.
    """
    y, ynew, k1, k7 = work.y, work.ynew, work.K[0], work.K[6]
    smodel, sprm, smode, sfloor, terms = storey.model, storey.parameters, storey.mode, storey.floor, storey.terms
    first = 2.0
    for hi in range(sfloor.size):
        j = sfloor[hi]
        if storeys.is_imk(smodel[j]):
            s, kind = imk_event(y, ynew, k1, k7, lay, j, terms, below, sprm, h)
        else:
            s, kind = storey_event(work, lay, j, terms, below, hi, smodel[j], sprm[j, 0], smode[hi], h)
        sev_s[hi] = s
        sev_kind[hi] = kind
        if kind != STOREY_NONE and s < first:
            first = s
    return first


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def apply_storey_events(kinds, y, lay, below, storey):
    """Apply located storey events ``kinds[h]`` (STOREY_*) to the state, in place; returns how many.

    Yield onset puts the plastic drift on the yield surface (``Δ − Δ_p = ±u_y``
    exactly) and enters the yield mode, unless the drift is not moving
    outward there (a grazing touch of the surface: it stays elastic);
    unloading returns to the elastic mode.  An IMK storey moves to its next branch at the
    located drift, its shear (the state) set to that branch's (:func:`imk.apply_event`).
    """
    sfloor, sprm, smode, terms = storey.floor, storey.parameters, storey.mode, storey.terms
    n = lay.n_floors
    ih = lay.hysteretic
    applied = 0
    for hi in range(smode.size):
        kind = kinds[hi]
        if kind == STOREY_NONE:
            continue
        applied += 1
        j = sfloor[hi]
        du = storey_drift(y, 0, terms, below, j)
        if kind >= STOREY_IMK_LOWER:
            y[ih + hi] = imk.apply_event(storey.imk[hi], sprm[j], kind - STOREY_IMK_LOWER, du, y[ih + hi],
                                         storey_drift(y, n, terms, below, j))
            continue
        rate = storey_drift(y, n, terms, below, j)
        uy = sprm[j, 0]
        if kind == STOREY_YIELD_POSITIVE:
            y[ih + hi] = du - uy
            smode[hi] = storeys.YIELD_POSITIVE if rate > 0.0 else storeys.ELASTIC
        elif kind == STOREY_YIELD_NEGATIVE:
            y[ih + hi] = du + uy
            smode[hi] = storeys.YIELD_NEGATIVE if rate < 0.0 else storeys.ELASTIC
        else:
            smode[hi] = storeys.ELASTIC
    return applied


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def failed_storey(storey):
    """Floor of the first IMK storey at zero strength (failed at an event), −1 if none."""
    smodel, sfloor = storey.model, storey.floor
    for hi in range(sfloor.size):
        if storeys.is_imk(smodel[sfloor[hi]]) and storey.imk[hi, imk.FAILED] > 0.0:
            return sfloor[hi]
    return sfloor.size - sfloor.size - 1


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def collapse_crossing(work, n, below, heights, stop_ratio, terms, h):
    """First instant in a step where a storey's |drift| exceeds ``stop_ratio[j]·height[j]``: (fraction, row).

    *stop_ratio*: (R,) each storey row's collapse drift ratio, its building's (0: no limit, not searched);
    the rows are the storeys under the N floors, or a plan model's planes (*terms*, :class:`StoreyTerms`)."""
    y, ynew, k1, k7 = work.y, work.ynew, work.K[0], work.K[6]
    best = -1.0
    where = -1
    for j in range(stop_ratio.size):
        if stop_ratio[j] <= 0.0:
            continue
        d0, r0, d1, r1, a0, a1 = storey_interpolant(y, ynew, k1, k7, n, terms, below, j)
        limit = stop_ratio[j] * heights[j]
        # The Hermite cubic stays within max(|d0|, |d1|) + (4/27)·h·(|r0| + |r1|) (its basis
        # functions' bounds): search only where the limit is within reach.
        if max(abs(d0), abs(d1)) + 0.25 * h * (abs(r0) + abs(r1)) < limit:
            continue
        for upward in (True, False):
            s = first_crossing(d0, r0, d1, r1, h, upward, limit)
            if s >= 0.0 and (best < 0.0 or s < best):
                best = s
                where = j
    return best, where


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def instability_crossing(work, lay, below, storey, stiffness, h):
    """First instant in a step where a storey with P-Delta loses its lateral resistance: (fraction, floor).

    The storey's total resistance ``R = F(Δ, r) + k_pd·Δ`` (restoring force and
    P-Delta, ``k_pd = −P/h``; *stiffness*: every storey's k, N/m) falls to zero
    while its drift grows away from zero: ``σR`` crosses from > 0 to ≤ 0 (σ the
    sign of the drift at the step's start) where ``σΔ > 0`` and ``σΔ̇ > 0``.
    Beyond it gravity's overturning moment exceeds what the storey can resist:
    the building cannot stand (a bilinear storey with αk < P/h, past its
    zero-resistance drift ``(1 − α)F_y / (P/h − αk)``).  F is linear in (Δ, r)
    for the bilinear and Bouc–Wen storeys (:mod:`pounding.solver.storeys`), so
    R's Hermite cubic on the step is that combination of the cubics of Δ and r
    (its rate F(Δ̇, ṙ) + k_pd·Δ̇) and its crossing is found exactly, as the
    collapse limit's; a model whose force is not linear in its state is not
    searched until it brings its own rate here.  Only a crossing from
    the near side counts: a step that starts with ``σR ≤ 0`` (a storey unloaded
    past zero force, moving back toward its plastic offset) has none.

    A crossing counts only from a resistance above the noise the tolerances
    leave in it, ``(k + P/h)·atol`` (atol: the storey state's tolerance in m):
    a storey drifting 1e-23 m with its Bouc–Wen z a tolerance away from AΔ/u_y
    would otherwise "cross" there.  A bilinear storey is searched only while
    it yields and beyond its yield drift u_y, two comparisons for most steps:
    while elastic its tangent ``k − P/h`` is positive (the model's check), and
    its zero-resistance drift ``(1 − α)F_y / (P/h − αk)`` exceeds u_y whenever
    ``P/h < k``.  (A Bouc–Wen storey softens from its first drift, and with
    ``k0 − P/h`` small loses its resistance well below u_y.)  A storey whose
    post-yield tangent ``αk − P/h`` is ≥ 0 is not searched at all (bilinear,
    and Bouc–Wen with β ≥ 0, whose z, within ±(A/(β + γ))^(1/n), does not fall
    while the drift grows: its resistance cannot fall either).
    """
    y, ynew, k1, k7 = work.y, work.ynew, work.K[0], work.K[6]
    n, ih = lay.n_floors, lay.hysteretic
    kpd, smodel, sprm, sidx = storey.p_delta, storey.model, storey.parameters, storey.state_index
    best = -1.0
    where = -1
    for j in range(kpd.size):
        if kpd[j] == 0.0:  # (a plan model's rows have none: its P-Delta terms are links)
            continue
        hi = sidx[j]
        model = smodel[j]
        if hi < 0 or (model != hysteresis.MODEL_BILINEAR and model != hysteresis.MODEL_BOUC_WEN):
            continue
        bilinear = model == hysteresis.MODEL_BILINEAR
        k = storey_stiffness(stiffness, storey.terms, j)
        if (bilinear or sprm[j, 3] >= 0.0) and sprm[j, 1] * k + kpd[j] >= 0.0:
            continue
        if bilinear and storey.mode[hi] == storeys.ELASTIC:
            continue
        reach = sprm[j, 0] if bilinear else 0.0
        d0, v0, d1, v1, a0, a1 = storey_interpolant(y, ynew, k1, k7, n, storey.terms, below, j)
        # The Hermite cubic stays within max(|d0|, |d1|) + (4/27)·h·(|v0| + |v1|) (collapse_crossing).
        if max(abs(d0), abs(d1)) + 0.25 * h * (abs(v0) + abs(v1)) < reach:
            continue
        sign = 1.0 if d0 > 0.0 else -1.0
        q0, q1, dq0, dq1 = y[ih + hi], ynew[ih + hi], k1[ih + hi], k7[ih + hi]
        r0 = sign * (storeys.restoring_force(model, sprm, j, k, d0, q0) + kpd[j] * d0)
        if r0 <= (k - kpd[j]) * storey.tolerance[hi] * (1.0 if bilinear else sprm[j, 0]):
            continue
        r1 = sign * (storeys.restoring_force(model, sprm, j, k, d1, q1) + kpd[j] * d1)
        rate0 = sign * (storeys.restoring_force(model, sprm, j, k, v0, dq0) + kpd[j] * v0)
        rate1 = sign * (storeys.restoring_force(model, sprm, j, k, v1, dq1) + kpd[j] * v1)
        s = first_crossing(r0, rate0, r1, rate1, h, False, DELTA_ROUNDOFF * (abs(k * d0) + abs(kpd[j] * d0)))
        if s < 0.0 or (best >= 0.0 and s >= best):
            continue
        drift_s = sign * hermite(d0, v0, d1, v1, h, s)
        if drift_s > 0.0 and drift_s >= reach and sign * hermite(v0, a0, v1, a1, h, s) > 0.0:
            best = s
            where = j
    return best, where


jit.stamp_solver_kernels(globals())
