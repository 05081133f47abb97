"""``pounding hysteresis``: a quasi-static cyclic test of one storey (drift history in, shear out)."""

from __future__ import annotations

import argparse

__all__ = ["register_cli"]


def _cmd_hysteresis(args: argparse.Namespace) -> int:
    from pounding.cli.csv_option import check_outputs
    from pounding.results.archive import save_run
    from pounding.results.output_place import check_output_place, check_writable
    from pounding.studies.cyclic import PROTOCOLS, hysteresis_test, plot_hysteresis, write_csv

    inputs = [args.model] + ([] if args.protocol in PROTOCOLS else [args.protocol])
    check_writable(args.output, overwrite=args.overwrite, inputs=inputs)
    check_outputs(args)   # -o and --csv: not the model, its records or the protocol file
    if args.plot:
        check_output_place(args.plot, "--plot", folder=True)
    ds = hysteresis_test(args.model, args.storey, args.protocol, args.amplitude)
    save_run(ds, args.output, overwrite=args.overwrite)
    print(f"wrote {args.output} ({ds.sizes['step']} steps; peak |shear| {abs(ds.storey_shear).max().item():.6g} N "
          f"at peak |drift| {abs(ds.storey_drift).max().item():.6g} m)")
    if args.csv:
        print(f"wrote {write_csv(ds, args.csv)}")
    if args.plot:
        for png in plot_hysteresis(ds, args.plot):
            print(f"wrote {png}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding hysteresis`` to *subparsers*."""
    parser = subparsers.add_parser(
        "hysteresis", help="quasi-static cyclic test of one storey (drift history in, storey shear out)",
        description="Drive one storey of MODEL alone (no mass, damping or P-Delta) through a drift history and "
                    "archive its storey shear: how a storey is calibrated against a test, and how its model is "
                    "checked against OpenSees' uniaxial materials (docs/hysteresis.md).")
    parser.add_argument("model", help="YAML model, e.g. models/pair_inelastic.yaml")
    parser.add_argument("--storey", required=True, metavar="BUILDING:LEVEL", help="the storey, e.g. A:1")
    parser.add_argument("--protocol", required=True, metavar="FILE|fema461|atc24",
                        help="a text file of storey drifts (m, one per line) or a named protocol: fema461 "
                             "(FEMA 461) or atc24 (ATC-24, in multiples of the storey's yield drift)")
    parser.add_argument("--amplitude", type=float, metavar="DRIFT_RATIO",
                        help="the named protocol's largest drift ratio (drift / storey height), e.g. 0.05")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.nc",
                        help="archive: storey_drift (m) and storey_shear (N) on the step dimension")
    parser.add_argument("--csv", metavar="OUT.csv", help="also write the two columns as CSV")
    parser.add_argument("--plot", metavar="DIR", help="write hysteresis.png to DIR")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.set_defaults(func=_cmd_hysteresis)
    return parser
