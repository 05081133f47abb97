"""The study engine on its own: a static and an adaptive task source, parts, resume (no simulation).

The runner is a toy (it squares a number), so these tests exercise only what the engine owns:
which scenarios run, what is stored, what a resumed study reuses and what it reports.
"""

from __future__ import annotations

import hashlib
from typing import Any

import numpy as np
import xarray as xr

from pounding.studies.engine.execution import run_study
from pounding.studies.engine.keys import PARTS_FORMAT
from pounding.studies.engine.store import parts_dir
from pounding.studies.engine.tasks import Scenario, StaticTasks, TaskSource

STUDY = "toy-1"


def square(task: dict[str, Any]) -> dict[str, Any]:
    """The toy runner: the square of the scenario's number."""
    x = task["data"]["x"]
    return {"key": task["key"], "status": "ok", "format": PARTS_FORMAT, "study": STUDY, "value": [x * x],
            "wall_time": 0.0}


def toy(x: int, code: str = "v1") -> Scenario:
    """The scenario of number *x*; *code* stands for the code fingerprint in its key."""
    identity = hashlib.sha256(f"x={x}".encode()).hexdigest()
    key = hashlib.sha256(f"{identity}|{code}".encode()).hexdigest()
    return Scenario((x,), {"x": x}, f"x: {x}\n", None, key, None, {"x": x}, identity)


def dataset(scenarios: list[Scenario], results: dict[str, dict[str, Any]]) -> xr.Dataset:
    values = [results[s.key]["value"][0] if results.get(s.key, {}).get("status") == "ok" else -1
              for s in scenarios]
    return xr.Dataset({"value": ("x", np.array(values, dtype=np.int64))},
                      coords={"x": [s.coords["x"] for s in scenarios]})


class Doubling(TaskSource):
    """Adaptive: from 1, each result hands the engine the next power of two, up to *top*."""

    name, label, unit, task_seconds = "doubling", "<doubling>", "run", 0.0

    def __init__(self, top: int, code: str = "v1"):
        self.top, self.code = top, code
        self.runner, self.inputs = square, []
        self.ran: list[Scenario] = []

    def _from(self, x: int, known) -> list[Scenario]:
        while x <= self.top:
            scenario = toy(x, self.code)
            self.ran.append(scenario)
            if known(scenario) is None:
                return [scenario]
            x *= 2
        return []

    def first(self, known) -> list[Scenario]:
        return self._from(1, known)

    def follow(self, scenario, result, known) -> list[Scenario]:
        return self._from(2 * scenario.coords["x"], known)

    def assemble(self, results, *, elapsed, ran, lost):
        return dataset(self.ran, results)


def test_a_static_list_runs_once_and_resumes_from_its_parts(in_process_client, tmp_path):
    out = tmp_path / "static.nc"
    scenarios = [toy(x) for x in range(5)]

    def source(listed):
        return StaticTasks(lambda: listed, lambda results, **_: dataset(listed, results), name="static",
                           label="<static>", model_name="toy", runner=square, inputs=[])

    first = run_study(source(scenarios), out, client=in_process_client, progress=False, keep_parts=True)
    assert first.value.values.tolist() == [0, 1, 4, 9, 16] and first.attrs["n_stale"] == 0
    assert len(list(parts_dir(out).glob("*.json"))) == 5
    notes: list[str] = []
    again = run_study(source(scenarios), out, client=in_process_client, progress=False, overwrite=True, log=notes.append)
    assert again.value.values.tolist() == [0, 1, 4, 9, 16]
    assert notes == [f"5 of 5 scenarios already done (in {parts_dir(out)}); running the other 0"]
    assert not parts_dir(out).exists()          # removed once the file is written


def test_an_adaptive_source_gets_its_next_scenarios_from_each_result_and_replays_on_resume(in_process_client, tmp_path):
    out = tmp_path / "adaptive.nc"
    first = run_study(Doubling(16), out, client=in_process_client, progress=False, keep_parts=True)
    assert first.value.values.tolist() == [1, 4, 16, 64, 256]
    assert first.attrs["n_stale"] == 0 and first.attrs["n_invalid_parts"] == 0
    notes: list[str] = []
    longer = run_study(Doubling(64), out, client=in_process_client, progress=False, overwrite=True, keep_parts=True,
                       log=notes.append)
    assert longer.value.values.tolist() == [1, 4, 16, 64, 256, 1024, 4096]
    assert notes == [f"5 runs already done (in {parts_dir(out)}); the study goes on from there"]
    # Parts of other code: one line, and every scenario runs again.
    notes.clear()
    other = run_study(Doubling(64, code="v2"), out, client=in_process_client, progress=False, overwrite=True,
                      log=notes.append)
    assert other.value.values.tolist() == longer.value.values.tolist()
    assert other.attrs["n_stale"] == 1          # the first run of the chain, found before anything ran
    assert len(notes) == 1 and "no longer match their inputs" in notes[0]
