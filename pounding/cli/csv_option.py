"""The ``--csv FILE`` option of run, compare, gap, sweep, ida and p695, the tables of each archive kind, and the
check that no output of a command is one of its inputs.

One table-building function per archive kind (:func:`archive_tables`), so
that ``pounding table`` on an archive (:mod:`pounding.cli.table`) and
``--csv`` on the command that wrote it give the same tables.  Light at
import: the functions import what they need.
"""

from __future__ import annotations

import argparse
import glob
import os
from pathlib import Path

__all__ = ["archive_tables", "add_csv_option", "check_outputs", "command_inputs", "archived_inputs",
           "write_csv_option", "CSV_HELP"]

CSV_HELP = ("also write the results as CSV tables, units in the headers: the main table to FILE, the others "
            "beside it as STEM.NAME.csv (see `pounding table`)")


def archive_tables(kind: str, ds) -> dict:
    """The tables (``{name: pandas.DataFrame}``, main table first) of an archive of *kind*.

    *kind* is what :func:`pounding.cli.run.open_archive` returns: ``run`` (a run of any model), ``sweep``,
    ``compare``, ``gap``, ``gap-code``, ``ida``, ``pushover``, ``hysteresis`` or ``verify``.
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
    if kind == "gap-code":
        from pounding.studies.design_check import code_gap_tables

        return code_gap_tables(ds)
    if kind == "ida":
        from pounding.studies.ida.report import ida_tables

        return ida_tables(ds)
    if kind == "risk":
        from pounding.studies.risk import risk_tables

        return risk_tables(ds)
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


def check_outputs(args: argparse.Namespace, inputs: list | tuple = (), *, model=None, sweep=None) -> None:
    """Before anything runs: no file the command writes is one of the files it reads.

    The outputs are ``-o``, ``--csv`` and the tables written beside it (``STEM.NAME.csv``); the inputs
    are :func:`command_inputs` and *inputs*, compared after resolving links and ``..``.  ``--csv`` is
    also checked for its place (not a folder, not under a file, its folder writable).  *model*, the
    command's ``MODEL`` already loaded, and *sweep*, its ``SWEEP`` file already read, spare reading them
    again (:func:`command_inputs`: a sweep file's every axis value is validated as a model).

    Raises
    ------
    ArchiveError
        Naming the output and the input it would destroy.
    """
    from pounding.results.output_place import check_not_input, check_output_place

    read = [*command_inputs(args, model=model, sweep=sweep), *inputs]
    output = getattr(args, "output", None)
    if output:
        check_not_input(output, read, "-o")
    if getattr(args, "csv", None):
        csv = Path(args.csv)
        check_output_place(csv, "--csv", folder=False, inputs=[*read, output])
        stem = csv.name[:-4] if csv.name.lower().endswith(".csv") else csv.name
        folder = csv.parent if str(csv.parent) else Path(".")
        for beside in (folder.glob(f"{glob.escape(stem)}.*.csv") if folder.is_dir() else ()):
            check_not_input(beside, [*read, output], f"--csv {csv} writes tables beside it, and")


def command_inputs(args: argparse.Namespace, *, model=None, sweep=None) -> list[str]:
    """Every file the command of *args* reads that its outputs could land on.

    The model (``MODEL``) with its record files (:func:`pounding.simulation.model_inputs`: the model's
    record, each building's, the components of a pair), ``--record``, files among ``--records``, a sweep
    file with its base model and records, an archive (``table``, ``rerun``: the records a rerun reads
    again), a user spectrum and a cyclic protocol file.  A model or archive that cannot be read adds only
    its own name: the command refuses it in its own words.  *model* is ``MODEL`` if the command has
    loaded it already (:class:`pounding.model.model.Model`), *sweep* its ``SWEEP`` file if read already
    (:class:`pounding.studies.sweep.spec.Sweep`); else each is read here.
    """
    found: list[str] = []
    for name in ("model", "sweep", "archive", "run", "spectrum_file", "protocol", "record"):
        value = getattr(args, name, None)
        if isinstance(value, str) and value:
            found.append(value)
    found += [item.strip() for item in (getattr(args, "records", None) or "").split(",") if os.path.isfile(item.strip())]
    from pounding.errors import PoundingError

    try:
        if isinstance(getattr(args, "model", None), str):
            from pounding.model.model import load_model
            from pounding.simulation import model_inputs

            found += model_inputs(load_model(args.model) if model is None else model)
        if isinstance(getattr(args, "sweep", None), str):
            from pounding.studies.sweep import load_sweep
            from pounding.studies.sweep.execution import sweep_inputs

            found += sweep_inputs(load_sweep(args.sweep) if sweep is None else sweep)
        if isinstance(getattr(args, "run", None), str):
            found += archived_inputs(args.run)
    except (PoundingError, OSError):
        pass
    return found


def archived_inputs(path: str) -> list[str]:
    """The files a rerun of the archive *path* reads again: its model file and record files."""
    import json

    from pounding.model.model import model_from_text
    from pounding.results.archive import open_run
    from pounding.simulation import model_inputs

    attrs = open_run(path).attrs
    spec = json.loads(attrs["run_spec"])
    model = model_from_text(spec["model"], name=attrs.get("model_name", "model"),
                            path=attrs.get("model_path") or None, base_dir=spec.get("base_dir"))
    return model_inputs(model)


def write_csv_option(args: argparse.Namespace, kind: str, ds, out=None) -> None:
    """Write the tables of *ds* (an archive of *kind*) where ``--csv`` says, if it was given; print each file."""
    if not getattr(args, "csv", None):
        return
    from pounding.results.tables import write_csv

    tables = archive_tables(kind, ds)
    for path in write_csv(tables, args.csv):
        print(f"wrote {path}", file=out)
