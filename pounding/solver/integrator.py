"""Event-driven, error-controlled integrator for rows of pounding shear buildings.

The equation of motion relative to the moving ground (docs/physics.md §1),

    M ü + C u̇ + K u + f_contact(u, u̇) = −M 1 a_g(t),

is integrated with the Dormand–Prince 5(4) embedded Runge–Kutta pair
(Dormand & Prince 1980; the method of ``scipy.integrate.RK45``) with
automatic step-size control, entirely inside one numba-compiled function: no
Python runs per step.

Design
------
* **Breakpoints.** The ground acceleration is piecewise linear between record
  samples, so steps never straddle a sample: every step sees a smooth
  forcing and the error estimate is not spoiled by the kinks.
* **Located contact events.** Gap closure (δ crossing 0 upwards on an open
  contact) and separation (δ crossing 0 downwards on a closed one) are found
  on the cubic Hermite interpolant of δ over an accepted step, the step is
  retaken to end exactly at the event, and the contact state switches there.
  Hertz-damp's ξ is computed from the approach velocity ``v0 = δ̇`` at that
  instant — not at the end of the first step inside the gap, as OpenSees'
  Hertzdamp does.
* **Linear cost.** Storey springs and Rayleigh damping act through the
  tridiagonal structure (O(n) per evaluation); only modal damping, on request,
  adds a dense block per building.
* **Full-resolution peaks.** Peak floor displacement, storey drift and contact
  force are tracked on every step, with extrema inside a step found on the
  interpolant; output decimation (``output_dt``) never changes them.
* **Energy audit.** Input energy, Rayleigh-damped energy, and per contact the
  impulse ``∫F dt`` and the work ``∫F δ̇ dt`` are integrated as extra states
  (excluded from the error norm: they are quadratures of a controlled solution).

State vector layout: ``[u (N), v (N), impulse (nc), work (nc), q (nc), E_input, E_damping]``
(``q``: each contact law's internal state, e.g. the bilinear law's hysteretic force).

References
----------
Dormand, J.R. & Prince, P.J. (1980). A family of embedded Runge-Kutta
formulae. J. Comput. Appl. Math. 6, 19-26.
Hairer, E., Nørsett, S.P. & Wanner, G. (1993). Solving Ordinary Differential
Equations I, 2nd ed., §II.4 (step control) and §II.6 (dense output).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numba.core.dispatcher import Dispatcher

from pounding.contact import laws as contact_laws
from pounding.solver import jit


jit.load_registries_without_scipy()

# Dormand–Prince 5(4) tableau.
C2, C3, C4, C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
A21 = 1 / 5
A31, A32 = 3 / 40, 9 / 40
A41, A42, A43 = 44 / 45, -56 / 15, 32 / 9
A51, A52, A53, A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
A61, A62, A63, A64, A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
B1, B3, B4, B5, B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
E1, E3, E4, E5, E6, E7 = 71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 5.0
#: Sub-intervals sampled on the interpolant when searching for a contact event.
EVENT_SAMPLES = 8
#: Points sampled on the interpolant of a closed contact to find its peak force.
FORCE_SAMPLES = 6

STATUS_OK = 0
STATUS_STEP_TOO_SMALL = 1  # also the outcome of a non-finite state: such steps are rejected and shrunk


@dataclass(frozen=True)
class System:
    """Flat arrays describing a row of buildings and its gap elements.

    All buildings' floors are concatenated left to right (N floors in all).

    Attributes
    ----------
    mass : (N,) kg
    storey_stiffness : (N,) N/m, storey under each floor
    below : (N,) int, index of the floor below, −1 for the ground
    rayleigh_mass, rayleigh_stiffness : (N,) Rayleigh a0 (1/s) and a1 (s) of the floor's building
    dense_start, dense_size, dense_offset : (B,) int, modal damping blocks (size 0 for Rayleigh)
    dense_values : flat float array of the dense damping blocks, N·s/m
    contact_left, contact_right : (nc,) int, floor indices of each gap element
    contact_gap : (nc,) m
    contact_law : (nc,) int, kernel branch (pounding.contact)
    contact_parameters : (nc, N_PARAMETERS) float
    """

    mass: np.ndarray
    storey_stiffness: np.ndarray
    below: np.ndarray
    rayleigh_mass: np.ndarray
    rayleigh_stiffness: np.ndarray
    dense_start: np.ndarray
    dense_size: np.ndarray
    dense_offset: np.ndarray
    dense_values: np.ndarray
    contact_left: np.ndarray
    contact_right: np.ndarray
    contact_gap: np.ndarray
    contact_law: np.ndarray
    contact_parameters: np.ndarray

    @property
    def n_floors(self) -> int:
        return int(self.mass.size)

    @property
    def n_contacts(self) -> int:
        return int(self.contact_gap.size)


@dataclass(frozen=True)
class RawSolution:
    """Everything the compiled integrator returns, as plain arrays (SI units)."""

    time: np.ndarray                 # (nt,) s
    state: np.ndarray                # (nt, S) interpolated state at output times
    acceleration: np.ndarray         # (nt, N) relative floor acceleration, m/s²
    contact_force: np.ndarray        # (nt, nc) N
    ground_acceleration: np.ndarray  # (nt,) m/s²
    contact_potential: np.ndarray    # (nt,) J, elastic energy stored in all contacts
    peak_displacement: np.ndarray    # (N,) m
    peak_drift: np.ndarray           # (N,) m, storey under each floor
    peak_contact_force: np.ndarray   # (nc,) N
    impact_contact: np.ndarray       # (ni,) int
    impact_time: np.ndarray          # (ni,) s
    impact_velocity: np.ndarray      # (ni,) m/s
    impact_constant: np.ndarray      # (ni,) law constant fixed at onset (ξ for hertz-damp)
    impact_peak_force: np.ndarray    # (ni,) N
    impact_end_time: np.ndarray      # (ni,) s (nan if still closed at the end)
    impact_impulse: np.ndarray       # (ni,) N·s
    impact_separation_velocity: np.ndarray  # (ni,) m/s, −δ̇ at separation (nan if open)
    impact_work: np.ndarray          # (ni,) J, ∫F·δ̇ dt over the impact (= energy dissipated once separated)
    trace_time: np.ndarray           # (nr,) s, full-resolution samples of closed contacts
    trace_contact: np.ndarray        # (nr,) int
    trace_penetration: np.ndarray    # (nr,) m
    trace_force: np.ndarray          # (nr,) N
    n_steps: int
    n_rejected: int
    status: int
    final_time: float


# --------------------------------------------------------------------------- #
# Right-hand side
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _ground(ag: np.ndarray, dt_rec: float, seg: int, t: float) -> float:
    """Piecewise-linear ground acceleration inside segment *seg* at time *t*."""
    t0 = seg * dt_rec
    if seg + 1 >= ag.size:
        return ag[ag.size - 1]
    return ag[seg] + (ag[seg + 1] - ag[seg]) * ((t - t0) / dt_rec)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _rhs(y, ag_t, mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
         cl, cr, cgap, claw, cprm, closed, cconst, out, fbuf, forces):
    """Time derivative of the state; contact forces are written to *forces*."""
    n = mass.size
    nc = cgap.size
    # fbuf[:n] accumulates internal + damping forces (N); power is the
    # damping power v·C v (W), summed in the same loops.
    power = 0.0
    for j in range(n):
        v = y[n + j]
        fbuf[j] = a0[j] * mass[j] * v
        power += fbuf[j] * v
    for j in range(n):
        b = below[j]
        if b >= 0:
            du = y[j] - y[b]
            dv = y[n + j] - y[n + b]
        else:
            du = y[j]
            dv = y[n + j]
        damping = kst[j] * a1[j] * dv
        s = kst[j] * du + damping
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
        for i in range(m):
            acc = 0.0
            for k in range(m):
                acc += dvals[off + i * m + k] * y[n + s0 + k]
            fbuf[s0 + i] += acc
            power += acc * y[n + s0 + i]
    for c in range(nc):
        f = 0.0
        if closed[c]:
            delta = y[cl[c]] - y[cr[c]] - cgap[c]
            rate = y[n + cl[c]] - y[n + cr[c]]
            q = y[2 * n + 2 * nc + c]
            f = contact_laws.force(claw[c], cprm[c], cconst[c], delta, rate, q)
            out[2 * n + nc + c] = f * rate
            out[2 * n + 2 * nc + c] = contact_laws.internal_rate(claw[c], cprm[c], delta, rate, q)
        else:
            out[2 * n + nc + c] = 0.0
            out[2 * n + 2 * nc + c] = 0.0
        forces[c] = f
        out[2 * n + c] = f
        fbuf[cl[c]] += f
        fbuf[cr[c]] -= f
    e_in_rate = 0.0
    for j in range(n):
        out[j] = y[n + j]
        out[n + j] = -fbuf[j] / mass[j] - ag_t
        e_in_rate -= ag_t * mass[j] * y[n + j]
    out[2 * n + 3 * nc] = e_in_rate
    out[2 * n + 3 * nc + 1] = power


# --------------------------------------------------------------------------- #
# Interpolation on an accepted step (cubic Hermite from values and rates)
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _hermite(y0: float, r0: float, y1: float, r1: float, h: float, s: float) -> float:
    """Cubic Hermite value at fraction *s* of a step of length *h*."""
    s2 = s * s
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * y0 + (s3 - 2.0 * s2 + s) * h * r0
            + (-2.0 * s3 + 3.0 * s2) * y1 + (s3 - s2) * h * r1)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _extremum_in_step(y0: float, r0: float, y1: float, r1: float, h: float) -> float:
    """Largest |y| of the Hermite cubic at its interior stationary points (0 if none)."""
    qa = 6.0 * y0 + 3.0 * h * r0 - 6.0 * y1 + 3.0 * h * r1
    qb = -6.0 * y0 - 4.0 * h * r0 + 6.0 * y1 - 2.0 * h * r1
    qc = h * r0
    best = 0.0
    if abs(qa) < 1e-300:
        if abs(qb) > 1e-300:
            s = -qc / qb
            if 0.0 < s < 1.0:
                best = abs(_hermite(y0, r0, y1, r1, h, s))
        return best
    disc = qb * qb - 4.0 * qa * qc
    if disc < 0.0:
        return best
    sq = math.sqrt(disc)
    # Numerically stable quadratic roots.
    q = -0.5 * (qb + math.copysign(sq, qb))
    roots = (q / qa, qc / q if q != 0.0 else -1.0)
    for s in roots:
        if 0.0 < s < 1.0:
            val = abs(_hermite(y0, r0, y1, r1, h, s))
            if val > best:
                best = val
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _first_crossing(d0: float, r0: float, d1: float, r1: float, h: float, upward: bool) -> float:
    """Fraction of the step where the Hermite cubic of δ first crosses zero.

    *upward* looks for δ going from ≤ 0 to > 0 (gap closure), otherwise from
    ≥ 0 to < 0 (separation).  Returns −1 if there is none, 0 if the step
    already starts on the far side moving further (a residual of an earlier
    located event).  The root is bracketed on EVENT_SAMPLES sub-intervals and
    refined by bisection to ~1e-15 of the step; the end of the bracket on the
    far side is returned, so the retaken step ends just past the event.
    """
    sign = 1.0 if upward else -1.0
    if sign * d0 > 0.0:
        if sign * r0 > 0.0:
            return 0.0
    prev_s = 0.0
    for i in range(1, EVENT_SAMPLES + 1):
        s = i / EVENT_SAMPLES
        d = d1 if i == EVENT_SAMPLES else _hermite(d0, r0, d1, r1, h, s)
        if sign * d > 0.0:
            lo = prev_s
            hi = s
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if sign * _hermite(d0, r0, d1, r1, h, mid) > 0.0:
                    hi = mid
                else:
                    lo = mid
                if hi - lo < 1e-15:
                    break
            return hi
        prev_s = s
    return -1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _closed_contact_samples(claw, prm, const, gap, yl0, vl0, yl1, vl1, al0, al1,
                            yr0, vr0, yr1, vr1, ar0, ar1, q0, qr0, q1, qr1, h, fractions, deltas,
                            values) -> float:
    """Sample a closed contact over a step on the interpolant; return its peak force.

    Fills *fractions*, *deltas* (penetration, m) and *values* (force, N) at
    ``s = i/FORCE_SAMPLES``; the peak is refined by a parabola through the
    largest sample and its neighbours.
    """
    best = 0.0
    best_i = 0
    for i in range(FORCE_SAMPLES + 1):
        s = i / FORCE_SAMPLES
        delta = _hermite(yl0, vl0, yl1, vl1, h, s) - _hermite(yr0, vr0, yr1, vr1, h, s) - gap
        rate = _hermite(vl0, al0, vl1, al1, h, s) - _hermite(vr0, ar0, vr1, ar1, h, s)
        f = contact_laws.force(claw, prm, const, delta, rate, _hermite(q0, qr0, q1, qr1, h, s))
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
            delta = _hermite(yl0, vl0, yl1, vl1, h, s) - _hermite(yr0, vr0, yr1, vr1, h, s) - gap
            rate = _hermite(vl0, al0, vl1, al1, h, s) - _hermite(vr0, ar0, vr1, ar1, h, s)
            f = contact_laws.force(claw, prm, const, delta, rate, _hermite(q0, qr0, q1, qr1, h, s))
            if f > best:
                best = f
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _contact_energy(y, n, cl, cr, cgap, claw, cprm) -> float:
    """Elastic energy stored in all contacts (J) for state *y* (the energy audit's contact strain)."""
    nc = cgap.size
    total = 0.0
    for c in range(nc):
        delta = y[cl[c]] - y[cr[c]] - cgap[c]
        total += contact_laws.potential(claw[c], cprm[c], delta, y[2 * n + 2 * nc + c])
    return total


# Columns of the impact table built during integration.
(IMP_CONTACT, IMP_TIME, IMP_VELOCITY, IMP_CONSTANT, IMP_PEAK_FORCE, IMP_END, IMP_IMPULSE, IMP_SEPARATION,
 IMP_WORK) = range(9)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _grown(table, rows, needed):
    """*table* if it has *needed* rows; else a copy of its first *rows* rows, NaN-padded to twice that.

    Written as loops: numba's slice assignment and np.full add seconds of compilation.
    """
    if needed <= table.shape[0]:
        return table
    bigger = np.empty((2 * needed, table.shape[1]))
    for i in range(bigger.shape[0]):
        for j in range(table.shape[1]):
            bigger[i, j] = table[i, j] if i < rows else np.nan
    return bigger


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _velocity_jump(c, t, y, n, cl, cr, claw, cprm, impacts, n_imp, mass):
    """Instantaneous impact (stereo-mechanical): jump the two floor velocities.

    The impulse ``J = (1+e)·m_eff·v0`` acts on the two floors (−J on the
    left, +J on the right); the work ``J·(v0 + v0')/2`` it does (the energy
    lost, ½·m_eff·(1−e²)·v0²) and the impulse are added to the contact's
    energy-audit states.  The impact row (room made by the caller) opens and
    closes at once; returns the new row count.
    """
    nc = (y.size - 2 * n - 2) // 3
    lf = cl[c]
    rf = cr[c]
    v0 = y[n + lf] - y[n + rf]
    impulse = contact_laws.jump_impulse(claw[c], cprm[c], v0)
    y[n + lf] -= impulse / mass[lf]
    y[n + rf] += impulse / mass[rf]
    v_after = y[n + lf] - y[n + rf]
    y[2 * n + c] += impulse
    y[2 * n + nc + c] += impulse * 0.5 * (v0 + v_after)
    impacts[n_imp, IMP_CONTACT] = c
    impacts[n_imp, IMP_TIME] = t
    impacts[n_imp, IMP_VELOCITY] = v0
    impacts[n_imp, IMP_CONSTANT] = np.nan
    impacts[n_imp, IMP_PEAK_FORCE] = np.nan
    impacts[n_imp, IMP_END] = t
    impacts[n_imp, IMP_IMPULSE] = impulse
    impacts[n_imp, IMP_SEPARATION] = -v_after
    impacts[n_imp, IMP_WORK] = impulse * 0.5 * (v0 + v_after)
    return n_imp + 1


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _switch_contact(c, upward, t, y, n, cl, cr, claw, cprm, closed, cconst, impacts, n_imp, open_imp, mass):
    """Apply a located gap closure (*upward*) or separation of contact *c* at time *t*.

    Closure fixes the per-impact constant from the approach velocity
    ``v0 = δ̇(t)`` and opens a row of the impact table; separation closes that
    row with the separation velocity and the impulse.  The caller makes room
    for one more row first (:func:`_grown`); returns the new row count.
    """
    rate = y[n + cl[c]] - y[n + cr[c]]
    nc = closed.size
    if upward:
        if contact_laws.is_instantaneous(claw[c]):
            return _velocity_jump(c, t, y, n, cl, cr, claw, cprm, impacts, n_imp, mass)
        closed[c] = True
        y[2 * n + 2 * nc + c] = 0.0  # internal state starts afresh at every impact
        cconst[c] = contact_laws.onset_constant(claw[c], cprm[c], rate)
        impacts[n_imp, IMP_CONTACT] = c
        impacts[n_imp, IMP_TIME] = t
        impacts[n_imp, IMP_VELOCITY] = rate
        impacts[n_imp, IMP_CONSTANT] = cconst[c]
        impacts[n_imp, IMP_PEAK_FORCE] = 0.0
        impacts[n_imp, IMP_IMPULSE] = y[2 * n + c]  # impulse state at onset; difference taken at the end
        impacts[n_imp, IMP_WORK] = y[2 * n + nc + c]  # contact work at onset; likewise
        open_imp[c] = n_imp
        n_imp += 1
    else:
        closed[c] = False
        row = open_imp[c]
        if row >= 0:
            impacts[row, IMP_END] = t
            impacts[row, IMP_SEPARATION] = -rate
            impacts[row, IMP_IMPULSE] = y[2 * n + c] - impacts[row, IMP_IMPULSE]
            impacts[row, IMP_WORK] = y[2 * n + nc + c] - impacts[row, IMP_WORK]
            open_imp[c] = -1
    return n_imp


# --------------------------------------------------------------------------- #
# The integrator
# --------------------------------------------------------------------------- #


@njit(cache=True)
def _integrate(mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
               cl, cr, cgap, claw, cprm, ag, dt_rec, t_end, rtol, atol_u, atol_v,
               output_dt, first_step, y_initial):
    n = mass.size
    nc = cgap.size
    S = 2 * n + 3 * nc + 2
    n_out = int(math.floor(t_end / output_dt + 1e-9)) + 1
    iq = 2 * n + 2 * nc  # first internal-state component

    # Sizes and counters are non-literal (``zero``): a literal (0, 64, FORCE_SAMPLES + 1, False) reaching
    # np.empty or a callee makes numba compile a throw-away literal specialisation of it (seconds in all).
    zero = nc - nc
    y = np.zeros(S)
    for i in range(2 * n):
        y[i] = y_initial[i]
    ynew = np.zeros(S)
    ystage = np.zeros(S)
    k1 = np.zeros(S)
    k2 = np.zeros(S)
    k3 = np.zeros(S)
    k4 = np.zeros(S)
    k5 = np.zeros(S)
    k6 = np.zeros(S)
    k7 = np.zeros(S)
    fbuf = np.zeros(n)
    forces = np.zeros(nc)
    closed = np.zeros(nc, dtype=np.bool_)
    cconst = np.zeros(nc)

    out_time = np.empty(n_out)
    out_state = np.empty((n_out, S))
    out_acc = np.empty((n_out, n))
    out_force = np.empty((n_out, nc))
    out_ag = np.empty(n_out)
    out_pot = np.empty(n_out)

    peak_u = np.zeros(n)
    peak_drift = np.zeros(n)
    peak_force = np.zeros(nc)

    impacts = _grown(np.empty((zero, zero + 9)), zero, zero + 64)  # NaN-filled
    n_imp = zero
    # Full-resolution trace of closed contacts: time, contact, penetration, force.
    trace = np.empty((zero + 1024, zero + 4))
    n_trace = zero
    fractions = np.empty(zero + FORCE_SAMPLES + 1)
    deltas = np.empty(zero + FORCE_SAMPLES + 1)
    values = np.empty(zero + FORCE_SAMPLES + 1)
    open_imp = np.empty(nc, dtype=np.int64)
    for c in range(nc):
        open_imp[c] = -1

    t = 0.0
    seg = zero
    _rhs(y, _ground(ag, dt_rec, seg, 0.0), mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
         cl, cr, cgap, claw, cprm, closed, cconst, k1, fbuf, forces)
    # First output sample at t = 0.
    out_time[0] = 0.0
    for i in range(S):
        out_state[0, i] = y[i]
    for j in range(n):
        out_acc[0, j] = k1[n + j]
    for c in range(nc):
        out_force[0, c] = 0.0
    out_ag[0] = _ground(ag, dt_rec, seg, 0.0)
    out_pot[0] = _contact_energy(y, n, cl, cr, cgap, claw, cprm)
    i_out = 1

    h = first_step
    n_steps = 0
    n_rej = 0
    status = 0
    tiny = 1e-12 * max(dt_rec, 1.0)

    while t < t_end - tiny and i_out <= n_out:
        while (seg + 1) * dt_rec <= t + 1e-9 * dt_rec:
            seg += 1
        seg_end = min((seg + 1) * dt_rec, t_end)
        room = seg_end - t
        h_try = h
        if h_try >= room or t + 1.01 * h_try >= seg_end:
            h_try = room
        event_c = zero - 1
        event_upward = zero < 0
        while True:
            if h_try < 1e-14 * max(1.0, t):
                status = 1
                break
            # ---- Dormand–Prince stages -----------------------------------
            for i in range(S):
                ystage[i] = y[i] + h_try * A21 * k1[i]
            _rhs(ystage, _ground(ag, dt_rec, seg, t + C2 * h_try), mass, kst, below, a0, a1, dstart, dsize,
                 doff, dvals, cl, cr, cgap, claw, cprm, closed, cconst, k2, fbuf, forces)
            for i in range(S):
                ystage[i] = y[i] + h_try * (A31 * k1[i] + A32 * k2[i])
            _rhs(ystage, _ground(ag, dt_rec, seg, t + C3 * h_try), mass, kst, below, a0, a1, dstart, dsize,
                 doff, dvals, cl, cr, cgap, claw, cprm, closed, cconst, k3, fbuf, forces)
            for i in range(S):
                ystage[i] = y[i] + h_try * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
            _rhs(ystage, _ground(ag, dt_rec, seg, t + C4 * h_try), mass, kst, below, a0, a1, dstart, dsize,
                 doff, dvals, cl, cr, cgap, claw, cprm, closed, cconst, k4, fbuf, forces)
            for i in range(S):
                ystage[i] = y[i] + h_try * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
            _rhs(ystage, _ground(ag, dt_rec, seg, t + C5 * h_try), mass, kst, below, a0, a1, dstart, dsize,
                 doff, dvals, cl, cr, cgap, claw, cprm, closed, cconst, k5, fbuf, forces)
            for i in range(S):
                ystage[i] = y[i] + h_try * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i]
                                            + A65 * k5[i])
            _rhs(ystage, _ground(ag, dt_rec, seg, t + h_try), mass, kst, below, a0, a1, dstart, dsize,
                 doff, dvals, cl, cr, cgap, claw, cprm, closed, cconst, k6, fbuf, forces)
            for i in range(S):
                ynew[i] = y[i] + h_try * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
            _rhs(ynew, _ground(ag, dt_rec, seg, t + h_try), mass, kst, below, a0, a1, dstart, dsize,
                 doff, dvals, cl, cr, cgap, claw, cprm, closed, cconst, k7, fbuf, forces)
            # ---- error norm (max norm over displacements and velocities) --
            err = 0.0
            finite = True
            for i in range(2 * n):
                e = h_try * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
                tol = (atol_u if i < n else atol_v) + rtol * max(abs(y[i]), abs(ynew[i]))
                r = abs(e) / tol
                if not (r < 1e300):
                    finite = False
                    break
                if r > err:
                    err = r
            if not finite:
                n_rej += 1
                h_try *= MIN_FACTOR
                event_c = zero - 1
                continue
            if err > 1.0:
                n_rej += 1
                h_try *= max(MIN_FACTOR, SAFETY * err ** -0.2)
                event_c = zero - 1
                continue
            # ---- contact events inside the accepted step -------------------
            if event_c < 0:
                s_first = 2.0
                for c in range(nc):
                    lf = cl[c]
                    rf = cr[c]
                    d0 = y[lf] - y[rf] - cgap[c]
                    r0 = y[n + lf] - y[n + rf]
                    d1 = ynew[lf] - ynew[rf] - cgap[c]
                    r1 = ynew[n + lf] - ynew[n + rf]
                    s = _first_crossing(d0, r0, d1, r1, h_try, not closed[c])
                    if s >= 0.0 and s < s_first:
                        s_first = s
                        event_c = c
                        event_upward = not closed[c]
                if event_c >= 0 and s_first < 1.0 - 1e-12:
                    h_event = s_first * h_try
                    if h_event <= tiny:
                        # The event is at the start of the step: switch now, redo the step.
                        impacts = _grown(impacts, n_imp, n_imp + 1)
                        n_imp = _switch_contact(event_c, event_upward, t, y, n, cl, cr, claw, cprm,
                                                closed, cconst, impacts, n_imp, open_imp, mass)
                        _rhs(y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize, doff,
                             dvals, cl, cr, cgap, claw, cprm, closed, cconst, k1, fbuf, forces)
                        event_c = zero - 1
                        continue
                    h_try = h_event
                    continue  # retake the step to end at the event
            break
        if status != 0:
            break
        h_used = h_try
        t_new = t + h_used if h_used != room else seg_end
        # ---- peaks at full resolution --------------------------------------
        for j in range(n):
            v = abs(ynew[j])
            if v > peak_u[j]:
                peak_u[j] = v
            if y[n + j] * ynew[n + j] < 0.0:
                v = _extremum_in_step(y[j], y[n + j], ynew[j], ynew[n + j], h_used)
                if v > peak_u[j]:
                    peak_u[j] = v
            b = below[j]
            if b >= 0:
                d0 = y[j] - y[b]
                r0 = y[n + j] - y[n + b]
                d1 = ynew[j] - ynew[b]
                r1 = ynew[n + j] - ynew[n + b]
            else:
                d0 = y[j]
                r0 = y[n + j]
                d1 = ynew[j]
                r1 = ynew[n + j]
            v = abs(d1)
            if v > peak_drift[j]:
                peak_drift[j] = v
            if r0 * r1 < 0.0:
                v = _extremum_in_step(d0, r0, d1, r1, h_used)
                if v > peak_drift[j]:
                    peak_drift[j] = v
        for c in range(nc):
            if closed[c]:
                lf = cl[c]
                rf = cr[c]
                fpk = _closed_contact_samples(claw[c], cprm[c], cconst[c], cgap[c],
                                              y[lf], y[n + lf], ynew[lf], ynew[n + lf], k1[n + lf],
                                              k7[n + lf], y[rf], y[n + rf], ynew[rf], ynew[n + rf],
                                              k1[n + rf], k7[n + rf], y[iq + c], k1[iq + c], ynew[iq + c],
                                              k7[iq + c], h_used, fractions, deltas, values)
                trace = _grown(trace, n_trace, n_trace + FORCE_SAMPLES + 1)
                for i in range(FORCE_SAMPLES + 1):
                    if i == 0 and n_trace > 0 and trace[n_trace - 1, 1] == c and trace[n_trace - 1, 0] == t:
                        continue  # the previous step already recorded its end point
                    trace[n_trace, 0] = t + fractions[i] * h_used
                    trace[n_trace, 1] = c
                    trace[n_trace, 2] = deltas[i]
                    trace[n_trace, 3] = values[i]
                    n_trace += 1
                if fpk > peak_force[c]:
                    peak_force[c] = fpk
                row = open_imp[c]
                if row >= 0 and fpk > impacts[row, IMP_PEAK_FORCE]:
                    impacts[row, IMP_PEAK_FORCE] = fpk
        # ---- output samples inside (t, t_new] ------------------------------
        while i_out < n_out and i_out * output_dt <= t_new + 1e-9 * output_dt:
            t_o = i_out * output_dt
            if t_o > t_new:
                t_o = t_new
            s = (t_o - t) / h_used
            for i in range(S):
                ystage[i] = _hermite(y[i], k1[i], ynew[i], k7[i], h_used, s)
            ag_o = _ground(ag, dt_rec, seg, t_o)
            _rhs(ystage, ag_o, mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                 cl, cr, cgap, claw, cprm, closed, cconst, k2, fbuf, forces)
            out_time[i_out] = t_o
            for i in range(S):
                out_state[i_out, i] = ystage[i]
            for j in range(n):
                out_acc[i_out, j] = k2[n + j]
            for c in range(nc):
                out_force[i_out, c] = forces[c]
            out_ag[i_out] = ag_o
            out_pot[i_out] = _contact_energy(ystage, n, cl, cr, cgap, claw, cprm)
            i_out += 1
        # ---- accept ---------------------------------------------------------
        t = t_new
        for i in range(S):
            y[i] = ynew[i]
            k1[i] = k7[i]
        n_steps += 1
        if event_c >= 0:
            impacts = _grown(impacts, n_imp, n_imp + 1)
            n_imp = _switch_contact(event_c, event_upward, t, y, n, cl, cr, claw, cprm,
                                    closed, cconst, impacts, n_imp, open_imp, mass)
            _rhs(y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                 cl, cr, cgap, claw, cprm, closed, cconst, k1, fbuf, forces)
            # Keep the step size the controller had before the event cut it short.
        else:
            factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** -0.2)
            h = h_used * factor
    # Impacts still open at the end: impulse so far, no end.
    for c in range(nc):
        row = open_imp[c]
        if row >= 0:
            impacts[row, IMP_IMPULSE] = y[2 * n + c] - impacts[row, IMP_IMPULSE]
            impacts[row, IMP_WORK] = y[2 * n + nc + c] - impacts[row, IMP_WORK]
    if status == 0 and i_out < n_out:
        # t_end reached within round-off before the last output sample: fill it.
        for i2 in range(i_out, n_out):
            out_time[i2] = t
            for i in range(S):
                out_state[i2, i] = y[i]
            for j in range(n):
                out_acc[i2, j] = k1[n + j]
            _rhs(y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                 cl, cr, cgap, claw, cprm, closed, cconst, k2, fbuf, forces)
            for c in range(nc):
                out_force[i2, c] = forces[c]
            out_ag[i2] = _ground(ag, dt_rec, seg, t)
            out_pot[i2] = _contact_energy(y, n, cl, cr, cgap, claw, cprm)
        i_out = n_out
    return (out_time[:i_out], out_state[:i_out], out_acc[:i_out], out_force[:i_out], out_ag[:i_out], out_pot[:i_out],
            peak_u, peak_drift, peak_force,
            impacts[:n_imp], trace[:n_trace], n_steps, n_rej, status, t)


