"""``pounding run | rerun | info | plot | xi``: one run, its archive and the ξ catalogue."""

from __future__ import annotations

import argparse
import time
from contextlib import contextmanager
from pathlib import Path

from pounding.cli.csv_option import add_csv_option, check_outputs, write_csv_option

__all__ = ["summary", "register_cli", "parse_scale_option", "SCALE_HELP", "open_archive", "add_plot_options", "outcome_status",
           "UNTRUSTED_RUN_STATUS", "archive_summary", "draw_figures", "stored_warnings",
           "damaged_if_garbled"]

SCALE_HELP = ("factor on the record (0.8), or a target as in the YAML: a PGA (0.4g, 3.9m/s2, 390gal), "
              "sa=0.8g@1.0 (Sa at 1.0 s, 5%% damping), sa=0.8g@A (at building A's first period), "
              "sa=0.8g@1.0,damping=0.02, or fema-p695 (the FEMA P695 normalisation)")


def parse_scale_option(text: str, buildings=None):
    """``--scale`` text as the YAML's ``ground_motion.scale`` value: a factor or a target mapping.

    ``0.8`` → 0.8; ``0.4g`` or ``pga=0.4g`` → ``{pga: 0.4g}``; ``sa=0.8g@1.0``
    → ``{sa: 0.8g, period: 1.0}``; ``sa=0.8g@A`` → ``{sa: 0.8g, period:
    building A}``; ``,damping=0.02`` adds the damping ratio; ``fema-p695`` →
    ``{fema-p695: true}``.  The result is checked with
    :func:`pounding.records.processing.parse_scale`.
    """
    from pounding.errors import PoundingError
    from pounding.records.processing import SpecProblem, parse_scale

    raw = str(text).strip()
    value: object
    try:
        value = float(raw)
    except ValueError:
        lowered = raw.lower().replace(" ", "")
        if lowered in ("fema-p695", "fema-p695=true"):
            value = {"fema-p695": True}
        elif "=" not in lowered:
            value = {"pga": raw}
        else:
            value = {}
            for part in raw.split(","):
                key, _, item = part.partition("=")
                key, item = key.strip().lower(), item.strip()
                if key == "sa" and "@" in item:
                    item, _, period = item.partition("@")
                    period = period.strip()
                    try:
                        value["period"] = float(period.rstrip("sS"))
                    except ValueError:
                        value["period"] = period if period.lower().startswith("building") else f"building {period}"
                if key == "damping":
                    try:
                        value[key] = float(item)
                    except ValueError:
                        value[key] = item
                else:
                    value[key] = item.strip()
    try:
        parse_scale(value, buildings)
    except SpecProblem as problem:
        detail = problem.message("--scale", None if problem.kind != "must" else raw)
        raise PoundingError(f"{detail}; write --scale 0.8 (a factor), --scale 0.4g (a PGA), --scale sa=0.8g@1.0 "
                            "(Sa at 1.0 s), --scale sa=0.8g@A (at building A's first period) or --scale fema-p695"
                            ) from None
    return value


# --------------------------------------------------------------------------- #
# Summaries
# --------------------------------------------------------------------------- #


def summary(ds) -> str:
    """A run archive's summary, of any model (:func:`pounding.results.summary.run_summary`)."""
    from pounding.results.summary import run_summary

    return run_summary(ds)


@contextmanager
def damaged_if_garbled(source):
    """Turn a missing or garbled variable met while reading archive *source* into a one-line error."""
    from pounding.errors import ArchiveError

    try:
        yield
    except (KeyError, ValueError, TypeError, AttributeError, IndexError) as exc:
        raise ArchiveError(f"damaged archive: {source}: {type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:120]}") from None


def _check_plot_dir(directory: str) -> None:
    """Fail before any computation if --plot DIR cannot be created or written."""
    from pounding.results.output_place import check_output_place

    check_output_place(directory, "--plot", folder=True)


# --------------------------------------------------------------------------- #
# Commands
# --------------------------------------------------------------------------- #


def _cmd_run(args: argparse.Namespace) -> int:
    from pounding.results.output_place import check_writable

    started = time.perf_counter()
    output = Path(args.output) if args.output else Path(Path(args.model).stem + ".nc")
    check_writable(output, overwrite=args.overwrite, inputs=[args.model])  # before computing or importing xarray
    if args.plot:
        _check_plot_dir(args.plot)
    from pounding.results.archive import output_lock

    model = _model_or_none(args.model)   # read once: for the inputs checked here and for the run
    check_outputs(args, model=model)
    with output_lock(output):   # a second run onto the same name refuses here, before computing
        return _run_locked(args, output, started, model)


