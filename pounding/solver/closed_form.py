"""Linear phases in closed form: the exact state transition of a linear, time-invariant phase.

While every contact is open, no friction face acts and every yielding storey is on
its elastic branch, the equation of motion is linear with constant coefficients,

    ẋ = A x + B g(t) + f,       x = [u, v],

with ``g`` the ground accelerations (piecewise linear between record samples) and
``f`` a constant load: the yielding storeys' departure from ``kΔ`` (a bilinear
storey's ``−(1 − α)·k·Δ_p``, an IMK storey's ``F − kΔ``), fixed while they stay
elastic.  Its solution over a step is exact in the eigenvectors of ``A``
(``A = V Λ V⁻¹``; the complex modes of the first-order system, Foss 1958, which are
the classically damped modes when the damping is classical and still exist when it
is not): each modal coordinate ``z = V⁻¹ x`` is a first-order equation with a force
linear in time,

    z(τ) = e^{λτ} z₀ + τ φ₁(λτ) β₀ + τ² φ₂(λτ) β₁,     φ_k(x) = Σ_j x^j / (j + k)!,

with ``β₀ = V⁻¹(B g(t) + f)`` and ``β₁ = V⁻¹ B ġ``: the recurrence of Nigam & Jennings
(1969) written for complex modes.  The energy audit over the step is exact as well:
the input energy ``−∫ g·Σ m v dt`` by parts (``∫ z dτ = τφ₁ z₀ + τ²φ₂ β₀ + τ³φ₃ β₁``),
the damped energy ``∫ vᵀ C v dt`` by Gauss–Legendre quadrature on the exact solution
(its node count chosen so the rule's error on the fastest mode is below 1e-10), the
yielding storeys' work ∫F dΔ in closed form.

Buildings that nothing couples while contacts are open are separate groups, each with
its own eigenvectors (a row of buildings costs the sum of its buildings' squares, not
the square of their sum).  Everything is built once per model (:func:`closed_form`);
the driver (:mod:`pounding.solver.integrator`) calls :func:`closed_form_step` in place of
the Runge–Kutta stages while :func:`linear_phase` holds, and keeps locating events,
peaks and output samples on the step's cubic Hermite interpolant of exact end states
and rates; :func:`graze_fraction` shortens a step whose interpolant might miss a
grazing closure, :func:`record_exact_peaks` moves each peak found on the interpolant onto the
exact solution, and :func:`exact_state_at` gives the output samples inside a step.
"""

from __future__ import annotations

import cmath
import functools
import hashlib
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from pounding import hysteresis
from pounding.solver import imk, jit, storeys
from pounding.solver.kernels import FIRST_LINK_ID
from pounding.solver.dense import cubic_max, extremum_in_step, rate_root
from pounding.solver.kinematics import (combo, contact_sums, drift, fill_grounds, ground_at, ground_offset,
                                        storey_drift, storey_stiffness)
from pounding.solver.rhs import rhs_called

__all__ = ["ClosedForm", "closed_form", "closed_form_refusal", "linear_phase", "closed_form_step", "start_phase",
           "graze_fraction", "record_exact_peaks", "exact_state_at", "run_closed_form", "no_closed_form", "has_modes",
           "wants_exact",
           "count_linear_step", "pays_threshold", "phis", "GRAZE_SPLIT", "CONDITION_LIMIT",
           "QUADRATURE_ERROR"]

#: Eigenvector matrices worse conditioned than this (a nearly defective system: a critically damped
#: mode) are not used: the model runs on Runge–Kutta steps throughout.
CONDITION_LIMIT = 1e8
#: Target relative error of the Gauss–Legendre rule for the damped energy on the fastest mode.
QUADRATURE_ERROR = 1e-10
#: A step whose interpolant might miss a grazing closure is retaken at this fraction of its length.
GRAZE_SPLIT = 0.5
#: Cost of an exact step in Runge–Kutta steps of a small model, and the rows × modes products that cost
#: one more (:func:`pays_threshold`; measured: an exact step costs 2.5–3 Runge–Kutta steps of models/pair.yaml,
#: and a 2 × 5 pair switched at 2.7 ran 1.18× slower: 3.5 keeps runs where the gain is not sure on Runge–Kutta).
BASE_RATIO = 3.5
WORK_PER_STEP = 150.0
#: Floors above which no closed form is built (the threshold of a single building of 60 floors is already
#: 51 Runge–Kutta steps per sample), and the threshold above which none is (:func:`closed_form`).
MAX_FLOORS = 400
MAX_THRESHOLD = 50.0
#: Linear-phase samples of a probing window (Runge–Kutta steps, counted) and of an exact window.
PROBE_SAMPLES = 32
EXACT_SAMPLES = 512
#: A step this close to the record step (relative) takes its cached factors: a step from one sample
#: to the next is ``(k + 1)·Δt − k·Δt``, the record step to within the round-off of the sample times
#: (≈ 1e-13 of it at 30 s), a difference of the order of the times' own round-off.
SAME_STEP = 1e-12
#: Terms of the φ functions' Taylor series below |x| = 1 (1/20! ≈ 4e-19).
SERIES_TERMS = 20
#: φ₃'s Taylor coefficients 1/(j + 3)!, j = 0 … SERIES_TERMS − 1 (Horner's rule in :func:`phi_values`).
PHI3_SERIES = np.array([1.0 / math.factorial(j + 3) for j in range(SERIES_TERMS)])


