"""One kinematics (pounding/solver/kinematics.py) for the solver and the results; contact sides of four terms.

The archive's ``penetration`` (sampled histories, by :func:`pounding.solver.kinematics.penetration`)
and the impact trace's ``trace_penetration`` (the solver's closed-contact samples on a step's
interpolant) are the same δ = Σ w·u + u_g,L − u_g,R − gap: where a trace sample falls on an
output time they agree to round-off, on one ground and with wave passage (ground offsets).

A side of four terms (a slab striking a column of a plan building between two floors: u_x and θ of
the floor below with N1 and N1·lever, of the floor above with N2 and N2·lever) is checked on the
solver's compiled kernels against hand values (δ, the force's virtual work, 1/m_eff), and a whole
impact, and a rigid one, against an independent scipy integration and the impulse law.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from numba import njit
from scipy.integrate import solve_ivp

from pounding import load_model, simulate
from pounding.contact import laws as contact
from pounding.solver import kinematics
from pounding.solver.integrator import System, integrate
from pounding.solver.layout import state_layout

MODELS = Path(__file__).resolve().parents[1] / "models"


@pytest.mark.parametrize("name", ["pair", "pair_wave_passage"])
def test_archive_penetration_equals_the_trace_at_the_trace_times(name):
    model = load_model(MODELS / f"{name}.yaml")
    ds = simulate(model, duration=8.0)  # output every 0.01 s: record samples, where steps end
    time = ds.time.values
    trace_time = ds.trace_time.values
    # Trace samples that fall on an output time (steps never straddle a record sample).
    at = np.searchsorted(time, trace_time)
    at = np.clip(at, 0, time.size - 1)
    on = np.abs(time[at] - trace_time) <= 1e-9
    assert on.sum() >= 20, "too few trace samples on output times to compare"
    contact = ds.trace_contact.values[on]
    archived = ds.penetration.values[at[on], contact]
    traced = ds.trace_penetration.values[on]
    assert np.all(traced > 0.0)  # closed contacts: overlapping
    np.testing.assert_allclose(archived, traced, rtol=0.0, atol=1e-12)


def test_results_penetration_is_the_solvers_sum():
    # A floor pair, a column point (two weighted terms) and a wall, against combo's own terms.
    floors = np.array([[0, -1, 2, -1], [0, 1, 3, -1], [1, -1, -1, -1]])
    weights = np.array([[1.0, 0.0, -1.0, 0.0], [0.25, 0.75, -1.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    gap = np.array([0.01, 0.02, 0.03])
    rng = np.random.default_rng(7)
    u = rng.normal(scale=0.05, size=(5, 4))
    ground = rng.normal(scale=1e-3, size=(5, 3))
    got = kinematics.penetration(u, floors, weights, gap, ground)
    cf, cw, width = kinematics.kernel_terms(floors, weights)
    assert len(width) == kinematics.NARROW_TERMS  # two terms per side: the narrow rows
    for i in range(u.shape[0]):
        for c in range(gap.size):
            expected = kinematics.combo.py_func(u[i], 0, cf, cw, width, c) + ground[i, c] - gap[c]
            assert got[i, c] == expected


def test_layout_offsets():
    lay = state_layout(5, 2, 3)
    assert (lay.velocity, lay.impulse, lay.work, lay.internal) == (5, 10, 12, 14)
    assert (lay.input_energy, lay.damping_energy, lay.hysteretic, lay.storey_work) == (16, 17, 18, 21)
    assert (lay.ground_work, lay.size) == (24, 25)


# --------------------------------------------------------------------------- #
# A side of four terms: a slab striking a column between two floors of a plan building
# --------------------------------------------------------------------------- #

# Building A: two rigid floors, DOF (u_x, u_y, θ) each (0-2, 3-5); B: a slab, u_x only (6).  Every DOF
# hangs on a spring to the DOF below it (A's floor 1 and B's slab to the ground), undamped.
A_MASS, A_INERTIA, B_MASS = (4.0e5, 3.0e5), (6.0e7, 4.5e7), 2.5e5            # kg, kg·m²
SPRINGS = np.array([8.0e7, 8.0e7, 1.2e10, 6.0e7, 6.0e7, 9.0e9, 5.0e7])       # N/m (θ: N·m/rad)
BELOW = np.array([-1, -1, -1, 0, 1, 2, -1], dtype=np.int64)
AT, LEVER, COLUMN_GAP = 0.3, -4.0, 0.01  # fraction of A's storey 2; u_x − 4·θ moves the column face; m


def hermite(at: float) -> tuple[float, float]:
    """N1 (floor below), N2 (floor above) of a fixed-fixed column at fraction *at* of its height."""
    return 1.0 - 3.0 * at**2 + 2.0 * at**3, 3.0 * at**2 - 2.0 * at**3


def column_strike(law) -> System:
    """B's slab (left side, one term) against the column point of A between its floors (right side,
    four terms: u_x and θ of the floor below with N1 and N1·lever, of the floor above with N2, N2·lever)."""
    n1, n2 = hermite(AT)
    mass = np.array([A_MASS[0], A_MASS[0], A_INERTIA[0], A_MASS[1], A_MASS[1], A_INERTIA[1], B_MASS])
    ints = lambda *a: np.array(a, dtype=np.int64)  # noqa: E731
    return System(mass=mass, storey_stiffness=SPRINGS.copy(), below=BELOW.copy(), rayleigh_mass=np.zeros(7),
                  rayleigh_stiffness=np.zeros(7), dense_start=ints(), dense_size=ints(), dense_offset=ints(),
                  dense_values=np.zeros(0), contact_left=ints(6), contact_right=ints(3),
                  contact_gap=np.array([COLUMN_GAP]), contact_law=ints(law.law_id),
                  contact_parameters=law.kernel_parameters(B_MASS, 1.0 / column_compliance())[None, :].copy(),
                  contact_floors=np.array([[6, -1, -1, -1, 0, 2, 3, 5]]),
                  contact_weights=np.array([[1.0, 0.0, 0.0, 0.0, -n1, -n1 * LEVER, -n2, -n2 * LEVER]]))


def column_compliance() -> float:
    """1/m of A's column point along the normal (1/kg), by hand: Σ w²/m over its four terms."""
    n1, n2 = hermite(AT)
    return (n1**2 / A_MASS[0] + (n1 * LEVER) ** 2 / A_INERTIA[0] + n2**2 / A_MASS[1]
            + (n2 * LEVER) ** 2 / A_INERTIA[1])