def _model_or_none(path: str):
    """The model of *path*, or None if it cannot be read (then :func:`_run_locked` reports why)."""
    from pounding.errors import PoundingError
    from pounding.model.model import load_model

    try:
        return load_model(path)
    except (PoundingError, OSError):
        return None


def _run_locked(args: argparse.Namespace, output: Path, started: float, model=None) -> int:
    """``pounding run`` once *output* is claimed; *model* is ``MODEL`` if already loaded."""
    from pounding.errors import PoundingError
    from pounding.results.archive import save_run
    from pounding.results.output_place import check_writable
    from pounding.results.checks import print_warnings, run_warnings
    from pounding.model.model import load_model
    from pounding.simulation import model_inputs, simulate

    check_writable(output, overwrite=args.overwrite, inputs=[args.model])   # finished by another meanwhile?
    if model is None:
        model = load_model(args.model)   # raises the model's own one-line error
    scale = None if args.scale is None else parse_scale_option(args.scale, [b.name for b in model.buildings])
    refused = [flag for flag, given in (("--units", args.units), ("--dt", args.dt)) if given is not None]
    if refused and model.ground_motion.two_components:
        raise PoundingError(f"{args.model}: {' and '.join(refused)} describe{'s' if len(refused) == 1 else ''} a "
                            "record file; a model in plan takes a catalogue pair as --record, which declares its "
                            "own (give files as x: and y: components, with units and dt, in the model's ground_motion)")
    if args.record is None and (args.units is not None or args.dt is not None):
        raise PoundingError("--units and --dt describe a record file given with --record; the model's own record "
                            "takes them from its YAML ground_motion section")
    if args.record is not None:
        from pounding.simulation import record_path

        check_writable(output, overwrite=args.overwrite, inputs=[args.model, record_path(args.record)])
    else:
        check_writable(output, overwrite=args.overwrite, inputs=model_inputs(model))
    ds = simulate(model, record=args.record, xi=args.xi, scale=scale, duration=args.duration,
                  rtol=args.rtol, output_dt=args.output_dt, record_units=args.units, record_dt=args.dt,
                  contacts=not args.no_contacts, where="cli")
    path = save_run(ds, output, overwrite=args.overwrite, keep_beside=True)
    print(summary(ds))
    print_warnings([*model.warnings, *run_warnings(ds).values()])
    print(f"wrote {path}")
    write_csv_option(args, "run", ds)
    if args.plot:
        _write_plots("run", ds, args.plot, args, f"; the archive {path} is written")
    print(f"wall time {time.perf_counter() - started:.2f} s (this command after start-up; Python and library imports excluded)")
    return outcome_status(ds)


def _write_plots(kind: str, ds, directory, args: argparse.Namespace, written_note: str = "") -> None:
    """Draw the figures of an archive of *kind* into *directory* and print each file; one line if they cannot be written."""
    from pounding.errors import PoundingError

    try:
        written = _draw(kind, ds, Path(directory), args)
    except OSError as exc:
        raise PoundingError(f"--plot {directory}: cannot write the plots ({exc.strerror or exc}){written_note}"
                            ) from None
    for png in written:
        print(f"wrote {png}")


#: Exit status of a run whose archive is written but whose results are not to be trusted
#: (``energy_inconsistent``); 2 stays the status of a user error, 0 of a completed, collapsed or
#: unstable run (physical outcomes).
UNTRUSTED_RUN_STATUS = 1


def outcome_status(ds) -> int:
    """Exit status of ``run``/``rerun`` for the written run *ds*: 1 if it ended ``energy_inconsistent``."""
    return UNTRUSTED_RUN_STATUS if ds.attrs.get("status") == "energy_inconsistent" else 0


