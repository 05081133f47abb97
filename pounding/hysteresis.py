"""Storey hysteresis: the restoring force of a yielding storey.

One base class, :class:`StoreyHysteresis`, and one small subclass per
published model, registered by name in :data:`HYSTERESES` (the style of
:mod:`pounding.contact.laws`).  A model is a validated parameter set (a
pydantic model, so the ``hysteresis:`` mapping of a storey in the YAML is
checked key by key); its compiled kernel lives in
:mod:`pounding.solver.storeys`.

Notation (docs/physics.md §7): storey drift Δ = u_i − u_(i−1) (m), elastic
storey stiffness k (N/m, the storey's ``stiffness``), yield force F_y (N),
yield drift u_y = F_y / k (m), post-yield stiffness ratio α.

Contract of a model
-------------------
``model_id``
    Integer that selects the branch of the compiled kernels, given by
    :func:`register` (1 + the place in :data:`HYSTERESES`; 0 is elastic).
``yield_force_for(stiffness, height)``
    F_y (N) from ``yield_force`` or ``yield_drift_ratio`` (exactly one is given).
``kernel_parameters(stiffness, height)``
    A float64 vector of length :data:`N_HYSTERESIS_PARAMETERS`:
    ``[u_y, α, n, β, γ, A]`` (the last four used by Bouc–Wen only).
``initial_stiffness(stiffness)``
    The tangent dF/dΔ at rest (Δ = 0, virgin state), N/m: what P-Delta must stay
    below for the storey to stand (the static stability check of a model).

Adding a model is one subclass with its citation and one ``register`` line,
plus one branch in each kernel of :mod:`pounding.solver.storeys`.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from pounding.registry import add_numbered

__all__ = ["StoreyHysteresis", "BilinearStorey", "BoucWenStorey", "HYSTERESES", "register",
           "N_HYSTERESIS_PARAMETERS", "MODEL_ELASTIC", "MODEL_BILINEAR", "MODEL_BOUC_WEN"]

#: Length of every model's kernel parameter vector.
N_HYSTERESIS_PARAMETERS = 6

#: Kernel branch id of a storey without ``hysteresis``; a model's id is 1 + its place in
#: :data:`HYSTERESES` (:func:`register`).
MODEL_ELASTIC = 0

PostYieldRatio = Annotated[float, Field(ge=0.0, lt=1.0)]
Positive = Annotated[float, Field(gt=0.0)]


class StoreyHysteresis(BaseModel):
    """Base class: a storey's hysteretic restoring force with validated parameters.

    Exactly one of ``yield_force`` (N) and ``yield_drift_ratio`` (yield drift
    over storey height) is given.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: ClassVar[str]
    model_id: ClassVar[int]
    reference: ClassVar[str]
    #: Checks of tests/test_registry_contract.py that apply to the model (its kind).
    checks: ClassVar[tuple[str, ...]] = ("dissipation_nonnegative",)
    #: True if the model has modes whose switches the solver locates as storey events (yield onset,
    #: unloading). The integrator's storey-event search handles modes for the bilinear model only
    #: (pounding.solver.integrator tests ``model == MODEL_BILINEAR``); tests/test_registry_contract.py
    #: holds this attribute to that rule until the search reads it from here.
    has_modes: ClassVar[bool] = False

    model: str
    yield_force: Positive | None = Field(None, description="yield force F_y, N")
    yield_drift_ratio: Positive | None = Field(None, description="yield drift / storey height")
    post_yield_ratio: PostYieldRatio = Field(0.02, description="post-yield stiffness ratio α, 0 <= α < 1")

    @model_validator(mode="after")
    def _one_yield_key(self) -> StoreyHysteresis:
        if (self.yield_force is None) == (self.yield_drift_ratio is None):
            given = "both" if self.yield_force is not None else "neither"
            raise ValueError(f"give exactly one of yield_force (N) and yield_drift_ratio (yield drift / height); "
                             f"{given} given")
        return self

    def yield_force_for(self, stiffness: float, height: float) -> float:
        """F_y (N) of a storey of elastic *stiffness* (N/m) and *height* (m)."""
        if self.yield_force is not None:
            return float(self.yield_force)
        return float(self.yield_drift_ratio) * float(height) * float(stiffness)

    def initial_stiffness(self, stiffness: float) -> float:
        """Tangent stiffness dF/dΔ at rest (Δ = 0, virgin state), N/m, of a storey of elastic *stiffness* (N/m).

        The elastic stiffness k for a model whose first branch is elastic (bilinear).
        """
        return float(stiffness)

    def kernel_parameters(self, stiffness: float, height: float) -> np.ndarray:
        """``[u_y, α, n, β, γ, A]`` for the compiled kernels."""
        out = np.zeros(N_HYSTERESIS_PARAMETERS)
        out[0] = self.yield_force_for(stiffness, height) / float(stiffness)
        out[1] = self.post_yield_ratio
        return out

    def describe(self) -> str:
        """One-line description for summaries."""
        fields = ", ".join(f"{k}={v}" for k, v in self.model_dump(exclude_none=True).items() if k != "model")
        return f"{self.name}({fields})"


