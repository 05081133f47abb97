"""Lognormal fragility functions: P(EDP > limit | IM = x) = Φ(ln(x / θ) / β).

Two ways to fit θ (median, in IM units) and β (dispersion), after Baker
(2015), "Efficient analytical fragility function fitting using dynamic
structural analysis", Earthquake Spectra 31(1) 579–599:

- :func:`fit_stripes`: maximum likelihood on stripe counts (n_j records at
  intensity x_j, z_j of them exceeding the limit), maximising
  Σ_j [z_j ln Φ(ln(x_j/θ)/β) + (n_j − z_j) ln(1 − Φ(ln(x_j/θ)/β))]
  (Baker 2015, eq. 11).  It is a probit regression of the exceedances on
  ln x, P = Φ(a + b ln x) with b = 1/β and a = −ln θ / β, solved here by
  Fisher scoring (iteratively reweighted least squares), which converges to
  the maximum in a few steps.
- :func:`fit_intensities`: from each record's own intensity at the limit (a
  collapse intensity found by hunt-and-fill):
  θ = exp(mean ln IM_c), β = standard deviation of ln IM_c with n − 1
  (Baker 2015, eqs. 3–4).

And :func:`collapse_margin_ratio`, the FEMA P695 (2009) CMR = Ŝ_CT / S_MT.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import log_ndtr, ndtr, ndtri

from pounding.errors import PoundingError

__all__ = ["Fragility", "fit_stripes", "fit_intensities", "collapse_margin_ratio", "probability"]


@dataclass(frozen=True)
class Fragility:
    """A lognormal fragility function.

    Attributes
    ----------
    theta : float
        Median capacity, in the units of the intensity measure (m/s² for Sa or PGA).
    beta : float
        Logarithmic standard deviation (dispersion), dimensionless.
    method : str
        ``mle-stripes`` or ``intensities``.
    """

    theta: float
    beta: float
    method: str

    def probability(self, intensity: np.ndarray | float) -> np.ndarray:
        """P(exceed | IM = intensity)."""
        return probability(intensity, self.theta, self.beta)


def probability(intensity: np.ndarray | float, theta: float, beta: float) -> np.ndarray:
    """Φ(ln(x/θ)/β) at intensities *x* (same units as θ)."""
    x = np.asarray(intensity, dtype=float)
    with np.errstate(divide="ignore"):
        return ndtr(np.log(x / theta) / beta)


def fit_stripes(intensity: np.ndarray, n_records: np.ndarray, n_exceed: np.ndarray, *,
                tolerance: float = 1e-13, max_iterations: int = 200) -> Fragility:
    """Maximum-likelihood lognormal fragility from stripe counts (Baker 2015, eq. 11).

    Parameters
    ----------
    intensity : (m,) array
        Intensity of each stripe (> 0, any units; θ comes out in the same units).
    n_records : (m,) array of int
        Records analysed at each stripe.
    n_exceed : (m,) array of int
        Of them, the number whose response exceeded the limit.

    Returns
    -------
    Fragility

    Raises
    ------
    PoundingError
        When the data cannot define a fragility: no exceedance at all, or
        exceedance at every stripe, or a perfect separation (every stripe below
        some intensity has no exceedance and every stripe above has all) — the
        maximum likelihood then has β → 0.
    """
    x = np.asarray(intensity, dtype=float)
    n = np.asarray(n_records, dtype=float)
    z = np.asarray(n_exceed, dtype=float)
    keep = n > 0
    x, n, z = x[keep], n[keep], z[keep]
    if x.size == 0 or np.any(x <= 0) or np.any(z < 0) or np.any(z > n):
        raise PoundingError("fragility fit: stripes need intensities > 0 and 0 <= exceedances <= records")
    if z.sum() == 0:
        raise PoundingError("fragility fit: no record exceeds the limit at any stripe; raise the intensities")
    if np.all(z == n):
        raise PoundingError("fragility fit: every record exceeds the limit at every stripe; lower the intensities")
    order = np.argsort(x)
    p_sorted = (z / n)[order]
    if np.all((p_sorted == 0) | (p_sorted == 1)) and np.all(np.diff(p_sorted) >= 0):
        raise PoundingError("fragility fit: the stripes separate exactly (none exceed below, all above), so "
                            "beta -> 0; add stripes between them")
    s = np.log(x)
    # Start from a least-squares probit fit of the empirical fractions (clipped off 0 and 1).
    fraction = np.clip((z + 0.5) / (n + 1.0), 1e-3, 1 - 1e-3)
    b, a = np.polyfit(s, ndtri(fraction), 1) if np.ptp(s) > 0 else (1.0, -s[0])
    if not b > 0:
        b, a = 1.0, -float(np.average(s, weights=n))
    params = np.array([a, b])
    design = np.column_stack([np.ones_like(s), s])
    for _ in range(max_iterations):
        eta = design @ params
        p = np.clip(ndtr(eta), 1e-300, 1 - 1e-16)
        density = np.exp(-0.5 * eta * eta) / math.sqrt(2 * math.pi)
        # Fisher scoring for the binomial-probit likelihood: score and expected information.
        weight = n * density * density / (p * (1 - p))
        score = design.T @ (density * (z - n * p) / (p * (1 - p)))
        information = design.T @ (design * weight[:, None])
        try:
            step = np.linalg.solve(information, score)
        except np.linalg.LinAlgError:   # the weights underflowed: the data pin no finite (theta, beta)
            raise PoundingError("fragility fit: the stripes do not define a lognormal fragility (the likelihood "
                                "is flat or the fit runs off to beta -> 0 or infinity); add stripes") from None
        if not np.all(np.isfinite(step)):
            raise PoundingError("fragility fit: the stripes do not define a lognormal fragility (the likelihood "
                                "is flat or the fit runs off to beta -> 0 or infinity); add stripes")
        # Damped: halve the step until the likelihood does not fall (a full step from a poor start can
        # overshoot into the tails, where the weights underflow).
        before = _log_likelihood(design @ params, n, z)
        for _ in range(60):
            trial = params + step
            if _log_likelihood(design @ trial, n, z) >= before - 1e-12 * (1 + abs(before)):
                break
            step = 0.5 * step
        params = params + step
        if np.max(np.abs(step)) < tolerance * (1 + np.max(np.abs(params))):
            break
    else:  # pragma: no cover - the probit likelihood is concave: scoring converges
        raise PoundingError("fragility fit: the maximum-likelihood iteration did not converge")
    a, b = params
    if not b > 0:
        raise PoundingError("fragility fit: the exceedances do not increase with intensity (slope <= 0)")
    return Fragility(theta=float(math.exp(-a / b)), beta=float(1.0 / b), method="mle-stripes")


def _log_likelihood(eta: np.ndarray, n: np.ndarray, z: np.ndarray) -> float:
    """Σ z ln Φ(η) + (n − z) ln Φ(−η), computed in the tails without underflow."""
    value = float(np.sum(z * log_ndtr(eta) + (n - z) * log_ndtr(-eta)))
    return value if math.isfinite(value) else -math.inf


def fit_intensities(intensities: np.ndarray) -> Fragility:
    """Lognormal fragility from each record's intensity at the limit (Baker 2015, eqs. 3–4).

    Parameters
    ----------
    intensities : (n,) array
        Per-record intensity at which the limit (e.g. collapse) is reached, > 0.
        Records that never reached it (NaN) are refused: give a finite bracket.
    """
    values = np.asarray(intensities, dtype=float)
    if values.size < 2 or not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise PoundingError("fragility fit: needs at least 2 finite intensities > 0 (got "
                            f"{values.size}, {int(np.sum(~np.isfinite(values)))} not finite)")
    logs = np.log(values)
    return Fragility(theta=float(np.exp(logs.mean())), beta=float(logs.std(ddof=1)), method="intensities")


def collapse_margin_ratio(median_collapse_intensity: float, mce_intensity: float) -> float:
    """FEMA P695 (2009) collapse margin ratio CMR = Ŝ_CT / S_MT (same units for both)."""
    if not mce_intensity > 0:
        raise PoundingError(f"--mce must be > 0 (got {mce_intensity:g})")
    return float(median_collapse_intensity) / float(mce_intensity)
