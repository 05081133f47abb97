"""What ``pounding sweep``, ``compare`` and ``gap`` share on plan models (docs/plan-models.md "Studies").

Each command hands a plan model to its own ``_cmd_plan_*``; options a plan study does not have yet are
refused in one line here.
"""

from __future__ import annotations

import argparse
import sys

from pounding.errors import PoundingError

__all__ = ["refuse_options", "interrupted"]


def refuse_options(args: argparse.Namespace, command: str, options: tuple[str, ...]) -> None:
    """Stop in one line at the first of *options* (``--plot``...) given to a plan *command*."""
    for option in options:
        value = getattr(args, option.lstrip("-").replace("-", "_"), None)
        if value not in (None, False):
            raise PoundingError(f"{option} is not yet available for plan models (pounding {command}); the archive "
                                "(-o) holds every result")


def interrupted(output) -> int:
    """Say where an interrupted study keeps its finished scenarios; the exit status 130."""
    from pounding.studies.engine.store import parts_dir

    where = f"; finished scenarios are kept in {parts_dir(output)}: run the same command again" if output else ""
    print(f"pounding: interrupted{where}", file=sys.stderr)
    return 130