class ClosedForm(NamedTuple):
    """The exact transition data of a model's linear phase (m kept modes, G grounds, nc contacts).

    A conjugate pair of modes is kept once with weight 2 (``x = Re Σ w_i V_i z_i``); a real mode
    with weight 1.
    """

    rows: np.ndarray          #: (2N,) int, state indices of the groups' u and v, group by group
    row_start: np.ndarray     #: (G_r + 1,) int, each group's first entry in *rows*
    mode_start: np.ndarray    #: (G_r + 1,) int, each group's first kept mode
    vector_start: np.ndarray  #: (G_r + 1,) int, each group's first entry in *vectors* and *inverse*
    eigenvalue: np.ndarray    #: (m,) complex, 1/s
    weight: np.ndarray        #: (m,) 1 (real mode) or 2 (a conjugate pair)
    vectors: np.ndarray       #: flat complex: group g's (2n_g, m_g) eigenvectors, row-major
    inverse: np.ndarray       #: flat complex: group g's (m_g, 2n_g) rows of V⁻¹ of its kept modes
    ground_load: np.ndarray   #: (m, G) complex, V⁻¹ B: modal load of a unit acceleration of each ground
    mass_load: np.ndarray     #: (m, G) complex, Σ_j m_j V[u_j, i] over the floors on each ground, kg·m
    floor_modes: np.ndarray   #: (N, m) complex, each floor's displacement row of V (0 outside its group)
    drift_modes: np.ndarray   #: (N, m) complex, each storey's drift row (floor − floor below)
    plane_modes: np.ndarray   #: (R, m) complex, each plane's drift row (a plan model's planes)
    contact_modes: np.ndarray  #: (nc, m) complex, each contact's Σ w·u row
    floor_size: np.ndarray    #: (N, m) moduli of *floor_modes* (the error bounds' weights)
    drift_size: np.ndarray    #: (N, m) of *drift_modes*
    plane_size: np.ndarray    #: (R, m) of *plane_modes*
    contact_size: np.ndarray  #: (nc, m) of *contact_modes*
    damping_index: np.ndarray  #: (nd, 2) int, nonzero entries (a ≤ b) of H = RᵀCR over ζ = [Re z, Im z]
    damping_value: np.ndarray  #: (nd,) their values (off-diagonal ones doubled), N·s/m
    nodes: np.ndarray         #: (q,) Gauss–Legendre nodes on [0, 1]
    node_weight: np.ndarray   #: (q,) their weights (sum 1)
    step: np.ndarray          #: (1,) s, the record step whose factors are cached
    factors: np.ndarray       #: (4, m) complex: e^{λh}, hφ₁, h²φ₂, h³φ₃ at the record step
    node_factors: np.ndarray  #: (3, q, m) complex: e^{λτ}, τφ₁, τ²φ₂ at the nodes of a record step
    z: np.ndarray             #: (m,) complex, the modal state at the step's start
    z_end: np.ndarray         #: (m,) complex, at the trial step's end
    load: np.ndarray          #: (3, m) complex: constant load f, β₀, β₁ of the trial step
    scratch: np.ndarray       #: (4, m) complex: step factors of a step other than the record step
    valid: np.ndarray         #: (1,) int, 1 while *z* and the constant load hold the current state
    z_at: np.ndarray          #: (m,) complex scratch: the modal state at an output sample inside a step
    node_state: np.ndarray    #: (m,) complex scratch: the modal state at a quadrature node
    bound: np.ndarray         #: (m,) scratch: each mode's bound on |d⁴(w z)/dτ⁴| over the trial step
    policy: np.ndarray        #: (4,) int: window kind (0 probing, 1 exact), its linear samples, its Runge–Kutta
                              #: steps, and the run's exact steps (:func:`count_linear_step`)
    threshold: np.ndarray     #: (1,) Runge–Kutta steps per linear sample above which the closed form pays


# --------------------------------------------------------------------------- #
# Built once per model (NumPy)
# --------------------------------------------------------------------------- #


