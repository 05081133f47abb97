"""Compiled kernels of the storey restoring force (elastic, bilinear, Bouc–Wen, IMK).

The models and their parameters are in :mod:`pounding.hysteresis`; here are
the branches the integrator inlines.  ``table[row]`` is a storey's kernel
vector ``[u_y, α, n, β, γ, A]`` (the table of every storey and a row, not a
row view: a view costs a reference count in the solver's innermost loop);
``k`` the storey's elastic stiffness (N/m); ``r``
the storey's hysteretic state: the plastic drift Δ_p (m) of the bilinear
model, the dimensionless z of Bouc–Wen (docs/physics.md §7).

Bilinear modes (``mode``): :data:`ELASTIC` (Δ_p fixed), :data:`YIELD_POSITIVE`
and :data:`YIELD_NEGATIVE` (Δ_p follows Δ).  The solver locates the switches
between them as events: yield onset where ``Δ − Δ_p`` reaches ``±u_y`` in the
elastic mode, unloading where the drift rate changes sign while yielding.
Bouc–Wen has no modes: its ż is continuous in Δ̇, so the step-size control
resolves its velocity reversals.  An IMK storey's state r is its shear, ṙ =
slope·Δ̇ with the slope of its current branch (``table[row, 1]``, a per-run
copy the events rewrite; :mod:`pounding.solver.imk`).
"""

from __future__ import annotations

from numba import njit

from pounding.hysteresis import MODEL_BILINEAR, MODEL_BOUC_WEN, MODEL_IMK_BILINEAR, MODEL_IMK_PEAK, MODEL_IMK_PINCHING
from pounding.solver import jit

__all__ = ["restoring_force", "state_rate", "recoverable_energy", "is_imk", "ELASTIC", "YIELD_POSITIVE",
           "YIELD_NEGATIVE"]

ELASTIC = 0
YIELD_POSITIVE = 1
YIELD_NEGATIVE = -1


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def is_imk(model):
    """True for the IMK storeys (their shear is the state r; pounding.solver.imk)."""
    return model == MODEL_IMK_BILINEAR or model == MODEL_IMK_PEAK or model == MODEL_IMK_PINCHING


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def restoring_force(model, table, row, k, drift, r):
    """Storey (column) shear, N, at *drift* (m) with state *r*; P-Delta and damping not included."""
    if model == MODEL_BILINEAR:
        alpha = table[row, 1]
        return alpha * k * drift + (1.0 - alpha) * k * (drift - r)
    if model == MODEL_BOUC_WEN:
        alpha = table[row, 1]
        return alpha * k * drift + (1.0 - alpha) * k * table[row, 0] * r
    if is_imk(model):
        return r
    return k * drift


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def state_rate(model, table, row, mode, drift_rate, r):
    """Time derivative of the state *r* at drift rate *drift_rate* (m/s) in *mode*."""
    if model == MODEL_BILINEAR:
        return drift_rate if mode != ELASTIC else 0.0
    if model == MODEL_BOUC_WEN:
        n = table[row, 2]
        power = abs(r) if n == 1.0 else (r * r if n == 2.0 else abs(r) ** n)  # |z|^n; exact for n = 1, 2
        same = 1.0 if drift_rate * r > 0.0 else (-1.0 if drift_rate * r < 0.0 else 0.0)
        return drift_rate / table[row, 0] * (table[row, 5] - power * (table[row, 3] * same + table[row, 4]))
    if is_imk(model):
        return table[row, 1] * drift_rate  # the branch's slope (pounding.solver.imk.P_SLOPE)
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def recoverable_energy(model, table, row, k, drift, r):
    """Energy the storey would give back on unloading to zero force, J.

    Elastic: ½kΔ².  Bilinear: ½αkΔ² + ½(1 − α)k(Δ − Δ_p)².  Bouc–Wen: ½αkΔ²
    plus the elastic energy of the hysteretic spring at its initial stiffness,
    ½(1 − α)k(u_y z)².  IMK: ½F²/k (at the elastic stiffness: what the
    unloading stiffness's deterioration withholds counts as dissipated).  The
    storey's dissipated (hysteretic) energy is its work ∫F dΔ minus this.
    """
    if model == MODEL_BILINEAR:
        elastic = drift - r
        alpha = table[row, 1]
        return 0.5 * alpha * k * drift * drift + 0.5 * (1.0 - alpha) * k * elastic * elastic
    if model == MODEL_BOUC_WEN:
        spring = table[row, 0] * r
        alpha = table[row, 1]
        return 0.5 * alpha * k * drift * drift + 0.5 * (1.0 - alpha) * k * spring * spring
    if is_imk(model):
        return 0.5 * r * r / k
    return 0.5 * k * drift * drift


jit.stamp_solver_kernels(globals())
