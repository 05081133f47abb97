"""IMK storeys in the building solver: branch changes as located events (compiled).

Within a branch an IMK storey's shear is affine in its drift, so the solver
integrates the shear itself as the storey's hysteretic state (ṙ = slope·Δ̇,
in the error norm) and its work ∫F dΔ beside it, and locates every branch
change as a storey event (:mod:`pounding.solver.storey_events`): the drift
crossing the branch's lower or upper limit, or turning back while on a
loading branch.  :func:`apply_event` moves the storey to its next branch at
the located drift with the rules of :class:`pounding.studies.imk.ImkMaterial`
(Ibarra, Medina & Krawinkler 2005; OpenSees ``IMKBilin``,
``IMKPeakOriented``, ``IMKPinching``), the energies of the deterioration
rules being the integrated work.  Zero strength (the ultimate drift, a
residual branch at zero force, an exhausted energy) marks the storey failed:
the run ends there as a collapse of its building.

Each storey's discrete state is a row of ``Storeys.imk`` (:data:`N_STATE`
floats: per direction, in that direction's own coordinates u' = σu, F' = σF,
the backbone and peaks; then the branch, the reference energies...).  Its
kernel row (``Storeys.parameters``, a per-run copy) holds what the
compiled kernels read at every step: ``[u_y, slope, k_unload, lower limit,
upper limit, watch]`` (m, N/m, N/m, m, m; watch ±1: the drift turning
against that direction is an event, 0: not watched).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pounding.solver import jit

__all__ = ["N_STATE", "initial_state", "apply_event", "beta", "set_row", "branch_force", "FAILED", "BRANCH", "KIND_LOWER", "KIND_UPPER",
           "KIND_REVERSAL", "P_SLOPE", "P_UNLOAD", "P_LOWER", "P_UPPER", "P_WATCH"]

# Per direction (offset 0: positive, SIDE: negative), own coordinates.
FY, UY, KP, KPC, UCAP, FCAP, FRES, URES, UU, RATE, FY0, KPC0, ULOC, FLOC, UGLO, FGLO = range(16)
SIDE = 16
# The storey.
KE, KUN, KRE, ELAST, BRANCH, DIR, UPIN, FPIN, FAILED, ONBB, YIELDED, RESID, VARIANT = range(32, 45)
ES, EC, EA, EK, CS, CC, CA, CK, KF, KD, UREF, FREF = range(45, 57)
# The drift and shear after the last event, and the work ∫F dΔ up to it (exact: F is affine in between).
ULAST, FLAST, WORK = range(57, 60)
N_STATE = 60

# Branches (as pounding.studies.imk) and variants.
ELASTIC, UNLOAD, PINCH, LOCAL, GLOBAL, HARDENING, POST_CAPPING, RESIDUAL = range(8)
V_BILINEAR, V_PEAK, V_PINCHING = range(3)
# Kernel row columns.
P_SLOPE, P_UNLOAD, P_LOWER, P_UPPER, P_WATCH = 1, 2, 3, 4, 5
# Event kinds (pounding.solver.storey_events numbers them after the bilinear ones).
KIND_LOWER, KIND_UPPER, KIND_REVERSAL = range(3)
#: Relative round-off within which a reloading line that reaches the backbone where its hardening line rises
#: from the residual floor (``line = F_r``) is on the line: the limit is that intersection, so the line is
#: F_r there only to round-off (the tolerance of the backbone's own reaching test in :func:`_bilinear_event` as well).
ON_LINE_TOLERANCE = 1e-12

INF = np.inf


def initial_state(law, stiffness: float, height: float) -> np.ndarray:
    """The state row of an IMK storey at rest (:data:`N_STATE` floats) from its validated *law*."""
    p = law.backbone(stiffness, height)
    ke = float(stiffness)
    st = np.zeros(N_STATE)
    for offset, sign in ((0, "positive"), (SIDE, "negative")):
        d = p[sign]
        fy = d["fy"]
        uy = fy / ke
        fcap = d["fcap_ratio"] * fy
        kpc = -fcap / d["upc"]
        fres = d["fres_ratio"] * fy
        ucap = uy + d["up"]
        values = {FY: fy, UY: uy, KP: (fcap - fy) / d["up"], KPC: kpc, UCAP: ucap, FCAP: fcap, FRES: fres,
                  URES: (fres - fcap) / kpc + ucap, UU: d["uu"], RATE: d["d"], FY0: fy, KPC0: kpc,
                  ULOC: uy, FLOC: fy, UGLO: uy, FGLO: fy}
        for index, value in values.items():
            st[offset + index] = value
    st[KE] = st[KUN] = st[KRE] = ke
    st[DIR] = 1.0
    st[VARIANT] = {"bilinear": V_BILINEAR, "peak-oriented": V_PEAK, "pinching": V_PINCHING}[law.variant]
    for index, key in ((ES, "e_s"), (EC, "e_c"), (EA, "e_a"), (EK, "e_k"), (CS, "c_s"), (CC, "c_c"), (CA, "c_a"),
                       (CK, "c_k"), (KF, "kappa_f"), (KD, "kappa_d")):
        st[index] = p[key]
    return st


# --------------------------------------------------------------------------- #
# Small pieces
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def beta(energy, reference, spent, c):
    """β = (E_i / (E_t − ΣE))^c of Ibarra et al. (2005) eq. 4, clipped to [0, 1], and whether it fails.

    *reference* E_t = 0: the mode is off (β = 0).  The capacity is exhausted
    (failure) where β > 1 or where the remaining energy E_t − ΣE is not
    positive (the paper: β outside 0 < β ≤ 1; OpenSees clips a negative β to 0
    and carries on, docs/hysteresis.md).  A negative E_i counts as 0.
    """
    if reference <= 0.0:
        return 0.0, False
    remaining = reference - spent
    if remaining <= 0.0:
        return 1.0, True
    beta = (max(energy, 0.0) / remaining) ** c
    return min(beta, 1.0), beta > 1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _slope(df, du, fallback):
    return df / du if du != 0.0 else fallback


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _side(sigma):
    return 0 if sigma > 0 else SIDE


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _unloading_deterioration(st, f, work):
    """k_u ← k_u(1 − β_k) at a reversal (elastic energy of the unloading excluded); returns a failure."""
    elastic = 0.5 * f * f / st[KUN]
    beta_k, fail = beta(work - st[ELAST] - elastic, st[EK], work - elastic, st[CK])
    st[KUN] *= 1.0 - beta_k
    return fail


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _deteriorate(st, o, work, use_accelerated):
    """β_s, β_c, β_a of a new excursion applied to the backbone at offset *o*; returns (the post-capping
    intercept, failure).  E_i is the work since the last excursion."""
    e_i = max(0.0, work - st[ELAST])
    beta_s, fail_s = beta(e_i, st[ES], work, st[CS])
    beta_c, fail_c = beta(e_i, st[EC], work, st[CC])
    beta_a, fail_a = 0.0, False
    if use_accelerated:
        beta_a, fail_a = beta(e_i, st[EA], work, st[CA])
    st[ELAST] = work
    intercept = st[o + FCAP] - st[o + KPC] * st[o + UCAP]
    strength = 1.0 - beta_s * st[o + RATE]
    capping = 1.0 - beta_c * st[o + RATE]
    # D > 1 and β near 1 would turn the strength negative: the capacity is exhausted, as where β > 1
    exhausted = strength <= 0.0 or capping <= 0.0
    st[o + FY] *= max(strength, 0.0)
    st[o + KP] *= max(strength, 0.0)
    st[o + UGLO] *= 1.0 + beta_a * st[o + RATE]
    st[o + UY] = st[o + FY] / st[KE]
    return intercept * max(capping, 0.0), fail_s or fail_c or fail_a or exhausted


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _place_capping_point(st, o, intercept_pc):
    intercept_p = st[o + FY] - st[o + KP] * st[o + UY]
    if st[o + KP] <= st[o + KPC]:
        st[o + UCAP] = 0.0
    else:
        st[o + UCAP] = (intercept_pc - intercept_p) / (st[o + KP] - st[o + KPC])
    st[o + FCAP] = intercept_p + st[o + KP] * st[o + UCAP]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _backbone_force(st, o, x):
    """The backbone at offset *o* at own drift *x*, not below the residual (peak-oriented targets)."""
    if x < st[o + UY]:
        f = st[KE] * x
    elif x < st[o + UCAP]:
        f = st[o + FY] + st[o + KP] * (x - st[o + UY])
    else:
        f = st[o + FCAP] + st[o + KPC] * (x - st[o + UCAP])
    return max(f, st[o + FRES])


# --------------------------------------------------------------------------- #
# Branch force, slope and limits
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def branch_force(st, u):
    """The current branch's shear (N) at drift *u* (m), and its slope (N/m)."""
    if st[FAILED] > 0.0:
        return 0.0, 0.0
    branch = int(st[BRANCH])
    if branch == ELASTIC:
        return st[KE] * u, st[KE]
    if branch == UNLOAD:
        return st[FREF] + st[KUN] * (u - st[UREF]), st[KUN]
    sigma = st[DIR]
    o = _side(sigma)
    x = sigma * u
    if branch == PINCH:
        f, k = sigma * st[FPIN] + st[KRE] * (x - sigma * st[UPIN]), st[KRE]
    elif branch == LOCAL:
        f, k = st[o + FLOC] + st[KRE] * (x - st[o + ULOC]), st[KRE]
    elif branch == GLOBAL:
        f, k = st[o + FGLO] + st[KRE] * (x - st[o + UGLO]), st[KRE]
    elif branch == HARDENING:
        f, k = st[o + FCAP] + st[o + KP] * (x - st[o + UCAP]), st[o + KP]
    elif branch == POST_CAPPING:
        f, k = st[o + FCAP] + st[o + KPC] * (x - st[o + UCAP]), st[o + KPC]
    else:
        f, k = st[o + FRES], 0.0
    return sigma * f, k


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _oriented_limits(st):
    """(lower, upper, watch) of the current branch (peak-oriented and pinching), absolute drifts."""
    branch = int(st[BRANCH])
    uu_pos, uu_neg = st[UU], st[SIDE + UU]
    if branch == ELASTIC:
        return -st[SIDE + UY], st[UY], 0.0
    if branch == UNLOAD:
        zero = st[UREF] - st[FREF] / st[KUN]
        if st[FREF] > 0.0:
            return max(zero, -uu_neg), min(st[ULOC], uu_pos), 0.0
        return max(-st[SIDE + ULOC], -uu_neg), min(zero, uu_pos), 0.0
    sigma = st[DIR]
    o = _side(sigma)
    if branch == PINCH:
        limit = sigma * st[UPIN]
    elif branch == LOCAL:
        limit = st[o + ULOC]
    elif branch == GLOBAL:
        limit = st[o + UGLO]
    elif branch == HARDENING:
        limit = st[o + UCAP]
    elif branch == POST_CAPPING:
        limit = st[o + URES]
    else:
        limit = INF
    limit = min(limit, st[o + UU])
    if sigma > 0:
        return -INF, limit, 1.0
    return -limit, INF, -1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _bilinear_line(st, o, x):
    """IMKBilin's hardening (before the capping point) or post-capping line at offset *o* at own drift *x*, N."""
    slope = st[o + KP] if x < st[o + UCAP] else st[o + KPC]
    return st[o + FCAP] + (x - st[o + UCAP]) * slope


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _bilinear_backbone(st, o, x):
    """IMKBilin's backbone at offset *o* at own drift *x*: the hardening or post-capping line, not below F_r."""
    return max(_bilinear_line(st, o, x), st[o + FRES])


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _bilinear_hit(st, o, x_ref, f_ref, k):
    """Smallest own drift x ≥ *x_ref* where the line f_ref + k(x − x_ref) reaches the backbone at *o*.

    Where the line meets the backbone at the very point a segment crosses the residual floor (IMKBilin
    places the hardening line through the point where the reloading line reaches F_r), the segment's
    intersection and the floor's are the same point to round-off, and each is accepted within
    :data:`ON_LINE_TOLERANCE` of the capping strength: with exact tests round-off could reject both, and
    the reloading line ran on with no limit past the backbone's strength.
    """
    best = INF
    fcap, ucap, fres = st[o + FCAP], st[o + UCAP], st[o + FRES]
    tol = ON_LINE_TOLERANCE * max(abs(fcap), abs(fres))
    for slope, lo, hi in ((st[o + KP], -INF, ucap), (st[o + KPC], ucap, INF)):
        if k != slope:
            # f_ref + k(x − x_ref) = fcap + slope(x − ucap)
            x = (fcap - slope * ucap - f_ref + k * x_ref) / (k - slope)
            if lo <= x < hi and x >= x_ref and fcap + slope * (x - ucap) >= fres - tol and x < best:
                best = x
    if k > 0.0:
        x = x_ref + (fres - f_ref) / k
        if x >= x_ref and _bilinear_line(st, o, x) <= fres + tol and x < best:
            best = x
    if f_ref >= _bilinear_backbone(st, o, x_ref):
        best = x_ref
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _bilinear_limits(st):
    """(lower, upper, watch) of IMKBilin's current state, absolute drifts."""
    uu_pos, uu_neg = st[UU], st[SIDE + UU]
    if st[ONBB] > 0.0:
        sigma = st[DIR]
        o = _side(sigma)
        x = sigma * st[UREF]
        limit = st[o + UU]
        if x < st[o + UCAP] < limit:
            limit = st[o + UCAP]
        if st[o + KPC] != 0.0 and x < st[o + URES] < limit:
            limit = st[o + URES]
        if st[o + KP] > 0.0:
            # Where the hardening line rises above the residual floor (the backbone's far, flat part).
            rise = st[o + UCAP] + (st[o + FRES] - st[o + FCAP]) / st[o + KP]
            if x < rise < limit:
                limit = rise
        if sigma > 0:
            return -INF, limit, 1.0
        return -limit, INF, -1.0
    u, f, k = st[UREF], st[FREF], st[KUN]
    upper = min(_bilinear_hit(st, 0, u, f, k), uu_pos)
    lower = max(-_bilinear_hit(st, SIDE, -u, -f, k), -uu_neg)
    if st[YIELDED] > 0.0 and f != 0.0:
        zero = u - f / k
        if f > 0.0:
            lower = max(lower, zero)
        else:
            upper = min(upper, zero)
    if st[RESID] == 0.0:
        for sigma in (1.0, -1.0):
            o = _side(sigma)
            if st[o + KPC] != 0.0 and sigma * u < st[o + URES]:
                if sigma > 0:
                    upper = min(upper, st[o + URES])
                else:
                    lower = max(lower, -st[o + URES])
    return lower, upper, 0.0


