"""Contact laws for gap elements between adjacent floors.

One base class, :class:`ContactLaw`, and one small subclass per published
impact model, registered by name in :data:`LAWS` (the style of
``scipy.integrate._ivp``).  A law is a validated parameter set (a pydantic
model, so a YAML contact entry is checked field by field) plus a compiled
kernel that the solver calls with the penetration ``δ`` (m, positive =
overlap) and its rate ``δ̇`` (m/s).

Contract of a law
-----------------
``law_id``
    Integer that selects the branch of the compiled kernels below.
``kernel_parameters(mass_left, mass_right)``
    A float64 vector of length :data:`N_PARAMETERS` handed to the kernels.
``force(law_id, prm, impact_constant, δ, δ̇)``
    Contact force (N, ≥ 0 unless the law allows tension) while the contact is
    closed.  ``impact_constant`` is fixed once per impact by
    ``onset_constant`` at the located instant of gap closure.
``onset_constant(law_id, prm, v0)``
    The per-impact constant from the approach velocity ``v0`` (m/s); for
    Hertz-damp this is ξ.
``potential(law_id, prm, δ)``
    Elastic energy stored in the contact (J), for the energy audit.

Adding a law is one subclass with its citation, one ``register`` line and one
branch in each kernel.
"""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field, field_validator

from . import xi as xi_formulas
from .errors import PoundingError, did_you_mean

__all__ = [
    "ContactLaw",
    "HertzDamp",
    "Hertz",
    "Linear",
    "LAWS",
    "register",
    "law_from_mapping",
    "N_PARAMETERS",
    "MIN_IMPACT_VELOCITY",
]

#: Length of every law's kernel parameter vector.
N_PARAMETERS = 8

#: Default floor on the approach velocity used to compute ξ (m/s).  A grazing
#: contact (v0 → 0) would otherwise give ξ → ∞ and an arbitrarily stiff
#: damping force.  1 mm/s is two to three orders of magnitude below the
#: impact velocities of building pounding (0.1–1 m/s), so it only acts on
#: grazing contacts, where the damping force it produces,
#: ``p·kh·δ^1.5·δ̇/1e-3``, stays bounded by the elastic force scale.
MIN_IMPACT_VELOCITY = 1.0e-3

# Kernel branch identifiers.
LAW_LINEAR = 0
LAW_HERTZ = 1
LAW_HERTZ_DAMP = 2

Restitution = Annotated[float, Field(gt=0.0, le=1.0)]
Positive = Annotated[float, Field(gt=0.0)]


