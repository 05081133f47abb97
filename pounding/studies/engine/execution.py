"""The study engine: every study's scenarios run on Dask, their results kept in a resumable parts store.

:func:`run_study` takes a task source (:mod:`pounding.studies.engine.tasks`:
a static list, or an adaptive source that adds scenarios as results
arrive), runs what the parts store (:mod:`~pounding.studies.engine.store`)
does not already hold on a LocalCluster or an existing scheduler — a few
scenarios per Dask task once their cost is known, each result stored as it
arrives — and writes the dataset the source assembles.  An interrupted
study resumes from its parts: the same command runs only what is missing.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterator

from pounding.errors import PoundingError
from pounding.studies.engine.keys import PARTS_FORMAT
from pounding.studies.engine.store import (history_name, load_parts, parts_dir, prepare_store, save_parts,
                                           sweep_lock)
from pounding.studies.engine.tasks import Scenario, TaskSource, one_line

__all__ = ["default_workers", "start_client", "check_scheduler_address", "run_study", "run_chunk", "Chunk",
           "LOCAL_CLUSTER_CONFIG"]


_ADDRESS = re.compile(r"^(?:(?:tcp|tls|inproc|ucx|ws|wss)://)?[A-Za-z0-9_.\-\[\]:]+:\d{1,5}/?$")


def check_scheduler_address(address: str) -> str:
    """*address* if it looks like a Dask scheduler address (``tcp://host:8786``), else a one-line error."""
    text = str(address).strip()
    if not _ADDRESS.match(text):
        raise PoundingError(f"--scheduler {address!r} is not a scheduler address; write tcp://HOST:PORT, e.g. "
                            "tcp://127.0.0.1:8786 (printed by `dask scheduler`)")
    return text


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
        with dask.config.set(LOCAL_CLUSTER_CONFIG), _held_logs() as logged:   # the nannies pass the config on
            try:
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                       silence_logs=logging.ERROR)
            except Exception as exc:   # noqa: BLE001 - dask raises anything a worker start met
                cause = logged[0] if logged else exc
                detail = one_line(cause) if isinstance(cause, BaseException) else " ".join(str(cause).split())
                raise PoundingError(f"could not start {n} Dask worker process{'es' if n > 1 else ''} "
                                    f"({detail[:200]}); use fewer --workers, raise the limits of this shell "
                                    "(ulimit -n open files, ulimit -v memory) or give --scheduler") from None
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)
    return Client(cluster), cluster


@contextmanager
def _held_logs() -> Iterator[list]:
    """Hold back what ``distributed``, ``tornado`` and ``asyncio`` log at ERROR while a cluster starts.

    Yields the list of the exceptions (or messages) held.

    A worker that cannot start is logged with a traceback per attempt and
    per nanny (75-124 lines); the caller turns the first of them into one
    line.  The logger's handlers are restored when the block ends.
    """
    import logging

    found: list = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            found.append(record.exc_info[1] if record.exc_info and record.exc_info[1] else record.getMessage())

    loggers = [logging.getLogger(name) for name in ("distributed", "tornado", "asyncio")]
    saved = [(list(logger.handlers), logger.propagate) for logger in loggers]
    for logger in loggers:
        logger.handlers = [Keep(logging.ERROR)]
        logger.propagate = False
    try:
        yield found
    finally:
        for logger, (handlers, propagate) in zip(loggers, saved):
            logger.handlers, logger.propagate = handlers, propagate


def run_study(source: TaskSource, output: str | os.PathLike | None = None, *, workers: int | None = None,
              scheduler: str | None = None, client: Any = None, keep_histories: str | os.PathLike | None = None,
              overwrite: bool = False, keep_parts: bool = False, progress: bool = True, retries: int = 2,
              task_seconds: float = 0.5, log: Callable[[str], None] | None = None, plan: str | None = None):
    """Run every scenario of *source* and return the dataset it assembles (written to *output* if given).

    Parameters
    ----------
    source : TaskSource
        The study's scenarios, its worker function and its dataset.
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
        Directory for each scenario's full results archive (runners that return one).
    overwrite : bool
        Replace an existing *output*.
    keep_parts : bool
        Keep ``<output>.parts/`` after the final file is written.
    progress : bool
        Show a tqdm progress bar on stderr.
    retries : int
        Retries of a task whose worker died.
    task_seconds : float
        Scenarios are grouped into Dask tasks of about this many seconds once
        their cost is known (the first tasks hold one scenario each); 0 keeps
        one scenario per task.  Each result is still stored on its own.  A
        source's own ``task_seconds`` takes precedence.
    log : callable, optional
        Receives one-line notes (default: print to stderr).
    plan : str, optional
        The study's number of runs, said once its inputs are checked and before any run starts.
    """
    from pounding.results.output_place import check_writable

    say = log or (lambda line: print(line, file=sys.stderr))
    if scheduler and client is None:
        check_scheduler_address(scheduler)
    target = check_writable(output, overwrite=overwrite, inputs=source.inputs) if output is not None else None
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
    source.check()  # before expanding the scenarios
    options = dict(workers=workers, scheduler=scheduler, client=client, overwrite=overwrite, keep_parts=keep_parts,
                   progress=progress, retries=retries, plan=plan,
                   task_seconds=task_seconds if source.task_seconds is None else source.task_seconds)
    if target is None:
        return _run_locked(source, None, None, histories, say, **options)
    with sweep_lock(target):
        store = prepare_store(parts_dir(target))
        return _run_locked(source, target, store, histories, say, **options)


