"""The FEMA P695 verdict of a shipped model over the full far-field set (issue 27 §4).

    python benchmarks/p695_full.py [--model models/pair_inelastic.yaml] [--system A=steel-moment,B=rc-moment]
                                   [--workers 2] [--out DIR]

Runs ``pounding p695`` with the methodology's 44 far-field components, hunt-and-fill with the default
settings, with and without contacts, for every building; the tests run 4 records only.  Prints the verdict table, the number of runs and runs per second, and writes ``p695.nc``
(with each building's IDA in ``p695.nc.ida/``), ``p695_full.json`` and ``p695.png`` to ``--out``
(default ``<user cache>/pounding/benchmarks/p695_full``), never into the checkout.  Run it again with
the same ``--out`` and it resumes; ``--fresh`` starts over.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", default=str(ROOT / "models" / "pair_inelastic.yaml"))
    parser.add_argument("--system", default="A=steel-moment,B=rc-moment", help="as pounding p695 --system")
    parser.add_argument("--sdc", default="Dmax")
    parser.add_argument("--quality", default="design=B,test=B,model=B")
    parser.add_argument("--workers", type=int, default=None, help="Dask workers (default: one per core)")
    parser.add_argument("--fresh", action="store_true", help="remove an earlier run's archive and parts first")
    add_output_arguments(parser, "p695_full")
    args = parser.parse_args(argv)

    from pounding.studies.ida import Hunt
    from pounding.studies.p695 import (DEFAULT_RECORDS, P695Inputs, ida_folder, mce_spectrum, p695_study,
                                       p695_summary, p695_table, parse_quality, parse_systems, plot_p695)
    from pounding.model.model import load_model

    folder = out_dir(args, "p695_full")
    output = folder / "p695.nc"
    if args.fresh:
        output.unlink(missing_ok=True)
        shutil.rmtree(ida_folder(output), ignore_errors=True)
    names = [b.name for b in load_model(args.model).buildings]
    inputs = P695Inputs(systems=parse_systems(args.system, names), spectrum=mce_spectrum(args.sdc),
                        quality=parse_quality(args.quality), group=tuple(names), records=DEFAULT_RECORDS, hunt=Hunt())
    started = time.perf_counter()
    ds = p695_study(args.model, inputs, output, overwrite=True, keep_parts=True, workers=args.workers,
                    progress=True)
    elapsed = time.perf_counter() - started
    print(p695_table(ds))
    rate = ds.attrs["n_run"] / elapsed if elapsed > 0 else float("nan")
    print(f"{ds.attrs['n_run']} runs of {ds.attrs['n_runs']} in {elapsed:.1f} s ({rate:.2f} runs/s), "
          f"{ds.sizes['record']} records")
    summary = dict(p695_summary(ds), runs=int(ds.attrs["n_run"]), elapsed_s=elapsed, runs_per_s=rate)
    (folder / "p695_full.json").write_text(json.dumps(summary, indent=2), encoding="utf-8")
    plot_p695(ds, folder)
    print(f"wrote {output}, {folder / 'p695_full.json'}, {folder / 'p695.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
