"""Design displacements by modal response-spectrum analysis, and the codes' separation rules.

Modal response-spectrum analysis (each building on its own)
------------------------------------------------------------
For a shear building with mass-normalised modes φ_k (``φᵀMφ = I``), circular
frequencies ω_k and participation factors Γ_k = φ_kᵀ M 1, the peak floor
displacements of mode k under a spectrum Sa(T) (g) are::

    u_k = Γ_k φ_k Sa(T_k) g / ω_k²

and the modes are combined by the complete quadratic combination (CQC)::

    u = √( Σ_i Σ_j ρ_ij u_i u_j )

with ρ_ij the coefficient of Der Kiureghian (1981) —
:func:`pounding.studies.gap.cqc_correlation`, the one the gap study uses for
the DDC rule — at the modes' own damping ratios (the building's Rayleigh or
modal damping).  The modes used are the fewest, from the first, whose
effective masses Γ_k² reach 90 % of the building's mass (ASCE 7-22 §12.9.1.1;
EN 1998-1 §4.3.3.3.1(3)); all modes if the building has fewer.  The codes'
spectra are at 5 % damping; the CQC coefficients use the building's damping
(5 % for the codes' usual models), so a building damped otherwise mixes the
two — this is said, not corrected.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.studies.gap import cqc_correlation
from pounding.units import STANDARD_GRAVITY

__all__ = ["ModalResponse", "modal_response", "cqc_combine", "MASS_FRACTION"]

#: Participating mass the modes of a response-spectrum analysis must reach (ASCE 7-22 §12.9.1.1, EC8 §4.3.3.3.1).
MASS_FRACTION = 0.90


@dataclass(frozen=True, eq=False)
class ModalResponse:
    """The response-spectrum analysis of one building.

    Attributes
    ----------
    building : str
        Building name.
    periods, damping : (m,) ndarray
        Periods (s) and damping ratios of the m modes used.
    participation : (m,) ndarray
        Participation factors Γ_k = φ_kᵀ M 1 of the mass-normalised modes, kg^½.
    mass_ratio : (m,) ndarray
        Effective modal mass Γ_k² over the building's mass.
    sa : (m,) ndarray
        Spectral acceleration at each mode's period, g.
    modal_displacement : (m, n) ndarray
        Peak floor displacements of each mode, m, signed (Γ_k φ_k Sd_k).
    displacement : (n,) ndarray
        CQC combination of the modes: peak floor displacements, m, floor 1 first.
    """

    building: str
    periods: np.ndarray
    damping: np.ndarray
    participation: np.ndarray
    mass_ratio: np.ndarray
    sa: np.ndarray
    modal_displacement: np.ndarray
    displacement: np.ndarray

    @property
    def n_modes(self) -> int:
        """Number of modes used."""
        return int(self.periods.size)

    @property
    def mass_fraction(self) -> float:
        """Participating mass of the modes used, as a fraction of the building's mass."""
        return float(self.mass_ratio.sum())


def cqc_combine(modal: Any, periods: Any, damping: Any) -> np.ndarray:
    """CQC combination √(Σ_i Σ_j ρ_ij r_i r_j) of modal peak responses *modal* (m, n) along the modes.

    Parameters
    ----------
    modal : (m, n) array
        Signed peak response of each mode (rows) at n places.
    periods, damping : (m,) array
        The modes' periods (s) and damping ratios; ρ_ij by :func:`pounding.studies.gap.cqc_correlation`.

    Returns
    -------
    (n,) ndarray
        The combined peak responses (≥ 0).
    """
    r = np.atleast_2d(np.asarray(modal, dtype=float))
    t = np.asarray(periods, dtype=float)
    z = np.asarray(damping, dtype=float)
    rho = np.array([[cqc_correlation(t[i], t[j], z[i], z[j]) for j in range(t.size)] for i in range(t.size)])
    return np.sqrt(np.maximum(np.einsum("in,ij,jn->n", r, rho, r), 0.0))


