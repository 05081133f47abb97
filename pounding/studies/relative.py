"""Relative changes ``(value − baseline) / baseline``, defined only where the baseline stands above round-off.

A study that compares two variants of a quantity (with and without pounding, a ξ formula against the
reference) reports the change relative to the baseline.  A baseline that is zero in exact arithmetic
(the roof rotation of a building symmetric in plan, ~1e-16 rad of round-off) would turn any change into
a meaningless percentage (+1e17 %).  Each quantity therefore has a **round-off scale**

    s = max(√ε · M, floor)

with ε the double-precision machine epsilon (√ε ≈ 1.5e-8), M the largest finite magnitude of that
quantity over the whole study (every variant, record, building, storey) and *floor* an absolute floor
in the quantity's units (:data:`ROUNDOFF_FLOOR`: 1e-12 m, rad or drift ratio).  Where the baseline's
magnitude is at most s, the relative change is not defined (NaN) and the absolute change is reported
instead.  Why these: round-off accumulated over a run stays orders of magnitude below √ε of the
study's largest values (ε times a modest growth), while a baseline that small is no physical
response of the study; the floor holds where every value of a quantity is round-off (M itself ~1e-16),
and is four orders of magnitude below the solver's default absolute tolerance (atol = 1e-8 m), below
anything the integration resolves.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ROUNDOFF_FRACTION", "ROUNDOFF_FLOOR", "roundoff_scale", "relative_change"]

#: √ε of double precision: the share of a quantity's largest magnitude below which a baseline is round-off.
ROUNDOFF_FRACTION = float(np.sqrt(np.finfo(float).eps))
#: Absolute floor of the round-off scale in SI units (m, rad, or a drift ratio): 1e-4 of the default atol.
ROUNDOFF_FLOOR = 1e-12


def roundoff_scale(values: Any, floor: float = ROUNDOFF_FLOOR) -> float:
    """The round-off scale of a quantity: ``max(√ε · largest finite |value|, floor)``.

    Parameters
    ----------
    values : array-like
        Every value of the quantity over the study (any shape; NaN and inf are ignored), in its units.
    floor : float
        Absolute floor in the same units (:data:`ROUNDOFF_FLOOR` for SI values; times 1e3 for mm or mrad).

    Returns
    -------
    float
        The scale, in the units of *values*.
    """
    magnitude = np.abs(np.asarray(values, dtype=float))
    finite = magnitude[np.isfinite(magnitude)]
    largest = float(finite.max()) if finite.size else 0.0
    return max(ROUNDOFF_FRACTION * largest, floor)


def relative_change(value: Any, baseline: Any, scale: float) -> Any:
    """``(value − baseline) / baseline`` where ``|baseline| > scale``, NaN elsewhere (and where either is NaN).

    Parameters
    ----------
    value, baseline : numpy array or xarray.DataArray
        The compared quantity and its baseline (broadcast together), in the same units.
    scale : float
        The quantity's round-off scale (:func:`roundoff_scale`), in those units.

    Returns
    -------
    numpy array or xarray.DataArray
        The relative change (1), of the type of the arithmetic on the inputs.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        change = (value - baseline) / baseline
    defined = abs(baseline) > scale
    if hasattr(change, "where"):   # xarray keeps its coordinates
        return change.where(defined)
    return np.where(defined, change, np.nan)
