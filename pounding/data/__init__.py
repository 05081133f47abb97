"""The files shipped inside the package: record catalogue and records, models, sweeps, examples.

They live in this folder so that a wheel carries them; the source checkout's
top-level ``models/``, ``ground_motions/``, ``sweeps/`` and ``examples/`` are
git symlinks to the folders here (one copy, nothing to keep in step).  They
are read through :mod:`importlib.resources`, so they are found wherever the
package is installed; ``pounding init DIR`` copies :data:`STARTER_FOLDERS`
into a folder of the user's own.
"""

from __future__ import annotations

import importlib.resources
from pathlib import Path

__all__ = ["STARTER_FOLDERS", "data_path", "catalogue_file"]

#: Folders that ``pounding init`` copies for the user to edit.
STARTER_FOLDERS = ("models", "sweeps", "examples")


def data_path(*parts: str) -> Path:
    """Path of a shipped file or folder, e.g. ``data_path("models", "pair.yaml")``.

    The package is installed as plain files (a wheel in site-packages, or the
    source tree), so the resource is a real file-system path.
    """
    return Path(str(importlib.resources.files(__name__).joinpath(*parts)))


def catalogue_file() -> Path:
    """The shipped record catalogue, ``ground_motions/catalogue.yaml``."""
    return data_path("ground_motions", "catalogue.yaml")