def column_point(q: np.ndarray) -> np.ndarray:
    """Displacement (or velocity) of A's struck column point along the normal, by hand, from DOF values *q*."""
    n1, n2 = hermite(AT)
    return n1 * (q[..., 0] + LEVER * q[..., 2]) + n2 * (q[..., 3] + LEVER * q[..., 5])


@njit(cache=False)
def _compiled_kinematics(y, n, mass, cf, cw, width, force):
    """The solver's compiled kernels on contact 0: δ + gap, δ̇, the floor forces of *force*, 1/m_eff, m_eff."""
    fbuf = np.zeros(mass.size)
    kinematics.push(fbuf, cf, cw, width, 0, force)
    return (kinematics.combo(y, 0, cf, cw, width, 0), kinematics.combo(y, n, cf, cw, width, 0), fbuf,
            kinematics.compliance(mass, cf, cw, width, 0), kinematics.effective_mass(mass, cf, cw, width, 0))


def test_a_four_term_side_gives_delta_virtual_work_and_effective_mass():
    system = column_strike(contact.Hertz(kh=1e9))
    cf, cw, width = kinematics.kernel_terms(system.contact_floors, system.contact_weights)
    assert len(width) == kinematics.SIDE_TERMS  # a side of four terms: the wide rows
    rng = np.random.default_rng(3)
    y = rng.normal(scale=0.02, size=14)  # u (7), v (7)
    u, v = y[:7], y[7:]
    total, rate, fbuf, inverse, m_eff = _compiled_kinematics(y, 7, system.mass, cf, cw, width, 1.0e6)
    assert total - COLUMN_GAP == pytest.approx(u[6] - column_point(u) - COLUMN_GAP, rel=1e-14, abs=1e-17)
    assert rate == pytest.approx(v[6] - column_point(v), rel=1e-14, abs=1e-17)
    # Virtual work: the force's power on the floors (−fbuf·v: the contact's share of M·a) is −F·δ̇ exactly.
    assert -fbuf @ v == pytest.approx(-1.0e6 * rate, rel=1e-13)
    n1, n2 = hermite(AT)
    assert fbuf[[6, 0, 2, 3, 5]] == pytest.approx(1.0e6 * np.array([1.0, -n1, -n1 * LEVER, -n2, -n2 * LEVER]),
                                                   rel=1e-15)
    assert fbuf[[1, 4]].tolist() == [0.0, 0.0]
    assert inverse == pytest.approx(1.0 / B_MASS + column_compliance(), rel=1e-14)
    assert m_eff == pytest.approx(1.0 / (1.0 / B_MASS + column_compliance()), rel=1e-14)
    # The results' δ is the same sum (kinematics.penetration: the Python body of combo).
    got = kinematics.penetration(u[None, :], system.contact_floors, system.contact_weights, system.contact_gap,
                                 np.zeros((1, 1)))
    assert got[0, 0] == total - COLUMN_GAP


