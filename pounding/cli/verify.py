"""``pounding verify``: the ball-drop verification of the contact laws (Ye, Li & Zhu 2009, Table I)."""

from __future__ import annotations

import argparse
import json

from pounding.errors import PoundingError

__all__ = ["register_cli"]


def _float_list(text: str) -> list[float]:
    try:
        values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise PoundingError(f"--e-pre: expected comma-separated numbers such as 0.1,0.5,0.9 (got '{text}')") \
            from None
    if not values:
        raise PoundingError("--e-pre: give at least one value")
    return values


class _ModelList(argparse.Action):
    """``--models LIST``, whose help names the model keys only when help is shown.

    The keys come from :mod:`pounding.studies.verify`, whose imports (xarray, the compiled
    contact kernels) take ~0.4 s: registering the subcommand, as ``pounding --help`` does for
    every subcommand, must not pay them.
    """

    @property
    def help(self) -> str:  # type: ignore[override]
        from pounding.studies.verify import OTHER_MODELS

        return "model keys, e.g. ye,exact (default: all; xi formulas and " + ", ".join(OTHER_MODELS) + ")"

    @help.setter
    def help(self, value) -> None:  # argparse.Action.__init__ sets it; the property above is the help
        pass

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        setattr(namespace, self.dest, values)


def _cmd_verify(args: argparse.Namespace) -> int:
    """Handler of ``pounding verify``."""
    from pounding.results.archive import save_run
    from pounding.results.output_place import check_writable
    from pounding.studies.verify import DEFAULT_E_PRE, format_report, plot_verification, run_verification, to_json

    if args.output:
        check_writable(args.output, overwrite=args.overwrite)  # before computing anything
    e_pre = _float_list(args.e_pre) if args.e_pre else list(DEFAULT_E_PRE)
    models = [m.strip() for m in args.models.split(",") if m.strip()] if args.models else None
    if models is not None and not models:
        raise PoundingError("--models: give at least one model key")
    ds = run_verification(e_pre, models, mass=args.mass, height=args.height, kh=args.kh, gravity=args.gravity)
    if args.json:
        print(json.dumps(to_json(ds), indent=2))
    else:
        print(format_report(ds))
    if args.output:
        path = save_run(ds, args.output, overwrite=args.overwrite, keep_beside=True)
        if not args.json:
            print(f"wrote {path}")
    if args.plot:
        path = plot_verification(ds, args.plot)
        if not args.json:
            print(f"wrote {path}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add the ``verify`` subcommand to *subparsers* (from ``add_subparsers``)."""
    parser = subparsers.add_parser(
        "verify", help="ball-drop verification of the contact laws (Ye, Li & Zhu 2009, Table I)",
        description="Drop a ball on a rigid surface with every contact model and compare the restitution "
                    "produced with the one prescribed (Ye, Li & Zhu 2009, Table I).")
    parser.add_argument("--e-pre", metavar="LIST", help="prescribed restitutions, e.g. 0.1,0.5,0.9 "
                        "(default 0.1,0.2,...,1.0)")
    parser.add_argument("--models", metavar="LIST", action=_ModelList)
    parser.add_argument("--mass", type=float, default=0.5, help="ball mass, kg (default 0.5)")
    parser.add_argument("--height", type=float, default=0.5, help="drop height, m (default 0.5)")
    parser.add_argument("--kh", type=float, default=2.0e9, help="Hertz stiffness, N/m^1.5 (default 2e9)")
    parser.add_argument("--gravity", type=float, default=9.81, help="gravity, m/s^2 (default 9.81; 0 = free "
                        "impact at the velocity of a standard drop)")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    parser.add_argument("-o", "--output", metavar="FILE.nc", help="write the results dataset (NetCDF)")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--plot", metavar="FILE.png", help="draw e_post vs e_pre for every model")
    parser.set_defaults(func=_cmd_verify)
    return parser