def _cmd_rerun(args: argparse.Namespace) -> int:
    from pounding.results.archive import open_run, output_lock, save_run
    from pounding.results.output_place import check_writable
    from pounding.results.summary import compare_runs
    from pounding.simulation import rerun

    check_writable(args.output, overwrite=args.overwrite, inputs=[args.run])
    check_outputs(args)   # nor the records the rerun reads again
    with output_lock(args.output, writer="pounding rerun"):
        check_writable(args.output, overwrite=args.overwrite, inputs=[args.run])
        before = open_run(args.run)
        ds = rerun(args.run)
        path = save_run(ds, args.output, overwrite=args.overwrite, keep_beside=True)
    print(summary(ds))
    print(compare_runs(before, ds, str(args.run)))
    print(f"wrote {path}")
    return outcome_status(ds)


def open_archive(path) -> tuple[str, object]:
    """Open any pounding archive; returns ``(kind, dataset)`` with kind ``run`` (a run of any model), ``sweep``,
    ``compare``, ``gap``, ``gap-code`` (``gap --code``), ``ida``, ``risk``, ``verify``, ``hysteresis``, ``pushover`` or ``p695``."""
    import xarray as xr

    from pounding.errors import ArchiveError
    from pounding.results.archive import load_within_memory, open_run

    source = Path(path)
    if not source.exists():
        raise ArchiveError(f"{source}: no such file")
    if not source.is_file():   # a FIFO would block the open forever
        raise ArchiveError(f"{source}: not a regular file; give the NetCDF archive itself")
    try:
        with xr.open_dataset(source, engine="netcdf4") as handle:
            attrs = dict(handle.attrs)
            names = set(handle.variables)
    except (OSError, ValueError) as exc:
        raise ArchiveError(f"{source}: not a readable NetCDF file ({type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:120]})") from None
    if "run_spec" in attrs:
        return "run", open_run(source)
    is_verify = {"e_pre", "e_post", "model"} <= names and "settings" in attrs
    if not is_verify and not str(attrs.get("source", "")).startswith("pounding"):
        raise ArchiveError(f"{source}: not a pounding archive (written by pounding run, rerun, sweep, compare or "
                           "verify)")
    with xr.open_dataset(source, engine="netcdf4") as handle:
        ds = load_within_memory(handle, source)
    if attrs.get("study") in ("gap", "ida", "risk") or "sweep_name" in attrs:
        if "status" not in names:   # every study archive has one status per scenario
            raise ArchiveError(f"damaged archive: {source}: variable status missing; run the study again to "
                               "write it again")
        if attrs.get("study") in ("gap", "ida", "risk"):
            return str(attrs["study"]), ds
        return ("compare" if str(attrs.get("sweep_file", "")).startswith("<compare") and names & {"xi", "pounding"}
                else "sweep"), ds
    if is_verify:
        return "verify", ds
    if attrs.get("kind") in ("hysteresis", "pushover", "p695", "gap-code"):
        return str(attrs["kind"]), ds
    raise ArchiveError(f"{source}: a pounding file of an unknown kind (not from run, rerun, sweep, compare or "
                       "verify); a newer pounding may read it")


def _reference(ds) -> str:
    """The formula a compare archive is compared with (``exact`` unless it was not run)."""
    from pounding.studies.compare import reference_formula

    return reference_formula(ds)


def _cmd_info(args: argparse.Namespace) -> int:
    kind, ds = open_archive(args.run)
    print(f"{args.run}: {ds.attrs.get('title', kind)} [{kind} archive]")
    print("  " + str(ds.attrs.get("history", "")).replace("\n", "\n  "))
    print("  dimensions: " + ", ".join(f"{k}={v}" for k, v in ds.sizes.items()))
    with damaged_if_garbled(args.run):
        _print_info(kind, ds)
        for line in stored_warnings(ds):
            print(f"  warning: {line}")
    if args.variables:
        for name, var in ds.data_vars.items():
            print(f"  {name}{tuple(var.dims)} [{var.attrs.get('units', '')}] {var.attrs.get('long_name', '')}")
    return 0


def stored_warnings(ds) -> list[str]:
    """The warnings a study stored when it ran (attribute ``warnings``, a JSON list; issue 28 §4)."""
    import json

    text = ds.attrs.get("warnings")
    if not text:
        return []
    lines = json.loads(text)
    return [str(line) for line in lines] if isinstance(lines, list) else [str(lines)]


def archive_summary(kind: str, ds) -> str:
    """The summary ``pounding info`` prints for an archive of *kind*, as text."""
    import io
    from contextlib import redirect_stdout

    with redirect_stdout(io.StringIO()) as text:
        _print_info(kind, ds)
    return text.getvalue().rstrip("\n")


