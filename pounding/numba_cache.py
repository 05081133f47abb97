"""Where numba caches the compiled kernels, and how a damaged cache file is read.

numba's ``cache=True`` writes next to the source (``pounding/*/__pycache__``),
which a wheel in a user's venv can.  When that folder cannot be written (a
read-only site-packages), numba falls back to its own user cache
(``~/.cache/numba``), and when that cannot be written either it refuses to
import the module (``RuntimeError: cannot cache function``).  So, before the
solver is first imported (:func:`install`, called by ``import pounding``),
:func:`use_writable_cache` points numba at a folder it can write:

1. ``NUMBA_CACHE_DIR`` set by the user, if it can be written (else one warning
   and the next choices);
2. the folder beside the solver's sources;
3. pounding's own user cache folder, ``<platformdirs user cache>/pounding/numba``;
4. a folder in the temporary directory;
5. none: the kernels are compiled in every process, not cached (one warning).

numba reads a cache index (``.nbi``) and its data files (``.nbc``) with
``pickle`` and lets any error through, so a truncated data file or a garbage
index failed every later run until the cache was deleted by hand.
:func:`tolerate_damaged_files` makes such a file a cache miss: numba compiles
the kernel and its next save replaces the damaged file (an index is written
whole, a data file under its own name).
"""

from __future__ import annotations

import importlib.abc
import os
import sys
import tempfile
from pathlib import Path

__all__ = ["writable", "use_writable_cache", "tolerate_damaged_files", "install", "SOLVER_PACKAGE"]

#: The package whose first import :func:`install` waits for.
SOLVER_PACKAGE = "pounding.solver"


def writable(folder: Path) -> bool:
    """True if *folder* exists or can be made, and a file can be created in it (numba's own test)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def _warn(message: str) -> None:
    """One line on stderr, once per process (the solver's cache is chosen again by each solver module)."""
    if message in _WARNED:
        return
    _WARNED.add(message)
    try:
        print(f"pounding: warning: {message}", file=sys.stderr)
    except (OSError, ValueError):
        pass


_WARNED: set[str] = set()


def use_writable_cache(source_file: str | os.PathLike) -> str | None:
    """Give numba a writable cache folder if the one it would use for *source_file* cannot be written.

    Call before the first ``@njit(cache=True)`` of the package (:func:`install` does).  Returns the
    folder set as ``numba.config.CACHE_DIR``, or None if nothing was changed.  Where no folder can be
    written, numba's caching is switched off instead (every kernel compiled in each process), with one
    warning: a read-only installation with a read-only home still runs.
    """
    from numba.core import config

    if config.CACHE_DIR:
        if writable(Path(config.CACHE_DIR)):
            return None
        given, config.CACHE_DIR = config.CACHE_DIR, ""
        found = use_writable_cache(source_file)
        _warn(f"NUMBA_CACHE_DIR={given} cannot be written; the compiled solver is "
              + (f"cached in {found} instead" if found else "not cached (compiled in every run)")
              + ": set NUMBA_CACHE_DIR to a writable folder")
        return found
    if writable(Path(source_file).resolve().parent / "__pycache__"):
        return None
    import platformdirs

    for folder in (Path(platformdirs.user_cache_dir("pounding", appauthor=False)) / "numba",
                   Path(tempfile.gettempdir()) / f"pounding-numba-{os.getuid() if hasattr(os, 'getuid') else 0}"):
        if writable(folder):
            config.CACHE_DIR = str(folder)
            return config.CACHE_DIR
    _cache_nothing()
    if not os.environ.get("NUMBA_CACHE_DIR"):   # else the warning above names it
        _warn("no folder for numba's cache can be written (the package folder, the home folder, the temporary "
              "folder): the solver is compiled in every run (a minute or more); set NUMBA_CACHE_DIR to a "
              "writable folder")
    return None


def _cache_nothing() -> None:
    """Make ``cache=True`` compile without caching where numba finds no folder (instead of failing)."""
    from numba.core import dispatcher
    from numba.core.caching import NullCache

    enable = dispatcher.Dispatcher.enable_caching
    if getattr(enable, "pounding_uncached", False):
        return

    def enable_caching(self):
        try:
            enable(self)
        except RuntimeError:   # "cannot cache function ...: no locator available"
            self._cache = NullCache()

    enable_caching.pounding_uncached = True
    dispatcher.Dispatcher.enable_caching = enable_caching


def tolerate_damaged_files() -> None:
    """Read a damaged numba cache file (truncated, garbage, unpicklable) as a cache miss.

    numba's ``IndexDataCacheFile`` already reads a missing data file as a miss; here an index that
    does not unpickle to ``(stamp, overloads)`` reads as an empty one, and a data file that does not
    unpickle as a missing one.  The kernel is then compiled and saved as on any miss, which replaces
    the damaged file.  Applies to every numba cache read in the process (the kernels built with the
    package, :data:`pounding.solver.jit.PREBUILT`, too: there a miss means numba's own cache or a
    compilation).  Nothing is done on a numba without these methods.
    """
    try:
        from numba.core.caching import IndexDataCacheFile
    except ImportError:   # pragma: no cover - another numba
        return
    load_index = getattr(IndexDataCacheFile, "_load_index", None)
    load_data = getattr(IndexDataCacheFile, "_load_data", None)
    if load_index is None or load_data is None or getattr(load_index, "pounding_tolerant", False):
        return

    def tolerant_index(self):
        try:
            overloads = load_index(self)
        except FileNotFoundError:   # pragma: no cover - numba returns {} itself
            return {}
        except Exception:  # noqa: BLE001 - any garbage: pickle raises many kinds
            return {}
        return overloads if isinstance(overloads, dict) else {}

    def tolerant_data(self, name):
        try:
            return load_data(self, name)
        except OSError:
            raise
        except Exception as exc:  # noqa: BLE001 - truncated or garbage: numba reads OSError as a miss
            raise OSError(f"damaged numba cache file {name}: {type(exc).__name__}") from exc

    tolerant_index.pounding_tolerant = True
    IndexDataCacheFile._load_index = tolerant_index
    IndexDataCacheFile._load_data = tolerant_data


def prepare() -> None:
    """Before the solver's first kernel is defined: a writable (or no) cache, damaged files as misses."""
    tolerate_damaged_files()
    use_writable_cache(Path(__file__).resolve().parent / "solver" / "kernels.py")   # this package's solver


class _BeforeSolver(importlib.abc.MetaPathFinder):
    """Runs :func:`prepare` when :data:`SOLVER_PACKAGE` is first imported, then steps aside."""

    def find_spec(self, name, path=None, target=None):  # noqa: ARG002 - the finder protocol
        if name == SOLVER_PACKAGE:
            if self in sys.meta_path:
                sys.meta_path.remove(self)
            prepare()
        return None   # the ordinary finders import the package


def install() -> None:
    """Call :func:`prepare` just before the solver is first imported (at once if it already is).

    ``import pounding`` calls this: the solver's modules define their kernels when imported, and a
    cache folder chosen afterwards comes too late for them.  Importing pounding stays light (numba is
    imported with the solver, not before).
    """
    if SOLVER_PACKAGE in sys.modules:
        prepare()
    elif not any(isinstance(finder, _BeforeSolver) for finder in sys.meta_path):
        sys.meta_path.insert(0, _BeforeSolver())
