"""A planar building's sway–rocking foundation: the base mat and its springs and dashpots (docs/foundations.md).

A founded building's degrees of freedom are its floors' displacements relative to the free
field, ``x_i`` (deformation + base sway + height times rocking), then the base mat's sway
``u_b`` and rocking ``θ_b``: ``q = (x_1 … x_n, u_b, θ_b)``.  Its deformations (the fixed-base
building's coordinates) are ``d = T q`` with ``d_i = x_i − u_b − z_i θ_b`` (z_i: floor i's
elevation, m), so that

* the mass matrix stays diagonal, ``diag(m_1 … m_n, m_b, I_b)`` (the floors' own rotary
  inertia neglected, as in a shear building);
* storey i's deformation is ``δ_i = x_i − x_(i−1) − h_i θ_b`` (x_0 = u_b): its plane weights
  are the fixed-base weights times T, and ``K = Tᵀ K_fixed T + diag(0 … 0, K_x, K_θ)``;
* the building's own damping acts on the deformations, ``C = Tᵀ C_fixed T``, and the
  foundation's dashpots on sway and rocking: ``+ diag(0 … 0, c_x, c_θ)``.

The springs and dashpots are given, or computed from the soil and the footing
(:func:`on_soil`, with :mod:`pounding.model.foundation_impedance`).

SI units: kg, kg·m², N/m, N·s/m, N·m/rad, N·m·s/rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.model.foundation_impedance import Footing, Soil, equivalent_oscillator, flexible_base

__all__ = ["Foundation", "on_soil", "BASE_DOFS", "BASE_DOF_NAMES", "base_transform", "founded_mass", "founded_matrix",
           "founded_weights", "effective_damping"]

#: Degrees of freedom a foundation adds to its building: the base mat's sway and rocking.
BASE_DOFS = 2
#: Their names, in the building's DOF order after the floors.
BASE_DOF_NAMES = ("sway", "rocking")


@dataclass(frozen=True)
class Foundation:
    """The base mat of a planar building on sway and rocking springs and dashpots.

    Attributes
    ----------
    mass : float
        Base mat mass m_b, kg.
    rotary_inertia : float
        Base mat rotary inertia I_b about its horizontal axis, kg·m².
    sway_stiffness, sway_damping : float
        K_x, N/m, and c_x, N·s/m, on the base mat's sway u_b.
    rocking_stiffness, rocking_damping : float
        K_θ, N·m/rad, and c_θ, N·m·s/rad, on its rocking θ_b.
    soil, footing : Soil, Footing or None
        Where the springs and dashpots come from the soil and the footing (:func:`on_soil`); None
        where they were given.
    frequency : float or None
        With *soil*: the circular frequency ω̃ (rad/s) the impedances were evaluated at, the
        building's flexible-base fundamental frequency (Veletsos & Meek's estimate).
    """

    mass: float
    rotary_inertia: float
    sway_stiffness: float
    sway_damping: float
    rocking_stiffness: float
    rocking_damping: float
    soil: Soil | None = None
    footing: Footing | None = None
    frequency: float | None = None

    def to_document(self) -> dict[str, Any]:
        """The YAML mapping of this foundation: as it was given (springs, or soil and footing)."""
        base = {"mass": float(self.mass), "rotary_inertia": float(self.rotary_inertia)}
        if self.soil is not None:
            return {**base, "soil": {"shear_wave_velocity": float(self.soil.shear_wave_velocity),
                                     "poisson": float(self.soil.poisson), "density": float(self.soil.density)},
                    "footing": {"length": float(self.footing.length), "width": float(self.footing.width),
                                "embedment": float(self.footing.embedment)}}
        return {**base, "sway": {"stiffness": float(self.sway_stiffness), "damping": float(self.sway_damping)},
                "rocking": {"stiffness": float(self.rocking_stiffness), "damping": float(self.rocking_damping)}}

    def springs(self) -> dict[str, float]:
        """The springs and dashpots in use (SI) and, from soil, the frequency ω̃ they were evaluated at (rad/s)."""
        found = {"sway_stiffness": float(self.sway_stiffness), "sway_damping": float(self.sway_damping),
                 "rocking_stiffness": float(self.rocking_stiffness), "rocking_damping": float(self.rocking_damping)}
        if self.frequency is not None:
            found["frequency"] = float(self.frequency)
        return found

    @property
    def stiffness(self) -> np.ndarray:
        """(2,) ``(K_x, K_θ)``, N/m and N·m/rad."""
        return np.array([self.sway_stiffness, self.rocking_stiffness], dtype=float)

    @property
    def damping(self) -> np.ndarray:
        """(2,) ``(c_x, c_θ)``, N·s/m and N·m·s/rad."""
        return np.array([self.sway_damping, self.rocking_damping], dtype=float)


def on_soil(mass: float, rotary_inertia: float, soil: Soil, footing: Footing, floor_mass: np.ndarray,
            shape: np.ndarray, elevation: np.ndarray, omega: float) -> Foundation:
    """A building's foundation whose springs and dashpots are the footing's impedances on *soil*.

    The impedances (NIST GCR 12-917-21 §2.2, :func:`~pounding.model.foundation_impedance.impedances`)
    are evaluated along x (the footing's ``length`` is along the floors' motion) at the
    flexible-base fundamental frequency ω̃ found by iteration
    (:func:`~pounding.model.foundation_impedance.flexible_base`) from the building's first
    fixed-base mode as a single oscillator.

    Parameters
    ----------
    mass, rotary_inertia : float
        The base mat's m_b (kg) and I_b (kg·m²).
    soil, footing : Soil, Footing
        The half-space and the rigid footing.
    floor_mass, shape, elevation : (n,) array_like
        The floors' masses (kg), the first fixed-base mode shape, the floors' elevations (m).
    omega : float
        The first fixed-base circular frequency, rad/s.
    """
    oscillator = equivalent_oscillator(floor_mass, shape, elevation, omega)
    base = flexible_base(soil, footing, oscillator, direction="x")
    sway, rocking = base.impedances.along("x")
    return Foundation(float(mass), float(rotary_inertia), sway.stiffness, sway.damping, rocking.stiffness,
                      rocking.damping, soil, footing, base.impedances.frequency)


def base_transform(elevation: np.ndarray) -> np.ndarray:
    """(n, n + 2) T with ``d = T q``: floor deformations from ``q = (x_1 … x_n, u_b, θ_b)``.

    *elevation*: (n,) floor elevations z_i above the base mat, m.
    """
    z = np.asarray(elevation, dtype=float)
    n = z.size
    t = np.zeros((n, n + BASE_DOFS))
    t[:, :n] = np.eye(n)
    t[:, n] = -1.0
    t[:, n + 1] = -z
    return t


def founded_mass(floor_mass: np.ndarray, foundation: Foundation) -> np.ndarray:
    """(n + 2,) the diagonal of the mass matrix: floors (kg), base mat (kg), its rotary inertia (kg·m²)."""
    return np.r_[np.asarray(floor_mass, dtype=float), foundation.mass, foundation.rotary_inertia]


def founded_matrix(fixed: np.ndarray, elevation: np.ndarray, base: np.ndarray) -> np.ndarray:
    """``Tᵀ fixed T + diag(0 … 0, base)``: a fixed-base stiffness or damping matrix on the founded DOF.

    *fixed*: (n, n) on the deformations; *base*: (2,) the foundation's sway and rocking terms.
    """
    t = base_transform(elevation)
    out = t.T @ np.asarray(fixed, dtype=float) @ t
    out[-BASE_DOFS:, -BASE_DOFS:] += np.diag(np.asarray(base, dtype=float))
    return out


def founded_weights(a: np.ndarray, elevation: np.ndarray) -> np.ndarray:
    """(n + 2,) a fixed-base drift's weights *a* (over the n floors) on the founded DOF: ``a T``.

    Storey i: ``δ_i = x_i − x_(i−1) − h_i θ_b`` (storey 1: ``x_1 − u_b − h_1 θ_b``).
    """
    return np.asarray(a, dtype=float) @ base_transform(elevation)


def effective_damping(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray) -> tuple[float, float]:
    """The fundamental mode of the damped system ``M q̈ + C q̇ + K q = 0``: ``(period s, damping ratio)``.

    From the complex eigenvalues λ of its first-order form: the underdamped pair of smallest
    |λ|, period ``2π/Im λ`` (damped) and ratio ``−Re λ / |λ|``.  *mass*: (N,) the diagonal of M.
    """
    m = np.asarray(mass, dtype=float)
    n = m.size
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, :n] = -stiffness / m[:, None]
    a[n:, n:] = -damping / m[:, None]
    eig = np.linalg.eigvals(a)
    oscillating = eig[eig.imag > 1e-12 * np.abs(eig).max(initial=1.0)]
    if oscillating.size == 0:
        return float("nan"), float("nan")
    first = oscillating[np.argmin(np.abs(oscillating))]
    return 2.0 * math.pi / float(first.imag), float(-first.real / abs(first))

