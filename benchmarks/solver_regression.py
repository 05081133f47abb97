"""Solver-only time of every shipped model, this checkout against a baseline checkout (issue 24 §5).

``python benchmarks/solver_regression.py --baseline DIR [--repeat 5] [--models pair,...] [--out DIR]``

One long-lived worker process per tree (``PYTHONPATH`` set to the tree) simulates a model on
request and answers the solver's own wall time (the archive attribute ``wall_time``: the
compiled integration, not assembly or the results dataset).  Each model is simulated once per
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

MODELS = ["pair", "pair_inelastic", "isolated_moat", "pair_bumper", "pair_column", "pair_links",
          "pair_wave_passage", "row_of_three"]

#: The worker: one model name per input line, one solver wall time (s) per output line.
WORKER = """
import sys
import pounding
from pounding.simulation import simulate
models = {}
for line in sys.stdin:
    name = line.strip()
    if name not in models:
        models[name] = pounding.load_model(f"models/{name}.yaml")
    print(repr(float(simulate(models[name]).attrs["wall_time"])), flush=True)
"""


class Worker:
    """A Python process of one tree that simulates models on request."""

    def __init__(self, tree: Path) -> None:
        self.process = subprocess.Popen([sys.executable, "-c", WORKER], cwd=tree, text=True,
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


def measure(trees: dict[str, Path], models: list[str], repeat: int) -> dict[str, dict[str, list[float]]]:
    workers = {name: Worker(tree) for name, tree in trees.items()}
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
    add_output_arguments(parser, "solver_regression")
    args = parser.parse_args(argv)
    baseline = args.baseline.expanduser().resolve()
    if not (baseline / "pounding" / "__init__.py").is_file():
        parser.error(f"--baseline {baseline}: not a pounding checkout (no pounding/__init__.py)")
    found = measure({"baseline": baseline, "this": ROOT}, args.models.split(","), args.repeat)
    path = out_dir(args, "solver_regression") / "solver_regression.json"
    path.write_text(json.dumps(found, indent=1))
    print(f"wrote {path}\ntarget (issue 24): every ratio <= 1.05")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
