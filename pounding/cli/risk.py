"""``pounding risk``: the annual risk of pounding and of collapse at a site, from a hazard curve and stripes."""

from __future__ import annotations

import argparse
import sys

from pounding.cli.csv_option import add_csv_option, check_outputs, write_csv_option
from pounding.cli.spectrum import (add_spectrum_options, code_options, refuse_spectrum_without_code,
                                    warn_of_parameters)
from pounding.cli.sweep import add_cluster_options, check_study_options, interrupted
from pounding.errors import PoundingError

__all__ = ["register_cli"]


def _codes(args: argparse.Namespace) -> dict[str, dict]:
    """{code: its design spectrum's options} of ``--code`` (empty without it); one line for an unknown code, a
    missing spectrum option, or a spectrum option without ``--code``."""
    if not args.code:
        refuse_spectrum_without_code(args)
        return {}
    codes = [c.strip() for c in args.code.split(",") if c.strip()]
    for code in codes:
        if code not in ("asce7-22", "ec8"):
            raise PoundingError(f"--code: unknown code {code!r}; give asce7-22, ec8 or asce7-22,ec8")
    found = {code: code_options(args, code) for code in codes}
    for code in codes:
        warn_of_parameters(args, code)
    return found


def _cmd_risk(args: argparse.Namespace) -> int:
    from pounding.model.model import load_model
    from pounding.results.checks import model_warnings, print_warnings
    from pounding.studies.risk import build_risk_plan, plot_risk, read_hazard, risk_study, risk_table

    check_study_options(args)
    check_outputs(args)
    curve = read_hazard(args.hazard)
    codes = _codes(args)
    plan = build_risk_plan(args.model, curve, im=args.im, records=args.records, levels=args.levels,
                           stripes=args.stripes, building=args.building, target=args.target,
                           duration=args.duration, collapse_drift=args.collapse_drift, codes=codes)
    ida = plan.ida
    print(f"risk of '{ida.model_name}': {len(ida.records)} records x {len(ida.levels)} stripes x 2 variants = "
          f"{ida.planned_runs()} runs; IM {ida.im.describe()}; {curve.describe()}", file=sys.stderr)
    model = load_model(args.model)
    print_warnings([*model.warnings, *model_warnings(model).values(), *ida.warnings])
    try:
        ds = risk_study(plan, args.output, workers=args.workers, scheduler=args.scheduler, overwrite=args.overwrite,
                        progress=not args.no_progress)
    except KeyboardInterrupt:
        return interrupted(args.output, "runs")
    ran = ds.status.values != "failed"
    if not ran.any():
        raise PoundingError(f"all {ds.status.size} runs failed: {ds.error.values.ravel()[0]}")
    print(risk_table(ds))
    failed = int((~ran).sum())
    if failed:
        print(f"pounding: {failed} run(s) failed (left out of their stripes); see the variable 'error'",
              file=sys.stderr)
    if ds.attrs.get("n_run"):
        print(f"ran {ds.attrs['n_run']} runs in {ds.attrs['elapsed_time']:.1f} s")
    if args.output:
        print(f"wrote {args.output}")
    write_csv_option(args, "risk", ds)
    if args.plot:
        for png in plot_risk(ds, args.plot):
            print(f"wrote {png}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding risk`` to *subparsers*."""
    parser = subparsers.add_parser(
        "risk", help="annual risk of pounding and of collapse at a site (hazard curve x stripes)",
        description="Run the model over a record set at stripes of intensity spanning a site's hazard curve, with "
                    "its contacts and with them held open; integrate over the curve the probability of pounding "
                    "at every separation (per contact) and of collapse (per building). See docs/risk.md.")
    parser.add_argument("model", help="YAML model with contacts, e.g. models/pair.yaml")
    parser.add_argument("--hazard", required=True, metavar="FILE|power:k0,k|example",
                        help="the site's hazard curve: a file of two columns (intensity in g, mean annual "
                             "frequency of exceedance 1/yr), power:k0,k (k0 x^-k, x in g), or example (shipped, "
                             "synthetic, Sa(1.0 s))")
    parser.add_argument("--im", default="sa-t1", metavar="IM",
                        help="the hazard curve's intensity measure: sa:T (e.g. sa:1.0), sa-avg:T1,T2, pga, or "
                             "sa-t1 (Sa at the first period of --building; the default)")
    parser.add_argument("--records", metavar="SET|LIST", help="a record set (fema-p695:farfield...) or a "
                                                              "comma-separated list (default: the model's record)")
    parser.add_argument("--building", help="the building of sa-t1 (default: the first)")
    stripes = parser.add_mutually_exclusive_group()
    stripes.add_argument("--stripes", type=int, default=8, metavar="N",
                         help="N stripes evenly spaced in ln IM from the curve's 50-year to its 10,000-year "
                              "intensity (8)")
    stripes.add_argument("--levels", metavar="A:B:STEP", help="the stripes in g instead, as pounding ida --levels")
    parser.add_argument("--target", default="2%/50y", metavar="P/Ty",
                        help="probability of pounding to meet, e.g. 2%%/50y (the default) or 10%%/50y")
    parser.add_argument("--collapse-drift", type=float, metavar="RATIO",
                        help="every building's collapse drift ratio, as pounding ida --collapse-drift")
    parser.add_argument("--duration", type=float, help="simulated time of every run, s (default: the model's)")
    parser.add_argument("-o", "--output", metavar="RISK.nc", help="also write the results (NetCDF); resumable")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--plot", metavar="DIR", help="write pounding_risk.png to DIR")
    parser.add_argument("--code", metavar="CODE[,CODE]",
                        help="also the risk of pounding at each code's separation: asce7-22, ec8 or both "
                             "(comma-separated), from each building's design: factors and the code's design "
                             "spectrum (--sds/--sd1, --ag... as pounding gap --code); docs/risk.md")
    add_spectrum_options(parser, "asce7-22")
    add_spectrum_options(parser, "ec8", q=False)
    add_csv_option(parser)
    add_cluster_options(parser)
    parser.set_defaults(func=_cmd_risk)
    return parser
