"""FEMA P695's arithmetic: the period T, S_MT, β_TOT, ACMR and the verdict (Chapters 5 and 7).

All accelerations here are in g, as the methodology's tables are; the
study (:mod:`pounding.studies.p695.study`) archives them in m/s².
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pounding.errors import PoundingError
from pounding.studies.p695.tables import (QUALITIES, acceptable_acmr, approximate_period, quality_beta,
                                          sdc_name, sdc_parameters, spectral_shape_factor, tabulated_beta_tot,
                                          upper_limit_coefficient)

__all__ = ["MIN_PERIOD", "BETA_RTR", "BETA_STEP", "Quality", "parse_quality", "Spectrum", "mce_spectrum",
           "DesignPeriod", "design_period", "beta_rtr", "total_uncertainty", "Verdict", "verdict",
           "group_verdict"]

#: FEMA P695 §5.2.5: T = C_u T_a is not taken below 0.25 s.
MIN_PERIOD = 0.25
#: β_RTR of the tables (μ_T ≥ 3), §7.3.1.
BETA_RTR = 0.40
#: β_TOT is rounded to the nearest 0.025, as Tables 7-2a–d are.
BETA_STEP = 0.025


@dataclass(frozen=True)
class Quality:
    """Quality ratings A-D of the design requirements, the test data and the model (FEMA P695 §3.4-3.5, §5.7)."""

    design: str = "B"
    test: str = "B"
    model: str = "B"

    def __str__(self) -> str:
        return f"design={self.design},test={self.test},model={self.model}"


def parse_quality(text: str | None) -> Quality:
    """``--quality design=B,test=C,model=B`` (each A superior, B good, C fair, D poor; unnamed ones B)."""
    if text is None:
        return Quality()
    given: dict[str, str] = {}
    for item in str(text).split(","):
        if not item.strip():
            continue
        key, sep, value = item.partition("=")
        key, value = key.strip().lower(), value.strip().upper()
        if not sep or key not in ("design", "test", "model"):
            raise PoundingError(f"--quality {text!r}: write design=A|B|C|D,test=...,model=... (got {item.strip()!r})")
        if value not in QUALITIES:
            raise PoundingError(f"--quality {text!r}: {key} must be A, B, C or D (superior, good, fair, poor), "
                                f"got {value!r}")
        if key in given:
            raise PoundingError(f"--quality {text!r}: {key} is given twice")
        given[key] = value
    return Quality(**given)


@dataclass(frozen=True)
class Spectrum:
    """The MCE spectrum: S_MS, S_M1 (g); S_MT(T) = S_MS for T ≤ T_s = S_M1/S_MS, S_M1/T beyond."""

    s_ms: float
    s_m1: float
    sdc: str
    source: str   # "Tables 5-1A/5-1B" or "--sms/--sm1"

    @property
    def s_d1(self) -> float:
        """S_D1 = (2/3) S_M1, g (ASCE 7 eq. 11.4-4)."""
        return 2.0 * self.s_m1 / 3.0

    @property
    def ts(self) -> float:
        return self.s_m1 / self.s_ms

    def s_mt(self, period: float) -> float:
        """S_MT at *period* (s), g."""
        return self.s_ms if period <= self.ts else self.s_m1 / period


def mce_spectrum(sdc: str = "Dmax", s_ms: float | None = None, s_m1: float | None = None) -> Spectrum:
    """The MCE spectrum of *sdc* (Tables 5-1A/5-1B), or of S_MS and S_M1 given together (g).

    The SDC still selects the SSF table (7-1b for Dmax, 7-1a otherwise).
    """
    mapped = sdc_parameters(sdc)
    name = sdc_name(sdc)
    if (s_ms is None) != (s_m1 is None):
        raise PoundingError("give --sms and --sm1 together (the MCE spectral accelerations, g), or neither")
    if s_ms is None:
        return Spectrum(mapped["S_MS"], mapped["S_M1"], name, "FEMA P695 Tables 5-1A/5-1B")
    for flag, value in (("--sms", s_ms), ("--sm1", s_m1)):
        if not (math.isfinite(value) and value > 0):
            raise PoundingError(f"{flag} must be > 0 (g; got {value:g})")
    return Spectrum(float(s_ms), float(s_m1), name, "--sms/--sm1")


@dataclass(frozen=True)
class DesignPeriod:
    """T_a (s), C_u, T = max(C_u T_a, 0.25 s) (FEMA P695 eq. 5-5) of a building of height h_n (m)."""

    system: str
    height: float
    ta: float
    cu: float
    period: float


def design_period(system: str, height: float, s_d1: float) -> DesignPeriod:
    """The FEMA P695 period of a building: C_u (Table 12.8-1 at S_D1, g) times T_a (Table 12.8-2), ≥ 0.25 s."""
    ta = approximate_period(system, height)
    cu = upper_limit_coefficient(s_d1)
    return DesignPeriod(system, float(height), ta, cu, max(cu * ta, MIN_PERIOD))


def beta_rtr(ductility: float) -> float:
    """Record-to-record uncertainty β_RTR = 0.1 + 0.1 μ_T ≤ 0.4 (FEMA P695 §7.3.1)."""
    return float(min(0.1 + 0.1 * ductility, BETA_RTR))


def total_uncertainty(quality: Quality, ductility: float) -> float:
    """β_TOT: Tables 7-2a–d for μ_T ≥ 3; below, √(β_RTR² + β_DR² + β_TD² + β_MDL²) with β_RTR of
    :func:`beta_rtr`, rounded to the nearest 0.025 as the tables are."""
    if not math.isfinite(ductility):
        raise PoundingError("β_TOT needs the period-based ductility μ_T")
    if ductility >= 3.0:
        return tabulated_beta_tot(quality.design, quality.test, quality.model)
    squares = beta_rtr(ductility) ** 2 + sum(quality_beta(q) ** 2 for q in (quality.design, quality.test,
                                                                           quality.model))
    return round(math.sqrt(squares) / BETA_STEP) * BETA_STEP


@dataclass(frozen=True)
class Verdict:
    """One building's FEMA P695 evaluation; accelerations in g.

    ``cmr = s_ct / s_mt`` (§7.2), ``acmr = ssf · cmr`` (eq. 7-1), ``passes``:
    ACMR ≥ ACMR_20% (§7.5, an individual archetype); NaN / False when S_CT is not determinable.
    """

    s_ct: float
    s_mt: float
    cmr: float
    ssf: float
    acmr: float
    beta_tot: float
    acmr_10: float
    acmr_20: float
    passes: bool


def verdict(s_ct: float, s_mt: float, period: float, ductility: float, sdc: str, quality: Quality) -> Verdict:
    """The verdict of one building from its S_CT and S_MT (g), its period T (s) and μ_T."""
    ssf = spectral_shape_factor(period, ductility, sdc)
    beta = total_uncertainty(quality, ductility)
    acmr_10, acmr_20 = acceptable_acmr(beta)
    cmr = s_ct / s_mt
    acmr = ssf * cmr
    return Verdict(s_ct, s_mt, cmr, ssf, acmr, beta, acmr_10, acmr_20, bool(acmr >= acmr_20))


def group_verdict(acmrs, betas) -> tuple[float, float, bool]:
    """A performance group (§7.5): (mean ACMR, ACMR_10% at the group's largest β_TOT, mean ≥ ACMR_10%).

    NaN / False when any member's ACMR is not determinable.
    """
    values = np.asarray(acmrs, dtype=float)
    if values.size == 0 or not np.all(np.isfinite(values)):
        return float("nan"), float("nan"), False
    acmr_10, _ = acceptable_acmr(float(np.max(betas)))
    mean = float(np.mean(values))
    return mean, acmr_10, bool(mean >= acmr_10)
