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

The same functions serve plan buildings (docs/plan-models.md: rigid floors with
u_x, u_y, θ): the difference is in the data.  A planar building is a building
whose floors have one DOF, shaken along x; a plan building has three per
floor, M = diag(m, m, m r²), and is shaken along x or y with the influence
vector r (1 on every u_x, resp. u_y, 0 on θ): Γ_k = φ_kᵀ M r and the
participating mass is Γ_k² / (rᵀ M r).  Its modes are the fewest, from the
first, that reach 90 % of the mass in *each* horizontal direction (ASCE 7-22
§12.9.1.1, EN 1998-1 §4.3.3.3.1(3)), and any response that is a linear
combination w · q of the DOF (a point's displacement along a face normal) is
combined from its modal values, CQC(w · u_k) (:meth:`ModalResponse.at`).  The
plan-only steps (accidental torsion, the two directions, contact points) are
in :mod:`pounding.studies.design_directions`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.studies.gap import cqc_correlation, order_statistic
from pounding.units import STANDARD_GRAVITY

__all__ = ["ModalResponse", "modal_response", "cqc_combine", "MASS_FRACTION", "dof_per_floor", "ground_influence",
           "modal_damping", "modes_for_mass", "response_directions",
           "Separation", "asce7_22_inelastic_displacement", "asce7_22_separation", "asce7_22_displacements",
           "EC8_SAME_LEVELS_FACTOR", "ec8_design_displacement", "ec8_separation", "is1893_separation",
           "nzs1170_5_separation", "NTC_2004_HEIGHT", "NTC_2004_SIMPLIFIED", "NTC_2004_MINIMUM", "ntc2004_setback",
           "ntc2004_separation", "SUITE_FRACTION", "SUITE_PERIODS", "EC8_MEAN_RECORDS", "ASCE_RECORDS",
           "suite_scale_factor", "Intensity", "record_set_spectra", "suite_warnings", "code_setup", "code_displacements",
           "pair_separation", "code_separations", "simulated_requirement"]

#: Participating mass the modes of a response-spectrum analysis must reach (ASCE 7-22 §12.9.1.1, EC8 §4.3.3.3.1).
MASS_FRACTION = 0.90


@dataclass(frozen=True, eq=False)
class ModalResponse:
    """The response-spectrum analysis of one building along one direction.

    Attributes
    ----------
    building : str
        Building name.
    periods, damping : (m,) ndarray
        Periods (s) and damping ratios of the m modes used.
    participation : (m,) ndarray
        Participation factors Γ_k = φ_kᵀ M r of the mass-normalised modes, kg^½.
    mass_ratio : (m,) ndarray
        Effective modal mass Γ_k² over the building's mass (rᵀ M r) along the direction.
    sa : (m,) ndarray
        Spectral acceleration at each mode's period, g.
    modal_displacement : (m, N) ndarray
        Peak displacements of each mode, signed (Γ_k φ_k Sd_k), at every DOF: m (rad on a plan floor's θ).
    displacement : (N,) ndarray
        CQC combination of the modes at every DOF: a planar building's floor displacements (m, floor 1
        first); a plan building's (u_x, u_y, θ) per floor.
    direction : {"x", "y"}
        The direction of the ground motion (a planar building: x).
    """

    building: str
    periods: np.ndarray
    damping: np.ndarray
    participation: np.ndarray
    mass_ratio: np.ndarray
    sa: np.ndarray
    modal_displacement: np.ndarray
    displacement: np.ndarray
    direction: str = "x"

    @property
    def n_modes(self) -> int:
        """Number of modes used."""
        return int(self.periods.size)

    @property
    def mass_fraction(self) -> float:
        """Participating mass of the modes used, as a fraction of the building's mass."""
        return float(self.mass_ratio.sum())

    def at(self, weights: Any) -> np.ndarray:
        """CQC of the modal values of the responses ``w · q`` (m): *weights* (N,) or (k, N) → (k,).

        Each mode's response is ``w · u_k`` (signed), then the modes are combined
        (:func:`cqc_combine`): a point's displacement is combined as itself, not
        from the combined centre and rotation.
        """
        w = np.atleast_2d(np.asarray(weights, dtype=float))
        return cqc_combine(self.modal_displacement @ w.T, self.periods, self.damping)

    def inertia_forces(self, mass: Any) -> np.ndarray:
        """(N,) CQC of the modes' inertia forces ω_k² M u_k at every DOF (N; N·m on θ), *mass* the (N,) diagonal of M."""
        omega = 2.0 * np.pi / self.periods
        modal = self.modal_displacement * (omega ** 2)[:, None] * np.asarray(mass, dtype=float)[None, :]
        return cqc_combine(modal, self.periods, self.damping)


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


def dof_per_floor(building) -> int:
    """Degrees of freedom per floor: 1 for a planar (shear) building, 3 (u_x, u_y, θ) for a plan building."""
    return int(building.mass_matrix().shape[0] // building.n_floors)


def response_directions(building) -> tuple[str, ...]:
    """The directions a building is shaken along: ``("x",)`` planar, ``("x", "y")`` plan."""
    return ("x",) if dof_per_floor(building) == 1 else ("x", "y")


def ground_influence(building, direction: str = "x") -> np.ndarray:
    """(N,) influence vector r of a ground motion along *direction*: 1 on every floor's translation that way, 0 on θ."""
    per = dof_per_floor(building)
    if direction not in response_directions(building):
        raise ValueError(f"building {building.name} is shaken along {' or '.join(response_directions(building))} "
                         f"(got {direction!r})")
    r = np.zeros(per * building.n_floors)
    r["xy".index(direction)::per] = 1.0
    return r


def modal_damping(building) -> np.ndarray:
    """(N,) damping ratio of every mode: Rayleigh ``(a0/ω + a1·ω)/2`` at its two targeted modes, or its modal ratios."""
    omega = np.asarray(building.modes[0], dtype=float)
    damping = building.damping
    if damping.kind == "modal":
        return np.asarray(damping.ratios(omega.size), dtype=float)
    i, j = damping.modes
    wi, wj = float(omega[i - 1]), float(omega[j - 1])
    a0, a1 = 2.0 * damping.ratio * wi * wj / (wi + wj), 2.0 * damping.ratio / (wi + wj)
    return 0.5 * (a0 / omega + a1 * omega)


def _mass_ratios(building, direction: str) -> np.ndarray:
    omega, phi = building.modes
    mass = np.diag(building.mass_matrix())
    r = ground_influence(building, direction)
    return (phi.T @ (mass * r)) ** 2 / float(mass @ r)


def modes_for_mass(building, mass_fraction: float = MASS_FRACTION) -> int:
    """The fewest modes, from the first, whose effective masses reach *mass_fraction* along every direction.

    ASCE 7-22 §12.9.1.1 ("in each of the orthogonal horizontal directions");
    EN 1998-1 §4.3.3.3.1(3).  All modes if the building has fewer.
    """
    count = 1
    for direction in response_directions(building):
        cumulative = np.cumsum(_mass_ratios(building, direction))
        count = max(count, int(np.searchsorted(cumulative, mass_fraction - 1e-12) + 1))
    return min(count, int(building.modes[0].size))


def modal_response(building, spectrum, *, mass_fraction: float = MASS_FRACTION, direction: str = "x",
                   n_modes: int | None = None) -> ModalResponse:
    """Peak displacements of *building* on its own under *spectrum* along *direction*, by modes and CQC.

    Parameters
    ----------
    building : pounding.model.Building or PlanBuilding
        A shear building (one DOF per floor) or a plan building (three); its
        elastic (initial) stiffness: yielding is not modelled here.
    spectrum : DesignSpectrum
        Anything with ``sa(periods) -> Sa in g`` (:mod:`pounding.records.design_spectra`).
    mass_fraction : float
        Participating mass the modes must reach in every direction (default 90 %).
    direction : {"x", "y"}
        The ground motion's direction (a planar building: x only).
    n_modes : int, optional
        Use exactly this many modes (default :func:`modes_for_mass`).

    Returns
    -------
    ModalResponse
    """
    omega, phi = building.modes
    mass = np.diag(building.mass_matrix())
    r = ground_influence(building, direction)
    gamma_all = phi.T @ (mass * r)
    ratio_all = gamma_all ** 2 / float(mass @ r)
    m = modes_for_mass(building, mass_fraction) if n_modes is None else min(max(int(n_modes), 1), omega.size)
    w = np.asarray(omega[:m])
    periods = 2.0 * np.pi / w
    sa = spectrum.sa(periods)
    sd = sa * STANDARD_GRAVITY / w ** 2
    modal = (gamma_all[:m] * sd)[:, None] * np.asarray(phi[:, :m]).T
    damping = modal_damping(building)[:m]
    return ModalResponse(building=building.name, periods=periods, damping=damping, participation=gamma_all[:m],
                         mass_ratio=ratio_all[:m], sa=np.asarray(sa, dtype=float), modal_displacement=modal,
                         displacement=cqc_combine(modal, periods, damping), direction=direction)


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


# --------------------------------------------------------------------------- #
# The code's separations beside the simulated requirement (pounding gap --code)
# --------------------------------------------------------------------------- #

#: Fraction of the target spectrum the record set's mean spectrum must reach over the period range
#: (ASCE 7-22 §16.2.3; EN 1998-1 §3.2.3.1.2(4)b).
SUITE_FRACTION = 0.90
#: Periods of the scaling range [0.2 T_min, 2 T_max] at which the mean spectrum is checked.
SUITE_PERIODS = 40
#: Records below which Eurocode 8 §4.3.3.4.3(3) takes the most unfavourable response instead of the mean.
EC8_MEAN_RECORDS = 7
#: Records ASCE 7-22 chapter 16 asks for (§16.2.2); its response is their mean.
ASCE_RECORDS = 11


def suite_scale_factor(psa: Any, target: Any, *, fraction: float = SUITE_FRACTION, pga: Any = None,
                       pga_target: float | None = None) -> float:
    """The least factor on every record for the set's mean spectrum to reach *fraction* of *target* everywhere.

    Parameters
    ----------
    psa : (r, p) array
        Each record's 5 % pseudo-spectral acceleration at p periods, g.
    target : (p,) array
        The target spectrum at those periods, g.
    fraction : float
        0.9: the mean must not fall below 90 % of the target (ASCE 7-22 §16.2.3;
        EN 1998-1 §3.2.3.1.2(4)b).
    pga, pga_target : (r,) array and float, optional
        Each record's PGA (g) and the least mean PGA (Eurocode 8
        §3.2.3.1.2(4)a: a_g S).

    Returns
    -------
    float
        ``max(max_T fraction·target(T)/mean(T), pga_target/mean PGA)``.
    """
    mean = np.mean(np.atleast_2d(np.asarray(psa, dtype=float)), axis=0)
    factor = float(np.max(fraction * np.asarray(target, dtype=float) / mean))
    if pga is not None and pga_target is not None:
        factor = max(factor, float(pga_target / np.mean(np.asarray(pga, dtype=float))))
    return factor


@dataclass(frozen=True)
class Intensity:
    """One intensity the record set is scaled to.

    Attributes
    ----------
    name : str
        ``design`` or ``MCE_R``.
    spectrum : DesignSpectrum
        The target spectrum.
    why : str
        The clause that prescribes it (or why it is reported).
    pga_target : float or None
        Least mean PGA, g (Eurocode 8 a_g S).
    """

    name: str
    spectrum: Any
    why: str
    pga_target: float | None = None


def record_set_spectra(model, records: list[str], periods: Any, *, duration: float | None = None,
                       read: list | None = None):
    """Each record's 5 % pseudo-spectral acceleration (g) at *periods*, and its PGA (g), as the model reads it.

    The record is read and processed as the model's ``ground_motion`` says
    (units, dt, processing), unscaled, and cut to *duration*; each record as read
    (:class:`~pounding.records.record.Record`, whole) is appended to *read* if given.
    """
    from pounding.records.spectra import response_spectrum
    from pounding.simulation import processed_record_for

    psa, pga = [], []
    for spec in records:
        record = processed_record_for(model.with_ground_motion(record=spec, scale=1.0), where="cli")
        if read is not None:
            read.append(record)
        acc = np.asarray(record.acceleration)
        if duration is not None:
            acc = acc[:int(round(duration / record.time_step)) + 1]
        spectrum = response_spectrum(acc, record.time_step, periods, 0.05)
        psa.append(spectrum.psa / STANDARD_GRAVITY)
        pga.append(spectrum.pga / STANDARD_GRAVITY)
    return np.array(psa), np.array(pga)


def suite_warnings(model, names: list[str], records: list, factors: list[float]) -> list[str]:
    """The plausibility warnings of a code check (:mod:`pounding.results.checks`), each kind once: the model's
    (periods, gaps), and each ground motion's (*names*; *records*: each one's records as read, a pair's two)
    units and PGA at each intensity's factor (*factors*)."""
    from pounding.results.checks import ground_motion_warnings, model_warnings, study_warnings

    runs = [ground_motion_warnings(name, group, factor) for factor in factors for name, group in zip(names, records)]
    return [*model_warnings(model).values(), *study_warnings(runs)]


def _design_of(model, code: str, key: str, example: str, designs: list | None = None):
    """Each building's design factors for *code* (``design.<key>``), refused in one line when missing.

    *designs* gives each building's ``design`` entry where the building object does not carry it.
    """
    from pounding.errors import ModelError

    found = []
    for index, b in enumerate(model.buildings):
        design = b.design if designs is None else designs[index]
        entry = getattr(design, key, None) if design is not None else None
        if entry is None:
            where = f"{model.path}: " if model.path else ""
            raise ModelError(f"{where}buildings[{index}] ({b.name}) has no design.{key}: --code {code} needs each "
                             f"building's factors, e.g. design: {{{key}: {example}}} (docs/design-codes.md)")
        found.append(entry)
    return found


def code_setup(model, code: str, spectrum_options: dict[str, Any], designs: list | None = None) -> dict[str, Any]:
    """The code's spectra and factors per building, the intensities of the records, the statistic and the rule.

    Parameters
    ----------
    model : Model or PlanModel
    code : {"asce7-22", "ec8"}
    spectrum_options : dict
        ASCE 7-22: ``sds``, ``sd1``, ``tl``; Eurocode 8: ``type``, ``ground``, ``ag``, ``beta``.
    designs : list, optional
        Each building's ``design`` entry (default: the buildings' own ``design``).

    Returns
    -------
    dict
        ``factors`` [the building's design factors], ``spectra`` {building: DesignSpectrum of its RSA},
        ``scale`` {building: the factor from the elastic RSA displacement to the code's design displacement:
        C_d/R (δ_max = u I_e/R, δ_M = C_d δ_max/I_e) or q_d}, ``intensities`` [Intensity], ``statistic``, ``rule``.
    """
    from pounding.records.design_spectra import asce7_22_spectrum, ec8_spectrum

    if code == "asce7-22":
        factors = _design_of(model, code, "asce7_22", "{R: 8, Cd: 5.5, Ie: 1.0}", designs)
        sds, sd1, tl = spectrum_options["sds"], spectrum_options["sd1"], spectrum_options["tl"]
        design, mce = asce7_22_spectrum(sds, sd1, tl), asce7_22_spectrum(sds, sd1, tl, mce=True)
        intensities = [
            Intensity("design", design, "the level of §12.12.2's delta_M (design spectrum, §11.4.5; 2/3 of MCE_R)"),
            Intensity("MCE_R", mce, "the target spectrum of response-history analysis, ASCE 7-22 ch. 16 (§16.2.1)")]
        return {"factors": factors, "spectra": {b.name: design for b in model.buildings},
                "scale": {b.name: float(asce7_22_displacements(1.0, f.R, f.Cd, f.Ie))
                          for b, f in zip(model.buildings, factors)},
                "intensities": intensities, "statistic": "mean",
                "rule": "ASCE 7-22 §12.12.2: delta_M = Cd delta_max / Ie; delta_MT = SRSS"}
    if code == "ec8":
        factors = _design_of(model, code, "ec8", "{q: 3.9}", designs)
        kind, ground, ag, beta = (spectrum_options[k] for k in ("type", "ground", "ag", "beta"))
        elastic = ec8_spectrum(kind, ground, ag)
        soil = elastic.sa([0.0])[0]   # a_g S
        intensities = [Intensity("design", elastic, "the elastic spectrum of the design seismic action, EN 1998-1 "
                                                    "§3.2.3.1.2(4) (mean >= 90 % over 0.2-2 T1, mean PGA >= a_g S)",
                                 pga_target=float(soil))]
        return {"factors": factors,
                "spectra": {b.name: ec8_spectrum(kind, ground, ag, q=f.q, beta=beta)
                            for b, f in zip(model.buildings, factors)},
                "scale": {b.name: float(f.qd or f.q) for b, f in zip(model.buildings, factors)},
                "intensities": intensities,
                "statistic": "mean (>= 7 records) or max (fewer), EN 1998-1 §4.3.3.4.3(3)",
                "rule": "EN 1998-1 §4.4.2.7: d_s = q_d d_e (4.23); SRSS; x0.7 where floor levels coincide"}
    raise ValueError(f"unknown code {code!r}")


def code_displacements(model, code: str, spectrum_options: dict[str, Any]) -> dict[str, Any]:
    """Per building: the RSA and the code's design displacement per floor (m), with the code's spectra.

    Parameters
    ----------
    model : Model
    code : {"asce7-22", "ec8"}
    spectrum_options : dict
        ASCE 7-22: ``sds``, ``sd1``, ``tl``; Eurocode 8: ``type``, ``ground``, ``ag``, ``beta``.

    Returns
    -------
    dict
        ``displacement`` {building: (n,) m}, ``rsa`` {building: ModalResponse},
        ``spectra`` {building: DesignSpectrum of the RSA}, ``intensities``
        [Intensity], ``statistic`` (how the records' results are combined),
        ``rule`` (the clause).
    """
    setup = code_setup(model, code, spectrum_options)
    rsa, displacement = {}, {}
    for b, f in zip(model.buildings, setup["factors"]):
        rsa[b.name] = modal_response(b, setup["spectra"][b.name])
        if code == "asce7-22":
            displacement[b.name] = asce7_22_displacements(rsa[b.name].displacement, f.R, f.Cd, f.Ie)
        else:
            displacement[b.name] = ec8_design_displacement(rsa[b.name].displacement, f.qd or f.q)
    return {"displacement": displacement, "rsa": rsa, "spectra": setup["spectra"],
            "intensities": setup["intensities"], "statistic": setup["statistic"], "rule": setup["rule"]}


def pair_separation(code: str, first: float, second: float, *, same_levels: bool) -> Separation:
    """The code's separation of two points with design displacements *first* and *second* (m).

    ASCE 7-22 §12.12.2 (:func:`asce7_22_separation`) or EN 1998-1 §4.4.2.7
    (:func:`ec8_separation`, its 0.7 where *same_levels*).
    """
    if code == "asce7-22":
        return asce7_22_separation(first, second)
    return ec8_separation(first, second, same_levels=same_levels)


def code_separations(model, code: str, displacement: dict[str, np.ndarray], *,
                     tolerance: float = 0.01) -> list[dict[str, Any]]:
    """The code's separation at every floor-to-floor contact of *model*, from each building's design displacement.

    Eurocode 8's 0.7 applies where the two floors of the pair stand within
    *tolerance* (m) of each other.
    """
    names = [b.name for b in model.buildings]
    rows = []
    for g in model.gaps:
        left, right = model.buildings[g.left], model.buildings[g.right]
        d1 = float(displacement[left.name][g.level_left - 1])
        d2 = float(displacement[right.name][g.level_right - 1])
        z1, z2 = float(left.elevation[g.level_left - 1]), float(right.elevation[g.level_right - 1])
        same = abs(z1 - z2) <= tolerance + 1e-9
        sep = pair_separation(code, d1, d2, same_levels=same)
        rows.append({"contact": g.label(names), "level_pair": g.label(names), "gap": float(g.gap),
                     "buildings": (left.name, right.name), "levels": (g.level_left, g.level_right),
                     "left": d1, "right": d2, "elevation": max(z1, z2), "same_levels": same, "separation": sep})
    return rows


def simulated_requirement(required: Any, separation: float, use_max: bool, gap: float = math.nan) -> dict[str, Any]:
    """A contact's simulated requirement over the records that ran (m) beside the code's *separation* and the
    model's *gap* (m).

    ``mean``, ``max``, ``used`` (the max where *use_max*, else the mean) and ``unconservative``: True
    where the code's separation is below the requirement used, None where no record ran (nothing to
    compare: not "ok").  ``median`` and ``p84`` (:func:`pounding.studies.gap.order_statistic`: +inf where
    they fall on a collapsed record), ``exceeding`` (how many records need more than *gap*: need > gap)
    and ``fraction`` (that over the records that ran; NaN where none ran).  A record on which a building
    collapsed needs +inf (the gap study's ``required_gap``): the mean and the max are then +inf, not
    bounded, every code separation is below them (unconservative), and it exceeds every gap.
    """
    values = np.asarray(required, dtype=float)
    if values.size == 0:
        return {"mean": math.nan, "max": math.nan, "used": math.nan, "unconservative": None, "median": math.nan,
                "p84": math.nan, "exceeding": 0, "fraction": math.nan, "records": 0}
    mean, largest = float(np.mean(values)), float(np.max(values))
    used = largest if use_max else mean
    exceeding = int(np.count_nonzero(values > gap))
    return {"mean": mean, "max": largest, "used": used, "unconservative": bool(separation < used),
            "median": float(order_statistic(values[:, None], 50.0)[0]),
            "p84": float(order_statistic(values[:, None], 84.0)[0]),
            "exceeding": exceeding, "fraction": exceeding / values.size if math.isfinite(gap) else math.nan,
            "records": int(values.size)}
