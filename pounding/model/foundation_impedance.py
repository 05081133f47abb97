"""Springs and dashpots of a rigid footing on soil: the impedances of NIST GCR 12-917-21, Chapter 2.

A rigid rectangular footing of plan ``length`` × ``width`` (m), embedded ``embedment`` m in a
uniform elastic half-space (shear-wave velocity V_s, Poisson's ratio ν, density ρ) resists a
harmonic sway u or rocking θ at circular frequency ω with a complex impedance, written as a
spring and a dashpot (NIST GCR 12-917-21, 2012, §2.2, "Foundation springs and dashpots")::

    k_j = α_j(a0) · η_j · K_j            c_j = 2 β_j(a0) k_j / ω

* G = ρ V_s² (Pa), the small-strain shear modulus (no modulus reduction for strain here);
* L, B the half-length and half-width of the footing (B ≤ L: B is half the *smaller* side);
  a0 = ω B / V_s the dimensionless frequency;
* K_j the static stiffness of the footing at the surface (Table 2-2a);
* η_j the embedment correction factor (Table 2-2b), 1 at the surface;
* α_j the dynamic stiffness modifier and β_j the radiation damping ratio (Tables 2-3a, 2-3b,
  after Pais & Kausel 1988).

NIST's axes have x along the footing's long side: sway x and y, rocking about x ("xx", the soft
rocking, across the short side) and about y ("yy", along the long side).  This module turns them
into the building's axes: the footing's ``length`` is along the building's x (the direction its
floors move in a planar model), so a building shaken along x sways with ``sway_x`` and rocks with
``rocking_y`` (rotation about y), whatever the footing's proportions.

Two published fits of the static stiffness are offered: ``method="gazetas"`` (Gazetas 1991,
Table 2-2a/2-2b, "Gazetas" column; the default) and ``method="pais-kausel"`` (Pais & Kausel
1988, the other column).  The dashpots do not depend on that choice: ``c = 2βk/ω`` with
β ∝ 1/(α η K) leaves c = ρ V_s B^(n+1) N_j(a0), N_j the radiation term of Tables 2-3a/2-3b
(n = 1 for sway, 3 for rocking); :func:`impedances` computes c that way, so it is defined
at ω = 0 too, and β = c ω / (2k).

The embedded rocking dashpot: open transcriptions of Table 2-3b disagree on the sidewall terms of
its frequency-dependent part (see docs/foundations-soil.md); this module writes that part from
the same tributary-area argument that gives every other entry of the table (the base and the
sidewalls' vertical motion radiate through a0²/(c + a0²), the sidewalls' horizontal motion at all
frequencies), which reproduces Table 2-3a at zero embedment and the table's frequency-independent
sidewall term exactly.

The flexible-base period and damping of a building on such a footing (:func:`flexible_base`) use
the single-mode estimate of Veletsos & Meek (1974) with the impedances evaluated at the
flexible-base frequency, found by fixed-point iteration, and the effective damping of Veletsos &
Nair (1975) with the foundation damping of Givens, Mylonakis & Stewart (2016) (NIST GCR
12-917-21 §2.1 and §2.3).

References
----------
Gazetas, G. (1991). Formulas and charts for impedances of surface and embedded foundations.
J. Geotech. Eng. 117(9), 1363-1381.
Pais, A., Kausel, E. (1988). Approximate formulas for dynamic stiffnesses of rigid foundations.
Soil Dyn. Earthquake Eng. 7(4), 213-227.
NIST GCR 12-917-21 (2012). Soil-Structure Interaction for Building Structures. NEHRP
Consultants Joint Venture, Chapter 2.
Veletsos, A. S., Meek, J. W. (1974). Dynamic behaviour of building-foundation systems.
Earthquake Eng. Struct. Dyn. 3(2), 121-138.
Veletsos, A. S., Nair, V. V. (1975). Seismic interaction of structures on hysteretic foundations.
J. Struct. Div. ASCE 101(ST1), 109-129.
Givens, M. J., Mylonakis, G., Stewart, J. P. (2016). Modular analytical solutions for foundation
damping in soil-structure interaction applications. Earthquake Spectra 32(3), 1749-1768.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pounding.errors import PoundingError

__all__ = ["METHODS", "Soil", "Footing", "Impedance", "Impedances", "impedances", "veletsos_meek_period",
           "EquivalentOscillator", "equivalent_oscillator", "FlexibleBase", "flexible_base"]

#: The published fits of the static stiffness and embedment factors (NIST GCR 12-917-21 Tables 2-2a, 2-2b).
METHODS = ("gazetas", "pais-kausel")

#: The cap on ψ = V_La/V_s-like ratio of the radiation terms (NIST GCR 12-917-21 Table 2-3a note: ψ ≤ 2.5).
PSI_CAP = 2.5


def _positive(value: float, where: str, unit: str, fix: str, *, zero: bool = False) -> float:
    """*value* as a finite float > 0 (≥ 0 with *zero*), or a one-line PoundingError naming *where*."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise PoundingError(f"{where} must be a number in {unit} (got {value!r}); {fix}") from None
    if not math.isfinite(number) or number < 0.0 or (number == 0.0 and not zero):
        bound = ">= 0" if zero else "> 0"
        raise PoundingError(f"{where} must be finite and {bound} {unit} (got {value!r}); {fix}")
    return number