HYSTERESES: dict[str, type[StoreyHysteresis]] = {}


def register(cls: type[StoreyHysteresis]) -> type[StoreyHysteresis]:
    """Class decorator: add a model to :data:`HYSTERESES` under ``cls.name`` (a name is taken once)."""
    return add_numbered(HYSTERESES, cls, "storey hysteresis", "model_id", first=MODEL_ELASTIC + 1)


@register
class BilinearStorey(StoreyHysteresis):
    """Bilinear storey with kinematic hardening.

    A linear spring αk in parallel with an elastic–perfectly-plastic spring
    (1 − α)k capped at (1 − α)F_y; its plastic drift Δ_p is the state:
    ``F = αkΔ + (1 − α)k(Δ − Δ_p)``, yielding while ``|Δ − Δ_p| = u_y`` and
    the drift moves outward.  Reverse yielding starts after a force change of
    2F_y, the loop of OpenSees ``Steel01(F_y, k, α)`` without isotropic
    hardening (docs/physics.md §7).

    Reference: Filippou, F.C., Popov, E.P. & Bertero, V.V. (1983), UCB/EERC-83/19
    (``Steel01`` is its bilinear limit); Chopra, A.K. (2017), Dynamics of
    Structures, 5th ed., §5.7 (bilinear hysteresis).
    """

    name: ClassVar[str] = "bilinear"
    has_modes: ClassVar[bool] = True
    checks: ClassVar[tuple[str, ...]] = ("elastic_potential", "dissipation_nonnegative")
    reference: ClassVar[str] = "Chopra (2017) Dynamics of Structures §5.7; OpenSees Steel01 (no isotropic hardening)"

    model: Literal["bilinear"] = "bilinear"


@register
class BoucWenStorey(StoreyHysteresis):
    """Bouc–Wen smooth hysteresis.

    ``F = αkΔ + (1 − α)F_y z``, ``ż = (Δ̇/u_y)[A − |z|ⁿ(β sgn(Δ̇ z) + γ)]``;
    with A = 1 and β + γ = 1 the state z saturates at ±1, so F_y is the
    yield force.  OpenSees ``BoucWen(alpha, ko=k, n, gamma/u_yⁿ, beta/u_yⁿ, Ao=A)``
    is the same model with z in length units (docs/physics.md §7).

    Reference: Wen, Y.K. (1976). Method for random vibration of hysteretic
    systems. J. Eng. Mech. Div. ASCE 102(2), 249-263; Bouc, R. (1967).
    """

    name: ClassVar[str] = "bouc-wen"
    checks: ClassVar[tuple[str, ...]] = ("bounded_state", "dissipation_nonnegative")
    reference: ClassVar[str] = "Wen (1976) J. Eng. Mech. Div. ASCE 102(2), 249-263"

    model: Literal["bouc-wen"] = "bouc-wen"
    n: Positive = Field(1.0, description="sharpness of the yield transition, > 0")
    beta: float = Field(0.5, description="Bouc-Wen beta (multiplies sgn(dΔ/dt·z))")
    gamma: float = Field(0.5, description="Bouc-Wen gamma")
    A: Positive = Field(1.0, description="Bouc-Wen A (initial tangent of z per drift / u_y)")

    @model_validator(mode="after")
    def _bounded(self) -> BoucWenStorey:
        if self.beta + self.gamma <= 0.0:
            raise ValueError(f"beta + gamma must be > 0 for a bounded loop (got {self.beta + self.gamma:g}); "
                             "beta = gamma = 0.5 is the usual choice")
        return self

    def initial_stiffness(self, stiffness: float) -> float:
        """``k·(α + (1 − α)·A)``, N/m: dF/dΔ = αk + (1 − α)F_y·dz/dΔ with dz/dΔ = A/u_y at z = 0 (k when A = 1)."""
        alpha = float(self.post_yield_ratio)
        return float(stiffness) * (alpha + (1.0 - alpha) * float(self.A))

    def kernel_parameters(self, stiffness: float, height: float) -> np.ndarray:
        out = super().kernel_parameters(stiffness, height)
        out[2:6] = (self.n, self.beta, self.gamma, self.A)
        return out


#: Kernel branch ids of the models, read from the registry (compile-time constants of the kernels).
MODEL_BILINEAR = BilinearStorey.model_id
MODEL_BOUC_WEN = BoucWenStorey.model_id
