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
  force (:mod:`pounding.solver.storeys`).  An IMK storey's state is its
  shear, and every branch change of it is a located event
  (:mod:`pounding.solver.imk`); one that loses its strength ends the run as a
  collapse.  P-Delta is a linear geometric stiffness per storey.  A run stops,
  located, when a storey's drift ratio first exceeds its building's collapse
  drift ratio (``storey_stop_ratio``, STATUS_COLLAPSED), or when a storey with P-Delta loses its lateral
  resistance, its restoring force plus P-Delta falling to zero as its drift
  grows (STATUS_UNSTABLE).

State vector layout (:mod:`pounding.solver.layout`): ``[u (N), v (N), impulse (nc), work (nc), q (nc), E_input, E_damping, r (nh), W (nh), W_g]``
(``q``: each contact law's internal state, e.g. the bilinear law's hysteretic force; ``r``: each
yielding storey's hysteretic state; ``W``: its work ∫F dΔ, J; ``W_g``: the work ∫F·(u̇_g,L − u̇_g,R) dt
of the contact forces on the differential ground motion, J, 0 with one common ground).

* **Multiple supports.** Each building may stand on its own ground motion (a row of the
  ground-acceleration array; a different record, or the same one lagged by wave passage).
  Floors move relative to their own ground; contacts see total displacements, so the
  differential ground displacement and velocity enter δ and δ̇ (:func:`pounding.solver.kinematics.ground_offset`),
  integrated exactly from the piecewise-linear accelerations.  Like *storey*, the *ground*
  argument is None with one common ground, and every ``if ground is not None`` block is then
  pruned at compile time: the single-record solver is the plain one.

Modules
-------
This module is the driver (attempt → locate → retake or accept → apply →
record) and the Python entry point :func:`integrate`; the parts it drives:

==================  ===========================================================
``layout``          state offsets (:class:`~pounding.solver.layout.Layout`) and the named records
``kinematics``      δ, δ̇, storey drift, ground offsets (solver and results)
``rhs``             right-hand side, stuck contacts' constraint forces
``dormand_prince``  tableau, stages, the error norm, step-size factor
``dense``           Hermite interpolant, its extrema and exact crossings
``contact_events``  contact events: locate, apply
``storey_events``   bilinear storeys' yield and unloading, IMK branch changes, collapse: locate, apply
``imk``             IMK storeys' discrete state and branch rules at their events
``recorder``        output samples, peaks, impact table, trace of closed contacts
``status``          how a run ended
==================  ===========================================================

