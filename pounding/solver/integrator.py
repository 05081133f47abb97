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

* **Yielding storeys.** A storey's hysteretic state (the plastic drift of a
  bilinear storey, Bouc–Wen's z) is integrated with the motion and is part
  of the error norm; a bilinear storey's yield onset and unloading are
  located as events, like gap closure, so no step straddles a kink of its
  force (:mod:`pounding.solver.storeys`).  P-Delta is a linear geometric
  stiffness per storey.  A run stops, located, when a storey's drift ratio
  first exceeds ``stop_drift_ratio`` (STATUS_COLLAPSED).

State vector layout: ``[u (N), v (N), impulse (nc), work (nc), q (nc), E_input, E_damping, r (nh), W (nh), W_g]``
(``q``: each contact law's internal state, e.g. the bilinear law's hysteretic force; ``r``: each
yielding storey's hysteretic state; ``W``: its work ∫F dΔ, J; ``W_g``: the work ∫F·(u̇_g,L − u̇_g,R) dt
of the contact forces on the differential ground motion, J, 0 with one common ground).

* **Multiple supports.** Each building may stand on its own ground motion (a row of the
  ground-acceleration array; a different record, or the same one lagged by wave passage).
  Floors move relative to their own ground; contacts see total displacements, so the
  differential ground displacement and velocity enter δ and δ̇ (:func:`_ground_offset`),
  integrated exactly from the piecewise-linear accelerations.  Like *storey*, the *ground*
  argument is None with one common ground, and every ``if ground is not None`` block is then
  pruned at compile time: the single-record solver is the plain one.

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
from pounding.contact import links as contact_links
from pounding import hysteresis
from pounding.solver import kernels
from pounding.solver import jit
from pounding.solver import storeys


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
#: Time of each stage within a step, as a fraction of it (stage s + 1 at t + _C[s]·h; the last two
#: at the step's end).
_C = np.array([0.0, C2, C3, C4, C5, 1.0, 1.0])

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 5.0
#: Sub-intervals sampled on the interpolant when searching for a contact event.
EVENT_SAMPLES = 8
#: Points sampled on the interpolant of a closed contact to find its peak force.
FORCE_SAMPLES = 6

STATUS_OK = 0
STATUS_STEP_TOO_SMALL = 1  # also the outcome of a non-finite state: such steps are rejected and shrunk
STATUS_EVENT_LIMIT = 2     # more contact events inside one record step than EVENTS_PER_WINDOW allows
STATUS_TABLE_LIMIT = 3     # the impact or trace table would exceed its row cap
STATUS_COLLAPSED = 4       # a storey's drift ratio exceeded stop_drift_ratio: the run ended there (not an error)
#: One-line explanation of every status, for error messages (``{t}``: the time the run stopped, s).
STATUS_MESSAGES = {
    STATUS_OK: "completed",
    STATUS_STEP_TOO_SMALL: ("the solver's step size fell below round-off at t = {t:.6g} s; "
                            "loosen solver.rtol/atol or check the model for unrealistic stiffness"),
    STATUS_EVENT_LIMIT: ("more than the allowed number of contact events within one record step at t = {t:.6g} s "
                         "(an impact sequence that does not end, e.g. chattering contacts); run stopped"),
    STATUS_TABLE_LIMIT: ("the impact or contact-trace table reached its row cap at t = {t:.6g} s "
                         "(too many impacts or closed-contact samples); run stopped"),
    STATUS_COLLAPSED: "collapsed: a storey's drift ratio exceeded solver.stop_drift_ratio at t = {t:.6g} s",
}

#: Event cap: a run stops with STATUS_EVENT_LIMIT when more than
#: ``EVENTS_PER_WINDOW_BASE + EVENTS_PER_WINDOW_PER_CONTACT·nc`` contact events
#: (closures, separations, mode switches, releases) fall within one record step.
#: A compliant impact has 2-4 events and lasts at least ~1e-5 s even for kh = 1e14
#: and 1 kg floors, so 2000 per contact and record step is far above any real
#: sequence, yet a sequence stuck at one instant reaches it in well under a second.
EVENTS_PER_WINDOW_BASE = 1000
EVENTS_PER_WINDOW_PER_CONTACT = 2000
#: Row caps of the impact table (9 floats a row: 72 MB) and of the trace of closed
#: contacts (4 floats a row: 256 MB); reaching one ends the run with STATUS_TABLE_LIMIT.
IMPACT_ROW_LIMIT = 1 << 20
TRACE_ROW_LIMIT = 1 << 23
#: Grazing floor: an overlap smaller than this multiple of the round-off of
#: δ = u_L − u_R − gap (``eps·(|u_L| + |u_R| + gap)``) is indistinguishable from zero and is
#: not an impact; every larger overlap of the step's interpolant is found exactly.
DELTA_ROUNDOFF = 8.0 * 2.220446049250313e-16
#: First step inside a newly closed compliant contact: its duration estimate over this.
STEPS_PER_CONTACT = 16.0
#: A located event within this fraction of a step from its end is applied at the end.
EVENT_END_TOLERANCE = 1e-9
#: Retakes of one step to bring a located event to its end before it is accepted as is.
MAX_RETAKES = 8
# Kinds of contact events.
# Switch events are EVENT_SWITCH0 + which, for which < kernels.N_SWITCHES: they come last.
EVENT_NONE, EVENT_CLOSE, EVENT_SEPARATE, EVENT_RELEASE, EVENT_SWITCH0 = range(5)
# Kinds of storey events (bilinear storeys).
STOREY_NONE, STOREY_YIELD_POSITIVE, STOREY_YIELD_NEGATIVE, STOREY_UNLOAD = range(4)


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
    contact_left, contact_right : (nc,) int, floor index of each gap element's left and right side
        (−1: a fixed wall; for a point of a column, the floor above it)
    contact_gap : (nc,) m
    contact_law : (nc,) int, kernel branch (pounding.contact)
    contact_parameters : (nc, N_PARAMETERS) float
    storey_model : (N,) int, hysteresis kernel branch of the storey under each floor (0: elastic)
    storey_parameters : (N, N_HYSTERESIS_PARAMETERS) float, ``[u_y, α, n, β, γ, A]``
    storey_state : (N,) int, index of the storey's hysteretic state among the nh yielding storeys, −1 if elastic
    p_delta_stiffness : (N,) N/m, geometric stiffness −P/h of the storey (0 without P-Delta)
    storey_height : (N,) m
    stop_drift_ratio : float, end the run when a storey's |drift ratio| exceeds it (0: never)
    contact_floors : (nc, SIDE_TERMS) int, optional
        Floor terms of each contact ``[left, left, right, right]`` (−1: none, the ground or a wall);
        default from ``contact_left`` / ``contact_right``: ``[left, −1, right, −1]``.
    contact_weights : (nc, SIDE_TERMS) float, optional
        Their weights: δ = Σ_k w_k·u[floor_k] − gap, the force enters floor_k as w_k·F (left
        weights ≥ 0, right ≤ 0); default ``[1, 0, −1, 0]`` (−1 sides get weight 0).
    floor_ground : (N,) int, row of the ground-acceleration array that moves each floor's building
        (all 0 with one common ground motion)
    contact_ground_left, contact_ground_right : (nc,) int, ground row under the left and the right
        side of each gap element: their differential displacement enters the penetration
        (``pounding.simulation.assemble``; a wall takes the row of the building it faces)
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
    storey_model: np.ndarray | None = None
    storey_parameters: np.ndarray | None = None
    storey_state: np.ndarray | None = None
    p_delta_stiffness: np.ndarray | None = None
    storey_height: np.ndarray | None = None
    stop_drift_ratio: float = 0.0
    contact_floors: np.ndarray | None = None
    contact_weights: np.ndarray | None = None
    floor_ground: np.ndarray | None = None
    contact_ground_left: np.ndarray | None = None
    contact_ground_right: np.ndarray | None = None

    def __post_init__(self) -> None:
        nc = int(self.contact_gap.size)
        if self.contact_floors is None:
            left = np.asarray(self.contact_left, dtype=np.int64).reshape(nc)
            right = np.asarray(self.contact_right, dtype=np.int64).reshape(nc)
            none = np.full(nc, -1, dtype=np.int64)
            object.__setattr__(self, "contact_floors", np.ascontiguousarray(np.stack([left, none, right, none], 1)))
            weights = np.stack([(left >= 0) * 1.0, np.zeros(nc), (right >= 0) * -1.0, np.zeros(nc)], 1)
            object.__setattr__(self, "contact_weights", np.ascontiguousarray(weights.reshape(nc, SIDE_TERMS)))

        # Storey fields left out: linear elastic storeys of unit height, no P-Delta, no collapse check.
        n = int(self.mass.size)
        defaults = {"storey_model": np.zeros(n, dtype=np.int64),
                    "storey_parameters": np.zeros((n, hysteresis.N_HYSTERESIS_PARAMETERS)),
                    "storey_state": np.full(n, -1, dtype=np.int64),
                    "p_delta_stiffness": np.zeros(n), "storey_height": np.ones(n),
                    "floor_ground": np.zeros(n, dtype=np.int64),
                    "contact_ground_left": np.zeros(self.contact_gap.size, dtype=np.int64),
                    "contact_ground_right": np.zeros(self.contact_gap.size, dtype=np.int64)}
        for key, value in defaults.items():
            if getattr(self, key) is None:
                object.__setattr__(self, key, value)

    @property
    def n_floors(self) -> int:
        return int(self.mass.size)

    @property
    def n_contacts(self) -> int:
        return int(self.contact_gap.size)

    @property
    def n_hysteretic(self) -> int:
        """Number of yielding storeys (each has a hysteretic state and a work state)."""
        return int((self.storey_state >= 0).sum())

    @property
    def n_states(self) -> int:
        """Length of the state vector (the last state: work of the differential ground motion on the contacts)."""
        return 2 * self.n_floors + 3 * self.n_contacts + 2 + 2 * self.n_hysteretic + 1


