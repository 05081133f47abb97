"""``pounding sweep``: run a sweep file on all cores or a Dask cluster."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any, Callable

from pounding.cli.csv_option import add_csv_option, check_outputs, write_csv_option
from pounding.errors import PoundingError
from pounding.studies.engine.execution import default_workers

__all__ = ["register_cli", "add_cluster_options", "check_study_options", "summary_lines", "raise_if_all_failed",
           "print_study_warnings", "interrupted"]

# --------------------------------------------------------------------------- #
# Command line
# --------------------------------------------------------------------------- #


def add_cluster_options(parser: argparse.ArgumentParser) -> None:
    """--workers / --scheduler, shared with ``pounding compare``."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--workers", type=int, metavar="N",
                       help=f"worker processes of the local cluster (default: one per core, {default_workers()})")
    group.add_argument("--scheduler", metavar="ADDRESS",
                       help="use an existing Dask cluster, e.g. tcp://HOST:8786 (started with `dask scheduler` "
                            "and `dask worker tcp://HOST:8786`)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def check_study_options(args: argparse.Namespace) -> None:
    """Before a study runs (compare, gap): ``--workers`` >= 1, a writable ``-o``, a ``--plot`` that is no file."""
    from pounding.results.output_place import check_writable

    if args.workers is not None and args.workers < 1:
        raise PoundingError(f"--workers must be >= 1 (got {args.workers})")
    if args.output:
        check_writable(args.output, overwrite=args.overwrite)
    if args.plot:
        from pounding.results.output_place import check_output_place

        check_output_place(args.plot, "--plot", folder=True)


def summary_lines(ds) -> list[str]:
    """Counts and each distinct error of a sweep results dataset, with the scenarios it hit."""
    from pounding.studies.sweep.execution import failure_report

    status = ds.status.values.ravel()
    lines = [f"{status.size} scenarios: {int((status == 'ok').sum())} ok, {int((status != 'ok').sum())} failed"]
    if "run_status" in ds:
        ended = ds.run_status.values.ravel()
        for outcome in ("collapsed", "unstable"):
            if (ended == outcome).any():
                lines.append(f"  {int((ended == outcome).sum())} of the ok scenarios {outcome} before the record's "
                             "end (variable run_status; their peaks stop at end_time)")
    return lines + failure_report(ds)


def print_study_warnings(ds) -> None:
    """The study's warnings (archive attribute ``warnings``: each kind once, pounding.results.checks) on stderr."""
    import json

    from pounding.results.checks import print_warnings

    print_warnings(json.loads(ds.attrs.get("warnings", "[]")))


def interrupted(output, what: str = "scenarios", folder: Callable[[Any], Any] | None = None) -> int:
    """Say on stderr where an interrupted study keeps its finished *what* (records, runs...); the exit status 130.

    *folder* gives that place from *output* (default: the archive's parts folder,
    :func:`pounding.studies.engine.store.parts_dir`); nothing is kept without an *output*.
    """
    from pounding.studies.engine.store import parts_dir

    where = f"; finished {what} are kept in {(folder or parts_dir)(output)}: run the same command again" \
        if output else ""
    print(f"pounding: interrupted{where}", file=sys.stderr)
    return 130


def raise_if_all_failed(ds, output) -> None:
    """Print each distinct error on stderr and stop (status 2) when no scenario ran."""
    from pounding.studies.sweep.execution import failure_report

    if ds.status.size and not bool((ds.status == "ok").any()):
        for line in failure_report(ds):
            print(f"pounding: {line.strip()}", file=sys.stderr)
        where = f"; the errors are also in the variable 'error' of {output}" if output else ""
        raise PoundingError(f"all {ds.status.size} scenarios failed (errors above){where}")


def _announce_invalid(sweep, strict: bool) -> None:
    """Each axis value that makes the model invalid: a warning, or (``--strict``) the first one as the error."""
    invalid = sweep.invalid_values()
    if invalid and strict:
        raise PoundingError(invalid[0])
    for message in invalid:
        print(f"pounding: warning: {message}; its scenarios will record this error", file=sys.stderr)


def _cmd_sweep(args: argparse.Namespace) -> int:
    from pounding.studies.engine.store import parts_dir
    from pounding.studies.sweep.execution import plan_line, run_sweep
    from pounding.results.checks import axis_warning, print_warnings
    from pounding.studies.sweep.spec import load_sweep

    if args.workers is not None and args.workers < 1:
        raise PoundingError(f"--workers must be >= 1 (got {args.workers})")
    sweep = load_sweep(args.sweep)
    check_outputs(args, sweep=sweep)   # the sweep read once: each axis value is validated as a model
    output = Path(args.output) if args.output else Path(Path(args.sweep).stem + ".nc")
    _announce_invalid(sweep, args.strict)
    print_warnings(filter(None, (axis_warning(a.name, a.values, a.units) for a in sweep.axes if a.kind == "path")))
    print(plan_line(sweep), file=sys.stderr)
    try:
        ds = run_sweep(sweep, output, workers=args.workers, scheduler=args.scheduler,
                       keep_histories=args.keep_histories, overwrite=args.overwrite, keep_parts=args.keep_parts,
                       progress=not args.no_progress)
    except KeyboardInterrupt:
        store = parts_dir(output)
        count = len(list(store.glob("*.json"))) if store.is_dir() else 0
        print(f"pounding: interrupted; {count} finished scenarios are kept in {store}; run the same command "
              "again to finish the others", file=sys.stderr)
        return 130
    raise_if_all_failed(ds, output)
    for line in summary_lines(ds):
        print(line)
    print_study_warnings(ds)
    rate = ds.attrs["n_run"] / ds.attrs["elapsed_time"] if ds.attrs["elapsed_time"] > 0 else float("nan")
    if ds.attrs["n_run"]:
        print(f"ran {ds.attrs['n_run']} scenarios in {ds.attrs['elapsed_time']:.1f} s ({rate:.2f} scenarios/s)")
    print(f"wrote {output}")
    write_csv_option(args, "sweep", ds)
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding sweep`` to *subparsers*."""
    parser = subparsers.add_parser(
        "sweep", help="run a parameter sweep (sweeps/*.yaml) on all cores or a Dask cluster",
        description="Run every scenario of a sweep file on a Dask cluster (one worker process per core by "
                    "default) and write one NetCDF file of peaks. Finished scenarios are saved as they "
                    "complete, so the same command resumes an interrupted sweep.")
    parser.add_argument("sweep", help="sweep file, e.g. sweeps/gap_restitution.yaml")
    parser.add_argument("-o", "--output", help="NetCDF results (default: SWEEP-STEM.nc)")
    add_cluster_options(parser)
    parser.add_argument("--keep-histories", metavar="DIR", help="also archive each scenario's full results in DIR")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--keep-parts", action="store_true", help="keep OUTPUT.parts/ after writing OUTPUT")
    add_csv_option(parser)
    parser.add_argument("--strict", action="store_true",
                        help="stop if an axis value makes the model invalid (default: record the error)")
    parser.set_defaults(func=_cmd_sweep)
    return parser
