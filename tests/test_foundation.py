"""Buildings on sway–rocking foundations: periods, the rigid limit, an independent reference, errors.

The reference below is written from docs/foundations.md in *other* coordinates than the solver's:
the floors' deformations d, the base mat's sway u_b and rocking θ_b, whose mass matrix is full
(each floor's total motion is u_g + u_b + z θ_b + d).  pounding uses the floors' displacements
relative to the free field, with a diagonal mass matrix; the two must give the same motion.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

import pounding
from pounding.errors import ModelError
from pounding.model.foundation_impedance import veletsos_meek_period
from pounding.model.model import model_from_text
from pounding.results.summary import run_summary
from pounding.simulation import record_for


def write(tmp_path, text: str, name: str = "m.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def sine_record(tmp_path, duration: float, amplitude: float = 3.0, frequency: float = 1.6) -> None:
    """A tapered sine ground acceleration (m/s², written in g) at dt = 0.01 s in sine.txt."""
    t = np.arange(0.0, duration + 1e-9, 0.01)
    ag = amplitude * np.sin(2 * np.pi * frequency * t) * np.minimum(1.0, t / 0.5)
    np.savetxt(tmp_path / "sine.txt", ag / 9.80665, header="units: g; dt = 0.01 s", comments="# ")


FOUNDATION = """    foundation:
      mass: {mb}
      rotary_inertia: {ib}
      sway: {{stiffness: {kx}, damping: {cx}}}
      rocking: {{stiffness: {kt}, damping: {ct}}}
"""

PAIR = """\
name: founded_pair
buildings:
  - name: A
    storeys: {{count: 4, mass: 2.0e5, stiffness: 2.0e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 3]}}
{found_a}  - name: B
    storeys: {{count: 3, mass: 1.5e5, stiffness: 3.5e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 2]}}
{found_b}contacts:
  - {{between: [A, B], levels: matching, gap: 0.004, law: {law}}}
ground_motion: {{record: sine.txt, units: g, dt: 0.01, duration: {duration}}}
solver: {{rtol: 1.0e-10, atol: 1.0e-13, atol_velocity: 1.0e-12, output_dt: 0.01}}
"""


def pair(tmp_path, found_a: dict | None, found_b: dict | None, *, law: str = "linear, k: 2.0e9",
         duration: float = 2.0):
    sine_record(tmp_path, duration)
    text = PAIR.format(found_a="" if found_a is None else FOUNDATION.format(**found_a),
                       found_b="" if found_b is None else FOUNDATION.format(**found_b), law=law, duration=duration)
    return pounding.load_model(write(tmp_path, text))


# As written in the YAML (strings: the error tests edit the text).
SOFT_A = dict(mb="8.0e5", ib="4.0e7", kx="1.5e9", cx="6.0e7", kt="2.0e11", ct="4.0e9")
SOFT_B = dict(mb="6.0e5", ib="2.5e7", kx="1.2e9", cx="5.0e7", kt="1.5e11", ct="3.0e9")


# --------------------------------------------------------------------------- #
# (a) periods of a one-storey building on springs
# --------------------------------------------------------------------------- #


ONE = """\
name: one
buildings:
  - name: A
    storeys:
      - {{mass: 1.0e6, stiffness: 4.0e8, height: 6.0}}
    damping: {{modal: [0.05]}}
    foundation:
      mass: {mb}
      rotary_inertia: {ib}
      sway: {{stiffness: 2.0e9, damping: 0}}
      rocking: {{stiffness: 1.0e11, damping: 0}}
ground_motion: {{record: sine.txt, units: g, dt: 0.01}}
"""


def three_dof_period(m, k, h, mb, ib, kx, kt) -> float:
    """The first undamped period of (d, u_b, θ): full mass matrix from T = ½ m (u̇_b + h θ̇ + ḋ)² + ½ m_b u̇_b²
    + ½ I_b θ̇², diagonal stiffness diag(k, K_x, K_θ); scipy's generalised symmetric eigensolver."""
    mass = np.array([[m, m, m * h], [m, m + mb, m * h], [m * h, m * h, m * h * h + ib]])
    omega2 = scipy.linalg.eigh(np.diag([k, kx, kt]), mass, eigvals_only=True)
    return 2 * np.pi / np.sqrt(omega2[0])


