"""The solver's data layout: the offsets of the state vector and the named records it passes around.

The state vector of a run is, in this order (docs/numerics.md)::

    [u (N), v (N), impulse (nc), work (nc), q (nc), E_input, E_damping, D (nf), r (nh), W (nh), W_g]

``u``, ``v``: floor displacements (m) and velocities (m/s) relative to each
floor's ground; per contact its impulse ∫F dt (N·s), its work ∫F·δ̇ dt (J)
and its law's internal state ``q``; the input and the Rayleigh-damped energy
(J); per friction face the energy its friction dissipated ∫λ·v_t dt (J; none without
friction, nf = 0); per yielding storey its hysteretic state ``r`` and its work ∫F dΔ (J);
the work of the contact forces on the differential ground motion (J).
:func:`state_layout` builds the offsets once (:class:`Layout`); the solver
and :mod:`pounding.results.dataset` both read them from there.

The other records are the compiled solver's arguments, numba named tuples of
arrays (numba passes a named tuple's members as flat arguments, so a record
costs nothing at a call):

* :class:`Structure` — floors, storey springs, damping, a plan model's stiffness blocks and plane drifts;
* :class:`Contacts` — every gap element's floor terms, gap, law and parameters;
* :class:`ContactState` — what changes at contact events (closed, onset constant, mode);
* :class:`Storeys` — yielding storeys, P-Delta and the collapse limit (None when there are none);
* :class:`StoreyTerms` — the drifts of a plan model's planes as weighted sums of floor DOF (``Storeys.terms``;
  None for a row of shear buildings, whose storey drift is ``u[j] − u[below[j]]``);
* :class:`Friction` — Coulomb friction faces of a plan model (None without friction);
* :class:`Grounds` — the support motions with several grounds (None with one common ground);
* :class:`Settings` — record step, duration, tolerances and output step;
* :class:`Forcing` — the ground acceleration of ground row 0 and its sample interval;
* :class:`Events` — the events located in a trial step;
* :class:`Work` — the step's scratch arrays (state, trial state, stage rates, force buffers).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["Layout", "state_layout", "Structure", "Contacts", "ContactState", "RigidWork", "Storeys", "StoreyTerms", "Friction", "Grounds", "Settings",
           "Forcing", "Events", "Work"]


class Layout(NamedTuple):
    """Offsets of the parts of the state vector (indices into it) and its length."""

    n_floors: int        #: N
    n_contacts: int      #: nc, gap elements and links
    n_hysteretic: int    #: nh, yielding storeys
    velocity: int        #: first floor velocity, N
    impulse: int         #: first contact impulse, 2N
    work: int            #: first contact work, 2N + nc
    internal: int        #: first contact internal state, 2N + 2nc
    input_energy: int    #: E_input, 2N + 3nc
    damping_energy: int  #: E_damping, 2N + 3nc + 1
    hysteretic: int      #: first storey hysteretic state, 2N + 3nc + 2 + nf
    storey_work: int     #: first storey work, 2N + 3nc + 2 + nf + nh
    ground_work: int     #: W_g, the last state
    size: int            #: length of the state vector
    n_faces: int = 0     #: nf, friction faces
    friction_work: int = -1  #: first friction face's dissipated energy, 2N + 3nc + 2


def state_layout(n_floors: int, n_contacts: int, n_hysteretic: int, n_faces: int = 0) -> Layout:
    """The :class:`Layout` of *n_floors* floors, *n_contacts* contacts, *n_hysteretic* yielding storeys
    and *n_faces* friction faces (their states sit before the storeys': without friction every offset
    is the one of a run without faces)."""
    n, nc, nh, nf = int(n_floors), int(n_contacts), int(n_hysteretic), int(n_faces)
    friction_work = 2 * n + 3 * nc + 2
    hysteretic = friction_work + nf
    size = hysteretic + 2 * nh + 1
    return Layout(n, nc, nh, n, 2 * n, 2 * n + nc, 2 * n + 2 * nc, 2 * n + 3 * nc, 2 * n + 3 * nc + 1, hysteretic,
                  hysteretic + nh, size - 1, size, nf, friction_work)


class Structure(NamedTuple):
    """Floors of every building, concatenated left to right (N floors; B buildings)."""

    mass: np.ndarray                #: (N,) kg
    storey_stiffness: np.ndarray    #: (N,) N/m, storey under each floor
    below: np.ndarray               #: (N,) int, floor below, −1 for the ground
    rayleigh_mass: np.ndarray       #: (N,) Rayleigh a0 of the floor's building, 1/s
    rayleigh_stiffness: np.ndarray  #: (N,) Rayleigh a1, s
    dense_start: np.ndarray         #: (B,) int, first floor of each modal damping block
    dense_size: np.ndarray          #: (B,) int, its size (0: Rayleigh)
    dense_offset: np.ndarray        #: (B,) int, its first value in *dense_values*
    dense_values: np.ndarray        #: flat dense damping blocks, N·s/m
    dense_band: np.ndarray          #: (B,) int, half-bandwidth of each block (entries beyond: zero; m − 1: full)
    dense_stiffness: np.ndarray     #: flat dense stiffness blocks, N/m, laid out as *dense_values* (empty: none)
    plane_floors: np.ndarray        #: (R·width,) int, a plan model's plane drifts' floor terms (empty: none)
    plane_weights: np.ndarray       #: (R·width,) their weights (drift ``Σ_k w_k·u[f_k]``, its peak recorded)
    plane_width: tuple              #: terms per plane row, as its type (:func:`.kinematics.row_width`)


class Contacts(NamedTuple):
    """Gap elements and links (nc); term k of contact c at ``width·c + k``, the left side's terms in the first
    half of a row, the right side's in the second (:mod:`.kinematics`)."""

    floors: np.ndarray      #: (nc·width,) int, floor of each term (an absent term: floor 0, weight 0)
    weights: np.ndarray     #: (nc·width,) its weight (left ≥ 0, right ≤ 0)
    width: tuple            #: terms per contact, as its type: NARROW_TERMS or SIDE_TERMS (:func:`.kinematics.row_width`)
    gap: np.ndarray         #: (nc,) m
    law: np.ndarray         #: (nc,) int, kernel branch (pounding.contact)
    parameters: np.ndarray  #: (nc, N_PARAMETERS)