@dataclass(frozen=True)
class RawSolution:
    """Everything the compiled integrator returns, as plain arrays (SI units)."""

    time: np.ndarray                 # (nt,) s
    state: np.ndarray                # (nt, S) interpolated state at output times
    acceleration: np.ndarray         # (nt, N) relative floor acceleration, m/s²
    contact_force: np.ndarray        # (nt, nc) N
    ground_acceleration: np.ndarray  # (nt,) m/s², ground row 0 (the common ground with one record)
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
    storey_shear: np.ndarray         # (nt, N) N, restoring (column) shear of each storey, without P-Delta
    storey_energy: np.ndarray        # (nt, 2) J: recoverable energy of all storeys (with P-Delta), of the yielding ones
    final_state: np.ndarray          # (S,) state at final_time
    collapse_storey: int             # floor index of the storey that exceeded stop_drift_ratio, −1 if none
    n_steps: int
    n_rejected: int
    status: int
    final_time: float
    support_acceleration: np.ndarray | None = None  # (nt, G) m/s², every ground row (None: one ground)


# --------------------------------------------------------------------------- #
# Contact sides: weighted floors (a floor, a point of a column, a fixed wall)
# --------------------------------------------------------------------------- #
# Contact c measures δ = Σ_k cw[c, k]·u[cf[c, k]] − gap over SIDE_TERMS terms
# (the left side's weights positive, the right side's negative); a term with
# cf < 0 is the ground or a fixed wall (zero displacement relative to the
# ground) and contributes nothing.  The contact force F enters the floors with
# the same weights (fbuf[cf] += cw·F), so its power is F·δ̇ exactly (virtual
# work): a floor is the term (floor, ±1); a point at fraction ξ of a storey's
# height the two terms (floor below, ±N1(ξ)) and (floor above, ±N2(ξ)).

#: Terms per contact: two per side.
SIDE_TERMS = 4


# The kernels get the terms flat (term k of contact c at SIDE_TERMS·c + k) and absent terms (floor −1)
# as floor 0 with weight 0, so every sum below is
# branch-free over the SIDE_TERMS terms (:func:`integrate` maps them); 0·y[0] adds an exact 0.


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _combo(y, offset, cf, cw, c) -> float:
    """Σ_k w_k·y[offset + f_k] over the contact's floor terms (δ + gap for offset 0, δ̇ for offset n)."""
    return (cw[4 * c + 0] * y[offset + cf[4 * c + 0]] + cw[4 * c + 1] * y[offset + cf[4 * c + 1]]
            + cw[4 * c + 2] * y[offset + cf[4 * c + 2]] + cw[4 * c + 3] * y[offset + cf[4 * c + 3]])


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _push(fbuf, cf, cw, c, force) -> None:
    """Add contact force *force* (N, ≥ 0 pushes apart) to the floors' internal forces with the side weights."""
    for k in range(SIDE_TERMS):
        fbuf[cf[4 * c + k]] += cw[4 * c + k] * force


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _compliance(mass, cf, cw, c) -> float:
    """Σ_k cw²/m (1/kg): δ̈ per unit contact force; 1/m_eff of the contact (a wall adds nothing)."""
    total = 0.0
    for k in range(SIDE_TERMS):
        total += cw[4 * c + k] * cw[4 * c + k] / mass[cf[4 * c + k]]
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _effective_mass(mass, cf, cw, c) -> float:
    """m_eff of contact *c* (kg): ``1/Σ cw²/m``; a plain floor pair as ``m_L·m_R/(m_L + m_R)``.

    The floor pair's form is the one the solver used before contact sides
    became weighted sums: it keeps a floor-to-floor run bit for bit the same
    (the two forms differ in the last bit for some masses).
    """
    k = SIDE_TERMS * c
    if cw[k] == 1.0 and cw[k + 1] == 0.0 and cw[k + 2] == -1.0 and cw[k + 3] == 0.0:
        ml = mass[cf[k]]
        mr = mass[cf[k + 2]]
        return ml * mr / (ml + mr)
    return 1.0 / _compliance(mass, cf, cw, c)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _ground_weight(cf, cw, c) -> float:
    """Σ_k cw over the floor terms: 0 between two buildings, ±1 against a wall (a_g's share in δ̈)."""
    return cw[4 * c + 0] + cw[4 * c + 1] + cw[4 * c + 2] + cw[4 * c + 3]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _kick(y, n, mass, cf, cw, c, impulse) -> None:
    """Apply an impulse *impulse* (N·s, ≥ 0 pushes apart) of contact *c* to the floor velocities."""
    for k in range(SIDE_TERMS):
        y[n + cf[4 * c + k]] -= cw[4 * c + k] * impulse / mass[cf[4 * c + k]]


# --------------------------------------------------------------------------- #
# Right-hand side
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _ground(ag: np.ndarray, dt_rec: float, seg: int, t: float) -> float:
    """Piecewise-linear ground acceleration inside segment *seg* at time *t*."""
    t0 = seg * dt_rec
    if seg + 1 >= ag.size:
        return ag[ag.size - 1]
    return ag[seg] + (ag[seg + 1] - ag[seg]) * ((t - t0) / dt_rec)


