"""The tasks of a study and where they come from: scenarios, and the task sources the engine runs.

A **scenario** is one model run: its document, its key (:mod:`~pounding.studies.engine.keys`)
and its coordinates in the study.  A **task source** hands the engine the
scenarios to run and, as results arrive, the ones they make runnable:

``StaticTasks``   a list known up front (a sweep, ``compare``, ``gap``, IDA stripes);
adaptive sources  a subclass whose :meth:`TaskSource.follow` returns the next scenarios from a
                  result (IDA hunt-and-fill, :class:`pounding.studies.ida.hunt.HuntTasks`).

The source also assembles the study's dataset from every result.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from pounding.errors import PoundingError

__all__ = ["Scenario", "TaskSource", "StaticTasks", "one_line"]

#: ``known(scenario)``: the scenario's result if it needs no run (a stored part, or the error of an
#: invalid scenario), else None; the engine's resolver, handed to the source.
Known = Callable[["Scenario"], "dict[str, Any] | None"]


def one_line(exc: BaseException) -> str:
    """An exception as a one-line message (its type named unless it is a :class:`PoundingError`)."""
    text = " ".join(str(exc).split())
    return text if isinstance(exc, PoundingError) else f"{type(exc).__name__}: {text}"


@dataclass(frozen=True)
class Scenario:
    """One model × record to simulate.

    Attributes
    ----------
    index : tuple of int
        Position along each dimension.
    coords : dict
        Axis name → label of this scenario.
    document : str
        The model YAML (what the key hashes and an archive keeps).
    base_dir : str or None
        Directory for relative record paths.
    key : str
        SHA-256 of everything the result depends on: :attr:`identity`, the
        content of the record it reads (:func:`record_fingerprint`) and the
        code (:func:`code_fingerprint`).
    error : str or None
        Known problem (an invalid axis value), recorded without running.
    data : dict or None
        The same model as plain data: workers validate it directly (no YAML parse).
    identity : str
        SHA-256 of the document and base_dir only: the same scenario across
        edits of its record or of the code (to count stale parts).
    """

    index: tuple[int, ...]
    coords: dict[str, Any]
    document: str
    base_dir: str | None
    key: str
    error: str | None = None
    data: dict | None = field(default=None, repr=False, compare=False)
    identity: str = ""

    @property
    def label(self) -> str:
        return ", ".join(f"{k}={v}" for k, v in self.coords.items())

    def task(self, *, sweep_label: str, name: str, keep_history: bool = False) -> dict[str, Any]:
        """What a worker receives (plain data, cheap to ship)."""
        return {"key": self.key, "document": self.document, "data": self.data, "base_dir": self.base_dir, "name": name,
                "where": f"{sweep_label}: scenario {self.label}", "keep_history": keep_history}


class TaskSource:
    """What a study runs on the engine (:func:`pounding.studies.engine.execution.run_study`).

    Attributes
    ----------
    name : str
        The study's name (progress bar).
    label : str
        The study as given (messages: ``<ida models/pair.yaml>``, a sweep file).
    model_name : str
        Name given to every model run.
    runner : callable
        ``runner(task) -> result``, run on a worker for each scenario (plain data in and out).
    inputs : list of str
        Files the study reads (an output may not overwrite them).
    unit : str
        What one scenario is called in messages (``scenario``, ``run``).
    task_seconds : float or None
        Seconds of work per Dask task once run times are known; 0 sends one scenario per task,
        None takes the engine's default.
    """

    name: str = "study"
    label: str = "<study>"
    model_name: str = "model"
    runner: Callable[[dict[str, Any]], dict[str, Any]]
    inputs: list[str]
    unit: str = "scenario"
    task_seconds: float | None = None

    def check(self) -> None:
        """Refuse, before anything is expanded, a study that cannot run (default: nothing to check)."""

    def first(self, known: Known) -> list[Scenario]:
        """The scenarios to run at once (those *known* answers are not run)."""
        raise NotImplementedError

    def follow(self, scenario: Scenario, result: dict[str, Any], known: Known) -> list[Scenario]:
        """The scenarios *result* makes runnable (default: none, a static list)."""
        return []

    def estimate(self) -> int | None:
        """How many scenarios the study will hold, for the progress bar (None: those of :meth:`first`)."""
        return None

    def resumed(self, reused: int, stored: set[str], store: Any, todo: list[Scenario]) -> str | None:
        """The note printed when stored parts are reused (None: nothing to say).

        *reused* counts the parts used so far, *stored* holds the keys of every part in *store*,
        *todo* the scenarios about to run.
        """
        if not reused:
            return None
        return f"{reused} {self.unit}s already done (in {store}); the study goes on from there"

    def assemble(self, results: dict[str, dict[str, Any]], *, elapsed: float, ran: int, lost: int) -> Any:
        """The study's dataset from every result by scenario key."""
        raise NotImplementedError


class StaticTasks(TaskSource):
    """A list of scenarios known up front (a sweep, ``compare``, ``gap``, IDA stripes).

    Parameters
    ----------
    scenarios : callable
        Returns the scenarios (called once, after :meth:`check`).
    assemble : callable
        ``assemble(results, elapsed=, ran=)`` → the dataset.
    check : callable, optional
        Refuses a study too large to expand (e.g. :meth:`pounding.studies.sweep.spec.Sweep.check_size`).
    name, label, model_name, runner, inputs, unit, task_seconds
        See :class:`TaskSource`.
    """

    def __init__(self, scenarios: Callable[[], list[Scenario]], assemble: Callable[..., Any], *, name: str,
                 label: str, model_name: str, runner: Callable[[dict[str, Any]], dict[str, Any]],
                 inputs: list[str], check: Callable[[], None] | None = None, unit: str = "scenario",
                 task_seconds: float | None = None):
        self.name, self.label, self.model_name = name, label, model_name
        self.runner, self.inputs, self.unit, self.task_seconds = runner, inputs, unit, task_seconds
        self._scenarios, self._assemble, self._check = scenarios, assemble, check
        self._listed: list[Scenario] = []

    def check(self) -> None:
        if self._check is not None:
            self._check()

    def first(self, known: Known) -> list[Scenario]:
        self._listed = self._scenarios()
        return [s for s in self._listed if known(s) is None]

    def resumed(self, reused: int, stored: set[str], store: Any, todo: list[Scenario]) -> str | None:
        keys = {s.key for s in self._listed}
        skipped = sum(1 for k in keys if k in stored)
        if not skipped:
            return None
        return f"{skipped} of {len(keys)} {self.unit}s already done (in {store}); running the other {len(todo)}"

    def assemble(self, results: dict[str, dict[str, Any]], *, elapsed: float, ran: int, lost: int) -> Any:
        return self._assemble(results, elapsed=elapsed, ran=ran)