def _print_info(kind: str, ds) -> None:
    """The summary ``pounding info`` prints for an archive of *kind*."""
    if kind == "run":
        print(summary(ds))
    elif kind == "gap":
        from pounding.studies.gap import gap_table

        print(gap_table(ds))
    elif kind == "gap-code":
        from pounding.studies.design_check import code_gap_info

        print(code_gap_info(ds))
    elif kind == "ida":
        from pounding.studies.ida import ida_table

        print(ida_table(ds))
    elif kind == "hysteresis":
        from pounding.studies.cyclic import hysteresis_summary

        print(hysteresis_summary(ds))
    elif kind == "pushover":
        from pounding.studies.pushover import pushover_table

        print(pushover_table(ds))
    elif kind == "p695":
        from pounding.studies.p695.report import p695_table

        print(p695_table(ds))
    elif kind == "risk":
        from pounding.studies.risk import risk_table

        print(risk_table(ds))
    elif kind in ("sweep", "compare"):
        from pounding.cli.sweep import summary_lines

        for line in summary_lines(ds):
            print(line)
        if kind == "compare" and bool((ds.status == "ok").any()):
            from pounding.studies.compare import comparison_table

            print(comparison_table(ds, _reference(ds)))
    else:
        from pounding.studies.verify import format_report

        print(format_report(ds))


def _cmd_plot(args: argparse.Namespace) -> int:
    from pounding.errors import PoundingError

    kind, ds = open_archive(args.run)
    with damaged_if_garbled(args.run):
        nothing = kind in ("sweep", "compare", "gap", "ida", "risk") and \
            not bool(ds.status.isin(["ok", "completed", "collapsed", "unstable"]).any())
    if nothing:
        raise PoundingError(f"{args.run}: every scenario failed, so there is nothing to plot; "
                            f"`pounding info {args.run}` lists the errors")
    _check_plot_dir(args.output)
    try:
        with damaged_if_garbled(args.run):
            written = _draw(kind, ds, Path(args.output), args)
    except OSError as exc:
        raise PoundingError(f"{args.output}: cannot write the plots ({exc.strerror or exc})") from None
    for png in written:
        print(f"wrote {png}")
    return 0


def draw_figures(kind: str, ds, out: Path, *, drift_limit: float | None = None, elevation: bool = False) -> list:
    """The figures of an archive of *kind* written to the folder *out* (``pounding plot``); their paths.

    *drift_limit* (%) and *elevation* as ``--drift-limit`` and ``--elevation``.
    """
    return _draw(kind, ds, out, argparse.Namespace(drift_limit=drift_limit, elevation=elevation))


def _draw(kind: str, ds, out: Path, args: argparse.Namespace) -> list:
    """The figures of an archive of *kind* written to the folder *out*; their paths."""
    if kind == "run":
        from pounding.results.plots import plot_run

        return plot_run(ds, out, drift_limit=args.drift_limit, elevation=args.elevation)
    if kind == "compare":
        from pounding.studies.compare import plot_comparison

        return plot_comparison(ds, out, _reference(ds), drift_limit=args.drift_limit)
    if kind == "sweep":
        from pounding.results.plots import plot_sweep

        return plot_sweep(ds, out)
    if kind == "gap":
        from pounding.studies.gap import plot_gap

        return plot_gap(ds, out)
    if kind == "gap-code":
        from pounding.studies.design_check import plot_code_gap

        return plot_code_gap(ds, out)
    if kind == "hysteresis":
        from pounding.studies.cyclic import plot_hysteresis

        return plot_hysteresis(ds, out)
    if kind == "pushover":
        from pounding.studies.pushover import plot_pushover

        return plot_pushover(ds, out)
    if kind == "ida":
        from pounding.studies.ida import plot_ida

        return plot_ida(ds, out)
    if kind == "p695":
        from pounding.studies.p695.report import plot_p695

        return plot_p695(ds, out)
    if kind == "risk":
        from pounding.studies.risk import plot_risk

        return plot_risk(ds, out)
    from pounding.studies.verify import plot_verification

    out.mkdir(parents=True, exist_ok=True)
    return [plot_verification(ds, out / "verify.png")]


