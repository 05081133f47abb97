"""Where the benchmarks write: never into the checkout unless asked.

Every script prints its tables and writes its files (figures, JSON) to
``--out DIR``, by default ``<user cache>/pounding/benchmarks/<script>``
(``$XDG_CACHE_HOME/pounding/benchmarks/...`` on Linux).  A script that owns a
figure of the documentation (``scaling.py``: ``docs/scaling.png``) rewrites
it only with ``--update-docs``.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def default_out(script: str) -> Path:
    """``<user cache>/pounding/benchmarks/<script>``: outside the checkout."""
    try:
        import platformdirs

        base = Path(platformdirs.user_cache_dir("pounding", appauthor=False))
    except ImportError:  # platformdirs is a dependency of pounding; this is only a fallback
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "pounding"
    return base / "benchmarks" / script


def add_output_arguments(parser: argparse.ArgumentParser, script: str, owns: tuple[str, ...] = ()) -> None:
    """``--out DIR`` and, for a script that owns documentation files, ``--update-docs``."""
    parser.add_argument("--out", type=Path, default=None, metavar="DIR",
                        help=f"folder for the files this benchmark writes (default: {default_out(script)})")
    if owns:
        parser.add_argument("--update-docs", action="store_true",
                            help="also rewrite the documentation files this benchmark owns: " + ", ".join(owns))


def out_dir(args: argparse.Namespace, script: str) -> Path:
    """The output folder (created), from ``--out`` or the default."""
    folder = (args.out or default_out(script)).expanduser().resolve()
    folder.mkdir(parents=True, exist_ok=True)
    return folder