# Ground motion of several supports.  *ground* is None with one common ground (every
# ``if ground is not None`` block is pruned at compile time), else the tuple built by
# :func:`_ground_arguments`: (accelerations (G, ns), displacements and velocities at the
# samples (G, ns), ground row of every floor (N,), of the left and the right side of every
# contact (nc,), and three (3, G) ground states [acceleration, velocity, displacement]:
# now, at the start of the step and at its end).


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _fill_grounds(ground, dt_rec, seg, t, gstate):
    """Acceleration, velocity and displacement of every ground at time *t* into *gstate* (3, G).

    The acceleration is piecewise linear as :func:`_ground`; velocity and displacement are its
    exact integrals from rest (quadratic and cubic in a record step; their sample values in
    ``ground[2]`` and ``ground[1]``).
    """
    ag = ground[0]
    ug = ground[1]
    vg = ground[2]
    for g in range(ag.shape[0]):
        row = ag[g]
        gstate[0, g] = _ground(row, dt_rec, seg, t)
        k = min(seg, row.size - 1)
        tau = t - k * dt_rec
        a0 = row[k]
        slope = (row[k + 1] - a0) / dt_rec if k + 1 < row.size else 0.0
        gstate[1, g] = vg[g, k] + a0 * tau + 0.5 * slope * tau * tau
        gstate[2, g] = ug[g, k] + vg[g, k] * tau + 0.5 * a0 * tau * tau + slope * tau * tau * tau / 6.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _ground_offset(ground, gstate, c, row):
    """Differential ground motion of contact *c*: ground of its left side minus ground of its right side.

    *row* 2: displacement (m), 1: velocity (m/s), 0: acceleration (m/s²) of the ground state
    *gstate*.  This is the one place where the supports' motion enters the contact kinematics:
    ``δ = Σ_k w_k·u[f_k] + (u_g,L − u_g,R) − gap`` with ``u`` relative to each floor's own ground
    (the rows ``ground[4]``, ``ground[5]``: a side's building's ground; a wall's, the ground of the
    building it faces, so a wall contact's offset is 0).
    """
    return gstate[row, ground[4][c]] - gstate[row, ground[5][c]]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _step_kinematics(y, ynew, k1, k7, n, cf, cw, c, ground):
    """Contact *c*'s ``Σ w·u`` (gap not subtracted) over an accepted or trial step: its value, rate
    and acceleration at both ends ``(d0, r0, d1, r1, a0, a1)`` and the round-off scale ``Σ |w·u|``
    at the start.  Sums over the contact's floor terms, plus the differential ground motion with
    several grounds (ground states ``ground[7]`` at the step's start, ``ground[8]`` at its end).
    The interpolants are linear in the data, so the contact's Hermite cubic is that of these sums.
    """
    d0 = 0.0
    r0 = 0.0
    d1 = 0.0
    r1 = 0.0
    a0 = 0.0
    a1 = 0.0
    size = 0.0
    for k in range(SIDE_TERMS * c, SIDE_TERMS * c + SIDE_TERMS):
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
        d0 += _ground_offset(ground, ground[7], c, 2)
        r0 += _ground_offset(ground, ground[7], c, 1)
        a0 += _ground_offset(ground, ground[7], c, 0)
        d1 += _ground_offset(ground, ground[8], c, 2)
        r1 += _ground_offset(ground, ground[8], c, 1)
        a1 += _ground_offset(ground, ground[8], c, 0)
    return d0, r0, d1, r1, a0, a1, size


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _stuck_constraints(ag_t, mass, cf, cw, closed, cmode, fbuf, forces, ground):
    """Constraint forces of stuck contacts (added to *forces* and *fbuf*): make every δ̈ = 0.

    Gauss–Seidel sweeps, exact in one when no two stuck contacts share a floor.
    a_g is common to both floors of a pair and cancels; against a wall it
    stays (the wall moves with the ground).  With several grounds (*ground* not
    None) a side's total acceleration is ``Σ w·(−fbuf/m − a_g,side) + a_g,side``
    (its weights sum to 1 with the ground's share of a storey-1 column point),
    so δ̈ = Σ_k w_k·(−fbuf_k/m_k) + a_g,L·(1 − W_L) − a_g,R·(1 + W_R) with W_L, W_R
    the sums of the left and right floor weights.  Kept out of :func:`_rhs` (rarely needed).
    """
    nc = forces.size
    for _ in range(100):
        largest = 0.0
        scale = 0.0
        for c in range(nc):
            if closed[c] and cmode[c] == kernels.MODE_STUCK:
                # δ̈ = Σ_k cw·(−fbuf/m − a_g) over the floor terms
                if ground is None:
                    relative = -ag_t * _ground_weight(cf, cw, c)
                else:
                    gnow = ground[6]
                    relative = (gnow[0, ground[4][c]] * (1.0 - cw[SIDE_TERMS * c] - cw[SIDE_TERMS * c + 1])
                                - gnow[0, ground[5][c]] * (1.0 + cw[SIDE_TERMS * c + 2] + cw[SIDE_TERMS * c + 3]))
                for k in range(SIDE_TERMS):
                    relative -= cw[SIDE_TERMS * c + k] * (fbuf[cf[SIDE_TERMS * c + k]] / mass[cf[SIDE_TERMS * c + k]])
                change = relative / _compliance(mass, cf, cw, c)
                forces[c] += change
                _push(fbuf, cf, cw, c, change)
                largest = max(largest, abs(change))
                scale = max(scale, abs(forces[c]))
        if largest <= 1e-13 * scale:
            break


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _rhs(y, ag_t, mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
         cf, cw, cgap, claw, cprm, closed, cconst, cmode, out, fbuf, forces, storey, ground):
    """Time derivative of the state; contact forces are written to *forces*.

    With several grounds (*ground* not None) each floor takes its own ground's
    acceleration and the contacts the differential ground motion of ``ground[6]``
    (the ground state at this time, filled by the caller); *ag_t* is then unused.

    A closed compliant contact acts through its law in its current mode
    (:func:`pounding.contact.mode_force`).  A persistent (stuck) contact of an
    instantaneous law is a constraint ``δ̈ = 0``: its force is whatever keeps
    the two floors moving together, found by Gauss–Seidel sweeps (exact in one
    sweep when no two stuck contacts share a floor); it may come out tensile,
    which the solver locates as the release event.
    """
    n = mass.size
    nc = cgap.size
    # fbuf[:n] accumulates internal + damping forces (N); power is the
    # damping power v·C v (W), summed in the same loops.  Storeys are linear
    # elastic here, with P-Delta; *storey* (None for a purely elastic row,
    # which compiles without any of it) then corrects the yielding ones.
    power = 0.0
    if storey is not None:
        kpd = storey[3]
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
        for i in range(m):
            acc = 0.0
            for k in range(m):
                acc += dvals[off + i * m + k] * y[n + s0 + k]
            fbuf[s0 + i] += acc
            power += acc * y[n + s0 + i]
    if storey is not None:
        _storey_forces(y, n, nc, below, kst, storey, out, fbuf)
    n_stuck = 0
    for c in range(nc):
        f = 0.0
        out[2 * n + 2 * nc + c] = 0.0
        out[2 * n + nc + c] = 0.0  # δ̇ of a closed contact for now; its power F·δ̇ below
        if closed[c]:
            # Loops over the terms, no helper taking the arrays (each call would reference-count
            # them); the gap last, so a floor pair's δ is u_L − u_R − gap to the bit, as before.
            delta = 0.0
            rate = 0.0
            for k in range(SIDE_TERMS * c, SIDE_TERMS * c + SIDE_TERMS):
                delta += cw[k] * y[cf[k]]
                rate += cw[k] * y[n + cf[k]]
            if ground is not None:
                delta += _ground_offset(ground, ground[6], c, 2)
                rate += _ground_offset(ground, ground[6], c, 1)
            delta -= cgap[c]
            out[2 * n + nc + c] = rate
            if cmode[c] == kernels.MODE_STUCK:
                n_stuck += 1
                forces[c] = 0.0
                continue
            q = y[2 * n + 2 * nc + c]
            f = kernels.mode_force(claw[c], cprm[c], cconst[c], cmode[c], delta, rate, q)
            if kernels.is_permanent(claw[c]):
                out[2 * n + 2 * nc + c] = kernels.link_internal_rate(claw[c], cprm[c], rate, q)
            else:
                out[2 * n + 2 * nc + c] = kernels.mode_internal_rate(claw[c], cprm[c], cmode[c], delta, rate)
        forces[c] = f
        if f != 0.0:
            for k in range(SIDE_TERMS * c, SIDE_TERMS * c + SIDE_TERMS):
                fbuf[cf[k]] += cw[k] * f
    if n_stuck > 0:
        _stuck_constraints(ag_t, mass, cf, cw, closed, cmode, fbuf, forces, ground)
    e_in_rate = 0.0
    if ground is None:
        for c in range(nc):
            f = forces[c]
            out[2 * n + c] = f
            out[2 * n + nc + c] *= f
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
            out[2 * n + c] = f
            out[2 * n + nc + c] *= f
            if closed[c]:
                ground_power += f * _ground_offset(ground, ground[6], c, 1)
        gnow = ground[6]
        fground = ground[3]
        for j in range(n):
            ag_j = gnow[0, fground[j]]
            out[j] = y[n + j]
            out[n + j] = -fbuf[j] / mass[j] - ag_j
            e_in_rate -= ag_j * mass[j] * y[n + j]
        out[out.size - 1] = ground_power
    out[2 * n + 3 * nc] = e_in_rate
    out[2 * n + 3 * nc + 1] = power


_rhs_inline = njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, inline="always",
                   **jit.NO_REFCOUNT)(_rhs.py_func)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _dp_stages(y, K, ystage, ynew, h, t, ag, dt_rec, seg, mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
               cf, cw, cgap, claw, cprm, closed, cconst, cmode, fbuf, forces, storey, ground):
    """Stages 2–7 of a Dormand–Prince step of size *h* from *y* at *t* (stage 1, ``K[0]``, given).

    Fills ``K[1..6]`` and the 5th-order solution *ynew* (stage 7 is its rate: first same as last).
    One call per attempted step, with the right-hand side inlined once, in its loop: six calls of
    :func:`_rhs`, each passing its ~30 arrays, cost more than their arithmetic (this kernel counts
    no references, so the inlined arguments cost nothing).  The weighted sums are written out per
    stage (they vectorise; a loop over the tableau did not).
    """
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
        at = t + _C[stage] * h
        if ground is not None:
            _fill_grounds(ground, dt_rec, seg, at, ground[6])
        _rhs_inline(target, _ground(ag, dt_rec, seg, at), mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                    cf, cw, cgap, claw, cprm, closed, cconst, cmode, K[stage], fbuf, forces, storey, ground)


# --------------------------------------------------------------------------- #
# Interpolation on an accepted step (cubic Hermite from values and rates)
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _hermite(y0: float, r0: float, y1: float, r1: float, h: float, s: float) -> float:
    """Cubic Hermite value at fraction *s* of a step of length *h*."""
    s2 = s * s
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * y0 + (s3 - 2.0 * s2 + s) * h * r0
            + (-2.0 * s3 + 3.0 * s2) * y1 + (s3 - s2) * h * r1)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
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