The method's references (Dormand & Prince 1980; Hairer, Nørsett & Wanner 1993) are in
:mod:`pounding.solver.dormand_prince`.
"""


from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from pounding import hysteresis
from pounding.solver import imk, jit
from pounding.solver import kernels
from pounding.solver.closed_form import (GRAZE_SPLIT, closed_form_step, count_linear_step, exact_state_at, graze_fraction,
                                         has_modes, linear_phase, record_exact_peaks, run_closed_form, start_phase,
                                         wants_exact)
from pounding.solver.contact_events import (EVENT_NONE, EVENTS_PER_WINDOW_BASE, EVENTS_PER_WINDOW_PER_CONTACT,
                                            apply_contact_events, locate_contact_events, locate_releases)
from pounding.solver.dense import interpolate
from pounding.solver.friction_events import apply_friction_events, locate_friction_events, record_friction
from pounding.solver.dormand_prince import (MAX_FACTOR, MIN_FACTOR, SAFETY, error_norm, fill_tolerances, normed_states,
                                            stages, step_factor)
from pounding.solver.kinematics import (NARROW_TERMS, SIDE_TERMS, fill_grounds, ground_at, ground_kinematics,
                                        ground_state_at, kernel_terms)
from pounding.solver.layout import (ContactState, RigidWork, Contacts, Events, Forcing, Friction, Grounds, Layout, Settings, Storeys,
                                    StoreyTerms, Structure, Work, state_layout)
from pounding.solver.recorder import (IMP_CONSTANT, IMP_CONTACT, IMP_END, IMP_IMPULSE, IMP_PEAK_FORCE,
                                      IMP_SEPARATION, IMP_TIME, IMP_VELOCITY, IMP_WORK, IMPACT_COLUMNS,
                                      IMPACT_ROW_LIMIT, Outputs, Peaks, close_open_impacts, grown, new_outputs,
                                      new_peaks, record_contacts, record_floor_peaks, record_plane_peaks,
                                      record_sample, trace_rows,
                                      trimmed_outputs, TRACE_ROW_LIMIT)
from pounding.solver.pending import add_pending, drop_later, mark_pending
from pounding.solver.rhs import rhs
from pounding.solver.status import (STATUS_COLLAPSED, STATUS_EVENT_LIMIT, STATUS_MESSAGES, STATUS_OK,
                                    STATUS_STEP_TOO_SMALL, STATUS_TABLE_LIMIT, STATUS_UNSTABLE)
from pounding.solver.storey_events import (apply_storey_events, collapse_crossing, failed_storey,
                                           instability_crossing, locate_storey_events)
from pounding.solver.tolerances import floor_tolerance_factors

#: Storey models whose hysteretic state is their shear (pounding.solver.imk).
IMK_MODELS = (hysteresis.MODEL_IMK_BILINEAR, hysteresis.MODEL_IMK_PEAK, hysteresis.MODEL_IMK_PINCHING)

__all__ = ["System", "RawSolution", "integrate", "ground_kinematics", "ground_state_at", "STATUS_OK",
           "STATUS_STEP_TOO_SMALL", "STATUS_EVENT_LIMIT", "STATUS_TABLE_LIMIT", "STATUS_COLLAPSED", "STATUS_UNSTABLE",
           "STATUS_MESSAGES",
           "SAFETY", "MIN_FACTOR", "MAX_FACTOR", "SIDE_TERMS", "IMPACT_ROW_LIMIT"]

jit.load_registries_without_scipy()

#: A located event within this fraction of a step from its end is applied at the end.
EVENT_END_TOLERANCE = 1e-9
#: Retakes of one step to bring a located event to its end before it is accepted as is.
MAX_RETAKES = 8
#: Halvings of an exact step whose interpolant might miss a grazing closure (each divides the cubic's
#: error bound by 16; pounding.solver.closed_form.graze_fraction), on top of the retakes.
MAX_GRAZE_SPLITS = 12


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
    dense_band : (B,) int, optional
        Half-bandwidth of each block: its entries farther than this from the diagonal are zero and
        skipped; default ``dense_size − 1`` (full).
    dense_stiffness : flat float array, optional
        Dense stiffness blocks laid out as *dense_values*, N/m (a plan model's planes and P-Delta
        terms, K = Σ k a aᵀ); default empty: none.
    plane_floors, plane_weights : (R, 2·t) int and float, optional
        A plan model's plane drifts ``Σ_k w_k·u[floor_k]`` (floor −1: none; two sides of t ≤ TERMS_PER_SIDE
        terms, the floor above and the floor below, like a contact's), whose full-resolution
        peaks the run records (``RawSolution.peak_plane_drift``); default none.
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
    storey_stop_ratio : (N,) float, end the run when the storey's |drift ratio| exceeds it (its building's
        collapse drift ratio; 0: never)
    storey_imk : (nh, imk.N_STATE) float, optional
        Initial discrete state of each IMK storey (row of its hysteretic state; other rows unused)
    contact_floors : (nc, 2·t) int, optional
        Floor terms of each contact, its left side's t terms then its right side's, t ≤ TERMS_PER_SIDE
        (``[left, left, right, right]`` for t = 2; −1: none, the ground or a wall); the solver lays each
        array out at the narrowest width its rows fit, two or four terms per side
        (:func:`pounding.solver.kinematics.kernel_terms`); default from ``contact_left`` /
        ``contact_right``: ``[left, −1, right, −1]``.
    contact_weights : (nc, 2·t) float, optional
        Their weights: δ = Σ_k w_k·u[floor_k] − gap, the force enters floor_k as w_k·F (left
        weights ≥ 0, right ≤ 0); default ``[1, 0, −1, 0]`` (−1 sides get weight 0).
    floor_ground : (N,) int, row of the ground-acceleration array that moves each floor's building
        (all 0 with one common ground motion)
    contact_ground_left, contact_ground_right : (nc,) int, ground row under the left and the right
        side of each gap element: their differential displacement enters the penetration
        (``pounding.solver.assembly.assemble``; a wall takes the row of the building it faces)
    storey_floors, storey_weights : (R, 2·t) int and float, optional
        A plan model's storey rows, its planes (``pounding.solver.plan_assembly``): row p's drift is
        ``Σ_k w_k·u[floor_k]`` (floor −1: none).  Then the storey fields above are per plane (R), not per
        floor, and ``storey_row_stiffness`` (R,) N/m holds each plane's elastic stiffness.  None: the
        storey under floor j, drift ``u[j] − u[below[j]]``.
    friction_floors, friction_weights : (nf, 2·t) int and float, optional
        A plan model's Coulomb friction faces: face f's slip rate is ``Σ_k w_k·v[floor_k]``
        (:class:`pounding.solver.layout.Friction`); None: no friction (the solver's friction code is pruned).
    friction_coefficient : (nf,) μ of each face
    friction_first_point, friction_point_count : (nf,) int, the face's contact points (consecutive contacts)
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
    storey_stop_ratio: np.ndarray | None = None
    storey_imk: np.ndarray | None = None
    contact_floors: np.ndarray | None = None
    contact_weights: np.ndarray | None = None
    floor_ground: np.ndarray | None = None
    contact_ground_left: np.ndarray | None = None
    contact_ground_right: np.ndarray | None = None
    storey_floors: np.ndarray | None = None
    storey_weights: np.ndarray | None = None
    storey_row_stiffness: np.ndarray | None = None
    friction_floors: np.ndarray | None = None
    friction_weights: np.ndarray | None = None
    friction_coefficient: np.ndarray | None = None
    friction_first_point: np.ndarray | None = None
    friction_point_count: np.ndarray | None = None
    dense_band: np.ndarray | None = None
    dense_stiffness: np.ndarray | None = None
    plane_floors: np.ndarray | None = None
    plane_weights: np.ndarray | None = None

    def __post_init__(self) -> None:
        nc = int(self.contact_gap.size)
        if self.contact_floors is None:
            left = np.asarray(self.contact_left, dtype=np.int64).reshape(nc)
            right = np.asarray(self.contact_right, dtype=np.int64).reshape(nc)
            none = np.full(nc, -1, dtype=np.int64)
            object.__setattr__(self, "contact_floors", np.ascontiguousarray(np.stack([left, none, right, none], 1)))
            weights = np.stack([(left >= 0) * 1.0, np.zeros(nc), (right >= 0) * -1.0, np.zeros(nc)], 1)
            object.__setattr__(self, "contact_weights", np.ascontiguousarray(weights.reshape(nc, 4)))

        # Storey fields left out: linear elastic storeys of unit height, no P-Delta, no collapse check.
        n = int(self.mass.size)
        defaults = {"storey_model": np.zeros(n, dtype=np.int64),
                    "storey_parameters": np.zeros((n, hysteresis.N_HYSTERESIS_PARAMETERS)),
                    "storey_state": np.full(n, -1, dtype=np.int64),
                    "p_delta_stiffness": np.zeros(n), "storey_height": np.ones(n), "storey_stop_ratio": np.zeros(n),
                    "floor_ground": np.zeros(n, dtype=np.int64),
                    "contact_ground_left": np.zeros(self.contact_gap.size, dtype=np.int64),
                    "contact_ground_right": np.zeros(self.contact_gap.size, dtype=np.int64),
                    "dense_band": np.asarray(self.dense_size, dtype=np.int64) - 1, "dense_stiffness": np.zeros(0),
                    "plane_floors": np.zeros((0, NARROW_TERMS), dtype=np.int64),
                    "plane_weights": np.zeros((0, NARROW_TERMS))}
        for key, value in defaults.items():
            if getattr(self, key) is None:
                object.__setattr__(self, key, value)
        if self.storey_imk is None:
            object.__setattr__(self, "storey_imk", np.zeros((self.n_hysteretic, imk.N_STATE)))

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
    def n_faces(self) -> int:
        """Number of friction faces (0 without friction)."""
        return 0 if self.friction_coefficient is None else int(self.friction_coefficient.size)

    @property
    def elastic_storeys(self) -> bool:
        """Every storey linear elastic, without P-Delta or collapse limit (no storey state, no storey event)."""
        return (self.n_hysteretic == 0 and not np.any(self.p_delta_stiffness)
                and not np.any(self.storey_stop_ratio > 0.0))

    @property
    def responds_linearly(self) -> bool:
        """The equations of motion are linear with constant coefficients for the whole run: no gap, wall or
        link element, no friction face, every storey linear elastic without P-Delta or collapse limit.
        From rest, the response to a ground motion scaled by λ is then λ times the response to the motion
        itself (superposition), and no run ends early."""
        return self.n_contacts == 0 and self.n_faces == 0 and self.elastic_storeys

    @property
    def layout(self) -> Layout:
        """Offsets of the state vector (:func:`pounding.solver.layout.state_layout`)."""
        return state_layout(self.n_floors, self.n_contacts, self.n_hysteretic, self.n_faces)

    @property
    def n_states(self) -> int:
        """Length of the state vector (the last state: work of the differential ground motion on the contacts)."""
        return self.layout.size


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
    collapse_storey: int             # floor index of the storey that collapsed or lost stability, −1 if none
    n_steps: int
    n_rejected: int
    status: int
    final_time: float
    support_acceleration: np.ndarray | None = None  # (nt, G) m/s², every ground row (None: one ground)
    collapse_cause: str = ""         # status.COLLAPSE_CAUSES: why collapse_storey collapsed ("" if none)
    friction_history: np.ndarray | None = None  # (nt, 3·nf): each face's N (N), λ (N), mode code (None: no friction)
    peak_plane_drift: np.ndarray | None = None  # (R,) m, |drift| of a plan model's planes (System.plane_floors)
    exact_steps: int = 0             # steps of linear phases taken in closed form (of n_steps)
    trial_steps: int = 0             # every trial step: accepted, rejected, retaken to end at an event, halved
    contact_steps: int = 0           # accepted steps with an impact under way (of n_steps)



# --------------------------------------------------------------------------- #
# The driver
# --------------------------------------------------------------------------- #


class ImpactTable(NamedTuple):
    """The impact table (columns ``recorder.IMP_*``, grown as needed) and its rows in use."""

    rows: np.ndarray
    count: int


class Integration(NamedTuple):
    """What the compiled integrator returns."""

    outputs: Outputs       #: the sampled histories
    peaks: Peaks           #: full-resolution peaks
    impacts: np.ndarray    #: (ni, IMPACT_COLUMNS) the impact table
    trace: np.ndarray      #: (nr, 4) time, contact, penetration, force of closed contacts
    final_state: np.ndarray
    collapse_floor: int    #: floor of the storey that exceeded the drift limit or lost stability, −1 if none
    n_steps: int
    n_rejected: int
    status: int
    final_time: float
    n_trials: int          #: every trial step: accepted, rejected by the error control, retaken to end at an
                           #: event or redone after events at its start, halved by the graze guard
    n_contact: int         #: accepted steps with an impact under way (a contact closed, neither a link nor stuck)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _rates_at(t, seg, y, rates, forcing, structure, contacts, cstate, work, storey, ground, friction) -> float:
    """The state's rates *rates* at time *t* (record step *seg*), with the ground states ``ground.now``;
    returns the ground acceleration of row 0 there (m/s²).  Contact forces go to ``work.forces``."""
    ag_t = ground_at(forcing.acceleration, forcing.record_step, seg, t)
    if ground is not None:
        fill_grounds(ground, forcing.record_step, seg, t, ground.now)
    rhs(y, ag_t, work.layout, structure, contacts, cstate, rates, work.fbuf, work.forces, storey, ground, friction)
    return ag_t


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _rates_after(t, seg, y, rates, forcing, structure, contacts, cstate, work, storey, ground, friction) -> float:
    """:func:`_rates_at`, called rather than inlined: for the driver's sites outside its step loop's
    every step (after events, the first and the last samples), where one more copy of the right-hand
    side would only cost compile time."""
    return _rates_at(t, seg, y, rates, forcing, structure, contacts, cstate, work, storey, ground, friction)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def _with_room(impacts, n_imp, nc):
    """The impact table *impacts* (its first *n_imp* rows used) with room for *nc* more rows (up to its cap)."""
    if n_imp + nc <= impacts.shape[0] or impacts.shape[0] >= IMPACT_ROW_LIMIT:
        return impacts
    return grown(impacts, n_imp, min(n_imp + nc, n_imp - n_imp + IMPACT_ROW_LIMIT), n_imp - n_imp + IMPACT_ROW_LIMIT)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _apply_events(t, seg, forcing, structure, contacts, cstate, work, events, table, storey, ground, friction):
    """Apply the storey events ``events.storey_kind``, the contact events ``events.kind`` and then the
    friction faces' (which follow their points' closures and separations) at *t*, in place:
    ``(n_imp, n_applied, first_step_cap, status)`` (:func:`contact_events.apply_contact_events`;
    *table* with room for a row per contact, :func:`_with_room`)."""
    lay = work.layout
    zero = lay.n_floors - lay.n_floors
    n_applied = zero
    if storey is not None:
        n_applied = apply_storey_events(events.storey_kind, work.y, lay, structure.below, storey)
    n_imp, cap, status = table.count, np.inf, zero
    for c in range(lay.n_contacts):
        if events.kind[c] != EVENT_NONE:  # the contact events' applier is called only when there is one
            if ground is not None:
                fill_grounds(ground, forcing.record_step, seg, t, ground.now)
            n_imp, n_contact, cap, status = apply_contact_events(
                events, t, ground_at(forcing.acceleration, forcing.record_step, seg, t), lay, structure,
                contacts, cstate, work, table, storey, ground, friction)
            n_applied += n_contact
            break
    if friction is not None and status == 0:
        if ground is not None:
            fill_grounds(ground, forcing.record_step, seg, t, ground.now)
        n_applied += apply_friction_events(t, ground_at(forcing.acceleration, forcing.record_step, seg, t), lay,
                                           structure, contacts, cstate, work, storey, ground, friction)
    return n_imp, n_applied, cap, status


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _set_pending(events, s_first, friction) -> None:
    """Mark the events at or before fraction *s_first* as those the retaken step ends at (all others
    cleared; *s_first* < 0 clears every one); the friction faces' too."""
    mark_pending(events.kind, events.s, events.pending, s_first)
    mark_pending(events.storey_kind, events.storey_s, events.storey_pending, s_first)
    if friction is not None:
        mark_pending(friction.event_kind, friction.event_s, friction.pending, s_first)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _keep_events_within(events, h, tiny, friction) -> None:
    """Drop the located events later than *tiny* seconds into a step of *h* s (those at its start stay)."""
    drop_later(events.kind, events.s, h, tiny)
    drop_later(events.storey_kind, events.storey_s, h, tiny)
    if friction is not None:
        drop_later(friction.event_kind, friction.event_s, h, tiny)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _with_pending(events, friction) -> bool:
    """Add the pending events (those the retaken step was shortened to) to the located ones; any left?"""
    found = add_pending(events.kind, events.pending)
    found = add_pending(events.storey_kind, events.storey_pending) or found
    if friction is not None:
        found = add_pending(friction.event_kind, friction.pending) or found
    return found


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _count_events(t, n_applied, start, count, record_step, cap, status):
    """Events applied in the current window of one record step: ``(its start, s; events in it; status)``
    after *n_applied* more at *t* (a window that began more than *record_step* s before *t* is a new one);
    the status becomes STATUS_EVENT_LIMIT when the window holds more than *cap* events, else stays *status*."""
    if t - start > record_step:
        start = t
        count = n_applied - n_applied
    count += n_applied
    return start, count, STATUS_EVENT_LIMIT if count > cap else status


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _locate_storeys(work, h, lay, structure, storey, events, s_first, collapse_floor, stop_status):
    """The yielding storeys' first events in a trial step of *h* s, and the first stop of the run in it
    (the collapse limit's crossing, STATUS_COLLAPSED, or a loss of stability, STATUS_UNSTABLE):
    ``(first event fraction, *s_first* if earlier; stop fraction, −1 if none; its floor and status, else
    *collapse_floor* and *stop_status*)``.  An IMK storey at zero strength (failed at the event that starts
    the step) is a collapse at the step's start.  A kernel of its own, so the driver's loop has no branch of
    its own for the storeys (its branches cost reference counts of the tables it grows, at every step)."""
    below = structure.below
    s_first = min(s_first, locate_storey_events(work, h, lay, below, storey, events.storey_s, events.storey_kind))
    collapse_s = -1.0
    failed = failed_storey(storey)
    if failed >= 0:  # an IMK storey lost its strength at the last event: its building collapses there
        return 0.0, 0.0, failed, STATUS_COLLAPSED
    collapse_s, collapse_at = collapse_crossing(work, lay.n_floors, below, storey.height, storey.stop_ratio,
                                                storey.terms, h)
    if collapse_s >= 0.0:
        collapse_floor = collapse_at
        stop_status = STATUS_COLLAPSED
    unstable_s, unstable_at = instability_crossing(work, lay, below, storey, structure.storey_stiffness, h)
    if unstable_s >= 0.0 and (collapse_s < 0.0 or unstable_s < collapse_s):
        collapse_s = unstable_s
        collapse_floor = unstable_at
        stop_status = STATUS_UNSTABLE
    if collapse_s >= 0.0:
        s_first = min(s_first, collapse_s)
    return s_first, collapse_s, collapse_floor, stop_status


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _exact_start(cf, t, seg, forcing, ground, work) -> bool:
    """The step from *t* of a linear phase in an exact window runs in closed form
    (:mod:`pounding.solver.closed_form`): the phase's modal state is started from ``work.y`` and its rate
    ``work.K[0]`` when it is new.  Returns True."""
    if cf.valid[0] == 0:
        start_phase(cf, work.y, work.K[0], t, seg, forcing, ground)
    return True


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _phase_after_events(cf, t, seg, forcing, cstate, structure, storey, ground, friction, work):
    """After events at *t*: ``(linear, exact)`` of the step from there (the events may end the linear phase or
    change its constant load: a new modal state)."""
    cf.valid[0] = 0
    linear, _, exact = _phase_now(cf, False, False, t, seg, forcing, cstate, structure, storey, ground, friction, work)
    return linear, exact


