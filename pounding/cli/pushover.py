"""``pounding pushover``: static pushover of each building alone, with FEMA P695's pushover quantities."""

from __future__ import annotations

import argparse

__all__ = ["register_cli", "PATTERNS"]

#: pounding.studies.pushover.PATTERNS, written here so that the parser imports no study (tests/test_pushover.py
#: holds the two equal).
PATTERNS = ("first-mode", "triangular", "uniform")


def _cmd_pushover(args: argparse.Namespace) -> int:
    from pounding.cli.csv_option import check_outputs
    from pounding.results.archive import save_run
    from pounding.results.output_place import check_output_place, check_writable
    from pounding.studies.pushover import plot_pushover, pushover, pushover_table

    if args.output:
        check_writable(args.output, overwrite=args.overwrite, inputs=[args.model])
        check_outputs(args)   # nor the model's record files
    if args.plot:
        check_output_place(args.plot, "--plot", folder=True)
    ds = pushover(args.model, pattern=args.pattern, building=args.building, steps=args.steps, period=args.period,
                  design_cs=args.design_cs)
    print(pushover_table(ds))
    if args.output:
        save_run(ds, args.output, overwrite=args.overwrite)
        print(f"wrote {args.output}")
    if args.plot:
        for png in plot_pushover(ds, args.plot):
            print(f"wrote {png}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding pushover`` to *subparsers*."""
    parser = subparsers.add_parser(
        "pushover", help="static pushover of each building alone (capacity curve, FEMA P695 quantities)",
        description="Push each building of MODEL alone (contacts open), with P-Delta when the building has it, "
                    "displacement-controlled through softening to zero strength (or the drift limit): capacity "
                    "curve, V_max, effective yield roof drift, the ultimate roof drift at 20 % strength loss, "
                    "period-based ductility and overstrength (FEMA P695 §6.3; docs/hysteresis.md).")
    parser.add_argument("model", help="YAML model, e.g. models/pair_inelastic.yaml")
    parser.add_argument("--pattern", choices=PATTERNS, default="first-mode", help="lateral load pattern")
    parser.add_argument("--building", help="push only this building")
    parser.add_argument("--steps", type=int, default=400, help="drift steps of the control storey (10 to 20000, default 400)")
    parser.add_argument("--period", type=float, metavar="T",
                        help="the period T of FEMA P695 eq. 6-7 (C_u·T_a), s; max(T, T1) is used (default T1)")
    parser.add_argument("--design-cs", type=float, metavar="C_S",
                        help="seismic response coefficient of the design: overstrength = V_max / (C_s·W)")
    parser.add_argument("-o", "--output", metavar="OUT.nc", help="archive the capacity curves (NetCDF)")
    parser.add_argument("--plot", metavar="DIR", help="write pushover.png to DIR")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.set_defaults(func=_cmd_pushover)
    return parser
