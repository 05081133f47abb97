"""Where numba caches the compiled kernels when the installed package is read-only.

numba's ``cache=True`` writes next to the source (``pounding/*/__pycache__``),
which a wheel in a user's venv can.  When that folder cannot be written (a
read-only site-packages), numba falls back to its own user cache
(``~/.cache/numba``), and when that cannot be written either it refuses to
import the module (``RuntimeError: cannot cache function``).  So, for a
read-only install, :func:`use_writable_cache` points numba at pounding's own
user cache folder, ``<platformdirs user cache>/pounding/numba``, or a folder
in the temporary directory if that cannot be written either.
``NUMBA_CACHE_DIR`` set by the user always wins.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["writable", "use_writable_cache"]


def writable(folder: Path) -> bool:
    """True if *folder* exists or can be made, and a file can be created in it (numba's own test)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def use_writable_cache(source_file: str | os.PathLike) -> str | None:
    """Give numba a writable cache folder if the one beside *source_file* is read-only.

    Call before the first ``@njit(cache=True)`` of the package.  Returns the
    folder set as ``numba.config.CACHE_DIR``, or None if nothing was changed.
    """
    from numba.core import config

    if config.CACHE_DIR or writable(Path(source_file).resolve().parent / "__pycache__"):
        return None
    import platformdirs

    for folder in (Path(platformdirs.user_cache_dir("pounding", appauthor=False)) / "numba",
                   Path(tempfile.gettempdir()) / f"pounding-numba-{os.getuid() if hasattr(os, 'getuid') else 0}"):
        if writable(folder):
            config.CACHE_DIR = str(folder)
            return config.CACHE_DIR
    return None  # nowhere to write: numba reports it