def _cmd_xi_list(args: argparse.Namespace) -> int:
    from pounding.contact import xi

    rows = xi.catalogue()
    width = max(len(r["key"]) for r in rows)
    pwidth = max(len(r["p(e)"]) for r in rows)
    print(f"{'key':<{width}}  {'p(e) = xi*v0/kh':<{pwidth}}  {'status':<11} reference")
    for r in rows:
        alias = f" [aliases: {r['aliases']}]" if r["aliases"] else ""
        print(f"{r['key']:<{width}}  {r['p(e)']:<{pwidth}}  {r['status']:<11} {r['reference']}{alias}")
    return 0




def register_cli(sub) -> None:
    """Add ``run``, ``rerun``, ``info``, ``plot`` and ``xi`` to *sub* (from ``add_subparsers``)."""
    run = sub.add_parser("run", help="simulate a YAML model under a record and archive the results")
    run.add_argument("model", help="YAML building model, e.g. models/pair.yaml")
    run.add_argument("--record", help="record instead of the model's: a catalogue name (pounding records list), "
                     "fema-p695:farfield/1a, or a .AT2 / text file relative to the current directory")
    run.add_argument("--units", help="units of a --record text file without a '# units: g' header "
                     "(g, m/s2, cm/s2, gal)")
    run.add_argument("--dt", type=float, metavar="S", help="time step of a one-column --record text file "
                     "without a '# dt = 0.005 s' header, s")
    run.add_argument("--scale", metavar="X", help=SCALE_HELP)
    run.add_argument("--xi", help="xi formula for every hertz-damp contact (see `pounding xi list`)")
    run.add_argument("--no-contacts", action="store_true", help="every contact held open: the run without pounding")
    run.add_argument("--duration", type=float, help="simulated time, s")
    run.add_argument("--rtol", type=float, help="relative tolerance of the solver")
    run.add_argument("--output-dt", type=float, help="sampling of stored histories, s")
    run.add_argument("-o", "--output", help="NetCDF archive (default: MODEL-STEM.nc)")
    run.add_argument("--overwrite", action="store_true", help="replace an existing archive")
    run.add_argument("--plot", metavar="DIR", help="also write the run's PNG figures to DIR (see pounding plot)")
    add_csv_option(run)
    add_plot_options(run)
    run.set_defaults(func=_cmd_run)

    again = sub.add_parser("rerun", help="rerun an archived simulation from its archive",
                           description="Simulate again what a `pounding run` archive recorded (model, record, "
                                       "scale); refuses if the record's samples no longer hash the same.")
    again.add_argument("run", help="archive written by `pounding run`")
    again.add_argument("-o", "--output", required=True, help="new NetCDF archive")
    again.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    again.set_defaults(func=_cmd_rerun)

    info = sub.add_parser("info", help="describe an archive (run, sweep, compare or verify)",
                          description="Print an archive's kind, history, dimensions and summary.")
    info.add_argument("run", metavar="ARCHIVE", help="NetCDF file written by run, rerun, sweep, compare or verify")
    info.add_argument("--variables", action="store_true", help="list every variable with units")
    info.set_defaults(func=_cmd_info)

    plot = sub.add_parser("plot", help="draw the PNG figures of an archive (run, sweep, compare or verify)",
                          description="Redraw an archive's figures: a run's (those its data call for), compare's two, a "
                                      "sweep's peak drifts against each axis, verify's e_post against e_pre.")
    plot.add_argument("run", metavar="ARCHIVE", help="NetCDF file written by run, rerun, sweep, compare or verify")
    plot.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for the PNG files "
                      "(created if needed)")
    add_plot_options(plot)
    plot.set_defaults(func=_cmd_plot)

    xi = sub.add_parser("xi", help="the catalogue of xi formulas")
    xi_sub = xi.add_subparsers(dest="xi_command", required=True, metavar="{list}")
    xi_list = xi_sub.add_parser("list", help="print the catalogue: key, p(e), status, reference, aliases")
    xi_list.set_defaults(func=_cmd_xi_list)


def add_plot_options(parser: argparse.ArgumentParser) -> None:
    """``--drift-limit`` and ``--elevation`` for the drift-profile figures."""
    parser.add_argument("--drift-limit", type=float, metavar="PCT",
                        help="draw a drift-ratio limit line on the drift profiles, in %% (e.g. 2.0)")
    parser.add_argument("--elevation", action="store_true",
                        help="drift profiles against floor elevation (m) instead of storey number")