@dataclass(frozen=True)
class Soil:
    """A uniform elastic half-space under the footing.

    Attributes
    ----------
    shear_wave_velocity : float
        V_s, m/s (small-strain; reduce it for strain yourself if you need to).
    poisson : float
        ν, in [0, 0.5].
    density : float
        ρ, kg/m³.
    """

    shear_wave_velocity: float
    poisson: float
    density: float

    def __post_init__(self):
        fix = "give the soil under the footing as soil: {shear_wave_velocity: m/s, poisson: 0-0.5, density: kg/m^3}"
        object.__setattr__(self, "shear_wave_velocity",
                           _positive(self.shear_wave_velocity, "soil.shear_wave_velocity", "m/s", fix))
        object.__setattr__(self, "density", _positive(self.density, "soil.density", "kg/m^3", fix))
        nu = _positive(self.poisson, "soil.poisson", "(dimensionless)", fix, zero=True)
        if nu > 0.5:
            raise PoundingError(f"soil.poisson must be between 0 and 0.5 (got {self.poisson!r}); "
                                f"use about 0.3 for dry soil and up to 0.5 for saturated clay")
        object.__setattr__(self, "poisson", nu)

    @property
    def shear_modulus(self) -> float:
        """G = ρ V_s², Pa."""
        return self.density * self.shear_wave_velocity ** 2

    @property
    def psi(self) -> float:
        """ψ = √(2(1 − ν)/(1 − 2ν)), capped at 2.5 (NIST GCR 12-917-21 Table 2-3a)."""
        if self.poisson >= 0.5:
            return PSI_CAP
        return min(math.sqrt(2.0 * (1.0 - self.poisson) / (1.0 - 2.0 * self.poisson)), PSI_CAP)


@dataclass(frozen=True)
class Footing:
    """A rigid rectangular footing.

    Attributes
    ----------
    length : float
        Plan dimension along the building's x (the direction of shaking of a planar model), m.
    width : float
        Plan dimension along y, m.
    embedment : float
        Depth D of the footing's base below the ground surface, m (0: at the surface).  Its
        sidewalls are taken in full contact with the soil over that depth.
    """

    length: float
    width: float
    embedment: float = 0.0

    def __post_init__(self):
        fix = "give the footing as footing: {length: m, width: m, embedment: m}"
        object.__setattr__(self, "length", _positive(self.length, "footing.length", "m", fix))
        object.__setattr__(self, "width", _positive(self.width, "footing.width", "m", fix))
        object.__setattr__(self, "embedment", _positive(self.embedment, "footing.embedment", "m", fix, zero=True))

    @property
    def half_sides(self) -> tuple[float, float]:
        """(L, B): half the longer and half the shorter side, m."""
        return max(self.length, self.width) / 2.0, min(self.length, self.width) / 2.0


