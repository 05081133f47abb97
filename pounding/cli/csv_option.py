"""The ``--csv FILE`` option of run, compare, gap, sweep, ida and p695, and the tables of each archive kind.

One table-building function per archive kind (:func:`archive_tables`), so
that ``pounding table`` on an archive (:mod:`pounding.cli.table`) and
``--csv`` on the command that wrote it give the same tables.  Light at
import: the functions import what they need.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["archive_tables", "add_csv_option", "check_csv", "write_csv_option", "CSV_HELP"]

CSV_HELP = ("also write the results as CSV tables, units in the headers: the main table to FILE, the others "
            "beside it as STEM.NAME.csv (see `pounding table`)")


def archive_tables(kind: str, ds) -> dict:
    """The tables (``{name: pandas.DataFrame}``, main table first) of an archive of *kind*.

    *kind* is what :func:`pounding.cli.run.open_archive` returns: ``run`` (a run of any model), ``sweep``,
    ``compare``, ``gap``, ``ida``, ``pushover``, ``hysteresis`` or ``verify``.
    """
    if kind == "run":
        from pounding.results.tables import run_tables

        return run_tables(ds)
    if kind == "sweep":
        from pounding.results.tables import sweep_tables

        return sweep_tables(ds)
    if kind == "compare":
        from pounding.studies.compare import compare_tables

        return compare_tables(ds)
    if kind == "gap":
        from pounding.studies.gap import gap_tables

        return gap_tables(ds)
    if kind == "ida":
        from pounding.studies.ida.report import ida_tables

        return ida_tables(ds)
    if kind == "p695":
        from pounding.studies.p695.report import p695_tables

        return p695_tables(ds)
    if kind == "pushover":
        from pounding.studies.pushover import pushover_tables

        return pushover_tables(ds)
    if kind == "hysteresis":
        from pounding.studies.cyclic import hysteresis_tables

        return hysteresis_tables(ds)
    from pounding.studies.verify import verify_tables

    return verify_tables(ds)


def add_csv_option(parser: argparse.ArgumentParser) -> None:
    """``--csv FILE`` on a command that writes results."""
    parser.add_argument("--csv", metavar="FILE", help=CSV_HELP)


def check_csv(args: argparse.Namespace, inputs: list | tuple = ()) -> None:
    """Before anything runs: ``--csv`` is not a folder and not one of the command's *inputs*."""
    from pounding.errors import PoundingError
    from pounding.results.archive import check_not_input, check_output_place

    if getattr(args, "csv", None):
        if Path(args.csv).is_dir():
            raise PoundingError(f"--csv {args.csv} is a directory; give a file name such as "
                                f"{Path(args.csv) / 'results.csv'}")
        check_output_place(args.csv, "--csv", folder=False)
        check_not_input(args.csv, [*inputs, getattr(args, "output", None)])


def write_csv_option(args: argparse.Namespace, kind: str, ds, out=None) -> None:
    """Write the tables of *ds* (an archive of *kind*) where ``--csv`` says, if it was given; print each file."""
    if not getattr(args, "csv", None):
        return
    from pounding.results.tables import write_csv

    tables = archive_tables(kind, ds)
    for path in write_csv(tables, args.csv):
        print(f"wrote {path}", file=out)