@pytest.mark.parametrize("scale", [1.0, 1e-9])
def test_one_storey_flexible_base_period_is_the_three_dof_eigenvalue_and_tends_to_veletsos_meek(tmp_path, scale):
    sine_record(tmp_path, 1.0)
    mb, ib = 5.0e5 * scale, 2.0e7 * scale
    building = pounding.load_model(write(tmp_path, ONE.format(mb=mb, ib=ib))).buildings[0]
    exact = three_dof_period(1.0e6, 4.0e8, 6.0, mb, ib, 2.0e9, 1.0e11)
    # Two eigensolvers on the same 3x3 problem in different coordinates: round-off only.
    assert building.flexible_periods[0] == pytest.approx(exact, rel=1e-10)
    fixed = 2 * np.pi * np.sqrt(1.0e6 / 4.0e8)
    assert building.periods[0] == pytest.approx(fixed, rel=1e-12)
    limit = veletsos_meek_period(fixed, 4.0e8, 6.0, 2.0e9, 1.0e11)
    assert limit == pytest.approx(fixed * np.sqrt(1 + 0.2 + 4.0e8 * 36 / 1.0e11), rel=1e-15)
    if scale < 1.0:
        # m_b, I_b scaled by 1e-9: the period differs from the massless-base limit by O(1e-9).
        assert building.flexible_periods[0] == pytest.approx(limit, rel=1e-7)
    else:
        # A heavy mat lengthens the period further than the massless formula (0.9 % here): the test can tell.
        assert building.flexible_periods[0] > limit * 1.005


# --------------------------------------------------------------------------- #
# (b) a rigid foundation is a fixed base
# --------------------------------------------------------------------------- #


def test_very_stiff_foundations_reproduce_the_fixed_base_run(tmp_path):
    rigid = dict(mb=8.0e5, ib=4.0e7, kx=1.0e16, cx=2.0e10, kt=1.0e19, ct=2.0e12)
    fixed = pounding.simulate(pair(tmp_path, None, None))
    founded = pounding.simulate(pair(tmp_path, rigid, dict(rigid, mb=6.0e5, ib=2.5e7)))
    assert int(fixed.impact_count.sum()) > 0
    np.testing.assert_array_equal(founded.impact_count.values, fixed.impact_count.values)
    # Foundation compliance k/K_x ~ 1e-7 and k H²/K_θ ~ 1e-8, both integrations at rtol 1e-10: 1e-6 holds.
    for name in ("peak_displacement", "peak_storey_drift"):
        np.testing.assert_allclose(founded[name].values, fixed[name].values, rtol=1e-6, err_msg=name)
    # A contact force is k times the penetration, a difference of displacements ~3x smaller than them and
    # closing at a located instant: its relative error is larger (measured 2.3e-6); 1e-5.
    np.testing.assert_allclose(founded.peak_contact_force.values, fixed.peak_contact_force.values, rtol=1e-5)
    assert float(founded.peak_base_sway.max()) < 1e-7
    assert founded.attrs["energy_closure_error"] < 1e-6


# --------------------------------------------------------------------------- #
# (c) an independent reference of a founded pair that pounds
# --------------------------------------------------------------------------- #


class Reference:
    """A founded row in coordinates p = (d, u_b, θ) per building: full M, K and C from the model's parameters."""

    def __init__(self, model):
        blocks_m, blocks_k, blocks_c, self.x_of = [], [], [], []
        self.storeys, self.floor_x = [], []
        offset = 0
        for b in model.buildings:
            n, z, f = b.n_floors, b.elevation, b.foundation
            s = np.zeros((n + 2, n + 2))        # total-minus-ground floor motions x and u_b, θ from p
            s[:n, :n] = np.eye(n)
            s[:n, n], s[:n, n + 1] = 1.0, z
            s[n, n], s[n + 1, n + 1] = 1.0, 1.0
            diag = np.r_[b.mass, f.mass, f.rotary_inertia]
            kf = np.zeros((n, n))
            for i, k in enumerate(b.stiffness):
                a = np.zeros(n)
                a[i] = 1.0
                if i:
                    a[i - 1] = -1.0
                kf += k * np.outer(a, a)
            a0, a1 = b.rayleigh_coefficients
            cf = a0 * np.diag(b.mass) + a1 * kf
            m = s.T @ np.diag(diag) @ s
            k = scipy.linalg.block_diag(kf, np.diag([f.sway_stiffness, f.rocking_stiffness]))
            c = scipy.linalg.block_diag(cf, np.diag([f.sway_damping, f.rocking_damping]))
            blocks_m.append(m), blocks_k.append(k), blocks_c.append(c)
            self.x_of.append((offset, s, diag))
            self.floor_x += [(offset, s[i]) for i in range(n)]
            self.storeys += [(offset + i, offset + i - 1 if i else -1) for i in range(n)]
            offset += n + 2
        self.M, self.K, self.C = (scipy.linalg.block_diag(*x) for x in (blocks_m, blocks_k, blocks_c))
        self.Minv = np.linalg.inv(self.M)
        self.N = offset
        # ground forcing −Sᵀ diag(m) r a_g with r = 1 on every translation (floors and sway), 0 on rocking
        self.r = np.concatenate([s.T @ (diag * np.r_[np.ones(s.shape[0] - 1), 0.0]) for _, s, diag in self.x_of])
        firsts = np.cumsum([0] + [b.n_floors + 2 for b in model.buildings])
        self.contacts = [(firsts[g.left] + g.level_left - 1, firsts[g.right] + g.level_right - 1, g.gap, g.law.k)
                         for g in model.gaps]

    def x(self, p: np.ndarray, j: int) -> np.ndarray:
        """Floor j's displacement relative to the free field (j: its index among p's deformations)."""
        offset, s, _ = next((o, s, d) for o, s, d in self.x_of if o <= j < o + s.shape[0] - 2)
        return s[j - offset] @ p[offset:offset + s.shape[0]]


