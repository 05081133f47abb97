"""``pounding table ARCHIVE [--csv FILE]``: any archive's results as tables (:mod:`pounding.cli.csv_option`)."""

from __future__ import annotations

import argparse

from pounding.cli.csv_option import archive_tables, check_outputs, write_csv_option

__all__ = ["register_cli"]


def _cmd_table(args: argparse.Namespace) -> int:
    from pounding.cli.run import open_archive
    from pounding.results.tables import format_tables

    check_outputs(args)
    kind, ds = open_archive(args.archive)
    if args.csv:
        write_csv_option(args, kind, ds)
    else:
        print(format_tables(archive_tables(kind, ds), f"{args.archive}: {ds.attrs.get('title', kind)} "
                                                      f"[{kind} archive]"))
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding table`` to *subparsers*."""
    parser = subparsers.add_parser(
        "table", help="print an archive's results as tables, or write them as CSV",
        description="Print the tables of any archive (run: per storey, contact and link, and of a plan run per plane, floor "
                    "and corner; sweep and compare: per "
                    "scenario and storey or contact; gap: per contact, rule and record; ida: fragility and "
                    "runs; pushover: per building, step and storey; hysteresis: per step; verify: per law), units in the headers, or write them as CSV files with --csv.")
    parser.add_argument("archive", metavar="ARCHIVE", help="NetCDF file written by run, rerun, sweep, compare, "
                        "gap, ida, pushover, hysteresis or verify")
    parser.add_argument("--csv", metavar="FILE", help="write the main table to FILE and the others beside it as "
                        "STEM.NAME.csv instead of printing them")
    parser.set_defaults(func=_cmd_table)
    return parser
