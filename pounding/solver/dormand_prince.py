"""The Dormand–Prince 5(4) pair: tableau, stages, the one error norm and the step-size control.

The embedded Runge–Kutta pair of Dormand & Prince (1980), the method of
``scipy.integrate.RK45``, with step control after Hairer, Nørsett & Wanner
(1993), §II.4.  The error norm is a max norm over the states in a
per-state tolerance vector built once per run (:func:`fill_tolerances`):
displacements, velocities, the contact laws' internal states and the
storeys' hysteretic states; the energy-audit quadratures are left out
(they integrate a controlled solution).

References
----------
Dormand, J.R. & Prince, P.J. (1980). A family of embedded Runge-Kutta
formulae. J. Comput. Appl. Math. 6, 19-26.
Hairer, E., Nørsett, S.P. & Wanner, G. (1993). Solving Ordinary Differential
Equations I, 2nd ed., §II.4 (step control) and §II.6 (dense output).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pounding.solver import jit
from pounding.solver import kernels
from pounding.solver.kinematics import fill_grounds, ground_at
from pounding.solver.rhs import rhs

__all__ = ["STAGE_TIME", "SAFETY", "MIN_FACTOR", "MAX_FACTOR", "EXCLUDED", "stages", "fill_tolerances",
           "normed_states", "error_norm", "step_factor"]

# Dormand–Prince 5(4) tableau.
C2, C3, C4, C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
A21 = 1 / 5
A31, A32 = 3 / 40, 9 / 40
A41, A42, A43 = 44 / 45, -56 / 15, 32 / 9
A51, A52, A53, A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
A61, A62, A63, A64, A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
B1, B3, B4, B5, B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
E1, E3, E4, E5, E6, E7 = 71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40
#: Time of each stage within a step, as a fraction of it (stage s + 1 at t + STAGE_TIME[s]·h; the
#: last two at the step's end).
STAGE_TIME = np.array([0.0, C2, C3, C4, C5, 1.0, 1.0])

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 5.0
#: Absolute tolerance of a state left out of the error norm.
EXCLUDED = -1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def stages(work, h, t, seg, forcing, lay, structure, contacts, cstate, storey, ground, friction):
    """Stages 2–7 of a Dormand–Prince step of size *h* from ``work.y`` at *t* (stage 1, ``K[0]``, given).

    Fills ``K[1..6]`` and the 5th-order solution ``work.ynew`` (stage 7 is its rate: first same as
    last); *seg* is the record step the step lies in (*forcing*: the ground acceleration record).
    One call per attempted step (itself inlined into the driver, :data:`jit.INLINED`), with the
    right-hand side inlined once, in its loop: six calls of :func:`rhs`, each passing its ~30
    arrays, cost more than their arithmetic.  The weighted sums are written out per
    stage (they vectorise; a loop over the tableau did not).
    """
    y, ynew, ystage, K, fbuf, forces = work.y, work.ynew, work.ystage, work.K, work.fbuf, work.forces
    ag, dt_rec = forcing.acceleration, forcing.record_step
    S = y.size
    k1, k2, k3, k4, k5, k6 = K[0], K[1], K[2], K[3], K[4], K[5]
    for stage in range(1, 7):
        target = ystage
        if stage == 1:
            for i in range(S):
                ystage[i] = y[i] + h * A21 * k1[i]
        elif stage == 2:
            for i in range(S):
                ystage[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i])
        elif stage == 3:
            for i in range(S):
                ystage[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
        elif stage == 4:
            for i in range(S):
                ystage[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
        elif stage == 5:
            for i in range(S):
                ystage[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
        else:
            target = ynew
            for i in range(S):
                ynew[i] = y[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
        at = t + STAGE_TIME[stage] * h
        if ground is not None:
            fill_grounds(ground, dt_rec, seg, at, ground.now)
        rhs(target, ground_at(ag, dt_rec, seg, at), lay, structure, contacts, cstate, K[stage], fbuf, forces,
                   storey, ground, friction)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def fill_tolerances(tol, lay, contacts, atol, atol_velocity, floor_factor, storey) -> None:
    """Each state's absolute tolerance into *tol* (S,): *atol* (m) for displacements, *atol_velocity*
    (m/s) for velocities, each times its floor's *floor_factor* (:mod:`pounding.solver.tolerances`),
    each contact law's internal tolerance (:func:`kernels.internal_tolerance`;
    none: EXCLUDED), each yielding storey's ``storey.tolerance``; EXCLUDED for the energy quadratures."""
    for i in range(tol.size):
        tol[i] = EXCLUDED
    n = lay.n_floors
    for i in range(n):
        tol[i] = atol * floor_factor[i]
        tol[n + i] = atol_velocity * floor_factor[i]
    for c in range(lay.n_contacts):
        internal = kernels.internal_tolerance(contacts.law[c], contacts.parameters[c], atol)
        if internal > 0.0:
            tol[lay.internal + c] = internal
    if storey is not None:
        for hi in range(lay.n_hysteretic):
            tol[lay.hysteretic + hi] = storey.tolerance[hi]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def normed_states(tol):
    """Indices of the states in the error norm (*tol* from :func:`fill_tolerances` not EXCLUDED), ascending."""
    count = 0
    for i in range(tol.size):
        if tol[i] >= 0.0:
            count += 1
    index = np.empty(count, dtype=np.int64)
    count = 0
    for i in range(tol.size):
        if tol[i] >= 0.0:
            index[count] = i
            count += 1
    return index


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def error_norm(work, h, tol, normed, rtol):
    """``(err, finite)``: the max over the states of |local error| / (tol + rtol·max(|y|, |y_new|)).

    *tol* from :func:`fill_tolerances`, *normed* the states it does not exclude (:func:`normed_states`:
    a loop over them only, in order, costs no branch per state); *finite* is False (and *err*
    meaningless) as soon as one ratio is not finite: the step is rejected and shrunk.
    """
    y, ynew, K = work.y, work.ynew, work.K
    k1, k3, k4, k5, k6, k7 = K[0], K[2], K[3], K[4], K[5], K[6]
    err = 0.0
    for m in range(normed.size):
        i = normed[m]
        e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
        r = abs(e) / (tol[i] + rtol * max(abs(y[i]), abs(ynew[i])))
        if not (r < 1e300):
            return err, False
        if r > err:
            err = r
    return err, True


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def step_factor(err, finite, rejected):
    """Factor of the next step size after a step with error norm *err* (Hairer et al. §II.4):
    shrink a rejected step (err > 1 or not *finite*), grow an accepted one, but not right after
    a rejection (*rejected*)."""
    if not finite:
        return MIN_FACTOR
    if err > 1.0:
        return max(MIN_FACTOR, SAFETY * err ** -0.2)
    factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** -0.2)
    if rejected:
        factor = min(factor, 1.0)  # no growth right after a rejection
    return factor


jit.stamp_solver_kernels(globals())
