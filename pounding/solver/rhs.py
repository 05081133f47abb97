"""The right-hand side of the equation of motion (docs/physics.md §1) and the stuck contacts' constraint forces.

    M ü + C u̇ + K u + f_contact(u, u̇) = −M 1 a_g(t)

Storey springs and Rayleigh damping act through the tridiagonal structure
(O(n) per evaluation); only modal damping, on request, adds a dense block per
building, and a plan model's buildings their banded damping and stiffness
blocks (its planes and P-Delta terms, :mod:`pounding.solver.plan_assembly`).
The energy audit's rates (input and damped power, each contact's force and power, each yielding storey's power, the ground work) are written
with the motion's (:mod:`pounding.solver.layout`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pounding.solver import jit
from pounding.solver import kernels
from pounding.solver import storeys
from pounding.solver.dense import interpolate
from pounding.solver.friction_forces import friction_forces
from pounding.solver.kinematics import (compliance, contact_sums, drift, fill_grounds, ground_at, ground_offset,
                                        ground_share, ground_weight, push, storey_drift, storey_push, storey_stiffness)

__all__ = ["stuck_constraints", "rhs", "rhs_called", "rates_within_step", "storey_forces"]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def stuck_constraints(ag_t, mass, contacts, cstate, fbuf, forces, ground):
    """Constraint forces of stuck contacts (added to *forces* and *fbuf*): make every δ̈ = 0.

    Gauss–Seidel sweeps, exact in one when no two stuck contacts share a floor.
    a_g is common to both floors of a pair and cancels; against a wall it
    stays (the wall moves with the ground).  With several grounds (*ground* not
    None) a side's total acceleration is ``Σ w·(−fbuf/m − a_g,side) + a_g,side``
    (its weights sum to 1 with the ground's share of a storey-1 column point),
    so δ̈ = Σ_k w_k·(−fbuf_k/m_k) + a_g,L·(1 − W_L) − a_g,R·(1 + W_R) with W_L, W_R
    the sums of the left and right floor weights.  Kept out of :func:`rhs` (rarely needed).
    """
    cf, cw, width = contacts.floors, contacts.weights, contacts.width
    stride = len(width)
    closed, cmode = cstate.closed, cstate.mode
    nc = forces.size
    for _ in range(100):
        largest = 0.0
        scale = 0.0
        for c in range(nc):
            if closed[c] and cmode[c] == kernels.MODE_STUCK:
                # δ̈ = Σ_k cw·(−fbuf/m − a_g) over the floor terms
                if ground is None:
                    relative = -ag_t * ground_weight(cw, width, c)
                else:
                    gnow = ground.now
                    relative = (gnow[0, ground.left_row[c]] * ground_share(cw, width, c, 1.0)
                                - gnow[0, ground.right_row[c]] * ground_share(cw, width, c, -1.0))
                for k in range(stride * c, stride * c + stride):
                    relative -= cw[k] * (fbuf[cf[k]] / mass[cf[k]])
                change = relative / compliance(mass, cf, cw, width, c)
                forces[c] += change
                push(fbuf, cf, cw, width, c, change)
                largest = max(largest, abs(change))
                scale = max(scale, abs(forces[c]))
        if largest <= 1e-13 * scale:
            break


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def rhs(y, ag_t, lay, structure, contacts, cstate, out, fbuf, forces, storey, ground, friction):
    """Time derivative of the state; contact forces are written to *forces*.

    With several grounds (*ground* not None) each floor takes its own ground's
    acceleration and the contacts the differential ground motion of ``ground.now``
    (the ground state at this time, filled by the caller); *ag_t* is then unused.

    A closed compliant contact acts through its law in its current mode
    (:func:`pounding.contact.mode_force`).  A persistent (stuck) contact of an
    instantaneous law is a constraint ``δ̈ = 0``: its force is whatever keeps
    the two floors moving together, found by Gauss–Seidel sweeps (exact in one
    sweep when no two stuck contacts share a floor); it may come out tensile,
    which the solver locates as the release event.  *lay*: the state's
    :class:`~pounding.solver.layout.Layout`.  *friction* (None without friction faces, pruned):
    the faces' Coulomb friction after every contact force (:mod:`pounding.solver.friction_forces`).
    """
    mass, kst, below, a0, a1 = (structure.mass, structure.storey_stiffness, structure.below, structure.rayleigh_mass,
                                structure.rayleigh_stiffness)
    dstart, dsize, doff = structure.dense_start, structure.dense_size, structure.dense_offset
    dvals = structure.dense_values
    dband, dstiff = structure.dense_band, structure.dense_stiffness
    cf, cw, cwidth, cgap, claw, cprm = contacts
    stride = len(cwidth)
    closed, cconst, cmode = cstate.closed, cstate.constant, cstate.mode
    n = mass.size
    nc = cgap.size
    impulse, work, internal = lay.impulse, lay.work, lay.internal
    # fbuf[:n] accumulates internal + damping forces (N); power is the
    # damping power v·C v (W), summed in the same loops.  Storeys are linear
    # elastic here, with P-Delta; *storey* (None for a purely elastic row,
    # which compiles without any of it) then corrects the yielding ones.
    power = 0.0
    if storey is not None:
        kpd = storey.p_delta
    for j in range(n):
        v = y[n + j]
        fbuf[j] = a0[j] * mass[j] * v
        power += fbuf[j] * v
    for j in range(n):
        b = below[j]
        du = drift(y, 0, j, b)
        dv = drift(y, n, j, b)
        damping = kst[j] * a1[j] * dv
        s = kst[j] * du + damping
        if storey is not None:
            s += kpd[j] * du  # P-Delta: −(P/h)·Δ (kpd ≤ 0)
        power += damping * dv
        fbuf[j] += s
        if b >= 0:
            fbuf[b] -= s
    for bidx in range(dsize.size):
        m = dsize[bidx]
        if m == 0:
            continue
        s0 = dstart[bidx]
        off = doff[bidx]
        band = dband[bidx]
        if dstiff.size > 0:  # a plan model's building: C·v and its planes' and P-Delta's K·u (K = Σ k a aᵀ)
            # Unsigned indices: numba adds a negative-index wrap-around to every signed one (a third of
            # this loop's instructions); these are sums of non-negative offsets.
            row, displacement, velocity = np.uint64(off), np.uint64(s0), np.uint64(n + s0)
            for i in range(m):
                acc = 0.0
                spring = 0.0
                for k in range(max(0, i - band), min(m, i + band + 1)):
                    entry, column = row + np.uint64(k), np.uint64(k)
                    acc += dvals[entry] * y[velocity + column]
                    spring += dstiff[entry] * y[displacement + column]
                row += np.uint64(m)
                fbuf[s0 + i] += acc
                power += acc * y[n + s0 + i]
                fbuf[s0 + i] += spring
            continue
        for i in range(m):  # a shear building's modal damping block: full (its band, m − 1, not read)
            acc = 0.0
            for k in range(m):
                acc += dvals[off + i * m + k] * y[n + s0 + k]
            fbuf[s0 + i] += acc
            power += acc * y[n + s0 + i]
    if storey is not None:
        storey_forces(y, lay, below, kst, storey, out, fbuf)
    n_stuck = 0
    for c in range(nc):
        f = 0.0
        out[internal + c] = 0.0
        out[work + c] = 0.0  # δ̇ of a closed contact for now; its power F·δ̇ below
        if closed[c]:
            # Summed from 0 term by term, the gap last: a floor pair's δ is u_L − u_R − gap to the bit.
            delta, rate = contact_sums(y, n, cf, cw, cwidth, c)
            if ground is not None:
                delta += ground_offset(ground, ground.now, c, 2)
                rate += ground_offset(ground, ground.now, c, 1)
            delta -= cgap[c]
            out[work + c] = rate
            if cmode[c] == kernels.MODE_STUCK:
                n_stuck += 1
                forces[c] = 0.0
                continue
            q = y[internal + c]
            f = kernels.mode_force(claw[c], cprm[c], cconst[c], cmode[c], delta, rate, q)
            if kernels.is_permanent(claw[c]):
                out[internal + c] = kernels.link_internal_rate(claw[c], cprm[c], rate, q)
            elif delta > 0.0 or cstate.rest_band[c] == 0.0:
                out[internal + c] = kernels.mode_internal_rate(claw[c], cprm[c], cmode[c], delta, rate)
            # a resting contact parted within its band carries no force: its internal state (the bilinear
            # law's force) waits, so it is the loop's value at δ = 0 when the faces meet again
        forces[c] = f
        if f != 0.0:
            for k in range(stride * c, stride * c + stride):
                fbuf[cf[k]] += cw[k] * f
    if n_stuck > 0:
        stuck_constraints(ag_t, mass, contacts, cstate, fbuf, forces, ground)
    if friction is not None:
        friction_forces(y, ag_t, mass, friction, forces, fbuf, out, lay.friction_work, ground)
    e_in_rate = 0.0
    if ground is None:
        for c in range(nc):
            f = forces[c]
            out[impulse + c] = f
            out[work + c] *= f
        for j in range(n):
            out[j] = y[n + j]
            out[n + j] = -fbuf[j] / mass[j] - ag_t
            e_in_rate -= ag_t * mass[j] * y[n + j]
    else:
        # Several grounds: δ̇ (above) includes the differential ground velocity; its work on the
        # contact forces is the input W_g (the last state); each building from its own ground.
        ground_power = 0.0
        for c in range(nc):
            f = forces[c]
            out[impulse + c] = f
            out[work + c] *= f
            if closed[c]:
                ground_power += f * ground_offset(ground, ground.now, c, 1)
        gnow = ground.now
        fground = ground.floor_row
        for j in range(n):
            ag_j = gnow[0, fground[j]]
            out[j] = y[n + j]
            out[n + j] = -fbuf[j] / mass[j] - ag_j
            e_in_rate -= ag_j * mass[j] * y[n + j]
        out[lay.ground_work] = ground_power
    out[lay.input_energy] = e_in_rate
    out[lay.damping_energy] = power


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def rhs_called(y, ag_t, lay, structure, contacts, cstate, out, fbuf, forces, storey, ground, friction):
    """:func:`rhs`, called rather than inlined: for the event kernels (a release's bisection, a rigid
    impact's constraint forces, friction's holding force), which run at events, not every step, where
    another inlined copy of the right-hand side would only cost compile time.  :func:`rhs` itself is
    inlined (:data:`jit.INLINED`) into the Dormand–Prince stages and the output samples' rates, where
    a call would copy its ~30 arrays every step; one function, typed once, serves both."""
    rhs(y, ag_t, lay, structure, contacts, cstate, out, fbuf, forces, storey, ground, friction)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def rates_within_step(work, h, s, t, seg, forcing, structure, contacts, cstate, storey, ground, friction) -> None:
    """The right-hand side at fraction *s* of the trial step of *h* s from *t* (record step *seg*): the
    step's interpolated state into ``work.ystage``, its rates into ``work.K[1]``, the contact forces into
    ``work.forces`` (and the friction faces' into *friction*).  What the event bisections test at each
    fraction (a stuck contact's release, a sticking face's loss of stick)."""
    interpolate(work, h, s, work.ystage)
    at = t + s * h
    if ground is not None:
        fill_grounds(ground, forcing.record_step, seg, at, ground.now)
    rhs_called(work.ystage, ground_at(forcing.acceleration, forcing.record_step, seg, at), work.layout, structure,
               contacts, cstate, work.K[1], work.fbuf, work.forces, storey, ground, friction)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, inline="always", **jit.NO_REFCOUNT)
def storey_forces(y, lay, below, kst, storey, out, fbuf):
    """Add the yielding storeys' departure from ``kΔ`` to the floor forces *fbuf*, N.

    Writes the rates of the hysteretic states and of the storeys' work
    ∫F dΔ into *out*.  The caller has already applied ``kΔ`` and P-Delta to
    every storey (a plan model's plane: its building's dense stiffness block carries ``kΔ``; the
    departure enters its floors with the plane's weights, :func:`pounding.solver.kinematics.storey_push`).
    The storey kernels take the parameter table and a row (no row views:
    each would be reference-counted, in the solver's innermost loop).
    """
    smodel, sprm, smode, sfloor, terms = storey.model, storey.parameters, storey.mode, storey.floor, storey.terms
    nh = sfloor.size
    n = lay.n_floors
    ih = lay.hysteretic  # first hysteretic state
    iw = lay.storey_work  # first storey work
    for hi in range(nh):
        j = sfloor[hi]
        du = storey_drift(y, 0, terms, below, j)
        dv = storey_drift(y, n, terms, below, j)
        r = y[ih + hi]
        model = smodel[j]
        k = storey_stiffness(kst, terms, j)
        restoring = storeys.restoring_force(model, sprm, j, k, du, r)
        out[ih + hi] = storeys.state_rate(model, sprm, j, smode[hi], dv, r)
        out[iw + hi] = restoring * dv
        storey_push(fbuf, terms, below, j, restoring - k * du)


jit.stamp_solver_kernels(globals())
