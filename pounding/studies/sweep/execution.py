"""Running a sweep on a Dask cluster: LocalCluster or an existing scheduler, batching, retries, progress."""

from __future__ import annotations

import math
import os
import re
import shutil
import sys
import time
from pathlib import Path
from typing import Any, Callable

from pounding.errors import PoundingError
from pounding.studies.sweep.dataset import build_dataset
from pounding.studies.sweep.scenario import one_line, run_scenario
from pounding.studies.sweep.spec import PARTS_FORMAT, Scenario, Sweep
from pounding.studies.sweep.store import (history_name, load_parts, parts_dir, prepare_store, save_parts,
                                          sweep_lock)

__all__ = ["default_workers", "start_client", "run_sweep", "run_chunk", "failures", "failure_report",
           "check_scheduler_address", "sweep_inputs"]


def failures(ds) -> dict[str, list[str]]:
    """The distinct errors of a sweep results dataset, each with the scenarios it hit.

    Returns
    -------
    dict
        Error message (without the ``<sweep>: scenario <label>:`` prefix) →
        scenario labels (``xi=ye, record=fema-p695:farfield/1a``), in
        scenario order.
    """
    import re

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


_ADDRESS = re.compile(r"^(?:(?:tcp|tls|inproc|ucx|ws|wss)://)?[A-Za-z0-9_.\-\[\]:]+:\d{1,5}/?$")


def check_scheduler_address(address: str) -> str:
    """*address* if it looks like a Dask scheduler address (``tcp://host:8786``), else a one-line error."""
    text = str(address).strip()
    if not _ADDRESS.match(text):
        raise PoundingError(f"--scheduler {address!r} is not a scheduler address; write tcp://HOST:PORT, e.g. "
                            "tcp://127.0.0.1:8786 (printed by `dask scheduler`)")
    return text


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

# --------------------------------------------------------------------------- #
# Running on Dask
# --------------------------------------------------------------------------- #