@dataclass(frozen=True)
class Impedance:
    """One degree of freedom of the footing (a sway or a rocking) at one frequency.

    Units are N/m and N s/m for a sway, N m/rad and N m s/rad for a rocking.

    Attributes
    ----------
    static : float
        K, the static stiffness of the footing at the surface (Table 2-2a).
    embedment_factor : float
        η (Table 2-2b); 1 at the surface.
    alpha : float
        α(a0), the dynamic stiffness modifier (Table 2-3a).
    beta : float
        β(a0), the radiation damping ratio (Tables 2-3a, 2-3b); c ω / (2k), 0 at ω = 0.
    stiffness : float
        k = α η K, the spring.
    damping : float
        c = 2 β k / ω, the dashpot (its limit at ω = 0).
    """

    static: float
    embedment_factor: float
    alpha: float
    beta: float
    stiffness: float
    damping: float


@dataclass(frozen=True)
class Impedances:
    """The footing's springs and dashpots at one frequency, in the building's axes.

    Attributes
    ----------
    frequency : float
        ω, rad/s.
    a0 : float
        ω B / V_s, B half the footing's smaller side.
    sway_x, sway_y : Impedance
        Translation along x (the footing's ``length``) and along y.
    rocking_y, rocking_x : Impedance
        Rotation about y (goes with ``sway_x``: the rocking of a building shaken along x) and about x.
    method : str
        The static-stiffness fit, one of :data:`METHODS`.
    """

    frequency: float
    a0: float
    sway_x: Impedance
    sway_y: Impedance
    rocking_y: Impedance
    rocking_x: Impedance
    method: str

    def along(self, direction: str = "x") -> tuple[Impedance, Impedance]:
        """(sway, rocking) of a building shaken along *direction* ('x' or 'y')."""
        return (self.sway_x, self.rocking_y) if direction == "x" else (self.sway_y, self.rocking_x)


def _static_gazetas(G: float, nu: float, L: float, B: float) -> dict[str, float]:
    """Gazetas (1991) static stiffnesses at the surface, NIST GCR 12-917-21 Table 2-2a (NIST axes, L ≥ B)."""
    k_y = 2.0 * G * L / (2.0 - nu) * (2.0 + 2.5 * (B / L) ** 0.85)
    i_x = 4.0 / 3.0 * L * B ** 3          # second moment of the base about x, m^4
    i_y = 4.0 / 3.0 * B * L ** 3          # ... about y
    return {"x": k_y - 0.2 / (0.75 - nu) * G * L * (1.0 - B / L),
            "y": k_y,
            "xx": G / (1.0 - nu) * i_x ** 0.75 * (L / B) ** 0.25 * (2.4 + 0.5 * B / L),
            "yy": 3.0 * G / (1.0 - nu) * i_y ** 0.75 * (L / B) ** 0.15}


def _static_pais_kausel(G: float, nu: float, L: float, B: float) -> dict[str, float]:
    """Pais & Kausel (1988) static stiffnesses at the surface, NIST GCR 12-917-21 Table 2-2a (NIST axes)."""
    r = L / B
    return {"x": G * B / (2.0 - nu) * (6.8 * r ** 0.65 + 2.4),
            "y": G * B / (2.0 - nu) * (6.8 * r ** 0.65 + 0.8 * r + 1.6),
            "xx": G * B ** 3 / (1.0 - nu) * (3.2 * r + 0.8),
            "yy": G * B ** 3 / (1.0 - nu) * (3.73 * r ** 2.4 + 0.27)}


