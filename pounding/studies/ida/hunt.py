"""Hunt-and-fill: the next level of a record's IDA from its runs so far, and the hunt on Dask futures."""

from __future__ import annotations

import os
import sys
import time
from typing import Any, Callable

import numpy as np

from pounding.studies.ida.dataset import assemble_ida_dataset
from pounding.studies.ida.plan import Hunt, IdaPlan
from pounding.studies.ida.runs import IDA_PART, collapsed_in, run_ida_scenario

__all__ = ["next_hunt_level", "run_hunt"]

# --------------------------------------------------------------------------- #
# Hunt-and-fill (sequential per record; records in parallel on dask futures)
# --------------------------------------------------------------------------- #


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
        return round(hunt.start, 6)
    collapses = [s for s, c in runs if c]
    if not collapses:                                    # hunt up
        last = runs[-1][0]
        if last >= hunt.ceiling:
            return None
        k = len(runs) - 1
        return round(min(last + hunt.step + k * hunt.increment, hunt.ceiling), 6)
    high = min(collapses)
    low = max([s for s, c in runs if not c and s < high], default=0.0)
    if high - low > hunt.tolerance * (1 + 1e-9):         # bracket
        middle = round(0.5 * (low + high), 6)
        return middle if low < middle < high else None
    if len(runs) >= hunt.runs:                           # fill
        return None
    points = sorted({0.0} | {s for s, c in runs if not c and s < high})
    gaps = np.diff(points)
    if gaps.size == 0 or gaps.max() <= hunt.tolerance:
        return None
    i = int(np.argmax(gaps))
    return round(0.5 * (points[i] + points[i + 1]), 6)


def run_hunt(plan: IdaPlan, output: str | os.PathLike | None = None, *, workers: int | None = None,
             scheduler: str | None = None, client: Any = None, overwrite: bool = False, keep_parts: bool = False,
             progress: bool = True, retries: int = 2, log: Callable[[str], None] | None = None):
    """Hunt-and-fill on Dask futures: each (variant, record) is a chain of runs, the chains run side by side.

    One future per run: when a run finishes, its part is stored (as in
    :func:`pounding.studies.sweep.execution.run_sweep`: ``OUTPUT.parts/``,
    one atomic JSON file per run) and the chain's next level is submitted at
    once, so a worker is never idle while any chain has work.  A resumed
    study replays every chain through :func:`next_hunt_level` and finds the
    runs already done in the store; only the missing ones run.
    """
    from pounding.results.archive import check_writable, save_run
    from pounding.studies.sweep.execution import check_scheduler_address, sweep_inputs
    from pounding.studies.sweep.store import load_parts, parts_dir, prepare_store, sweep_lock

    say = log or (lambda line: print(line, file=sys.stderr))
    if scheduler and client is None:
        check_scheduler_address(scheduler)
    target = check_writable(output, overwrite=overwrite, inputs=sweep_inputs(plan.sweep)) \
        if output is not None else None
    if target is None:
        return _hunt_locked(plan, None, None, {}, say, workers=workers, scheduler=scheduler, client=client,
                            progress=progress, retries=retries)
    with sweep_lock(target):
        store = prepare_store(parts_dir(target))
        bad: list[str] = []
        done = load_parts(store, bad=bad)
        for message in bad[:5]:
            say(f"pounding: warning: invalid part {message}; its run runs again")
        ds = _hunt_locked(plan, target, store, done, say, workers=workers, scheduler=scheduler, client=client,
                          progress=progress, retries=retries)
        save_run(ds, target, overwrite=overwrite)
        if not keep_parts and not ds.attrs.get("n_lost", 0):
            import shutil

            shutil.rmtree(store, ignore_errors=True)
    return ds


