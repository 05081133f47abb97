"""The benchmarks write outside the checkout unless asked (issue 13 §4): ``--out DIR``, ``--update-docs``.

Only their command lines are checked here (``--help``, a few seconds); nothing
is timed by the test suite.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
SCRIPTS = sorted(p for p in BENCHMARKS.glob("*.py") if not p.name.startswith("_"))
#: The documentation files each benchmark may rewrite, with --update-docs only.
OWNS = {"scaling.py": ["docs/scaling.png"], "vs_opensees.py": [], "sweep_scaling.py": [], "configurations.py": [],
        "ida_throughput.py": [], "startup.py": [], "solver_regression.py": [], "p695_full.py": [],
        "collapse_ida.py": [], "plan_speed.py": [], "time_split.py": [],
        "worker_share.py": [], "open_phase_bound.py": [], "contact_phase_order.py": []}


def _output_module():
    spec = importlib.util.spec_from_file_location("bench_output", BENCHMARKS / "_output.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_script_is_listed():
    assert sorted(p.name for p in SCRIPTS) == sorted(OWNS)


def test_default_output_folder_is_outside_the_checkout(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    output = _output_module()
    for script in OWNS:
        folder = output.default_out(Path(script).stem).resolve()
        assert ROOT not in folder.parents and folder != ROOT


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_help_offers_out_and_update_docs_only_where_docs_are_owned(script):
    env = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="200")
    done = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "--out DIR" in done.stdout
    owns = OWNS[script.name]
    assert ("--update-docs" in done.stdout) == bool(owns)
    for path in owns:
        assert path in done.stdout


def _scaling(tmp_path: Path, *options: str) -> subprocess.CompletedProcess:
    """``benchmarks/scaling.py`` in its smallest form: 2 x 3 storeys, 1 s, one run, no figure, no memory run."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    command = [sys.executable, str(BENCHMARKS / "scaling.py"), "--storeys", "3", "--durations", "1", "--repeat", "1",
               "--no-plot", "--no-memory", "--out", str(tmp_path), *options]
    return subprocess.run(command, capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)


def test_scaling_before_and_after_with_the_same_solver_take_the_same_steps(tmp_path):
    """Two sides that differ only in a setting that does not change the step (a coarser output_dt):
    the same steps and impacts on both, and a ratio after / before of the solver's CPU times at every point."""
    import json

    done = _scaling(tmp_path, "--before-settings", "output_dt=0.01", "--settings", "output_dt=0.02", "--clock", "cpu")
    assert done.returncode == 0, done.stderr
    found = json.loads((tmp_path / "scaling.json").read_text())
    assert set(found["sides"]) == {"before", "after"}
    assert "output_dt=0.02" in found["sides"]["after"]
    for point in found["storeys"] + found["durations"]:
        before, after = point["sides"]["before"], point["sides"]["after"]
        assert (before["steps"], before["impacts"]) == (after["steps"], after["impacts"])
        assert min(before["times"] + after["times"]) > 0 and point["after_over_before"] > 0


@pytest.mark.parametrize("options, says", [
    (["--settings", "no_such_setting=1"], "--settings no_such_setting=1: 2 x 5 pair:"),
    (["--before-settings", "rtol=abc"], "--before-settings rtol=abc: 2 x 5 pair:"),
    (["--settings", "rtol"], "expected KEY=VALUE"),
    (["--storeys", "2"], "--storeys >= 3"),
    (["--before", "no-such-commit"], "--before no-such-commit: neither a commit"),
])
def test_scaling_refuses_a_bad_side_in_one_line(tmp_path, options, says):
    done = _scaling(tmp_path, *options)
    assert done.returncode != 0
    assert says in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 or "usage:" in done.stderr