def _embedment_gazetas(L: float, B: float, D: float) -> dict[str, float]:
    """Gazetas (1991) embedment factors, NIST GCR 12-917-21 Table 2-2b, sidewalls in full contact.

    Sidewall contact height d = D, depth of its centroid z_w = D/2, contact area A_w = 4 (L + B) D.
    """
    if D == 0.0:
        return dict.fromkeys(("x", "y", "xx", "yy"), 1.0)
    d, z_w, a_w = D, D / 2.0, 4.0 * (L + B) * D
    depth = 1.0 + 0.15 * math.sqrt(D / B)
    return {"x": depth * (1.0 + 0.52 * (z_w * a_w / (L * B ** 2)) ** 0.4),
            "y": depth * (1.0 + 0.52 * (z_w * a_w / (B * L ** 2)) ** 0.4),
            "xx": 1.0 + 1.26 * (d / B) * (1.0 + (d / B) * (d / D) ** -0.2 * math.sqrt(B / L)),
            "yy": 1.0 + 0.92 * (d / L) ** 0.6 * (1.5 + (d / L) ** 1.9 * (d / D) ** -0.6)}


def _embedment_pais_kausel(L: float, B: float, D: float) -> dict[str, float]:
    """Pais & Kausel (1988) embedment factors, NIST GCR 12-917-21 Table 2-2b."""
    r, e = L / B, D / B
    sway = 1.0 + (0.33 + 1.34 / (1.0 + r)) * e ** 0.8
    return {"x": sway, "y": sway,
            "xx": 1.0 + e + 1.6 / (0.35 + r) * e ** 2,
            "yy": 1.0 + e + 1.6 / (0.35 + r ** 4) * e ** 2}


def _alpha(L: float, B: float, a0: float) -> dict[str, float]:
    """Dynamic stiffness modifiers α(a0), NIST GCR 12-917-21 Table 2-3a (also for embedded footings, Table 2-3b)."""
    r, a2 = L / B, a0 * a0
    return {"x": 1.0, "y": 1.0,
            "xx": 1.0 - (0.55 + 0.01 * math.sqrt(r - 1.0)) * a2 / ((2.4 - 0.4 / r ** 3) + a2),
            "yy": 1.0 - 0.55 * a2 / ((0.6 + 1.4 / r ** 3) + a2)}


def _radiation(L: float, B: float, D: float, psi: float, a0: float) -> dict[str, float]:
    """Radiation terms N_j(a0): the dashpot is c_j = ρ V_s B^(n+1) N_j (n = 1 sway, 3 rocking).

    NIST GCR 12-917-21 Tables 2-3a (D = 0) and 2-3b: β_j = N_j a0 / (2 α_j K_j/(G B^n)).
    Sway: the base radiates shear waves, the sidewalls normal to the motion compression-like
    waves (ψ), those along it shear waves.  Rocking: the base (ψ) and the sidewalls' vertical
    motion through a0²/(c + a0²), the sidewalls' horizontal motion at every frequency.
    """
    r, e, a2 = L / B, D / B, a0 * a0
    return {"x": 4.0 * (r + e * (psi + r)),
            "y": 4.0 * (r + e * (1.0 + psi * r)),
            "xx": 4.0 / 3.0 * ((psi * r + 3.0 * r * e + e) * a2 / ((2.2 - 0.4 / r ** 3) + a2)
                               + (psi * r + 1.0) * e ** 3),
            "yy": 4.0 / 3.0 * ((psi * r ** 3 + 3.0 * e * r ** 2 + e * r ** 3) * a2
                               / (1.8 / (1.0 + 1.75 * (r - 1.0)) + a2)
                               + (r + psi) * e ** 3)}