def test_narrow_rows_keep_their_layout_and_padding_goes_after_each_side():
    # Rows whose sides have at most two terms run at the narrow width, in the very arrays they always had
    # (a plan model's 8-column arrays with four absent columns included); others at SIDE_TERMS.
    floors = np.array([[0, -1, 2, -1], [0, 1, 3, -1], [1, -1, -1, -1]])
    weights = np.array([[1.0, 0.0, -1.0, -0.0], [0.25, 0.75, -1.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    cf, cw, width = kinematics.kernel_terms(floors, weights)
    assert len(width) == kinematics.NARROW_TERMS
    assert cf.tolist() == [0, 0, 2, 0, 0, 1, 3, 0, 1, 0, 0, 0]
    assert [np.copysign(1.0, w) for w in cw] == [np.copysign(1.0, w) for w in weights.ravel()]  # zeros' signs too
    wide_floors = np.insert(np.insert(floors, [2, 2], -1, axis=1), [6, 6], -1, axis=1)
    wide_weights = np.insert(np.insert(weights, [2, 2], 0.0, axis=1), [6, 6], 0.0, axis=1)
    wf, ww, wide = kinematics.kernel_terms(wide_floors, wide_weights)
    assert len(wide) == kinematics.NARROW_TERMS and wf.tolist() == cf.tolist()
    assert np.array_equal(ww, cw) and np.array_equal(np.signbit(ww), np.signbit(cw))
    three = np.array([[0, 1, 4, 2, -1, -1]]), np.array([[0.2, 0.3, 0.5, -1.0, 0.0, 0.0]])
    tf, tw, terms = kinematics.kernel_terms(*three)
    assert len(terms) == kinematics.SIDE_TERMS
    assert tf.tolist() == [0, 1, 4, 0, 2, 0, 0, 0] and tw.tolist() == [0.2, 0.3, 0.5, 0.0, -1.0, 0.0, 0.0, 0.0]
    with pytest.raises(ValueError):
        kinematics.kernel_terms(np.zeros((1, 10), dtype=np.int64), np.ones((1, 10)))


def reference_column_strike(law, v0: float, duration: float, samples: np.ndarray):
    """The same run written out for scipy's DOP853, from the equations, not from the solver's kernels.

    M q̈ = −K q − w·F(δ, δ̇) with δ = u_B − u_column − gap (:func:`column_point`), K the springs between
    each DOF and the one below it, w the contact's weights; Hertz-damp F = δ^1.5·(kh + ξ·δ̇) while
    δ > 0 with ξ = p·kh/v_c fixed at the closure (approach velocity v_c), closure and separation
    located as terminal events.  Returns the closure and separation (t, δ̇), the dense solution at
    *samples* and the contact force there.
    """
    n1, n2 = hermite(AT)
    mass = np.array([A_MASS[0], A_MASS[0], A_INERTIA[0], A_MASS[1], A_MASS[1], A_INERTIA[1], B_MASS])
    w = np.array([-n1, 0.0, -n1 * LEVER, -n2, 0.0, -n2 * LEVER, 1.0])

    def spring_forces(q):
        drift = q - np.where(BELOW >= 0, q[np.maximum(BELOW, 0)], 0.0)
        f = SPRINGS * drift
        out = f.copy()
        for j, b in enumerate(BELOW):
            if b >= 0:
                out[b] -= f[j]
        return out

    def delta(y):
        return w @ y[:7] - COLUMN_GAP

    def force(y, xi):
        d = delta(y)
        return d**1.5 * (law.kh + xi * (w @ y[7:])) if xi is not None and d > 0.0 else 0.0

    def rhs(t, y, xi):
        return np.concatenate([y[7:], -(spring_forces(y[:7]) + w * force(y, xi)) / mass])

    def crossing(direction):
        def event(t, y, xi):
            return delta(y)
        event.terminal, event.direction = True, direction
        return event

    y0 = np.zeros(14)
    y0[13] = v0
    pieces, events, xi, t = [], [], None, 0.0
    while t < duration:
        sol = solve_ivp(rhs, (t, duration), y0, method="DOP853", rtol=1e-12, atol=1e-15, dense_output=True,
                        events=[crossing(1.0 if xi is None else -1.0)], args=(xi,))
        pieces.append((t, sol.t[-1], sol.sol, xi))
        t, y0 = sol.t[-1], sol.y[:, -1]
        if sol.status == 1:
            events.append((t, w @ y0[7:]))
            xi = law.p * law.kh / (w @ y0[7:]) if xi is None else None
    state = np.empty((samples.size, 14))
    forces = np.empty(samples.size)
    for i, s in enumerate(samples):
        t0, t1, dense, piece_xi = next(p for p in pieces if p[0] <= s <= p[1])
        state[i] = dense(s)
        forces[i] = force(state[i], piece_xi)
    return events, state, forces


def test_a_slab_striking_a_column_between_floors_matches_scipy():
    law = contact.HertzDamp(kh=2.0e10, restitution=0.6, xi="ye")
    v0, duration = 0.8, 0.12
    raw = integrate(column_strike(law), np.zeros(int(duration / 0.01) + 2), 0.01, duration,
                    initial_velocity=np.r_[np.zeros(6), v0], rtol=1e-11, atol=1e-14, atol_velocity=1e-13,
                    output_dt=0.002)
    assert raw.status == 0 and raw.impact_time.size == 1
    events, state, forces = reference_column_strike(law, v0, duration, np.r_[raw.time, raw.trace_time])
    (t_close, v_close), (t_open, v_open) = events[:2]
    assert len(events) == 2  # one impact, then apart until the end
    assert raw.impact_time[0] == pytest.approx(t_close, abs=1e-10)
    assert raw.impact_velocity[0] == pytest.approx(v_close, rel=1e-9)
    assert raw.impact_end_time[0] == pytest.approx(t_open, abs=1e-9)
    assert raw.impact_separation_velocity[0] == pytest.approx(-v_open, rel=1e-7)
    nt = raw.time.size
    # Every DOF of both buildings (the θ of A's floors turned by the strike off their centre), at every sample.
    scale = np.abs(state[:nt]).max(axis=0)
    assert np.all(np.abs(state[:nt] - raw.state[:, :14]).max(axis=0) <= 1e-7 * scale + 1e-15)
    assert np.abs(state[:nt, [2, 5, 9, 12]]).max() > 1e-6  # the floors did turn
    # The solver's own δ and force on its step interpolants, at its trace samples.
    assert raw.trace_time.size > 20
    reference_delta = state[nt:, 6] - column_point(state[nt:, :7]) - COLUMN_GAP
    assert np.abs(raw.trace_penetration - reference_delta).max() <= 1e-7 * reference_delta.max()
    assert np.abs(raw.trace_force - forces[nt:]).max() <= 1e-6 * forces.max()
    assert raw.peak_contact_force[0] == pytest.approx(forces.max(), rel=1e-5)
    # Energy: kinetic + spring + the contact's work ∫F·δ̇ dt stays ½·m_B·v0² (no damping anywhere else).
    lay = column_strike(law).layout
    q, v = raw.state[:, :7], raw.state[:, 7:14]
    drift = q - np.where(BELOW >= 0, q[:, np.maximum(BELOW, 0)], 0.0)
    mass = column_strike(law).mass
    energy = 0.5 * (v**2 * mass).sum(axis=1) + 0.5 * (SPRINGS * drift**2).sum(axis=1) + raw.state[:, lay.work]
    assert np.abs(energy - 0.5 * B_MASS * v0**2).max() <= 1e-7 * 0.5 * B_MASS * v0**2
    assert raw.impact_work[0] == pytest.approx(raw.state[-1, lay.work], rel=1e-12)


def test_a_rigid_strike_on_a_four_term_side_rebounds_with_e():
    # The impulse J = (1 + e)·m_eff·v (m_eff of the four-term side by hand) kicks every term by −w·J/m:
    # δ̇ jumps from v to −e·v only if the kick and the effective mass use the same weights.
    e, v0 = 0.5, 0.8
    system = column_strike(contact.StereoMechanical(restitution=e))
    raw = integrate(system, np.zeros(12), 0.01, 0.1, initial_velocity=np.r_[np.zeros(6), v0], rtol=1e-11,
                    atol=1e-14, atol_velocity=1e-13, output_dt=0.01)
    assert raw.impact_time.size >= 1
    m_eff = 1.0 / (1.0 / B_MASS + column_compliance())
    v_close = raw.impact_velocity[0]
    assert raw.impact_impulse[0] == pytest.approx((1.0 + e) * m_eff * v_close, rel=1e-12)
    assert raw.impact_separation_velocity[0] == pytest.approx(e * v_close, rel=1e-12)
