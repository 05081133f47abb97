"""Tolerances that follow the model's own scales (docs/numerics.md, "Tolerances at the model's scale").

The absolute tolerances ``atol`` (m) and ``atol_velocity`` (m/s) of the
error norm are the user's; they suit floors that move millimetres to metres.
A storey far stiffer than that (a stiff neighbour, a shear wall core) moves
far less: its static drift under the inertia of the lightest floor of the
row at the peak ground acceleration,

    u_s = a_ref · m_min / k_max,

can be below ``atol``.  Stick and release of a resting contact against such a
building are decided on displacements of that size (its spring force is
``k·u``): an error of ``atol`` then flips the sign of the contact force and an
impact sequence never ends (issue 25: 14,471 impacts where an exact solution
has 25).  Each building's floors therefore get ``min(atol, SCALE_FRACTION·u_s)``
(and their velocities the same factor on ``atol_velocity``); the floors of
ordinary buildings (u_s of millimetres) keep the user's tolerances exactly.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SCALE_FRACTION", "REFERENCE_ACCELERATION", "floor_tolerance_factors"]

#: Fraction of a building's static drift scale u_s that its displacement error may reach: 1 % of the
#: force that decides a stick or a release (k·u_s) keeps that decision's sign.
SCALE_FRACTION = 1e-2
#: a_ref when the ground does not move (free vibration): 1 g, m/s².
REFERENCE_ACCELERATION = 9.80665


def floor_tolerance_factors(mass: np.ndarray, storey_stiffness: np.ndarray, below: np.ndarray,
                            peak_ground_acceleration: float, atol: float) -> np.ndarray:
    """Factor (0, 1] on ``atol`` and ``atol_velocity`` for every floor (N,).

    Parameters
    ----------
    mass : (N,) kg
    storey_stiffness : (N,) N/m, the storey under each floor
    below : (N,) int, the floor below (−1: ground; a building starts at each −1)
    peak_ground_acceleration : float
        a_ref, m/s² (the largest |a_g| of the run's records; 0: 1 g).
    atol : float
        The user's displacement tolerance, m.
    """
    mass = np.asarray(mass, dtype=float)
    stiffness = np.asarray(storey_stiffness, dtype=float)
    factors = np.ones(mass.size)
    if mass.size == 0 or not atol > 0.0:
        return factors
    a_ref = float(peak_ground_acceleration) if peak_ground_acceleration > 0.0 else REFERENCE_ACCELERATION
    starts = list(np.flatnonzero(np.asarray(below) < 0)) + [mass.size]
    lightest = float(mass.min())
    for first, end in zip(starts[:-1], starts[1:]):
        stiffest = float(stiffness[first:end].max())
        if not stiffest > 0.0:
            continue  # free masses (no storey springs): no static scale
        static_drift = a_ref * lightest / stiffest
        factors[first:end] = min(1.0, SCALE_FRACTION * static_drift / atol)
    return factors
