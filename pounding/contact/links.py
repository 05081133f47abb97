"""Permanent links between adjacent floors: the coupling dampers used to prevent pounding.

A link joins two floors of neighbouring buildings for the whole run (no gap,
never open). Its force F (N, positive pushing the left floor left and the
right floor right, like a contact's) depends on the relative displacement
``δ = u_L − u_R`` (m) and its rate ``δ̇`` (m/s); unlike a contact it pulls as
well as pushes. One pydantic class per element, registered by name in
:data:`LINK_LAWS` (the style of :mod:`pounding.contact.laws`); the compiled
force, internal rate and stored energy are branches of
:mod:`pounding.solver.kernels` (docs/physics.md §9).

Contract of a link law
----------------------
``law_id``
    Integer that selects the kernel branch, given by :func:`register`:
    FIRST_LINK_ID (20) + the place in :data:`LINK_LAWS` (the contact laws'
    ids stay below).
``kernel_parameters()``
    ``[stiffness, damping]`` padded to :data:`pounding.contact.laws.N_PARAMETERS`.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from pounding.contact.laws import N_PARAMETERS
from pounding.registry import add_numbered

__all__ = ["LinkLaw", "ViscousLink", "KelvinLink", "MaxwellLink", "LINK_LAWS", "register", "FIRST_LINK_ID",
           "LINK_VISCOUS", "LINK_KELVIN", "LINK_MAXWELL"]

#: First kernel branch id of the link laws (contact laws use ids below it); a link's id is
#: FIRST_LINK_ID + its place in :data:`LINK_LAWS`.
FIRST_LINK_ID = 20

Positive = Annotated[float, Field(gt=0.0)]


class LinkLaw(BaseModel):
    """Base class: a permanent link element with validated parameters."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: ClassVar[str]
    law_id: ClassVar[int]
    reference: ClassVar[str]
    #: Checks of tests/test_registry_contract.py that apply to the link (its kind).
    checks: ClassVar[tuple[str, ...]] = ("dissipation_nonnegative",)

    law: str

    def kernel_parameters(self) -> np.ndarray:
        """``[stiffness N/m, damping N·s/m]`` padded with zeros."""
        out = np.zeros(N_PARAMETERS)
        out[0] = getattr(self, "stiffness", 0.0)
        out[1] = getattr(self, "damping", 0.0)
        return out

    def describe(self) -> str:
        """One-line description for summaries and archive attributes."""
        fields = ", ".join(f"{k}={v}" for k, v in self.model_dump().items() if k != "law")
        return f"{self.name}({fields})"


LINK_LAWS: dict[str, type[LinkLaw]] = {}


def register(cls: type[LinkLaw]) -> type[LinkLaw]:
    """Class decorator: add a link law to :data:`LINK_LAWS` under ``cls.name`` (a name is taken once); its ``law_id`` is
    FIRST_LINK_ID + its place."""
    return add_numbered(LINK_LAWS, cls, "link law", "law_id", first=FIRST_LINK_ID)


@register
class ViscousLink(LinkLaw):
    """Linear viscous damper: ``F = c·δ̇``.

    Reference: Soong, T.T. & Dargush, G.F. (1997). Passive Energy Dissipation
    Systems in Structural Engineering. Wiley, ch. 6 (viscous fluid dampers).
    """

    name: ClassVar[str] = "viscous"
    checks: ClassVar[tuple[str, ...]] = ("elastic_potential", "dissipation_nonnegative")
    reference: ClassVar[str] = "Soong & Dargush (1997) Passive Energy Dissipation Systems, ch. 6"

    law: Literal["viscous"] = "viscous"
    damping: Positive = Field(description="damping coefficient c, N s/m")


@register
class KelvinLink(LinkLaw):
    """Kelvin (Voigt) element, a spring beside a dashpot: ``F = k·δ + c·δ̇``.

    Reference: Westermo, B.D. (1989). The dynamics of interstructural
    connection to prevent pounding. Earthquake Eng. Struct. Dyn. 18, 687-699
    (linked adjacent buildings).
    """

    name: ClassVar[str] = "kelvin"
    checks: ClassVar[tuple[str, ...]] = ("elastic_potential", "dissipation_nonnegative")
    reference: ClassVar[str] = "Westermo (1989) EESD 18, 687-699"

    law: Literal["kelvin"] = "kelvin"
    stiffness: Positive = Field(description="spring stiffness k, N/m")
    damping: Positive = Field(description="damping coefficient c, N s/m")


@register
class MaxwellLink(LinkLaw):
    """Maxwell element, a spring in series with a dashpot.

    Its force q is the internal state: ``q̇ = k·(δ̇ − q/c)``, ``F = q``; the
    relaxation time is c/k. The standard model of a fluid viscous damper with
    brace flexibility (OpenSees ``ViscousDamper`` with exponent 1).

    Reference: Constantinou, M.C. & Symans, M.D. (1993). Experimental study of
    seismic response of buildings with supplemental fluid dampers. Struct.
    Design Tall Build. 2, 93-132.
    """

    name: ClassVar[str] = "maxwell"
    reference: ClassVar[str] = "Constantinou & Symans (1993) Struct. Design Tall Build. 2, 93-132"

    law: Literal["maxwell"] = "maxwell"
    stiffness: Positive = Field(description="spring (brace) stiffness k, N/m")
    damping: Positive = Field(description="dashpot coefficient c, N s/m")


#: Kernel branch ids of the link laws, read from the registry (compile-time constants of the kernels).
LINK_VISCOUS = ViscousLink.law_id
LINK_KELVIN = KelvinLink.law_id
LINK_MAXWELL = MaxwellLink.law_id