def reference_run(model, ag: np.ndarray, dt: float, duration: float) -> dict:
    ref = Reference(model)
    n = ref.N
    closed = [False] * len(ref.contacts)
    impacts = 0
    floors = [j for j, _ in ref.storeys]
    peak_x = np.zeros(len(floors))
    peak_drift = np.zeros(len(floors))

    def delta(y, c):
        left, right, gap, _ = ref.contacts[c]
        return ref.x(y[:n], left) - ref.x(y[:n], right) - gap

    def rhs(t, y, a_g):
        p, v = y[:n], y[n:]
        f = ref.K @ p + ref.C @ v + ref.r * a_g
        for c, (left, right, gap, k) in enumerate(ref.contacts):
            if closed[c]:
                force = k * max(delta(y, c), 0.0)
                for j, sign in ((left, 1.0), (right, -1.0)):   # a force F on floor j: generalised Sᵀ e_j F
                    offset, s, _ = next((o, s, d) for o, s, d in ref.x_of if o <= j < o + s.shape[0] - 2)
                    f[offset:offset + s.shape[0]] += sign * force * s[j - offset]
        return np.r_[v, -ref.Minv @ f]

    def track(sol, a, b):
        nonlocal peak_x, peak_drift
        grid = np.linspace(a, b, max(2, int(np.ceil((b - a) / 2e-5)) + 1))
        p = sol.sol(grid)[:n]
        x = np.array([[ref.x(p[:, i], j) for i in range(grid.size)] for j in floors])
        d = np.array([p[j] - (p[below] if below >= 0 else 0.0) for j, below in ref.storeys])
        peak_x = np.maximum(peak_x, np.abs(x).max(axis=1))
        peak_drift = np.maximum(peak_drift, np.abs(d).max(axis=1))

    def events():
        out = []
        for c in range(len(ref.contacts)):
            def ev(t, y, *args, c=c):
                return delta(y, c)
            ev.terminal, ev.direction = True, (-1.0 if closed[c] else 1.0)
            out.append(ev)
        return out

    y = np.zeros(2 * n)
    samples = np.arange(int(round(duration / dt)) + 1) * dt
    for i in range(samples.size - 1):
        t0, t1 = samples[i], samples[i + 1]
        g0, g1 = ag[i], ag[i + 1]
        t = t0
        while t < t1 - 1e-15:
            sol = solve_ivp(lambda tt, yy: rhs(tt, yy, g0 + (g1 - g0) * (tt - t0) / dt), (t, t1), y,
                            method="DOP853", rtol=1e-11, atol=1e-14, dense_output=True, events=events())
            hit = [(te[0], c) for c, te in enumerate(sol.t_events) if te.size]
            if not hit:
                track(sol, t, t1)
                y, t = sol.y[:, -1], t1
                break
            te, c = min(hit)
            track(sol, t, te)
            y = sol.y_events[c][0].copy()
            impacts += not closed[c]
            closed[c] = not closed[c]
            t = te
    return {"peak_displacement": peak_x, "peak_drift": peak_drift, "impacts": impacts}


def test_a_founded_pair_that_pounds_matches_an_independent_scipy_integration(tmp_path):
    model = pair(tmp_path, SOFT_A, SOFT_B, duration=1.5)
    ds = pounding.simulate(model)
    record = record_for(model)
    ref = reference_run(model, record.acceleration, record.time_step, 1.5)
    assert int(ds.impact_count.sum()) == ref["impacts"] > 0
    assert float(ds.peak_base_rocking.min()) > 0.0
    # DOP853 at rtol 1e-11 with every closure and separation a located event, against our DP5(4) at rtol 1e-10;
    # the reference's peaks are read on a 2e-5 s grid of its dense output (error ≪ 1e-6 of the peak).
    np.testing.assert_allclose(ds.peak_displacement.values, ref["peak_displacement"], rtol=1e-6)
    np.testing.assert_allclose(ds.peak_storey_drift.values, ref["peak_drift"], rtol=1e-6)
    assert ds.attrs["energy_closure_error"] < 1e-6


