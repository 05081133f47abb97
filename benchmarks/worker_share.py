"""How much of a sweep's, compare's and gap study's worker time is spent in the compiled solver.

    python benchmarks/worker_share.py                      # this tree, 3 rounds (~1 min)
    python benchmarks/worker_share.py --before main        # main against this tree, alternated round by round
    python benchmarks/worker_share.py --studies gap --rounds 5

Files go to ``--out DIR`` (default ``<user cache>/pounding/benchmarks/worker_share``:
``worker_share.json``), never into the checkout (see ``benchmarks/_output.py``).

For each study (``benchmarks/_share_worker.py``: the sweep ``sweeps/gap_restitution.yaml``, 36
runs; a compare study of ``models/pair.yaml``, its 3 default ξ formulas × 3 records, 20 s; a gap
study of the same model, 6 records, 20 s) the study's tasks are built as the study builds them and
the worker's function (``run_scenario``, ``run_gap_scenario``) is called on each in one process,
every task run once first so that first-use imports and compilations are not counted.  Per run:
the worker call's wall time and its thread's CPU time, the solver's own wall time (the run's
``solver_wall_time``) and its thread's CPU time; the share in the solver is the solver's time over
the worker's, summed over the study's runs, for each clock (the CPU clock does not count waiting
for a core on a shared machine).  Printed: medians over the rounds of the milliseconds per run
(worker, outside the solver) and of the shares.

**Sides.**  With ``--before REF`` (a commit, extracted once with ``git archive`` into
``<out>/trees/<commit>``, or another checkout's folder) the same is measured in that tree too, each
side in its own process with its tree on ``PYTHONPATH``, the sides alternated round by round (the
order reversed each round), and the ratio after / before of the medians printed.  The results of
the two sides are compared as well (a digest of every result less its times): ``same results``
says whether both trees computed the same values, bit for bit.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402
from _sides import ROOT, WorkerProcess, checked, this_tree_label, tree_of  # noqa: E402

WORKER = Path(__file__).resolve().parent / "_share_worker.py"
STUDIES = ("sweep", "compare", "gap")


class Side:
    """One tree's worker process (:mod:`_share_worker`), checked and warmed up when started."""

    def __init__(self, name: str, label: str, tree: Path) -> None:
        self.name, self.label, self.tree = name, label, tree
        self.worker = WorkerProcess(WORKER, tree, [], name=name, script="worker_share.py")

    def ask(self, **request) -> dict:
        answer = self.worker.ask(request)
        if "error" in answer:
            raise SystemExit(f"worker_share.py: {self.name} side ({self.label}): {answer['error']}")
        return answer

    def close(self) -> None:
        self.worker.close()


def round_figures(runs: list[dict]) -> dict:
    """One study's round: ms per run (medians) and the shares in the solver (sums), per clock."""
    figures = {"runs": len(runs)}
    for clock in ("wall", "cpu"):
        worker = sum(r[clock] for r in runs)
        solver = sum(r[f"solver_{clock}"] for r in runs)
        figures[f"{clock}_ms"] = 1e3 * statistics.median(r[clock] for r in runs)
        figures[f"{clock}_outside_ms"] = 1e3 * statistics.median(r[clock] - r[f"solver_{clock}"] for r in runs)
        figures[f"{clock}_share"] = solver / worker
    return figures


def medians(rounds: list[dict]) -> dict:
    """The median of each figure over *rounds*, and each figure's range (noise)."""
    keys = [k for k in rounds[0] if k != "runs"]
    return {"runs": rounds[0]["runs"], "rounds": len(rounds),
            **{k: statistics.median(r[k] for r in rounds) for k in keys},
            "range": {k: [min(r[k] for r in rounds), max(r[k] for r in rounds)] for k in keys}}


