"""The risk integrals: how often a demand exceeds a capacity, given a site's hazard curve.

The mean annual frequency of an event E (pounding at separation g, collapse of a building) is the
total-probability integral over the hazard curve λ_IM (Cornell, Jalayer, Hamburger & Foutch 2002, J. Struct.
Eng. 128(4) 526–533)::

    λ_E = ∫ P(E | IM = x) |dλ_IM(x)|,

and the probability that it happens at least once in t years (a Poisson process) is
``1 − exp(−t λ_E)``.  Numerically (:func:`annual_rate`) the integral is taken in u = ln x, where
``|dλ_IM| = k(u) λ_IM(u) du`` with the curve's local log–log slope k: Gauss–Legendre quadrature on pieces at
most :data:`PIECE` wide in ln x whose ends include every tabulated intensity and every break of P, from
:data:`BELOW` below the curve's first intensity to :data:`ABOVE` above its last (the curve's end segments
extended as power laws, :meth:`pounding.studies.risk.hazard.HazardCurve.rate`).  On a power-law curve the
result is exact to the quadrature's error (below 1e-8 relative for a lognormal P).

P(E | IM = x) is either

* a lognormal fragility Φ(ln(x/θ)/β) (:func:`lognormal_rate`); on a power law λ_IM = k0 x^(−k) the
  integral is k0 θ^(−k) exp(k² β² / 2) (Cornell et al. 2002, the closed form of the SAC/FEMA framework; :func:`closed_form_rate`), the check
  of the numerical route; or
* empirical (non-parametric), from the demands D of the runs at each stripe of a multi-stripe analysis
  (:func:`exceedance_rates`): at stripe j the fraction of runs whose demand exceeds g, P_j(D > g); between
  stripes linear in ln x; above the highest stripe the highest stripe's; below the lowest stripe 0 (the
  runs say nothing there: the lowest stripe should sit where the event is rare, which
  :func:`lowest_stripe_share` measures).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.special import ndtr

from pounding.errors import PoundingError
from pounding.studies.risk.hazard import HazardCurve

__all__ = ["annual_rate", "lognormal_rate", "closed_form_rate", "probability_in", "rate_for_probability",
           "parse_target", "stripe_exceedance", "exceedance_rates", "separation_for_rate", "lowest_stripe_share",
           "PIECE", "BELOW", "ABOVE", "YEARS"]

#: Widest quadrature piece, in ln x (a factor 1.05 in intensity).
PIECE = 0.05
#: How far below the curve's first and above its last intensity the integral goes, in ln x (factors 1e-3, 1e3).
BELOW = math.log(1e3)
ABOVE = math.log(1e3)
#: The period of the probability a risk target is written in (2 %/50y), years.
YEARS = 50.0
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(8)


def _pieces(curve: HazardCurve, breaks=()) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature points u = ln x and weights of ∫ … du over the integration range (module docstring)."""
    lx = np.log(curve.intensity)
    ends = np.unique(np.concatenate([lx, np.log(np.asarray(breaks, dtype=float)), [lx[0] - BELOW, lx[-1] + ABOVE]]))
    ends = ends[(ends >= lx[0] - BELOW) & (ends <= lx[-1] + ABOVE)]
    u, w = [], []
    for a, b in zip(ends[:-1], ends[1:]):
        n = max(1, int(math.ceil((b - a) / PIECE)))
        edges = np.linspace(a, b, n + 1)
        half = 0.5 * np.diff(edges)[:, None]
        u.append((0.5 * (edges[:-1] + edges[1:]))[:, None] + half * _NODES[None, :])
        w.append(half * _WEIGHTS[None, :])
    return np.concatenate(u).ravel(), np.concatenate(w).ravel()


def annual_rate(curve: HazardCurve, probability: Callable[[np.ndarray], np.ndarray], breaks=()) -> np.ndarray:
    """λ_E = ∫ P(E | x) |dλ_IM(x)| (1/yr) for one event or many.

    Parameters
    ----------
    curve : HazardCurve
        The site's hazard curve.
    probability : callable
        ``probability(x)`` with x an array of intensities (m/s²) → P(E | x), an array of x's shape with,
        for many events, one more axis last (one column per event).
    breaks : sequence of float
        Intensities (m/s²) where P has a kink or a jump (stripes): quadrature pieces end there.
    """
    u, w = _pieces(curve, breaks)
    x = np.exp(u)
    density = curve.slope(x) * curve.rate(x) * w     # |dλ_IM| = k λ du
    p = np.asarray(probability(x), dtype=float)
    return np.tensordot(density, p, axes=(0, 0))


def lognormal_rate(curve: HazardCurve, theta: float, beta: float) -> float:
    """λ of a lognormal fragility, median *theta* (m/s²) and dispersion *beta*, on *curve* (1/yr)."""
    if not (theta > 0 and beta > 0):
        raise PoundingError(f"a lognormal fragility needs theta > 0 and beta > 0 (got {theta:g}, {beta:g})")
    return float(annual_rate(curve, lambda x: ndtr(np.log(x / theta) / beta), breaks=[theta]))


