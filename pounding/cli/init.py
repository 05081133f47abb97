"""``pounding init DIR``: a folder of the shipped models, sweeps and examples to edit.

A wheel installs the shipped files inside the package (``pounding/data/``);
``init`` copies ``models/``, ``sweeps/`` and ``examples/`` from there into a
new (or empty) folder, keeping their layout, so that the relative paths in
them (``model: ../models/pair.yaml`` in a sweep) and the commands of the
README (``pounding run models/pair.yaml``) work inside it.  Records are named
by catalogue key in the shipped models, and the catalogue stays in the
package, so no record is copied.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path
from typing import Any

from pounding.errors import PoundingError

__all__ = ["init_folder", "register_cli"]


def _shipped_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")


def init_folder(target: str | Path) -> list[Path]:
    """Copy the shipped ``models/``, ``sweeps/`` and ``examples/`` into *target*.

    *target* must not exist or be an empty folder.  Returns the files written.

    Raises
    ------
    PoundingError
        *target* is a file or a folder that is not empty, or cannot be written.
    """
    from pounding.data import STARTER_FOLDERS, data_path

    target = Path(target)
    label = str(target)
    if target.exists() and not target.is_dir():
        raise PoundingError("is a file; give a new folder, e.g. pounding init pounding-study", file=label)
    if target.is_dir() and any(target.iterdir()):
        raise PoundingError("the folder is not empty; give a new or empty folder "
                            f"(e.g. pounding init {target.name or 'study'}-new) so that no file is overwritten",
                            file=label)
    written: list[Path] = []
    try:
        for name in STARTER_FOLDERS:
            source = data_path(name)
            for path in _shipped_files(source):
                destination = target / name / path.relative_to(source)
                destination.parent.mkdir(parents=True, exist_ok=True)
                # copyfile, not copy2: the copies are the user's to edit, even from a read-only site-packages.
                shutil.copyfile(path, destination)
                written.append(destination)
    except OSError as exc:
        raise PoundingError(f"cannot write {exc.filename or target}: {exc.strerror or exc}; choose a folder "
                            "you can write to", file=label) from None
    return written


def _cmd_init(args: argparse.Namespace) -> int:
    written = init_folder(args.folder)
    for path in written:
        print(f"wrote {path}")
    print(f"{len(written)} files; next: cd {args.folder} && pounding run models/pair.yaml -o pair.nc")
    return 0


def register_cli(subparsers: Any) -> None:
    """Add ``pounding init``."""
    parser = subparsers.add_parser("init", help="copy the shipped models, sweeps and examples into a new folder")
    parser.add_argument("folder", help="new or empty folder to create, e.g. my-study")
    parser.set_defaults(func=_cmd_init)