def _hunt_locked(plan: IdaPlan, target, store, done, say, *, workers, scheduler, client, progress, retries):
    import uuid

    from pounding.studies.sweep.execution import Chunk, run_chunk, start_client
    from pounding.studies.sweep.scenario import one_line
    from pounding.studies.sweep.spec import PARTS_FORMAT
    from pounding.studies.sweep.store import save_part

    hunt = plan.hunt
    chains = [(v, r) for v in plan.variants for r in range(len(plan.records))]
    runs: dict[tuple[str, int], list[tuple[float, Any]]] = {c: [] for c in chains}   # (level, scenario)
    results: dict[str, dict[str, Any]] = {}
    lost: set[str] = set()
    reused = 0

    def history(chain) -> list[tuple[float, bool]] | None:
        out = []
        for level, scenario in runs[chain]:
            collapsed = collapsed_in(results.get(scenario.key), plan, plan.im.building)
            if collapsed is None:
                return None          # a failed run ends its chain
            out.append((level, collapsed))
        return out

    def advance(chain):
        """The chain's next scenario to run, after replaying the finished ones; None when the chain is done."""
        nonlocal reused
        while True:
            past = history(chain)
            if past is None:
                return None
            level = next_hunt_level(hunt, past)
            if level is None:
                return None
            scenario = plan.scenario(chain[0], chain[1], level)
            runs[chain].append((level, scenario))
            if scenario.error is not None:
                results[scenario.key] = {"key": scenario.key, "status": "error", "error": scenario.error,
                                         "format": PARTS_FORMAT, "study": IDA_PART, "wall_time": 0.0}
                return None
            if scenario.key in done:
                results[scenario.key] = done[scenario.key]
                reused += 1
                continue
            return scenario

    started = time.perf_counter()
    first = [(c, advance(c)) for c in chains]
    first = [(c, s) for c, s in first if s is not None]
    if reused:
        say(f"{reused} runs already done (in {store}); the hunt goes on from there")
    ran = 0
    if first:
        from dask.distributed import as_completed
        from tqdm import tqdm

        own = client is None
        cluster = None
        if own:
            client, cluster = start_client(workers=workers, scheduler=scheduler)
        flying: dict[str, tuple[tuple[str, int], Any]] = {}
        completed = as_completed(loop=client.loop)

        def submit(chain, scenario):
            task = scenario.task(sweep_label=plan.sweep.label, name=plan.model_name)
            key = f"pounding-ida-{scenario.key[:16]}-{uuid.uuid4().hex[:8]}"
            # one run as a Chunk, as the stripes send theirs: Dask does not walk its model document
            future = client.submit(run_chunk, run_ida_scenario, Chunk([task]), key=key, retries=retries, pure=False)
            flying[future.key] = (chain, scenario)
            completed.add(future)

        estimate = len(chains) * hunt.runs
        bar = tqdm(total=estimate, initial=reused, unit="run", desc=plan.sweep.name, file=sys.stderr,
                   disable=not progress, dynamic_ncols=True, smoothing=0.1)
        try:
            for chain, scenario in first:
                submit(chain, scenario)
            for future in completed:
                chain, scenario = flying.pop(future.key)
                try:
                    result = future.result()[0]
                except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after the retries
                    result = {"key": scenario.key, "status": "error", "format": PARTS_FORMAT, "study": IDA_PART,
                              "wall_time": float("nan"),
                              "error": f"{plan.sweep.label}: scenario {scenario.label}: {one_line(exc)}"}
                    lost.add(scenario.key)
                finally:
                    future.release()
                if store is not None and scenario.key not in lost:
                    result["identity"] = scenario.identity
                    save_part(store, result)
                results[scenario.key] = result
                ran += 1
                if bar.n + 1 > bar.total:
                    bar.total = bar.n + 1 + len(flying)
                bar.update(1)
                nxt = advance(chain)
                if nxt is not None:
                    submit(chain, nxt)
        except BaseException:
            for future in list(completed.futures):
                future.cancel()
            raise
        finally:
            bar.close()
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    elapsed = time.perf_counter() - started
    entries = [(chain[0], chain[1], level, scenario.key) for chain in chains for level, scenario in runs[chain]]
    ds = assemble_ida_dataset(plan, results, entries, elapsed=elapsed, ran=ran)
    ds.attrs["n_lost"] = len(lost)
    if lost:
        say(f"{len(lost)} runs could not run (their workers died); the others are kept in {store}: rerun the "
            "same command with --overwrite to retry just those")
    return ds
