"""Contact events: gap closure, separation, release of a stuck contact and mode switches (locate; apply).

Gap closure (δ crossing 0 upwards on an open contact) and separation (δ
crossing 0 downwards on a closed one) are found on the cubic Hermite
interpolant of δ over a trial step (:func:`pounding.solver.dense.first_crossing`);
the driver retakes the step to end exactly at the event, and the contact
state switches there (:func:`apply_contact_events`).  Hertz-damp's ξ is
computed from the approach velocity ``v0 = δ̇`` at that instant.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pounding.solver import jit
from pounding.solver import kernels
from pounding.solver.dense import DELTA_ROUNDOFF, first_crossing, hermite
from pounding.solver.kinematics import (combo, compliance, contact_delta, effective_mass, fill_grounds, floor_pair,
                                        ground_offset, kick, step_kinematics_inline)
from pounding.solver.recorder import (IMP_CONSTANT, IMP_CONTACT, IMP_END, IMP_IMPULSE, IMP_PEAK_FORCE,
                                      IMP_SEPARATION, IMP_TIME, IMP_VELOCITY, IMP_WORK, IMPACT_ROW_LIMIT)
from pounding.solver.rhs import rates_within_step, rhs_called
from pounding.solver.simultaneous import delassus, solve_lcp
from pounding.solver.status import STATUS_TABLE_LIMIT

__all__ = ["EVENT_NONE", "EVENT_CLOSE", "EVENT_SEPARATE", "EVENT_RELEASE", "EVENT_SWITCH0", "EVENT_SAMPLES",
           "STEPS_PER_CONTACT", "EVENTS_PER_WINDOW_BASE", "EVENTS_PER_WINDOW_PER_CONTACT", "switch_crossing",
           "locate_contact_events", "locate_releases", "velocity_jump", "switch_contact", "plastic_jump", "instant_row", "resolve_rigid_contacts", "apply_contact_events"]

#: A Hermite cubic stays within (4/27)·h·(|r0| + |r1|) of its ends' range (the basis functions' bounds):
#: this factor, above 4/27, bounds it with room for round-off.
HERMITE_REACH = 0.25
#: Sub-intervals sampled on the interpolant when searching for a contact event.
EVENT_SAMPLES = 8
#: First step inside a newly closed compliant contact: its duration estimate over this.
STEPS_PER_CONTACT = 16.0
#: Event cap: a run stops with STATUS_EVENT_LIMIT when more than
#: ``EVENTS_PER_WINDOW_BASE + EVENTS_PER_WINDOW_PER_CONTACT·nc`` contact events
#: (closures, separations, mode switches, releases) fall within one record step.
#: A compliant impact has 2-4 events and lasts at least ~1e-5 s even for kh = 1e14
#: and 1 kg floors, so 2000 per contact and record step is far above any real
#: sequence, yet a sequence stuck at one instant reaches it in well under a second.
EVENTS_PER_WINDOW_BASE = 1000
EVENTS_PER_WINDOW_PER_CONTACT = 2000
# Kinds of contact events.
# Switch events are EVENT_SWITCH0 + which, for which < kernels.N_SWITCHES: they come last.
EVENT_NONE, EVENT_CLOSE, EVENT_SEPARATE, EVENT_RELEASE, EVENT_SWITCH0 = range(5)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def switch_crossing(claw, prm, const, mode, which, gap, kin, internal, h) -> float:
    """Fraction of the step where switch function *which* of a closed contact's mode turns negative.

    The function (:func:`pounding.contact.switch_value`) is evaluated on the
    interpolants of δ, δ̇ and the internal state at EVENT_SAMPLES points; a
    sign change from ≥ 0 to < 0 is bisected to ~1e-15 of the step and the end
    of the bracket past the switch returned.  A mode entered at a located
    switch starts with its function at 0 (round-off either side): the search
    only counts a crossing after the function has been ≥ 0 in this step.
    Returns −1 if there is none.  *kin*: the contact's ``Σ w·u`` at both ends
    of the step, its rate and acceleration ``(d0, r0, d1, r1, a0, a1)``;
    *internal*: its internal state and rate at both ends ``(q0, q̇0, q1, q̇1)``.
    """
    yl0, vl0, yl1, vl1, al0, al1 = kin
    q0, qr0, q1, qr1 = internal
    reach = HERMITE_REACH * h * (abs(al0) + abs(al1))
    if not kernels.switch_may_cross(claw, prm, const, mode, which, min(vl0, vl1) - reach, max(vl0, vl1) + reach):
        return -1.0
    d = hermite(yl0, vl0, yl1, vl1, h, 0.0) - gap
    g = kernels.switch_value(claw, prm, const, mode, which, d, vl0, q0)
    been_positive = g > 0.0
    prev_s = 0.0
    for i in range(1, EVENT_SAMPLES + 1):
        s = i / EVENT_SAMPLES
        d = hermite(yl0, vl0, yl1, vl1, h, s) - gap
        rate = hermite(vl0, al0, vl1, al1, h, s)
        g = kernels.switch_value(claw, prm, const, mode, which, d, rate, hermite(q0, qr0, q1, qr1, h, s))
        if g < 0.0 and been_positive:
            lo = prev_s
            hi = s
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                d = hermite(yl0, vl0, yl1, vl1, h, mid) - gap
                rate = hermite(vl0, al0, vl1, al1, h, mid)
                gm = kernels.switch_value(claw, prm, const, mode, which, d, rate,
                                               hermite(q0, qr0, q1, qr1, h, mid))
                if gm < 0.0:
                    hi = mid
                else:
                    lo = mid
                if hi - lo < 1e-15:
                    break
            return hi
        if g > 0.0:
            been_positive = True
        prev_s = s
    return -1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def locate_contact_events(work, h, t, seg, forcing, lay, contacts, cstate, events, ground):
    """Each contact's first event inside a trial step from *t* of *h* s into ``events.s`` (fraction of
    the step, −1 if none) and ``events.kind`` (EVENT_*): ``(earliest fraction, 2.0 if none; number of
    stuck contacts whose release is still to be located by :func:`locate_releases`)``.

    Keeps the forces at the step's end (the last stage evaluation) in ``work.forces_end``; with
    several grounds fills ``ground.start`` and ``ground.end``.  δ is the Hermite cubic of the total
    displacements: each side's weighted floors over its own ground plus the contact's differential
    ground motion (itself a cubic within a record step, so the interpolant reproduces it exactly).
    """
    y, ynew, K, forces, forces_end = work.y, work.ynew, work.K, work.forces, work.forces_end
    k1, k7 = K[0], K[6]
    dt_rec = forcing.record_step
    n, iq = lay.n_floors, lay.internal
    cf, cw, width, cgap, claw, cprm = contacts
    closed, cconst, cmode = cstate.closed, cstate.constant, cstate.mode
    event_s, event_kind = events.s, events.kind
    h_try = h
    for c in range(lay.n_contacts):
        forces_end[c] = forces[c]
    if ground is not None:
        fill_grounds(ground, dt_rec, seg, t, ground.start)
        fill_grounds(ground, dt_rec, seg, t + h_try, ground.end)
    s_first = 2.0
    n_release = 0
    for c in range(lay.n_contacts):
        event_s[c] = -1.0
        event_kind[c] = EVENT_NONE
        # δ, δ̇ at both ends of the step, their rates (k1, k7), and the round-off scale of δ.
        d0, r0, d1, r1, q0, q1, size = step_kinematics_inline(y, ynew, k1, k7, n, cf, cw, width, c, ground)
        d0 -= cgap[c]
        d1 -= cgap[c]
        floor = DELTA_ROUNDOFF * (size + abs(cgap[c]))
        s = -1.0
        kind = EVENT_NONE
        if kernels.is_permanent(claw[c]):
            continue  # a link has no events
        if cstate.rest_band[c] > 0.0:
            # at rest: neither parting nor (after a release at rest) re-closing within the band is an event
            floor = max(floor, cstate.rest_band[c])
        if not closed[c]:
            # not closed[c], a run-time bool: one specialisation of first_crossing, not one per literal
            s = first_crossing(d0, r0, d1, r1, h_try, not closed[c], floor)  # upward: closure
            kind = EVENT_CLOSE
        elif cmode[c] == kernels.MODE_STUCK:
            if forces_end[c] < 0.0:
                n_release += 1  # the constraint force turns tensile inside the step: locate_releases
        else:
            s = first_crossing(d0, r0, d1, r1, h_try, not closed[c], floor)  # downward: separation
            kind = EVENT_SEPARATE
            for which in range(kernels.switch_count(claw[c], cprm[c])):
                # The interpolants are linear in the data: δ's from the combined side data.
                sw = switch_crossing(claw[c], cprm[c], cconst[c], cmode[c], which, cgap[c],
                                     (d0 + cgap[c], r0, d1 + cgap[c], r1, q0, q1),
                                     (y[iq + c], k1[iq + c], ynew[iq + c], k7[iq + c]), h_try)
                if sw >= 0.0 and (s < 0.0 or sw < s):
                    s = sw
                    kind = EVENT_SWITCH0 + which
        if s >= 0.0:
            event_s[c] = s
            event_kind[c] = kind
            if s < s_first:
                s_first = s
    return s_first, n_release


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def locate_releases(work, h, t, seg, forcing, structure, contacts, cstate, events, storey, ground, friction):
    """Release of every stuck contact whose constraint force is tensile at the end of a trial step from
    *t* of *h* s (``work.forces_end``): bisected on the interpolant, into ``events.s`` and
    ``events.kind`` (EVENT_RELEASE); returns the earliest fraction (2.0 if none).  Kept out of
    :func:`locate_contact_events` (rare, and it needs the whole right-hand side)."""
    forces, forces_end, lay = work.forces, work.forces_end, work.layout
    closed, cmode = cstate.closed, cstate.mode
    h_try = h
    s_first = 2.0
    for c in range(lay.n_contacts):
        if kernels.is_permanent(contacts.law[c]) or not closed[c] or cmode[c] != kernels.MODE_STUCK:
            continue
        if forces_end[c] < 0.0:
            lo = 0.0
            hi = 1.0
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                rates_within_step(work, h_try, mid, t, seg, forcing, structure, contacts, cstate, storey, ground,
                                  friction)
                if forces[c] < 0.0:
                    hi = mid
                else:
                    lo = mid
                if hi - lo < 1e-13:
                    break
            events.s[c] = hi
            events.kind[c] = EVENT_RELEASE
            s_first = min(s_first, hi)
    return s_first


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def velocity_jump(c, t, y, lay, mass, contacts, impacts, n_imp, dvg):
    """Instantaneous impact (stereo-mechanical): jump the two floor velocities.

    The impulse ``J = (1+e)·m_eff·v0`` acts on the two floors (−J on the
    left, +J on the right); the work ``J·(v0 + v0')/2`` it does (the energy
    lost, ½·m_eff·(1−e²)·v0²) and the impulse are added to the contact's
    energy-audit states.  The impact row (room made by the caller) opens and
    closes at once; returns the new row count.  *dvg* (m/s) is the contact's
    differential ground velocity: ``v0 = δ̇`` includes it, and the work
    ``J·dvg`` it does goes to the ground-work state (the last one).
    """
    n, cf, cw, claw, cprm = lay.n_floors, contacts.floors, contacts.weights, contacts.law, contacts.parameters
    width = contacts.width
    v0 = combo(y, n, cf, cw, width, c) + dvg
    impulse = kernels.jump_impulse(claw[c], cprm[c], v0)
    kick(y, n, mass, cf, cw, width, c, impulse)
    v_after = combo(y, n, cf, cw, width, c) + dvg
    y[lay.impulse + c] += impulse
    y[lay.work + c] += impulse * 0.5 * (v0 + v_after)
    y[lay.ground_work] += impulse * dvg
    instant_row(impacts, n_imp, c, t, v0, impulse, v_after)
    return n_imp + 1


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def instant_row(impacts, row, c, t, v0, impulse, v_after) -> None:
    """Row *row* of the impact table for an instantaneous impact of contact *c* at *t*: approach *v0*
    and leaving *v_after* (m/s, δ̇ before and after), impulse (N·s) and its work, opened and closed at once."""
    impacts[row, IMP_CONTACT] = c
    impacts[row, IMP_TIME] = t
    impacts[row, IMP_VELOCITY] = v0
    impacts[row, IMP_CONSTANT] = np.nan
    impacts[row, IMP_PEAK_FORCE] = np.nan
    impacts[row, IMP_END] = t
    impacts[row, IMP_IMPULSE] = impulse
    impacts[row, IMP_SEPARATION] = -v_after
    impacts[row, IMP_WORK] = impulse * 0.5 * (v0 + v_after)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def switch_contact(c, upward, t, y, lay, mass, contacts, cstate, impacts, n_imp, dvg):
    """Apply a located gap closure (*upward*) or separation of contact *c* at time *t*.

    Closure fixes the per-impact constant from the approach velocity
    ``v0 = δ̇(t)`` and opens a row of the impact table; separation closes that
    row with the separation velocity and the impulse.  The caller makes room
    for one more row first (:func:`grown`); returns the new row count.
    """
    n, cf, cw, claw, cprm = lay.n_floors, contacts.floors, contacts.weights, contacts.law, contacts.parameters
    closed, cconst, open_imp = cstate.closed, cstate.constant, cstate.open_row
    rate = combo(y, n, cf, cw, contacts.width, c) + dvg
    if upward:
        if kernels.is_instantaneous(claw[c]):
            return velocity_jump(c, t, y, lay, mass, contacts, impacts, n_imp, dvg)
        closed[c] = True
        if rate < 0.0:
            rate = 0.0  # a grazing touch (the caller removed δ̇ < 0): what is left is round-off of that correction
        y[lay.internal + c] = 0.0  # internal state starts afresh at every impact
        cconst[c] = kernels.onset_constant(claw[c], cprm[c], rate)
        impacts[n_imp, IMP_CONTACT] = c
        impacts[n_imp, IMP_TIME] = t
        impacts[n_imp, IMP_VELOCITY] = rate
        impacts[n_imp, IMP_CONSTANT] = cconst[c]
        impacts[n_imp, IMP_PEAK_FORCE] = 0.0
        impacts[n_imp, IMP_IMPULSE] = y[lay.impulse + c]  # impulse state at onset; difference taken at the end
        impacts[n_imp, IMP_WORK] = y[lay.work + c]  # contact work at onset; likewise
        open_imp[c] = n_imp
        n_imp += 1
    else:
        closed[c] = False
        row = open_imp[c]
        if row >= 0:
            impacts[row, IMP_END] = t
            impacts[row, IMP_SEPARATION] = -rate
            impacts[row, IMP_IMPULSE] = y[lay.impulse + c] - impacts[row, IMP_IMPULSE]
            impacts[row, IMP_WORK] = y[lay.work + c] - impacts[row, IMP_WORK]
            open_imp[c] = -1
    return n_imp


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def plastic_jump(c, y, lay, mass, contacts, dvg):
    """Remove the relative velocity of contact *c* with a plastic impulse ``m_eff·v0`` (N·s, returned).

    The impulse and its work (the energy lost, ½·m_eff·v0²) are added to the
    contact's energy-audit states, ``J·dvg`` to the ground work (*dvg*: the
    contact's differential ground velocity, m/s, part of ``v0 = δ̇``).
    """
    n, cf, cw, width = lay.n_floors, contacts.floors, contacts.weights, contacts.width
    v0 = combo(y, n, cf, cw, width, c) + dvg
    impulse = effective_mass(mass, cf, cw, width, c) * v0
    kick(y, n, mass, cf, cw, width, c, impulse)
    y[lay.impulse + c] += impulse
    y[lay.work + c] += impulse * 0.5 * (v0 + (combo(y, n, cf, cw, width, c) + dvg))
    y[lay.ground_work] += impulse * dvg
    return impulse


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _rigid_set(kinds, contacts, cstate, active):
    """Instantaneous contacts to resolve together at this instant into *active*, the
    closing ones first, then the stuck ones: ``(number closing, number in all)``; 0 in all when
    fewer than two, or none closing (a single closure keeps the rule of :func:`apply_contact_events`)."""
    n_closing = 0
    n_all = 0
    for c in range(kinds.size):
        if kernels.is_instantaneous(contacts.law[c]) and kinds[c] == EVENT_CLOSE:
            active[n_all] = c
            n_closing += 1
            n_all += 1
    for c in range(kinds.size):
        if (kernels.is_instantaneous(contacts.law[c]) and kinds[c] == EVENT_NONE and cstate.closed[c]
                and cstate.mode[c] == kernels.MODE_STUCK):
            active[n_all] = c
            n_all += 1
    if n_closing == 0 or n_all < 2:
        n_all = 0
    return n_closing, n_all


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def resolve_rigid_contacts(events, t, ag_t, lay, structure, contacts, cstate, work, table, storey, ground, friction):
    """Closures of instantaneous contacts (``events.kind``) together with the stuck ones, when there are
    two or more of them (:func:`_rigid_set`): one impulse each from Newton's restitution as an LCP
    (:mod:`pounding.solver.simultaneous`).  Returns ``(new impact-row count, closures handled, status)``.

    A closure at or below the rest velocity is plastic (e = 0) and becomes stuck where the
    constraint forces after the impulses press it (else it leaves at rest, a plastic impact);
    a stuck contact that takes no impulse and is left separating is released.  Every contact's
    impulse and work ``P·(w + w⁺)/2`` go to its energy-audit states (their sum is the kinetic
    energy lost), ``P·dvg`` to the ground work.  Clears ``events.kind`` of the closures handled.
    """
    y, scratch, deriv, fbuf, forces = work.y, work.ystage, work.K[1], work.fbuf, work.forces
    impacts, n_imp = table.rows, table.count
    mass = structure.mass
    cf, cw, width, claw, cprm = contacts.floors, contacts.weights, contacts.width, contacts.law, contacts.parameters
    kinds, rigid = events.kind, events.rigid
    active, rate, dvg, impulse = rigid.active, rigid.rate, rigid.dvg, rigid.impulse
    n = mass.size
    n_closing, na = _rigid_set(kinds, contacts, cstate, active)
    if na == 0:
        return n_imp, n_closing - n_closing, n_closing - n_closing
    if n_imp + n_closing > IMPACT_ROW_LIMIT:
        return n_imp, n_closing - n_closing, n_closing - n_closing + STATUS_TABLE_LIMIT
    for i in range(na):
        c = active[i]
        dvg[i] = 0.0
        if ground is not None:
            dvg[i] = ground_offset(ground, ground.now, c, 1)
        rate[i] = combo(y, n, cf, cw, width, c) + dvg[i]
        e = 0.0
        if i < n_closing and rate[i] > kernels.rest_velocity(claw[c], cprm[c]):
            e = kernels.restitution(claw[c], cprm[c])
        rigid.target[i] = rate[i] + e * max(rate[i], 0.0)
    delassus(mass, cf, cw, width, active, na, rigid.delassus)
    solve_lcp(rigid, na)
    for i in range(na):
        kick(y, n, mass, cf, cw, width, active[i], impulse[i])
    first_row = n_imp
    for i in range(na):
        c = active[i]
        after = combo(y, n, cf, cw, width, c) + dvg[i]
        y[lay.impulse + c] += impulse[i]
        y[lay.work + c] += impulse[i] * 0.5 * (rate[i] + after)
        y[lay.ground_work] += impulse[i] * dvg[i]
        if i >= n_closing:
            if impulse[i] == 0.0 and after < 0.0:  # left separating: released
                n_imp = switch_contact(c, False, t, y, lay, mass, contacts, cstate, impacts, n_imp, dvg[i])
                cstate.mode[c] = 0
                cstate.rest_band[c] = events.band[c]
            continue
        kinds[c] = EVENT_NONE
        cstate.rest_band[c] = 0.0
        instant_row(impacts, n_imp, c, t, rate[i], impulse[i], after)
        if rate[i] <= kernels.rest_velocity(claw[c], cprm[c]):
            cstate.closed[c] = True  # tentatively stuck: kept where the constraint force presses it
            cstate.mode[c] = kernels.MODE_STUCK
        n_imp += 1
    for i in range(y.size):
        scratch[i] = y[i]
    rhs_called(scratch, ag_t, lay, structure, contacts, cstate, deriv, fbuf, forces, storey, ground, friction)
    for i in range(n_closing):
        c = active[i]
        row = first_row + i
        if not cstate.closed[c]:
            continue
        if forces[c] >= 0.0:
            # an open row, as a stuck contact's: the impulse and work states at onset, the end at release
            impacts[row, IMP_PEAK_FORCE] = 0.0
            impacts[row, IMP_IMPULSE] = y[lay.impulse + c] - impacts[row, IMP_IMPULSE]
            impacts[row, IMP_WORK] = y[lay.work + c] - impacts[row, IMP_WORK]
            cstate.open_row[c] = row
            cstate.constant[c] = 0.0
        else:
            cstate.closed[c] = False
            cstate.mode[c] = 0
    return n_imp, n_closing, n_closing - n_closing


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def apply_contact_events(events, t, ag_t, lay, structure, contacts, cstate, work, table, storey, ground, friction):
    """Apply the located events ``events.kind[c]`` (EVENT_*) at time *t* to the state ``work.y``, in place.

    * Closure of a compliant contact: ξ (or the law's constant) from
      ``v0 = δ̇``, the law's onset mode, a new impact row.
    * Closure of an instantaneous (stereo-mechanical) contact: the velocity
      jump with restitution e — unless ``v0`` is at most the law's rest
      velocity and the floors are being pressed together (the constraint
      force after a plastic impact is compressive): that is the
      accumulation point of an impact sequence, and the contact becomes
      **persistent** (a plastic impact, then a stuck contact that moves the
      two floors together until its force would turn tensile).  The impact
      row stays open while stuck.
    * Separation (δ back to 0) or release of a stuck contact (its force
      turning tensile): the impact row is closed.
    * Mode switch: the next mode of the law, internal state put on its branch.

    Returns ``(n_imp, n_applied, first_step_cap, status)``;
    *first_step_cap* (s) is the duration estimate of the shortest newly
    closed compliant contact over STEPS_PER_CONTACT (inf if none).  The
    impact table *table* (``ImpactTable``: its first ``count`` rows used) has room for a row per
    contact (up to IMPACT_ROW_LIMIT; the caller grows it, :func:`recorder.grown`).
    ``work.ystage``, ``work.K[1]``, ``work.fbuf`` and ``work.forces`` serve as scratch.
    """
    y, scratch, deriv, fbuf, forces = work.y, work.ystage, work.K[1], work.fbuf, work.forces
    mass = structure.mass
    cf, cw, width, cgap, claw, cprm = contacts
    closed, cconst, cmode, open_imp = cstate.closed, cstate.constant, cstate.mode, cstate.open_row
    n = mass.size
    nc = cgap.size
    iq = lay.internal
    cap = np.inf
    kinds = events.kind
    impacts = table.rows
    n_imp, n_applied, status = resolve_rigid_contacts(events, t, ag_t, lay, structure, contacts, cstate, work, table,
                                                      storey, ground, friction)
    if status != 0:
        return n_imp, n_applied, cap, status
    for c in range(nc):
        kind = kinds[c]
        if kind == EVENT_NONE:
            continue
        n_applied += 1
        dvg = 0.0
        if ground is not None:
            dvg = ground_offset(ground, ground.now, c, 1)
        rate = combo(y, n, cf, cw, width, c) + dvg
        if kind == EVENT_CLOSE:
            if n_imp + 1 > IMPACT_ROW_LIMIT:
                status = STATUS_TABLE_LIMIT
                break
            if kernels.is_instantaneous(claw[c]):
                cstate.rest_band[c] = 0.0
                stick = False
                if rate <= kernels.rest_velocity(claw[c], cprm[c]):
                    for i in range(y.size):
                        scratch[i] = y[i]
                    plastic_jump(c, scratch, lay, mass, contacts, dvg)
                    closed[c] = True
                    cmode[c] = kernels.MODE_STUCK
                    rhs_called(scratch, ag_t, lay, structure, contacts, cstate, deriv, fbuf, forces, storey, ground, friction)
                    # touching without approach (v0 ≤ 0, e.g. at gap 0) sticks at zero force too
                    stick = forces[c] > 0.0 or (rate <= 0.0 and forces[c] >= 0.0)
                    closed[c] = False
                    cmode[c] = 0
                if not stick and rate <= 0.0:
                    continue  # touching without approach and not pressed: no impact (still an event: counted)
                if not stick:
                    n_imp = velocity_jump(c, t, y, lay, mass, contacts, impacts, n_imp, dvg)
                    continue
                impacts[n_imp, IMP_CONTACT] = c
                impacts[n_imp, IMP_TIME] = t
                impacts[n_imp, IMP_VELOCITY] = rate
                impacts[n_imp, IMP_CONSTANT] = np.nan
                impacts[n_imp, IMP_PEAK_FORCE] = 0.0
                impacts[n_imp, IMP_IMPULSE] = y[lay.impulse + c]
                impacts[n_imp, IMP_WORK] = y[lay.work + c]
                plastic_jump(c, y, lay, mass, contacts, dvg)
                closed[c] = True
                cmode[c] = kernels.MODE_STUCK
                cconst[c] = 0.0
                open_imp[c] = n_imp
                n_imp += 1
                continue
            if rate < 0.0:
                # A tangency located to round-off (δ̇ ~ −1e-17 m/s): a grazing touch, v0 = 0.
                if floor_pair(cw, width, c):
                    # a plain floor pair: the pre-weighted form, bit for bit (see effective_mass)
                    lf = cf[len(width) * c]
                    rf = cf[len(width) * c + len(width) // 2]
                    y[n + lf] -= rate * mass[rf] / (mass[lf] + mass[rf])
                    y[n + rf] += rate * mass[lf] / (mass[lf] + mass[rf])
                else:
                    kick(y, n, mass, cf, cw, width, c, rate / compliance(mass, cf, cw, width, c))
                rate = 0.0
            # kind == EVENT_CLOSE (a run-time True, like the separation's False): one specialisation
            n_imp = switch_contact(c, kind == EVENT_CLOSE, t, y, lay, mass, contacts, cstate, impacts, n_imp, dvg)
            cmode[c] = kernels.onset_mode(claw[c], cprm[c], rate)
            cstate.rest_band[c] = events.band[c] if rate <= kernels.rest_velocity(claw[c], cprm[c]) else 0.0
            m_eff = effective_mass(mass, cf, cw, width, c)
            duration = kernels.contact_duration(claw[c], cprm[c], rate, m_eff)
            if duration > 0.0:
                cap = min(cap, duration / STEPS_PER_CONTACT)
        elif kind == EVENT_SEPARATE or kind == EVENT_RELEASE:
            n_imp = switch_contact(c, kind == EVENT_CLOSE, t, y, lay, mass, contacts, cstate, impacts, n_imp, dvg)
            cmode[c] = 0
            cstate.rest_band[c] = events.band[c] if kind == EVENT_RELEASE else 0.0
        else:
            which = kind - EVENT_SWITCH0
            new_mode = kernels.next_mode(claw[c], cmode[c], which)
            delta = contact_delta(y, contacts, ground, c)
            y[iq + c] = kernels.snapped_internal(claw[c], cprm[c], new_mode, delta, rate, y[iq + c])
            cmode[c] = new_mode
    return n_imp, n_applied, cap, status


jit.stamp_solver_kernels(globals())