class ContactLaw(BaseModel):
    """Base class: a contact law with validated parameters.

    Subclasses set ``name``, ``law_id``, ``reference`` and the parameter
    fields, and implement :meth:`kernel_parameters`.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: ClassVar[str]
    law_id: ClassVar[int]
    reference: ClassVar[str]
    dissipative: ClassVar[bool] = False

    law: str

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        """Float vector for the compiled kernels (length :data:`N_PARAMETERS`).

        Parameters
        ----------
        mass_left, mass_right : float
            Masses of the two contacting floors (kg); laws that need an
            effective mass use ``m1·m2/(m1+m2)``.
        """
        raise NotImplementedError

    def describe(self) -> str:
        """One-line description for summaries and archive attributes."""
        fields = ", ".join(f"{k}={v}" for k, v in self.model_dump().items() if k != "law")
        return f"{self.name}({fields})"


LAWS: dict[str, type[ContactLaw]] = {}


def register(cls: type[ContactLaw]) -> type[ContactLaw]:
    """Class decorator: add a law to :data:`LAWS` under ``cls.name``."""
    LAWS[cls.name] = cls
    return cls


def _pack(*values: float) -> np.ndarray:
    out = np.zeros(N_PARAMETERS)
    out[: len(values)] = values
    return out


@register
class Linear(ContactLaw):
    """Linear elastic spring, ``F = k·δ``; no dissipation.

    Reference: Maison, B.F. & Kasai, K. (1992). Dynamics of pounding when two
    buildings collide. Earthquake Eng. Struct. Dyn. 21, 771-786.
    """

    name: ClassVar[str] = "linear"
    law_id: ClassVar[int] = LAW_LINEAR
    reference: ClassVar[str] = "Maison & Kasai (1992), EESD 21, 771-786"

    law: Literal["linear"] = "linear"
    k: Positive = Field(description="contact stiffness, N/m")

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        return _pack(self.k)


@register
class Hertz(ContactLaw):
    """Nonlinear elastic Hertz contact, ``F = kh·δ^1.5``; no dissipation.

    Reference: Davis, R.O. (1992). Pounding of buildings modelled by an
    impact oscillator. Earthquake Eng. Struct. Dyn. 21, 253-274.
    """

    name: ClassVar[str] = "hertz"
    law_id: ClassVar[int] = LAW_HERTZ
    reference: ClassVar[str] = "Davis (1992), EESD 21, 253-274"

    law: Literal["hertz"] = "hertz"
    kh: Positive = Field(description="Hertz stiffness, N/m^1.5")

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        return _pack(self.kh)


@register
class HertzDamp(ContactLaw):
    """Hertz-damp (Hunt–Crossley) contact: ``F = kh·δ^1.5 + ξ·δ^1.5·δ̇``.

    ξ is fixed once per impact, at the located instant of gap closure, from
    the approach velocity ``v0``: ``ξ = p(e)·kh/max(v0, min_impact_velocity)``
    with ``p(e)`` from the chosen formula (:mod:`pounding.xi`).  Inside a
    building model the structure can pull the floors apart faster than
    ``v0/p`` and the formula then turns negative; with ``tension: clamp``
    (default) the force is ``max(F, 0)``, with ``tension: allow`` it is left
    as is (what OpenSees' Hertzdamp material does).

    References
    ----------
    Hunt, K.H. & Crossley, F.R.E. (1975), J. Appl. Mech. 42, 440-445.
    Muthukumar, S. & DesRoches, R. (2006). A Hertz contact model with
    non-linear damping for pounding simulation. EESD 35, 811-828.
    Ye, K., Li, L. & Zhu, H. (2009). EESD 38, 1135-1142.
    """

    name: ClassVar[str] = "hertz-damp"
    law_id: ClassVar[int] = LAW_HERTZ_DAMP
    reference: ClassVar[str] = "Muthukumar & DesRoches (2006), EESD 35, 811-828; Ye, Li & Zhu (2009), EESD 38, 1135-1142"
    dissipative: ClassVar[bool] = True

    law: Literal["hertz-damp"] = "hertz-damp"
    kh: Positive = Field(description="Hertz stiffness, N/m^1.5")
    restitution: Restitution = Field(description="coefficient of restitution e, 0 < e <= 1")
    xi: str = Field("exact", description="name of the xi formula (pounding.xi)")
    tension: Literal["clamp", "allow"] = "clamp"
    min_impact_velocity: Positive = Field(MIN_IMPACT_VELOCITY, description="floor on v0, m/s")

    @field_validator("xi")
    @classmethod
    def _known_formula(cls, value: str) -> str:
        if xi_formulas.ALIASES.get(value, value) not in xi_formulas.FORMULAS:
            choices = list(xi_formulas.FORMULAS) + list(xi_formulas.ALIASES)
            raise ValueError(f"unknown xi formula '{value}'{did_you_mean(value, choices)}; "
                             f"choose one of: {', '.join(xi_formulas.FORMULAS)}")
        return xi_formulas.ALIASES.get(value, value)

    @property
    def p(self) -> float:
        """Dimensionless p(e) = ξ·v0/kh of the chosen formula."""
        return xi_formulas.get(self.xi)(self.restitution)

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        return _pack(self.kh, self.p, self.min_impact_velocity, 1.0 if self.tension == "allow" else 0.0)

    def damping_constant(self, v0: float) -> float:
        """ξ (N·s/m^2.5) for an approach velocity *v0* (m/s), with the floor applied."""
        return self.p * self.kh / max(v0, self.min_impact_velocity)


def law_from_mapping(fields: dict) -> ContactLaw:
    """Build a law from a mapping with a ``law`` key (used outside the YAML loader).

    Raises
    ------
    PoundingError
        For an unknown law name (with a suggestion) or invalid parameters.
    """
    from pydantic import ValidationError

    name = fields.get("law")
    if name not in LAWS:
        raise PoundingError(f"unknown contact law '{name}'{did_you_mean(str(name), list(LAWS))}; "
                            f"choose one of: {', '.join(LAWS)}")
    try:
        return LAWS[name](**fields)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(x) for x in first["loc"])
        raise PoundingError(f"contact law {name}: {where}: {first['msg']}") from None


# --------------------------------------------------------------------------- #
# Compiled kernels.  One branch per law; no Python objects inside.
# --------------------------------------------------------------------------- #


@njit(cache=True)
def onset_constant(law_id: int, prm: np.ndarray, v0: float) -> float:
    """Per-impact constant fixed at the located gap closure (ξ for Hertz-damp)."""
    if law_id == LAW_HERTZ_DAMP:
        return prm[1] * prm[0] / max(v0, prm[2])
    return 0.0


@njit(cache=True)
def force(law_id: int, prm: np.ndarray, impact_constant: float, delta: float,
          delta_rate: float) -> float:
    """Contact force (N) for penetration *delta* (m) and its rate (m/s)."""
    if delta <= 0.0:
        return 0.0
    if law_id == LAW_HERTZ_DAMP:
        d15 = delta * math.sqrt(delta)
        f = d15 * (prm[0] + impact_constant * delta_rate)
        if prm[3] == 0.0 and f < 0.0:
            return 0.0
        return f
    if law_id == LAW_HERTZ:
        return prm[0] * delta * math.sqrt(delta)
    if law_id == LAW_LINEAR:
        return prm[0] * delta
    return 0.0


@njit(cache=True)
def potential(law_id: int, prm: np.ndarray, delta: float) -> float:
    """Elastic energy stored in the contact at penetration *delta* (J)."""
    if delta <= 0.0:
        return 0.0
    if law_id == LAW_HERTZ_DAMP or law_id == LAW_HERTZ:
        return prm[0] * delta * delta * math.sqrt(delta) / 2.5
    if law_id == LAW_LINEAR:
        return 0.5 * prm[0] * delta * delta
    return 0.0
