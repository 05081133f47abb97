"""Hysteretic planes, plane collapse and their energy in plan models (issue 26 §2-3)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pounding.model.model import model_from_text
from pounding.simulation import ground_on_grid, simulate

from plan_cases import SOLVER, bilinear as _bilinear, plan_pair as _plan_pair, two_tone_record as _record


ECCENTRIC = """name: e
buildings:
  - name: A
    plan: {outline: [[0, 0], [20, 10]]}
    storeys:
      - {mass: 2.0e5, height: 3.0, centre_of_mass: [8, 4], planes: [
         {direction: x, at: 0, stiffness: 1.0e7, HYST},
         {direction: x, at: 10, stiffness: 2.0e7, HYST},
         {direction: y, at: 0, stiffness: 3.0e7, HYST},
         {direction: y, at: 20, stiffness: 4.0e7}]}
    damping: {ratio: 0.05, modes: [1, 3]}
ground_motion: {x: {record: REC}, y: {record: REC, scale: 0.6}, angle: 30, duration: 2.0}
"""


def _eccentric(tmp_path, extra: str = SOLVER):
    text = ECCENTRIC.replace("REC", _record(tmp_path)).replace("HYST", _bilinear(0.001, 0.1)) + extra
    return model_from_text(text, name="e")


def _reference(model, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """solve_ivp on M q̈ + C q̇ + Σ a F_p(a·q, Δ_p) = −M r a_g, every yield onset and unloading of a
    bilinear plane a terminal event (the integration restarts in the plane's new mode), each record
    step integrated on its own (a_g is linear there).  Returns (times, q) on the record's grid."""
    b = model.buildings[0]
    m, c = b.mass_matrix(), b.damping_matrix()
    minv = np.linalg.inv(m)
    planes = [(a, b.storeys[s - 1].planes[j], b.storeys[s - 1].height) for s, j, a in b.plane_weights()]
    k = np.array([p.stiffness for _, p, _ in planes])
    weights = np.array([a for a, _, _ in planes])
    yielding = np.array([p.hysteresis is not None for _, p, _ in planes])
    uy = np.array([p.hysteresis.yield_force_for(p.stiffness, h) / p.stiffness if p.hysteresis else np.inf
                   for _, p, h in planes])
    alpha = np.array([p.hysteresis.post_yield_ratio if p.hysteresis else 1.0 for _, p, _ in planes])
    step = 0.01
    time = np.arange(int(round(duration / step)) + 1) * step
    ax, ay = ground_on_grid(model, time)
    mode = np.zeros(len(planes), dtype=int)
    nq = m.shape[0]

    def rhs(t, y):
        q, v, plastic = y[:nq], y[nq:2 * nq], y[2 * nq:]
        drift, rate = weights @ q, weights @ v
        force = alpha * k * drift + (1 - alpha) * k * (drift - plastic)
        gx, gy = np.interp(t, time, ax), np.interp(t, time, ay)
        acc = minv @ (-(c @ v) - weights.T @ force - m @ np.array([gx, gy, 0.0]))
        return np.r_[v, acc, np.where(mode != 0, rate, 0.0)]

    def events():
        out = []
        for p in np.flatnonzero(yielding):
            if mode[p] == 0:
                for sign in (1.0, -1.0):
                    def onset(t, y, p=p, sign=sign):
                        return weights[p] @ y[:nq] - y[2 * nq + p] - sign * uy[p]
                    onset.terminal = True
                    onset.direction = sign
                    out.append((onset, p, int(sign)))
            else:
                def unload(t, y, p=p):
                    return weights[p] @ y[nq:2 * nq]
                unload.terminal = True
                unload.direction = -mode[p]
                out.append((unload, p, 0))
        return out

    y = np.zeros(2 * nq + len(planes))
    states = [y[:nq].copy()]
    for i in range(time.size - 1):
        t0, t1 = time[i], time[i + 1]
        while t0 < t1:
            found = events()
            sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-15,
                            events=[e for e, _, _ in found])
            y = sol.y[:, -1].copy()
            t0 = sol.t[-1]
            if sol.status == 1:
                hit = [i for i, te in enumerate(sol.t_events) if te.size]
                for index in hit:
                    _, p, kind = found[index]
                    if kind != 0:
                        y[2 * nq + p] = weights[p] @ y[:nq] - kind * uy[p]
                        mode[p] = kind
                    else:
                        mode[p] = 0
        states.append(y[:nq].copy())
    return time, np.array(states)


def test_yielding_eccentric_storey_matches_scipy_with_every_switch_an_event(tmp_path):
    """Bilinear planes on an eccentric storey under two components: the solver against solve_ivp."""
    model = _eccentric(tmp_path)
    ds = simulate(model, duration=1.5)
    time, ref = _reference(model, 1.5)
    assert float(ds.energy_hysteretic[-1]) > 0.05 * float(ds.energy_input.max())  # the planes yielded
    got = np.c_[ds.displacement.values[:, 0, :], ds.rotation.values[:, 0]]
    assert np.allclose(ds.time.values, time)
    peak = np.abs(ref).max(axis=0)
    assert np.all(np.abs(got - ref).max(axis=0) <= 1e-6 * peak)
    assert ds.attrs["energy_closure"] < 1e-6