@njit(cache=True, **jit.NO_REFCOUNT)  # with a Python wrapper: tested directly
def _first_crossing(d0: float, r0: float, d1: float, r1: float, h: float, upward: bool,
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
    # Stationary points of the cubic (roots of its derivative, a quadratic in s).
    qa = 6.0 * d0 + 3.0 * h * r0 - 6.0 * d1 + 3.0 * h * r1
    qb = -6.0 * d0 - 4.0 * h * r0 + 6.0 * d1 - 2.0 * h * r1
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
        f_hi = sign * (d1 if hi == 1.0 else _hermite(d0, r0, d1, r1, h, hi)) - threshold
        if near and f_hi > 0.0:
            a = lo
            b = hi
            for _ in range(80):
                mid = 0.5 * (a + b)
                if sign * _hermite(d0, r0, d1, r1, h, mid) - threshold > 0.0:
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _switch_crossing(claw, prm, const, mode, which, gap, yl0, vl0, yl1, vl1, al0, al1,
                     yr0, vr0, yr1, vr1, ar0, ar1, q0, qr0, q1, qr1, h) -> float:
    """Fraction of the step where switch function *which* of a closed contact's mode turns negative.

    The function (:func:`pounding.contact.switch_value`) is evaluated on the
    interpolants of δ, δ̇ and the internal state at EVENT_SAMPLES points; a
    sign change from ≥ 0 to < 0 is bisected to ~1e-15 of the step and the end
    of the bracket past the switch returned.  A mode entered at a located
    switch starts with its function at 0 (round-off either side): the search
    only counts a crossing after the function has been ≥ 0 in this step.
    Returns −1 if there is none.
    """
    d = _hermite(yl0, vl0, yl1, vl1, h, 0.0) - _hermite(yr0, vr0, yr1, vr1, h, 0.0) - gap
    g = kernels.switch_value(claw, prm, const, mode, which, d, vl0 - vr0, q0)
    been_positive = g > 0.0
    prev_s = 0.0
    for i in range(1, EVENT_SAMPLES + 1):
        s = i / EVENT_SAMPLES
        d = _hermite(yl0, vl0, yl1, vl1, h, s) - _hermite(yr0, vr0, yr1, vr1, h, s) - gap
        rate = _hermite(vl0, al0, vl1, al1, h, s) - _hermite(vr0, ar0, vr1, ar1, h, s)
        g = kernels.switch_value(claw, prm, const, mode, which, d, rate, _hermite(q0, qr0, q1, qr1, h, s))
        if g < 0.0 and been_positive:
            lo = prev_s
            hi = s
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                d = _hermite(yl0, vl0, yl1, vl1, h, mid) - _hermite(yr0, vr0, yr1, vr1, h, mid) - gap
                rate = _hermite(vl0, al0, vl1, al1, h, mid) - _hermite(vr0, ar0, vr1, ar1, h, mid)
                gm = kernels.switch_value(claw, prm, const, mode, which, d, rate,
                                               _hermite(q0, qr0, q1, qr1, h, mid))
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _closed_contact_samples(claw, prm, const, mode, gap, yl0, vl0, yl1, vl1, al0, al1,
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
        f = kernels.mode_force(claw, prm, const, mode, delta, rate, _hermite(q0, qr0, q1, qr1, h, s))
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
            f = kernels.mode_force(claw, prm, const, mode, delta, rate, _hermite(q0, qr0, q1, qr1, h, s))
            if f > best:
                best = f
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _peak_magnitude(values) -> float:
    """Largest |value| of equally spaced samples, refined by a parabola through the largest and its neighbours.

    For a link's force over a step (it pulls as well as pushes): the samples
    of :func:`_closed_contact_samples`.  A largest sample at either end of
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _contact_energy(y, n, cf, cw, cgap, claw, cprm, ground) -> float:
    """Elastic energy stored in all contacts (J) for state *y* (the energy audit's contact strain)."""
    nc = cgap.size
    total = 0.0
    for c in range(nc):
        delta = _combo(y, 0, cf, cw, c) - cgap[c]
        if ground is not None:
            delta = _combo(y, 0, cf, cw, c) + _ground_offset(ground, ground[6], c, 2) - cgap[c]
        total += kernels.potential(claw[c], cprm[c], delta, y[2 * n + 2 * nc + c])
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _storey_outputs(y, n, nc, below, kst, storey, shear, energy, row):
    """Storey shears and energies of state *y* into ``shear[row]`` and ``energy[row]``.

    ``shear[row, j]``: restoring (column) shear of the storey under floor j, N,
    without P-Delta.  ``energy[row]``: recoverable energy of every storey (with
    the P-Delta potential ½·(−P/h)·Δ², J) and the recoverable energy of the
    yielding ones.  *storey* is None for linear elastic storeys without P-Delta.
    """
    total = 0.0
    yielding = 0.0
    for j in range(n):
        b = below[j]
        du = y[j] - y[b] if b >= 0 else y[j]
        if storey is None:
            shear[row, j] = kst[j] * du
            total += 0.5 * kst[j] * du * du
        else:
            smodel, sprm, sidx, kpd = storey[0], storey[1], storey[2], storey[3]
            hi = sidx[j]
            r = y[2 * n + 3 * nc + 2 + hi] if hi >= 0 else 0.0
            shear[row, j] = storeys.restoring_force(smodel[j], sprm, j, kst[j], du, r)
            recoverable = storeys.recoverable_energy(smodel[j], sprm, j, kst[j], du, r)
            total += recoverable + 0.5 * kpd[j] * du * du
            if hi >= 0:
                yielding += recoverable
    energy[row, 0] = total
    energy[row, 1] = yielding


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, inline="always", **jit.NO_REFCOUNT)
def _storey_forces(y, n, nc, below, kst, storey, out, fbuf):
    """Add the yielding storeys' departure from ``kΔ`` to the floor forces *fbuf*, N.

    Writes the rates of the hysteretic states and of the storeys' work
    ∫F dΔ into *out*.  The caller has already applied ``kΔ`` and P-Delta to
    every storey.
    The storey kernels take the parameter table and a row (no row views:
    each would be reference-counted, in the solver's innermost loop).
    """
    smodel, sprm, smode, sfloor = storey[0], storey[1], storey[6], storey[7]
    nh = sfloor.size
    ih = 2 * n + 3 * nc + 2  # first hysteretic state
    for hi in range(nh):
        j = sfloor[hi]
        b = below[j]
        du = y[j] - y[b] if b >= 0 else y[j]
        dv = y[n + j] - y[n + b] if b >= 0 else y[n + j]
        r = y[ih + hi]
        model = smodel[j]
        restoring = storeys.restoring_force(model, sprm, j, kst[j], du, r)
        out[ih + hi] = storeys.state_rate(model, sprm, j, smode[hi], dv, r)
        out[ih + nh + hi] = restoring * dv
        departure = restoring - kst[j] * du
        fbuf[j] += departure
        if b >= 0:
            fbuf[b] -= departure


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _drift_interpolant(y, ynew, k1, k7, n, j, b):
    """Drift and drift rate of the storey under floor *j* at both ends of a step, and their rates."""
    if b >= 0:
        return (y[j] - y[b], y[n + j] - y[n + b], ynew[j] - ynew[b], ynew[n + j] - ynew[n + b],
                k1[n + j] - k1[n + b], k7[n + j] - k7[n + b])
    return y[j], y[n + j], ynew[j], ynew[n + j], k1[n + j], k7[n + j]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, inline="always", **jit.NO_REFCOUNT)
def _storey_event(y, ynew, k1, k7, n, nc, j, b, hi, model, uy, mode, h):
    """First switch of bilinear storey *j* inside a step: ``(fraction, STOREY_*)``, fraction −1 if none.

    Elastic mode: ``Δ − Δ_p`` reaching ``+u_y`` or ``−u_y`` (Δ_p is constant, so
    this is a crossing of the drift's Hermite cubic, found exactly by
    :func:`_first_crossing`).  Yielding: the drift rate crossing 0 against
    the yield direction (the cubic of Δ̇ from Δ̇ and Δ̈ at the ends).  *uy*: its
    yield drift, m.
    """
    if model != hysteresis.MODEL_BILINEAR:
        return -1.0, STOREY_NONE
    d0, r0, d1, r1, a0, a1 = _drift_interpolant(y, ynew, k1, k7, n, j, b)
    ih = 2 * n + 3 * nc + 2
    if mode == storeys.ELASTIC:
        plastic = y[ih + hi]
        e0 = d0 - plastic
        e1 = d1 - plastic
        # The Hermite cubic stays within max(|e0|, |e1|) + (4/27)·h·(|r0| + |r1|) (its basis
        # functions' bounds): most steps are far from the yield surface and need no search.
        if max(abs(e0), abs(e1)) + 0.25 * h * (abs(r0) + abs(r1)) < uy:
            return -1.0, STOREY_NONE
        floor = DELTA_ROUNDOFF * (abs(d0) + abs(plastic) + uy)
        s = _first_crossing(e0 - uy, r0, e1 - uy, r1, h, True, floor)
        kind = STOREY_YIELD_POSITIVE
        s2 = _first_crossing(e0 + uy, r0, e1 + uy, r1, h, False, floor)
        if s2 >= 0.0 and (s < 0.0 or s2 < s):
            s = s2
            kind = STOREY_YIELD_NEGATIVE
        return s, kind if s >= 0.0 else STOREY_NONE
    floor = DELTA_ROUNDOFF * (abs(y[n + j]) + (abs(y[n + b]) if b >= 0 else 0.0))
    s = _first_crossing(r0, a0, r1, a1, h, mode < 0, floor)
    return s, STOREY_UNLOAD if s >= 0.0 else STOREY_NONE


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _storey_events(y, ynew, k1, k7, n, nc, below, smodel, sprm, smode, sfloor, h, sev_s, sev_kind) -> float:
    """Each yielding storey's first switch inside a step (:func:`_storey_event`, inlined here) into
    ``sev_s`` and ``sev_kind``; returns the earliest fraction (2.0 if none).

    One call per attempted step for all the storeys: a call per storey passed
    its four state arrays each time, which measured ~6 % of an inelastic run.
    """
    first = 2.0
    for hi in range(sfloor.size):
        j = sfloor[hi]
        s, kind = _storey_event(y, ynew, k1, k7, n, nc, j, below[j], hi, smodel[j], sprm[j, 0], smode[hi], h)
        sev_s[hi] = s
        sev_kind[hi] = kind
        if kind != STOREY_NONE and s < first:
            first = s
    return first


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _apply_storey_events(kinds, y, n, nc, below, sfloor, sprm, smode):
    """Apply located storey events ``kinds[h]`` (STOREY_*) to the state, in place; returns how many.

    Yield onset puts the plastic drift on the yield surface (``Δ − Δ_p = ±u_y``
    exactly) and enters the yield mode, unless the drift is not moving
    outward there (a grazing touch of the surface: it stays elastic);
    unloading returns to the elastic mode.
    """
    ih = 2 * n + 3 * nc + 2
    applied = 0
    for hi in range(smode.size):
        kind = kinds[hi]
        if kind == STOREY_NONE:
            continue
        applied += 1
        j = sfloor[hi]
        b = below[j]
        drift = y[j] - y[b] if b >= 0 else y[j]
        rate = y[n + j] - y[n + b] if b >= 0 else y[n + j]
        uy = sprm[j, 0]
        if kind == STOREY_YIELD_POSITIVE:
            y[ih + hi] = drift - uy
            smode[hi] = storeys.YIELD_POSITIVE if rate > 0.0 else storeys.ELASTIC
        elif kind == STOREY_YIELD_NEGATIVE:
            y[ih + hi] = drift + uy
            smode[hi] = storeys.YIELD_NEGATIVE if rate < 0.0 else storeys.ELASTIC
        else:
            smode[hi] = storeys.ELASTIC
    return applied


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _collapse_crossing(y, ynew, k1, k7, n, below, heights, stop_ratio, h):
    """First instant in a step where a storey's |drift| exceeds ``stop_ratio·height``: (fraction, floor)."""
    best = -1.0
    where = -1
    for j in range(n):
        d0, r0, d1, r1, a0, a1 = _drift_interpolant(y, ynew, k1, k7, n, j, below[j])
        limit = stop_ratio * heights[j]
        # The Hermite cubic stays within max(|d0|, |d1|) + (4/27)·h·(|r0| + |r1|) (its basis
        # functions' bounds): search only where the limit is within reach.
        if max(abs(d0), abs(d1)) + 0.25 * h * (abs(r0) + abs(r1)) < limit:
            continue
        for upward in (True, False):
            s = _first_crossing(d0, r0, d1, r1, h, upward, limit)
            if s >= 0.0 and (best < 0.0 or s < best):
                best = s
                where = j
    return best, where


# Columns of the impact table built during integration.
(IMP_CONTACT, IMP_TIME, IMP_VELOCITY, IMP_CONSTANT, IMP_PEAK_FORCE, IMP_END, IMP_IMPULSE, IMP_SEPARATION,
 IMP_WORK) = range(9)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _grown(table, rows, needed, limit):
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _velocity_jump(c, t, y, n, cf, cw, claw, cprm, impacts, n_imp, mass, dvg):
    """Instantaneous impact (stereo-mechanical): jump the two floor velocities.

    The impulse ``J = (1+e)·m_eff·v0`` acts on the two floors (−J on the
    left, +J on the right); the work ``J·(v0 + v0')/2`` it does (the energy
    lost, ½·m_eff·(1−e²)·v0²) and the impulse are added to the contact's
    energy-audit states.  The impact row (room made by the caller) opens and
    closes at once; returns the new row count.  *dvg* (m/s) is the contact's
    differential ground velocity: ``v0 = δ̇`` includes it, and the work
    ``J·dvg`` it does goes to the ground-work state (the last one).
    """
    nc = cf.size // SIDE_TERMS
    v0 = _combo(y, n, cf, cw, c) + dvg
    impulse = kernels.jump_impulse(claw[c], cprm[c], v0)
    _kick(y, n, mass, cf, cw, c, impulse)
    v_after = _combo(y, n, cf, cw, c) + dvg
    y[2 * n + c] += impulse
    y[2 * n + nc + c] += impulse * 0.5 * (v0 + v_after)
    y[y.size - 1] += impulse * dvg
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _switch_contact(c, upward, t, y, n, cf, cw, claw, cprm, closed, cconst, impacts, n_imp, open_imp, mass, dvg):
    """Apply a located gap closure (*upward*) or separation of contact *c* at time *t*.

    Closure fixes the per-impact constant from the approach velocity
    ``v0 = δ̇(t)`` and opens a row of the impact table; separation closes that
    row with the separation velocity and the impulse.  The caller makes room
    for one more row first (:func:`_grown`); returns the new row count.
    """
    rate = _combo(y, n, cf, cw, c) + dvg
    nc = closed.size
    if upward:
        if kernels.is_instantaneous(claw[c]):
            return _velocity_jump(c, t, y, n, cf, cw, claw, cprm, impacts, n_imp, mass, dvg)
        closed[c] = True
        if rate < 0.0:
            rate = 0.0  # a grazing touch (the caller removed δ̇ < 0): what is left is round-off of that correction
        y[2 * n + 2 * nc + c] = 0.0  # internal state starts afresh at every impact
        cconst[c] = kernels.onset_constant(claw[c], cprm[c], rate)
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.NO_REFCOUNT)
def _plastic_jump(c, y, n, cf, cw, mass, dvg):
    """Remove the relative velocity of contact *c* with a plastic impulse ``m_eff·v0`` (N·s, returned).

    The impulse and its work (the energy lost, ½·m_eff·v0²) are added to the
    contact's energy-audit states, ``J·dvg`` to the ground work (*dvg*: the
    contact's differential ground velocity, m/s, part of ``v0 = δ̇``).
    """
    nc = cf.size // SIDE_TERMS
    v0 = _combo(y, n, cf, cw, c) + dvg
    impulse = _effective_mass(mass, cf, cw, c) * v0
    _kick(y, n, mass, cf, cw, c, impulse)
    y[2 * n + c] += impulse
    y[2 * n + nc + c] += impulse * 0.5 * (v0 + (_combo(y, n, cf, cw, c) + dvg))
    y[y.size - 1] += impulse * dvg
    return impulse


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _apply_events(kinds, t, y, ag_t, mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                  cf, cw, cgap, claw, cprm, closed, cconst, cmode, scratch, deriv, fbuf, forces,
                  impacts, n_imp, open_imp, storey, ground):
    """Apply the located events ``kinds[c]`` (EVENT_*) at time *t* to the state *y*, in place.

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

    Returns ``(impacts, n_imp, n_applied, first_step_cap, status)``;
    *first_step_cap* (s) is the duration estimate of the shortest newly
    closed compliant contact over STEPS_PER_CONTACT (inf if none).
    """
    n = mass.size
    nc = cgap.size
    iq = 2 * n + 2 * nc
    n_applied = 0
    cap = np.inf
    status = 0
    for c in range(nc):
        kind = kinds[c]
        if kind == EVENT_NONE:
            continue
        n_applied += 1
        dvg = 0.0
        if ground is not None:
            dvg = _ground_offset(ground, ground[6], c, 1)
        rate = _combo(y, n, cf, cw, c) + dvg
        if kind == EVENT_CLOSE:
            if n_imp + 1 > IMPACT_ROW_LIMIT:
                status = STATUS_TABLE_LIMIT
                break
            impacts = _grown(impacts, n_imp, n_imp + 1, n_imp - n_imp + IMPACT_ROW_LIMIT)
            if kernels.is_instantaneous(claw[c]):
                if rate <= 0.0:
                    n_applied -= 1  # touching without approach: no impact
                    continue
                stick = False
                if rate <= kernels.rest_velocity(claw[c], cprm[c]):
                    for i in range(y.size):
                        scratch[i] = y[i]
                    _plastic_jump(c, scratch, n, cf, cw, mass, dvg)
                    closed[c] = True
                    cmode[c] = kernels.MODE_STUCK
                    _rhs(scratch, ag_t, mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                         cf, cw, cgap, claw, cprm, closed, cconst, cmode, deriv, fbuf, forces, storey, ground)
                    stick = forces[c] > 0.0
                    closed[c] = False
                    cmode[c] = 0
                if not stick:
                    n_imp = _velocity_jump(c, t, y, n, cf, cw, claw, cprm, impacts, n_imp, mass, dvg)
                    continue
                impacts[n_imp, IMP_CONTACT] = c
                impacts[n_imp, IMP_TIME] = t
                impacts[n_imp, IMP_VELOCITY] = rate
                impacts[n_imp, IMP_CONSTANT] = np.nan
                impacts[n_imp, IMP_PEAK_FORCE] = 0.0
                impacts[n_imp, IMP_IMPULSE] = y[2 * n + c]
                impacts[n_imp, IMP_WORK] = y[2 * n + nc + c]
                _plastic_jump(c, y, n, cf, cw, mass, dvg)
                closed[c] = True
                cmode[c] = kernels.MODE_STUCK
                cconst[c] = 0.0
                open_imp[c] = n_imp
                n_imp += 1
                continue
            if rate < 0.0:
                # A tangency located to round-off (δ̇ ~ −1e-17 m/s): a grazing touch, v0 = 0.
                k = SIDE_TERMS * c
                if cw[k] == 1.0 and cw[k + 1] == 0.0 and cw[k + 2] == -1.0 and cw[k + 3] == 0.0:
                    # a plain floor pair: the pre-weighted form, bit for bit (see _effective_mass)
                    lf = cf[k]
                    rf = cf[k + 2]
                    y[n + lf] -= rate * mass[rf] / (mass[lf] + mass[rf])
                    y[n + rf] += rate * mass[lf] / (mass[lf] + mass[rf])
                else:
                    _kick(y, n, mass, cf, cw, c, rate / _compliance(mass, cf, cw, c))
                rate = 0.0
            n_imp = _switch_contact(c, True, t, y, n, cf, cw, claw, cprm, closed, cconst, impacts, n_imp,
                                    open_imp, mass, dvg)
            cmode[c] = kernels.onset_mode(claw[c], cprm[c], rate)
            m_eff = _effective_mass(mass, cf, cw, c)
            duration = kernels.contact_duration(claw[c], cprm[c], rate, m_eff)
            if duration > 0.0:
                cap = min(cap, duration / STEPS_PER_CONTACT)
        elif kind == EVENT_SEPARATE or kind == EVENT_RELEASE:
            n_imp = _switch_contact(c, False, t, y, n, cf, cw, claw, cprm, closed, cconst, impacts, n_imp,
                                    open_imp, mass, dvg)
            cmode[c] = 0
        else:
            which = kind - EVENT_SWITCH0
            new_mode = kernels.next_mode(claw[c], cmode[c], which)
            delta = _combo(y, 0, cf, cw, c) - cgap[c]
            if ground is not None:
                delta = _combo(y, 0, cf, cw, c) + _ground_offset(ground, ground[6], c, 2) - cgap[c]
            y[iq + c] = kernels.snapped_internal(claw[c], cprm[c], new_mode, delta, rate, y[iq + c])
            cmode[c] = new_mode
    return impacts, n_imp, n_applied, cap, status