def modal_response(building, spectrum, *, mass_fraction: float = MASS_FRACTION) -> ModalResponse:
    """Peak floor displacements of *building* on its own under *spectrum*, by modes and CQC.

    Parameters
    ----------
    building : pounding.model.Building
        A shear building (its elastic storey stiffnesses; yielding is not modelled here).
    spectrum : DesignSpectrum
        Anything with ``sa(periods) -> Sa in g`` (:mod:`pounding.records.design_spectra`).
    mass_fraction : float
        Participating mass the modes must reach (default 90 %).

    Returns
    -------
    ModalResponse
    """
    omega, phi = building.modes
    mass = np.asarray(building.mass, dtype=float)
    gamma_all = phi.T @ mass
    ratio_all = gamma_all ** 2 / mass.sum()
    needed = int(np.searchsorted(np.cumsum(ratio_all), mass_fraction - 1e-12) + 1)
    m = min(max(needed, 1), omega.size)
    w = np.asarray(omega[:m])
    periods = 2.0 * np.pi / w
    sa = spectrum.sa(periods)
    sd = sa * STANDARD_GRAVITY / w ** 2
    modal = (gamma_all[:m] * sd)[:, None] * np.asarray(phi[:, :m]).T
    damping = np.asarray(building.modal_damping_ratios[:m], dtype=float)
    return ModalResponse(building=building.name, periods=periods, damping=damping, participation=gamma_all[:m],
                         mass_ratio=ratio_all[:m], sa=np.asarray(sa, dtype=float), modal_displacement=modal,
                         displacement=cqc_combine(modal, periods, damping))


# --------------------------------------------------------------------------- #
# The codes' separation rules, per level pair
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class Separation:
    """A code's minimum separation at one level pair, m.

    Attributes
    ----------
    same_property : float
        Between the two buildings when they stand on one property (one site).
    setback_left, setback_right : float
        Each building's setback from a property line between them (NaN where
        the code has no property-line rule).
    """

    same_property: float
    setback_left: float
    setback_right: float

    @property
    def property_lines(self) -> float:
        """The two setbacks together: the separation of buildings on two properties."""
        return self.setback_left + self.setback_right


def asce7_22_inelastic_displacement(delta_max: float, cd: float, ie: float) -> float:
    """δ_M = C_d δ_max / I_e, ASCE 7-22 §12.12.2 Eq. (12.12-1), m.

    δ_max is the maximum elastic displacement at the critical location under
    the design forces (a modal analysis with the design spectrum divided by
    R/I_e, §12.9.1.2); with the elastic RSA displacement u of the design
    spectrum, δ_max = u I_e/R and δ_M = C_d u / R (:func:`asce7_22_displacements`).
    """
    return cd * delta_max / ie


def asce7_22_separation(delta_m_left: float, delta_m_right: float) -> Separation:
    """ASCE 7-22 §12.12.2: δ_MT = √(δ_M1² + δ_M2²) (Eq. 12.12-2) on one property; each δ_M from a property line.

    "Where a structure adjoins a property line not common to a public way,
    the structure shall be set back from the property line by at least the
    displacement δ_M of that structure."
    """
    return Separation(math.hypot(delta_m_left, delta_m_right), delta_m_left, delta_m_right)


def asce7_22_displacements(elastic: Any, r: float, cd: float, ie: float) -> np.ndarray:
    """δ_M per floor from the elastic RSA displacements *elastic* (m) of the design spectrum.

    δ_max = elastic · I_e/R (the design forces, §12.9.1.2), then δ_M = C_d δ_max / I_e (§12.12.2).
    """
    return asce7_22_inelastic_displacement(np.asarray(elastic, dtype=float) * ie / r, cd, ie)


#: Reduction of the Eurocode 8 §4.4.2.7(3) minimum distance where the floor elevations coincide.
EC8_SAME_LEVELS_FACTOR = 0.7


def ec8_design_displacement(d_e: Any, q_d: float) -> np.ndarray:
    """d_s = q_d d_e, EN 1998-1 §4.3.4(1) expression (4.23), m (q_d = q unless specified otherwise)."""
    return q_d * np.asarray(d_e, dtype=float)


