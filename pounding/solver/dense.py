"""Dense output of an accepted step: the cubic Hermite interpolant, its extrema and its exact crossings.

A step of length *h* from a value ``y0`` with rate ``r0`` to ``y1`` with rate
``r1`` is interpolated by the cubic Hermite polynomial of these four numbers
(Hairer, Nørsett & Wanner 1993, §II.6).  The interpolants are linear in the
data, so a weighted sum of states (a contact's δ, a storey's drift) has the
Hermite cubic of the weighted sums.
"""

from __future__ import annotations

import math

from numba import njit

from pounding.solver import jit

__all__ = ["DELTA_ROUNDOFF", "hermite", "hermite_rate", "stationary_points", "interpolate", "extremum_in_step",
           "cubic_max", "rate_root", "first_crossing"]

#: Grazing floor: an overlap smaller than this multiple of the round-off of
#: δ = u_L − u_R − gap (``eps·(|u_L| + |u_R| + gap)``) is indistinguishable from zero and is
#: not an impact; every larger overlap of the step's interpolant is found exactly.
DELTA_ROUNDOFF = 8.0 * 2.220446049250313e-16


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def hermite(y0: float, r0: float, y1: float, r1: float, h: float, s: float) -> float:
    """Cubic Hermite value at fraction *s* of a step of length *h*."""
    s2 = s * s
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * y0 + (s3 - 2.0 * s2 + s) * h * r0
            + (-2.0 * s3 + 3.0 * s2) * y1 + (s3 - s2) * h * r1)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def hermite_rate(y0: float, r0: float, y1: float, r1: float, h: float, s: float) -> float:
    """Rate of the Hermite cubic at fraction *s* of a step of length *h*, per second."""
    s2 = s * s
    return ((6.0 * s2 - 6.0 * s) * y0 / h + (3.0 * s2 - 4.0 * s + 1.0) * r0
            + (-6.0 * s2 + 6.0 * s) * y1 / h + (3.0 * s2 - 2.0 * s) * r1)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def stationary_points(y0: float, r0: float, y1: float, r1: float, h: float) -> tuple[float, float]:
    """Fractions of the step where the Hermite cubic's rate vanishes, ascending; 2.0 for a root that
    does not exist (the rate is a quadratic in s, its roots taken in the numerically stable form)."""
    qa = 6.0 * y0 + 3.0 * h * r0 - 6.0 * y1 + 3.0 * h * r1
    qb = -6.0 * y0 - 4.0 * h * r0 + 6.0 * y1 - 2.0 * h * r1
    qc = h * r0
    s_a = 2.0
    s_b = 2.0
    if abs(qa) < 1e-300:
        if abs(qb) > 1e-300:
            s_a = -qc / qb
    else:
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            q = -0.5 * (qb + math.copysign(math.sqrt(disc), qb))
            s_a = q / qa
            s_b = qc / q if q != 0.0 else 2.0
    if s_a > s_b:
        s_a, s_b = s_b, s_a
    return s_a, s_b


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def extremum_in_step(y0: float, r0: float, y1: float, r1: float, h: float) -> float:
    """Largest |y| of the Hermite cubic at its interior stationary points (0 if none)."""
    s_a, s_b = stationary_points(y0, r0, y1, r1, h)
    best = 0.0
    if 0.0 < s_a < 1.0:
        best = abs(hermite(y0, r0, y1, r1, h, s_a))
    if 0.0 < s_b < 1.0:
        val = abs(hermite(y0, r0, y1, r1, h, s_b))
        if val > best:
            best = val
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def cubic_max(y0: float, r0: float, y1: float, r1: float, h: float) -> float:
    """Largest value (signed) of the Hermite cubic over the step: its ends and interior stationary points."""
    s_a, s_b = stationary_points(y0, r0, y1, r1, h)
    best = max(y0, y1)
    if 0.0 < s_a < 1.0:
        best = max(best, hermite(y0, r0, y1, r1, h, s_a))
    if 0.0 < s_b < 1.0:
        best = max(best, hermite(y0, r0, y1, r1, h, s_b))
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def rate_root(y0: float, r0: float, y1: float, r1: float, h: float) -> float:
    """Fraction of the step where the Hermite cubic's rate changes sign, for ``r0·r1 < 0`` (exactly one
    root inside): bisected to 1e-12 of the step."""
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        rate = hermite_rate(y0, r0, y1, r1, h, mid)
        if (rate > 0.0) == (r0 > 0.0):
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-12:
            break
    return 0.5 * (lo + hi)


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)  # with a Python wrapper: tested directly
def first_crossing(d0: float, r0: float, d1: float, r1: float, h: float, upward: bool,
                    threshold: float) -> float:
    """Fraction of the step where the Hermite cubic of δ first crosses into the far side.

    The far side is ``δ > threshold`` for *upward* (gap closure), ``δ < −threshold``
    otherwise (separation); *threshold* (m, ≥ 0) is the grazing floor.  An event
    is a crossing **from the near side**: a step that starts on the far side
    moving further in (``±r0 > 0``, the residual of an event located just
    past its instant) returns 0, one that starts on the far side moving back
    (an open contact still overlapping while it opens, e.g. just after an
    instantaneous impact) has no event until it has returned to the near side.

    Exact on the interpolant: the cubic is split at its interior stationary
    points into monotone pieces, so an excursion to the far side of any
    depth above *threshold* is found, however short; the root in the first
    piece that ends on the far side is bisected to ~1e-15 of the step and the
    end of the bracket on the far side is returned (the retaken step ends
    just past the event).  Returns −1 if there is no event.
    """
    sign = 1.0 if upward else -1.0
    f0 = sign * d0 - threshold
    if f0 > 0.0 and sign * r0 > 0.0:
        return 0.0
    # ±δ stays below max(±d0, ±d1) + (4/27)·h·(|r0| + |r1|) on the step (the Hermite basis
    # functions' bounds): a step that cannot reach the far side needs no search (most steps).
    if max(sign * d0, sign * d1) + 0.25 * h * (abs(r0) + abs(r1)) <= threshold:
        return -1.0
    s_a, s_b = stationary_points(d0, r0, d1, r1, h)
    near = f0 <= 0.0
    lo = 0.0
    for piece in range(3):
        if piece == 0:
            hi = s_a
        elif piece == 1:
            hi = s_b
        else:
            hi = 1.0
        if not (lo < hi < 1.0) and piece < 2:
            continue
        f_hi = sign * (d1 if hi == 1.0 else hermite(d0, r0, d1, r1, h, hi)) - threshold
        if near and f_hi > 0.0:
            a = lo
            b = hi
            for _ in range(80):
                mid = 0.5 * (a + b)
                if sign * hermite(d0, r0, d1, r1, h, mid) - threshold > 0.0:
                    b = mid
                else:
                    a = mid
                if b - a < 1e-15:
                    break
            return b
        if f_hi <= 0.0:
            near = True
        lo = hi
    return -1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def interpolate(work, h, s, out) -> None:
    """The state at fraction *s* of the trial step of *h* s in ``work`` (a :class:`~pounding.solver.layout.Work`)
    into *out*: every state's Hermite cubic from its values and rates (``K[0]``, ``K[6]``) at both ends."""
    y, ynew, k1, k7 = work.y, work.ynew, work.K[0], work.K[6]
    for i in range(y.size):
        out[i] = hermite(y[i], k1[i], ynew[i], k7[i], h, s)


jit.stamp_solver_kernels(globals())