def linear_matrices(system) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(M, C, K)`` of the model's linear phase (every storey elastic, contacts open), N, N·s/m, N/m.

    The same terms as :func:`pounding.solver.rhs.rhs`: storey springs with P-Delta, Rayleigh damping
    on the floor masses and storey springs, and each building's dense damping (and a plan model's
    dense stiffness) block read within its band.
    """
    n = system.n_floors
    mass = np.asarray(system.mass, dtype=float)
    stiffness = np.zeros((n, n))
    damping = np.diag(np.asarray(system.rayleigh_mass) * mass)
    floors = np.arange(n)
    below = np.asarray(system.below, dtype=np.int64)
    spring = np.asarray(system.storey_stiffness, dtype=float)
    for matrix, value in ((stiffness, spring + np.asarray(system.p_delta_stiffness, dtype=float)),
                          (damping, spring * np.asarray(system.rayleigh_stiffness, dtype=float))):
        np.add.at(matrix, (floors, floors), value)  # k·a aᵀ with a = e_j − e_below
        up = below >= 0
        np.add.at(matrix, (below[up], below[up]), value[up])
        np.add.at(matrix, (floors[up], below[up]), -value[up])
        np.add.at(matrix, (below[up], floors[up]), -value[up])
    banded = np.asarray(system.dense_stiffness).size > 0
    for start, size, offset, band in zip(system.dense_start, system.dense_size, system.dense_offset,
                                         system.dense_band):
        if size == 0:
            continue
        s0, m, off = int(start), int(size), int(offset)
        block = np.asarray(system.dense_values[off: off + m * m], dtype=float).reshape(m, m)
        if banded:
            rows, cols = np.indices((m, m))
            inside = np.abs(rows - cols) <= int(band)
            damping[s0:s0 + m, s0:s0 + m] += np.where(inside, block, 0.0)
            spring = np.asarray(system.dense_stiffness[off: off + m * m], dtype=float).reshape(m, m)
            stiffness[s0:s0 + m, s0:s0 + m] += np.where(inside, spring, 0.0)
        else:
            damping[s0:s0 + m, s0:s0 + m] += block
    return np.diag(mass), damping, stiffness


def coupled_groups(stiffness: np.ndarray, damping: np.ndarray) -> list[np.ndarray]:
    """Floors that stiffness or damping couple, as groups of floor indices (each a building, or
    several joined by their storeys' matrices); ascending, each group ascending."""
    n = stiffness.shape[0]
    parent = np.arange(n)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    rows, cols = np.nonzero((stiffness != 0.0) | (damping != 0.0))
    for i, j in zip(rows, cols):
        a, b = root(int(i)), int(root(int(j)))
        if a != b:
            parent[max(a, b)] = min(a, b)
    labels = np.array([root(i) for i in range(n)])
    return [np.flatnonzero(labels == label) for label in np.unique(labels)]


def closed_form_refusal(system) -> str | None:
    """Why *system* has no linear phase to run in closed form (None if it has): a storey that is never
    linear (Bouc–Wen), a link (always engaged: the buildings are never free), friction faces, a linear
    phase that grows (a building unstable under its P-Delta alone) or a nearly defective one."""
    if np.any(system.storey_model == hysteresis.MODEL_BOUC_WEN):
        return "a Bouc-Wen storey is never linear"
    if np.any(np.asarray(system.contact_law) >= FIRST_LINK_ID):
        return "a link keeps the buildings coupled through its own law"
    if system.n_faces > 0:
        return "friction faces"
    if system.n_floors > MAX_FLOORS:
        return f"more than {MAX_FLOORS} floors: the closed form would cost more than Runge-Kutta steps"
    return None


def _mode_refusal(values: np.ndarray, vectors: np.ndarray) -> str | None:
    """Why a group's modes cannot serve (None if they can): a growing mode or nearly defective modes."""
    if np.max(values.real) > 0.0:
        return "a building's linear phase grows (unstable under P-Delta)"
    if np.linalg.cond(vectors) > CONDITION_LIMIT:
        return "a building's modes are nearly defective (a critically damped mode)"
    return None


def _group_modes(mass, damping, stiffness, floors):
    """Eigenvalues and eigenvectors of the first-order matrix of the floors *floors*."""
    n = floors.size
    index = np.ix_(floors, floors)
    inverse_mass = 1.0 / np.diag(mass)[floors]
    first_order = np.zeros((2 * n, 2 * n))
    first_order[:n, n:] = np.eye(n)
    first_order[n:, :n] = -inverse_mass[:, None] * stiffness[index]
    first_order[n:, n:] = -inverse_mass[:, None] * damping[index]
    return np.linalg.eig(first_order)


def _kept(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the modes kept (real ones, and the member of each conjugate pair with Im λ > 0)
    and their weights."""
    keep = np.flatnonzero(values.imag >= 0.0)
    weight = np.where(values[keep].imag > 0.0, 2.0, 1.0)
    return keep, weight


def phis(x: np.ndarray) -> np.ndarray:
    """``φ₀(x) … φ₃(x)`` elementwise, ``φ_k(x) = Σ_j x^j/(j + k)!`` (φ₀ = eˣ, φ₁ = (eˣ − 1)/x, …), shape
    ``(4,) + x.shape``: the compiled :func:`phi_values` the steps use."""
    x = np.asarray(x, dtype=complex)
    flat = np.ascontiguousarray(x.ravel())
    out = np.empty((4, flat.size), dtype=complex)
    _phi_table(flat, out)
    return out.reshape((4,) + x.shape)


def gauss_nodes(fastest: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on [0, 1] whose rule integrates the damped power of the
    fastest mode (|λ| *fastest* 1/s, frequency 2|λ| in vᵀCv) over *step* s to QUADRATURE_ERROR:
    the rule's error factor ``x^{2q} (q!)^4 / ((2q + 1) ((2q)!)^3)`` with ``x = 2|λ|h``."""
    x = 2.0 * fastest * step
    q = 2
    while q < 24:
        error = x ** (2 * q) * math.factorial(q) ** 4 / ((2 * q + 1) * math.factorial(2 * q) ** 3)
        if error < QUADRATURE_ERROR:
            break
        q += 1
    return _legendre(q)


@functools.lru_cache(maxsize=None)
def _legendre(q: int) -> tuple[np.ndarray, np.ndarray]:
    """The q-point Gauss–Legendre nodes and weights on [0, 1]."""
    nodes, weights = np.polynomial.legendre.leggauss(q)
    return 0.5 * (nodes + 1.0), 0.5 * weights


def pays_threshold(row_start, mode_start) -> float:
    """Runge–Kutta steps per record sample of a linear phase above which its closed form is cheaper.

    An exact step costs about BASE_RATIO Runge–Kutta steps of a small model plus the products
    ``Σ_g 2n_g·m_g`` of its groups' rows and kept modes (the motion rebuilt from the modes) at
    WORK_PER_STEP of them per Runge–Kutta step; measured on the shipped models (docs/performance.md).
    """
    rows = np.diff(np.asarray(row_start))
    modes = np.diff(np.asarray(mode_start))
    return BASE_RATIO + float(np.sum(rows * modes)) / WORK_PER_STEP


def closed_form(system, record_step: float, n_grounds: int) -> ClosedForm | None:
    """The :class:`ClosedForm` of *system* for records sampled at *record_step* s on *n_grounds*
    grounds; None when :func:`closed_form_refusal` refuses (the run then takes Runge–Kutta steps)."""
    if closed_form_refusal(system) is not None:
        return None
    mass, damping, stiffness = linear_matrices(system)
    key = _content_key(system, mass, damping, stiffness, float(record_step), int(n_grounds))
    if key not in _BY_CONTENT:
        if len(_BY_CONTENT) >= CONTENT_CACHE_SIZE:
            _BY_CONTENT.pop(next(iter(_BY_CONTENT)))
        _BY_CONTENT[key] = _built(mass, damping, stiffness, system, float(record_step), int(n_grounds))
    return _BY_CONTENT[key]


#: Closed forms by the content they are built from (a study's runs of one structure share one).
_BY_CONTENT: dict[bytes, ClosedForm | None] = {}
#: Structures whose closed forms are kept (oldest dropped first).
CONTENT_CACHE_SIZE = 16


def _content_key(system, mass, damping, stiffness, record_step: float, n_grounds: int) -> bytes:
    """A digest of everything :func:`_built` reads."""
    digest = hashlib.blake2b(digest_size=20)
    for array in (mass, damping, stiffness, system.below, system.floor_ground, system.plane_floors,
                  system.plane_weights, system.contact_floors, system.contact_weights,
                  np.array([record_step, n_grounds], dtype=float)):
        item = np.ascontiguousarray(array)
        digest.update(repr(item.shape).encode() + item.dtype.str.encode())
        digest.update(item.data)
    return digest.digest()


def _built(mass, damping, stiffness, system, record_step: float, n_grounds: int) -> ClosedForm | None:
    """:func:`closed_form` from the linear phase's matrices."""
    groups = coupled_groups(stiffness, damping)
    sizes = np.array([g.size for g in groups], dtype=np.int64)
    if pays_threshold(np.cumsum(np.r_[0, 2 * sizes]), np.cumsum(np.r_[0, sizes])) > MAX_THRESHOLD:
        return None  # no run takes that many Runge-Kutta steps per sample: the modes are not worth computing
    n = system.n_floors
    masses = np.diag(mass)
    ground_of = np.asarray(system.floor_ground, dtype=np.int64)
    rows, row_start, mode_start, vector_start = [], [0], [0], [0]
    values_all, weights_all, vectors_flat, inverse_flat = [], [], [], []
    full_vectors = []  # (2N, m_g) columns of each group in the whole state's rows
    for floors in groups:
        values, vectors = _group_modes(mass, damping, stiffness, floors)
        if _mode_refusal(values, vectors) is not None:
            return None
        inverse = np.linalg.inv(vectors)
        keep, weight = _kept(values)
        group_rows = np.concatenate([floors, n + floors])
        rows.append(group_rows)
        row_start.append(row_start[-1] + group_rows.size)
        mode_start.append(mode_start[-1] + keep.size)
        values_all.append(values[keep])
        weights_all.append(weight)
        vectors_flat.append(vectors[:, keep].ravel())
        inverse_flat.append(inverse[keep, :].ravel())
        vector_start.append(vector_start[-1] + keep.size * group_rows.size)
        whole = np.zeros((2 * n, keep.size), dtype=complex)
        whole[group_rows, :] = vectors[:, keep]
        full_vectors.append((whole, inverse[keep, :], group_rows))
    eigenvalue = np.concatenate(values_all)
    weight = np.concatenate(weights_all)
    columns = np.concatenate([w for w, _, _ in full_vectors], axis=1)  # (2N, m)
    ground_load = np.zeros((eigenvalue.size, n_grounds), dtype=complex)
    start = 0
    for whole, inverse, group_rows in full_vectors:
        for g in range(n_grounds):
            load = np.zeros(group_rows.size)
            half = group_rows.size // 2
            load[half:] = -(ground_of[group_rows[:half]] == g).astype(float)
            ground_load[start:start + inverse.shape[0], g] = inverse @ load
        start += inverse.shape[0]
    floor_modes = columns[:n, :]
    mass_load = np.stack([(masses * (ground_of == g)) @ floor_modes for g in range(n_grounds)], axis=1)
    below = np.asarray(system.below, dtype=np.int64)
    drift_modes = floor_modes - np.where(below[:, None] >= 0, floor_modes[np.maximum(below, 0), :], 0.0)
    plane_modes = _weighted_rows(system.plane_floors, system.plane_weights, floor_modes)
    contact_modes = _weighted_rows(system.contact_floors, system.contact_weights, floor_modes)
    damping_index, damping_value = _damping_form(columns[n:, :], weight, damping)
    fastest = float(np.max(np.abs(eigenvalue)))
    nodes, node_weight = gauss_nodes(fastest, record_step)
    m = eigenvalue.size
    cf = ClosedForm(np.concatenate(rows).astype(np.int64), np.array(row_start, dtype=np.int64),
                    np.array(mode_start, dtype=np.int64), np.array(vector_start, dtype=np.int64),
                    eigenvalue.astype(np.complex128), weight.astype(np.float64),
                    np.concatenate(vectors_flat).astype(np.complex128),
                    np.concatenate(inverse_flat).astype(np.complex128),
                    np.ascontiguousarray(ground_load), np.ascontiguousarray(mass_load, dtype=np.complex128),
                    np.ascontiguousarray(floor_modes), np.ascontiguousarray(drift_modes),
                    np.ascontiguousarray(plane_modes), np.ascontiguousarray(contact_modes),
                    np.abs(floor_modes), np.abs(drift_modes), np.abs(plane_modes), np.abs(contact_modes),
                    damping_index, damping_value, np.ascontiguousarray(nodes), np.ascontiguousarray(node_weight),
                    np.array([float(record_step)]), np.zeros((4, m), dtype=np.complex128),
                    np.zeros((3, nodes.size, m), dtype=np.complex128), np.zeros(m, dtype=np.complex128),
                    np.zeros(m, dtype=np.complex128), np.zeros((3, m), dtype=np.complex128),
                    np.zeros((4, m), dtype=np.complex128), np.zeros(1, dtype=np.int64),
                    np.zeros(m, dtype=np.complex128), np.zeros(m, dtype=np.complex128), np.zeros(m),
                    np.zeros(4, dtype=np.int64),
                    np.array([pays_threshold(row_start, mode_start)]))
    _fill_factors(cf, float(record_step))
    return cf


def _weighted_rows(floors: np.ndarray, weights: np.ndarray, floor_modes: np.ndarray) -> np.ndarray:
    """Rows ``Σ_k w_k·V[u_{f_k}]`` of weighted floor sums (floor −1: none), (R, m) complex."""
    floors = np.asarray(floors, dtype=np.int64).reshape(len(floors), -1) if len(floors) else \
        np.zeros((0, 1), dtype=np.int64)
    weights = np.asarray(weights, dtype=float).reshape(floors.shape)
    out = np.zeros((floors.shape[0], floor_modes.shape[1]), dtype=complex)
    for r in range(floors.shape[0]):
        for f, w in zip(floors[r], weights[r]):
            if f >= 0 and w != 0.0:
                out[r] += w * floor_modes[f]
    return out


def _damping_form(velocity_modes: np.ndarray, weight: np.ndarray, damping: np.ndarray):
    """The damped power ``vᵀCv`` as a quadratic form in ζ = [Re z, Im z]: its nonzero entries
    (upper triangle, off-diagonal doubled).  Classical damping gives 2×2 blocks, one per mode."""
    real = np.concatenate([velocity_modes.real * weight, -velocity_modes.imag * weight], axis=1)
    form = real.T @ damping @ real
    form = 0.5 * (form + form.T)
    scale = np.max(np.abs(form)) if form.size else 0.0
    a, b = np.nonzero(np.triu(np.abs(form) > 1e-14 * scale))
    values = np.where(a == b, form[a, b], 2.0 * form[a, b])
    return np.ascontiguousarray(np.stack([a, b], axis=1).astype(np.int64)), np.ascontiguousarray(values)


def _fill_factors(cf: ClosedForm, step: float) -> None:
    """The record step's factors and node factors into *cf* (built once per model and record step)."""
    values = phis(cf.eigenvalue * step)
    for k in range(4):
        cf.factors[k] = step ** k * values[k]
    tau = (cf.nodes * step)[:, None]
    values = phis(cf.eigenvalue[None, :] * tau)
    for k in range(3):
        cf.node_factors[k] = tau ** k * values[k]


# --------------------------------------------------------------------------- #
# The compiled kernels
# --------------------------------------------------------------------------- #


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def phi_values(x):
    """``(e^x, φ₁(x), φ₂(x), φ₃(x))``: below |x| = 1 φ₃ by Horner's rule on its Taylor series (SERIES_TERMS
    terms, :data:`PHI3_SERIES`) and ``φ_k = 1/k! + x·φ_{k+1}`` down to φ₁; above, the recurrence
    ``φ_k = (φ_{k−1} − 1/(k − 1)!)/x`` up from eˣ (its cancellation is below a few ulps there)."""
    e = cmath.exp(x)
    if abs(x) >= 1.0:
        p1 = (e - 1.0) / x
        p2 = (p1 - 1.0) / x
        return e, p1, p2, (p2 - 0.5) / x
    p3 = PHI3_SERIES[SERIES_TERMS - 1] + 0j
    for j in range(SERIES_TERMS - 2, -1, -1):
        p3 = p3 * x + PHI3_SERIES[j]
    p2 = 0.5 + x * p3
    return e, 1.0 + x * p2, p2, p3


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)  # with a Python wrapper: :func:`phis`
def _phi_table(x, out) -> None:
    """:func:`phi_values` of each entry of *x* into ``out[0..3, i]``."""
    for i in range(x.size):
        e, p1, p2, p3 = phi_values(x[i])
        out[0, i] = e
        out[1, i] = p1
        out[2, i] = p2
        out[3, i] = p3


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _modal_at(cf, i, tau):
    """Mode *i*'s state ``z(τ) = e^{λτ}z₀ + τφ₁β₀ + τ²φ₂β₁`` at *tau* s into the trial step."""
    e, p1, p2, _ = phi_values(cf.eigenvalue[i] * tau)
    return e * cf.z[i] + tau * p1 * cf.load[1, i] + tau * tau * p2 * cf.load[2, i]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _step_factors(cf, h) -> bool:
    """The factors ``e^{λh}, hφ₁, h²φ₂, h³φ₃`` of a step of *h* s: True if they are the cached ones of
    the record step (``cf.factors``; a step to the next sample is the record step to the round-off
    of the sample times, :data:`SAME_STEP`), else False, computed into ``cf.scratch``."""
    if abs(h - cf.step[0]) <= SAME_STEP * cf.step[0]:
        return True
    out = cf.scratch
    for i in range(cf.eigenvalue.size):
        e, p1, p2, p3 = phi_values(cf.eigenvalue[i] * h)
        out[0, i] = e
        out[1, i] = p1 * h
        out[2, i] = p2 * (h * h)
        out[3, i] = p3 * (h * h * h)
    return False


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _ground_values(forcing, ground, seg, t, g):
    """Acceleration of ground row *g* at *t* in record step *seg*, m/s² (row 0: ``forcing``)."""
    if ground is None:
        return ground_at(forcing.acceleration, forcing.record_step, seg, t)
    acc = ground.acceleration
    ns = acc.shape[1]
    if seg + 1 >= ns:
        return acc[g, ns - 1]
    return acc[g, seg] + (acc[g, seg + 1] - acc[g, seg]) * ((t - seg * forcing.record_step) / forcing.record_step)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def linear_phase(cstate, structure, storey, friction) -> bool:
    """True while the model is linear: every contact open, no friction face, and every yielding storey
    on its elastic branch (a bilinear storey in its elastic mode, an IMK storey on a branch of its
    elastic stiffness that has not failed; Bouc–Wen never)."""
    if friction is not None:
        return False
    closed = cstate.closed
    for c in range(closed.size):
        if closed[c]:
            return False
    if storey is not None:
        model, sfloor = storey.model, storey.floor
        for hi in range(sfloor.size):
            j = sfloor[hi]
            if model[j] == hysteresis.MODEL_BILINEAR:
                if storey.mode[hi] != storeys.ELASTIC:
                    return False
            elif storeys.is_imk(model[j]):
                if storey.imk[hi, imk.FAILED] > 0.0 or storey.parameters[j, imk.P_SLOPE] != storey_stiffness(
                        structure.storey_stiffness, storey.terms, j):
                    return False
            else:
                return False
    return True


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def start_phase(cf, y, rate, t, seg, forcing, ground) -> None:
    """Start a linear phase at *t* from state *y* with rate *rate*: the modal state ``z = V⁻¹x`` and the
    constant load ``f = V⁻¹ẋ − Λz − V⁻¹B g(t)`` (the yielding storeys' fixed departure from kΔ)."""
    rows, rstart, mstart, vstart, inverse = cf.rows, cf.row_start, cf.mode_start, cf.vector_start, cf.inverse
    lam, gl, z, load = cf.eigenvalue, cf.ground_load, cf.z, cf.load
    for grp in range(rstart.size - 1):
        r0, r1, m0 = rstart[grp], rstart[grp + 1], mstart[grp]
        width = r1 - r0
        for i in range(m0, mstart[grp + 1]):
            base = vstart[grp] + (i - m0) * width
            zi = 0j
            fi = 0j
            for r in range(width):
                w = inverse[base + r]
                zi += w * y[rows[r0 + r]]
                fi += w * rate[rows[r0 + r]]
            z[i] = zi
            fi -= lam[i] * zi
            for g in range(gl.shape[1]):
                fi -= gl[i, g] * _ground_values(forcing, ground, seg, t, g)
            load[0, i] = fi
    cf.valid[0] = 1


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _modal_end(cf, h, t, seg, forcing, ground, z_end):
    """The trial step's loads ``β₀, β₁`` (into ``cf.load[1:]``; the same for any *h* inside the record step)
    and ``z(h)`` into *z_end*; returns whether its factors are the cached ones (:func:`_step_factors`)."""
    cached = _step_factors(cf, h)
    fac = cf.factors if cached else cf.scratch
    lam, gl, z, load = cf.eigenvalue, cf.ground_load, cf.z, cf.load
    for i in range(lam.size):
        b0 = load[0, i]
        b1 = 0j
        for g in range(gl.shape[1]):
            a0 = _ground_values(forcing, ground, seg, t, g)
            a1 = _ground_values(forcing, ground, seg, t + h, g)
            b0 += gl[i, g] * a0
            b1 += gl[i, g] * ((a1 - a0) / h)
        load[1, i] = b0
        load[2, i] = b1
        z_end[i] = fac[0, i] * z[i] + fac[1, i] * b0 + fac[2, i] * b1
    return cached


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _motion(cf, zv, out) -> None:
    """Floor displacements and velocities ``x = Re Σ w V z`` of the modal state *zv* into *out*."""
    rows, rstart, mstart, vstart, vectors, weight = (cf.rows, cf.row_start, cf.mode_start, cf.vector_start,
                                                     cf.vectors, cf.weight)
    for grp in range(rstart.size - 1):
        r0, m0, m1 = rstart[grp], mstart[grp], mstart[grp + 1]
        width = m1 - m0
        for r in range(rstart[grp + 1] - r0):
            base = vstart[grp] + r * width
            acc = 0.0
            for i in range(width):
                acc += weight[m0 + i] * (vectors[base + i] * zv[m0 + i]).real
            out[rows[r0 + r]] = acc


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _input_energy(cf, y, ynew, h, t, seg, forcing, ground, cached, mass) -> float:
    """Input energy over the step, J: ``−∫ Σ_j a_g,j m_j v_j dt = −[a_g U]₀ʰ + ȧ_g ∫U dt`` per ground,
    ``U = Σ m_j u_j``, with ``∫U`` from the exact ``∫z``."""
    lam, ml, z, load, weight = cf.eigenvalue, cf.mass_load, cf.z, cf.load, cf.weight
    fac = cf.factors if cached else cf.scratch
    # Floor by floor and mode by mode, each term with its own ground's values: the same sums, in the same
    # order, whether the floors stand on one ground or on several identical ones.
    total = 0.0
    for j in range(mass.size):
        g = 0 if ground is None else ground.floor_row[j]
        a0 = _ground_values(forcing, ground, seg, t, g)
        a1 = _ground_values(forcing, ground, seg, t + h, g)
        total -= mass[j] * (a1 * ynew[j] - a0 * y[j])
    for i in range(lam.size):
        zint = fac[1, i] * z[i] + fac[2, i] * load[1, i] + fac[3, i] * load[2, i]
        for g in range(ml.shape[1]):
            if ml[i, g] != 0j:
                slope = (_ground_values(forcing, ground, seg, t + h, g) - _ground_values(forcing, ground, seg, t, g)) / h
                total += slope * (weight[i] * (ml[i, g] * zint).real)
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _damped_energy(cf, h) -> float:
    """Damped energy ∫vᵀCv dt over the step, J: Gauss–Legendre on the exact modal state."""
    lam, z, load, index, value = cf.eigenvalue, cf.z, cf.load, cf.damping_index, cf.damping_value
    m = lam.size
    nodes, wq = cf.nodes, cf.node_weight
    cached = abs(h - cf.step[0]) <= SAME_STEP * cf.step[0]
    nf = cf.node_factors
    total = 0.0
    zq = cf.node_state
    for q in range(nodes.size):
        tau = nodes[q] * h
        for i in range(m):
            if cached:
                zq[i] = nf[0, q, i] * z[i] + nf[1, q, i] * load[1, i] + nf[2, q, i] * load[2, i]
            else:
                zq[i] = _modal_at(cf, i, tau)
        power = 0.0
        for k in range(value.size):
            a, b = index[k, 0], index[k, 1]
            za = zq[a].real if a < m else zq[a - m].imag
            zb = zq[b].real if b < m else zq[b - m].imag
            power += value[k] * za * zb
        total += wq[q] * power
    return total * h


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _storey_work(y, ynew, lay, structure, storey) -> None:
    """The yielding storeys' states and work ∫F dΔ at the step's end (elastic branches: exact)."""
    ih, iw, n = lay.hysteretic, lay.storey_work, lay.n_floors
    below, kst, terms, table = structure.below, structure.storey_stiffness, storey.terms, storey.parameters
    for hi in range(storey.floor.size):
        j = storey.floor[hi]
        d0 = storey_drift(y, 0, terms, below, j)
        d1 = storey_drift(ynew, 0, terms, below, j)
        k = storey_stiffness(kst, terms, j)
        r = y[ih + hi]
        if storeys.is_imk(storey.model[j]):
            r1 = r + table[j, imk.P_SLOPE] * (d1 - d0)
            ynew[ih + hi] = r1
            ynew[iw + hi] = y[iw + hi] + 0.5 * (r + r1) * (d1 - d0)
        else:  # bilinear, elastic mode: Δ_p fixed
            alpha = table[j, 1]
            ynew[iw + hi] = y[iw + hi] + 0.5 * alpha * k * (d1 * d1 - d0 * d0) + 0.5 * (1.0 - alpha) * k * (
                (d1 - r) * (d1 - r) - (d0 - r) * (d0 - r))
    _ = n


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _exact_state(cf, y, h, t, seg, forcing, structure, storey, ground, lay, out, z_out) -> None:
    """The exact state *h* s after *t* (from *y* at *t*) into *out*, its modal state into *z_out*: the motion,
    the energy audit and the yielding storeys' states; the contacts' states (all open) unchanged."""
    n = lay.n_floors
    cached = _modal_end(cf, h, t, seg, forcing, ground, z_out)
    for i in range(2 * n, y.size):
        out[i] = y[i]
    _motion(cf, z_out, out)
    out[lay.input_energy] = y[lay.input_energy] + _input_energy(cf, y, out, h, t, seg, forcing, ground, cached,
                                                                structure.mass)
    out[lay.damping_energy] = y[lay.damping_energy] + _damped_energy(cf, h)
    if storey is not None:
        _storey_work(y, out, lay, structure, storey)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def exact_state_at(cf, work, h, s, t, seg, forcing, structure, storey, ground, out) -> None:
    """The exact state at fraction *s* of the accepted step of *h* s from *t* into *out* (an output sample
    inside an exact step: its motion and its energy audit, not the cubic's)."""
    _exact_state(cf, work.y, s * h, t, seg, forcing, structure, storey, ground, work.layout, out, cf.z_at)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def closed_form_step(cf, work, h, t, seg, forcing, structure, contacts, cstate, storey, ground) -> None:
    """The exact trial step of *h* s from *t* (in record step *seg*) of a linear phase: its end state into
    ``work.ynew`` and its rate into ``work.K[6]`` (the interpolant's data, as a Runge–Kutta step's)."""
    ynew, lay = work.ynew, work.layout
    _exact_state(cf, work.y, h, t, seg, forcing, structure, storey, ground, lay, ynew, cf.z_end)
    t_end = t + h
    if ground is not None:
        fill_grounds(ground, forcing.record_step, seg, t_end, ground.now)
    rhs_called(ynew, ground_at(forcing.acceleration, forcing.record_step, seg, t_end), lay, structure, contacts,
               cstate, work.K[6], work.fbuf, work.forces, storey, ground, None)  # a linear phase has no friction


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _mode_bounds(cf, h) -> None:
    """Each kept mode's bound on ``|w d⁴z/dτ⁴|`` over the trial step into ``cf.bound``.

    With ``ż = λz + β₀ + β₁τ``: ``z̈ = λż + β₁``, so ``ż(τ) = e^{λτ}ż₀ + τφ₁(λτ)β₁`` and
    ``z⁗ = λ³ż + λ²β₁``; for Re λ ≤ 0 (every kept mode: :func:`closed_form_refusal`)
    ``|ż(τ)| ≤ |ż₀| + h|β₁|`` on the step."""
    lam, z, load, weight, bound = cf.eigenvalue, cf.z, cf.load, cf.weight, cf.bound
    for i in range(lam.size):
        a = abs(lam[i])
        b1 = abs(load[2, i])
        rate = abs(lam[i] * z[i] + load[1, i]) + h * b1
        bound[i] = weight[i] * (a * a * a * rate + a * a * b1)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _row_bound(cf, size, r, h) -> float:
    """Bound on |exact − Hermite cubic| over the step of a combination whose modal row has the moduli
    ``size[r]``: the cubic Hermite remainder ``h⁴/384 · max|f⁗|`` (Hairer, Nørsett & Wanner 1993, §II.6)."""
    total = 0.0
    bound = cf.bound
    for i in range(bound.size):
        total += size[r, i] * bound[i]
    return h * h * h * h / 384.0 * total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def graze_fraction(cf, work, h, lay, contacts, cstate, ground) -> float:
    """Fraction of the trial step to retake it at (GRAZE_SPLIT), or 2.0: an open contact's δ stays
    below 0 on the step's Hermite cubic but the cubic's error bound (:func:`_row_bound`) reaches 0, so
    the exact δ might touch 0 unseen (a closure and reopening inside one step).  Halving the step
    divides the bound by 16: after a few halvings either the cubic crosses (the event is located as
    any other) or the bound clears.  Called after ``locate_contact_events`` (``ground.start`` and
    ``ground.end`` filled)."""
    _mode_bounds(cf, h)
    y, ynew = work.y, work.ynew
    n = lay.n_floors
    for c in range(lay.n_contacts):
        d0, r0 = contact_sums(y, n, contacts.floors, contacts.weights, contacts.width, c)
        d1, r1 = contact_sums(ynew, n, contacts.floors, contacts.weights, contacts.width, c)
        if ground is not None:
            d0 += ground_offset(ground, ground.start, c, 2)
            r0 += ground_offset(ground, ground.start, c, 1)
            d1 += ground_offset(ground, ground.end, c, 2)
            r1 += ground_offset(ground, ground.end, c, 1)
        d0 -= contacts.gap[c]
        d1 -= contacts.gap[c]
        # the cubic rises at most (4/27)·h·(|r0| + |r1|) above its ends: a cheap first filter
        reach = max(d0, d1) + 0.15 * h * (abs(r0) + abs(r1))
        bound = _row_bound(cf, cf.contact_size, c, h)
        if reach + bound < 0.0:
            continue
        top = cubic_max(d0, r0, d1, r1, h)
        if top < 0.0 and top + bound >= 0.0:
            return GRAZE_SPLIT
    return 2.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _exact_at(cf, modes, r, tau):
    """``(value, rate, rate of rate)`` of the combination ``modes[r]`` at *tau* s into the trial step."""
    lam, load, weight = cf.eigenvalue, cf.load, cf.weight
    value = 0.0
    rate = 0.0
    accel = 0.0
    for i in range(lam.size):
        row = modes[r, i]
        if row == 0j:
            continue
        zi = _modal_at(cf, i, tau)
        zd = lam[i] * zi + load[1, i] + load[2, i] * tau
        zdd = lam[i] * zd + load[2, i]
        value += weight[i] * (row * zi).real
        rate += weight[i] * (row * zd).real
        accel += weight[i] * (row * zdd).real
    return value, rate, accel


#: Newton steps on the exact rate from the Hermite cubic's stationary point (converged to round-off
#: in 2–3 from a start within the cubic's error).
NEWTON_STEPS = 4
#: A Newton update below this fraction of the step ends the search (the extremum is flat there: its value
#: moves by the square of the update).
NEWTON_CONVERGED = 1e-12


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def _row_peak(cf, modes, size, r, y0, r0, y1, r1, h, peak) -> float:
    """The peak *peak* of |combination r| after the step: its end value (exact), and where its rate
    changes sign inside the step the exact extremum, found by Newton's method on the exact rate from the
    Hermite cubic's, when the cubic's extremum plus its error bound (:func:`_row_bound`, *size* the
    row's moduli) could pass the peak."""
    peak = max(peak, abs(y1))
    if r0 * r1 >= 0.0:
        return peak
    if extremum_in_step(y0, r0, y1, r1, h) + _row_bound(cf, size, r, h) <= peak:
        return peak
    s = rate_root(y0, r0, y1, r1, h)
    tau = s * h
    for _ in range(NEWTON_STEPS):
        _, rate, accel = _exact_at(cf, modes, r, tau)
        if accel == 0.0:
            break
        moved = min(h, max(0.0, tau - rate / accel))
        if abs(moved - tau) <= NEWTON_CONVERGED * h:
            tau = moved
            break
        tau = moved
    value, _, _ = _exact_at(cf, modes, r, tau)
    return max(peak, abs(value))


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def record_exact_peaks(cf, work, h, n, structure, peaks) -> None:
    """Peaks of floor displacements, storey drifts and a plan model's plane drifts over an exact step:
    found on the exact solution (:func:`_row_peak`); ``cf.bound`` from this step (:func:`graze_fraction`)."""
    y, ynew, below = work.y, work.ynew, structure.below
    for j in range(n):
        peaks.displacement[j] = _row_peak(cf, cf.floor_modes, cf.floor_size, j, y[j], y[n + j], ynew[j],
                                          ynew[n + j], h, peaks.displacement[j])
        b = below[j]
        peaks.drift[j] = _row_peak(cf, cf.drift_modes, cf.drift_size, j, drift(y, 0, j, b), drift(y, n, j, b),
                                   drift(ynew, 0, j, b), drift(ynew, n, j, b), h, peaks.drift[j])
    floors, weights, width = structure.plane_floors, structure.plane_weights, structure.plane_width
    for p in range(peaks.plane.size):
        peaks.plane[p] = _row_peak(cf, cf.plane_modes, cf.plane_size, p, combo(y, 0, floors, weights, width, p),
                                   combo(y, n, floors, weights, width, p), combo(ynew, 0, floors, weights, width, p),
                                   combo(ynew, n, floors, weights, width, p), h, peaks.plane[p])


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def has_modes(cf) -> bool:
    """False for :func:`no_closed_form` (Runge–Kutta steps throughout)."""
    return cf.eigenvalue.size > 0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def wants_exact(cf) -> bool:
    """True in an exact window of the run (:func:`count_linear_step`)."""
    return cf.policy[0] == 1


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def count_linear_step(policy, threshold, exact, at_sample) -> None:
    """Count an accepted step of a linear phase (*exact*: in closed form; *at_sample*: it ends at a record
    sample) and switch windows: a probing window of PROBE_SAMPLES linear samples runs Runge–Kutta steps
    and counts them; if they were more than ``cf.threshold`` per sample the next EXACT_SAMPLES linear
    samples run in closed form, then the run probes again.  Counts, not clocks: a run is repeatable.
    *policy*, *threshold*: ``cf.policy`` and ``cf.threshold``."""
    if exact:
        policy[3] += 1
    else:
        policy[2] += 1
    if not at_sample or threshold[0] < 0.0:  # a negative threshold: every linear phase in closed form
        return
    policy[1] += 1
    if policy[0] == 0 and policy[1] >= PROBE_SAMPLES:
        if policy[2] > threshold[0] * policy[1]:
            policy[0] = 1
        policy[1] = 0
        policy[2] = 0
    elif policy[0] == 1 and policy[1] >= EXACT_SAMPLES:
        policy[0] = 0
        policy[1] = 0
        policy[2] = 0


jit.stamp_solver_kernels(globals())


def no_closed_form() -> ClosedForm:
    """A :class:`ClosedForm` without modes: a run on Runge–Kutta steps throughout.  Its arrays have the
    types of a built one, so the solver is compiled once for both (:func:`has_modes` is False)."""
    c1, c2, c3 = (np.zeros((0,) * k, dtype=np.complex128) for k in (1, 2, 3))
    f1, f2 = np.zeros(0), np.zeros((0, 0))
    i1, i2 = np.zeros(0, dtype=np.int64), np.zeros((0, 0), dtype=np.int64)
    return ClosedForm(i1, np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64),
                      c1, f1, c1, c1, c2, c2, c2, c2, c2, c2, f2, f2, f2, f2, i2, f1, f1, f1, np.zeros(1), c2, c3,
                      c1, c1, c2, c2, np.zeros(1, dtype=np.int64), c1, c1, f1, np.zeros(4, dtype=np.int64),
                      np.array([np.inf]))