def ec8_separation(ds_left: float, ds_right: float, *, same_levels: bool) -> Separation:
    """EN 1998-1 §4.4.2.7: SRSS of d_s on one property (2)b; d_s from the property line (2)a; ×0.7 if levels coincide (3).

    The 0.7 of (3) reduces "the above referred minimum distance", read here
    as both the same-property distance and the property-line setbacks.
    """
    factor = EC8_SAME_LEVELS_FACTOR if same_levels else 1.0
    return Separation(factor * math.hypot(ds_left, ds_right), factor * ds_left, factor * ds_right)


def is1893_separation(delta_left: float, delta_right: float, r_left: float, r_right: float, *,
                      same_levels: bool) -> Separation:
    """IS 1893 (Part 1):2016 §7.11.3, as commonly quoted (the standard's text was NOT verified in this work).

    "Two adjacent buildings, or two adjacent units of the same building with
    separation joint in between shall be separated by a distance equal to R
    times the sum of the storey displacements [Δ, under the design lateral
    force, 7.11.1] of each of them ... When floor levels of two adjacent units
    or buildings are at the same elevation levels, factor R in this
    requirement shall be replaced by R/2."  With two different R, each
    building's own R multiplies its own displacement (R₁Δ₁ + R₂Δ₂; the text
    names one R).  The clause has no property-line rule (setbacks NaN).
    """
    factor = 0.5 if same_levels else 1.0
    return Separation(factor * (r_left * delta_left + r_right * delta_right), math.nan, math.nan)


def nzs1170_5_separation(d_left: float, d_right: float) -> Separation:
    """NZS 1170.5:2004 §7.4, NOT verified: SRSS of the ULS design deflections on one site, each from a boundary.

    The standard's text was not available in this work.  Assumed (to be
    checked against §7.4 before use): buildings on one site separated by the
    square root of the sum of the squares of their ultimate-limit-state
    design horizontal deflections at the level (§7.3, with the k_dm and
    P-delta amplifications applied by the user), and each building set back
    from the site boundary by its own deflection.  Any reduction where floors
    align is not implemented.
    """
    return Separation(math.hypot(d_left, d_right), d_left, d_right)


#: NTC-Sismo 2004 §1.10: height coefficient added to the computed displacement, per zone (I, II, III).
NTC_2004_HEIGHT = {"I": 0.001, "II": 0.003, "III": 0.006}
#: NTC-Sismo 2004 §1.10: height coefficient of the simplified method of analysis, per zone.
NTC_2004_SIMPLIFIED = {"I": 0.007, "II": 0.009, "III": 0.012}
#: NTC-Sismo 2004 §1.10: the least setback from a boundary, m.
NTC_2004_MINIMUM = 0.050


def ntc2004_setback(displacement: float, height: float, zone: str, *, simplified: bool = False) -> float:
    """Setback of one building from the boundary, Mexico City NTC-Sismo 2004 §1.10, m.

    "Not less than 50 mm, nor less than the horizontal displacement computed
    for the level, increased by 0.001, 0.003 or 0.006 times the height of that
    level above the ground in zones I, II or III"; with the simplified method
    of analysis, not less than 50 mm nor the height times 0.007, 0.009 or
    0.012.  Read in a third-party transcription of the 2004 edition, not
    checked against the Gaceta Oficial; the later editions (2017, 2020, 2023)
    were not verified.  *displacement* is the computed displacement at the
    level (for NTC 2004, those of the reduced forces times Q, §1.8 — not verified).
    """
    key = str(zone).strip().upper()
    table = NTC_2004_SIMPLIFIED if simplified else NTC_2004_HEIGHT
    if key not in table:
        raise ValueError(f"NTC zone must be I, II or III (got {zone!r})")
    if simplified:
        return max(NTC_2004_MINIMUM, table[key] * height)
    return max(NTC_2004_MINIMUM, displacement + table[key] * height)


def ntc2004_separation(setback_left: float, setback_right: float, *, alike: bool = False) -> Separation:
    """Separation of two buildings or bodies, NTC-Sismo 2004 §1.10: the sum of their setbacks, or half of it.

    Half the sum "if the two bodies have the same height and structuring and,
    besides, the slabs coincide at the same height at every level" (*alike*).
    """
    total = setback_left + setback_right
    return Separation(0.5 * total if alike else total, setback_left, setback_right)
