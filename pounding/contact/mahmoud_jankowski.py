"""Modified linear viscoelastic contact (Mahmoud & Jankowski 2011): damped only while approaching.

    F = k·δ + c·δ̇    while approaching (δ̇ > 0),
    F = k·δ          while separating (δ̇ ≤ 0),

with ``c = 2ζ·sqrt(k·m_eff)``, ``m_eff = m1·m2/(m1 + m2)`` from the two floor
masses.  Removing the dashpot in the restitution phase removes the tension
of the Kelvin–Voigt element at the end of the contact (its force is
``k·δ ≥ 0`` there) and the jump back from ``c·v`` at separation.

Restitution relation (derived here; docs/physics.md "Modified linear viscoelastic")
------------------------------------------------------------------------------------
For two free bodies the approach is a damped oscillator ``m·δ̈ + c·δ̇ + k·δ = 0``
from ``δ = 0``, ``δ̇ = v0`` to ``δ̇ = 0``; the restitution is undamped, so the
rebound speed is ``ω·δmax`` (``ω = sqrt(k/m)``, energy ``½kδmax²`` returned).
With ``ζ < 1`` the peak comes at ``ω_d·t* = arccos ζ`` and ``δmax = (v0/ω)·exp(−ζ·arccos ζ/√(1−ζ²))``,
hence

    e = exp(−ζ·φ(ζ)),   φ(ζ) = arccos(ζ)/√(1 − ζ²) (ζ < 1),  1 (ζ = 1),  arccosh(ζ)/√(ζ² − 1) (ζ > 1),

exact, independent of k and the masses.  ``ζ·φ(ζ)`` grows from 0 to ∞, so
every 0 < e ≤ 1 has one ζ (critical damping gives e = 1/ê = 0.368, ê Euler's
number; lower restitutions need ζ > 1).  :func:`damping_ratio` solves it.

The relation ``ζ = −ln e / sqrt(π² + ln² e)`` that is sometimes quoted with
this model is the Kelvin–Voigt one (Anagnostopoulos 1988: the dashpot acts
over the whole half period, ``ω_d·t = π``).  It could not be confirmed
against the paper (not reachable from here); used with this model it damps
only half a cycle and gives ``e_post = exp(−ζ·φ(ζ))`` ≈ ``sqrt(e)`` for
small damping (e = 0.5 → 0.72), so this module uses the exact relation
above, which the ball drop of ``pounding verify`` (row
``mahmoud-jankowski``) confirms: e_post = e_pre to ~1e-9 for a free impact.

References
----------
Mahmoud, S. & Jankowski, R. (2011). Modified linear viscoelastic model of
earthquake-induced structural pounding. Iranian Journal of Science and
Technology, Transactions of Civil Engineering 35(C1), 51-62.
Anagnostopoulos, S.A. (1988). EESD 16, 443-456 (the Kelvin–Voigt model it modifies).
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field

from pounding.contact.laws import (ContactLaw, LawKernels, N_PARAMETERS, Positive, Restitution, effective_mass,
                                   register)

__all__ = ["MahmoudJankowski", "damping_ratio", "restitution_of", "APPROACH", "RECEDE"]

#: Modes of a closed contact: the dashpot acts (approaching) or not (receding).
APPROACH = 0
RECEDE = 1


def restitution_of(zeta: float) -> float:
    """e = exp(−ζ·φ(ζ)) of a free impact with damping ratio *zeta* ≥ 0 (module docstring)."""
    if zeta == 0.0:
        return 1.0
    if abs(zeta - 1.0) < 1e-7:  # φ → 1 on both sides; the formulas are 0/0 at ζ = 1
        phi = 1.0
    elif zeta < 1.0:
        phi = math.acos(zeta) / math.sqrt(1.0 - zeta * zeta)
    else:
        phi = math.acosh(zeta) / math.sqrt(zeta * zeta - 1.0)
    return math.exp(-zeta * phi)


def damping_ratio(restitution: float) -> float:
    """ζ with ``restitution_of(ζ) = e`` for 0 < e ≤ 1 (0 at e = 1), to 1e-15 relative."""
    from scipy.optimize import brentq

    if restitution >= 1.0:
        return 0.0
    target = -math.log(restitution)
    high = 1.0
    while high * (math.acosh(high) / math.sqrt(high * high - 1.0) if high > 1.0 else 1.0) < target:
        high *= 2.0
    return brentq(lambda z: -math.log(restitution_of(z)) - target, 0.0, high, xtol=1e-300, rtol=4.0 * 2.0**-52)


# --------------------------------------------------------------------------- #
# Kernels (compiled by pounding.solver.kernels); prm = [k N/m, c N·s/m]
# --------------------------------------------------------------------------- #


def mode_force(prm, impact_constant, mode, delta, delta_rate, q):
    """k·δ, plus c·δ̇ while approaching (N)."""
    if mode == APPROACH:
        return prm[0] * delta + prm[1] * delta_rate
    return prm[0] * delta


def potential(prm, delta, q):
    """½·k·δ² (J)."""
    return 0.5 * prm[0] * delta * delta


def onset_mode(prm, v0):
    """Approaching at a closure with v0 > 0."""
    return APPROACH if v0 > 0.0 else RECEDE


def switch_count(prm):
    """One switch: the sign of δ̇."""
    return 1


def switch_value(prm, impact_constant, mode, which, delta, delta_rate, q):
    """+δ̇ while approaching, −δ̇ while receding (m/s)."""
    return delta_rate if mode == APPROACH else -delta_rate


def implied_mode(prm, impact_constant, delta, delta_rate, q):
    """Approaching while δ̇ > 0."""
    return APPROACH if delta_rate > 0.0 else RECEDE


@register
class MahmoudJankowski(ContactLaw):
    """Modified linear viscoelastic contact: ``F = k·δ + c·δ̇`` approaching, ``k·δ`` separating.

    ``c = 2ζ·sqrt(k·m_eff)``, ζ from the restitution by the exact relation of
    this model (:func:`damping_ratio`, module docstring); ``m_eff`` from the
    two floor masses.  Never pulls.

    Reference: Mahmoud, S. & Jankowski, R. (2011). Iranian Journal of Science
    and Technology, Transactions of Civil Engineering 35(C1), 51-62.
    """

    name: ClassVar[str] = "mahmoud-jankowski"
    reference: ClassVar[str] = "Mahmoud & Jankowski (2011), Iran. J. Sci. Technol. Trans. Civ. Eng. 35(C1), 51-62"
    dissipative: ClassVar[bool] = True
    kernels: ClassVar[LawKernels] = LawKernels(mode_force=mode_force, potential=potential, onset_mode=onset_mode,
                                               switch_count=switch_count, switch_value=switch_value,
                                               implied_mode=implied_mode)
    checks: ClassVar[tuple[str, ...]] = ("implied_mode_force", "elastic_potential", "never_pulls",
                                         "dissipation_nonnegative", "free_restitution")

    law: Literal["mahmoud-jankowski"] = "mahmoud-jankowski"
    k: Positive = Field(description="contact stiffness, N/m")
    restitution: Restitution = Field(description="coefficient of restitution e, 0 < e <= 1")

    @property
    def damping_ratio(self) -> float:
        """ζ of the exact relation e = exp(−ζ·φ(ζ))."""
        return damping_ratio(self.restitution)

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        out = np.zeros(N_PARAMETERS)
        out[0] = self.k
        out[1] = 2.0 * self.damping_ratio * math.sqrt(self.k * effective_mass(mass_left, mass_right))
        return out

    @classmethod
    def for_ball_drop(cls, restitution: float, *, mass: float, kh: float, v0: float) -> MahmoudJankowski:
        """The ball drop's law (``pounding verify``): k = the Hertz secant ``kh·sqrt(δmax)``, like ``linear``."""
        dmax = (5.0 * mass * v0 * v0 / (4.0 * kh)) ** 0.4
        return cls(k=kh * math.sqrt(dmax), restitution=restitution)
