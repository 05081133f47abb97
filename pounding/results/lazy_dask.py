"""xarray without importing ``dask.array`` in a process that never makes a dask array.

xarray asks, for every variable it builds from a NumPy array, whether the data is a dask array,
and to know what a dask array is it imports ``dask.array`` the first time (when dask is
installed, as it is for the studies): 0.5-1.2 s at the end of every study (its dataset, built in
the process that ran the study) and in each sweep worker, spent in processes that hold no dask
array (``pounding run`` and the other one-run commands keep dask out altogether:
``pounding.cli.LEAN_COMMANDS``).  :func:`defer_dask_import` gives xarray the same answer without
the import: nothing is a dask array while ``dask.array`` has not been imported (no such object
can exist), and once it has been imported (a user's own dask work in the same process) xarray
sees its real ``Array`` type, as before.

``pounding.results.dataset`` and ``pounding.results.archive`` call it when they are imported (every
path that builds or writes a dataset goes through one of them).  Only xarray's cache of that answer is
filled in advance (``xarray.namedarray.pycompat``); if a
later xarray lays it out differently, nothing is changed and xarray imports dask as it always did.
"""

from __future__ import annotations

import sys

__all__ = ["defer_dask_import"]


def defer_dask_import() -> bool:
    """Let xarray recognise dask arrays without importing ``dask.array`` first (module docstring).

    Returns
    -------
    bool
        True if xarray's answer is now the lazy one (also when it already was, or when xarray
        had already imported ``dask.array``, which then costs nothing more), False if this
        xarray has no such cache (nothing changed).
    """
    try:
        from xarray.namedarray import pycompat
    except ImportError:   # pragma: no cover - an xarray without namedarray
        return False
    cache = getattr(pycompat, "_cached_duck_array_modules", None)
    base = getattr(pycompat, "DuckArrayModule", None)
    if not isinstance(cache, dict) or base is None:
        return False
    if "dask" in cache:
        return True

    class LazyDask(base):
        """xarray's record of dask: its ``Array`` type only once ``dask.array`` is imported."""

        def __init__(self) -> None:   # nothing imported here (the point)
            pass

        @property
        def type(self):
            loaded = sys.modules.get("dask.array")
            array = getattr(loaded, "Array", None)
            return (array,) if isinstance(array, type) else ()

        @property
        def module(self):
            import dask

            return dask

        @property
        def version(self):
            return base("dask").version

        @property
        def available(self) -> bool:
            import importlib.util

            return importlib.util.find_spec("dask") is not None

    cache["dask"] = LazyDask()
    return True
