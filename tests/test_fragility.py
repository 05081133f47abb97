"""Lognormal fragility fits (pounding.studies.fragility) against an independent maximum-likelihood solution."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize
from scipy.stats import norm

from pounding.errors import PoundingError
from pounding.studies.fragility import collapse_margin_ratio, fit_intensities, fit_stripes


def _independent_mle(x, n, z):
    """Baker (2015) eq. 11 maximised by Nelder-Mead on (ln theta, ln beta): a second method, not scoring."""
    def negative_log_likelihood(params):
        theta, beta = np.exp(params)
        p = np.clip(norm.cdf(np.log(x / theta) / beta), 1e-300, 1 - 1e-16)
        return -np.sum(z * np.log(p) + (n - z) * np.log(1 - p))

    start = [np.log(np.median(x)), np.log(0.5)]
    result = minimize(negative_log_likelihood, start, method="Nelder-Mead",
                      options={"xatol": 1e-13, "fatol": 1e-15, "maxiter": 40000, "maxfev": 40000})
    return np.exp(result.x)


STRIPES = [
    # Baker (2015)-like stripes: 8 intensities (g), 40 records each.
    (np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0]), np.full(8, 40), np.array([0, 1, 4, 10, 18, 25, 33, 38])),
    # few records, uneven stripes, m/s² units
    (np.array([1.0, 2.5, 4.0, 7.0]), np.array([7, 7, 6, 7]), np.array([0, 2, 3, 6])),
    # 44 far-field components, 20 stripes from an IDA
    (np.linspace(0.1, 2.0, 20), np.full(20, 44), np.round(44 * norm.cdf(np.log(np.linspace(0.1, 2.0, 20) / 0.9) / 0.35))),
]


@pytest.mark.parametrize("x,n,z", STRIPES)
def test_stripe_fit_is_the_maximum_likelihood(x, n, z):
    # 1e-6 relative: Nelder-Mead converged to ~1e-10 in the parameters; scoring to 1e-13.
    fit = fit_stripes(x, n, z)
    theta, beta = _independent_mle(x, n, z)
    assert fit.theta == pytest.approx(theta, rel=1e-6)
    assert fit.beta == pytest.approx(beta, rel=1e-6)


@settings(max_examples=25, deadline=None)
@given(theta=st.floats(0.2, 3.0), beta=st.floats(0.15, 0.8))
def test_stripe_fit_recovers_the_fragility_that_made_exact_fractions(theta, beta):
    # Stripes whose exceedance fractions are exactly the fragility's (n huge, z
    # not rounded) are fitted by that fragility: the score vanishes there.
    x = theta * np.exp(np.linspace(-2.0, 2.0, 15) * beta)
    n = np.full(15, 1.0e6)
    z = n * norm.cdf(np.log(x / theta) / beta)
    fit = fit_stripes(x, n, z)
    assert fit.theta == pytest.approx(theta, rel=1e-9)
    assert fit.beta == pytest.approx(beta, rel=1e-9)


@pytest.mark.parametrize("z,message", [([0, 0, 0], "no record exceeds"), ([5, 5, 5], "every record exceeds"),
                                       ([0, 5, 5], "separate exactly")])
def test_degenerate_stripes_are_refused(z, message):
    with pytest.raises(PoundingError, match=message):
        fit_stripes([0.2, 0.4, 0.6], [5, 5, 5], z)


def test_intensity_fit_is_the_lognormal_moments():
    values = np.array([0.8, 1.1, 0.65, 1.7, 0.95, 1.3])
    fit = fit_intensities(values)
    assert fit.theta == pytest.approx(math.exp(np.mean(np.log(values))), rel=1e-14)
    assert fit.beta == pytest.approx(np.std(np.log(values), ddof=1), rel=1e-14)
    with pytest.raises(PoundingError, match="finite"):
        fit_intensities([1.0, np.nan, 2.0])


def test_probability_is_one_half_at_the_median():
    fit = fit_stripes(*STRIPES[0])
    assert fit.probability(fit.theta) == pytest.approx(0.5, abs=1e-15)


def test_collapse_margin_ratio():
    assert collapse_margin_ratio(2.4, 1.5) == pytest.approx(1.6)
    with pytest.raises(PoundingError):
        collapse_margin_ratio(2.4, 0.0)
