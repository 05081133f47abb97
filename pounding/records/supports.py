"""Support motions: the ground acceleration under every building, on one time grid.

The records are read, processed and scaled elsewhere (:mod:`pounding.records.load`,
:mod:`pounding.records.processing`); here they are put on one grid for the solver:
records of different steps on the finest (:func:`common_step`, :func:`on_step`),
a wave-passage lag as leading zeros (:func:`lagged`), and grounds that come out
identical shared as one row (:func:`support_motions_from`), so a model whose
buildings all see the same record at the same time runs exactly as a
single-record model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pounding.errors import PoundingError
from pounding.records.record import Record

__all__ = ["SupportMotions", "common_step", "on_step", "lagged", "support_motions_from"]


@dataclass(frozen=True)
class SupportMotions:
    """The ground motion under every building, on one time grid.

    Attributes
    ----------
    rows : (G, ns) ndarray
        Ground accelerations, m/s², one row per distinct ground (G = 1 when
        every building sees the same motion at the same time).
    time_step : float
        Their common sampling interval, s.
    building_row : tuple of int
        Row of each building, left to right.
    records : tuple of Record
        The record under each building (scaled and processed; before any lag or resampling).
    lag_requested, lag : tuple of float
        Per building: the wave-passage lag asked for, ``(d_b − min d)/c`` (s), and the
        one applied, rounded to the record step (0 without wave passage).
    end_time : float
        Default simulated time, s: the longest record plus its lag.
    building_row_y : tuple of int
        Two horizontal components: each building's row along y (the rows are then the global
        components along x and y); empty with one component (along x).
    records_y : tuple of Record or None
        Two components: the second (b, or y) under each building, None where absent.
    zero_row : int
        A row of zeros (the ground of rotations), −1 when there is none.
    angle : float or None
        Two components: the angle of incidence of component a (x), degrees from +x.
    """

    rows: np.ndarray
    time_step: float
    building_row: tuple
    records: tuple
    lag_requested: tuple
    lag: tuple
    end_time: float
    building_row_y: tuple = ()
    records_y: tuple = ()
    zero_row: int = -1
    angle: float | None = None


def common_step(records: list[Record], names: list[str]) -> float:
    """The finest time step of *records* (s); every other must be a whole multiple of it (else one line)."""
    finest = min(r.time_step for r in records)
    for record, name in zip(records, names):
        ratio = record.time_step / finest
        if abs(ratio - round(ratio)) > 1e-6 * ratio:
            raise PoundingError(f"the records under the buildings have time steps {finest:g} s and "
                                f"{record.time_step:g} s (building {name}), not whole multiples of one another; "
                                "resample one record to the other's step")
    return finest


def on_step(record: Record, step: float) -> np.ndarray:
    """*record*'s acceleration (m/s²) sampled every *step* s (a whole fraction of its own): exact for
    piecewise-linear data."""
    ratio = int(round(record.time_step / step))
    if ratio == 1:
        return np.asarray(record.acceleration, dtype=float)
    fine = np.arange((record.acceleration.size - 1) * ratio + 1) * step
    return np.interp(fine, record.time, record.acceleration)


def lagged(record: Record, lag_requested: list[float]) -> tuple[list[np.ndarray], list[float]]:
    """*record* delayed by each lag (s), rounded to its step: ``(series, lags applied)``.

    Building b receives ``a_g(t − τ_b)``, zero before τ_b; rounding τ_b to the
    record step keeps every ground on the solver's breakpoints (error ≤ dt/2).
    """
    step = record.time_step
    shifts = [int(round(lag / step)) for lag in lag_requested]
    base = np.asarray(record.acceleration, dtype=float)
    return [np.concatenate([np.zeros(k), base]) if k else base for k in shifts], [k * step for k in shifts]


def support_motions_from(series: list[np.ndarray], step: float, records: list[Record], lag_requested: list[float],
                         lags: list[float], ends: list[float]) -> SupportMotions:
    """One :class:`SupportMotions` from each building's ground series on the grid *step* (s).

    Identical series share a row; shorter rows are followed by zeros.  *ends* are
    the buildings' simulated durations (s): the run's default end is the longest.
    """
    distinct: list[np.ndarray] = []
    building_row = []
    for values in series:
        for row, known in enumerate(distinct):
            if known.size == values.size and np.array_equal(known, values):
                building_row.append(row)
                break
        else:
            building_row.append(len(distinct))
            distinct.append(values)
    size = max(v.size for v in distinct)
    rows = np.zeros((len(distinct), size))
    for row, values in enumerate(distinct):
        rows[row, :values.size] = values
    return SupportMotions(rows, float(step), tuple(building_row), tuple(records), tuple(lag_requested),
                          tuple(lags), float(max(ends)))