# The closed form's calls in the driver's loop are inlined: a run that takes no exact step (most runs at
# default tolerances; every run of :func:`.closed_form.no_closed_form`) pays a few tests a step for them,
# not a call that passes the whole ClosedForm record.
@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _phase_now(cf, linear, linear_known, t, seg, forcing, cstate, structure, storey, ground, friction, work):
    """``(linear, linear_known, exact)`` of the step from *t*: whether the phase is linear is decided again
    only after events (*linear_known* False), and a linear phase's step is exact in an exact window."""
    if not linear_known:
        linear = has_modes(cf) and linear_phase(cstate, structure, storey, friction)
        linear_known = True
    if not linear or not wants_exact(cf):  # (a probing window's steps: _exact_accepted ends the modal state)
        return linear, linear_known, False
    return linear, linear_known, _exact_start(cf, t, seg, forcing, ground, work)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _phase_ended(cf) -> bool:
    """Events were applied: the linear phase (if any) must be decided again; returns False (not known)."""
    cf.valid[0] = 0
    return False


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _exact_accepted(cf, exact, linear, at_sample) -> None:
    """After an accepted step: an exact step's end becomes the modal state (a Runge–Kutta step ends the
    phase's modal state), and a linear phase's step is counted (:func:`.closed_form.count_linear_step`)."""
    if not linear:
        return
    if exact:
        z, z_end = cf.z, cf.z_end
        for i in range(z.size):
            z[i] = z_end[i]
    else:
        cf.valid[0] = 0
    count_linear_step(cf.policy, cf.threshold, exact, at_sample)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _exact_step(cf, exact, work, h, t, seg, forcing, structure, contacts, cstate, storey, ground) -> bool:
    """Take the trial step in closed form if it is an exact one (:func:`.closed_form.closed_form_step`)."""
    if not exact:
        return False
    closed_form_step(cf, work, h, t, seg, forcing, structure, contacts, cstate, storey, ground)
    return True


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _grazes(cf, exact, s_first, n_graze, work, h, lay, contacts, cstate, ground) -> bool:
    """An exact trial step to halve: no event before GRAZE_SPLIT, halvings left, and an open contact's exact
    δ might touch 0 unseen by the cubic (:func:`.closed_form.graze_fraction`)."""
    if not exact or s_first <= GRAZE_SPLIT or n_graze >= MAX_GRAZE_SPLITS:
        return False
    return graze_fraction(cf, work, h, lay, contacts, cstate, ground) < 1.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _record_peaks(cf, exact, work, h, n, structure, peaks) -> None:
    """The peaks over an accepted step: on the cubic of a Runge–Kutta step, on the exact solution of an
    exact one (:func:`.closed_form.record_exact_peaks`)."""
    if exact:
        record_exact_peaks(cf, work, h, n, structure, peaks)
        return
    record_floor_peaks(work, h, n, structure.below, peaks)
    record_plane_peaks(work, h, n, structure.plane_floors, structure.plane_weights, structure.plane_width, peaks)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _exact_output(cf, exact, work, h, s, t, seg, forcing, structure, storey, ground, out) -> None:
    """An output sample inside an exact step: the exact state (:func:`.closed_form.exact_state_at`)."""
    if exact and s < 1.0:
        exact_state_at(cf, work, h, s, t, seg, forcing, structure, storey, ground, out)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _exact_end_events(exact, events, friction) -> None:
    """At an exact step's end only the events found there are applied (the pending ones are dropped): one
    the long step's cubic placed a little early is found at the start of the next step."""
    if exact:
        _set_pending(events, -1.0, friction)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _accept(work) -> None:
    """Accept the trial step: its end state and rate become the next step's start (first same as last)."""
    y, ynew, k1, k7 = work.y, work.ynew, work.K[0], work.K[6]
    for i in range(y.size):
        y[i] = ynew[i]
        k1[i] = k7[i]


