"""pounding — structural pounding of adjacent shear buildings under earthquake records.

Public API
----------
``load_model(path)``
    Read and validate a YAML building model (:mod:`pounding.model`).
``simulate(model, record=None, xi=None, ...)``
    Integrate it under a ground-acceleration record; returns an
    ``xarray.Dataset`` (:mod:`pounding.simulation`, :mod:`pounding.results.dataset`).
``open_run(path)``
    Reopen a NetCDF results archive (:mod:`pounding.results.archive`).
``drop_ragged(ds)``
    The dataset without its run-dependent ``impact`` / ``trace`` dimensions,
    so that runs can be combined with ``xr.concat`` (:mod:`pounding.results.dataset`).
"""

from __future__ import annotations

__version__ = "0.1.0"

from pounding.errors import PoundingError  # noqa: E402

__all__ = ["__version__", "PoundingError", "load_model", "simulate", "open_run", "save_run", "rerun", "drop_ragged"]


def __getattr__(name: str):
    # Lazy imports keep `import pounding` (and the CLI's start-up) light.
    if name == "load_model":
        from pounding.model.model import load_model
        return load_model
    if name == "simulate":
        from pounding.simulation import simulate
        return simulate
    if name in ("open_run", "save_run"):
        from pounding.results import archive
        return getattr(archive, name)
    if name == "drop_ragged":
        from pounding.results.dataset import drop_ragged
        return drop_ragged
    if name == "rerun":
        from pounding.simulation import rerun
        return rerun
    raise AttributeError(f"module 'pounding' has no attribute {name!r}")
