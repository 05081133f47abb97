"""Coulomb friction on the faces of a plan model: stick/slip events, located and applied.

The law and its forces are :mod:`pounding.solver.friction_forces` (docs/physics.md, "Coulomb
friction on a face").  Every transition is a located event, none regularised
(:func:`locate_friction_events`, :func:`apply_friction_events`): a face starts when one of its
points closes (slipping along its slip rate, or sticking if that is 0 and sticking holds) and
stops when its last point opens; a slipping face whose slip rate reaches 0 sticks if the force
that holds it is at most μN, else slips the other way; a sticking face slips, in the direction of
the force that held it, when that force reaches μN.  A sticking face's force is checked against
μN at the end of each trial step and the crossing then bisected on the step's interpolant (as a
stuck rigid contact's release): a stick lost and regained within one error-controlled step is not
seen.

The solver's *friction* argument is None in every model without friction: all of this is
pruned at compile time (the planar and frictionless solvers are the plain ones).
"""

from __future__ import annotations

from numba import njit

from pounding.solver import jit
from pounding.solver.dense import DELTA_ROUNDOFF, first_crossing
from pounding.solver.friction_forces import FRICTION_OFF, FRICTION_SLIP, FRICTION_STICK, stick_margin
from pounding.solver.kinematics import combo, compliance, kick
from pounding.solver.rhs import rates_within_step, rhs_called

__all__ = ["FRICTION_EVENT_NONE", "FRICTION_EVENT_STOP", "FRICTION_EVENT_SLIP", "locate_friction_events",
           "apply_friction_events", "record_friction"]