#: A stuck rigid contact released at rest re-closes only past this fraction of its displacement tolerance.
RIGID_BAND_FRACTION = 1e-3


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def _new_contact_state(contacts):
    """Every contact open (a link: closed, engaged from the start and never open), none at rest, no impact row."""
    nc = contacts.gap.size
    cstate = ContactState(np.zeros(nc, dtype=np.bool_), np.zeros(nc), np.zeros(nc, dtype=np.int64),
                          np.empty(nc, dtype=np.int64), np.zeros(nc))
    for c in range(nc):
        cstate.open_row[c] = -1
        cstate.closed[c] = kernels.is_permanent(contacts.law[c])
    return cstate


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED)
def _new_events(contacts, nh, tol):
    """No event located, none pending, for the contacts and *nh* yielding storeys; the rigid-impact
    scratch sized for the contacts of instantaneous laws.

    A contact's rest band is the displacement tolerance of its floors (*tol*: the error norm's per-state
    tolerances; the smallest over the contact's floor terms): parting by less than the solver resolves
    is not a separation (docs/numerics.md, "Contacts at rest"); a rigid contact's, 1e-3 of that."""
    nc = contacts.gap.size
    ni = nc - nc
    band = np.zeros(nc)
    for c in range(nc):
        if kernels.is_instantaneous(contacts.law[c]):
            ni += 1
        smallest = np.inf
        terms = len(contacts.width)
        for k in range(terms * c, terms * c + terms):
            if contacts.weights[k] != 0.0:
                smallest = min(smallest, tol[contacts.floors[k]])
        if smallest < np.inf:
            # a rigid contact's band only needs to clear the interpolant's round-off: 1e-3 of it (≪ 1e-9 m)
            band[c] = smallest * RIGID_BAND_FRACTION if kernels.is_instantaneous(contacts.law[c]) else smallest
    rigid = RigidWork(np.zeros(ni, dtype=np.int64), np.zeros(ni), np.zeros(ni), np.zeros(ni), np.zeros(ni),
                      np.zeros(ni), np.zeros(ni, dtype=np.int64), np.zeros((ni, ni)), np.zeros((ni, ni + 1)))
    return Events(np.empty(nc), np.zeros(nc, dtype=np.int64), np.zeros(nc, dtype=np.int64), np.empty(nh),
                  np.zeros(nh, dtype=np.int64), np.zeros(nh, dtype=np.int64), band, rigid)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _fill_tail(i_out, t, seg, forcing, structure, contacts, cstate, work, storey, ground, friction, out):
    """Output samples *i_out*… of *out* at the run's end *t* (reached within round-off before the last one's
    time): the end state ``work.y`` with its rate ``work.K[0]``; returns the number of samples (all)."""
    y, k1, k2, lay = work.y, work.K[0], work.K[1], work.layout
    n_out = out.time.size
    for i in range(i_out, n_out):
        ag_t = _rates_after(t, seg, y, k2, forcing, structure, contacts, cstate, work, storey, ground, friction)
        record_sample(i, t, y, k1, ag_t, lay, structure, contacts, work.forces, storey, ground, out)
        record_friction(i, friction)
    return n_out