def closed_form_rate(k0: float, k: float, theta_g: float, beta: float) -> float:
    """k0 θ^(−k) exp(k² β² / 2): λ of a lognormal fragility (median θ in g) on λ_IM = k0 x^(−k), x in g
    (Cornell et al. 2002), 1/yr."""
    return float(k0 * theta_g ** -k * math.exp(0.5 * k * k * beta * beta))


def probability_in(rate, years: float = YEARS):
    """The probability of at least one event in *years* years, 1 − exp(−years λ), for a rate *rate* (1/yr)."""
    return -np.expm1(-years * np.asarray(rate, dtype=float))


def rate_for_probability(probability: float, years: float = YEARS) -> float:
    """The annual rate (1/yr) whose probability in *years* years is *probability*: −ln(1 − p) / years."""
    return -math.log1p(-probability) / years


def parse_target(text: str) -> tuple[float, float]:
    """``--target 2%/50y`` (or ``0.02/50y``, ``2%/50``): (probability, years)."""
    raw = str(text).strip().replace(" ", "")
    what = f"--target {text!r}"
    if "/" not in raw:
        raise PoundingError(f"{what}: write a probability in a number of years, e.g. 2%/50y")
    p_text, y_text = raw.split("/", 1)
    try:
        p = float(p_text[:-1]) / 100.0 if p_text.endswith("%") else float(p_text)
        years = float(y_text.rstrip("yYrRsS") or "nan")
    except ValueError:
        raise PoundingError(f"{what}: write a probability in a number of years, e.g. 2%/50y") from None
    if not 0 < p < 1:
        raise PoundingError(f"{what}: the probability must be between 0 and 100 % (e.g. 2%/50y)")
    if not (math.isfinite(years) and years > 0):
        raise PoundingError(f"{what}: the number of years must be > 0 (e.g. 2%/50y)")
    return p, years


def stripe_exceedance(demands: np.ndarray, separations: np.ndarray) -> np.ndarray:
    """P_j(D > g): per stripe (rows of *demands*, runs along the columns, NaN: no result, +inf: unbounded)
    the fraction of the runs with a result whose demand exceeds each separation g; shape (stripe, g).
    A stripe without a result is NaN."""
    d = np.asarray(demands, dtype=float)
    g = np.asarray(separations, dtype=float)
    counted = np.isfinite(d) | np.isposinf(d)
    n = counted.sum(axis=1)
    over = (np.where(counted, d, -np.inf)[:, :, None] > g[None, None, :]).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n[:, None] > 0, over / n[:, None], np.nan)


def _interpolated(stripes: np.ndarray, p: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """P(x) for every g: linear in ln x between stripes, the highest stripe's above, 0 below the lowest."""
    lx = np.log(stripes)

    def probability(x: np.ndarray) -> np.ndarray:
        u = np.log(x)
        i = np.clip(np.searchsorted(lx, u, side="right") - 1, 0, max(lx.size - 2, 0))
        if lx.size == 1:
            out = np.broadcast_to(p[0], (u.size, p.shape[1])).copy()
        else:
            t = np.clip((u - lx[i]) / (lx[i + 1] - lx[i]), 0.0, 1.0)[:, None]
            out = (1.0 - t) * p[i] + t * p[i + 1]
        out[u < lx[0]] = 0.0
        return out
    return probability


def exceedance_rates(curve: HazardCurve, stripes: np.ndarray, demands: np.ndarray,
                     separations: np.ndarray) -> np.ndarray:
    """λ(g) = ∫ P(D > g | x) |dλ_IM(x)| (1/yr) at each separation *g* (m), the empirical route.

    Parameters
    ----------
    curve : HazardCurve
        The site's hazard curve.
    stripes : ndarray
        The stripes' intensities, m/s², increasing.
    demands : ndarray
        (stripe, run): each run's demand D, m (its required separation); NaN where the run has no result,
        +inf where it is unbounded (a building collapsed).
    separations : ndarray
        The separations g, m.
    """
    stripes = np.asarray(stripes, dtype=float)
    p = stripe_exceedance(demands, separations)
    have = np.all(np.isfinite(p), axis=1)
    if not have.any():
        raise PoundingError("no stripe has a run with a result: no rate of pounding can be computed")
    return annual_rate(curve, _interpolated(stripes[have], p[have]), breaks=stripes[have])


def separation_for_rate(curve: HazardCurve, stripes: np.ndarray, demands: np.ndarray, target: float) -> float:
    """The smallest separation g (m) with λ(g) ≤ *target* (1/yr): one of the demands, since λ(g) only changes
    there (0 when even g = 0 is rare enough; +inf when no finite demand is enough: runs with unbounded demands
    alone pound too often)."""
    d = np.asarray(demands, dtype=float)
    candidates = np.unique(np.concatenate([[0.0], d[np.isfinite(d)]]))
    rates = exceedance_rates(curve, stripes, d, candidates)
    ok = np.flatnonzero(rates <= target)
    return float(candidates[ok[0]]) if ok.size else math.inf


def lowest_stripe_share(stripes: np.ndarray, demands: np.ndarray, separation: float) -> float:
    """P(D > g) at the lowest stripe with results: the part of the integral below it is left out (taken as
    0), a fair omission only when this is small."""
    p = stripe_exceedance(demands, np.array([separation]))[:, 0]
    have = np.flatnonzero(np.isfinite(p))
    return float(p[have[0]]) if have.size else math.nan
