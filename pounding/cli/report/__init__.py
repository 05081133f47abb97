"""``pounding report ARCHIVE [ARCHIVE ...] -o REPORT.html``: one self-contained HTML file of any archives.

A section per archive (:mod:`pounding.cli.report.sections`), laid out by
:mod:`pounding.cli.report.html`; what differs between archive kinds is in
:mod:`pounding.cli.report.kinds`.  See docs/reports.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Sequence

__all__ = ["register_cli", "write_report", "report_html"]


def report_html(archives: Sequence[str | Path]) -> str:
    """The report of *archives* (NetCDF files of any kind pounding writes) as HTML text.

    Raises
    ------
    ArchiveError
        One line naming the archive that is missing, unreadable, not a pounding archive, of an unknown
        kind or damaged.
    """
    from pounding.cli.report.html import render
    from pounding.cli.report.kinds import kind_of
    from pounding.cli.report.sections import archive_section
    from pounding.cli.run import open_archive

    opened = []
    for archive in archives:   # every archive checked before any figure is drawn
        name, ds = open_archive(archive)
        opened.append((Path(archive), kind_of(name, str(archive)), ds))
    sections = [archive_section(i, path, kind, ds) for i, (path, kind, ds) in enumerate(opened, start=1)]
    from pounding import __version__

    title = (f"pounding report: {opened[0][0].name}" if len(opened) == 1 else
             f"pounding report: {len(opened)} archives")
    return render(sections, title, [("archives", ", ".join(str(p) for p, _, _ in opened)),
                                    ("made by", f"pounding {__version__}")])


def write_report(archives: Sequence[str | Path], output: str | Path, *, overwrite: bool = False) -> Path:
    """Write the report of *archives* to *output* (HTML, atomically); returns the path written.

    Raises
    ------
    ArchiveError
        *output* exists (without *overwrite*), is one of *archives* or cannot be written; or an archive
        cannot be read (:func:`report_html`).
    """
    from pounding.results.archive import atomic_path
    from pounding.results.output_place import check_writable

    target = check_writable(output, overwrite=overwrite, inputs=list(archives), example="report.html")
    text = report_html(archives)
    with atomic_path(target) as temporary:
        Path(temporary).write_text(text, encoding="utf-8")
    return target


def _cmd_report(args: argparse.Namespace) -> int:
    from pounding.cli.csv_option import check_outputs

    check_outputs(args, inputs=args.archives)
    path = write_report(args.archives, args.output, overwrite=args.overwrite)
    print(f"wrote {path}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding report`` to *subparsers*."""
    parser = subparsers.add_parser(
        "report", help="one self-contained HTML report of one or more archives",
        description="Write one HTML file (figures embedded, nothing fetched from the network) with a section "
                    "per archive: what was modelled, under what, the run status and warnings, the tables and "
                    "figures of its kind and the command that makes it again. See docs/reports.md.")
    parser.add_argument("archives", nargs="+", metavar="ARCHIVE",
                        help="NetCDF file written by run, rerun, sweep, compare, gap, ida, risk, p695, pushover, "
                             "hysteresis or verify")
    parser.add_argument("-o", "--output", required=True, metavar="REPORT.html", help="the HTML file to write")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing report")
    parser.set_defaults(func=_cmd_report)
    return parser