def impedances(soil: Soil, footing: Footing, frequency: float, method: str = "gazetas") -> Impedances:
    """The footing's springs and dashpots at circular frequency *frequency* (rad/s).

    Parameters
    ----------
    soil : Soil
        V_s (m/s), ν, ρ (kg/m³).
    footing : Footing
        length (along x), width, embedment, m.
    frequency : float
        ω ≥ 0, rad/s (the flexible-base fundamental frequency of the building, usually).
    method : str
        ``"gazetas"`` (Gazetas 1991) or ``"pais-kausel"`` (Pais & Kausel 1988): the static
        stiffness and embedment fit of NIST GCR 12-917-21 Tables 2-2a, 2-2b.

    Returns
    -------
    Impedances
        Sways in N/m and N s/m, rockings in N m/rad and N m s/rad.
    """
    if method not in METHODS:
        raise PoundingError(f"foundation method {method!r} is not known; use one of {', '.join(METHODS)}")
    omega = _positive(frequency, "foundation frequency", "rad/s", "give the circular frequency ω", zero=True)
    L, B = footing.half_sides
    G, D, a0 = soil.shear_modulus, footing.embedment, omega * B / soil.shear_wave_velocity
    static = (_static_gazetas if method == "gazetas" else _static_pais_kausel)(G, soil.poisson, L, B)
    eta = (_embedment_gazetas if method == "gazetas" else _embedment_pais_kausel)(L, B, D)
    alpha, radiation = _alpha(L, B, a0), _radiation(L, B, D, soil.psi, a0)
    scale = soil.density * soil.shear_wave_velocity
    found = {}
    for j in ("x", "y", "xx", "yy"):
        k = alpha[j] * eta[j] * static[j]
        c = scale * B ** (2 if len(j) == 1 else 4) * radiation[j]
        found[j] = Impedance(static[j], eta[j], alpha[j], c * omega / (2.0 * k), k, c)
    along_x = footing.length >= footing.width       # the footing's long side is the building's x
    return Impedances(omega, a0,
                      sway_x=found["x" if along_x else "y"], sway_y=found["y" if along_x else "x"],
                      rocking_y=found["yy" if along_x else "xx"], rocking_x=found["xx" if along_x else "yy"],
                      method=method)


def veletsos_meek_period(period: float, stiffness: float, height: float, sway: float, rocking: float) -> float:
    """The flexible-base period T̃ = T √(1 + k/K_x + k h²/K_θ), s (Veletsos & Meek 1974).

    Exact for a single-storey structure on a massless base mat (springs in series).

    Parameters
    ----------
    period : float
        T, the fixed-base period, s.
    stiffness : float
        k, the structure's (effective) lateral stiffness, N/m.
    height : float
        h, its (effective) height above the base, m.
    sway, rocking : float
        K_x (N/m) and K_θ (N m/rad), the foundation springs.
    """
    return period * math.sqrt(1.0 + stiffness / sway + stiffness * height ** 2 / rocking)


@dataclass(frozen=True)
class EquivalentOscillator:
    """The single-degree-of-freedom stand-in for one mode of a building.

    Attributes
    ----------
    mass : float
        Effective modal mass (Σ m φ)² / Σ m φ², kg.
    height : float
        Effective height Σ m φ z / Σ m φ above the base, m.
    stiffness : float
        mass · ω², N/m.
    period : float
        2π/ω, s.
    """

    mass: float
    height: float
    stiffness: float
    period: float


def equivalent_oscillator(masses, shape, elevations, frequency: float) -> EquivalentOscillator:
    """The effective mass, height and stiffness of a mode (NIST GCR 12-917-21 §2.1: k and h of T̃).

    Parameters
    ----------
    masses : array_like
        Floor masses, kg.
    shape : array_like
        The mode's floor displacements (any scale and sign).
    elevations : array_like
        Floor heights above the foundation's base, m.
    frequency : float
        The mode's fixed-base circular frequency ω, rad/s.
    """
    m, phi, z = (np.asarray(a, dtype=float) for a in (masses, shape, elevations))
    participation = float(m @ phi)
    mass = participation ** 2 / float(m @ phi ** 2)
    return EquivalentOscillator(mass, float(m @ (phi * z)) / participation, mass * frequency ** 2,
                                2.0 * math.pi / frequency)


