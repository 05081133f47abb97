"""Contact and storey kinematics: the one place where δ, δ̇, storey drift and ground offsets are formed.

Contact sides are weighted floors (a floor, a point of a column, a fixed wall).
Contact c measures δ = Σ_k cw[c, k]·u[cf[c, k]] − gap over its terms, up to
TERMS_PER_SIDE per side (the left side's weights positive, the right side's
negative); a term with cf < 0 is the ground or a fixed wall (zero
displacement relative to the ground) and contributes nothing.  The contact
force F enters the floors with the same weights (fbuf[cf] += cw·F), so its
power is F·δ̇ exactly (virtual work): a floor is the term (floor, ±1); a point
at fraction ξ of a storey's height the two terms (floor below, ±N1(ξ)) and
(floor above, ±N2(ξ)); in a plan model a floor's point the terms (u_n, ±1)
and (θ, ±lever), and a point of a column between two floors the four
(u_n and θ of the floor below, ±N1 and ±N1·lever; of the floor above, ±N2 and
±N2·lever).  Plane drifts, yielding planes and friction faces are rows of the
same form.

The kernels get the terms flat (term k of row c at width·c + k, the left
side's in the first half of the row) and absent terms (floor −1) as floor 0
with weight 0, so every sum below is branch-free over a row's terms; 0·y[0]
adds an exact 0.  :func:`kernel_terms` lays an array out at NARROW_TERMS (two
terms per side: every model before sides of four terms, in exactly the layout
and arithmetic it always had) when it fits, else at SIDE_TERMS, and hands the
width over as :func:`row_width`, a value whose numba *type* is the width: the
kernels read it with ``len(width)``, a compile-time constant, so their loops
unroll as they did over the fixed four terms, each width is a compiled
specialisation of its own, and a run at the narrow width does the same
floating-point operations in the same order as before (docs/numerics.md,
"Contact sides as weighted floors").

With several supports (*ground* a :class:`~pounding.solver.layout.Grounds`,
None with one common ground) floors move relative to their own ground and the
contacts see total displacements: the differential ground motion of a
contact's two sides (:func:`ground_offset`) joins δ and δ̇, from ground
velocity and displacement integrated exactly from the piecewise-linear
accelerations (:func:`fill_grounds`, and :func:`ground_state_at` for the
results).  :func:`penetration` is the results' δ, by the solver's own
:func:`combo`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pounding.solver import jit

__all__ = ["SIDE_TERMS", "TERMS_PER_SIDE", "NARROW_TERMS", "row_width", "combo", "push", "compliance",
           "effective_mass", "floor_pair", "ground_weight", "ground_share", "kick", "ground_at",
           "fill_grounds", "ground_offset", "contact_sums", "contact_delta", "step_kinematics",
           "step_kinematics_inline", "drift",
           "drift_interpolant", "storey_drift", "storey_interpolant", "storey_push", "storey_rate_scale",
           "storey_stiffness", "ground_kinematics", "ground_state_at", "kernel_terms", "penetration"]

#: Most terms per contact (or plane, storey or friction row): four per side.
SIDE_TERMS = 8
#: Most terms per side: a row's left side is its first half, its right side the second.
TERMS_PER_SIDE = SIDE_TERMS // 2
#: Terms per row of the arrays whose sides all have at most two terms (every model before sides of
#: four terms): these run at this width, in the layout and with the sums they always had.
NARROW_TERMS = 4


def row_width(terms: int) -> tuple:
    """The kernels' mark of *terms* terms per row: a tuple of that many empty tuples.

    Its numba type (``UniTuple(Tuple(), terms)``) carries the number, so every loop over a row's
    terms has a compile-time trip count (``len(width)``; unrolled) and each width is its own
    compiled specialisation, while the value itself occupies no argument words.
    """
    return ((),) * int(terms)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def combo(y, offset, cf, cw, width, c) -> float:
    """Σ_k w_k·y[offset + f_k] over row *c*'s terms (δ + gap for offset 0, δ̇ for offset n), from the
    first term in order."""
    terms = len(width)
    first = terms * c
    total = cw[first] * y[offset + cf[first]]
    for k in range(first + 1, first + terms):
        total += cw[k] * y[offset + cf[k]]
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def push(fbuf, cf, cw, width, c, force) -> None:
    """Add contact force *force* (N, ≥ 0 pushes apart) to the floors' internal forces with the side weights."""
    terms = len(width)
    for k in range(terms * c, terms * c + terms):
        fbuf[cf[k]] += cw[k] * force


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def compliance(mass, cf, cw, width, c) -> float:
    """Σ_k cw²/m (1/kg): δ̈ per unit contact force; 1/m_eff of the contact (a wall adds nothing)."""
    terms = len(width)
    total = 0.0
    for k in range(terms * c, terms * c + terms):
        total += cw[k] * cw[k] / mass[cf[k]]
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def effective_mass(mass, cf, cw, width, c) -> float:
    """m_eff of contact *c* (kg): ``1/Σ cw²/m``; a plain floor pair as ``m_L·m_R/(m_L + m_R)``.

    The floor pair's form is the one the solver used before contact sides
    became weighted sums: it keeps a floor-to-floor run bit for bit the same
    (the two forms differ in the last bit for some masses).
    """
    if floor_pair(cw, width, c):
        first = len(width) * c
        ml = mass[cf[first]]
        mr = mass[cf[first + len(width) // 2]]
        return ml * mr / (ml + mr)
    return 1.0 / compliance(mass, cf, cw, width, c)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def floor_pair(cw, width, c) -> bool:
    """True if contact *c* is a plain floor pair: weights ``(1, 0, …)`` on its left side, ``(−1, 0, …)`` on its right."""
    half = len(width) // 2
    left = len(width) * c
    if cw[left] != 1.0 or cw[left + half] != -1.0:
        return False
    for k in range(left + 1, left + half):
        if cw[k] != 0.0 or cw[k + half] != 0.0:
            return False
    return True


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def ground_weight(cw, width, c) -> float:
    """Σ_k cw over the floor terms, from the first: 0 between two buildings, ±1 against a wall (a_g's share in δ̈)."""
    terms = len(width)
    first = terms * c
    total = cw[first]
    for k in range(first + 1, first + terms):
        total += cw[k]
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def ground_share(cw, width, c, side) -> float:
    """``1 − W_L`` (*side* 1.0) or ``1 + W_R`` (*side* −1.0), W the sum of that side's weights (W_R ≤ 0),
    taken term by term from 1: the part of a side's own ground acceleration that its floor terms do
    not carry (0 for a floor, 1 for a wall; :func:`pounding.solver.rhs.stuck_constraints`)."""
    half = len(width) // 2
    first = len(width) * c + (0 if side > 0.0 else half)
    share = 1.0
    for k in range(first, first + half):
        share -= side * cw[k]  # ±1·w is exact, and x − (−w) is x + w to the bit
    return share


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def kick(y, n, mass, cf, cw, width, c, impulse) -> None:
    """Apply an impulse *impulse* (N·s, ≥ 0 pushes apart) of contact *c* to the floor velocities."""
    terms = len(width)
    for k in range(terms * c, terms * c + terms):
        y[n + cf[k]] -= cw[k] * impulse / mass[cf[k]]


# --------------------------------------------------------------------------- #
# Ground motion and storey drift
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def ground_at(ag: np.ndarray, dt_rec: float, seg: int, t: float) -> float:
    """Piecewise-linear ground acceleration inside segment *seg* at time *t*."""
    t0 = seg * dt_rec
    if seg + 1 >= ag.size:
        return ag[ag.size - 1]
    return ag[seg] + (ag[seg + 1] - ag[seg]) * ((t - t0) / dt_rec)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def fill_grounds(ground, dt_rec, seg, t, gstate):
    """Acceleration, velocity and displacement of every ground at time *t* into *gstate* (3, G).

    The acceleration is piecewise linear as :func:`ground_at`; velocity and displacement are its
    exact integrals from rest (quadratic and cubic in a record step; their sample values in
    ``ground.velocity`` and ``ground.displacement``).
    """
    ag = ground.acceleration
    ug = ground.displacement
    vg = ground.velocity
    for g in range(ag.shape[0]):
        row = ag[g]
        gstate[0, g] = ground_at(row, dt_rec, seg, t)
        k = min(seg, row.size - 1)
        tau = t - k * dt_rec
        a0 = row[k]
        slope = (row[k + 1] - a0) / dt_rec if k + 1 < row.size else 0.0
        gstate[1, g] = vg[g, k] + a0 * tau + 0.5 * slope * tau * tau
        gstate[2, g] = ug[g, k] + vg[g, k] * tau + 0.5 * a0 * tau * tau + slope * tau * tau * tau / 6.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def ground_offset(ground, gstate, c, row):
    """Differential ground motion of contact *c*: ground of its left side minus ground of its right side.

    *row* 2: displacement (m), 1: velocity (m/s), 0: acceleration (m/s²) of the ground state
    *gstate*.  This is the one place where the supports' motion enters the contact kinematics:
    ``δ = Σ_k w_k·u[f_k] + (u_g,L − u_g,R) − gap`` with ``u`` relative to each floor's own ground
    (the rows ``ground.left_row``, ``ground.right_row``: a side's building's ground; a wall's, the ground of the
    building it faces, so a wall contact's offset is 0).
    """
    return gstate[row, ground.left_row[c]] - gstate[row, ground.right_row[c]]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def step_kinematics(y, ynew, k1, k7, n, cf, cw, width, c, ground):
    """Contact *c*'s ``Σ w·u`` (gap not subtracted) over an accepted or trial step: its value, rate
    and acceleration at both ends ``(d0, r0, d1, r1, a0, a1)`` and the round-off scale ``Σ |w·u|``
    at the start.  Sums over the contact's floor terms, plus the differential ground motion with
    several grounds (ground states ``ground.start`` at the step's start, ``ground.end`` at its end).
    The interpolants are linear in the data, so the contact's Hermite cubic is that of these sums.
    """
    d0 = 0.0
    r0 = 0.0
    d1 = 0.0
    r1 = 0.0
    a0 = 0.0
    a1 = 0.0
    size = 0.0
    terms = len(width)
    for k in range(terms * c, terms * c + terms):
        w = cw[k]
        f = cf[k]
        d0 += w * y[f]
        r0 += w * y[n + f]
        d1 += w * ynew[f]
        r1 += w * ynew[n + f]
        a0 += w * k1[n + f]
        a1 += w * k7[n + f]
        size += abs(w * y[f])
    if ground is not None:
        d0 += ground_offset(ground, ground.start, c, 2)
        r0 += ground_offset(ground, ground.start, c, 1)
        a0 += ground_offset(ground, ground.start, c, 0)
        d1 += ground_offset(ground, ground.end, c, 2)
        r1 += ground_offset(ground, ground.end, c, 1)
        a1 += ground_offset(ground, ground.end, c, 0)
    return d0, r0, d1, r1, a0, a1, size


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def contact_sums(y, n, cf, cw, width, c):
    """Contact *c*'s ``(Σ w·u, Σ w·v)`` of state *y* (its δ + gap and δ̇ without the ground offsets),
    summed term by term from 0 (the right-hand side's form, as :func:`step_kinematics`)."""
    delta = 0.0
    rate = 0.0
    terms = len(width)
    for k in range(terms * c, terms * c + terms):
        delta += cw[k] * y[cf[k]]
        rate += cw[k] * y[n + cf[k]]
    return delta, rate


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def contact_delta(y, contacts, ground, c) -> float:
    """Penetration δ of contact *c* (m) in state *y*: ``Σ w·u`` (:func:`combo`), plus the
    differential ground displacement of ``ground.now`` with several grounds, minus the gap."""
    if ground is not None:
        return combo(y, 0, contacts.floors, contacts.weights, contacts.width, c) \
            + ground_offset(ground, ground.now, c, 2) - contacts.gap[c]
    return combo(y, 0, contacts.floors, contacts.weights, contacts.width, c) - contacts.gap[c]


step_kinematics_inline = njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, inline="always",
                              **jit.NO_REFCOUNT)(step_kinematics.py_func)
""":func:`step_kinematics` inlined: for the event search, which runs it for every contact at every step
(as a call it measured ~5 % slower on pair.yaml, min of 6 alternated runs, 9.2 against 8.7 ms)."""


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def drift(y, offset, j, b) -> float:
    """Drift of the storey under floor *j* (floor below *b*, −1 for the ground) from ``y[offset:]``.

    ``y[offset + j] − y[offset + b]``: the drift (offset 0) or its rate (offset N) of a state.
    """
    return y[offset + j] - y[offset + b] if b >= 0 else y[offset + j]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def drift_interpolant(y, ynew, k1, k7, n, j, b):
    """Drift and drift rate of the storey under floor *j* at both ends of a step, and their rates."""
    if b >= 0:
        return (y[j] - y[b], y[n + j] - y[n + b], ynew[j] - ynew[b], ynew[n + j] - ynew[n + b],
                k1[n + j] - k1[n + b], k7[n + j] - k7[n + b])
    return y[j], y[n + j], ynew[j], ynew[n + j], k1[n + j], k7[n + j]


# Storey rows: the storeys of shear buildings (*terms* None: drift u[j] − u[below[j]]) or a plan model's
# planes (*terms* a layout.StoreyTerms: a weighted sum of floor DOF, ``terms.width`` terms per row).  Called, not
# inlined, so that each is compiled per type of *terms*: numba prunes the other branch, and the shear
# buildings' arithmetic is :func:`drift`'s, bit for bit.


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def storey_drift(y, offset, terms, below, j) -> float:
    """Drift (offset 0, m) or drift rate (offset N, m/s) of storey row *j* of state *y*."""
    if terms is None:
        return drift(y, offset, j, below[j])
    return combo(y, offset, terms.floors, terms.weights, terms.width, j)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def storey_interpolant(y, ynew, k1, k7, n, terms, below, j):
    """:func:`drift_interpolant` of storey row *j*: drift and drift rate at both ends of a step, their rates."""
    if terms is None:
        return drift_interpolant(y, ynew, k1, k7, n, j, below[j])
    d0, r0, d1, r1, a0, a1, _ = step_kinematics(y, ynew, k1, k7, n, terms.floors, terms.weights, terms.width, j,
                                                None)
    return d0, r0, d1, r1, a0, a1


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def storey_push(fbuf, terms, below, j, force) -> None:
    """Add storey row *j*'s shear *force* (N) to the floor forces: +F on the floor above, −F on the one
    below; a plane's ``w·F`` on each of its terms (virtual work, :func:`push`)."""
    if terms is None:
        fbuf[j] += force
        b = below[j]
        if b >= 0:
            fbuf[b] -= force
        return
    push(fbuf, terms.floors, terms.weights, terms.width, j, force)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def storey_rate_scale(y, n, terms, below, j) -> float:
    """Σ |w·v| over storey row *j*'s terms (m/s): the round-off scale of its drift rate."""
    if terms is None:
        b = below[j]
        return abs(y[n + j]) + (abs(y[n + b]) if b >= 0 else 0.0)
    f, w, width = terms.floors, terms.weights, len(terms.width)
    total = 0.0
    for k in range(width * j, width * j + width):
        total += abs(w[k] * y[n + f[k]])
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def storey_stiffness(kst, terms, j) -> float:
    """Elastic stiffness of storey row *j*, N/m: ``kst[j]`` (the floors' storey springs) or the plane's."""
    if terms is None:
        return kst[j]
    return terms.stiffness[j]


# --------------------------------------------------------------------------- #
# The same kinematics for the results (NumPy)
# --------------------------------------------------------------------------- #


def ground_kinematics(acceleration: np.ndarray, time_step: float) -> tuple[np.ndarray, np.ndarray]:
    """Ground velocity and displacement at the samples of piecewise-linear accelerations, from rest.

    Parameters
    ----------
    acceleration : (G, ns) ndarray
        Ground accelerations, m/s², one row per ground, uniform step *time_step* (s).

    Returns
    -------
    velocity, displacement : (G, ns) ndarray
        m/s and m: the exact integrals (trapezoid for the velocity; for the
        displacement ``u_{k+1} = u_k + v_k·dt + dt²·(a_k/3 + a_{k+1}/6)``), so
        that between samples the velocity is the quadratic and the
        displacement the cubic the solver evaluates (:func:`fill_grounds`).
    """
    a = np.atleast_2d(np.asarray(acceleration, dtype=float))
    dt = float(time_step)
    velocity = np.zeros_like(a)
    displacement = np.zeros_like(a)
    velocity[:, 1:] = np.cumsum(0.5 * dt * (a[:, :-1] + a[:, 1:]), axis=1)
    displacement[:, 1:] = np.cumsum(dt * velocity[:, :-1] + dt * dt * (a[:, :-1] / 3.0 + a[:, 1:] / 6.0), axis=1)
    return velocity, displacement


def ground_state_at(acceleration: np.ndarray, time_step: float, times: np.ndarray) -> tuple[np.ndarray, ...]:
    """Ground acceleration, velocity and displacement of every row at *times*, as the solver sees them.

    Parameters
    ----------
    acceleration : (G, ns) ndarray
        The ground-acceleration rows given to :func:`integrate`, m/s².
    time_step : float
        Their sampling interval, s.
    times : (nt,) ndarray
        s.

    Returns
    -------
    acceleration, velocity, displacement : (nt, G) ndarray
        m/s², m/s, m: piecewise linear, quadratic and cubic from rest (past the
        last sample the last acceleration is held, as in the solver).
    """
    a = np.atleast_2d(np.asarray(acceleration, dtype=float))
    velocity, displacement = ground_kinematics(a, time_step)
    t = np.asarray(times, dtype=float)
    k = np.minimum(np.floor(t / time_step + 1e-9).astype(np.int64), a.shape[1] - 1)
    k = np.maximum(k, 0)
    tau = (t - k * time_step)[:, None]
    a0 = a[:, k].T
    nxt = np.minimum(k + 1, a.shape[1] - 1)
    slope = np.where((k + 1 < a.shape[1])[:, None], (a[:, nxt].T - a0) / time_step, 0.0)
    acc = a0 + slope * tau
    vel = velocity[:, k].T + a0 * tau + 0.5 * slope * tau ** 2
    disp = displacement[:, k].T + velocity[:, k].T * tau + 0.5 * a0 * tau ** 2 + slope * tau ** 3 / 6.0
    return acc, vel, disp


def kernel_terms(floors: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Terms as the kernels take them: flat, term k of row c at ``width·c + k``, an absent term
    (floor −1: the ground, a wall; or weight 0) as floor 0 with weight 0.

    The width is NARROW_TERMS (two terms per side) when no row has a side of more than two
    terms, the layout every model had before sides of four terms existed (the same arrays, so the
    same sums, bit for bit), else SIDE_TERMS (four per side): only arrays that need the wider
    rows pay for them.  A side with fewer terms is padded after its own with absent terms
    (each adds an exact 0 to the sums); terms absent from every row past a side's second are dropped.

    Parameters
    ----------
    floors : (rows, 2·t) int
        Floor of each term, the left side's t terms then the right side's (1 ≤ t ≤ TERMS_PER_SIDE),
        −1 for none.
    weights : (rows, 2·t) float
        Their weights (left ≥ 0, right ≤ 0; a plane's or friction face's as their rows define them).

    Returns
    -------
    floors, weights : (rows·width,) int and float
    width : tuple
        :func:`row_width` of the width (NARROW_TERMS or SIDE_TERMS), the kernels' mark of it.
    """
    weights = np.asarray(weights, dtype=float)
    floors = np.asarray(floors, dtype=np.int64)
    if weights.ndim != 2 or floors.shape != weights.shape or weights.shape[1] % 2 \
            or not 0 < weights.shape[1] <= SIDE_TERMS:
        raise ValueError(f"terms of shapes {floors.shape} and {weights.shape}: expected one (rows, 2·t) shape "
                         f"with 1 ≤ t ≤ {TERMS_PER_SIDE} terms per side")
    rows, given = weights.shape[0], weights.shape[1] // 2
    half = NARROW_TERMS // 2
    if given > half:
        sides = weights.reshape(rows, 2, given)
        if sides[:, :, half:].any():
            half = TERMS_PER_SIDE
        else:  # a side's terms past the second are absent in every row: the narrow layout
            weights = sides[:, :, :half].reshape(rows, 2 * half)
            floors = floors.reshape(rows, 2, given)[:, :, :half].reshape(rows, 2 * half)
    if given < half:  # each side's own terms, then absent ones
        padded = np.zeros((rows, 2, half))
        padded[:, :, :given] = weights.reshape(rows, 2, given)
        weights = padded.reshape(rows, 2 * half)
        padded = np.zeros((rows, 2, half), dtype=np.int64)
        padded[:, :, :given] = floors.reshape(rows, 2, given)
        floors = padded.reshape(rows, 2 * half)
    flat_floors = np.ascontiguousarray(np.where(weights == 0.0, 0, floors), dtype=np.int64).reshape(-1)
    return flat_floors, np.ascontiguousarray(weights, dtype=float).reshape(-1), row_width(2 * half)


def penetration(u: np.ndarray, floors: np.ndarray, weights: np.ndarray, gap: np.ndarray,
                ground_difference: np.ndarray) -> np.ndarray:
    """(nt, nc) penetration ``Σ_k w_k·u[floor_k] + u_g,L − u_g,R − gap`` of every contact, m.

    The solver's own :func:`combo` (its Python body, on whole histories), so
    the terms are summed in the solver's order.

    Parameters
    ----------
    u : (nt, N) ndarray
        Floor displacements relative to each floor's ground, m.
    floors, weights : (nc, 2·t) ndarray
        The contacts' floor terms, t ≤ TERMS_PER_SIDE per side (padded by :func:`kernel_terms`).
    gap : (nc,) ndarray
        m.
    ground_difference : (nt, nc) ndarray
        Displacement of the ground under each contact's left side minus its right side's, m.
    """
    cf, cw, width = kernel_terms(floors, weights)
    histories = np.ascontiguousarray(np.asarray(u, dtype=float).T)  # histories[f]: floor f's displacement
    out = np.empty((histories.shape[1], gap.size))
    for c in range(gap.size):
        out[:, c] = combo.py_func(histories, 0, cf, cw, width, c) + ground_difference[:, c] - gap[c]
    return out


jit.stamp_solver_kernels(globals())
