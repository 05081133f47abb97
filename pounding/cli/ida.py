"""``pounding ida``: incremental dynamic analysis and fragility, with and without pounding."""

from __future__ import annotations

import argparse
import json
import sys

from pounding.cli.sweep import add_cluster_options, check_study_options, interrupted
from pounding.cli.csv_option import add_csv_option, check_outputs, write_csv_option
from pounding.errors import PoundingError

__all__ = ["register_cli", "add_hunt_options"]


def _cmd_ida(args: argparse.Namespace) -> int:
    from pounding.studies.ida import Hunt, build_ida_plan, ida_study, ida_summary, ida_table, parse_intensity, plot_ida
    from pounding.model.model import load_model
    from pounding.results.checks import model_warnings, print_warnings

    check_study_options(args)
    check_outputs(args)
    hunt = None
    if args.hunt:
        hunt = Hunt(start=args.hunt_start, step=args.hunt_step, increment=args.hunt_increment,
                    tolerance=args.tolerance, runs=args.runs_per_record, ceiling=args.hunt_ceiling)
    elif args.levels is None:
        raise PoundingError("give --levels START:STOP:STEP (fixed stripes, in g, e.g. 0.1:3.0:0.1) or --hunt "
                            "(hunt-and-fill)")
    mce = None if args.mce is None else parse_intensity(args.mce, "--mce")
    plan = build_ida_plan(args.model, args.records, im=args.im, building=args.building, levels=args.levels,
                          hunt=hunt, without_contacts=args.without_contacts, limits=args.limits,
                          collapse_drift=args.collapse_drift, mce=mce, scaling=args.scaling, duration=args.duration)
    print(f"IDA of '{plan.model_name}': {len(plan.records)} records x "
          + (f"{len(plan.levels)} levels" if hunt is None else "hunt-and-fill")
          + f" x {len(plan.variants)} variant(s) = {'up to ' if hunt is not None else ''}{plan.planned_runs()} runs; "
          f"IM {plan.im.describe()}", file=sys.stderr)
    model = load_model(args.model)   # its runs are not checked one by one: the model's and the records' warnings once
    print_warnings([*model.warnings, *model_warnings(model).values(), *plan.warnings])
    try:
        ds = ida_study(plan, args.output, workers=args.workers, scheduler=args.scheduler, overwrite=args.overwrite,
                       progress=not args.no_progress)
    except KeyboardInterrupt:
        return interrupted(args.output, "runs")
    status = ds.status.values
    ran = (status == "completed") | (status == "collapsed")
    failed = status == "failed"
    errors: dict[str, int] = {}
    for message in ds.error.values[failed]:
        errors[str(message)] = errors.get(str(message), 0) + 1
    if not ran.any():
        for message, count in errors.items():
            print(f"pounding: {count} run(s) failed: {message}", file=sys.stderr)
        where = f"; the errors are also in the variable 'error' of {args.output}" if args.output else ""
        raise PoundingError(f"all {int(failed.sum())} runs failed (errors above){where}")
    if args.json:
        print(json.dumps(ida_summary(ds), indent=2))
    else:
        print(ida_table(ds))
    for message, count in errors.items():
        print(f"pounding: {count} run(s) failed: {message}", file=sys.stderr)
    out = sys.stderr if args.json else sys.stdout
    if ds.attrs.get("n_run"):
        rate = ds.attrs["n_run"] / ds.attrs["elapsed_time"] if ds.attrs["elapsed_time"] > 0 else float("nan")
        print(f"ran {ds.attrs['n_run']} runs in {ds.attrs['elapsed_time']:.1f} s ({rate:.2f} runs/s)", file=out)
    if args.output:
        print(f"wrote {args.output}", file=out)
    write_csv_option(args, "ida", ds, out)
    if args.plot:
        for png in plot_ida(ds, args.plot):
            print(f"wrote {png}", file=out)
    return 0


