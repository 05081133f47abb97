"""Corners of floors in plan: where they are at rest, how they move, their peaks.

A floor in plan is a rigid diaphragm with an axis-aligned outline; its corners move with the
floor's u_x, u_y and θ (small rotations: ``u_x − θ (p_y − y_c)``, ``u_y + θ (p_x − x_c)``).  The
archive of a run records every corner's displacement and its peaks
(:func:`pounding.results.dataset.to_dataset`); :func:`hermite_at` evaluates stored samples
between output times (an impact's onset).
"""

from __future__ import annotations

import numpy as np

from pounding.model.floors import DOF_PER_FLOOR, point_weights

__all__ = ["CORNERS", "corner_weights", "floor_corners", "hermite_at", "peak_corner", "corner_displacements"]

#: The outline's corners, counter-clockwise from the south-west one (the ``corner`` coordinate).
CORNERS = ("south-west", "south-east", "north-east", "north-west")


def floor_corners(model) -> np.ndarray:
    """(floors, 4, 2) the outline's corners of every floor at rest (:data:`CORNERS` order), m."""
    rows = []
    for b in model.buildings:
        (x0, y0), (x1, y1) = b.outline
        rows += [[(x0, y0), (x1, y0), (x1, y1), (x0, y1)]] * b.n_floors
    return np.asarray(rows, dtype=float).reshape(-1, 4, 2)


def corner_weights(centres: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(floors, 4, 2, 3) weights over each floor's own (u_x, u_y, θ) giving its corners' displacements (x, y), m.

    *centres* (floors, 2) and *corners* (floors, 4, 2) in m; small rotations
    (:func:`pounding.model.plan.point_weights`).
    """
    return np.array([[[point_weights(tuple(c), tuple(p), d) for d in ("x", "y")] for p in floor]
                     for c, floor in zip(centres, corners)]).reshape(len(centres), 4, 2, DOF_PER_FLOOR)


def hermite_at(time: np.ndarray, y: np.ndarray, rate: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Samples *y* (nt, k) with their rates *rate* at times *time* (nt,), s, interpolated at *at* (m,) s.

    Cubic Hermite between the two samples around each time (exact for cubics); times
    outside the samples take the end values.  Returns (m, k).
    """
    at = np.clip(np.asarray(at, dtype=float), time[0], time[-1])
    if time.size < 2:
        return np.repeat(y[:1], at.size, axis=0)
    k = np.clip(np.searchsorted(time, at, side="right") - 1, 0, time.size - 2)
    h = (time[k + 1] - time[k])[:, None]
    s = ((at - time[k]) / h[:, 0])[:, None]
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * y[k] + (s3 - 2 * s2 + s) * h * rate[k]
            + (3 * s2 - 2 * s3) * y[k + 1] + (s3 - s2) * h * rate[k + 1])


def corner_displacements(model, u: np.ndarray) -> np.ndarray:
    """(nt, floors, 4, 2) displacement (m) of every floor's outline corners along x and y, from the floors'
    (nt, floors, 3) states *u* (u_x, u_y, θ)."""
    centres = np.array([c for b in model.buildings for c in b.centres], dtype=float).reshape(-1, 2)
    return np.einsum("tfk,fcdk->tfcd", u, corner_weights(centres, floor_corners(model)))


def peak_corner(ds, building: str) -> tuple[int, int, float]:
    """Building *building*'s largest peak corner displacement magnitude: (floor level, corner index, m)."""
    floors = np.flatnonzero(ds.building.values == building)
    peaks = ds.peak_corner_displacement_magnitude.values[floors]
    row, corner = np.unravel_index(int(np.argmax(peaks)), peaks.shape)
    return int(ds.level.values[floors[row]]), int(corner), float(peaks[row, corner])
