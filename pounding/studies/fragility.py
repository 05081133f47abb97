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

- :func:`fit_censored_intensities`: the same from per-record intensities of
  which some are right-censored (the record had not reached the limit at that
  intensity: another building collapsed first and ended the run, or the hunt
  reached its ceiling), by maximum likelihood,
  L = Π_observed φ(z_i)/(β x_i) · Π_censored [1 − Φ(z_i)], z = ln(x/θ)/β.
  Without censored records its maximum is the closed form θ = exp(mean ln x),
  β = standard deviation of ln x with n (the MLE; Baker's eq. 4 uses n − 1).
- Stripes with censored runs: a run whose outcome is unknown (the building had
  not reached the limit when another building's collapse ended the run) is not
  a Bernoulli trial, so it leaves its stripe's n_j (and z_j); the binomial
  likelihood of :func:`fit_stripes` is then the likelihood of the observed runs.

Whether the data define a fit at all (:func:`median_observed`,
:func:`median_observed_stripes`): a two-parameter lognormal needs
:data:`MIN_DISTINCT_OBSERVATIONS` distinct observations, and its median must be
inside the data, not extrapolated from its lower tail through the lognormal
shape: at least half of the records that ran were seen to reach the limit (on
hunts), or at some stripe at least half of the runs exceeded it.  A censored
record counts in the denominators and never as reaching the limit: its own
outcome was hidden, so it may lie on either side of the median.  Otherwise the
fit is "not determinable", with the counts, never a number.

The median of a right-censored sample without a distribution (:func:`kaplan_meier`,
:func:`kaplan_meier_median`): the product-limit estimator of Kaplan & Meier (1958), "Nonparametric
estimation from incomplete observations", J. Amer. Statist. Assoc. 53 457–481, of the fraction of records
that reached the limit by intensity x, F(x) = 1 − Π_{x_j ≤ x} (1 − d_j / n_j) (d_j records reaching it at
x_j, n_j records still observed there), and the smallest x_j at which F reaches 1/2.

And :func:`collapse_margin_ratio`, the FEMA P695 (2009) CMR = Ŝ_CT / S_MT.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from scipy.special import log_ndtr, ndtr, ndtri

from pounding.errors import PoundingError

__all__ = ["Fragility", "fit_stripes", "fit_intensities", "fit_censored_intensities", "collapse_margin_ratio",
           "probability", "median_observed", "median_observed_stripes", "MIN_DISTINCT_OBSERVATIONS", "kaplan_meier",
           "kaplan_meier_median"]

#: Distinct observed intensities (or stripes with observed runs) a two-parameter fit needs: one gives
#: no dispersion (β = 0 or undefined).
MIN_DISTINCT_OBSERVATIONS = 2


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


def fit_censored_intensities(intensities: np.ndarray, censored: np.ndarray, *, tolerance: float = 1e-12) -> Fragility:
    """Lognormal fragility by maximum likelihood from per-record intensities, some right-censored.

    Parameters
    ----------
    intensities : (n,) array
        Each record's intensity at the limit (``censored`` False), or the highest intensity at which it
        was seen not to reach it (``censored`` True), > 0, any units (θ comes out in the same).
    censored : (n,) array of bool

    Maximises Σ_observed [−ln β − z²/2] + Σ_censored ln Φ(−z), z = (ln x − ln θ)/β, over (ln θ, ln β)
    with scipy's BFGS from the observed records' moments (gradient norm below *tolerance*).  Without
    censored records the result is the closed form (mean and standard deviation with n of ln x).

    Raises
    ------
    PoundingError
        Fewer than :data:`MIN_DISTINCT_OBSERVATIONS` distinct observed intensities.
    """
    from scipy.optimize import minimize

    x = np.asarray(intensities, dtype=float)
    cens = np.asarray(censored, dtype=bool)
    if x.shape != cens.shape or not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise PoundingError("fragility fit: needs finite intensities > 0, one censoring flag each")
    logs = np.log(x)
    seen = logs[~cens]
    if np.unique(seen).size < MIN_DISTINCT_OBSERVATIONS:
        raise PoundingError(f"fragility fit: needs at least {MIN_DISTINCT_OBSERVATIONS} distinct observed "
                            f"intensities (got {np.unique(seen).size}; {int(cens.sum())} censored)")
    mu0, sigma0 = float(seen.mean()), float(seen.std())
    if not cens.any():
        return Fragility(theta=float(math.exp(mu0)), beta=sigma0, method="mle-censored")
    gone = logs[cens]

    def negative(p: np.ndarray) -> float:
        mu, log_beta = p
        beta = math.exp(log_beta)
        z_seen = (seen - mu) / beta
        value = -(seen.size * -log_beta - 0.5 * float(z_seen @ z_seen)) - float(np.sum(log_ndtr(-(gone - mu) / beta)))
        return value if math.isfinite(value) else math.inf

    best = minimize(negative, np.array([mu0, math.log(sigma0)]), method="BFGS", options={"gtol": tolerance})
    if not np.all(np.isfinite(best.x)):   # pragma: no cover - the likelihood is smooth and bounded
        raise PoundingError("fragility fit: the censored maximum likelihood did not converge")
    mu, log_beta = best.x
    return Fragility(theta=float(math.exp(mu)), beta=float(math.exp(log_beta)), method="mle-censored")


def median_observed(n_reached: int, n_records: int) -> bool:
    """Whether a fit's median is inside the data: at least half of *n_records* (every record that ran,
    censored ones included) were seen to reach the limit.  A censored record may lie on either side of
    the median (another building's collapse hid its own), so it is never counted as above it."""
    return n_records > 0 and 2 * n_reached >= n_records


def median_observed_stripes(n_exceed: np.ndarray, n_ran: np.ndarray) -> bool:
    """Whether a stripe fit's median is inside the data: :data:`MIN_DISTINCT_OBSERVATIONS` stripes with
    runs, and a stripe where at least half of the runs (censored ones included: *n_ran*) exceeded."""
    z = np.asarray(n_exceed, dtype=float)
    n = np.asarray(n_ran, dtype=float)
    return bool(np.sum(n > 0) >= MIN_DISTINCT_OBSERVATIONS and np.any((n > 0) & (2 * z >= n)))


def kaplan_meier(values: np.ndarray, reached: np.ndarray) -> tuple[np.ndarray, list[Fraction]]:
    """The Kaplan–Meier (1958) product-limit estimate of the fraction of records that reached a limit.

    Parameters
    ----------
    values : (n,) array
        Each record's intensity at the limit (*reached* True), or the highest intensity at which it was seen
        not to reach it (*reached* False: right-censored; +inf for a record never seen to reach it), any units.
    reached : (n,) array of bool

    Returns
    -------
    intensities : (m,) array
        The distinct intensities at which records reached the limit, ascending (the units of *values*).
    fraction : list of Fraction
        The estimate of the fraction reached at and just above each, F(x_j) = 1 − Π_{i ≤ j} (n_i − d_i) / n_i:
        d_i records reached the limit at x_i, n_i records had values ≥ x_i (were still observed there).

    Records that reach the limit at equal intensities reach it together (one factor, d_i > 1); a record
    censored at an intensity where others reach the limit is still observed there (the convention of
    Kaplan & Meier 1958: losses at a death time follow the deaths; Klein & Moeschberger 2003, "Survival
    Analysis", 2nd ed., §4.2).  Exact (fractions of counts): without
    censoring F(x_k) is exactly k/n, so no round-off decides a comparison with 1/2.
    """
    x = np.asarray(values, dtype=float)
    hit = np.asarray(reached, dtype=bool)
    if x.shape != hit.shape or np.any(np.isnan(x)):
        raise PoundingError("Kaplan-Meier: needs one value (not NaN) and one flag per record")
    intensities = np.unique(x[hit])
    surviving, fraction = Fraction(1), []
    for value in intensities:
        at_risk = int(np.sum(x >= value))
        surviving *= Fraction(at_risk - int(np.sum(hit & (x == value))), at_risk)
        fraction.append(1 - surviving)
    return intensities, fraction


def kaplan_meier_median(values: np.ndarray, reached: np.ndarray) -> float:
    """The smallest intensity at which the Kaplan–Meier fraction reached (:func:`kaplan_meier`) is at least 1/2;
    NaN where it never is (too many records censored, or too few reached the limit).

    Without censoring (every record reached the limit, or was never seen to: +inf) this is the k-th smallest
    value with k = ⌈n/2⌉ of the n records: with an even n the (n/2)-th, not an average with the next.
    """
    for value, fraction in zip(*kaplan_meier(values, reached)):
        if 2 * fraction >= 1:
            return float(value)
    return float("nan")


def collapse_margin_ratio(median_collapse_intensity: float, mce_intensity: float) -> float:
    """FEMA P695 (2009) collapse margin ratio CMR = Ŝ_CT / S_MT (same units for both)."""
    if not mce_intensity > 0:
        raise PoundingError(f"--mce must be > 0 (got {mce_intensity:g})")
    return float(median_collapse_intensity) / float(mce_intensity)