# --------------------------------------------------------------------------- #
# Behaviour: the archive, the summary, errors
# --------------------------------------------------------------------------- #


def test_the_archive_reports_base_motion_deformations_and_a_closed_energy_audit(tmp_path):
    ds = pounding.simulate(pair(tmp_path, SOFT_A, None, duration=1.0))
    assert list(ds.foundation.values) == ["A"]
    # Floor displacement relative to the free field = deformation + sway + z θ (docs/foundations.md).
    a = ds.building.values == "A"
    rebuilt = (ds.floor_deformation.values[:, a] + ds.base_sway.values[:, [0]]
               + ds.base_rocking.values[:, [0]] * ds.elevation.values[a][None, :])
    np.testing.assert_allclose(rebuilt, ds.displacement.values[:, a], rtol=0, atol=1e-15)
    # Storey drifts are deformations: differences of floor_deformation, not of the displacements.
    np.testing.assert_allclose(ds.storey_drift.values[:, 1], ds.floor_deformation.values[:, 1]
                               - ds.floor_deformation.values[:, 0], atol=1e-15)
    assert 0.0 < float(ds.energy_foundation_damping[-1]) < float(ds.energy_damping[-1])
    assert ds.attrs["energy_closure_error"] < 1e-6
    text = run_summary(ds)
    assert "foundations" in text and "A: T " in text


@pytest.mark.parametrize("edit, message", [
    (("stiffness: 1.5e9", "stiffness: -1.5e9"), "foundation.sway.stiffness must be > 0"),
    (("rotary_inertia: 4.0e7", "rotary_inertia: 0"), "foundation.rotary_inertia must be > 0"),
    (("      mass: 8.0e5", "      mas: 8.0e5"), "did you mean 'mass'"),
    (("damping: {ratio: 0.05, modes: [1, 3]}", "damping: {ratio: 0.05, modes: [1, 3]}\n    p_delta: true"),
     "p_delta is not supported on a building with a foundation"),
])
def test_a_bad_foundation_is_one_located_line(tmp_path, edit, message):
    sine_record(tmp_path, 1.0)
    text = PAIR.format(found_a=FOUNDATION.format(**SOFT_A), found_b="", law="linear, k: 2.0e9", duration=1.0)
    assert edit[0] in text
    with pytest.raises(ModelError) as caught:
        pounding.load_model(write(tmp_path, text.replace(edit[0], edit[1], 1)))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_a_plan_building_refuses_a_foundation_in_one_line(tmp_path):
    text = open("models/corner_pair.yaml").read()
    marker = "    damping:"
    assert marker in text
    found = text.replace(marker, FOUNDATION.format(**SOFT_A) + marker, 1)
    with pytest.raises(ModelError) as caught:
        model_from_text(found, base_dir="models")
    assert "foundations are for planar buildings for now" in str(caught.value)
    assert "\n" not in str(caught.value)


def test_the_gap_study_of_a_founded_pair_reads_the_approach_of_total_displacements(tmp_path, studies_in_process):
    """The separation a founded pair needs is the peak approach of the floors' displacements relative to the
    free field (sway and rocking included), the same as read from the contact-free run itself.
    The study runs on the in-process cluster (tests/conftest.py): its result is what is tested."""
    from pounding.cli import main

    model = pair(tmp_path, SOFT_A, SOFT_B, duration=2.0)
    path = tmp_path / "m.yaml"
    assert main(["gap", str(path), "--workers", "1", "--no-progress", "-o", str(tmp_path / "gap.nc")]) == 0
    import xarray as xr

    with xr.open_dataset(tmp_path / "gap.nc") as gap:
        required = gap.required_gap.values[0]
    ds = pounding.simulate(model.with_contacts_open())
    u = ds.displacement.values
    for c, (left, right) in enumerate(zip(ds.level_left.values, ds.level_right.values)):
        approach = u[:, left - 1] - u[:, 4 + right - 1]    # A has 4 floors, B's follow
        sampled = float(np.max(np.abs(approach)))
        # the study takes the largest of the cubic Hermite interpolant between the stored samples (0.01 s):
        # at least the sampled peak, and above it by less than the curvature over half a step,
        # |a| dt^2 / 8 < (0.2 m/s^2 ... ) -> 1 % of these centimetre approaches is ample
        assert sampled > 1e-3     # the buildings do move towards each other by millimetres
        assert sampled - 1e-12 <= required[c] <= 1.01 * sampled
