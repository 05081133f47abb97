"""``pounding animate``: a run archive as a film (MP4 with ffmpeg, or an animated GIF)."""

from __future__ import annotations

import argparse

__all__ = ["register_cli"]


def _cmd_animate(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pounding.cli.csv_option import check_outputs
    from pounding.cli.run import open_archive
    from pounding.errors import PoundingError
    from pounding.results.animation import RunAnimation, film_format, parse_window
    from pounding.results.output_place import check_writable

    out = Path(args.output)
    suffix = film_format(out)
    window = parse_window(args.window)
    check_writable(out, overwrite=args.overwrite, inputs=[args.run])
    check_outputs(args)
    kind, ds = open_archive(args.run)
    if kind != "run":
        raise PoundingError(f"{args.run}: a {kind} archive; pounding animate draws the archive of one run "
                            "(pounding run MODEL -o RUN.nc)")
    film = RunAnimation(ds, exaggerate=args.exaggerate, speed=args.speed, window=window,
                        dpi=100.0 if suffix == ".mp4" else 80.0)
    film.save(out)
    print(f"wrote {out}: {film.n_frames} frames at {film.fps:.3g} frames/s ({film.times[0]:g} to "
          f"{film.times[-1]:g} s at {args.speed:g} simulated s per s), displacements and gaps x{film.exaggerate:g}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding animate`` to *subparsers*."""
    parser = subparsers.add_parser(
        "animate", help="a run archive as a film: the buildings swaying and striking (MP4 or GIF)",
        description="Draw a run archive frame by frame: a planar model in elevation (buildings side by side, "
                    "floors displaced), a model in plan as floor outlines; impacts flash with their force; a "
                    "cursor runs along the ground acceleration below.  MP4 needs ffmpeg; GIF needs nothing more.")
    parser.add_argument("run", metavar="ARCHIVE", help="NetCDF archive of a run (pounding run MODEL -o RUN.nc)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.mp4|OUT.gif",
                        help="the film: .mp4 (H.264, ffmpeg) or .gif (Pillow)")
    parser.add_argument("--exaggerate", type=float, metavar="X",
                        help="draw displacements and gaps x X (default: the largest displacement as about a quarter "
                             "of a building's drawn width, or a tenth of the plan)")
    parser.add_argument("--speed", type=float, default=1.0, metavar="S",
                        help="simulated seconds per second of film (default 1: real time; 0.2: five times slower)")
    parser.add_argument("--window", metavar="T0,T1", help="only the part of the run from T0 to T1, s")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.set_defaults(func=_cmd_animate)
    return parser
