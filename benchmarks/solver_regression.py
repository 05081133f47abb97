"""Solver-only time of every shipped model, this checkout against a baseline checkout (issue 24 §5).

``python benchmarks/solver_regression.py --baseline DIR [--repeat 5] [--models pair,...] [--clock cpu] [--out DIR]``

One long-lived worker process per tree (``PYTHONPATH`` set to the tree) simulates a model on
request and answers the solver's own wall time (the archive attribute ``wall_time``: the
compiled integration, not assembly or the results dataset), or with ``--clock cpu`` the CPU time
of its thread over the same call (``time.thread_time``; on a machine shared with other jobs the
wall time also counts the time the solver waits for a core).  Each model is simulated once per
tree to load or compile the code (not counted), then ``--repeat`` times, baseline and this
tree in turn, so drifts of the machine's speed fall on both alike.  Printed per model: the
median solver time of each tree and the ratio this / baseline.  Issue 24: every ratio ≤ 1.05.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402

MODELS = ["pair", "pair_inelastic", "pair_collapse", "isolated_moat", "pair_bumper", "pair_column", "pair_links",
          "pair_wave_passage", "row_of_three", "corner_pair", "isolated_moat_plan"]

#: The worker: one model name per input line, one solver wall time (s) per output line (in a tree
#: from before the one structure model, a plan model through its own loader and ``simulate_plan``).
WORKER = """
import sys
import pounding
from pounding.model.model import is_plan_file
from pounding.simulation import simulate
sys.path.insert(0, sys.argv[2])   # benchmarks/ of the checkout that runs the comparison
from _sides import time_solver_thread
clock, spent = sys.argv[1], []
time_solver_thread(spent)
models = {}
for line in sys.stdin:
    name = line.strip()
    if name not in models:
        path = f"models/{name}.yaml"
        try:   # a tree before one structure model: plan models had their own loader and simulate
            from pounding.model.plan_model import load_plan_model
            from pounding.simulation import simulate_plan
        except ImportError:
            load_plan_model = None
        if is_plan_file(path) and load_plan_model is not None:
            models[name] = (simulate_plan, load_plan_model(path))
        else:
            models[name] = (simulate, pounding.load_model(path))
    run, model = models[name]
    wall = float(run(model).attrs["wall_time"])
    print(repr(spent.pop() if clock == "cpu" else wall), flush=True)
"""


class Worker:
    """A Python process of one tree that simulates models on request."""

    def __init__(self, tree: Path, clock: str = "wall") -> None:
        self.process = subprocess.Popen([sys.executable, "-c", WORKER, clock, str(Path(__file__).resolve().parent)], cwd=tree, text=True,
                                        env=dict(os.environ, PYTHONPATH=str(tree)),
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE)

    def solve(self, model: str) -> float:
        self.process.stdin.write(model + "\n")
        self.process.stdin.flush()
        answer = self.process.stdout.readline()
        if not answer:
            raise SystemExit(f"worker failed on {model} (exit {self.process.wait()})")
        return float(answer)

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait()


def measure(trees: dict[str, Path], models: list[str], repeat: int,
            clock: str = "wall") -> dict[str, dict[str, list[float]]]:
    workers = {name: Worker(tree, clock) for name, tree in trees.items()}
    found: dict[str, dict[str, list[float]]] = {model: {name: [] for name in trees} for model in models}
    try:
        for model in models:
            for worker in workers.values():
                worker.solve(model)  # compile or load from the cache; not counted
            for _ in range(repeat):
                for name, worker in workers.items():
                    found[model][name].append(worker.solve(model))
            base, this = (statistics.median(found[model][n]) for n in ("baseline", "this"))
            print(f"{model:<20} baseline {base * 1e3:8.2f} ms   this {this * 1e3:8.2f} ms   ratio {this / base:5.3f}",
                  flush=True)
    finally:
        for worker in workers.values():
            worker.close()
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", type=Path, required=True, help="another checkout of pounding")
    parser.add_argument("--repeat", type=int, default=5, help="timed solves of each model per tree (median)")
    parser.add_argument("--models", default=",".join(MODELS), help="comma-separated shipped model names")
    parser.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                        help="the solver's wall time (default) or its thread's CPU time")
    add_output_arguments(parser, "solver_regression")
    args = parser.parse_args(argv)
    baseline = args.baseline.expanduser().resolve()
    if not (baseline / "pounding" / "__init__.py").is_file():
        parser.error(f"--baseline {baseline}: not a pounding checkout (no pounding/__init__.py)")
    found = measure({"baseline": baseline, "this": ROOT}, args.models.split(","), args.repeat, args.clock)
    path = out_dir(args, "solver_regression") / "solver_regression.json"
    path.write_text(json.dumps(found, indent=1))
    print(f"wrote {path}\ntarget (issue 24): every ratio <= 1.05")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
