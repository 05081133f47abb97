"""Cost of our solver against building height and record duration, before and after a change; peak memory.

    python benchmarks/scaling.py                  # this tree: tables, plot, JSON, memory run (~2 min)
    python benchmarks/scaling.py --before 66b6f41 # the same, another commit against this tree, run by run
    python benchmarks/scaling.py --before-settings linear_phases=runge-kutta --settings linear_phases=exact
    python benchmarks/scaling.py --storeys 5 20 100 --repeat 1 --no-memory --no-plot
    python benchmarks/scaling.py --update-docs    # also rewrite docs/scaling.png

Files go to ``--out DIR`` (default ``<user cache>/pounding/benchmarks/scaling``:
``scaling.png``, ``scaling.json``), never into the checkout unless
``--update-docs`` is given (see ``benchmarks/_output.py``).

Models: a pair of uniform shear buildings of n storeys each (A: 2.5e5 kg,
3.5e8 N/m; B: 2.0e5 kg, 4.5e8 N/m; 3.2 m storeys; 5 % Rayleigh at modes 1
and 3) joined at every floor (``levels: matching``, 2 cm gap, hertz-damp
kh 1e10, e 0.65, Ye's ξ), so the number of contacts grows with n as well
(``benchmarks/_scaling_worker.py``).

**Sides.**  Without ``--before`` or ``--before-settings`` one side is measured:
this tree.  With either, two: *before* (the tree ``--before REF``, default this
one, with the ``solver:`` settings ``--before-settings``) and *after* (this tree
with ``--settings``).  ``REF`` is a commit of this repository, extracted once
with ``git archive`` into ``<out>/trees/<commit>`` and kept there (its numba
cache is built beside its sources on the first run, which can take minutes; a
folder outside ``/tmp``, where creating files is slow on the development
machine), or the folder of another checkout.  ``KEY=VALUE`` settings are
written into each model's ``solver:`` mapping as in a model file; a key a tree
does not know stops the run with that tree's one-line model error.  Each side
runs in its own long-lived process of ``benchmarks/_scaling_worker.py`` with
``PYTHONPATH`` set to its tree, and every point is measured run by run on
alternate sides (order reversed each round), so the machine's drifts fall on
both alike; printed per point: each side's time and the ratio after / before.

* **Storeys** (``--storeys``, default n in {5, 10, 20, 50, 100, 200, 500}):
  2 × n under FEMA P695 far-field record 1a (30 s).  Printed: solver time per
  simulated second (median of ``--repeat`` runs, JIT excluded: one 1 s run of
  each model first), steps, impacts, time per step, the ratio to the
  smallest n, and the wall time the point took.  Linear cost means the time
  per step grows like n and the number of steps does not (the step is set by
  the record's samples and the impacts, not by n: the highest frequency of a
  uniform shear building, 2·sqrt(k/m), does not depend on n).
* **Duration**: the 2 × 20 pair under record 1a repeated back to back to
  120 s, simulated for 10 … 120 s; time per simulated second should be flat.
* **Memory** (``--no-memory`` to skip; this tree, with ``--settings``):
  ``/usr/bin/time -v python -m pounding run`` on the 2 × 100 pair, 120 s,
  ``output_dt 0.005`` (record and model written to a temporary folder); peak
  resident set size.  The same model is then simulated in-process with
  ``output_dt`` 0.005 and 0.05 s to show that decimating the output never
  changes the peaks or the impacts (they are tracked at full solver resolution).

Time on the development machine (2 cores shared with other jobs, load 4 – 6,
Runge-Kutta for every phase): the default run with ``--before`` (two sides,
``--repeat 5``, memory run included) took 143 s, of which the 2 × 500 point
54 s (~3 s a run: its solver, then the 1000-floor dataset) and the memory run
29 s; one side takes about half the measuring, ~1.5 min in all.  A first
``--before`` of a commit adds its extraction and numba compilation (~50 s).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402
from _sides import WorkerProcess, checked, this_tree_label, tree_of  # noqa: E402
from _scaling_worker import RECORD, pair_yaml, repeated_record  # noqa: E402

DOCS_FIGURE = ROOT / "docs" / "scaling.png"
WORKER = Path(__file__).resolve().parent / "_scaling_worker.py"

STOREYS = [5, 10, 20, 50, 100, 200, 500]
DURATIONS = [10.0, 20.0, 30.0, 60.0, 90.0, 120.0]


class Side:
    """One side of the comparison: a tree and the ``solver:`` settings of its models, in its own process."""

    def __init__(self, name: str, tree_label: str, tree: Path, settings: list[str], clock: str) -> None:
        self.name, self.tree, self.settings = name, tree, settings
        self.tree_label, self.label = tree_label, tree_label + (f" [{', '.join(settings)}]" if settings else "")
        self.worker = WorkerProcess(WORKER, tree, [clock], name=name, script="scaling.py")

    def ask(self, **request) -> dict:
        """One answer of the worker; stops the run in one line on a model error or a dead worker."""
        answer = self.worker.ask(dict(request, settings=self.settings))
        if "error" in answer:
            given = " ".join(f"{'--before-settings' if self.name == 'before' else '--settings'} {s}"
                             for s in self.settings)
            raise SystemExit(f"scaling.py: {self.name} side ({self.tree_label}){', ' + given if given else ''}: "
                             f"{answer['error']}")
        return answer

    def run(self, storeys: int, duration: float | None = None, repeated: float | None = None) -> dict:
        return self.ask(op="run", storeys=storeys, duration=duration, repeated=repeated)

    def close(self) -> None:
        self.worker.close()


def setting(text: str) -> str:
    """argparse type of ``--settings``: ``KEY=VALUE``."""
    key, equals, value = text.partition("=")
    if not equals or not key.strip() or not value.strip():
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, e.g. linear_phases=runge-kutta (got {text!r})")
    return text


def start_sides(args: argparse.Namespace, out: Path) -> list[Side]:
    """The measured sides, each checked (its models built with its settings) before any timing."""
    after = this_tree_label()
    if args.before is None and args.before_settings is None:
        sides = [Side("this", after, ROOT, args.settings, args.clock)]
    else:
        tree, label = tree_of(args.before, out, "scaling.py") if args.before else (ROOT, after)
        sides = [Side("before", label, tree, args.before_settings or [], args.clock),
                 Side("after", after, ROOT, args.settings, args.clock)]

    def check(side: Side) -> None:
        started = time.perf_counter()
        version = side.ask(op="check")["version"]
        side.run(5, duration=1.0)
        print(f"{side.name}: {side.label} ({side.tree}), pounding {version}; first run (imports, cache load "
              f"or compile, record): {time.perf_counter() - started:.2f} s, excluded", flush=True)

    return checked(sides, check)


def measure(sides: list[Side], repeat: int, storeys: int, duration: float | None = None,
            repeated: float | None = None) -> dict:
    """One point on every side: a warm-up run each, then *repeat* rounds alternating the sides.

    Returns ``{"elapsed": s, "sides": {name: {...}}}`` with each side's median solver time
    ``time`` (s), ``per_second`` (solver s per simulated s), ``steps``, ``impacts``,
    ``per_step_us``, ``contacts`` and every run's ``times``; with two sides also
    ``after_over_before``, the ratio of the medians.
    """
    started = time.perf_counter()
    for side in sides:
        side.run(storeys, duration=1.0, repeated=repeated)  # the model's own code loaded or compiled
    found: dict[str, list[dict]] = {side.name: [] for side in sides}
    for round_ in range(repeat):
        for side in sides if round_ % 2 == 0 else sides[::-1]:
            found[side.name].append(side.run(storeys, duration, repeated))
    point = {"elapsed": time.perf_counter() - started, "sides": {}}
    for name, runs in found.items():
        times = [r["wall_time"] for r in runs]
        last, t = runs[-1], statistics.median(times)
        point["sides"][name] = {"time": t, "per_second": t / last["duration"], "steps": last["steps"],
                                "impacts": last["impacts"], "per_step_us": 1e6 * t / last["steps"],
                                "contacts": last["contacts"], "times": times}
    if len(sides) == 2:
        point["after_over_before"] = point["sides"]["after"]["time"] / point["sides"]["before"]["time"]
    return point


def print_point(first: str, point: dict, first_width: int, base: dict | None = None) -> None:
    """One table row per side of *point*; ``base``: the first point's sides, for the ratio to it."""
    for i, (name, s) in enumerate(point["sides"].items()):
        ratio = f"{s['per_second'] / base[name]['per_second']:>8.1f}" if base else ""
        last = i == len(point["sides"]) - 1
        against = f"{point['after_over_before']:>13.3f}" if last and "after_over_before" in point else " " * 13
        elapsed = f"{point['elapsed']:>8.1f}" if last else ""
        print(f"{first if i == 0 else '':>{first_width}} {name:>6} {s['contacts']:>8d} {s['time']:>8.4f} "
              f"{1e3 * s['per_second']:>13.3f} {s['steps']:>7d} {s['impacts']:>7d} {s['per_step_us']:>8.2f} "
              f"{ratio:>8} {against} {elapsed}", flush=True)


