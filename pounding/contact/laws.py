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
    Integer that selects the branch of the compiled kernels: given by
    :func:`register` (the law's place in :data:`LAWS`), never by hand.
``kernel_parameters(mass_left, mass_right)``
    A float64 vector of length :data:`N_PARAMETERS` handed to the kernels.
``mode_force(law_id, prm, impact_constant, mode, δ, δ̇, q)``
    Contact force (N, ≥ 0 unless the law allows tension) while the contact is
    closed, in the contact's mode (:mod:`pounding.solver.kernels`);
    ``force(law_id, prm, impact_constant, δ, δ̇, q)`` is the same routine in
    the mode the state implies.  ``impact_constant`` is fixed once per impact by
    ``onset_constant`` at the located instant of gap closure; ``q`` is the
    law's internal state (the hysteretic force of the bilinear law), reset to
    0 at every gap closure and advanced by ``internal_rate``.
``instantaneous``
    True for laws that act as a velocity jump at the located closure instead
    of a force (stereo-mechanical); the solver applies ``jump_impulse``.
``onset_constant(law_id, prm, v0)``
    The per-impact constant from the approach velocity ``v0`` (m/s); for
    Hertz-damp this is ξ.
``potential(law_id, prm, δ, q)``
    Elastic energy stored in the contact (J), for the energy audit.

``onset_xi``, ``checks``, ``kernels``, ``for_ball_drop``
    Whether the per-impact constant is a ξ the archive reports; the checks of
    tests/test_registry_contract.py that apply; the law's own compiled
    behaviour (:class:`LawKernels`) and its ball-drop row, for a law written
    in a module of its own.

The laws of this module have their compiled branches in
:mod:`pounding.solver.kernels`.  A new law is one module of its own with its
class and its :class:`LawKernels`, one line in :data:`LAW_MODULES` and one
row of tests/data/registry_examples.yaml (docs/adding-a-law.md;
:mod:`pounding.contact.mahmoud_jankowski` is the example).
"""

from __future__ import annotations

import importlib
import math
from typing import Annotated, Callable, ClassVar, Literal, NamedTuple

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from pounding.contact import xi as xi_formulas
from pounding.errors import PoundingError, did_you_mean
from pounding.registry import add_numbered, lookup

__all__ = [
    "ContactLaw",
    "effective_mass",
    "HertzDamp",
    "Hertz",
    "Linear",
    "Kelvin",
    "Jankowski",
    "Bilinear",
    "StereoMechanical",
    "Bumper",
    "LAWS",
    "register",
    "law_from_mapping",
    "LawKernels",
    "LAW_MODULES",
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

# --------------------------------------------------------------------------- #
# The kernels of a law written in a module of its own (docs/adding-a-law.md).
# Plain Python on floats and the parameter vector ``prm``: the solver compiles
# them (pounding.solver.kernels) and dispatches to them by ``law_id``.
# --------------------------------------------------------------------------- #


def no_onset_constant(prm, v0):
    """Default ``onset_constant``: no per-impact constant (0.0)."""
    return 0.0


def first_mode(prm, v0):
    """Default ``onset_mode`` (and, with other arguments, ``implied_mode``): mode 0."""
    return 0


def no_switches(prm):
    """Default ``switch_count``: the force is one formula while closed."""
    return 0


def no_internal_rate(prm, mode, delta, delta_rate):
    """Default ``mode_internal_rate``: no internal state (0.0 N/s)."""
    return 0.0


def no_switch_value(prm, impact_constant, mode, which, delta, delta_rate, q):
    """Default ``switch_value``: 1.0 (positive: a switch the mode does not have never fires)."""
    return 1.0


def other_mode(mode, which):
    """Default ``next_mode``: toggles between modes 0 and 1."""
    return 1 - mode


def same_internal(prm, mode, delta, delta_rate, q):
    """Default ``snapped_internal``: the internal state as it is."""
    return q


def mode_zero(prm, impact_constant, delta, delta_rate, q):
    """Default ``implied_mode``: mode 0."""
    return 0


def no_internal_tolerance(prm, atol_displacement):
    """Default ``internal_tolerance``: 0.0 (no internal state to control)."""
    return 0.0


def linear_duration(prm, v0, effective_mass):
    """Default ``contact_duration`` (s): the half period ``π·sqrt(m/k)`` with ``k = prm[0]`` (N/m)."""
    return math.pi * math.sqrt(effective_mass / prm[0])


class LawKernels(NamedTuple):
    """The compiled behaviour of a law written in a module of its own: plain Python functions.

    Each is compiled by :mod:`pounding.solver.kernels` (numba ``njit``), so it
    may use only ``math``, arithmetic, comparisons and indexing of ``prm``
    (the law's float vector of length :data:`N_PARAMETERS`).  Arguments:
    ``impact_constant`` the constant fixed at the located closure, ``mode``
    the contact's integer mode, ``which`` a switch index, ``delta`` the
    penetration (m), ``delta_rate`` its rate (m/s), ``q`` the internal state.
    ``mode_force`` and ``potential`` have no default; the others describe a
    law without modes, internal state or per-impact constant.

    mode_force(prm, impact_constant, mode, delta, delta_rate, q) -> N (only called with delta > 0)
    potential(prm, delta, q) -> J, elastic energy stored (only called with delta > 0)
    onset_constant(prm, v0) -> the per-impact constant from the approach velocity v0 (m/s)
    onset_mode(prm, v0) -> mode at the located closure
    switch_count(prm) -> number of switch functions of a mode (at most pounding.solver.kernels.N_SWITCHES)
    switch_value(prm, impact_constant, mode, which, delta, delta_rate, q) -> > 0 while the mode holds
    next_mode(mode, which) -> mode entered where switch *which* crosses 0
    snapped_internal(prm, mode, delta, delta_rate, q) -> internal state put on the new mode's branch
    mode_internal_rate(prm, mode, delta, delta_rate) -> rate of the internal state
    implied_mode(prm, impact_constant, delta, delta_rate, q) -> the mode the state implies (no history)
    internal_tolerance(prm, atol_displacement) -> absolute tolerance of the internal state
    contact_duration(prm, v0, effective_mass) -> s, free-impact duration estimate (first step inside)
    """

    mode_force: Callable
    potential: Callable
    onset_constant: Callable = no_onset_constant
    onset_mode: Callable = first_mode
    switch_count: Callable = no_switches
    switch_value: Callable = no_switch_value
    next_mode: Callable = other_mode
    snapped_internal: Callable = same_internal
    mode_internal_rate: Callable = no_internal_rate
    implied_mode: Callable = mode_zero
    internal_tolerance: Callable = no_internal_tolerance
    contact_duration: Callable = linear_duration


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
    instantaneous: ClassVar[bool] = False
    #: The law's compiled behaviour when it is written in a module of its own (docs/adding-a-law.md);
    #: None for the laws of this module, whose branches are in pounding.solver.kernels.
    kernels: ClassVar[LawKernels | None] = None
    #: Checks of tests/test_registry_contract.py that apply to the law (its kind): see that file.
    checks: ClassVar[tuple[str, ...]] = ()
    #: True if the per-impact constant fixed at the located closure (``onset_constant``) is a
    #: damping constant ξ (N·s/m^2.5), reported per impact as ``impact_xi`` in the run archive.
    onset_xi: ClassVar[bool] = False

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

    @classmethod
    def for_ball_drop(cls, restitution: float, *, mass: float, kh: float, v0: float) -> ContactLaw | None:
        """The law's row in the ball-drop verification (``pounding verify``), or None for no row.

        A law written in a module of its own returns itself for a ball of
        *mass* (kg) hitting a rigid surface at *v0* (m/s) with restitution
        *restitution*, ``kh`` (N/m^1.5) the test's Hertz stiffness; the laws
        of this module have their rows written in :mod:`pounding.studies.verify`.
        """
        return None


LAWS: dict[str, type[ContactLaw]] = {}


def register(cls: type[ContactLaw]) -> type[ContactLaw]:
    """Class decorator: add a law to :data:`LAWS` under ``cls.name`` (a name is taken once).

    Its ``law_id`` is its place in :data:`LAWS` (:func:`pounding.registry.add_numbered`).
    """
    return add_numbered(LAWS, cls, "contact law", "law_id")


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
    checks: ClassVar[tuple[str, ...]] = ('elastic_potential', 'never_pulls', 'dissipation_nonnegative')
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
    checks: ClassVar[tuple[str, ...]] = ('elastic_potential', 'never_pulls', 'dissipation_nonnegative')
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
    checks: ClassVar[tuple[str, ...]] = ('implied_mode_force', 'elastic_potential', 'never_pulls', 'dissipation_nonnegative')
    reference: ClassVar[str] = "Muthukumar & DesRoches (2006), EESD 35, 811-828; Ye, Li & Zhu (2009), EESD 38, 1135-1142"
    dissipative: ClassVar[bool] = True
    onset_xi: ClassVar[bool] = True

    law: Literal["hertz-damp"] = "hertz-damp"
    kh: Positive = Field(description="Hertz stiffness, N/m^1.5")
    restitution: Restitution = Field(description="coefficient of restitution e, 0 < e <= 1")
    xi: str = Field("exact", description="name of the xi formula (pounding.xi)")
    tension: Literal["clamp", "allow"] = "clamp"
    min_impact_velocity: Positive = Field(MIN_IMPACT_VELOCITY, description="floor on v0, m/s")

    @field_validator("xi")
    @classmethod
    def _known_formula(cls, value: str) -> str:
        try:
            return xi_formulas.get(value).key
        except PoundingError as exc:
            raise ValueError(str(exc)) from None

    @property
    def p(self) -> float:
        """Dimensionless p(e) = ξ·v0/kh of the chosen formula."""
        return xi_formulas.get(self.xi)(self.restitution)

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        return _pack(self.kh, self.p, self.min_impact_velocity, 1.0 if self.tension == "allow" else 0.0)

    def damping_constant(self, v0: float) -> float:
        """ξ (N·s/m^2.5) for an approach velocity *v0* (m/s), with the floor applied."""
        return self.p * self.kh / max(v0, self.min_impact_velocity)


def effective_mass(mass_left: float, mass_right: float) -> float:
    """m1·m2/(m1+m2), kg: the two floor masses stand for the colliding bodies (a fixed wall: inf, m_eff = m)."""
    if math.isinf(mass_left) or math.isinf(mass_right):
        return min(mass_left, mass_right)
    return mass_left * mass_right / (mass_left + mass_right)


@register
class Kelvin(ContactLaw):
    """Kelvin–Voigt spring-dashpot, ``F = k·δ + c·δ̇`` (Anagnostopoulos 1988).

    ``c = 2ζ·sqrt(k·m_eff)`` with ``ζ = −ln e / sqrt(π² + ln² e)`` (exact for
    a free linear impact), ``m_eff`` from the two floor masses.  The force
    jumps to ``c·v0`` at the touch and turns negative (pulls) before
    separation: ``tension: clamp`` (default) sets it to ``max(F, 0)``,
    ``tension: allow`` keeps the pull, as the original model does.

    Reference: Anagnostopoulos, S.A. (1988). Pounding of buildings in series
    during earthquakes. Earthquake Eng. Struct. Dyn. 16, 443-456.
    """

    name: ClassVar[str] = "kelvin"
    checks: ClassVar[tuple[str, ...]] = ('implied_mode_force', 'elastic_potential', 'never_pulls', 'dissipation_nonnegative')
    reference: ClassVar[str] = "Anagnostopoulos (1988), EESD 16, 443-456"
    dissipative: ClassVar[bool] = True

    law: Literal["kelvin"] = "kelvin"
    k: Positive = Field(description="contact stiffness, N/m")
    restitution: Restitution = Field(description="coefficient of restitution e, 0 < e <= 1")
    tension: Literal["clamp", "allow"] = "clamp"

    @property
    def damping_ratio(self) -> float:
        """ζ = −ln e / sqrt(π² + ln² e)."""
        log_e = math.log(self.restitution)
        return -log_e / math.sqrt(math.pi**2 + log_e**2)

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        c = 2.0 * self.damping_ratio * math.sqrt(self.k * effective_mass(mass_left, mass_right))
        return _pack(self.k, c, 1.0 if self.tension == "allow" else 0.0)


@register
class Jankowski(ContactLaw):
    """Nonlinear viscoelastic contact (Jankowski 2005).

    ``F = β·δ^1.5 + c·δ̇`` while approaching (δ̇ > 0), ``F = β·δ^1.5`` while
    separating, with ``c = 2ζ·sqrt(β·sqrt(δ)·m_eff)`` and
    ``ζ = (9√5/2)·(1 − e²)/(e·(e·(9π − 16) + 16))`` (Jankowski 2006);
    ``m_eff`` from the two floor masses.

    References
    ----------
    Jankowski, R. (2005). Non-linear viscoelastic modelling of earthquake-
    induced structural pounding. Earthquake Eng. Struct. Dyn. 34, 595-611.
    Jankowski, R. (2006). Analytical expression between the impact damping
    ratio and the coefficient of restitution in the non-linear viscoelastic
    model of structural pounding. EESD 35, 517-524.
    """

    name: ClassVar[str] = "jankowski"
    checks: ClassVar[tuple[str, ...]] = ('implied_mode_force', 'elastic_potential', 'never_pulls', 'dissipation_nonnegative')
    reference: ClassVar[str] = "Jankowski (2005), EESD 34, 595-611; Jankowski (2006), EESD 35, 517-524"
    dissipative: ClassVar[bool] = True

    law: Literal["jankowski"] = "jankowski"
    beta: Positive = Field(description="impact stiffness β, N/m^1.5")
    restitution: Restitution = Field(description="coefficient of restitution e, 0 < e <= 1")

    @property
    def damping_ratio(self) -> float:
        """ζ of Jankowski (2006)."""
        e = self.restitution
        return 9.0 * math.sqrt(5.0) / 2.0 * (1.0 - e * e) / (e * (e * (9.0 * math.pi - 16.0) + 16.0))

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        return _pack(self.beta, self.damping_ratio, effective_mass(mass_left, mass_right))


@register
class Bilinear(ContactLaw):
    """Muthukumar's bilinear impact element (OpenSees ``ImpactMaterial``).

    Loading follows ``K1`` up to the yield penetration ``δy = a·δm`` and
    ``K2`` beyond; unloading follows ``K1`` down to the line ``F = K2·δ`` and
    then that line back to zero, a parallelogram loop (the rules of
    ``ImpactMaterial::setTrialStrain``).  Stiffnesses follow from the
    Hertz-damp parameters: ``Keff = kh·sqrt(δm)``,
    ``ΔE = kh·δm^2.5·(1 − e²)/2.5``, ``K1 = Keff + ΔE/(a·δm²)``,
    ``K2 = Keff − ΔE/((1 − a)·δm²)``.  ``δm`` is an assumed maximum
    penetration.  The hysteretic force is the law's internal state.

    Reference: Muthukumar, S. (2003). A contact element approach with
    hysteresis damping for the analysis and design of pounding in bridges.
    PhD thesis, Georgia Institute of Technology; Muthukumar & DesRoches (2006).
    """

    name: ClassVar[str] = "bilinear"
    checks: ClassVar[tuple[str, ...]] = ('implied_mode_force', 'never_pulls')
    reference: ClassVar[str] = "Muthukumar (2003), PhD thesis, Georgia Tech; OpenSees ImpactMaterial"
    dissipative: ClassVar[bool] = True

    law: Literal["bilinear"] = "bilinear"
    kh: Positive = Field(description="Hertz stiffness the element approximates, N/m^1.5")
    restitution: Restitution = Field(description="coefficient of restitution e, 0 < e <= 1")
    max_penetration: Positive = Field(description="assumed maximum penetration δm, m")
    yield_ratio: Annotated[float, Field(gt=0.0, lt=1.0)] = Field(0.1, description="a = δy/δm")

    @property
    def stiffnesses(self) -> tuple[float, float, float]:
        """(K1 N/m, K2 N/m, δy m)."""
        dm, a = self.max_penetration, self.yield_ratio
        k_eff = self.kh * math.sqrt(dm)
        energy = self.kh * dm**2.5 * (1.0 - self.restitution**2) / 2.5
        return k_eff + energy / (a * dm * dm), k_eff - energy / ((1.0 - a) * dm * dm), a * dm

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        k1, k2, dy = self.stiffnesses
        if k2 <= 0.0:
            raise PoundingError(f"bilinear law: K2 = {k2:.3g} N/m <= 0 for restitution {self.restitution}; "
                                "raise restitution or yield_ratio")
        return _pack(k1, k2, dy)


@register
class StereoMechanical(ContactLaw):
    """Stereo-mechanical impact: an instantaneous velocity jump (Goldsmith 1960).

    At the located gap closure the floor velocities jump to
    ``v1' = v1 − (1+e)·m2·(v1−v2)/(m1+m2)`` and
    ``v2' = v2 + (1+e)·m1·(v1−v2)/(m1+m2)``, with the two floor masses;
    there is no force history, the impulse ``(1+e)·m_eff·(v1 − v2)`` is
    recorded instead.

    Reference: Goldsmith, W. (1960). Impact: the theory and physical behaviour
    of colliding solids. Edward Arnold, London.
    """

    name: ClassVar[str] = "stereo-mechanical"
    checks: ClassVar[tuple[str, ...]] = ('free_restitution',)
    reference: ClassVar[str] = "Goldsmith (1960), Impact, Edward Arnold"
    dissipative: ClassVar[bool] = True
    instantaneous: ClassVar[bool] = True

    law: Literal["stereo-mechanical"] = "stereo-mechanical"
    restitution: Restitution = Field(description="coefficient of restitution e, 0 < e <= 1")

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        return _pack(self.restitution, effective_mass(mass_left, mass_right))


@register
class Bumper(ContactLaw):
    """A rubber or polymer bumper of thickness ``t`` on the contact face, then the hard face.

    While the layer is compressed by less than its limit ``δlim = max_compression·t``
    the bumper alone acts, as a Hunt–Crossley (Hertz-damp) element of its own::

        F_b = kb·δ^1.5 + ξb·δ^1.5·δ̇,      ξb = p(eb)·kb / max(v0, v_min)

    with ``v0`` the approach velocity at the gap closure.  Once ``δ > δlim`` the
    layer is spent and the hard contact of the face adds on, the Hertz-damp law
    of the two structures with its own ξ::

        F_h = kh·(δ − δlim)^1.5 + ξh·(δ − δlim)^1.5·δ̇,   ξh = p(e)·kh / max(v_lim, v_min)

    where ``v_lim = δ̇`` at the located instant the layer is fully compressed
    (the hard face's own impact velocity); ``F = F_b + F_h``.  ``p`` is the
    chosen ξ formula (:mod:`pounding.xi`), shared by both parts.  With
    ``tension: clamp`` (default) each part is clamped at 0 on its own (neither the
    rubber nor the hard face pulls); ``tension: allow`` keeps both formulas.
    The engagement of the hard face, its release and every clamp are located
    as events (:mod:`pounding.solver.kernels`).  ``gap`` is the clear distance
    to the bumper's surface.

    The structure — the bumper's nonlinear impact law first, the structure-to-
    structure law added once the rubber is compressed to a limit set by its
    thickness — follows Polycarpou, Komodromos & Polycarpou (2013); their
    paper's own equations and parameter values could not be consulted for this
    implementation, so both parts use the Hunt–Crossley form of the existing
    ``hertz-damp`` law (Hunt & Crossley 1975; ξ formulas of :mod:`pounding.xi`)
    with the bumper's own stiffness and restitution, which the user supplies
    from tests of the rubber.

    References
    ----------
    Polycarpou, P.C., Komodromos, P. & Polycarpou, A.C. (2013). A nonlinear
    impact model for simulating the use of rubber shock absorbers for
    mitigating the effects of structural pounding during earthquakes.
    Earthquake Eng. Struct. Dyn. 42, 81-100 (the layered structure).
    Hunt, K.H. & Crossley, F.R.E. (1975), J. Appl. Mech. 42, 440-445 (both parts).
    Muthukumar & DesRoches (2006), EESD 35, 811-828 (the hard face, as ``hertz-damp``).
    """

    name: ClassVar[str] = "bumper"
    checks: ClassVar[tuple[str, ...]] = ('implied_mode_force', 'elastic_potential', 'never_pulls', 'dissipation_nonnegative')
    reference: ClassVar[str] = ("Polycarpou, Komodromos & Polycarpou (2013), EESD 42, 81-100 (layered structure); "
                                "Hunt & Crossley (1975), J. Appl. Mech. 42, 440-445")
    dissipative: ClassVar[bool] = True
    onset_xi: ClassVar[bool] = True

    law: Literal["bumper"] = "bumper"
    thickness: Positive = Field(description="thickness t of the rubber layer, m")
    max_compression: Annotated[float, Field(gt=0.0, le=1.0)] = Field(
        description="compression at which the layer is spent, as a fraction of its thickness, 0 < r <= 1")
    bumper_kh: Positive = Field(description="Hertz stiffness of the rubber layer, N/m^1.5")
    bumper_restitution: Restitution = Field(description="coefficient of restitution of the rubber, 0 < e <= 1")
    kh: Positive = Field(description="Hertz stiffness of the hard face, N/m^1.5")
    restitution: Restitution = Field(description="coefficient of restitution of the hard face, 0 < e <= 1")
    xi: str = Field("exact", description="name of the xi formula (pounding.xi), for both parts")
    tension: Literal["clamp", "allow"] = "clamp"
    min_impact_velocity: Positive = Field(MIN_IMPACT_VELOCITY, description="floor on v0 and v_lim, m/s")

    _known_formula = field_validator("xi")(HertzDamp._known_formula.__func__)

    @property
    def limit(self) -> float:
        """δlim = max_compression·thickness (m): the penetration where the hard face engages."""
        return self.max_compression * self.thickness

    @property
    def p_bumper(self) -> float:
        """p(eb) of the chosen formula for the rubber."""
        return xi_formulas.get(self.xi)(self.bumper_restitution)

    @property
    def p(self) -> float:
        """p(e) of the chosen formula for the hard face."""
        return xi_formulas.get(self.xi)(self.restitution)

    def kernel_parameters(self, mass_left: float, mass_right: float) -> np.ndarray:
        return _pack(self.bumper_kh, self.p_bumper, self.min_impact_velocity,
                     1.0 if self.tension == "allow" else 0.0, self.kh, self.p, self.limit)

    def damping_constant(self, v0: float) -> float:
        """ξb (N·s/m^2.5) of the rubber for an approach velocity *v0* (m/s), with the floor applied."""
        return self.p_bumper * self.bumper_kh / max(v0, self.min_impact_velocity)


def law_from_mapping(fields: dict) -> ContactLaw:
    """Build a law from a mapping with a ``law`` key (used outside the YAML loader).

    Raises
    ------
    PoundingError
        For an unknown law name (with a suggestion) or invalid parameters.
    """
    from pydantic import ValidationError

    given = fields.get("law")
    name = lookup(LAWS, given)
    if name is None:
        raise PoundingError(f"unknown contact law '{given}'{did_you_mean(str(given), list(LAWS))}; "
                            f"choose one of: {', '.join(LAWS)}")
    try:
        return LAWS[name](**{**fields, "law": name})
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(x) for x in first["loc"])
        raise PoundingError(f"contact law {name}: {where}: {first['msg']}") from None


#: Contact laws written in modules of their own, one line each: importing a module registers its law
#: (after the laws above, so their ids stay put).  docs/adding-a-law.md.
LAW_MODULES: tuple[str, ...] = (
    "pounding.contact.mahmoud_jankowski",
)
for _module in LAW_MODULES:
    importlib.import_module(_module)
