"""``pounding spectrum``: print, plot or write a code's design spectrum (ASCE 7-22, Eurocode 8, a user table)."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

from pounding.errors import PoundingError

__all__ = ["register_cli", "spectrum_from_args", "add_spectrum_options", "spectrum_table", "warn_of_parameters"]


def spectrum_from_args(args: argparse.Namespace, *, code: str | None = None):
    """The :class:`~pounding.records.design_spectra.DesignSpectrum` named by the parsed options.

    *code* (``asce7-22``, ``ec8``, ``user``) defaults to ``args.code``.
    """
    from pounding.records import design_spectra as ds

    code = code or args.code
    if code == "asce7-22":
        missing = [f"--{name}" for name in ("sds", "sd1") if getattr(args, name) is None]
        if missing:
            raise PoundingError(f"the ASCE 7-22 spectrum needs {' and '.join(missing)} (g)")
        return ds.asce7_22_spectrum(args.sds, args.sd1, args.tl, mce=getattr(args, "mce", False))
    if code == "ec8":
        missing = [f"--{name}" for name in ("ag",) if getattr(args, name) is None]
        if missing:
            raise PoundingError("the Eurocode 8 spectrum needs --ag (design ground acceleration on ground A, g)")
        return ds.ec8_spectrum(args.type, args.ground, args.ag, q=args.q, damping=args.damping, beta=args.beta)
    if code == "user":
        if not getattr(args, "spectrum_file", None):
            raise PoundingError("a user spectrum needs a file of two columns, period (s) and Sa (g)")
        return ds.read_user_spectrum(args.spectrum_file)
    raise PoundingError(f"unknown code {code!r}; choose asce7-22, ec8 or user")  # pragma: no cover


def warn_of_parameters(args: argparse.Namespace, code: str) -> None:
    """The ``spectrum`` warning (:func:`pounding.results.checks.spectrum_warnings`) of the parsed options of *code*'s
    spectrum (``asce7-22``: S_DS, S_D1; ``ec8``: a_g), on stderr."""
    from pounding.results.checks import print_warnings, spectrum_warnings

    given = {"asce7-22": {"S_DS": "sds", "S_D1": "sd1"}, "ec8": {"a_g": "ag"}}.get(code, {})
    print_warnings(spectrum_warnings({name: getattr(args, key, None) for name, key in given.items()}).values())


def refuse_spectrum_without_code(args: argparse.Namespace) -> None:
    """A design spectrum's option (--sds, --sd1, --ag) given without --code is refused in one line."""
    given = [option for option, value in (("--sds", args.sds), ("--sd1", args.sd1), ("--ag", args.ag))
             if value is not None]
    if given:
        raise PoundingError(f"{given[0]} sets a design spectrum: give --code asce7-22 or --code ec8 with it")


def code_options(args: argparse.Namespace, code: str, option: str = "--code") -> dict:
    """The design spectrum's options of *code* (``asce7-22``: sds, sd1, tl; ``ec8``: type, ground, ag, beta) from
    the parsed *args*, each missing one refused in one line naming *option*."""
    if code == "asce7-22":
        missing = [f"--{name}" for name in ("sds", "sd1") if getattr(args, name) is None]
        if missing:
            raise PoundingError(f"{option} asce7-22 needs {' and '.join(missing)} (g)")
        return {"sds": args.sds, "sd1": args.sd1, "tl": args.tl}
    if args.ag is None:
        raise PoundingError(f"{option} ec8 needs --ag (design ground acceleration on ground type A, g)")
    return {"type": args.type, "ground": args.ground, "ag": args.ag, "beta": args.beta}


def add_spectrum_options(parser: argparse.ArgumentParser, code: str, *, q: bool = True) -> None:
    """The options of one code's spectrum (shared by ``pounding spectrum`` and ``pounding gap --code``).

    Without *q* (``pounding gap``, where each building brings its own q) neither ``--q`` nor ``--damping``.
    """
    if code == "asce7-22":
        parser.add_argument("--sds", type=float, help="S_DS, design spectral acceleration at short periods, g")
        parser.add_argument("--sd1", type=float, help="S_D1, design spectral acceleration at 1 s, g")
        parser.add_argument("--tl", type=float, default=8.0, help="T_L, long-period transition period, s (default 8)")
    elif code == "ec8":
        parser.add_argument("--type", type=int, default=1, choices=(1, 2),
                            help="spectrum type (EN 1998-1 §3.2.2.2: 1 for Ms > 5.5, 2 otherwise; default 1)")
        parser.add_argument("--ground", default="B", help="ground type A-E (Tables 3.2/3.3; default B)")
        parser.add_argument("--ag", type=float, help="design ground acceleration on type A ground a_g, g")
        if q:
            parser.add_argument("--q", type=float, help="behaviour factor q: the design spectrum of §3.2.2.5 "
                                                        "(default: the elastic spectrum of §3.2.2.2)")
            parser.add_argument("--damping", type=float, default=0.05,
                                help="damping ratio of the elastic spectrum (eta of (3.6); default 0.05)")
        parser.add_argument("--beta", type=float, default=0.2, help="lower-bound factor beta of §3.2.2.5 (default 0.2)")


