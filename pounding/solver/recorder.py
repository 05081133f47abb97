"""The recorder: output samples, full-resolution peaks, the impact table and the trace of closed contacts.

Everything a run keeps, written as the driver accepts steps:

* output samples at ``output_dt`` on the step's interpolant (:func:`record_sample`,
  the one sampling routine, also for the first sample and for the tail);
* peaks of floor displacement and storey drift on every step, with extrema
  inside a step found on the interpolant (:func:`record_floor_peaks`), of a plan
  model's plane drifts (:func:`record_plane_peaks`), and of
  every contact's force with each closed contact's samples appended to the
  trace (:func:`record_contacts`): output decimation never changes them;
* the impact table (its columns ``IMP_*``), filled by the contact events.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from pounding.solver import jit
from pounding.solver import kernels
from pounding.solver import storeys
from pounding.solver.dense import extremum_in_step, hermite
from pounding.solver.kinematics import combo, contact_delta, drift, step_kinematics, storey_drift
from pounding.solver.status import STATUS_TABLE_LIMIT

__all__ = ["FORCE_SAMPLES", "IMPACT_COLUMNS", "IMPACT_ROW_LIMIT", "TRACE_ROW_LIMIT", "Outputs", "Peaks", "grown",
           "new_outputs", "new_peaks", "closed_contact_samples", "peak_magnitude", "contact_energy",
           "storey_outputs", "plane_outputs", "record_sample", "record_floor_peaks", "record_plane_peaks",
           "trace_rows", "record_contacts", "close_open_impacts",
           "trimmed_outputs",
           "IMP_CONTACT", "IMP_TIME", "IMP_VELOCITY", "IMP_CONSTANT", "IMP_PEAK_FORCE", "IMP_END", "IMP_IMPULSE",
           "IMP_SEPARATION", "IMP_WORK"]

#: Points sampled on the interpolant of a closed contact to find its peak force.
FORCE_SAMPLES = 6
# Columns of the impact table built during integration.
(IMP_CONTACT, IMP_TIME, IMP_VELOCITY, IMP_CONSTANT, IMP_PEAK_FORCE, IMP_END, IMP_IMPULSE, IMP_SEPARATION,
 IMP_WORK) = range(9)
IMPACT_COLUMNS = 9
#: Row caps of the impact table (9 floats a row: 72 MB) and of the trace of closed
#: contacts (4 floats a row: 256 MB); reaching one ends the run with STATUS_TABLE_LIMIT.
IMPACT_ROW_LIMIT = 1 << 20
TRACE_ROW_LIMIT = 1 << 23


class Outputs(NamedTuple):
    """The sampled histories (nt samples)."""

    time: np.ndarray           #: (nt,) s
    state: np.ndarray          #: (nt, S)
    acceleration: np.ndarray   #: (nt, N) relative floor acceleration, m/s²
    force: np.ndarray          #: (nt, nc) N
    ground: np.ndarray         #: (nt,) m/s², ground row 0
    support: np.ndarray        #: (nt, G) m/s², every ground row (G = 1 with one ground: unused)
    potential: np.ndarray      #: (nt,) J, elastic energy stored in the contacts
    shear: np.ndarray          #: (nt, N) N, storey restoring shear
    storey_energy: np.ndarray  #: (nt, 2) J, recoverable storey energy: all, the yielding ones


class Peaks(NamedTuple):
    """Full-resolution peaks, and the scratch of a closed contact's samples over a step."""

    displacement: np.ndarray  #: (N,) m
    drift: np.ndarray         #: (N,) m
    force: np.ndarray         #: (nc,) N
    plane: np.ndarray         #: (R,) m, |drift| of a plan model's planes (Structure.plane_floors)
    fractions: np.ndarray     #: (FORCE_SAMPLES + 1,) scratch: fractions of the step
    deltas: np.ndarray        #: (FORCE_SAMPLES + 1,) scratch: penetrations, m
    values: np.ndarray        #: (FORCE_SAMPLES + 1,) scratch: forces, N


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def new_outputs(n_out, lay, ground):
    """Empty :class:`Outputs` of *n_out* samples (*ground*: the solver's, None with one ground)."""
    n, nc = lay.n_floors, lay.n_contacts
    n_ground = nc - nc + 1
    if ground is not None:
        n_ground = ground.acceleration.shape[0]
    return Outputs(np.empty(n_out), np.empty((n_out, lay.size)), np.empty((n_out, n)), np.empty((n_out, nc)),
                   np.empty(n_out), np.empty((n_out, n_ground)), np.empty(n_out), np.empty((n_out, n)),
                   np.empty((n_out, n_ground - n_ground + 2)))  # non-literal 2: no extra np.empty specialisation


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def new_peaks(lay, n_planes):
    """Zero :class:`Peaks` (and its scratch) with *n_planes* plane drifts."""
    m = lay.n_contacts - lay.n_contacts + FORCE_SAMPLES + 1
    return Peaks(np.zeros(lay.n_floors), np.zeros(lay.n_floors), np.zeros(lay.n_contacts), np.zeros(n_planes),
                 np.empty(m), np.empty(m), np.empty(m))


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def grown(table, rows, needed, limit):
    """*table* if it has *needed* rows; else a copy of its first *rows* rows, NaN-padded to twice that.

    Never more than *limit* rows (the caller checks ``needed <= limit``).
    Written as loops: numba's slice assignment and np.full add seconds of compilation.
    """
    if needed <= table.shape[0]:
        return table
    bigger = np.empty((max(needed, min(2 * needed, limit)), table.shape[1]))
    for i in range(bigger.shape[0]):
        for j in range(table.shape[1]):
            bigger[i, j] = table[i, j] if i < rows else np.nan
    return bigger


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def closed_contact_samples(claw, prm, const, mode, gap, kin, internal, h, fractions, deltas, values) -> float:
    """Sample a closed contact over a step on the interpolant; return its peak force.

    Fills *fractions*, *deltas* (penetration, m) and *values* (force, N) at
    ``s = i/FORCE_SAMPLES``; the peak is refined by a parabola through the
    largest sample and its neighbours.  *kin*: the contact's ``Σ w·u`` over
    the step (:func:`~pounding.solver.kinematics.step_kinematics`, without
    the round-off scale), *internal*: its internal state and rate at both
    ends ``(q0, q̇0, q1, q̇1)``; the interpolants are linear in the data, so
    δ's is that of the combined side data.
    """
    yl0, vl0, yl1, vl1, al0, al1 = kin
    q0, qr0, q1, qr1 = internal
    best = 0.0
    best_i = 0
    for i in range(FORCE_SAMPLES + 1):
        s = i / FORCE_SAMPLES
        delta = hermite(yl0, vl0, yl1, vl1, h, s) - gap
        rate = hermite(vl0, al0, vl1, al1, h, s)
        f = kernels.mode_force(claw, prm, const, mode, delta, rate, hermite(q0, qr0, q1, qr1, h, s))
        fractions[i] = s
        deltas[i] = delta
        values[i] = f
        if f > best:
            best = f
            best_i = i
    if 0 < best_i < FORCE_SAMPLES:
        fm, f0, fp = values[best_i - 1], values[best_i], values[best_i + 1]
        denom = fm - 2.0 * f0 + fp
        if denom < 0.0:
            offset = 0.5 * (fm - fp) / denom
            s = (best_i + offset) / FORCE_SAMPLES
            delta = hermite(yl0, vl0, yl1, vl1, h, s) - gap
            rate = hermite(vl0, al0, vl1, al1, h, s)
            f = kernels.mode_force(claw, prm, const, mode, delta, rate, hermite(q0, qr0, q1, qr1, h, s))
            if f > best:
                best = f
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def peak_magnitude(values) -> float:
    """Largest |value| of equally spaced samples, refined by a parabola through the largest and its neighbours.

    For a link's force over a step (it pulls as well as pushes): the samples
    of :func:`closed_contact_samples`.  A largest sample at either end of
    the step uses the parabola through the three samples at that end, and its
    vertex is accepted up to half a sample spacing beyond the step (a peak
    that falls between two steps' end samples is found by one of them).
    """
    best = 0.0
    best_i = 0
    m = values.size
    for i in range(m):
        if abs(values[i]) > best:
            best = abs(values[i])
            best_i = i
    if m < 3:
        return best
    centre = min(max(best_i, 1), m - 2)
    fm, f0, fp = abs(values[centre - 1]), abs(values[centre]), abs(values[centre + 1])
    denom = fm - 2.0 * f0 + fp
    if denom < 0.0:
        offset = 0.5 * (fm - fp) / denom
        where = centre + offset
        if -0.5 <= where <= m - 0.5:
            top = f0 - 0.25 * (fm - fp) * offset
            if top > best:
                best = top
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def contact_energy(y, lay, contacts, ground) -> float:
    """Elastic energy stored in all contacts (J) for state *y* (the energy audit's contact strain)."""
    total = 0.0
    for c in range(lay.n_contacts):
        delta = contact_delta(y, contacts, ground, c)
        total += kernels.potential(contacts.law[c], contacts.parameters[c], delta, y[lay.internal + c])
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def storey_outputs(y, lay, structure, storey, out, row):
    """Storey shears and energies of state *y* into ``shear[row]`` and ``energy[row]``.

    ``shear[row, j]`` (*out*: :class:`Outputs`): restoring (column) shear of the storey under floor j, N,
    without P-Delta.  ``energy[row]``: recoverable energy of every storey (with
    the P-Delta potential ½·(−P/h)·Δ², J) and the recoverable energy of the
    yielding ones.  *storey* is None for linear elastic storeys without P-Delta.
    """
    below, kst, shear, energy = structure.below, structure.storey_stiffness, out.shear, out.storey_energy
    if storey is not None:
        plane_outputs(y, lay, structure, storey, storey.terms, out, row)
        return
    total = 0.0
    for j in range(lay.n_floors):
        du = drift(y, 0, j, below[j])
        shear[row, j] = kst[j] * du
        total += 0.5 * kst[j] * du * du
    energy[row, 0] = total
    energy[row, 1] = 0.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def plane_outputs(y, lay, structure, storey, terms, out, row):
    """:func:`storey_outputs` with a *storey* record.  Its rows are the storeys (*terms* None), or a plan
    model's planes (*terms*: :class:`~pounding.solver.layout.StoreyTerms`); then ``shear[row]`` (one column
    per floor, no storey springs) is 0 and ``energy[row]`` the recoverable energy of the yielding planes
    in both columns (the elastic ones' is their Kelvin links', and a yielding plane's link carries its
    ``½kΔ²``: the plan archive takes the planes' energies from their works, pounding.results.plan_dataset)."""
    below, kst, shear, energy = structure.below, structure.storey_stiffness, out.shear, out.storey_energy
    smodel, sprm, sidx, kpd = storey.model, storey.parameters, storey.state_index, storey.p_delta
    total = 0.0
    yielding = 0.0
    if terms is None:
        for j in range(lay.n_floors):
            du = drift(y, 0, j, below[j])
            hi = sidx[j]
            r = y[lay.hysteretic + hi] if hi >= 0 else 0.0
            shear[row, j] = storeys.restoring_force(smodel[j], sprm, j, kst[j], du, r)
            recoverable = storeys.recoverable_energy(smodel[j], sprm, j, kst[j], du, r)
            total += recoverable + 0.5 * kpd[j] * du * du
            if hi >= 0:
                yielding += recoverable
    else:
        for j in range(lay.n_floors):
            shear[row, j] = 0.0
        for hi in range(storey.floor.size):
            j = storey.floor[hi]
            du = storey_drift(y, 0, terms, below, j)
            yielding += storeys.recoverable_energy(smodel[j], sprm, j, terms.stiffness[j], du,
                                                   y[lay.hysteretic + hi])
        total = yielding
    energy[row, 0] = total
    energy[row, 1] = yielding


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def record_sample(i, t, ys, rates, ag_t, lay, structure, contacts, forces, storey, ground, out) -> None:
    """Output sample *i* at time *t* (s): state *ys*, floor accelerations ``rates[N:2N]``, contact
    forces *forces*, ground acceleration *ag_t* (and with several grounds ``ground.now``), the
    contacts' stored energy and the storeys' shears and energies, into *out* (:class:`Outputs`)."""
    n = lay.n_floors
    out.time[i] = t
    for k in range(ys.size):
        out.state[i, k] = ys[k]
    for j in range(n):
        out.acceleration[i, j] = rates[n + j]
    for c in range(lay.n_contacts):
        out.force[i, c] = forces[c]
    out.ground[i] = ag_t
    if ground is not None:
        for g in range(out.support.shape[1]):
            out.support[i, g] = ground.now[0, g]
    out.potential[i] = contact_energy(ys, lay, contacts, ground)
    storey_outputs(ys, lay, structure, storey, out, i)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def record_floor_peaks(work, h, n, below, peaks) -> None:
    """Peak |displacement| of every floor and |drift| of every storey over an accepted step of *h* s."""
    y, ynew = work.y, work.ynew
    peak_u, peak_drift = peaks.displacement, peaks.drift
    for j in range(n):
        v = abs(ynew[j])
        if v > peak_u[j]:
            peak_u[j] = v
        if y[n + j] * ynew[n + j] < 0.0:
            v = extremum_in_step(y[j], y[n + j], ynew[j], ynew[n + j], h)
            if v > peak_u[j]:
                peak_u[j] = v
        b = below[j]
        d0 = drift(y, 0, j, b)
        r0 = drift(y, n, j, b)
        d1 = drift(ynew, 0, j, b)
        r1 = drift(ynew, n, j, b)
        v = abs(d1)
        if v > peak_drift[j]:
            peak_drift[j] = v
        if r0 * r1 < 0.0:
            v = extremum_in_step(d0, r0, d1, r1, h)
            if v > peak_drift[j]:
                peak_drift[j] = v


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def record_plane_peaks(work, h, n, floors, weights, width, peaks) -> None:
    """Peak |drift| of every plane of a plan model over an accepted step of *h* s (none: no planes).

    A plane's drift ``Σ_k w_k·u[f_k]`` (*floors*, *weights*, *width*: ``Structure.plane_floors``,
    ``plane_weights`` and ``plane_width``) as a storey's in :func:`record_floor_peaks`: its value at the step's end, and
    the extremum of its Hermite cubic inside the step when its rate changes sign.
    """
    y, ynew, peak = work.y, work.ynew, peaks.plane
    for p in range(peak.size):
        d1 = combo(ynew, 0, floors, weights, width, p)
        v = abs(d1)
        if v > peak[p]:
            peak[p] = v
        r0 = combo(y, n, floors, weights, width, p)
        r1 = combo(ynew, n, floors, weights, width, p)
        if r0 * r1 < 0.0:
            v = extremum_in_step(combo(y, 0, floors, weights, width, p), r0, d1, r1, h)
            if v > peak[p]:
                peak[p] = v


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def trace_rows(contacts, cstate) -> int:
    """Most rows a step adds to the trace: FORCE_SAMPLES + 1 per closed contact, neither a link nor stuck."""
    rows = 0
    for c in range(cstate.closed.size):
        if cstate.closed[c] and not kernels.is_permanent(contacts.law[c]) and cstate.mode[c] != kernels.MODE_STUCK:
            rows += FORCE_SAMPLES + 1
    return rows


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def record_contacts(work, h, t, lay, contacts, cstate, ground, peaks, impacts, trace, n_trace):
    """Peak force of every contact over an accepted step from *t* of *h* s, and the samples of every
    closed one appended to the *trace* (its first *n_trace* rows used; the caller makes room for
    :func:`trace_rows` more, up to TRACE_ROW_LIMIT); an open impact row gets its peak.  Returns
    ``(n_trace, status)``, STATUS_TABLE_LIMIT when the trace would pass its cap.
    """
    y, ynew, K, forces_end = work.y, work.ynew, work.K, work.forces_end
    k1, k7 = K[0], K[6]
    n, iq = lay.n_floors, lay.internal
    cf, cw, width, cgap, claw, cprm = contacts
    closed, cconst, cmode, open_imp = cstate.closed, cstate.constant, cstate.mode, cstate.open_row
    peak_force, fractions, deltas, values = peaks.force, peaks.fractions, peaks.deltas, peaks.values
    zero = n - n
    for c in range(lay.n_contacts):
        if kernels.is_permanent(claw[c]):
            # A link: peak |F| on the step's interpolant (no trace: it is engaged at every step).
            e_d0, e_r0, e_d1, e_r1, e_a0, e_a1, _ = step_kinematics(y, ynew, k1, k7, n, cf, cw, width, c, ground)
            closed_contact_samples(claw[c], cprm[c], cconst[c], cmode[c], cgap[c],
                                   (e_d0, e_r0, e_d1, e_r1, e_a0, e_a1), (y[iq + c], k1[iq + c], ynew[iq + c],
                                                                          k7[iq + c]), h, fractions, deltas, values)
            fpk = peak_magnitude(values)
            if fpk > peak_force[c]:
                peak_force[c] = fpk
        elif closed[c] and cmode[c] == kernels.MODE_STUCK:
            fpk = forces_end[c]
            if fpk > peak_force[c]:
                peak_force[c] = fpk
            row = open_imp[c]
            if row >= 0 and fpk > impacts[row, IMP_PEAK_FORCE]:
                impacts[row, IMP_PEAK_FORCE] = fpk
        elif closed[c]:
            e_d0, e_r0, e_d1, e_r1, e_a0, e_a1, _ = step_kinematics(y, ynew, k1, k7, n, cf, cw, width, c, ground)
            fpk = closed_contact_samples(claw[c], cprm[c], cconst[c], cmode[c], cgap[c],
                                         (e_d0, e_r0, e_d1, e_r1, e_a0, e_a1),
                                         (y[iq + c], k1[iq + c], ynew[iq + c], k7[iq + c]), h, fractions, deltas,
                                         values)
            if n_trace + FORCE_SAMPLES + 1 > TRACE_ROW_LIMIT:
                return n_trace, STATUS_TABLE_LIMIT
            for i in range(FORCE_SAMPLES + 1):
                if i == 0 and n_trace > 0 and trace[n_trace - 1, 1] == c and trace[n_trace - 1, 0] == t:
                    continue  # the previous step already recorded its end point
                trace[n_trace, 0] = t + fractions[i] * h
                trace[n_trace, 1] = c
                trace[n_trace, 2] = deltas[i]
                trace[n_trace, 3] = values[i]
                n_trace += 1
            if fpk > peak_force[c]:
                peak_force[c] = fpk
            row = open_imp[c]
            if row >= 0 and fpk > impacts[row, IMP_PEAK_FORCE]:
                impacts[row, IMP_PEAK_FORCE] = fpk
    return n_trace, zero


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def close_open_impacts(y, lay, cstate, impacts) -> None:
    """Impacts still open at the end of a run: their impulse and work so far, no end."""
    for c in range(lay.n_contacts):
        row = cstate.open_row[c]
        if row >= 0:
            impacts[row, IMP_IMPULSE] = y[lay.impulse + c] - impacts[row, IMP_IMPULSE]
            impacts[row, IMP_WORK] = y[lay.work + c] - impacts[row, IMP_WORK]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def trimmed_outputs(out, count):
    """The first *count* samples of *out* (:class:`Outputs`)."""
    return Outputs(out.time[:count], out.state[:count], out.acceleration[:count], out.force[:count],
                   out.ground[:count], out.support[:count], out.potential[:count], out.shear[:count],
                   out.storey_energy[:count])


jit.stamp_solver_kernels(globals())
