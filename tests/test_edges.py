"""Regression tests of issue 25 §2–§4 (third adversarial audit): one test per item, each failing before its fix.

Cases that would take hours or allocate hundreds of GiB are run in a
subprocess under ``RLIMIT_AS`` and a time limit (:func:`tests.test_fuzz.pounding`)
and must be refused before any run starts.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr

from pounding.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_fuzz import _write_case, base_model, pounding, verdict  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """A small model (5 floors, 1.5 s text record) and its archive."""
    folder = tmp_path_factory.mktemp("edges")
    path = _write_case(folder, base_model())
    assert main(["run", str(path), "-o", str(folder / "run.nc")]) == 0
    return folder


def _error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pounding: error: "), err
    return err[0]


# --------------------------------------------------------------------------- #
# §4 Data loss: two runs onto one output
# --------------------------------------------------------------------------- #


def test_a_file_written_meanwhile_is_not_replaced(case, tmp_path, capsys, monkeypatch):
    # Before: `run -o same.nc` replaced a same.nc that another run wrote while this one computed.
    import pounding.simulation as simulation

    target = tmp_path / "same.nc"
    real = simulation.simulate

    def simulate_while_another_writes(*args, **kwargs):
        ds = real(*args, **kwargs)
        target.write_bytes(b"the other run's archive")
        return ds

    monkeypatch.setattr(simulation, "simulate", simulate_while_another_writes)
    assert main(["run", str(case / "model.yaml"), "-o", str(target)]) == 2
    line = _error(capsys)
    assert "was written by another process" in line and f"same.{os.getpid()}.nc" in line
    assert target.read_bytes() == b"the other run's archive"
    kept = tmp_path / f"same.{os.getpid()}.nc"
    assert xr.open_dataset(kept).attrs["model_name"] == "fuzz"   # nothing computed is lost
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["same.nc", kept.name])


def test_a_live_writer_of_the_same_output_is_refused_before_running(case, tmp_path):
    # Before: the second run computed and silently replaced the first one's archive.
    target = tmp_path / "same.nc"
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from pounding.results.archive import output_lock\n"
         f"with output_lock({str(target)!r}):\n    print('held', flush=True); time.sleep(60)"],
        stdout=subprocess.PIPE, text=True, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    try:
        assert holder.stdout.readline().strip() == "held"
        started = time.perf_counter()
        status, out, err = pounding(["run", str(case / "model.yaml"), "-o", str(target)], tmp_path)
        assert status == 2 and verdict(status, out, err, None) is None, err
        assert f"is being written by another pounding run (pid {holder.pid} on" in err
        assert "wrote" not in out and not target.exists()
        assert time.perf_counter() - started < 30
    finally:
        holder.kill()   # a killed holder leaves no claim: the next run proceeds
        holder.wait()
    status, out, err = pounding(["run", str(case / "model.yaml"), "-o", str(target)], tmp_path)
    assert status == 0 and f"wrote {target}" in out, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["same.nc"]


def test_two_runs_started_together(case, tmp_path):
    # Before: both said "wrote same.nc" and one archive silently replaced the other.
    target = tmp_path / "same.nc"
    environ = dict(os.environ, PYTHONPATH=str(ROOT))
    runs = [subprocess.Popen([sys.executable, "-m", "pounding", "run", str(case / "model.yaml"), "-o", str(target)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=environ)
            for _ in range(2)]
    outcomes = [(run.wait(timeout=120), run.stdout.read(), run.stderr.read()) for run in runs]
    assert sorted(status for status, _, _ in outcomes) == [0, 2], outcomes
    assert sum(f"wrote {target}" in out for _, out, _ in outcomes) == 1
    assert all(verdict(*outcome, None) is None for outcome in outcomes)
    assert [p.name for p in tmp_path.iterdir()] == ["same.nc"]


def test_overwrite_still_replaces(case, tmp_path):
    target = tmp_path / "same.nc"
    target.write_bytes(b"old")
    assert main(["run", str(case / "model.yaml"), "-o", str(target), "--overwrite"]) == 0
    assert xr.open_dataset(target).attrs["model_name"] == "fuzz"