def header(first: str, first_width: int, base: str | None) -> None:
    print(f"{first:>{first_width}} {'side':>6} {'contacts':>8} {'time s':>8} {'ms per sim. s':>13} {'steps':>7} "
          f"{'impacts':>7} {'us/step':>8} {base or '':>8} {'after/before':>13} {'point s':>8}", flush=True)


def by_storeys(sides: list[Side], storeys: list[int], repeat: int) -> list[dict]:
    """Cost against the number of storeys: 2 × n pairs under record 1a (30 s)."""
    print(f"\n== cost against storeys: 2 x n pair, contacts at every floor, {RECORD} (30 s), "
          f"median of {repeat} ==")
    header("2 x n", 7, f"x 2x{storeys[0]}")
    rows: list[dict] = []
    for n in storeys:
        row = {"storeys": n, "floors": 2 * n, **measure(sides, repeat, n)}
        print_point(f"2 x {n}", row, 7, rows[0]["sides"] if rows else row["sides"])
        rows.append(row)
    for name in rows[0]["sides"]:
        first, last = rows[0], rows[-1]
        print(f"{name}: 2 x {last['storeys']} vs 2 x {first['storeys']}: "
              f"{last['sides'][name]['per_second'] / first['sides'][name]['per_second']:.1f}x per simulated "
              f"second for {last['floors'] / first['floors']:.0f}x the floors")
    return rows