class RigidWork(NamedTuple):
    """Scratch of the simultaneous rigid-impact resolution (pounding.solver.simultaneous), sized for the
    ni contacts of instantaneous laws (allocated once: the solver's kernels may not allocate)."""

    active: np.ndarray   #: (ni,) int, contacts resolved together
    rate: np.ndarray     #: (ni,) m/s, their approach rates before the impulses
    dvg: np.ndarray      #: (ni,) m/s, their differential ground velocities
    target: np.ndarray   #: (ni,) m/s, b of the LCP
    impulse: np.ndarray  #: (ni,) N·s, the LCP's solution
    exact: np.ndarray    #: (ni,) N·s, its exact solution on the active set
    index: np.ndarray    #: (ni,) int, the active set
    delassus: np.ndarray  #: (ni, ni) 1/kg
    system: np.ndarray   #: (ni, ni + 1) the active set's augmented matrix


class ContactState(NamedTuple):
    """What the contact events change (nc each)."""

    closed: np.ndarray    #: bool, contact closed (a link: always)
    constant: np.ndarray  #: law constant fixed at onset (ξ of Hertz-damp)
    mode: np.ndarray      #: int, mode of a closed contact (pounding.contact.MODE_*)
    open_row: np.ndarray  #: int, row of the contact's open impact in the impact table, −1 if none
    rest_band: np.ndarray  #: m, 0 unless the contact is at rest; then how far its faces part (or, released
    #: at rest, overlap again) before that is an event (events.band; docs/numerics.md "Contacts at rest")


class StoreyTerms(NamedTuple):
    """A plan model's storey elements, its planes (R rows): row p's drift is ``Σ_k weights[w·p + k]·u[floors[w·p + k]]``
    (w terms per row; the plane's weight vector a: u and θ of the floors above and below, docs/plan-models.md) and its
    shear F enters the floors as ``weights·F`` (virtual work).  Absent terms: floor 0, weight 0."""

    floors: np.ndarray     #: (R·w,) int
    weights: np.ndarray    #: (R·w,) float
    width: tuple           #: w, as its type (:func:`.kinematics.row_width`)
    stiffness: np.ndarray  #: (R,) N/m, the plane's elastic stiffness (the dense stiffness block carries k·Δ)


class Storeys(NamedTuple):
    """Yielding storeys, P-Delta and the collapse limit (the solver's *storey* argument).

    Its rows are the storeys under the N floors of a row of shear buildings (``terms`` None), or the R
    planes of a plan model (``terms`` a :class:`StoreyTerms`: a row's drift is a weighted sum of floor DOF;
    :mod:`pounding.solver.kinematics` ``storey_*``)."""

    model: np.ndarray        #: (R,) int, hysteresis kernel branch of the storey under each floor (0: elastic)
    parameters: np.ndarray   #: (R, N_HYSTERESIS_PARAMETERS) kernel vectors
    state_index: np.ndarray  #: (R,) int, the storey's hysteretic state among the nh, −1 if elastic
    p_delta: np.ndarray      #: (N,) N/m, geometric stiffness −P/h of the storey under each floor (plan: zeros)
    height: np.ndarray       #: (R,) m
    mode: np.ndarray         #: (nh,) int, bilinear mode of each yielding storey (changed by the solver)
    floor: np.ndarray        #: (nh,) int, floor (row) of each hysteretic state
    tolerance: np.ndarray    #: (nh,) absolute tolerance of each hysteretic state
    stop_ratio: np.ndarray   #: (R,) drift ratio of the storey that ends the run, its building's collapse (0: never)
    imk: np.ndarray          #: (nh, imk.N_STATE) discrete state of each IMK storey (other rows unused)
    terms: StoreyTerms | None  #: a plan model's plane drifts; None: storey j's drift is u[j] − u[below[j]]