# --------------------------------------------------------------------------- #
# The integrator
# --------------------------------------------------------------------------- #


@njit(cache=True)
def _integrate(mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
               cf, cw, cgap, claw, cprm, storey, ground,
               ag, dt_rec, t_end, rtol, atol_u, atol_v, output_dt, first_step, y_initial):
    n = mass.size
    nc = cgap.size
    # *storey* is None for linear elastic storeys without P-Delta or a collapse limit: every
    # ``if storey is not None`` block below is then pruned at compile time, and the elastic
    # row runs the plain elastic integrator.  Otherwise it is the tuple built by
    # :func:`_storey_arguments`.
    # The tuples' arrays are taken out once, here: each ``storey[k]`` in the loop would count a reference.
    nh = nc - nc
    if storey is not None:
        smodel, sprm, heights, stop_ratio, smode, sfloor, storey_tol = (storey[0], storey[1], storey[4], storey[5],
                                                                        storey[6], storey[7], storey[8])
        nh = sfloor.size
    S = 2 * n + 3 * nc + 2 + 2 * nh + 1  # the last state: work of the differential ground motion on the contacts
    # *ground* is None with one common ground (row 0 is *ag*); else the tuple of _ground_arguments.
    n_ground = nc - nc + 1
    if ground is not None:
        n_ground = ground[0].shape[0]
        gnow, gstart, gend = ground[6], ground[7], ground[8]  # the ground state now, at a step's start and end
    ih = 2 * n + 3 * nc + 2  # first hysteretic state
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
    K = np.zeros((7, S))  # the stage rates, rows k1..k7
    k1, k2, k3, k4, k5, k6, k7 = K[0], K[1], K[2], K[3], K[4], K[5], K[6]
    fbuf = np.zeros(n)
    forces = np.zeros(nc)
    closed = np.zeros(nc, dtype=np.bool_)
    cconst = np.zeros(nc)
    cmode = np.zeros(nc, dtype=np.int64)  # mode of each closed contact (pounding.contact.MODE_*)
    event_s = np.empty(nc)                # fraction of the step where each contact's next event lies
    event_kind = np.zeros(nc, dtype=np.int64)
    pending = np.zeros(nc, dtype=np.int64)  # events the current (retaken) step was shortened to end at
    forces_end = np.zeros(nc)
    internal_tol = np.empty(nc)
    for c in range(nc):
        internal_tol[c] = kernels.internal_tolerance(claw[c], cprm[c], atol_u)
    # Yielding storeys' located events (bilinear yield onset and unloading) and the collapse limit.
    sev_s = np.empty(nh)
    sev_kind = np.zeros(nh, dtype=np.int64)
    spending = np.zeros(nh, dtype=np.int64)
    collapse_floor = zero - 1
    collapse_s = -1.0
    collapse_pending = False

    out_time = np.empty(n_out)
    out_state = np.empty((n_out, S))
    out_acc = np.empty((n_out, n))
    out_force = np.empty((n_out, nc))
    out_ag = np.empty(n_out)
    out_support = np.empty((n_out, n_ground))
    out_pot = np.empty(n_out)
    out_shear = np.empty((n_out, n))
    out_storey_energy = np.empty((n_out, 2))

    peak_u = np.zeros(n)
    peak_drift = np.zeros(n)
    peak_force = np.zeros(nc)

    impacts = _grown(np.empty((zero, zero + 9)), zero, zero + 64, zero + IMPACT_ROW_LIMIT)  # NaN-filled
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
        closed[c] = kernels.is_permanent(claw[c])  # links are engaged from the start and never open

    t = 0.0
    seg = zero
    if ground is not None:
        _fill_grounds(ground, dt_rec, seg, 0.0, gnow)
    _rhs(y, _ground(ag, dt_rec, seg, 0.0), mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
         cf, cw, cgap, claw, cprm, closed, cconst, cmode, k1, fbuf, forces, storey, ground)
    # First output sample at t = 0.
    out_time[0] = 0.0
    _storey_outputs(y, n, nc, below, kst, storey, out_shear, out_storey_energy, 0)
    for i in range(S):
        out_state[0, i] = y[i]
    for j in range(n):
        out_acc[0, j] = k1[n + j]
    for c in range(nc):
        out_force[0, c] = 0.0
    out_ag[0] = _ground(ag, dt_rec, seg, 0.0)
    if ground is not None:
        for g in range(n_ground):
            out_support[0, g] = gnow[0, g]
    out_pot[0] = _contact_energy(y, n, cf, cw, cgap, claw, cprm, ground)
    i_out = 1

    h = first_step
    n_steps = 0
    n_rej = 0
    status = 0
    tiny = 1e-12 * max(dt_rec, 1.0)
    event_cap = EVENTS_PER_WINDOW_BASE + EVENTS_PER_WINDOW_PER_CONTACT * nc
    window_start = 0.0
    window_events = zero

    while t < t_end - tiny and i_out <= n_out:
        while (seg + 1) * dt_rec <= t + 1e-9 * dt_rec:
            seg += 1
        seg_end = min((seg + 1) * dt_rec, t_end)
        room = seg_end - t
        h_try = h
        if h_try >= room or t + 1.01 * h_try >= seg_end:
            h_try = room
        h_before_events = h_try  # the error-controlled size a located event shortens
        rejected = False
        n_retake = zero
        for c in range(nc):
            pending[c] = EVENT_NONE
        if storey is not None:
            for hi in range(nh):
                spending[hi] = STOREY_NONE
            collapse_pending = False
        while True:
            if h_try < 1e-14 * max(1.0, t):
                status = STATUS_STEP_TOO_SMALL
                break
            # ---- Dormand–Prince stages 2–7 ---------------------------------
            _dp_stages(y, K, ystage, ynew, h_try, t, ag, dt_rec, seg, mass, kst, below, a0, a1, dstart, dsize, doff,
                       dvals, cf, cw, cgap, claw, cprm, closed, cconst, cmode, fbuf, forces, storey, ground)
            # ---- error norm (max norm over displacements, velocities and the laws' internal states)
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
            for c in range(nc):
                if internal_tol[c] > 0.0 and finite:
                    i = iq + c
                    e = h_try * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
                    r = abs(e) / (internal_tol[c] + rtol * max(abs(y[i]), abs(ynew[i])))
                    if not (r < 1e300):
                        finite = False
                    elif r > err:
                        err = r
            if storey is not None:
                for hi in range(nh):
                    if not finite:
                        break
                    i = ih + hi
                    e = h_try * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
                    r = abs(e) / (storey_tol[hi] + rtol * max(abs(y[i]), abs(ynew[i])))
                    if not (r < 1e300):
                        finite = False
                    elif r > err:
                        err = r
            if not finite or err > 1.0:
                n_rej += 1
                rejected = True
                h_try *= MIN_FACTOR if not finite else max(MIN_FACTOR, SAFETY * err ** -0.2)
                h_before_events = h_try
                n_retake = zero
                for c in range(nc):
                    pending[c] = EVENT_NONE
                if storey is not None:
                    for hi in range(nh):
                        spending[hi] = STOREY_NONE
                    collapse_pending = False
                continue
            for c in range(nc):
                forces_end[c] = forces[c]  # forces at the step's end (the last stage evaluation)
            # ---- contact events inside the step ------------------------------
            # With several grounds δ is the Hermite cubic of the total displacements: each side's
            # weighted floors over its own ground plus the contact's differential ground motion
            # (itself a cubic within a record step, so the interpolant reproduces it exactly).
            if ground is not None:
                _fill_grounds(ground, dt_rec, seg, t, gstart)
                _fill_grounds(ground, dt_rec, seg, t + h_try, gend)
            s_first = 2.0
            for c in range(nc):
                event_s[c] = -1.0
                event_kind[c] = EVENT_NONE
                # δ, δ̇ at both ends of the step, their rates (k1, k7), and the round-off scale of δ:
                # _step_kinematics written out, as this search runs for every contact at every step
                # (as a call it measured ~5 % slower on pair.yaml, and again once the kernels counted
                # no references: min of 6 alternated runs, 9.2 against 8.7 ms).
                d0 = 0.0
                r0 = 0.0
                d1 = 0.0
                r1 = 0.0
                q0 = 0.0
                q1 = 0.0
                size = 0.0
                for k in range(SIDE_TERMS * c, SIDE_TERMS * c + SIDE_TERMS):
                    w = cw[k]
                    f = cf[k]
                    d0 += w * y[f]
                    r0 += w * y[n + f]
                    d1 += w * ynew[f]
                    r1 += w * ynew[n + f]
                    q0 += w * k1[n + f]
                    q1 += w * k7[n + f]
                    size += abs(w * y[f])
                if ground is not None:
                    d0 += _ground_offset(ground, gstart, c, 2)
                    r0 += _ground_offset(ground, gstart, c, 1)
                    q0 += _ground_offset(ground, gstart, c, 0)
                    d1 += _ground_offset(ground, gend, c, 2)
                    r1 += _ground_offset(ground, gend, c, 1)
                    q1 += _ground_offset(ground, gend, c, 0)
                d0 -= cgap[c]
                d1 -= cgap[c]
                floor = DELTA_ROUNDOFF * (size + abs(cgap[c]))
                s = -1.0
                kind = EVENT_NONE
                if kernels.is_permanent(claw[c]):
                    continue  # a link has no events
                if not closed[c]:
                    s = _first_crossing(d0, r0, d1, r1, h_try, True, floor)
                    kind = EVENT_CLOSE
                elif cmode[c] == kernels.MODE_STUCK:
                    kind = EVENT_RELEASE
                    if forces_end[c] < 0.0:
                        # The constraint force turns tensile inside the step: bisect on the interpolant.
                        lo = 0.0
                        hi = 1.0
                        for _ in range(60):
                            mid = 0.5 * (lo + hi)
                            for i in range(S):
                                ystage[i] = _hermite(y[i], k1[i], ynew[i], k7[i], h_try, mid)
                            if ground is not None:
                                _fill_grounds(ground, dt_rec, seg, t + mid * h_try, gnow)
                            _rhs(ystage, _ground(ag, dt_rec, seg, t + mid * h_try), mass, kst, below, a0, a1,
                                 dstart, dsize, doff, dvals, cf, cw, cgap, claw, cprm, closed, cconst, cmode, k2,
                                 fbuf, forces, storey, ground)
                            if forces[c] < 0.0:
                                hi = mid
                            else:
                                lo = mid
                            if hi - lo < 1e-13:
                                break
                        s = hi
                else:
                    s = _first_crossing(d0, r0, d1, r1, h_try, False, floor)
                    kind = EVENT_SEPARATE
                    for which in range(kernels.switch_count(claw[c], cprm[c])):
                        # The interpolants are linear in the data: δ's from the combined side data.
                        sw = _switch_crossing(claw[c], cprm[c], cconst[c], cmode[c], which, cgap[c],
                                              d0 + cgap[c], r0, d1 + cgap[c], r1, q0, q1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                                              y[iq + c], k1[iq + c], ynew[iq + c], k7[iq + c], h_try)
                        if sw >= 0.0 and (s < 0.0 or sw < s):
                            s = sw
                            kind = EVENT_SWITCH0 + which
                if s >= 0.0:
                    event_s[c] = s
                    event_kind[c] = kind
                    if s < s_first:
                        s_first = s
            collapse_s = -1.0
            if storey is not None:
                s = _storey_events(y, ynew, k1, k7, n, nc, below, smodel, sprm, smode, sfloor, h_try, sev_s, sev_kind)
                if s < s_first:
                    s_first = s
                if stop_ratio > 0.0:
                    collapse_s, collapse_at = _collapse_crossing(y, ynew, k1, k7, n, below, heights, stop_ratio,
                                                                 h_try)
                    if collapse_s >= 0.0:
                        collapse_floor = collapse_at
                        if collapse_s < s_first:
                            s_first = collapse_s
            if s_first <= 1.0 and s_first * h_try <= tiny:
                # Events at the very start of the step: apply them at t and redo the step.
                for c in range(nc):
                    if event_kind[c] != EVENT_NONE and event_s[c] * h_try > tiny:
                        event_kind[c] = EVENT_NONE
                if collapse_s >= 0.0 and collapse_s * h_try <= tiny:
                    status = STATUS_COLLAPSED
                    break
                n_storey = zero
                if storey is not None:
                    for hi in range(nh):
                        if sev_kind[hi] != STOREY_NONE and sev_s[hi] * h_try > tiny:
                            sev_kind[hi] = STOREY_NONE
                    n_storey = _apply_storey_events(sev_kind, y, n, nc, below, sfloor, sprm, smode)
                if ground is not None:
                    _fill_grounds(ground, dt_rec, seg, t, gnow)
                impacts, n_imp, n_applied, cap, status = _apply_events(
                    event_kind, t, y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize,
                    doff, dvals, cf, cw, cgap, claw, cprm, closed, cconst, cmode, ystage, k2, fbuf, forces,
                    impacts, n_imp, open_imp, storey, ground)
                n_applied += n_storey
                if t - window_start > dt_rec:
                    window_start = t
                    window_events = zero
                window_events += n_applied
                if window_events > event_cap:
                    status = STATUS_EVENT_LIMIT
                if status != 0:
                    break
                if ground is not None:
                    _fill_grounds(ground, dt_rec, seg, t, gnow)
                _rhs(y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize, doff,
                     dvals, cf, cw, cgap, claw, cprm, closed, cconst, cmode, k1, fbuf, forces, storey, ground)
                if cap < h_try:
                    h_try = cap
                    h_before_events = cap
                for c in range(nc):
                    pending[c] = EVENT_NONE
                if storey is not None:
                    for hi in range(nh):
                        spending[hi] = STOREY_NONE
                    collapse_pending = False
                n_retake = zero
                continue
            if s_first < 1.0 - EVENT_END_TOLERANCE and n_retake < MAX_RETAKES:
                # Retake the step to end at the first event; the retaken step is searched again.
                for c in range(nc):
                    pending[c] = event_kind[c] if event_kind[c] != EVENT_NONE and event_s[c] <= s_first else EVENT_NONE
                if storey is not None:
                    for hi in range(nh):
                        spending[hi] = (sev_kind[hi] if sev_kind[hi] != STOREY_NONE and sev_s[hi] <= s_first
                                        else STOREY_NONE)
                    collapse_pending = collapse_s >= 0.0 and collapse_s <= s_first
                h_try = s_first * h_try
                n_retake += 1
                continue
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
            if kernels.is_permanent(claw[c]):
                # A link: peak |F| on the step's interpolant (no trace: it is engaged at every step).
                e_d0, e_r0, e_d1, e_r1, e_a0, e_a1, _ = _step_kinematics(y, ynew, k1, k7, n, cf, cw, c, ground)
                _closed_contact_samples(claw[c], cprm[c], cconst[c], cmode[c], cgap[c],
                                        e_d0, e_r0, e_d1, e_r1, e_a0, e_a1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                                        y[iq + c], k1[iq + c], ynew[iq + c], k7[iq + c], h_used, fractions, deltas,
                                        values)
                fpk = _peak_magnitude(values)
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
                # The interpolants are linear in the data: δ's from the combined side data.
                e_d0, e_r0, e_d1, e_r1, e_a0, e_a1, _ = _step_kinematics(y, ynew, k1, k7, n, cf, cw, c, ground)
                fpk = _closed_contact_samples(claw[c], cprm[c], cconst[c], cmode[c], cgap[c],
                                              e_d0, e_r0, e_d1, e_r1, e_a0, e_a1,
                                              0.0, 0.0, 0.0, 0.0, 0.0, 0.0, y[iq + c], k1[iq + c], ynew[iq + c],
                                              k7[iq + c], h_used, fractions, deltas, values)
                if n_trace + FORCE_SAMPLES + 1 > TRACE_ROW_LIMIT:
                    status = STATUS_TABLE_LIMIT
                    break
                trace = _grown(trace, n_trace, n_trace + FORCE_SAMPLES + 1, zero + TRACE_ROW_LIMIT)
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
        if status != 0:
            break
        # ---- output samples inside (t, t_new] ------------------------------
        while i_out < n_out and i_out * output_dt <= t_new + 1e-9 * output_dt:
            t_o = i_out * output_dt
            if t_o > t_new:
                t_o = t_new
            s = (t_o - t) / h_used
            for i in range(S):
                ystage[i] = _hermite(y[i], k1[i], ynew[i], k7[i], h_used, s)
            ag_o = _ground(ag, dt_rec, seg, t_o)
            if ground is not None:
                _fill_grounds(ground, dt_rec, seg, t_o, gnow)
                for g in range(n_ground):
                    out_support[i_out, g] = gnow[0, g]
            _rhs(ystage, ag_o, mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                 cf, cw, cgap, claw, cprm, closed, cconst, cmode, k2, fbuf, forces, storey, ground)
            out_time[i_out] = t_o
            for i in range(S):
                out_state[i_out, i] = ystage[i]
            for j in range(n):
                out_acc[i_out, j] = k2[n + j]
            for c in range(nc):
                out_force[i_out, c] = forces[c]
            out_ag[i_out] = ag_o
            out_pot[i_out] = _contact_energy(ystage, n, cf, cw, cgap, claw, cprm, ground)
            _storey_outputs(ystage, n, nc, below, kst, storey, out_shear, out_storey_energy, i_out)
            i_out += 1
        # ---- accept ---------------------------------------------------------
        t = t_new
        for i in range(S):
            y[i] = ynew[i]
            k1[i] = k7[i]
        n_steps += 1
        # Events at the step's end: those the retaken step was shortened to, and any other found there.
        # (The appliers are called only when there is something to apply: a call passes each of
        # their arrays as a flattened struct, and most steps end without an event.)
        contact_events = False
        for c in range(nc):
            if event_kind[c] == EVENT_NONE:
                event_kind[c] = pending[c]
            if event_kind[c] != EVENT_NONE:
                contact_events = True
        n_storey = zero
        if storey is not None:
            if collapse_s >= 0.0 or collapse_pending:
                status = STATUS_COLLAPSED  # located: this step ends where the drift limit is first exceeded
                break
            storey_events = False
            for hi in range(nh):
                if sev_kind[hi] == STOREY_NONE:
                    sev_kind[hi] = spending[hi]
                if sev_kind[hi] != STOREY_NONE:
                    storey_events = True
            if storey_events:
                n_storey = _apply_storey_events(sev_kind, y, n, nc, below, sfloor, sprm, smode)
        if ground is not None:
            _fill_grounds(ground, dt_rec, seg, t, gnow)
        n_applied = zero
        cap = np.inf
        if contact_events:
            impacts, n_imp, n_applied, cap, status = _apply_events(
                event_kind, t, y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize, doff,
                dvals, cf, cw, cgap, claw, cprm, closed, cconst, cmode, ystage, k2, fbuf, forces, impacts, n_imp,
                open_imp, storey, ground)
        n_applied += n_storey
        if n_applied > 0:
            if t - window_start > dt_rec:
                window_start = t
                window_events = zero
            window_events += n_applied
            if window_events > event_cap:
                status = STATUS_EVENT_LIMIT
            if ground is not None:
                _fill_grounds(ground, dt_rec, seg, t, gnow)
            _rhs(y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                 cf, cw, cgap, claw, cprm, closed, cconst, cmode, k1, fbuf, forces, storey, ground)
            # The step the controller accepted before the event cut it short; a newly closed
            # compliant contact starts at a fraction of its duration estimate instead.
            h = min(h_before_events, cap)
            if status != 0:
                break
        else:
            factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** -0.2)
            if rejected:
                factor = min(factor, 1.0)  # no growth right after a rejection (Hairer et al. §II.4)
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
            if ground is not None:
                _fill_grounds(ground, dt_rec, seg, t, gnow)
            _rhs(y, _ground(ag, dt_rec, seg, t), mass, kst, below, a0, a1, dstart, dsize, doff, dvals,
                 cf, cw, cgap, claw, cprm, closed, cconst, cmode, k2, fbuf, forces, storey, ground)
            for c in range(nc):
                out_force[i2, c] = forces[c]
            _storey_outputs(y, n, nc, below, kst, storey, out_shear, out_storey_energy, i2)
            out_ag[i2] = _ground(ag, dt_rec, seg, t)
            if ground is not None:
                for g in range(n_ground):
                    out_support[i2, g] = gnow[0, g]
            out_pot[i2] = _contact_energy(y, n, cf, cw, cgap, claw, cprm, ground)
        i_out = n_out
    if status != STATUS_COLLAPSED:
        collapse_floor = zero - 1
    return (out_time[:i_out], out_state[:i_out], out_acc[:i_out], out_force[:i_out], out_ag[:i_out], out_pot[:i_out],
            out_support[:i_out],
            peak_u, peak_drift, peak_force,
            impacts[:n_imp], trace[:n_trace], out_shear[:i_out], out_storey_energy[:i_out], y, collapse_floor,
            n_steps, n_rej, status, t)