def _run_locked(source: TaskSource, target: Path | None, store: Path | None, histories: Path | None, say, *,
                workers, scheduler, client, overwrite, keep_parts, progress, retries, task_seconds, plan=None):
    """The body of :func:`run_study`, once the output is checked and locked."""
    from pounding.results.archive import save_run

    bad: list[str] = []
    done = load_parts(store, bad=bad) if store is not None else {}
    for message in bad[:5]:
        say(f"pounding: warning: invalid part {message}; its {source.unit} runs again")
    if len(bad) > 5:
        say(f"pounding: warning: ... and {len(bad) - 5} more invalid parts set aside in {store}")

    results: dict[str, dict[str, Any]] = {}
    reused = [0]

    def known(scenario: Scenario) -> dict[str, Any] | None:
        """The scenario's result without running it (a stored part, or its known error), else None."""
        if scenario.key in results:
            return results[scenario.key]
        part = done.get(scenario.key)
        history_missing = histories is not None and scenario.error is None and \
            not (histories / history_name(scenario)).exists()
        if part is not None and not history_missing:
            results[scenario.key] = part
            reused[0] += 1
            return part
        if scenario.error is not None:
            results[scenario.key] = {"key": scenario.key, "status": "error", "error": scenario.error,
                                     "format": PARTS_FORMAT, "wall_time": 0.0}
            return results[scenario.key]
        return None

    todo = source.first(known)
    if plan:
        say(plan)  # the scenarios are valid: the number of runs, before any runs
    done_identities = {p.get("identity") for p in done.values()} - {None}
    stale = len({s.key for s in todo if s.identity in done_identities})
    if stale:
        say(f"{stale} finished {source.unit}s no longer match their inputs (a record file or pounding's code "
            "changed since they ran) and are run again")
    note = source.resumed(reused[0], set(done), store, todo)
    if note:
        say(note)
    transient: set[str] = set()
    ran = [0]
    started = time.perf_counter()
    if todo:
        own = client is None
        cluster = None
        if own:
            client, cluster = start_client(workers=workers, scheduler=scheduler)
        try:
            estimate = source.estimate()
            initial = len(results)
            _run_on(client, source, todo, results, known, store=store, histories=histories, retries=retries,
                    progress=progress, initial=initial,
                    total=initial + len(todo) if estimate is None else estimate, transient=transient,
                    task_seconds=task_seconds, ran=ran)
        finally:
            if own:
                # A worker's heartbeat racing the shutdown logs a CommClosedError traceback on a loaded machine:
                # the results are in hand, so what the closing cluster logs is noise (held back, dropped).
                with _held_logs():
                    client.close()
                    if cluster is not None:
                        cluster.close()
    elapsed = time.perf_counter() - started
    ds = source.assemble(results, elapsed=elapsed, ran=ran[0], lost=len(transient))
    ds.attrs["n_stale"] = int(stale)
    ds.attrs["n_invalid_parts"] = len(bad)
    if histories is not None:
        ds.attrs["histories"] = str(histories)
    if target is not None:
        save_run(ds, target, overwrite=overwrite)
        if transient:
            say(f"{len(transient)} {source.unit}s could not run (their workers died); the others are kept in "
                f"{store}: rerun the same command with --overwrite to retry just those")
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


def _run_on(client, source: TaskSource, todo: list[Scenario], results: dict[str, dict[str, Any]], known, *,
            store: Path | None, histories: Path | None, retries: int, progress: bool, initial: int, total: int,
            transient: set[str], ran: list[int], task_seconds: float = 0.5, max_batch: int = 64) -> None:
    """Submit the scenarios as tasks (a few in flight per worker thread), store each result as it arrives and
    submit the scenarios the source makes runnable from it."""
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
            tasks = [s.task(sweep_label=source.label, name=source.model_name, keep_history=histories is not None)
                     for s in chunk]
            key = f"pounding-scenarios-{chunk[0].key[:16]}-{len(chunk)}-{uuid.uuid4().hex[:8]}"
            future = client.submit(run_chunk, source.runner, Chunk(tasks), key=key, retries=retries, pure=False)
            chunks[future.key] = chunk
            completed.add(future)

    bar = tqdm(total=total, initial=initial, unit=source.unit, desc=source.name, file=sys.stderr,
               disable=not progress, dynamic_ncols=True, smoothing=0.1)
    try:
        submit_more()
        for future in completed:
            chunk = chunks.pop(future.key)
            try:
                outcomes = future.result()
            except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after the retries
                outcomes = [{"key": s.key, "status": "error", "format": PARTS_FORMAT, "wall_time": float("nan"),
                             "error": f"{source.label}: scenario {s.label}: {one_line(exc)}"} for s in chunk]
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
            ran[0] += len(chunk)
            for scenario, result in zip(chunk, outcomes):
                pending.extend(source.follow(scenario, result, known))
            if bar.n + len(chunk) > bar.total:
                bar.total = bar.n + len(chunk) + len(pending) + sum(len(c) for c in chunks.values())
            bar.update(len(chunk))
            submit_more()
    except BaseException:
        for future in list(completed.futures):
            future.cancel()
        raise
    finally:
        bar.close()