def default_workers() -> int:
    """One worker per usable core."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:   # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


#: Dask settings of the LocalCluster :func:`start_client` starts (a cluster reached with a scheduler
#: address keeps its own).  Dask's defaults sample every worker's stack every 10 ms (its statistical
#: profiler) and tick every event loop every 20 ms: on a 2-core machine each idle worker process
#: and the scheduler each took ~8 % of a core, time the runs wait for; with these, 1.5-3 %.
#: The profiler only feeds the dashboard's profile page; the tick only warns of a blocked loop.
LOCAL_CLUSTER_CONFIG = {"distributed.worker.profile.enabled": False,
                        "distributed.admin.tick.interval": "1s",
                        "distributed.admin.system-monitor.interval": "2s"}


def start_client(*, workers: int | None = None, scheduler: str | None = None):
    """A dask Client: on an existing scheduler, else on a new LocalCluster (:data:`LOCAL_CLUSTER_CONFIG`).

    Returns
    -------
    (client, cluster)
        *cluster* is None with *scheduler* (the cluster is used unchanged).
    """
    import logging

    import dask
    from dask.distributed import Client, LocalCluster

    if scheduler:
        scheduler = check_scheduler_address(scheduler)
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            raise PoundingError(f"cannot reach the Dask scheduler at {scheduler} ({one_line(exc)}); start one "
                                "with `dask scheduler` and workers with `dask worker tcp://HOST:8786`") from None
    import signal
    import threading

    n = workers or default_workers()
    # Worker processes inherit an ignored SIGINT (an ignored disposition survives exec): a Ctrl-C at the
    # terminal reaches the whole process group, and workers that took it printed their tracebacks; this
    # process alone handles it and shuts the cluster down.
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        with dask.config.set(LOCAL_CLUSTER_CONFIG):   # the workers' nannies pass it on to their processes
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                   silence_logs=logging.ERROR)
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)
    return Client(cluster), cluster


def run_sweep(sweep: Sweep, output: str | os.PathLike | None = None, *, workers: int | None = None,
              scheduler: str | None = None, client: Any = None, keep_histories: str | os.PathLike | None = None,
              overwrite: bool = False, keep_parts: bool = False, progress: bool = True,
              runner: Callable[[dict[str, Any]], dict[str, Any]] = run_scenario,
              retries: int = 2, task_seconds: float = 0.5, log: Callable[[str], None] | None = None,
              assemble: Callable[..., Any] = build_dataset):
    """Run every scenario of *sweep* and return the results dataset.

    Parameters
    ----------
    sweep : Sweep
        From :func:`load_sweep`.
    output : path-like, optional
        The NetCDF file; finished scenarios are kept in ``<output>.parts/``
        meanwhile, so an interrupted run resumes.  Without it nothing is stored.
    workers : int, optional
        LocalCluster size (default: one per core).
    scheduler : str, optional
        Address of an existing scheduler (``tcp://host:8786``); used unchanged.
    client : dask.distributed.Client, optional
        An existing client (overrides *workers* and *scheduler*).
    keep_histories : path-like, optional
        Directory for each scenario's full results archive.
    overwrite : bool
        Replace an existing *output*.
    keep_parts : bool
        Keep ``<output>.parts/`` after the final file is written.
    progress : bool
        Show a tqdm progress bar on stderr.
    runner : callable
        The function run on workers for each task (default :func:`run_scenario`).
    assemble : callable
        ``assemble(sweep, results, elapsed=, ran=)`` → the dataset that is
        returned and written (default :func:`build_dataset`); a study with its
        own runner (``pounding gap``) gives its own layout here.
    retries : int
        Retries of a task whose worker died.
    task_seconds : float
        Scenarios are grouped into Dask tasks of about this many seconds once
        their cost is known (the first tasks hold one scenario each); 0 keeps
        one scenario per task.  Each result is still stored on its own.
    log : callable, optional
        Receives one-line notes (default: print to stderr).
    """
    from pounding.results.archive import check_writable

    say = log or (lambda line: print(line, file=sys.stderr))
    if scheduler and client is None:
        check_scheduler_address(scheduler)
    inputs = sweep_inputs(sweep)
    target = check_writable(output, overwrite=overwrite, inputs=inputs) if output is not None else None
    histories = Path(keep_histories) if keep_histories is not None else None
    if histories is not None:
        if histories.exists() and not histories.is_dir():
            raise PoundingError(f"--keep-histories {histories} is a file; give a folder (it is created if missing)")
        try:
            histories.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise PoundingError(f"--keep-histories {histories}: cannot create the folder "
                                f"({exc.strerror or exc})") from None
        if not os.access(histories, os.W_OK | os.X_OK):
            raise PoundingError(f"--keep-histories {histories} is not writable; choose another folder")
    sweep.check_size()  # before expanding the scenarios
    if target is None:
        return _run_sweep_locked(sweep, None, None, histories, say, workers=workers, scheduler=scheduler,
                                 client=client, overwrite=overwrite, keep_parts=keep_parts, progress=progress,
                                 runner=runner, retries=retries, task_seconds=task_seconds, assemble=assemble)
    with sweep_lock(target):
        store = prepare_store(parts_dir(target))
        return _run_sweep_locked(sweep, target, store, histories, say, workers=workers, scheduler=scheduler,
                                 client=client, overwrite=overwrite, keep_parts=keep_parts, progress=progress,
                                 runner=runner, retries=retries, task_seconds=task_seconds, assemble=assemble)


def _run_sweep_locked(sweep: Sweep, target: Path | None, store: Path | None, histories: Path | None, say, *,
                      workers, scheduler, client, overwrite, keep_parts, progress, runner, retries, task_seconds,
                      assemble):
    """The body of :func:`run_sweep`, once the output is checked and locked."""
    from pounding.results.archive import save_run

    bad: list[str] = []
    done = load_parts(store, bad=bad) if store is not None else {}
    for message in bad[:5]:
        say(f"pounding: warning: invalid part {message}; its scenario runs again")
    if len(bad) > 5:
        say(f"pounding: warning: ... and {len(bad) - 5} more invalid parts set aside in {store}")

    scenarios = sweep.scenarios()
    results: dict[str, dict[str, Any]] = {}
    todo: list[Scenario] = []
    for scenario in scenarios:
        if scenario.key in results:
            continue
        part = done.get(scenario.key)
        history_missing = histories is not None and scenario.error is None and \
            not (histories / history_name(scenario)).exists()
        if part is not None and not history_missing:
            results[scenario.key] = part
        elif scenario.error is not None:
            results[scenario.key] = {"key": scenario.key, "status": "error", "error": scenario.error,
                                     "format": PARTS_FORMAT, "wall_time": 0.0}
        else:
            todo.append(scenario)
    unique = len({s.key for s in scenarios})
    skipped = sum(1 for k in {s.key for s in scenarios} if k in done)
    done_identities = {p.get("identity") for p in done.values()} - {None}
    stale = len({s.key for s in todo if s.identity in done_identities})
    if stale:
        say(f"{stale} finished scenarios no longer match their inputs (a record file or pounding's code changed "
            "since they ran) and are run again")
    if skipped:
        say(f"{skipped} of {unique} scenarios already done (in {store}); running the other {len(todo)}")
    transient: set[str] = set()
    started = time.perf_counter()
    if todo:
        own = client is None
        cluster = None
        if own:
            client, cluster = start_client(workers=workers, scheduler=scheduler)
        try:
            _run_on(client, sweep, todo, results, store=store, histories=histories, runner=runner,
                    retries=retries, progress=progress, initial=len(results), total=len(results) + len(todo),
                    transient=transient, task_seconds=task_seconds)
        finally:
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    elapsed = time.perf_counter() - started
    ds = assemble(sweep, results, elapsed=elapsed, ran=len(todo))
    ds.attrs["n_stale"] = int(stale)
    ds.attrs["n_invalid_parts"] = len(bad)
    if histories is not None:
        ds.attrs["histories"] = str(histories)
    if target is not None:
        save_run(ds, target, overwrite=overwrite)
        if transient:
            say(f"{len(transient)} scenarios could not run (their workers died); the others are kept in {store}: "
                "rerun the same command with --overwrite to retry just those")
        elif not keep_parts:
            shutil.rmtree(store, ignore_errors=True)
    return ds


class Chunk:
    """The scenarios of one Dask task, in a wrapper Dask ships as it is.

    Dask walks every list and mapping of a task's arguments looking for
    futures; over the model document of every scenario that was ~2 ms of
    the client's CPU per scenario, taken from the workers on a small machine.
    """

    __slots__ = ("tasks",)

    def __init__(self, tasks: list[dict[str, Any]]):
        self.tasks = tasks


def run_chunk(runner: Callable[[dict[str, Any]], dict[str, Any]],
              tasks: Chunk | list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Run a few scenarios in a row on one worker (what a Dask task does)."""
    return [runner(task) for task in (tasks.tasks if isinstance(tasks, Chunk) else tasks)]


class _Batcher:
    """How many scenarios go into the next task.

    Starts at one scenario per task; after the first results, sizes tasks to
    take about *task_seconds* on a worker (so the per-task overhead of Dask,
    a few ms, stays around 1 %), never more than *max_batch*, and splits the
    last scenarios evenly over the workers.
    """

    def __init__(self, task_seconds: float, max_batch: int):
        self.task_seconds = task_seconds
        self.max_batch = max_batch
        self.per_scenario: float | None = None

    def observe(self, results: list[dict[str, Any]]) -> None:
        times = [r.get("wall_time") for r in results]
        times = [t for t in times if isinstance(t, (int, float)) and math.isfinite(t)]
        if times:
            value = sum(times) / len(times)
            self.per_scenario = value if self.per_scenario is None else 0.5 * (self.per_scenario + value)

    def size(self, pending: int, slots: int) -> int:
        if self.per_scenario is None or self.task_seconds <= 0:
            return 1
        wanted = int(self.task_seconds / max(self.per_scenario, 1e-6))
        even = math.ceil(pending / max(1, 2 * slots))
        return max(1, min(self.max_batch, wanted, even))


def _run_on(client, sweep: Sweep, todo: list[Scenario], results: dict[str, dict[str, Any]], *, store: Path | None,
            histories: Path | None, runner, retries: int, progress: bool, initial: int, total: int,
            transient: set[str], task_seconds: float = 0.5, max_batch: int = 64) -> None:
    """Submit the scenarios as tasks (a few in flight per worker thread) and store each result as it arrives."""
    import uuid
    from collections import deque

    from dask.distributed import as_completed
    from tqdm import tqdm

    from pounding.results.archive import save_run

    pending = deque(todo)
    chunks: dict[str, list[Scenario]] = {}
    batcher = _Batcher(task_seconds, max_batch)
    completed = as_completed(loop=client.loop)
    state = {"slots": 1, "checked": -1e9}

    def slots() -> int:
        now = time.monotonic()
        if now - state["checked"] > 2.0:
            try:
                state["slots"] = max(1, sum(client.nthreads().values()))
            except Exception:  # noqa: BLE001 - keep the last known size
                pass
            state["checked"] = now
        return state["slots"]

    def submit_more() -> None:
        while pending and len(chunks) < 2 * slots() + 1:
            size = batcher.size(len(pending), slots())
            chunk = [pending.popleft() for _ in range(min(size, len(pending)))]
            tasks = [s.task(sweep_label=sweep.label, name=sweep.model_name, keep_history=histories is not None)
                     for s in chunk]
            key = f"pounding-scenarios-{chunk[0].key[:16]}-{len(chunk)}-{uuid.uuid4().hex[:8]}"
            future = client.submit(run_chunk, runner, Chunk(tasks), key=key, retries=retries, pure=False)
            chunks[future.key] = chunk
            completed.add(future)

    bar = tqdm(total=total, initial=initial, unit="scenario", desc=sweep.name, file=sys.stderr,
               disable=not progress, dynamic_ncols=True, smoothing=0.1)
    try:
        submit_more()
        for future in completed:
            chunk = chunks.pop(future.key)
            try:
                outcomes = future.result()
            except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after the retries
                outcomes = [{"key": s.key, "status": "error", "format": PARTS_FORMAT, "wall_time": float("nan"),
                             "error": f"{sweep.label}: scenario {s.label}: {one_line(exc)}"} for s in chunk]
                transient.update(s.key for s in chunk)
            finally:
                future.release()
            batcher.observe(outcomes)
            # The task's parts first, in one batch (a part whose history is missing runs again on resume).
            finished, datasets = [], []
            for scenario, result in zip(chunk, outcomes):
                datasets.append(result.pop("dataset", None))
                if store is not None and scenario.key not in transient:
                    result["identity"] = scenario.identity
                    finished.append(result)
                results[scenario.key] = result
            if finished:
                save_parts(store, finished)
            for scenario, dataset in zip(chunk, datasets):
                if dataset is not None and histories is not None:
                    save_run(dataset, histories / history_name(scenario), overwrite=True)
            bar.update(len(chunk))
            submit_more()
    except BaseException:
        for future in list(completed.futures):
            future.cancel()
        raise
    finally:
        bar.close()