# In the loop below: events at the step's start are applied at t and the step redone (they may end the linear
# phase or change its constant load); a step is retaken to end at its first event; events at the step's end are
# those the retaken step was shortened to and any other found there; after them the next step is the size
# accepted before the event cut it short (a newly closed contact: its cap).  The contacts' event location and
# the recording of closed contacts are written in the loop, not in functions of their own: inlined from them,
# the driver ran pair.yaml's Runge-Kutta steps ~10 % slower (docs/performance.md).
@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED)
def _integrate(lay, structure, contacts, storey, ground, friction, forcing, settings, y_initial, cf):
    """The run (module docstring; *storey*, *ground*, *friction* None: pruned; *cf*: :mod:`.closed_form`)."""
    n, nc, nh, S = lay.n_floors, lay.n_contacts, lay.n_hysteretic, lay.size
    dt_rec, t_end, output_dt = forcing.record_step, settings.end_time, settings.output_step
    n_out = int(math.floor(t_end / output_dt + 1e-9)) + 1
    zero = nc - nc  # sizes and counters non-literal: a literal reaching np.empty or a callee compiles a throw-away one
    work = Work(np.zeros(S), np.zeros(S), np.zeros(S), np.zeros((zero + 7, S)), np.zeros(n), np.zeros(nc), np.zeros(nc),
                lay)
    y, ystage, k1, k2 = work.y, work.ystage, work.K[0], work.K[1]
    forces, rtol = work.forces, settings.rtol  # taken out once: each ``record.member`` in the loop counts a reference
    y[:2 * n] = y_initial[:2 * n]
    tol = np.empty(S)  # each state's absolute tolerance in the error norm
    fill_tolerances(tol, lay, contacts, settings.atol, settings.atol_velocity, settings.floor_factor, storey)
    cstate, events = _new_contact_state(contacts), _new_events(contacts, nh, tol)
    normed = normed_states(tol)
    out = new_outputs(n_out, lay, ground)
    peaks = new_peaks(lay, structure.plane_weights.size // len(structure.plane_width))
    impacts, n_imp = grown(np.empty((zero, zero + IMPACT_COLUMNS)), zero, zero + 64, zero + IMPACT_ROW_LIMIT), zero
    trace, n_trace = np.empty((zero + 1024, zero + 4)), zero  # full-resolution samples of closed contacts
    t, seg = 0.0, zero
    ag_t = _rates_after(t, seg, y, k1, forcing, structure, contacts, cstate, work, storey, ground, friction)
    record_sample(zero, t, y, k1, ag_t, lay, structure, contacts, work.forces_end, storey, ground, out)  # no force yet
    record_friction(zero, friction)
    h, n_steps, n_rej, status, collapse_floor, i_out = settings.first_step, zero, zero, zero, zero - 1, zero + 1
    tiny, event_cap = 1e-12 * max(dt_rec, 1.0), EVENTS_PER_WINDOW_BASE + EVENTS_PER_WINDOW_PER_CONTACT * nc
    window_start, window_events, err, collapse_s, n_applied, cap = 0.0, zero, 0.0, -1.0, zero, np.inf
    stop_status = zero + STATUS_COLLAPSED  # which stop collapse_s / collapse_pending is: collapsed or unstable
    exact, linear, linear_known, n_trials, n_contact = False, False, False, zero, zero  # linear: decided after events
    while t < t_end - tiny and i_out <= n_out:
        while (seg + 1) * dt_rec <= t + 1e-9 * dt_rec:
            seg += 1
        seg_end = min((seg + 1) * dt_rec, t_end)
        room = seg_end - t
        linear, linear_known, exact = _phase_now(cf, linear, linear_known, t, seg, forcing, cstate, structure, storey,
                                                 ground, friction, work)
        h_try = room if exact or h >= room or t + 1.01 * h >= seg_end else h
        h_before_events = h_try  # the error-controlled size a located event shortens
        rejected, n_retake, collapse_pending, n_graze = False, zero, False, zero
        _set_pending(events, -1.0, friction)
        while True:  # attempt -> locate -> retake, or apply events at the step's start and attempt again
            if h_try < 1e-14 * max(1.0, t):
                status = STATUS_STEP_TOO_SMALL
                break
            n_trials += 1
            if _exact_step(cf, exact, work, h_try, t, seg, forcing, structure, contacts, cstate, storey, ground):
                err, finite = 0.0, True
            else:
                stages(work, h_try, t, seg, forcing, lay, structure, contacts, cstate, storey, ground, friction)
                err, finite = error_norm(work, h_try, tol, normed, rtol)
            if not finite or err > 1.0:
                n_rej, rejected = n_rej + 1, True
                h_try *= step_factor(err, finite, False)
                h_before_events, n_retake, collapse_pending = h_try, zero, False
                _set_pending(events, -1.0, friction)
                continue
            s_first, n_release = locate_contact_events(work, h_try, t, seg, forcing, lay, contacts, cstate, events, ground)
            if friction is not None:  # before locate_releases: friction.force still holds the step's end
                s_first = min(s_first, locate_friction_events(work, h_try, t, seg, forcing, lay, structure, contacts,
                                                              cstate, storey, ground, friction))
            if n_release > 0:
                s_first = min(s_first, locate_releases(work, h_try, t, seg, forcing, structure, contacts, cstate,
                                                       events, storey, ground, friction))
            collapse_s = -1.0
            if storey is not None:
                s_first, collapse_s, collapse_floor, stop_status = _locate_storeys(
                    work, h_try, lay, structure, storey, events, s_first, collapse_floor, stop_status)
            if _grazes(cf, exact, s_first, n_graze, work, h_try, lay, contacts, cstate, ground):
                n_graze, h_try, h_before_events = n_graze + 1, h_try * GRAZE_SPLIT, h_try * GRAZE_SPLIT  # halve
                _set_pending(events, -1.0, friction)
                continue
            if s_first <= 1.0 and s_first * h_try <= tiny:
                _keep_events_within(events, h_try, tiny, friction)
                if collapse_s >= 0.0 and collapse_s * h_try <= tiny:
                    status = stop_status
                    break
                impacts = _with_room(impacts, n_imp, nc)
                n_imp, n_applied, cap, status = _apply_events(t, seg, forcing, structure, contacts, cstate, work, events,
                                                              ImpactTable(impacts, n_imp), storey, ground, friction)
                window_start, window_events, status = _count_events(t, n_applied, window_start, window_events, dt_rec,
                                                                    event_cap, status)
                if status != 0:
                    break
                _rates_after(t, seg, y, k1, forcing, structure, contacts, cstate, work, storey, ground, friction)
                linear, exact = _phase_after_events(cf, t, seg, forcing, cstate, structure, storey, ground, friction,
                                                    work)
                if cap < h_try:
                    h_try, h_before_events = cap, cap
                n_retake, collapse_pending = zero, False
                _set_pending(events, -1.0, friction)
                continue
            if s_first < 1.0 - EVENT_END_TOLERANCE and n_retake < MAX_RETAKES:
                _set_pending(events, s_first, friction)
                collapse_pending = collapse_s >= 0.0 and collapse_s <= s_first
                h_try = s_first * h_try
                n_retake += 1
                continue
            break
        if status != 0:
            break
        h_used = h_try
        t_new = t + h_used if h_used != room else seg_end
        _record_peaks(cf, exact, work, h_used, n, structure, peaks)
        added = trace_rows(contacts, cstate)
        rows = min(n_trace + added, zero + TRACE_ROW_LIMIT)
        if rows > trace.shape[0]:
            trace = grown(trace, n_trace, rows, zero + TRACE_ROW_LIMIT)
        n_trace, status = record_contacts(work, h_used, t, lay, contacts, cstate, ground, peaks, impacts, trace, n_trace)
        n_contact += 1 if added > 0 else 0   # an impact under way
        if status != 0:
            break
        while i_out < n_out and i_out * output_dt <= t_new + 1e-9 * output_dt:  # output samples in (t, t_new]
            t_o = min(i_out * output_dt, t_new)
            s = (t_o - t) / h_used
            interpolate(work, h_used, s, ystage)
            _exact_output(cf, exact, work, h_used, s, t, seg, forcing, structure, storey, ground, ystage)
            ag_o = _rates_at(t_o, seg, ystage, k2, forcing, structure, contacts, cstate, work, storey, ground, friction)
            record_sample(i_out, t_o, ystage, k2, ag_o, lay, structure, contacts, forces, storey, ground, out)
            record_friction(i_out, friction)
            i_out += 1
        t = t_new  # accept
        _accept(work)
        _exact_accepted(cf, exact, linear, t_new == seg_end)
        n_steps += 1
        _exact_end_events(exact, events, friction)
        any_events = _with_pending(events, friction)
        if storey is not None:  # located: this step ends where the drift limit is first exceeded (or stability lost)
            status = stop_status if collapse_s >= 0.0 or collapse_pending else status
        if status != 0:
            break
        if any_events:
            impacts = _with_room(impacts, n_imp, nc)
            n_imp, n_applied, cap, status = _apply_events(t, seg, forcing, structure, contacts, cstate, work, events,
                                                          ImpactTable(impacts, n_imp), storey, ground, friction)
        if any_events and n_applied > 0:
            linear_known = _phase_ended(cf)
            window_start, window_events, status = _count_events(t, n_applied, window_start, window_events, dt_rec,
                                                                event_cap, status)
            _rates_after(t, seg, y, k1, forcing, structure, contacts, cstate, work, storey, ground, friction)
            h = min(h_before_events, cap)
            if status != 0:
                break
        else:
            h = h_used * step_factor(err, True, rejected)
    close_open_impacts(y, lay, cstate, impacts)
    if status == 0:  # t_end reached within round-off before the last output sample: fill it
        i_out = _fill_tail(i_out, t, seg, forcing, structure, contacts, cstate, work, storey, ground, friction, out)
    collapse_floor = collapse_floor if status == STATUS_COLLAPSED or status == STATUS_UNSTABLE else zero - 1
    return Integration(trimmed_outputs(out, i_out), peaks, impacts[:n_imp], trace[:n_trace], y,
                       collapse_floor, n_steps, n_rej, status, t, n_trials, n_contact)


jit.stamp_solver_kernels(globals())


def _storey_arguments(system: System, atol: float) -> Storeys | None:
    """The compiled integrator's *storey* argument: None for linear elastic storeys without
    P-Delta or collapse limit (the integrator then compiles without any storey code), else
    a :class:`~pounding.solver.layout.Storeys`.

    A state's tolerance is atol for a bilinear storey's plastic drift (m) and atol/u_y for
    Bouc–Wen's dimensionless z; its mode (a fresh array: the integrator changes it) starts elastic.
    """
    if system.elastic_storeys:
        return None
    floors = np.flatnonzero(system.storey_state >= 0)
    state_floor = np.empty(floors.size, dtype=np.int64)
    state_floor[system.storey_state[floors]] = floors
    bilinear = system.storey_model[state_floor] == hysteresis.MODEL_BILINEAR
    tolerance = np.where(bilinear, atol, atol / np.where(bilinear, 1.0, system.storey_parameters[state_floor, 0]))
    # An IMK storey's state is its shear: atol times its stiffness (N).
    shear_state = np.isin(system.storey_model[state_floor], IMK_MODELS)
    stiffness = system.storey_stiffness if system.storey_floors is None else system.storey_row_stiffness
    tolerance = np.where(shear_state, atol * stiffness[state_floor], tolerance)
    terms = None
    if system.storey_floors is not None:
        terms = StoreyTerms(*kernel_terms(system.storey_floors, system.storey_weights),
                            np.ascontiguousarray(system.storey_row_stiffness, dtype=np.float64))
    # Fresh copies: the IMK events rewrite their storeys' kernel rows and states during the run.
    return Storeys(np.ascontiguousarray(system.storey_model, dtype=np.int64),
                   np.array(system.storey_parameters, dtype=np.float64, copy=True, order="C"),
                   np.ascontiguousarray(system.storey_state, dtype=np.int64),
                   np.ascontiguousarray(system.p_delta_stiffness, dtype=np.float64),
                   np.ascontiguousarray(system.storey_height, dtype=np.float64),
                   np.zeros(floors.size, dtype=np.int64), state_floor, np.ascontiguousarray(tolerance, dtype=np.float64),
                   np.ascontiguousarray(system.storey_stop_ratio, dtype=np.float64),
                   np.array(system.storey_imk, dtype=np.float64, copy=True, order="C").reshape(-1, imk.N_STATE),
                   terms)


def integrate(system: System, ground_acceleration: np.ndarray, time_step: float, duration: float,
              *, rtol: float, atol: float, atol_velocity: float, output_dt: float,
              scale_tolerances: bool = True, initial_displacement: np.ndarray | None = None,
              initial_velocity: np.ndarray | None = None,
              floor_factors: np.ndarray | None = None, linear_phases: str = "exact",
              closed_form_threshold: float | None = None) -> RawSolution:
    """Integrate the row of buildings under a piecewise-linear ground motion.

    Parameters
    ----------
    system : System
        Flat arrays from :func:`pounding.solver.assembly.assemble`.
    ground_acceleration : (ns,) ndarray
        Samples of a_g, m/s², uniform step *time_step*; must cover *duration*.
    time_step : float
        Record sampling interval, s.  Steps never straddle a sample.
    duration : float
        End time, s.
    rtol, atol, atol_velocity : float
        Error control: each displacement (velocity) component's local error is
        kept below ``atol (atol_velocity) + rtol·|y|``.
    scale_tolerances : bool
        Tighten atol and atol_velocity per building to its own static drift scale
        (:mod:`pounding.solver.tolerances`; False: the given values for every floor, as before).
    output_dt : float
        Sampling interval of the stored histories, s (peaks and impacts are
        tracked at full solver resolution regardless).
    initial_displacement, initial_velocity : (N,) ndarray, optional
        Initial state relative to the ground (m, m/s); default at rest.  All
        contacts start open.
    floor_factors : (N,) ndarray, optional
        Factors (0, 1] on atol and atol_velocity per floor, given by the caller (a plan model's
        rotations, :mod:`pounding.solver.plan_assembly`); replaces *scale_tolerances*.
    linear_phases : {"exact", "runge-kutta"}
        How the linear phases (every contact open, every storey elastic) are advanced: in closed form
        (:mod:`pounding.solver.closed_form`; a model it refuses takes Runge–Kutta steps) or by the
        Runge–Kutta steps of every other phase.
    closed_form_threshold : float, optional
        Runge–Kutta steps per record sample of a linear phase above which the closed form runs (default:
        :func:`pounding.solver.closed_form.pays_threshold`, where it is cheaper); negative: every linear
        phase in closed form (the tests' and benchmarks' setting).
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
    # Absent terms (the ground, a wall: floor −1) go to the kernels as floor 0 with weight 0, each array at the
    # narrowest width its rows fit (kinematics.kernel_terms; the width's type selects the compiled kernels).
    planes = kernel_terms(system.plane_floors, system.plane_weights)
    structure = Structure(system.mass, system.storey_stiffness, system.below, system.rayleigh_mass,
                          system.rayleigh_stiffness, system.dense_start, system.dense_size, system.dense_offset,
                          system.dense_values, np.asarray(system.dense_band, dtype=np.int64),
                          np.ascontiguousarray(system.dense_stiffness, dtype=np.float64), *planes)
    contacts = Contacts(*kernel_terms(system.contact_floors, system.contact_weights), system.contact_gap,
                        system.contact_law, system.contact_parameters)
    factors = np.ones(system.n_floors)
    if floor_factors is not None:
        factors = np.array(floor_factors, dtype=np.float64, copy=True)
    elif scale_tolerances:
        factors = floor_tolerance_factors(system.mass, system.storey_stiffness, system.below,
                                          float(np.max(np.abs(rows))) if rows.size else 0.0, float(atol))
    settings = Settings(float(time_step), float(duration), float(rtol), float(atol), float(atol_velocity),
                        float(output_dt), float(first_step), factors)
    storey = _storey_arguments(system, float(atol))
    friction = _friction_argument(system, float(duration), float(output_dt))
    cf = run_closed_form(system, float(time_step), rows.shape[0], closed_form_threshold, linear_phases)
    raw = _integrate(system.layout, structure, contacts, storey, ground, friction, Forcing(ag, float(time_step)),
                     settings, y_initial, cf)
    out, impacts, trace = raw.outputs, raw.impacts, raw.trace
    return RawSolution(out.time, out.state, out.acceleration, out.force, out.ground, out.potential,
                       raw.peaks.displacement, raw.peaks.drift, raw.peaks.force,
                       impacts[:, IMP_CONTACT].astype(np.int64), impacts[:, IMP_TIME],
                       impacts[:, IMP_VELOCITY], impacts[:, IMP_CONSTANT], impacts[:, IMP_PEAK_FORCE],
                       impacts[:, IMP_END], impacts[:, IMP_IMPULSE], impacts[:, IMP_SEPARATION],
                       impacts[:, IMP_WORK], trace[:, 0], trace[:, 1].astype(np.int64), trace[:, 2], trace[:, 3],
                       out.shear, out.storey_energy, raw.final_state.copy(), int(raw.collapse_floor),
                       int(raw.n_steps), int(raw.n_rejected), int(raw.status), float(raw.final_time),
                       None if ground is None else out.support,
                       _collapse_cause(storey, int(raw.status), int(raw.collapse_floor)),
                       friction_history=None if friction is None else friction.history[:out.time.size].copy(),
                       peak_plane_drift=raw.peaks.plane, exact_steps=int(cf.policy[3]),
                       trial_steps=int(raw.n_trials), contact_steps=int(raw.n_contact))


def _friction_argument(system: System, duration: float, output_dt: float) -> Friction | None:
    """The compiled integrator's *friction* argument: None without friction faces, else a
    :class:`~pounding.solver.layout.Friction` with every face open and a history of the run's
    output samples (the integrator's count: ``floor(duration/output_dt + 1e-9) + 1``)."""
    nf = system.n_faces
    if nf == 0:
        return None
    n_out = int(math.floor(duration / output_dt + 1e-9)) + 1
    return Friction(*kernel_terms(system.friction_floors, system.friction_weights),
                    np.ascontiguousarray(system.friction_coefficient, dtype=np.float64),
                    np.ascontiguousarray(system.friction_first_point, dtype=np.int64),
                    np.ascontiguousarray(system.friction_point_count, dtype=np.int64),
                    np.zeros(nf, dtype=np.int64), np.ones(nf), np.zeros(nf), np.zeros(nf), np.full(nf, -1.0),
                    np.zeros(nf, dtype=np.int64), np.zeros(nf, dtype=np.int64), np.zeros((n_out, 3 * nf)))


def _collapse_cause(storey: Storeys | None, status: int, floor: int) -> str:
    """Why the storey under *floor* ended the run (:data:`pounding.solver.status.COLLAPSE_CAUSES`; "" if it
    did not): an IMK storey whose discrete state the run left failed reached zero strength, else its
    drift passed its collapse drift ratio; status ``unstable`` is a loss of resistance to P-Delta."""
    if floor < 0 or storey is None:
        return ""
    if status == STATUS_UNSTABLE:
        return "unstable"
    hi = int(storey.state_index[floor])
    failed = hi >= 0 and storey.model[floor] in IMK_MODELS and storey.imk[hi, imk.FAILED] > 0.0
    return "zero_strength" if failed else "drift_ratio"


def _ground_arguments(system: System, rows: np.ndarray, time_step: float) -> Grounds:
    """The solver's *ground* record for several grounds (rows of *rows*, m/s², step *time_step* s)."""
    velocity, displacement = ground_kinematics(rows, time_step)
    n_ground = rows.shape[0]
    return Grounds(rows, displacement, velocity, np.asarray(system.floor_ground, dtype=np.int64),
                   np.asarray(system.contact_ground_left, dtype=np.int64),
                   np.asarray(system.contact_ground_right, dtype=np.int64),
                   np.zeros((3, n_ground)), np.zeros((3, n_ground)), np.zeros((3, n_ground)))