#: A face's events: none, slip rate reaching 0, sticking force reaching μN.
FRICTION_EVENT_NONE, FRICTION_EVENT_STOP, FRICTION_EVENT_SLIP = 0, 1, 2


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _slip_rate_scale(y, ynew, n, friction, f) -> float:
    """Σ_k |w_k|·(|v_k(0)| + |v_k(h)|) (m/s): the round-off scale of the slip rate over a step."""
    total = 0.0
    terms = len(friction.width)
    for k in range(terms * f, terms * f + terms):
        j = n + friction.floors[k]
        total += abs(friction.weights[k]) * (abs(y[j]) + abs(ynew[j]))
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def locate_friction_events(work, h, t, seg, forcing, lay, structure, contacts, cstate, storey, ground,
                           friction) -> float:
    """Each face's first event in a trial step from *t* of *h* s into ``friction.event_s`` and
    ``friction.event_kind``; returns the earliest fraction (2.0 if none).

    Called right after the step's stages, while ``friction.force`` and ``friction.normal`` hold the
    step's end (the last stage).  A slipping face's event is its slip rate ``s·v_t`` (a cubic
    Hermite in the velocities and accelerations at both ends) crossing below 0, exactly on the
    interpolant; a sticking face's, μN − |λ| turning negative, bisected with the right-hand side
    on the interpolated state when it is negative at the end.
    """
    y, ynew, k1, k7 = work.y, work.ynew, work.K[0], work.K[6]
    n = lay.n_floors
    ff, fw, width = friction.floors, friction.weights, friction.width
    s_first = 2.0
    lost = 0
    for f in range(friction.mode.size):
        friction.event_s[f] = -1.0
        friction.event_kind[f] = FRICTION_EVENT_NONE
        if friction.mode[f] == FRICTION_SLIP:
            sign = friction.direction[f]
            floor = DELTA_ROUNDOFF * _slip_rate_scale(y, ynew, n, friction, f)
            s = first_crossing(sign * combo(y, n, ff, fw, width, f), sign * combo(k1, n, ff, fw, width, f),
                               sign * combo(ynew, n, ff, fw, width, f), sign * combo(k7, n, ff, fw, width, f), h,
                               False, floor)
            if s >= 0.0:
                friction.event_s[f] = s
                friction.event_kind[f] = FRICTION_EVENT_STOP
                s_first = min(s_first, s)
        elif friction.mode[f] == FRICTION_STICK and stick_margin(friction, f) < 0.0:
            friction.event_kind[f] = FRICTION_EVENT_SLIP
            lost += 1
    if lost == 0:
        return s_first
    for f in range(friction.mode.size):
        if friction.event_kind[f] != FRICTION_EVENT_SLIP:
            continue
        lo = 0.0
        hi = 1.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            rates_within_step(work, h, mid, t, seg, forcing, structure, contacts, cstate, storey, ground, friction)
            if stick_margin(friction, f) < 0.0:
                hi = mid
            else:
                lo = mid
            if hi - lo < 1e-13:
                break
        friction.event_s[f] = hi
        s_first = min(s_first, hi)
    return s_first


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _face_closed(cstate, friction, f) -> bool:
    """True if any contact point of face *f* is closed."""
    for c in range(friction.first_point[f], friction.first_point[f] + friction.point_count[f]):
        if cstate.closed[c]:
            return True
    return False


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _held_force(f, t, ag_t, lay, structure, contacts, cstate, work, storey, ground, friction) -> float:
    """The force (N) that would hold face *f* sticking now, with every other face in its mode."""
    scratch, deriv = work.ystage, work.K[1]
    for i in range(lay.size):
        scratch[i] = work.y[i]
    friction.mode[f] = FRICTION_STICK
    rhs_called(scratch, ag_t, lay, structure, contacts, cstate, deriv, work.fbuf, work.forces, storey, ground, friction)
    return friction.force[f]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _stick_or_slip(f, t, ag_t, lay, structure, contacts, cstate, work, storey, ground, friction) -> None:
    """Face *f* at zero slip rate: stick if the force that holds it is at most μN, else slip along that force.

    The slip rate left by the located crossing (round-off past 0) is removed first, by the impulse
    ``v_t / Σ w²/m`` along the slip terms; its work joins the face's dissipated energy.
    """
    y, mass = work.y, structure.mass
    n = lay.n_floors
    ff, fw, width = friction.floors, friction.weights, friction.width
    rate = combo(y, n, ff, fw, width, f)
    impulse = rate / compliance(mass, ff, fw, width, f)
    kick(y, n, mass, ff, fw, width, f, impulse)
    y[lay.friction_work + f] += impulse * 0.5 * rate
    held = _held_force(f, t, ag_t, lay, structure, contacts, cstate, work, storey, ground, friction)
    if abs(held) > friction.coefficient[f] * friction.normal[f]:
        friction.mode[f] = FRICTION_SLIP
        friction.direction[f] = 1.0 if held > 0.0 else -1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def apply_friction_events(t, ag_t, lay, structure, contacts, cstate, work, storey, ground, friction) -> int:
    """Apply the faces' located events and follow their points' contact events at *t*; returns how many
    faces changed mode or state.

    Called after the contact events of the same instant (so ``cstate.closed`` is current): a face
    whose last point opened stops; an open face with a closed point starts, slipping along its slip
    rate, or (rate exactly 0) sticking if that holds; a slipping face at zero slip rate
    (FRICTION_EVENT_STOP) sticks or reverses; a sticking face at μN (FRICTION_EVENT_SLIP) slips in
    the direction of the force that held it.  ``work.ystage``, ``work.K[1]``, ``work.fbuf`` and
    ``work.forces`` serve as scratch.
    """
    n = lay.n_floors
    ff, fw, width = friction.floors, friction.weights, friction.width
    changed = 0
    for f in range(friction.mode.size):
        kind = friction.event_kind[f]
        friction.event_kind[f] = FRICTION_EVENT_NONE
        before = friction.mode[f]
        if not _face_closed(cstate, friction, f):
            friction.mode[f] = FRICTION_OFF
        elif before == FRICTION_OFF:
            rate = combo(work.y, n, ff, fw, width, f)
            if rate != 0.0:
                friction.mode[f] = FRICTION_SLIP
                friction.direction[f] = 1.0 if rate > 0.0 else -1.0
            else:
                _stick_or_slip(f, t, ag_t, lay, structure, contacts, cstate, work, storey, ground, friction)
        elif kind == FRICTION_EVENT_STOP and before == FRICTION_SLIP:
            _stick_or_slip(f, t, ag_t, lay, structure, contacts, cstate, work, storey, ground, friction)
            changed += 1  # sticking, or reversed (the same mode, the other direction): the state changed
            continue
        elif kind == FRICTION_EVENT_SLIP and before == FRICTION_STICK:
            held = _held_force(f, t, ag_t, lay, structure, contacts, cstate, work, storey, ground, friction)
            friction.mode[f] = FRICTION_SLIP
            friction.direction[f] = 1.0 if held > 0.0 else -1.0
        if friction.mode[f] != before:
            changed += 1
    return changed


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def record_friction(i, friction) -> None:
    """Output sample *i*: each face's N, λ (N) and mode code (0 open, ±1 slipping along ±v_t, 2 sticking);
    nothing without friction faces (*friction* None: pruned)."""
    if friction is None:
        return
    nf = friction.mode.size
    if i >= friction.history.shape[0]:
        return
    for f in range(nf):
        friction.history[i, f] = friction.normal[f]
        friction.history[i, nf + f] = friction.force[f]
        code = 0.0
        if friction.mode[f] == FRICTION_SLIP:
            code = friction.direction[f]
        elif friction.mode[f] == FRICTION_STICK:
            code = 2.0
        friction.history[i, 2 * nf + f] = code


jit.stamp_solver_kernels(globals())