class Friction(NamedTuple):
    """Coulomb friction faces of a plan model (the solver's *friction* argument; nf faces).

    A face's tangential slip rate is ``v_t = Σ_k weights[w·f + k]·v[floors[w·f + k]]`` (w terms per face; the low side's
    material point on its face minus the high side's, along +tangent); its friction λ (N, positive
    resisting +v_t) enters the floors as ``weights·λ`` (virtual work), like a contact force.  Its normal
    force N is the sum of its points' forces (contacts ``first_point … first_point + point_count − 1``).
    """

    floors: np.ndarray       #: (nf·w,) int, slip terms (an absent term: floor 0, weight 0)
    weights: np.ndarray      #: (nf·w,) float
    width: tuple             #: w, as its type (:func:`.kinematics.row_width`)
    coefficient: np.ndarray  #: (nf,) μ
    first_point: np.ndarray  #: (nf,) int, the face's first contact point
    point_count: np.ndarray  #: (nf,) int, its number of points
    mode: np.ndarray         #: (nf,) int, FRICTION_OFF / SLIP / STICK (changed at events)
    direction: np.ndarray    #: (nf,) ±1.0, the slip direction while slipping
    force: np.ndarray        #: (nf,) N, λ of the last right-hand side (scratch)
    normal: np.ndarray       #: (nf,) N, N of the last right-hand side (scratch)
    event_s: np.ndarray      #: (nf,) fraction of the trial step of each face's next event (−1: none)
    event_kind: np.ndarray   #: (nf,) int, its kind (pounding.solver.friction FRICTION_EVENT_*)
    pending: np.ndarray      #: (nf,) int, events the retaken step was shortened to end at
    history: np.ndarray      #: (n_out, 3·nf) N, λ and the mode code at each output sample


class Grounds(NamedTuple):
    """Several support motions (the solver's *ground* argument; G grounds, ns record samples)."""

    acceleration: np.ndarray  #: (G, ns) m/s²
    displacement: np.ndarray  #: (G, ns) m, at the samples, from rest
    velocity: np.ndarray      #: (G, ns) m/s
    floor_row: np.ndarray     #: (N,) int, ground of each floor's building
    left_row: np.ndarray      #: (nc,) int, ground under each contact's left side
    right_row: np.ndarray     #: (nc,) int, and its right side
    now: np.ndarray           #: (3, G) [acceleration, velocity, displacement] now (scratch)
    start: np.ndarray         #: (3, G) at the start of the step (scratch)
    end: np.ndarray           #: (3, G) at its end (scratch)


class Settings(NamedTuple):
    """Run settings, SI."""

    record_step: float   #: s, ground-motion sample interval (steps never straddle a sample)
    end_time: float      #: s
    rtol: float
    atol: float          #: m, displacements
    atol_velocity: float  #: m/s
    output_step: float   #: s
    first_step: float    #: s
    floor_factor: np.ndarray  #: (N,) factor (0, 1] on atol and atol_velocity per floor (pounding.solver.tolerances)


class Forcing(NamedTuple):
    """The ground acceleration the floors of ground row 0 feel (piecewise linear between samples)."""

    acceleration: np.ndarray  #: (ns,) m/s²
    record_step: float        #: s


class Events(NamedTuple):
    """Events located in a trial step (nc contacts, nh yielding storeys)."""

    s: np.ndarray               #: (nc,) fraction of the step where each contact's next event lies (−1: none)
    kind: np.ndarray            #: (nc,) int, its kind (contact_events.EVENT_*)
    pending: np.ndarray         #: (nc,) int, events the current (retaken) step was shortened to end at
    storey_s: np.ndarray        #: (nh,) likewise for the yielding storeys
    storey_kind: np.ndarray     #: (nh,) int (storey_events.STOREY_*)
    storey_pending: np.ndarray  #: (nh,) int
    band: np.ndarray            #: (nc,) m, each contact's rest band (ContactState.rest_band while at rest)
    rigid: RigidWork            #: scratch of the simultaneous rigid-impact resolution (kept out of the
    #: contact state, which the right-hand side takes six times a step)


class Work(NamedTuple):
    """A step's arrays (S states, N floors, nc contacts)."""

    y: np.ndarray           #: (S,) state at the step's start
    ynew: np.ndarray        #: (S,) 5th-order state at its end
    ystage: np.ndarray      #: (S,) scratch: a stage's state, an interpolated state
    K: np.ndarray           #: (7, S) stage rates k1..k7
    fbuf: np.ndarray        #: (N,) scratch: floor forces
    forces: np.ndarray      #: (nc,) contact forces of the last right-hand side
    forces_end: np.ndarray  #: (nc,) contact forces at the end of the last accepted trial step
    layout: Layout          #: the state vector's layout (the kernels that take no ``lay`` of their own read it here)
