"""What ``pounding sweep``, ``compare`` and ``gap`` share on plan models (docs/plan-models.md "Studies").

Each command hands a plan model to its own ``_cmd_plan_*``; options a plan study does not have yet are
refused in one line here.
"""

from __future__ import annotations

import argparse

from pounding.errors import PoundingError

__all__ = ["refuse_options"]


def refuse_options(args: argparse.Namespace, command: str, options: tuple[str, ...]) -> None:
    """Stop in one line at the first of *options* (``--plot``...) given to a plan *command*."""
    for option in options:
        value = getattr(args, option.lstrip("-").replace("-", "_"), None)
        if value not in (None, False):
            raise PoundingError(f"{option} is not yet available for plan models (pounding {command}); the archive "
                                "(-o) holds every result")
