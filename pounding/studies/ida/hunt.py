"""Hunt-and-fill: the next level of a record's IDA from its runs so far, as an adaptive task source.

Each (variant, record) is a chain of runs; :class:`HuntTasks` hands the study
engine (:func:`pounding.studies.engine.execution.run_study`) the first run of
every chain, and the chain's next level as soon as a run finishes, so the
chains run side by side and a worker is never idle while any chain has work.

A chain hunts each building's collapse in turn (model order), from the runs
in which that building was observed: a run that another building's collapse
ended censors it (its outcome there is unknown), and its hunt goes no higher
than the lowest level where that happened (docs/ida.md "Collapse of each
building").  One building: the hunt of Vamvatsikos & Cornell, as before.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from pounding.studies.engine.tasks import Scenario, TaskSource
from pounding.studies.ida.dataset import assemble_ida_dataset
from pounding.studies.ida.schedule import LEVEL_DECIMALS, Hunt, IdaPlan
from pounding.studies.ida.runs import run_collapses, run_ida_scenario

__all__ = ["next_hunt_level", "HuntTasks", "run_hunt"]


def next_hunt_level(hunt: Hunt, runs: list[tuple[float, bool]]) -> float | None:
    """The next level (g) of one record's hunt-and-fill, or None when it is done.

    Parameters
    ----------
    hunt : Hunt
    runs : list of (level in g, collapsed)
        The record's runs so far, in the order they ran.

    The answer depends on *runs* alone, so a resumed study replays the same
    sequence and finds the finished runs in its parts store.
    """
    if not runs:
        return round(hunt.start, LEVEL_DECIMALS)
    collapses = [s for s, c in runs if c]
    if not collapses:                                    # hunt up
        last = runs[-1][0]
        if last >= hunt.ceiling:
            return None
        k = len(runs) - 1
        level = round(min(last + hunt.step + k * hunt.increment, hunt.ceiling), LEVEL_DECIMALS)
        return level if level > last else None           # never the same level again (rounding)
    high = min(collapses)
    low = max([s for s, c in runs if not c and s < high], default=0.0)
    if high - low > hunt.tolerance * (1 + 1e-9):         # bracket
        middle = round(0.5 * (low + high), LEVEL_DECIMALS)
        return middle if low < middle < high else None
    if len(runs) >= hunt.runs:                           # fill
        return None
    points = sorted({0.0} | {s for s, c in runs if not c and s < high})
    gaps = np.diff(points)
    if gaps.size == 0 or gaps.max() <= hunt.tolerance:
        return None
    i = int(np.argmax(gaps))
    middle = round(0.5 * (points[i] + points[i + 1]), LEVEL_DECIMALS)
    return middle if points[i] < middle < points[i + 1] else None


class HuntTasks(TaskSource):
    """The adaptive task source of a hunt-and-fill IDA: one chain of runs per (variant, record).

    A chain's next level depends on its past runs alone (:func:`next_hunt_level`), so a resumed
    study replays every chain, finds the runs already done in the parts store and runs only the
    missing ones.  A failed run ends its chain.
    """

    unit = "run"
    task_seconds = 0.0   # one run per Dask task: a chain waits for its run, not for a batch

    def __init__(self, plan: IdaPlan):
        from pounding.studies.sweep.execution import sweep_inputs

        self.plan = plan
        self.name, self.label, self.model_name = plan.sweep.name, plan.sweep.label, plan.model_name
        self.runner = run_ida_scenario
        self.inputs = sweep_inputs(plan.sweep)
        self.chains = [(v, r) for v in plan.variants for r in range(len(plan.records))]
        self.runs: dict[tuple[str, int], list[tuple[float, Scenario]]] = {c: [] for c in self.chains}
        self.results: dict[str, dict[str, Any]] = {}
        self.chain_of: dict[str, tuple[str, int]] = {}

    def _histories(self, chain: tuple[str, int]) -> tuple[list[list[tuple[float, bool]]], list[float]] | None:
        """Per building: its (level, collapsed) in the chain's runs that observed it, and the lowest level
        at which another building's collapse censored it (inf: none); None once a run of it failed."""
        observed: list[list[tuple[float, bool]]] = [[] for _ in self.plan.buildings]
        censored_at = [np.inf] * len(self.plan.buildings)
        for level, scenario in self.runs[chain]:
            found = run_collapses(self.results.get(scenario.key), self.plan)
            if found is None:
                return None
            for b, (collapsed, censored) in enumerate(zip(*found)):
                if censored:
                    censored_at[b] = min(censored_at[b], level)
                else:
                    observed[b].append((level, bool(collapsed)))
        return observed, censored_at

    def _next_level(self, chain: tuple[str, int]) -> float | None:
        """The chain's next level: the first building (of ``plan.hunted``, default all) whose hunt
        (:func:`next_hunt_level` on the runs that observed it) asks for a level below its censoring and not
        yet run; None when every hunt is done."""
        found = self._histories(chain)
        if found is None:
            return None
        ran = {level for level, _ in self.runs[chain]}
        hunted = self.plan.hunted or self.plan.buildings
        for name, history, ceiling in zip(self.plan.buildings, *found):
            if name not in hunted:
                continue
            level = next_hunt_level(self.plan.hunt, history)
            if level is not None and level < ceiling and level not in ran:
                return level
        return None

    def _advance(self, chain: tuple[str, int], known) -> list[Scenario]:
        """The chain's next scenario to run, after replaying the finished ones; [] when the chain is done."""
        while True:
            level = self._next_level(chain)
            if level is None:
                return []
            scenario = self.plan.scenario(chain[0], chain[1], level)
            self.runs[chain].append((level, scenario))
            self.chain_of[scenario.key] = chain
            result = known(scenario)
            if result is None:
                return [scenario]
            self.results[scenario.key] = result

    def first(self, known) -> list[Scenario]:
        return [s for chain in self.chains for s in self._advance(chain, known)]

    def follow(self, scenario: Scenario, result: dict[str, Any], known) -> list[Scenario]:
        self.results[scenario.key] = result
        return self._advance(self.chain_of[scenario.key], known)

    def estimate(self) -> int:
        return len(self.chains) * self.plan.hunt.runs

    def resumed(self, reused: int, stored: set[str], store: Any, todo: list[Scenario]) -> str | None:
        return f"{reused} runs already done (in {store}); the hunt goes on from there" if reused else None

    def assemble(self, results: dict[str, dict[str, Any]], *, elapsed: float, ran: int, lost: int):
        entries = [(chain[0], chain[1], level, scenario.key) for chain in self.chains
                   for level, scenario in self.runs[chain]]
        ds = assemble_ida_dataset(self.plan, results, entries, elapsed=elapsed, ran=ran)
        ds.attrs["n_lost"] = lost
        if self.plan.hunted:   # only these buildings' collapses are bracketed (the others' fragilities: as seen)
            ds.attrs["hunted_buildings"] = ",".join(self.plan.hunted)
        return ds


def run_hunt(plan: IdaPlan, output: str | os.PathLike | None = None, **run_options):
    """Hunt-and-fill on the study engine; returns the IDA dataset.

    Every run is stored as it finishes (``OUTPUT.parts/``, one atomic JSON
    file per run, as every study's); a resumed study replays every chain
    through :func:`next_hunt_level` and runs only the missing runs.
    *run_options* go to :func:`pounding.studies.engine.execution.run_study`
    (workers, scheduler, client, overwrite, keep_parts, progress, retries, log).
    """
    from pounding.studies.engine.execution import run_study

    return run_study(HuntTasks(plan), output, **run_options)