def start_sides(args: argparse.Namespace, out: Path) -> list[Side]:
    after = this_tree_label()
    if args.before is None:
        named = [("this", after, ROOT)]
    else:
        tree, label = tree_of(args.before, out, "worker_share.py")
        named = [("before", label, tree), ("after", after, ROOT)]
    sides = [Side(name, label, tree) for name, label, tree in named]

    def check(side: Side) -> None:
        started = time.perf_counter()
        answer = side.ask(op="check")
        print(f"{side.name}: {side.label} ({side.tree}), pounding {answer['version']}, tasks {answer['tasks']}; "
              f"first runs (imports, kernels, records): {time.perf_counter() - started:.1f} s, excluded", flush=True)

    return checked(sides, check)


def measure(sides: list[Side], studies: list[str], rounds: int) -> dict:
    """*rounds* rounds, each every study on every side (the sides' order reversed each round)."""
    found = {s: {side.name: [] for side in sides} for s in studies}
    digests = {s: {side.name: set() for side in sides} for s in studies}
    for round_ in range(rounds):
        for side in sides if round_ % 2 == 0 else sides[::-1]:
            for study in studies:
                answer = side.ask(op="run", study=study)
                found[study][side.name].append(round_figures(answer["runs"]))
                digests[study][side.name].add(answer["digest"])
        print(f"round {round_ + 1} of {rounds} done", flush=True)
    result = {}
    for study in studies:
        result[study] = {name: medians(r) for name, r in found[study].items()}
        seen = set().union(*digests[study].values())
        result[study]["same_results"] = len(seen) == 1
    return result


def report(result: dict, sides: list[Side]) -> None:
    print(f"\n{'study':>8} {'side':>6} {'runs':>5} {'wall ms':>8} {'outside':>8} {'share':>6} "
          f"{'CPU ms':>8} {'outside':>8} {'share':>6}   (medians over rounds; share: solver / worker)")
    for study, by_side in result.items():
        for side in sides:
            m = by_side[side.name]
            print(f"{study:>8} {side.name:>6} {m['runs']:>5} {m['wall_ms']:>8.2f} {m['wall_outside_ms']:>8.2f} "
                  f"{m['wall_share']:>6.0%} {m['cpu_ms']:>8.2f} {m['cpu_outside_ms']:>8.2f} {m['cpu_share']:>6.0%}")
            lo, hi = m["range"]["cpu_share"]
            print(f"{'':>8} {'':>6} {'':>5} CPU share over the rounds {lo:.0%} - {hi:.0%}, wall ms "
                  f"{m['range']['wall_ms'][0]:.1f} - {m['range']['wall_ms'][1]:.1f}")
        if len(sides) == 2:
            before, after = by_side["before"], by_side["after"]
            by_side["after_over_before"] = {k: after[k] / before[k] for k in ("wall_ms", "cpu_ms", "wall_outside_ms",
                                                                              "cpu_outside_ms")}
            ratio = by_side["after_over_before"]
            print(f"{study:>8} after / before: wall {ratio['wall_ms']:.2f}, CPU {ratio['cpu_ms']:.2f}; outside the "
                  f"solver: wall {ratio['wall_outside_ms']:.2f}, CPU {ratio['cpu_outside_ms']:.2f}; same results: "
                  f"{by_side['same_results']}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="rounds of every study on every side (medians)")
    parser.add_argument("--studies", nargs="+", choices=STUDIES, default=list(STUDIES), help="studies to measure")
    parser.add_argument("--before", metavar="REF", help="measure this commit (or checkout folder) as well, "
                        "alternating with this tree")
    add_output_arguments(parser, "worker_share")
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error("--rounds takes a whole number >= 1")
    out = out_dir(args, "worker_share")
    started = time.perf_counter()
    sides = start_sides(args, out)
    try:
        result = measure(sides, args.studies, args.rounds)
    finally:
        for side in sides:
            side.close()
    report(result, sides)
    document = {"sides": {side.name: side.label for side in sides}, "studies": result,
                "elapsed": time.perf_counter() - started}
    (out / "worker_share.json").write_text(json.dumps(document, indent=1))
    print(f"wrote {out / 'worker_share.json'}\nwhole run {document['elapsed']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
