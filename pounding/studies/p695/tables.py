"""The FEMA P695 (2009) and ASCE/SEI 7 tables of ``pounding p695``, read from ``pounding/data/p695/tables.yaml``.

Lookups only, each with the interpolation the methodology allows; the
verdict's arithmetic is in :mod:`pounding.studies.p695.verdict`.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from pounding.errors import PoundingError

__all__ = ["SDCS", "SYSTEMS", "QUALITIES", "FEET", "tables", "sdc_name", "sdc_parameters", "upper_limit_coefficient",
           "approximate_period", "ssf_table", "spectral_shape_factor", "quality_beta", "tabulated_beta_tot",
           "acceptable_acmr"]

#: Seismic design categories of FEMA P695 Tables 5-1A/5-1B.
SDCS = ("Dmax", "Dmin", "Cmax", "Cmin", "Bmax", "Bmin")
#: Structural systems of ASCE 7 Table 12.8-2 (``--system``).
SYSTEMS = ("steel-moment", "rc-moment", "steel-ebf", "steel-brbf", "other")
#: Quality ratings (superior, good, fair, poor).
QUALITIES = ("A", "B", "C", "D")
#: One foot, m (ASCE 7 Table 12.8-2 takes h_n in feet).
FEET = 0.3048


@functools.lru_cache(maxsize=1)
def tables() -> dict:
    """The shipped tables as plain data (parsed once)."""
    import yaml

    from pounding.data import data_path

    with open(data_path("p695", "tables.yaml"), encoding="utf-8") as handle:
        return yaml.safe_load(handle)


def sdc_name(sdc: str) -> str:
    """The SDC as the tables spell it (Dmax...), from any case; one-line error otherwise."""
    for name in SDCS:
        if name.lower() == str(sdc).strip().lower():
            return name
    raise PoundingError(f"--sdc {sdc!r}: choose one of {', '.join(SDCS)} (FEMA P695 Tables 5-1A/5-1B)")


def sdc_parameters(sdc: str) -> dict[str, float]:
    """S_MS, S_M1, S_DS, S_D1 (g) of a seismic design category (FEMA P695 Tables 5-1A and 5-1B)."""
    return {k: float(v) for k, v in tables()["seismic_design_categories"][sdc_name(sdc)].items()}


def upper_limit_coefficient(s_d1: float) -> float:
    """C_u of ASCE 7 Table 12.8-1 against S_D1 (g): linear between the rows, the end values beyond them."""
    table = tables()["upper_limit_coefficient"]
    return float(np.interp(s_d1, table["S_D1"], table["C_u"]))


def approximate_period(system: str, height: float) -> float:
    """T_a = C_t h_n^x (ASCE 7 eq. 12.8-7, Table 12.8-2; h_n in feet there), s, for a height in metres."""
    rows = tables()["approximate_period"]
    if system not in rows:
        raise PoundingError(f"--system {system!r}: choose one of {', '.join(SYSTEMS)} (ASCE 7 Table 12.8-2)")
    if not (math.isfinite(height) and height > 0):
        raise PoundingError(f"the height of a building must be > 0 m (got {height:g})")
    row = rows[system]
    return float(row["C_t"] * (height / FEET) ** row["x"])


def ssf_table(sdc: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(periods s, μ_T, SSF[period, μ_T]) of Table 7-1b (SDC Dmax) or Table 7-1a (every other SDC)."""
    table = tables()["ssf_dmax" if sdc_name(sdc) == "Dmax" else "ssf_b_c_dmin"]
    periods = np.array(sorted(float(t) for t in table["rows"]))
    values = np.array([table["rows"][t] for t in sorted(table["rows"], key=float)], dtype=float)
    return periods, np.array(table["mu_T"], dtype=float), values


def spectral_shape_factor(period: float, ductility: float, sdc: str) -> float:
    """SSF of Tables 7-1a/7-1b: linear in T and in μ_T between rows and columns (bilinear), the first/last
    row for T ≤ 0.5 s / T ≥ 1.5 s, μ_T ≥ 8 as 8 and μ_T < 1 as 1."""
    if not (math.isfinite(period) and math.isfinite(ductility)):
        return float("nan")
    periods, mus, values = ssf_table(sdc)
    t = float(np.clip(period, periods[0], periods[-1]))
    mu = float(np.clip(ductility, mus[0], mus[-1]))
    by_period = np.array([np.interp(t, periods, values[:, j]) for j in range(mus.size)])
    return float(np.interp(mu, mus, by_period))


def quality_beta(rating: str) -> float:
    """β of a quality rating A-D (FEMA P695 §7.3.1: 0.10, 0.20, 0.35, 0.50)."""
    return float(tables()["quality_beta"][rating])


def tabulated_beta_tot(design: str, test: str, model: str) -> float:
    """β_TOT of Tables 7-2a–d (μ_T ≥ 3): table by model quality, row by test data, column by design requirements."""
    return float(tables()["beta_tot"][model][test][QUALITIES.index(design)])


def acceptable_acmr(beta_tot: float) -> tuple[float, float]:
    """(ACMR_10%, ACMR_20%) of Table 7-3 at β_TOT, linear between rows (β_TOT outside 0.275-0.950 is refused)."""
    table = tables()["acceptable_acmr"]
    betas = np.array(table["beta_tot"], dtype=float)
    if not (betas[0] - 1e-9 <= beta_tot <= betas[-1] + 1e-9):
        raise PoundingError(f"beta_TOT {beta_tot:g} is outside FEMA P695 Table 7-3 ({betas[0]:g}-{betas[-1]:g})")
    return (float(np.interp(beta_tot, betas, table["acmr_10"])), float(np.interp(beta_tot, betas, table["acmr_20"])))