def add_hunt_options(parser: argparse.ArgumentParser) -> None:
    """The hunt-and-fill options (levels in g) of ``pounding ida --hunt`` and ``pounding p695``."""
    parser.add_argument("--hunt-start", type=float, default=0.1, metavar="G", help="first level of a hunt (g; 0.1)")
    parser.add_argument("--hunt-step", type=float, default=0.1, metavar="G",
                        help="first step of a hunt (g; 0.1); the k-th step adds k x --hunt-increment")
    parser.add_argument("--hunt-increment", type=float, default=0.05, metavar="G", help="step growth (g; 0.05)")
    parser.add_argument("--tolerance", type=float, default=0.05, metavar="G",
                        help="width of the final collapse bracket (g; 0.05)")
    parser.add_argument("--runs-per-record", type=int, default=12, metavar="N",
                        help="fill each record's IDA curve up to N runs after bracketing (12)")
    parser.add_argument("--hunt-ceiling", type=float, default=5.0, metavar="G",
                        help="highest level of a hunt (g; 5): a record that has not collapsed there is censored")


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding ida`` to *subparsers*."""
    parser = subparsers.add_parser(
        "ida", help="incremental dynamic analysis and fragility, with and without pounding",
        description="Scale every record of a set to a series of intensities (fixed stripes, or hunt-and-fill to "
                    "each record's collapse), run the model at each, optionally again with its contacts held "
                    "open, and fit lognormal fragility functions (median theta, dispersion beta) per building "
                    "and drift limit and for collapse. Intensities are in g. See docs/ida.md.")
    parser.add_argument("model", help="YAML model, e.g. models/pair.yaml (or a plan model: record pairs, each in "
                                      "both orientations; docs/ida.md)")
    parser.add_argument("--records", metavar="SET|LIST",
                        help="a record set (fema-p695:farfield, fema-p695:nearfield, farfield...) or a "
                             "comma-separated list of records (default: the model's record); a plan model takes "
                             "record pairs (fema-p695:farfield = 22 pairs, fema-p695:farfield/1,...)")
    parser.add_argument("--im", choices=("sa-t1", "pga"), default="sa-t1",
                        help="intensity measure: Sa(T1, 5 %%) of --building (default) or PGA")
    parser.add_argument("--building", help="the building of Sa(T1) (default: the first); a hunt brackets every "
                                           "building's collapse")
    levels = parser.add_mutually_exclusive_group()
    levels.add_argument("--levels", metavar="A:B:STEP",
                        help="fixed stripes in g (or with units, as --mce: 0.1g, 1 m/s2, 100 gal): START:STOP:STEP "
                        "(both ends included) or a list 0.2,0.4,0.8")
    levels.add_argument("--hunt", action="store_true",
                        help="hunt-and-fill (Vamvatsikos & Cornell): bracket each record's collapse intensity, "
                             "per building")
    add_hunt_options(parser)
    parser.add_argument("--without-contacts", action="store_true",
                        help="run every scenario again with the contacts held open (the effect of pounding)")
    parser.add_argument("--limits", metavar="LIST",
                        help="peak storey drift ratio limits, e.g. 0.005,0.015,0.025 (the default); in plan a "
                             "storey's drift ratio is its planes' largest")
    parser.add_argument("--collapse-drift", type=float, metavar="RATIO",
                        help="every building's collapse drift ratio in this study, over the model's collapse: "
                             "{drift_ratio} and solver.stop_drift_ratio (the runs end there; default: the model's, "
                             "else the largest limit, applied to the peaks); see docs/ida.md")
    parser.add_argument("--mce", metavar="IM",
                        help="MCE intensity S_MT (g, or with units: 0.9g) for the FEMA P695 collapse margin ratio")
    parser.add_argument("--scaling", choices=("auto", "record", "fema-p695"), default="auto",
                        help="record: each record to the level; fema-p695: normalised set, its median IM at the "
                             "level; auto (default): fema-p695 for FEMA P695 records, else record")
    parser.add_argument("--duration", type=float, help="simulated time of every run, s (default: the model's)")
    parser.add_argument("-o", "--output", metavar="IDA.nc", help="also write the results (NetCDF); resumable")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--json", action="store_true", help="print the fragility as one JSON document (g)")
    parser.add_argument("--plot", metavar="DIR", help="write ida_curves.png and fragility.png to DIR")
    add_csv_option(parser)
    add_cluster_options(parser)
    parser.set_defaults(func=_cmd_ida)
    return parser
