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
    ``[u_y, α, n, β, γ, A]`` (the last four used by Bouc–Wen only); an IMK
    storey's ``[u_y, slope, k_unload, lower limit, upper limit, watch]`` at rest
    (:mod:`pounding.solver.imk` rewrites its run's copy at each branch change).
``initial_stiffness(stiffness)``
    The tangent dF/dΔ at rest (Δ = 0, virgin state), N/m: what P-Delta must stay
    below for the storey to stand (the static stability check of a model).

Adding a model is one subclass with its citation and one ``register`` line,
plus one branch in each kernel of :mod:`pounding.solver.storeys`.
"""

from __future__ import annotations

from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from pounding.registry import add_numbered

__all__ = ["StoreyHysteresis", "BilinearStorey", "BoucWenStorey", "ImkStorey", "ImkBilinearStorey",
           "ImkPeakOrientedStorey", "ImkPinchingStorey", "ImkDirection", "Deterioration", "Pinching",
           "HYSTERESES", "register", "N_HYSTERESIS_PARAMETERS", "MODEL_ELASTIC", "MODEL_BILINEAR",
           "MODEL_BOUC_WEN", "MODEL_IMK_BILINEAR", "MODEL_IMK_PEAK", "MODEL_IMK_PINCHING"]

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
    #: unloading; an IMK storey's branch changes). The integrator's storey-event search handles them for
    #: the bilinear and IMK models, by id (pounding.solver.storey_events); tests/test_registry_contract.py
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

    def described_fields(self) -> dict[str, Any]:
        """The keys and values :meth:`describe` shows: those given, without ``model``."""
        return {k: v for k, v in self.model_dump(exclude_none=True).items() if k != "model"}

    def describe(self) -> str:
        """One-line description for summaries and archives."""
        return f"{self.name}({', '.join(f'{k}={v}' for k, v in self.described_fields().items())})"


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
        """``k·(α + (1 − α)·A)``, N/m: dF/dΔ = αk + (1 − α)F_y·dz/dΔ with dz/dΔ = A/u_y at z = 0 (exactly k when
        A = 1, as the elastic stiffness a building's matrices use)."""
        if float(self.A) == 1.0:
            return float(stiffness)
        alpha = float(self.post_yield_ratio)
        return float(stiffness) * (alpha + (1.0 - alpha) * float(self.A))

    def kernel_parameters(self, stiffness: float, height: float) -> np.ndarray:
        out = super().kernel_parameters(stiffness, height)
        out[2:6] = (self.n, self.beta, self.gamma, self.A)
        return out


#: Kernel branch ids of the models, read from the registry (compile-time constants of the kernels).
MODEL_BILINEAR = BilinearStorey.model_id
MODEL_BOUC_WEN = BoucWenStorey.model_id


# --------------------------------------------------------------------------- #
# Modified Ibarra–Medina–Krawinkler (IMK) deteriorating storeys
# --------------------------------------------------------------------------- #

NonNegative = Annotated[float, Field(ge=0.0)]


class ImkDirection(BaseModel):
    """The ``negative:`` mapping of an IMK storey: backbone keys that differ in the negative direction.

    Every key is optional; a key left out takes the positive direction's value.
    Giving ``yield_force`` or ``yield_drift_ratio`` here replaces the positive
    direction's yield key of either kind.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    yield_force: Positive | None = Field(None, description="negative-direction yield force F_y-, N (magnitude)")
    yield_drift_ratio: Positive | None = Field(None, description="negative-direction yield drift / height")
    capping_strength_ratio: float | None = Field(None, description="F_c / F_y in the negative direction")
    plastic_drift_ratio: float | None = Field(None, description="θ_p in the negative direction")
    post_capping_drift_ratio: float | None = Field(None, description="θ_pc in the negative direction")
    residual_strength_ratio: float | None = Field(None, description="F_r / F_y in the negative direction")
    ultimate_drift_ratio: float | None = Field(None, description="θ_u in the negative direction")
    deterioration_rate: NonNegative | None = Field(None, description="D- (OpenSees D_neg)")

    @model_validator(mode="after")
    def _one_yield_key(self) -> ImkDirection:
        if self.yield_force is not None and self.yield_drift_ratio is not None:
            raise ValueError("negative: give at most one of yield_force (N) and yield_drift_ratio; both given")
        return self


class Deterioration(BaseModel):
    """Cyclic deterioration of an IMK storey (Ibarra, Medina & Krawinkler 2005, eq. 3-4).

    Λ (``lambda_*``) is a drift ratio: mode x has the reference hysteretic
    energy E_t = Λ_x F_y h (J; F_y the positive yield force, h the storey
    height), OpenSees' E_t = Λ M_y with Λ a rotation.  Λ = 0 switches that mode
    off.  ``c_*`` is the exponent of β_i = (E_i / (E_t − ΣE_j))^c; c = 1 is the
    value Lignos & Krawinkler (2011) use for every mode (the default).
    Modes: s basic strength, c post-capping strength, a accelerated reloading
    stiffness (peak-oriented and pinching only), k unloading stiffness.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    lambda_s: NonNegative = Field(description="Λ_s, basic strength: E_t = Λ_s F_y h (drift ratio); 0 = off")
    lambda_c: NonNegative = Field(description="Λ_c, post-capping strength (drift ratio); 0 = off")
    lambda_a: NonNegative | None = Field(None, description="Λ_a, accelerated reloading (drift ratio); 0 = off")
    lambda_k: NonNegative = Field(description="Λ_k, unloading stiffness (drift ratio); 0 = off")
    c_s: Positive = Field(1.0, description="exponent c_s (Lignos & Krawinkler 2011: 1.0)")
    c_c: Positive = Field(1.0, description="exponent c_c")
    c_a: Positive | None = Field(None, description="exponent c_a (default 1.0 where lambda_a applies)")
    c_k: Positive = Field(1.0, description="exponent c_k")


class Pinching(BaseModel):
    """Pinching of ``imk-pinching`` (Ibarra, Medina & Krawinkler 2005, Fig. 4b)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    kappa_f: Annotated[float, Field(ge=0.0, le=1.0)] = Field(
        description="κ_f: force of the pinching point over the target's force, 0..1")
    kappa_d: Annotated[float, Field(ge=0.0, le=1.0)] = Field(
        description="κ_d: drift of the pinching point, fraction of the way back from the plastic drift, 0..1")


class ImkStorey(StoreyHysteresis):
    """Modified Ibarra–Medina–Krawinkler storey (shear against drift), a base for its three variants.

    Backbone (per direction): elastic to the yield drift u_y = F_y/k, hardening
    to the capping point (u_y + θ_p h, F_c = capping_strength_ratio·F_y), then
    the post-capping branch of slope −F_c/(θ_pc h) down to the residual
    strength F_r = residual_strength_ratio·F_y, which holds until the
    ultimate drift θ_u h, where the strength drops to zero (collapse).  Cyclic
    deterioration of the backbone and of the unloading and reloading stiffness
    follows the hysteretic energy (:class:`Deterioration`).  The rules, branch
    by branch, are those of OpenSees' ``IMKBilin``, ``IMKPeakOriented`` and
    ``IMKPinching`` (Elkady & Eljisr); :mod:`pounding.studies.imk` drives the
    model and docs/hysteresis.md lists where it departs from them.

    References: Ibarra, L.F., Medina, R.A. & Krawinkler, H. (2005). Hysteretic
    models that incorporate strength and stiffness deterioration. Earthquake
    Eng. Struct. Dyn. 34(12), 1489-1511; Lignos, D.G. & Krawinkler, H. (2011).
    Deterioration modeling of steel components in support of collapse
    prediction of steel moment frames under earthquake loading. J. Struct.
    Eng. 137(11), 1291-1302.
    """

    checks: ClassVar[tuple[str, ...]] = ("cyclic_response",)
    has_modes: ClassVar[bool] = True
    reference: ClassVar[str] = ("Ibarra, Medina & Krawinkler (2005) EESD 34(12); Lignos & Krawinkler (2011) "
                                "J. Struct. Eng. 137(11)")
    #: The variant's kernel in pounding.studies.imk ("bilinear", "peak-oriented", "pinching").
    variant: ClassVar[str]
    #: Whether the variant has the accelerated-reloading mode (lambda_a, c_a).
    accelerated_reloading: ClassVar[bool] = True
    #: The nested mappings' classes (pounding.model.schema reads them for the keys of a message).
    CHILDREN: ClassVar[dict] = {"deterioration": Deterioration, "pinching": Pinching, "negative": ImkDirection}

    post_yield_ratio: float | None = Field(None, description="not an IMK key: the hardening slope is "
                                           "(capping_strength_ratio − 1) F_y / (θ_p h)")
    capping_strength_ratio: float = Field(description="F_c / F_y, ≥ 1")
    plastic_drift_ratio: float = Field(description="θ_p: plastic drift ratio from yield to capping, > 0")
    post_capping_drift_ratio: float = Field(description="θ_pc: drift ratio from capping to zero strength along "
                                            "the post-capping branch, > 0")
    residual_strength_ratio: float = Field(description="F_r / F_y, 0 ≤ F_r/F_y ≤ F_c/F_y")
    ultimate_drift_ratio: float = Field(description="θ_u: total drift ratio at which the strength drops to zero")
    deterioration: Deterioration = Field(description="cyclic deterioration: lambda_* (drift ratios), c_*")
    deterioration_rate: NonNegative = Field(1.0, description="D+: rate of cyclic deterioration in the positive "
                                            "direction (OpenSees D_pos)")
    negative: ImkDirection | None = Field(None, description="backbone keys that differ in the negative direction")

    def described_fields(self) -> dict[str, Any]:
        """As the base class, with every deterioration exponent the model runs with (``c_a``, left out, is 1.0
        where ``lambda_a`` applies)."""
        fields = super().described_fields()
        if self.accelerated_reloading and self.deterioration.c_a is None:
            given = fields["deterioration"]
            fields["deterioration"] = {key: value for key, value in given.items() if key != "c_k"}
            fields["deterioration"].update(c_a=1.0, c_k=given["c_k"])
        return fields

    @model_validator(mode="before")
    @classmethod
    def _no_post_yield_ratio(cls, data):
        if isinstance(data, dict) and data.get("post_yield_ratio") is not None:
            raise ValueError("post_yield_ratio is not a key of an IMK storey: its hardening slope is "
                             "(capping_strength_ratio − 1)·F_y / (plastic_drift_ratio·h)")
        return data

    @model_validator(mode="after")
    def _consistent(self) -> ImkStorey:
        if not self.accelerated_reloading and (self.deterioration.lambda_a is not None
                                               or self.deterioration.c_a is not None):
            raise ValueError(f"{self.name} has no accelerated-reloading mode: lambda_a and c_a are not its keys")
        if self.accelerated_reloading and self.deterioration.lambda_a is None:
            raise ValueError(f"{self.name}: deterioration needs lambda_a (accelerated reloading; 0 = off)")
        for sign in ("positive", "negative"):
            d = self.direction(sign)
            where = "" if sign == "positive" else "negative: "
            if d["capping_strength_ratio"] < 1.0 or d["plastic_drift_ratio"] <= 0.0:
                raise ValueError(f"{where}capping before yield: capping_strength_ratio must be >= 1 and "
                                 f"plastic_drift_ratio > 0 (got {d['capping_strength_ratio']:g} and "
                                 f"{d['plastic_drift_ratio']:g})")
            if d["post_capping_drift_ratio"] <= 0.0:
                raise ValueError(f"{where}post_capping_drift_ratio must be > 0 (got {d['post_capping_drift_ratio']:g})")
            if not 0.0 <= d["residual_strength_ratio"] <= d["capping_strength_ratio"]:
                raise ValueError(f"{where}residual above cap: residual_strength_ratio must be within 0 and "
                                 f"capping_strength_ratio = {d['capping_strength_ratio']:g} "
                                 f"(got {d['residual_strength_ratio']:g})")
            if d["yield_drift_ratio"] is not None:
                capping = d["yield_drift_ratio"] + d["plastic_drift_ratio"]
                if d["ultimate_drift_ratio"] <= capping:
                    raise ValueError(f"{where}ultimate before capping: ultimate_drift_ratio "
                                     f"{d['ultimate_drift_ratio']:g} must exceed the capping drift ratio "
                                     f"yield_drift_ratio + plastic_drift_ratio = {capping:g}")
        return self

    def direction(self, sign: str) -> dict:
        """The backbone keys of one direction (``"positive"`` or ``"negative"``), ``negative:`` applied."""
        keys = ("capping_strength_ratio", "plastic_drift_ratio", "post_capping_drift_ratio",
                "residual_strength_ratio", "ultimate_drift_ratio", "deterioration_rate")
        out = {key: getattr(self, key) for key in keys}
        out["yield_force"], out["yield_drift_ratio"] = self.yield_force, self.yield_drift_ratio
        if sign == "negative" and self.negative is not None:
            for key in keys:
                if getattr(self.negative, key) is not None:
                    out[key] = getattr(self.negative, key)
            if self.negative.yield_force is not None or self.negative.yield_drift_ratio is not None:
                out["yield_force"], out["yield_drift_ratio"] = self.negative.yield_force, self.negative.yield_drift_ratio
        return out

    def backbone(self, stiffness: float, height: float) -> dict:
        """The storey's IMK parameters in SI: per direction ``{fy, up, upc, uu, fcap_ratio, fres_ratio, d}``
        (N, m, m, m, -, -, -) under ``"positive"`` and ``"negative"``, and the reference energies
        ``e_s, e_c, e_a, e_k`` (J, 0 = mode off), exponents ``c_s, c_c, c_a, c_k``, ``kappa_f, kappa_d``.

        Raises
        ------
        ModelError
            Ultimate drift not beyond the capping drift (checked here when the yield force is given in N).
        """
        from pounding.errors import ModelError

        k, h = float(stiffness), float(height)
        out: dict = {}
        for sign in ("positive", "negative"):
            d = self.direction(sign)
            fy = float(d["yield_force"]) if d["yield_force"] is not None else float(d["yield_drift_ratio"]) * h * k
            up, uu = float(d["plastic_drift_ratio"]) * h, float(d["ultimate_drift_ratio"]) * h
            if uu <= fy / k + up:
                raise ModelError(f"{self.name} storey: ultimate before capping in the {sign} direction: "
                                 f"ultimate drift {uu:g} m must exceed the capping drift {fy / k + up:g} m "
                                 f"(yield {fy / k:g} m + plastic {up:g} m)")
            out[sign] = dict(fy=fy, up=up, upc=float(d["post_capping_drift_ratio"]) * h, uu=uu,
                             fcap_ratio=float(d["capping_strength_ratio"]),
                             fres_ratio=float(d["residual_strength_ratio"]), d=float(d["deterioration_rate"]))
        det = self.deterioration
        energy = out["positive"]["fy"] * h
        out.update(e_s=det.lambda_s * energy, e_c=det.lambda_c * energy, e_a=(det.lambda_a or 0.0) * energy,
                   e_k=det.lambda_k * energy, c_s=det.c_s, c_c=det.c_c, c_a=det.c_a or 1.0, c_k=det.c_k,
                   kappa_f=0.0, kappa_d=0.0)
        return out

    def kernel_parameters(self, stiffness: float, height: float) -> np.ndarray:
        """``[u_y, slope, k_unload, lower limit, upper limit, watch]`` of the storey at rest: elastic (slope k),
        its limits the yield drifts −u_y⁻ and u_y⁺ (pounding.solver.imk rewrites the row at each event)."""
        k = float(stiffness)
        p = self.backbone(k, height)
        return np.array([p["positive"]["fy"] / k, k, k, -p["negative"]["fy"] / k, p["positive"]["fy"] / k, 0.0])


@register
class ImkBilinearStorey(ImkStorey):
    """IMK with bilinear hysteresis: unloading and reloading along the elastic (deteriorating) stiffness,
    bounded by the deteriorated backbone (OpenSees ``IMKBilin``); no accelerated-reloading mode."""

    name: ClassVar[str] = "imk-bilinear"
    variant: ClassVar[str] = "bilinear"
    accelerated_reloading: ClassVar[bool] = False
    model: Literal["imk-bilinear"] = "imk-bilinear"


@register
class ImkPeakOrientedStorey(ImkStorey):
    """IMK with peak-oriented hysteresis: reloading aims at the previous peak of the direction
    (OpenSees ``IMKPeakOriented``); for flexural RC and steel components."""

    name: ClassVar[str] = "imk-peak-oriented"
    variant: ClassVar[str] = "peak-oriented"
    model: Literal["imk-peak-oriented"] = "imk-peak-oriented"


@register
class ImkPinchingStorey(ImkStorey):
    """IMK with pinched hysteresis: reloading passes through a pinching point set by κ_f and κ_d
    (OpenSees ``IMKPinching``); for shear-dominated RC, masonry and timber."""

    name: ClassVar[str] = "imk-pinching"
    variant: ClassVar[str] = "pinching"
    model: Literal["imk-pinching"] = "imk-pinching"
    pinching: Pinching = Field(description="{kappa_f, kappa_d}: the pinching point")

    def backbone(self, stiffness: float, height: float) -> dict:
        out = super().backbone(stiffness, height)
        out.update(kappa_f=float(self.pinching.kappa_f), kappa_d=float(self.pinching.kappa_d))
        return out


#: Kernel branch ids of the IMK variants (compile-time constants of the kernels).
MODEL_IMK_BILINEAR = ImkBilinearStorey.model_id
MODEL_IMK_PEAK = ImkPeakOrientedStorey.model_id
MODEL_IMK_PINCHING = ImkPinchingStorey.model_id