def spectrum_table(spectrum, periods: np.ndarray) -> str:
    """The spectrum as a printed table: period (s), Sa (g), Sd (mm)."""
    from pounding.units import STANDARD_GRAVITY

    sa = spectrum.sa(periods)
    with np.errstate(divide="ignore", invalid="ignore"):
        sd = np.where(periods > 0, sa * STANDARD_GRAVITY * (periods / (2 * np.pi)) ** 2, 0.0)
    lines = [spectrum.name, f"  {spectrum.clause}", f"{'T (s)':>8} {'Sa (g)':>9} {'Sd (mm)':>9}"]
    lines += [f"{t:8.3f} {a:9.4f} {1000 * d:9.1f}" for t, a, d in zip(periods, sa, sd)]
    return "\n".join(lines)


def _periods(text: str | None, spectrum) -> np.ndarray:
    from pounding.records.design_spectra import spectrum_periods

    if text is None:
        return spectrum_periods(spectrum)
    parts = text.split(":")
    try:
        start, stop, step = (float(p) for p in parts)
    except ValueError:
        raise PoundingError(f"--periods must be START:STOP:STEP in s, e.g. 0:4:0.05 (got {text!r})") from None
    if not (0 <= start < stop and step > 0) or (stop - start) / step > 100_000:
        raise PoundingError(f"--periods must be START:STOP:STEP with 0 <= START < STOP and a STEP > 0 giving at most "
                            f"100000 periods (got {text!r})")
    return np.round(np.arange(start, stop + 0.5 * step, step), 10)


def _cmd_spectrum(args: argparse.Namespace) -> int:
    from pounding.units import STANDARD_GRAVITY

    from pounding.cli.csv_option import check_outputs
    from pounding.results.output_place import check_output_place

    check_outputs(args)   # --csv: not the user spectrum's own file
    if args.plot:   # a file
        check_output_place(args.plot, "--plot", folder=False, inputs=[getattr(args, "spectrum_file", None)])
    spectrum = spectrum_from_args(args)
    warn_of_parameters(args, args.code)
    periods = _periods(args.periods, spectrum)
    print(spectrum_table(spectrum, periods))
    if args.csv:   # the headers and the atomic writing of every pounding CSV (pounding.results.tables)
        import pandas as pd

        from pounding.results.tables import write_csv

        sa = spectrum.sa(periods)
        table = pd.DataFrame({"period [s]": periods, "Sa [g]": sa,
                              "Sd [m]": sa * STANDARD_GRAVITY * (periods / (2 * np.pi)) ** 2})
        for path in write_csv({"spectrum": table}, args.csv):
            print(f"wrote {path}")
    if args.plot:
        from pounding.results.plots import pyplot, save_figure

        plt = pyplot()
        target = Path(args.plot)
        if target.parent and not target.parent.exists():
            os.makedirs(target.parent, exist_ok=True)
        dense = np.unique(np.concatenate([np.linspace(periods[0], periods[-1], 801), periods]))
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        ax.plot(dense, spectrum.sa(dense), color="k", lw=1.6)
        ax.set_xlabel("period T (s)")
        ax.set_ylabel("Sa (g)")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.set_title(f"{spectrum.name}\n{spectrum.clause}", fontsize=8)
        print(f"wrote {save_figure(fig, target)}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding spectrum {asce7-22, ec8, user}`` to *subparsers*."""
    parser = subparsers.add_parser(
        "spectrum", help="print or plot a design spectrum (ASCE 7-22, Eurocode 8, a user table)",
        description="Print a code's design response spectrum as a table (period, Sa in g, Sd in mm), optionally "
                    "plot it or write it as CSV. See docs/design-codes.md.")
    codes = parser.add_subparsers(dest="code", required=True, metavar="CODE")
    asce = codes.add_parser("asce7-22", help="ASCE 7-22 two-period design spectrum (§11.4.5.2), or MCE_R",
                            description="ASCE 7-22 two-period design response spectrum; --mce: the MCE_R spectrum, "
                                        "1.5 x design. A multi-period spectrum (§11.4.5.1, USGS site data) is "
                                        "given as a user table: pounding spectrum user FILE.")
    add_spectrum_options(asce, "asce7-22")
    asce.add_argument("--mce", action="store_true", help="the MCE_R spectrum (1.5 x design, §11.4.6)")
    ec8 = codes.add_parser("ec8", help="Eurocode 8 elastic (§3.2.2.2) or design spectrum (§3.2.2.5, --q)",
                           description="EN 1998-1 horizontal spectrum: elastic (§3.2.2.2) or, with --q, the design "
                                       "spectrum for elastic analysis (§3.2.2.5).")
    add_spectrum_options(ec8, "ec8")
    user = codes.add_parser("user", help="a two-column file: period (s), Sa (g)",
                            description="A spectrum from a text file of two columns, period (s) and Sa (g), linear "
                                        "between rows; '#' starts a comment line.")
    user.add_argument("spectrum_file", metavar="FILE", help="two columns: period (s), Sa (g)")
    for sub in (asce, ec8, user):
        sub.add_argument("--periods", metavar="START:STOP:STEP",
                         help="periods of the table, s (default 0 to 4 s every 0.1 s with the corner periods)")
        sub.add_argument("--csv", metavar="FILE", help="also write the table as CSV (period s, Sa g, Sd m)")
        sub.add_argument("--plot", metavar="FILE", help="also plot the spectrum to FILE (PNG)")
        sub.set_defaults(func=_cmd_spectrum)
    return parser