def _planar_pair(record: str, hyst: str) -> str:
    return ("name: p\nbuildings:\n"
            f"  - {{name: A, storeys: {{count: 3, mass: 2.5e5, stiffness: 3.5e8, height: 3.2, {hyst}}}, "
            "damping: {ratio: 0.05, modes: [1, 3]}}\n"
            "  - {name: B, storeys: {count: 2, mass: 2.0e5, stiffness: 4.5e8, height: 3.2}, "
            "damping: {ratio: 0.05, modes: [1, 2]}}\n"
            "contacts:\n  - {between: [A, B], levels: matching, gap: 0.004, law: hertz-damp, kh: 1.0e10, "
            "restitution: 0.65}\n"
            f"ground_motion: {{record: {record}, scale: 2.0, duration: 3.0}}\n" + SOLVER)


@pytest.mark.parametrize("hyst", [_bilinear(0.002, 0.05),
                                  "hysteresis: {model: bouc-wen, yield_drift_ratio: 0.002, post_yield_ratio: 0.05}"])
def test_symmetric_plan_with_yielding_planes_reproduces_the_planar_inelastic_model(tmp_path, hyst):
    """Issue 26 §1 acceptance with yielding storeys: each x plane half the storey (stiffness and yield force)."""
    record = _record(tmp_path)
    a = simulate(model_from_text(_planar_pair(record, hyst), name="p"))
    b = simulate(model_from_text(_plan_pair(record, hyst), name="q"))
    assert float(a.energy_hysteretic[-1]) > 0.0 and int(a.impact_contact.size) > 0
    assert np.allclose(b.peak_displacement.values[:, 0], a.peak_displacement.values, rtol=1e-8, atol=0.0)
    assert np.all(b.peak_rotation.values == 0.0)
    # A's storey 1 is its two x planes: each carries half the storey shear; the plan's energies are the planar ones
    x1 = [0, 1]
    shear = b.plane_shear.values[:, x1].sum(axis=1)
    scale = float(np.abs(a.storey_shear[:, 0]).max())
    assert np.allclose(shear, a.storey_shear.values[:, 0], rtol=0, atol=1e-7 * scale)
    assert np.isclose(float(b.energy_hysteretic[-1]), float(a.energy_hysteretic[-1]), rtol=1e-6)
    assert b.attrs["energy_closure"] < 1e-6


def test_stop_drift_ratio_ends_the_run_at_the_first_plane_past_it(tmp_path):
    model = _eccentric(tmp_path, SOLVER.replace("output_dt", "stop_drift_ratio: 0.004, output_dt"))
    ds = simulate(model)
    assert ds.attrs["status"] == "collapsed"
    assert ds.attrs["collapse_building"] == "A" and ds.attrs["collapse_storey"] == "A:1"
    assert ds.attrs["collapse_cause"] == "drift_ratio"
    p = ds.attrs["collapse_plane"]
    ratio = ds.peak_plane_drift.values / 3.0
    assert np.isclose(ratio[p], 0.004, rtol=1e-9)
    assert np.all(np.delete(ratio, p) < 0.004)
    assert f"plane {p}" in ds.attrs["status_message"] and "building A collapsed" in ds.attrs["status_message"]
    assert float(ds.time[-1]) <= ds.attrs["collapse_time"] < 2.0


def test_a_building_collapse_drift_ratio_applies_to_its_own_planes(tmp_path):
    text = (ECCENTRIC.replace("REC", _record(tmp_path)).replace(", HYST", "")
            .replace("    damping: {ratio: 0.05, modes: [1, 3]}\n",
                     "    damping: {ratio: 0.05, modes: [1, 3]}\n    collapse: {drift_ratio: 0.5}\n")) + SOLVER
    ds = simulate(model_from_text(text, name="e"))
    assert ds.attrs["status"] == "completed"
    tight = text.replace("drift_ratio: 0.5", "drift_ratio: 0.002")
    ds = simulate(model_from_text(tight, name="e"))
    assert ds.attrs["status"] == "collapsed" and ds.attrs["collapse_building"] == "A"
    assert np.isclose(float(ds.peak_plane_drift.max()) / 3.0, 0.002, rtol=1e-9)


def test_energy_closes_with_yielding_planes_and_impacts(tmp_path):
    """Two components at 20° on the yielding pair, A's storeys eccentric (CM off the centre): twist, impacts."""
    text = (_plan_pair(_record(tmp_path), _bilinear(0.002, 0.05)).replace("duration: 3.0}", "angle: 20, duration: 3.0}")
            .replace("{mass: 250000.0, height: 3.2,", "{mass: 250000.0, height: 3.2, centre_of_mass: [9, 4],"))
    ds = simulate(model_from_text(text, name="q"))
    assert int(ds.impact_count.sum()) > 0 and float(ds.energy_hysteretic[-1]) > 0.0
    assert np.abs(ds.peak_rotation.values).max() > 0.0
    assert ds.attrs["energy_closure"] < 1e-5