@dataclass(frozen=True)
class FlexibleBase:
    """A building's first mode on its foundation (NIST GCR 12-917-21 §2.1, §2.3).

    Attributes
    ----------
    fixed_period, period : float
        T (fixed base) and T̃ (flexible base), s.
    sway_period, rocking_period : float
        T_x = 2π √(m/k_x) and T_θ = 2π √(m h²/k_θ), s; T̃² = T² + T_x² + T_θ².
    structural_damping : float
        β_i, the fixed-base building's damping ratio of the mode.
    foundation_damping : float
        β_f = (1 − (T/T̃)²) β_s + (T_x/T̃)² β_x + (T_θ/T̃)² β_θ (Givens et al. 2016).
    damping : float
        β_0 = β_f + β_i / (T̃/T)³ (Veletsos & Nair 1975; viscous structural damping).
    impedances : Impedances
        The footing's springs and dashpots at ω̃ = 2π/T̃.
    iterations : int
        Fixed-point iterations taken.
    """

    fixed_period: float
    period: float
    sway_period: float
    rocking_period: float
    structural_damping: float
    foundation_damping: float
    damping: float
    impedances: Impedances
    iterations: int


def flexible_base(soil: Soil, footing: Footing, oscillator: EquivalentOscillator, *, structural_damping: float = 0.05,
                  soil_damping: float = 0.0, direction: str = "x", method: str = "gazetas",
                  tolerance: float = 1e-10, max_iterations: int = 100) -> FlexibleBase:
    """The flexible-base period and effective damping of a building's first mode on *footing*.

    The impedances depend on the frequency, which depends on them: starting from the fixed-base
    frequency ω, ω̃ ← 2π / T̃(k_x(ω̃), k_θ(ω̃)) (Veletsos & Meek) until two iterates agree within
    *tolerance* (relative).  The sway springs do not depend on frequency and the rocking spring
    softens as it rises, so each step moves ω̃ less than the last.

    Parameters
    ----------
    soil, footing : Soil, Footing
        The site and the foundation.
    oscillator : EquivalentOscillator
        The fixed-base first mode (:func:`equivalent_oscillator`).
    structural_damping : float
        β_i, the building's fixed-base damping ratio in that mode.
    soil_damping : float
        β_s, the soil's hysteretic damping ratio (0: radiation damping only).
    direction : str
        'x' (sway_x with rocking_y) or 'y'.
    method : str
        The static-stiffness fit (:data:`METHODS`).
    tolerance : float
        Relative change of ω̃ between iterations at which to stop.
    max_iterations : int
        Refuse (one line) past this many iterations.
    """
    if direction not in ("x", "y"):
        raise PoundingError(f"foundation direction must be 'x' or 'y' (got {direction!r})")
    m, h, k, period = oscillator.mass, oscillator.height, oscillator.stiffness, oscillator.period
    omega = 2.0 * math.pi / period
    for iteration in range(1, max_iterations + 1):
        found = impedances(soil, footing, omega, method)
        sway, rocking = found.along(direction)
        new = 2.0 * math.pi / veletsos_meek_period(period, k, h, sway.stiffness, rocking.stiffness)
        converged = abs(new - omega) <= tolerance * new
        omega = new
        if converged:
            break
    else:
        raise PoundingError(f"the flexible-base frequency did not settle within {max_iterations} iterations "
                            f"(last {omega:.6g} rad/s); check the soil and footing")
    found = impedances(soil, footing, omega, method)
    sway, rocking = found.along(direction)
    flexible = 2.0 * math.pi / omega
    t_x = 2.0 * math.pi * math.sqrt(m / sway.stiffness)
    t_r = 2.0 * math.pi * math.sqrt(m * h * h / rocking.stiffness)
    ratio = flexible / period
    beta_f = (1.0 - ratio ** -2) * soil_damping + (t_x / flexible) ** 2 * sway.beta + (t_r / flexible) ** 2 * rocking.beta
    return FlexibleBase(period, flexible, t_x, t_r, structural_damping, beta_f,
                        beta_f + structural_damping / ratio ** 3, found, iteration)