def run_closed_form(system, record_step: float, n_grounds: int, threshold: float | None = None,
                    linear_phases: str = "exact") -> ClosedForm:
    """The :class:`ClosedForm` of *system* for one run: built once per structure, record step and ground
    count (:func:`closed_form`'s cache), with fresh scratch arrays each call (two runs never share one).

    *threshold*: Runge–Kutta steps per linear sample above which the run switches to closed form
    (default :func:`pays_threshold`); negative: every linear phase in closed form from the start.
    :func:`no_closed_form` for a model :func:`closed_form` refuses and for *linear_phases*
    ``"runge-kutta"``: every run passes a closed form of one type, so the solver is compiled once for
    models with and without one (a pruned variant without it was 1 % faster on ``pair_inelastic``,
    within the noise, and cost a compilation of its own, ~50 s, for every combination of features)."""
    cf = closed_form(system, record_step, n_grounds) if linear_phases == "exact" else None
    if cf is None:
        return no_closed_form()
    m = cf.eigenvalue.size
    cf = cf._replace(z=np.zeros(m, dtype=np.complex128), z_end=np.zeros(m, dtype=np.complex128),
                       load=np.zeros((3, m), dtype=np.complex128), scratch=np.zeros((4, m), dtype=np.complex128),
                       valid=np.zeros(1, dtype=np.int64), z_at=np.zeros(m, dtype=np.complex128),
                       node_state=np.zeros(m, dtype=np.complex128),
                       bound=np.zeros(m), policy=np.array([0, 0, 0, 0], dtype=np.int64),
                       threshold=cf.threshold.copy() if threshold is None else np.array([float(threshold)]))
    if cf.threshold[0] < 0.0:
        cf.policy[0] = 1
    return cf