# The integrator inlines the kernels, and they inline the law ids and sizes of contact/laws.py:
# its cached code is stale when any of the three files changes.
jit.stamp_caches_with_sources([f for f in globals().values() if isinstance(f, Dispatcher)],
                              [__file__, kernels.__file__, contact_laws.__file__, storeys.__file__,
                               hysteresis.__file__, contact_links.__file__])
jit.load_from_cache_without_refresh(_integrate)


def _storey_arguments(system: System, atol: float) -> tuple | None:
    """The compiled integrator's *storey* argument: None for linear elastic storeys without
    P-Delta or collapse limit (the integrator then compiles without any storey code), else
    ``(model, parameters, state index, P-Delta stiffness, height, stop ratio, mode, floor of
    each state, tolerance of each state)``.

    A state's tolerance is atol for a bilinear storey's plastic drift (m) and atol/u_y for
    Bouc–Wen's dimensionless z; its mode (a fresh array: the integrator changes it) starts elastic.
    """
    if system.n_hysteretic == 0 and not np.any(system.p_delta_stiffness) and system.stop_drift_ratio <= 0.0:
        return None
    floors = np.flatnonzero(system.storey_state >= 0)
    state_floor = np.empty(floors.size, dtype=np.int64)
    state_floor[system.storey_state[floors]] = floors
    bilinear = system.storey_model[state_floor] == hysteresis.MODEL_BILINEAR
    tolerance = np.where(bilinear, atol, atol / np.where(bilinear, 1.0, system.storey_parameters[state_floor, 0]))
    return (np.ascontiguousarray(system.storey_model, dtype=np.int64),
            np.ascontiguousarray(system.storey_parameters, dtype=np.float64),
            np.ascontiguousarray(system.storey_state, dtype=np.int64),
            np.ascontiguousarray(system.p_delta_stiffness, dtype=np.float64),
            np.ascontiguousarray(system.storey_height, dtype=np.float64),
            float(system.stop_drift_ratio), np.zeros(floors.size, dtype=np.int64), state_floor,
            np.ascontiguousarray(tolerance, dtype=np.float64))


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
    # A fresh writable copy: a read-only array would compile a second specialisation.  One ground:
    # a 1-D array (ground None: the single-record solver); several: one row each (row 0 also as *ag*).
    rows = np.array(np.atleast_2d(ground_acceleration), dtype=np.float64, copy=True, order="C")
    ag = np.ascontiguousarray(rows[0]).copy()
    ground = _ground_arguments(system, rows, float(time_step)) if rows.shape[0] > 1 else None
    # Independent of output_dt, so the step sequence (and every peak) is the same whatever the output sampling.
    first_step = 0.1 * time_step
    y_initial = np.zeros(2 * system.n_floors)
    if initial_displacement is not None:
        y_initial[: system.n_floors] = initial_displacement
    if initial_velocity is not None:
        y_initial[system.n_floors:] = initial_velocity
    # Absent terms (the ground, a wall: floor −1) go to the kernels as floor 0 with weight 0.
    kernel_floors = np.ascontiguousarray(np.where(system.contact_weights == 0.0, 0, system.contact_floors),
                                         dtype=np.int64).reshape(-1)  # flat: term k of contact c at 4c + k
    raw = _integrate(system.mass, system.storey_stiffness, system.below, system.rayleigh_mass,
                     system.rayleigh_stiffness, system.dense_start, system.dense_size,
                     system.dense_offset, system.dense_values, kernel_floors,
                     np.ascontiguousarray(system.contact_weights, dtype=float).reshape(-1), system.contact_gap,
                     system.contact_law, system.contact_parameters, _storey_arguments(system, float(atol)), ground, ag,
                     float(time_step), float(duration), float(rtol),
                     float(atol), float(atol_velocity), float(output_dt), float(first_step),
                     y_initial)
    (time, state, acc, force, ag_out, potential, support, peak_u, peak_drift, peak_force, impacts, trace, shear,
     storey_energy, final_state, collapse_floor, n_steps, n_rej, status, t_final) = raw
    return RawSolution(time, state, acc, force, ag_out, potential, peak_u, peak_drift, peak_force,
                       impacts[:, IMP_CONTACT].astype(np.int64), impacts[:, IMP_TIME],
                       impacts[:, IMP_VELOCITY], impacts[:, IMP_CONSTANT], impacts[:, IMP_PEAK_FORCE],
                       impacts[:, IMP_END], impacts[:, IMP_IMPULSE], impacts[:, IMP_SEPARATION],
                       impacts[:, IMP_WORK], trace[:, 0], trace[:, 1].astype(np.int64), trace[:, 2], trace[:, 3],
                       shear, storey_energy, final_state.copy(), int(collapse_floor),
                       int(n_steps), int(n_rej), int(status), float(t_final),
                       None if ground is None else support)


def _ground_arguments(system: System, rows: np.ndarray, time_step: float) -> tuple:
    """The solver's *ground* tuple for several grounds (rows of *rows*, m/s², step *time_step* s)."""
    velocity, displacement = ground_kinematics(rows, time_step)
    n_ground = rows.shape[0]
    return (rows, displacement, velocity, np.asarray(system.floor_ground, dtype=np.int64),
            np.asarray(system.contact_ground_left, dtype=np.int64),
            np.asarray(system.contact_ground_right, dtype=np.int64),
            np.zeros((3, n_ground)), np.zeros((3, n_ground)), np.zeros((3, n_ground)))


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
        displacement the cubic the solver evaluates (:func:`_grounds`).
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