# --------------------------------------------------------------------------- #
# Events
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _cascade(st, x):
    """Advance along the reloading path while own drift *x* has reached the branch's end (≥: at an event)."""
    sigma = st[DIR]
    o = _side(sigma)
    if int(st[BRANCH]) == PINCH and x >= sigma * st[UPIN]:
        up, fp = sigma * st[UPIN], sigma * st[FPIN]
        k_global = _slope(st[o + FGLO] - fp, st[o + UGLO] - up, st[KE])
        k_local = _slope(st[o + FLOC] - fp, st[o + ULOC] - up, st[KE])
        if up < st[o + ULOC] and fp < st[o + FLOC] and st[o + FLOC] < st[o + FGLO] and k_local > k_global:
            st[BRANCH], st[KRE] = LOCAL, k_local
        else:
            st[BRANCH], st[KRE] = GLOBAL, k_global
    if int(st[BRANCH]) == LOCAL and x >= st[o + ULOC]:
        st[BRANCH] = GLOBAL
        st[KRE] = _slope(st[o + FGLO] - st[o + FLOC], st[o + UGLO] - st[o + ULOC], st[KE])
    if int(st[BRANCH]) == GLOBAL and x >= st[o + UGLO]:
        st[BRANCH] = HARDENING
    if int(st[BRANCH]) == HARDENING and x >= st[o + UCAP]:
        st[BRANCH] = POST_CAPPING
    if int(st[BRANCH]) == POST_CAPPING and x >= st[o + URES]:
        st[BRANCH] = RESIDUAL


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _oriented_event(st, kind, u, f, work):
    """Peak-oriented and pinching: the branch after an event of *kind* at drift *u*; returns a failure."""
    branch = int(st[BRANCH])
    fail = False
    if kind == KIND_REVERSAL:
        sigma = 1.0 if f > 0.0 else -1.0
        o = _side(sigma)
        st[o + ULOC], st[o + FLOC] = sigma * u, sigma * f
        if sigma * u > st[o + UGLO]:
            st[o + UGLO], st[o + FGLO] = sigma * u, sigma * f
        fail = _unloading_deterioration(st, f, work)
        st[BRANCH] = UNLOAD
        st[UREF], st[FREF] = u, f
        return fail
    moving = 1.0 if kind == KIND_UPPER else -1.0
    o_moving = _side(moving)
    if moving * u >= st[o_moving + UU]:
        return True
    if branch == ELASTIC:
        st[BRANCH], st[DIR] = HARDENING, moving
        return False
    if branch == UNLOAD:
        if st[FREF] * moving < 0.0:
            # The force reaches zero: a new excursion toward *moving*.
            sigma = moving
            o = _side(sigma)
            intercept, fail = _deteriorate(st, o, work, True)
            _place_capping_point(st, o, intercept)
            st[o + FGLO] = _backbone_force(st, o, st[o + UGLO])
            st[o + URES] = (st[o + FRES] - st[o + FCAP] + st[o + KPC] * st[o + UCAP]) / st[o + KPC]
            u0 = sigma * u
            k_global = st[o + FGLO] / (st[o + UGLO] - u0)
            k_local = _slope(st[o + FLOC], st[o + ULOC] - u0, -INF)  # 0/0 in OpenSees: NaN, never chosen
            st[DIR] = sigma
            if st[VARIANT] == V_PINCHING:
                u_plastic = st[o + UGLO] - st[o + FGLO] / st[KUN]
                u_pinch = (1.0 - st[KD]) * u_plastic
                f_pinch = st[KF] * st[o + FGLO] * (u_pinch - u0) / (st[o + UGLO] - u0)
                st[UPIN], st[FPIN] = sigma * u_pinch, sigma * f_pinch
            if st[VARIANT] == V_PINCHING and u0 < sigma * st[UPIN]:
                st[BRANCH], st[KRE] = PINCH, (sigma * st[FPIN]) / (sigma * st[UPIN] - u0)
            elif u0 < st[o + ULOC] and st[o + FLOC] < st[o + FGLO] and k_local > k_global:
                st[BRANCH], st[KRE] = LOCAL, k_local
            else:
                st[BRANCH], st[KRE] = GLOBAL, k_global
            if st[FGLO] == 0.0 or st[SIDE + FGLO] == 0.0:
                fail = True
        else:
            # Back past the last peak before the force changed sign: reload toward the global peak.
            sigma = 1.0 if st[FREF] > 0.0 else -1.0
            o = _side(sigma)
            st[DIR] = sigma
            st[BRANCH] = GLOBAL
            st[KRE] = _slope(st[o + FGLO] - st[o + FLOC], st[o + UGLO] - st[o + ULOC], st[KE])
            if st[VARIANT] == V_PINCHING:
                up, fp = sigma * st[UPIN], sigma * st[FPIN]
                k_pinch = _slope(fp - st[o + FLOC], up - st[o + ULOC], st[KE])
                if (st[o + ULOC] < up and st[o + FLOC] < fp and up < st[o + UGLO] and fp < st[o + FGLO]
                        and k_pinch < st[KRE]):
                    st[BRANCH], st[KRE] = PINCH, k_pinch
    _cascade(st, st[DIR] * u)
    if int(st[BRANCH]) == RESIDUAL and st[_side(st[DIR]) + FRES] <= 0.0:
        fail = True
    return fail


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _bilinear_event(st, kind, u, f, work):
    """IMKBilin: the state after an event of *kind* at drift *u*; returns a failure (zero strength)."""
    fail = False
    if kind == KIND_REVERSAL:
        st[ONBB] = 0.0
        fail = _unloading_deterioration(st, f, work)
        if st[RESID] > 0.0:
            st[KUN] = 0.5 * st[KE]
        st[UREF], st[FREF] = u, f
        return fail
    moving = 1.0 if kind == KIND_UPPER else -1.0
    o = _side(moving)
    x = moving * u
    if x >= st[o + UU]:
        return True
    if st[ONBB] > 0.0:
        # Along the backbone: past the capping point, into the residual branch.
        if st[o + KPC] != 0.0 and x >= st[o + URES]:
            st[RESID] = 1.0
        if _bilinear_backbone(st, o, x) <= 0.0:
            return True
        return False
    zero = st[UREF] - st[FREF] / st[KUN]
    if st[YIELDED] > 0.0 and st[FREF] != 0.0 and st[FREF] * moving < 0.0 and u == zero:
        # (u is the limit crossed, the very float _bilinear_limits wrote: equality identifies it)
        # The force reaches zero off the backbone: deteriorate the backbone ahead.
        intercept, fail = _deteriorate(st, o, work, False)
        if st[o + FY] < st[o + FRES]:
            st[o + KPC] = 0.0
        else:
            st[o + KPC] = st[o + KPC0] * (st[o + FY] - st[o + FRES]) / (st[o + FY0] - st[o + FRES])
        _place_capping_point(st, o, intercept)
        x_ref, g_ref = moving * st[UREF], moving * st[FREF]
        candidate = (st[o + FCAP] - st[o + FRES]) / (st[o + UCAP] - x_ref - (st[o + FRES] - g_ref) / st[KUN])
        if st[o + FCAP] < st[o + FRES]:
            st[o + FY] = st[o + FRES]
            st[o + FCAP] = st[o + FRES]
            st[o + KP] = 0.0
            st[o + KPC] = 0.0
            st[o + UY] = st[o + FY] / st[KE]
            st[o + UCAP] = 0.0
        elif 0.0 < candidate < st[o + KP]:
            st[o + KP] = candidate
        if st[o + KPC] != 0.0:
            st[o + URES] = (st[o + FRES] - st[o + FCAP] + st[o + KPC] * st[o + UCAP]) / st[o + KPC]
        # The unloading line continues through zero force.
        st[UREF], st[FREF] = u, 0.0
        return fail
    line = st[FREF] + st[KUN] * (u - st[UREF])
    if moving * line >= _bilinear_backbone(st, o, x) * (1.0 - ON_LINE_TOLERANCE):
        # The unloading/reloading line reaches the backbone.
        st[ONBB], st[DIR], st[YIELDED] = 1.0, moving, 1.0
        if st[o + KPC] != 0.0 and x >= st[o + URES]:
            st[RESID] = 1.0
        if _bilinear_backbone(st, o, x) <= 0.0:
            return True
        return False
    if st[o + KPC] != 0.0 and x >= st[o + URES]:
        st[RESID] = 1.0
    st[UREF], st[FREF] = u, line
    return False


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def apply_event(st, row, kind, u, f, rate):
    """Apply an event of *kind* (KIND_*) at drift *u* (m) with shear *f* (N) and drift rate *rate* (m/s):
    update the state *st* and the kernel row *row*; returns the shear (N) of the new branch at *u*.

    A limit the drift only touches (its rate not outward there, a grazing touch) changes nothing: the
    drift stays on the near side, where the limit is found again if it crosses later.

    The deterioration rules read the work ∫F dΔ, kept here exactly (the shear is affine in the drift
    between events: the trapezoid from the last event is exact) rather than the integrated work of the
    energy audit, which is outside the error norm.  A limit crossing is decided at the limit itself
    (``row[P_LOWER]`` or ``row[P_UPPER]``, the drift the event was located at, exactly); the new
    branch's shear is evaluated at *u*."""
    st[WORK] += 0.5 * (st[FLAST] + f) * (u - st[ULAST])
    st[ULAST], st[FLAST] = u, f
    work = st[WORK]
    if (kind == KIND_UPPER and rate <= 0.0) or (kind == KIND_LOWER and rate >= 0.0):
        return f
    at = u
    if kind == KIND_LOWER:
        at = row[P_LOWER]
    elif kind == KIND_UPPER:
        at = row[P_UPPER]
    if st[VARIANT] == V_BILINEAR:
        fail = _bilinear_event(st, kind, at, f, work)
    else:
        fail = _oriented_event(st, kind, at, f, work)
    if fail:
        st[FAILED] = 1.0
    force = set_row(st, row, u, at)
    st[ULAST], st[FLAST] = u, force
    return force


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def set_row(st, row, u, at):
    """Write the current branch's slope, unloading stiffness and limits into the kernel *row*; the
    shear (N) at drift *u*.  *at* (m): the drift the branch was decided at (the limit crossed; the
    located drift may fall a round-off short of it), where IMKBilin's backbone segment is read."""
    if st[FAILED] > 0.0:
        row[P_SLOPE], row[P_LOWER], row[P_UPPER], row[P_WATCH] = 0.0, -INF, INF, 0.0
        return 0.0
    if st[VARIANT] == V_BILINEAR:
        if st[ONBB] > 0.0:
            sigma = st[DIR]
            o = _side(sigma)
            x = sigma * at
            segment = st[o + KP] if x < st[o + UCAP] else st[o + KPC]
            line = st[o + FCAP] + (x - st[o + UCAP]) * segment
            if segment < 0.0:
                # Post-capping: the residual floor from its drift u_res on.  *at* is that limit exactly where the
                # residual is reached, so the drift decides; the line there is F_r only to round-off, and a line a
                # hair above F_r kept the falling slope past the floor, the shear through zero.
                on_line = x < st[o + URES]
            else:
                # At the rise onto the hardening line (line = F_r, rising) the line is ahead: its slope.
                on_line = line > st[o + FRES] or (segment > 0.0 and line >= st[o + FRES] * (1.0 - ON_LINE_TOLERANCE))
            slope = segment if on_line else 0.0
            st[UREF], st[FREF] = at, sigma * max(line, st[o + FRES])
            force = st[FREF] + slope * (u - at)
        else:
            force, slope = st[FREF] + st[KUN] * (u - st[UREF]), st[KUN]
        lower, upper, watch = _bilinear_limits(st)
    else:
        force, slope = branch_force(st, u)
        lower, upper, watch = _oriented_limits(st)
    row[P_SLOPE], row[P_UNLOAD], row[P_LOWER], row[P_UPPER], row[P_WATCH] = slope, st[KUN], lower, upper, watch
    return force


jit.stamp_solver_kernels(globals())