def by_duration(sides: list[Side], durations: list[float], repeat: int, n: int = 20) -> list[dict]:
    """Cost against the record's length: the 2 × *n* pair under record 1a repeated, for *durations* (s)."""
    print(f"\n== cost against duration: 2 x {n} pair, {RECORD} repeated back to back, median of {repeat} ==")
    header("duration s", 10, None)
    rows: list[dict] = []
    for duration in durations:
        row = {"duration": duration, **measure(sides, repeat, n, duration, repeated=max(durations))}
        print_point(f"{duration:.0f}", row, 10)
        rows.append(row)
    for name in rows[0]["sides"]:
        per = [r["sides"][name]["per_second"] for r in rows]
        print(f"{name}: time per simulated second {1e3 * min(per):.3f} - {1e3 * max(per):.3f} ms "
              "(flat = linear in duration)")
    return rows


def memory(settings: list[str], n: int = 100, duration: float = 120.0, output_dt: float = 0.005) -> dict:
    """Peak resident memory of ``pounding run`` (this tree) and the output decimation check."""
    import pounding

    record = repeated_record(duration)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        np.savetxt(folder / "record.txt", record.acceleration, fmt="%.17g")
        extra = f", dt: {record.time_step!r}, units: m/s2, duration: {duration!r}"
        (folder / "model.yaml").write_text(pair_yaml(n, "record.txt", extra, settings + [f"output_dt={output_dt!r}"]))
        env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
        command = ["/usr/bin/time", "-v", sys.executable, "-m", "pounding", "run", "model.yaml", "-o", "run.nc"]
        done = subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(done.stderr[-2000:])
        rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr).group(1))
        wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", done.stderr).group(1)
        solver = re.search(r"solver wall time ([0-9.]+) s", done.stdout)
        size = (folder / "run.nc").stat().st_size

        model = pounding.load_model(folder / "model.yaml")
        fine = pounding.simulate(model, output_dt=output_dt)
        coarse = pounding.simulate(model, output_dt=0.05)
    same = all(np.array_equal(fine[v].values, coarse[v].values)
               for v in ("peak_displacement", "peak_storey_drift", "peak_contact_force", "impact_count",
                         "impact_time", "impact_velocity"))
    print(f"\n== memory: `pounding run`, 2 x {n} pair, {duration:g} s, output_dt {output_dt:g} s "
          f"({fine.sizes['time']} samples x {fine.sizes['floor']} floors, {fine.sizes['contact']} contacts) ==")
    print(f"  peak resident set size {rss_kb / 1024:.0f} MiB (target < 1024 MiB); wall {wall}; "
          f"solver {solver.group(1) if solver else '?'} s; archive {size / 2**20:.0f} MiB")
    print(f"  peaks and impacts identical with output_dt {output_dt:g} and 0.05 s: {same}")
    return {"rss_mib": rss_kb / 1024, "wall": wall, "archive_mib": size / 2**20, "decimation_invariant": same}