# The kernels inline contact.py's force laws: their cached code is stale when either file changes.
jit.stamp_caches_with_sources([f for f in globals().values() if isinstance(f, Dispatcher)],
                              [__file__, contact_laws.__file__])
jit.load_from_cache_without_refresh(_integrate)


def integrate(system: System, ground_acceleration: np.ndarray, time_step: float, duration: float,
              *, rtol: float, atol: float, atol_velocity: float, output_dt: float,
              initial_displacement: np.ndarray | None = None,
              initial_velocity: np.ndarray | None = None) -> RawSolution:
    """Integrate the row of buildings under a piecewise-linear ground motion.

    Parameters
    ----------
    system : System
        Flat arrays from :func:`pounding.simulation.assemble`.
    ground_acceleration : (ns,) ndarray
        Samples of a_g, m/s², uniform step *time_step*; must cover *duration*.
    time_step : float
        Record sampling interval, s.  Steps never straddle a sample.
    duration : float
        End time, s.
    rtol, atol, atol_velocity : float
        Error control: each displacement (velocity) component's local error is
        kept below ``atol (atol_velocity) + rtol·|y|``.
    output_dt : float
        Sampling interval of the stored histories, s (peaks and impacts are
        tracked at full solver resolution regardless).
    initial_displacement, initial_velocity : (N,) ndarray, optional
        Initial state relative to the ground (m, m/s); default at rest.  All
        contacts start open.
    """
    # A fresh writable copy: a read-only array would compile a second specialisation.
    ag = np.array(ground_acceleration, dtype=np.float64, copy=True)
    # Independent of output_dt, so the step sequence (and every peak) is the same whatever the output sampling.
    first_step = 0.1 * time_step
    y_initial = np.zeros(2 * system.n_floors)
    if initial_displacement is not None:
        y_initial[: system.n_floors] = initial_displacement
    if initial_velocity is not None:
        y_initial[system.n_floors:] = initial_velocity
    raw = _integrate(system.mass, system.storey_stiffness, system.below, system.rayleigh_mass,
                     system.rayleigh_stiffness, system.dense_start, system.dense_size,
                     system.dense_offset, system.dense_values, system.contact_left,
                     system.contact_right, system.contact_gap, system.contact_law,
                     system.contact_parameters, ag, float(time_step), float(duration), float(rtol),
                     float(atol), float(atol_velocity), float(output_dt), float(first_step),
                     y_initial)
    (time, state, acc, force, ag_out, potential, peak_u, peak_drift, peak_force, impacts, trace, n_steps, n_rej,
     status, t_final) = raw
    return RawSolution(time, state, acc, force, ag_out, potential, peak_u, peak_drift, peak_force,
                       impacts[:, IMP_CONTACT].astype(np.int64), impacts[:, IMP_TIME],
                       impacts[:, IMP_VELOCITY], impacts[:, IMP_CONSTANT], impacts[:, IMP_PEAK_FORCE],
                       impacts[:, IMP_END], impacts[:, IMP_IMPULSE], impacts[:, IMP_SEPARATION],
                       impacts[:, IMP_WORK], trace[:, 0], trace[:, 1].astype(np.int64), trace[:, 2], trace[:, 3],
                       int(n_steps), int(n_rej), int(status), float(t_final))
