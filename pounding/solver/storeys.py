"""Compiled kernels of the storey restoring force (elastic, bilinear, Bouc–Wen).

The models and their parameters are in :mod:`pounding.hysteresis`; here are
the branches the integrator inlines.  ``prm`` is a model's kernel vector
``[u_y, α, n, β, γ, A]``; ``k`` the storey's elastic stiffness (N/m); ``r``
the storey's hysteretic state: the plastic drift Δ_p (m) of the bilinear
model, the dimensionless z of Bouc–Wen (docs/physics.md §7).

Bilinear modes (``mode``): :data:`ELASTIC` (Δ_p fixed), :data:`YIELD_POSITIVE`
and :data:`YIELD_NEGATIVE` (Δ_p follows Δ).  The solver locates the switches
between them as events: yield onset where ``Δ − Δ_p`` reaches ``±u_y`` in the
elastic mode, unloading where the drift rate changes sign while yielding.
Bouc–Wen has no modes: its ż is continuous in Δ̇, so the step-size control
resolves its velocity reversals.
"""

from __future__ import annotations

from numba import njit

from pounding.hysteresis import MODEL_BILINEAR, MODEL_BOUC_WEN

__all__ = ["restoring_force", "state_rate", "recoverable_energy", "ELASTIC", "YIELD_POSITIVE",
           "YIELD_NEGATIVE"]

ELASTIC = 0
YIELD_POSITIVE = 1
YIELD_NEGATIVE = -1


@njit(cache=True)
def restoring_force(model, prm, k, drift, r):
    """Storey (column) shear, N, at *drift* (m) with state *r*; P-Delta and damping not included."""
    if model == MODEL_BILINEAR:
        return prm[1] * k * drift + (1.0 - prm[1]) * k * (drift - r)
    if model == MODEL_BOUC_WEN:
        return prm[1] * k * drift + (1.0 - prm[1]) * k * prm[0] * r
    return k * drift


@njit(cache=True)
def state_rate(model, prm, mode, drift_rate, r):
    """Time derivative of the state *r* at drift rate *drift_rate* (m/s) in *mode*."""
    if model == MODEL_BILINEAR:
        return drift_rate if mode != ELASTIC else 0.0
    if model == MODEL_BOUC_WEN:
        n = prm[2]
        power = abs(r) if n == 1.0 else (r * r if n == 2.0 else abs(r) ** n)  # |z|^n; exact for n = 1, 2
        same = 1.0 if drift_rate * r > 0.0 else (-1.0 if drift_rate * r < 0.0 else 0.0)
        return drift_rate / prm[0] * (prm[5] - power * (prm[3] * same + prm[4]))
    return 0.0


@njit(cache=True)
def recoverable_energy(model, prm, k, drift, r):
    """Energy the storey would give back on unloading to zero force, J.

    Elastic: ½kΔ².  Bilinear: ½αkΔ² + ½(1 − α)k(Δ − Δ_p)².  Bouc–Wen: ½αkΔ²
    plus the elastic energy of the hysteretic spring at its initial stiffness,
    ½(1 − α)k(u_y z)².  The storey's dissipated (hysteretic) energy is its
    work ∫F dΔ minus this.
    """
    if model == MODEL_BILINEAR:
        elastic = drift - r
        return 0.5 * prm[1] * k * drift * drift + 0.5 * (1.0 - prm[1]) * k * elastic * elastic
    if model == MODEL_BOUC_WEN:
        spring = prm[0] * r
        return 0.5 * prm[1] * k * drift * drift + 0.5 * (1.0 - prm[1]) * k * spring * spring
    return 0.5 * k * drift * drift