def plot(result: dict, path: str) -> None:
    """Solver time per simulated second against floors (log-log) and against duration, one curve per side."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.5))
    storeys, durations = result["storeys"], result["durations"]
    floors = np.array([r["floors"] for r in storeys], dtype=float)
    every = []
    for (name, label), marker in zip(result["sides"].items(), "os"):
        per = np.array([1e3 * r["sides"][name]["per_second"] for r in storeys])
        every.extend(per)
        a.loglog(floors, per, marker + "-", label=f"{name}: {label}" if name != "this" else label)
        b.plot([r["duration"] for r in durations], [1e3 * r["sides"][name]["per_second"] for r in durations],
               marker + "-", label=f"{name}: {label}" if name != "this" else label)
    first = per[0]  # the last side's smallest pair: the guides start there
    a.loglog(floors, first * floors / floors[0], "k--", lw=0.8, label="∝ floors")
    a.loglog(floors, first * (floors / floors[0]) ** 2, "k:", lw=0.8, label="∝ floors²")
    if "after" in result["sides"]:
        for r, y in zip(storeys, per):
            a.annotate(f"{r['after_over_before']:.2f}", (r["floors"], y), textcoords="offset points",
                       xytext=(0, -13), ha="center", fontsize=7)
    a.set_ylim(min(every) / 2, max(every) * 2)
    for axis in (a.xaxis, a.yaxis):
        axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    a.set_xticks(floors)
    a.set_yticks([t for t in (0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000)
                  if min(every) / 2 <= t <= max(every) * 2])
    a.set_xlabel("floors (2 x n)" + (";  figures: after / before" if "after" in result["sides"] else ""))
    a.set_ylabel(f"solver {'CPU ' if result['clock'] == 'cpu' else ''}time per simulated second (ms)")
    a.set_title(f"cost against storeys ({RECORD}, 30 s)")
    a.legend(fontsize=7)
    b.set_ylim(bottom=0)
    b.set_xlabel("simulated duration (s)")
    b.set_ylabel(f"solver {'CPU ' if result['clock'] == 'cpu' else ''}time per simulated second (ms)")
    b.set_title("cost against duration (2 x 20, record repeated)")
    b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    print(f"\nwrote {path}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per point and side (median)")
    parser.add_argument("--storeys", type=int, nargs="+", default=STOREYS, metavar="N",
                        help=f"storeys per building of the 2 x N pairs (default: {' '.join(map(str, STOREYS))})")
    parser.add_argument("--durations", type=float, nargs="+", default=DURATIONS, metavar="T",
                        help=f"simulated seconds of the 2 x 20 pair (default: {' '.join(f'{d:g}' for d in DURATIONS)})")
    parser.add_argument("--before", metavar="REF", help="measure this commit (or checkout folder) as well, "
                        "alternating with this tree")
    parser.add_argument("--before-settings", type=setting, action="append", metavar="KEY=VALUE",
                        help="solver: setting of the before side's models (repeatable); alone, compares "
                        "settings of this tree")
    parser.add_argument("--settings", type=setting, action="append", default=[], metavar="KEY=VALUE",
                        help="solver: setting of this tree's models (repeatable), e.g. linear_phases=runge-kutta")
    parser.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                        help="the solver's wall time (default) or its thread's CPU time")
    parser.add_argument("--no-plot", action="store_true", help="draw no figure")
    parser.add_argument("--no-memory", action="store_true", help="skip the /usr/bin/time memory run")
    add_output_arguments(parser, "scaling", owns=("docs/scaling.png",))
    args = parser.parse_args(argv)
    if args.update_docs and args.no_plot:
        parser.error("--update-docs rewrites docs/scaling.png: leave out --no-plot")
    if args.repeat < 1 or min(args.storeys) < 3 or min(args.durations) <= 0:
        parser.error("--repeat takes a whole number >= 1, --storeys >= 3 (damped at modes 1 and 3), "
                     "--durations seconds > 0")
    out = out_dir(args, "scaling")
    started = time.perf_counter()
    sides = start_sides(args, out)
    try:
        result = {"sides": {side.name: side.label for side in sides}, "clock": args.clock,
                  "storeys": by_storeys(sides, sorted(set(args.storeys)), args.repeat),
                  "durations": by_duration(sides, sorted(set(args.durations)), args.repeat)}
    finally:
        for side in sides:
            side.close()
    if not args.no_plot:
        plot(result, str(out / "scaling.png"))
        if args.update_docs:
            plot(result, str(DOCS_FIGURE))
    if not args.no_memory:
        result["memory"] = memory(args.settings)
    result["elapsed"] = time.perf_counter() - started
    (out / "scaling.json").write_text(json.dumps(result, indent=1))
    print(f"wrote {out / 'scaling.json'}\nwhole run {result['elapsed']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
