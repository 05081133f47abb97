"""Lognormal fragility fits (pounding.studies.fragility) against an independent maximum-likelihood solution."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize
from scipy.stats import norm

from pounding.errors import PoundingError
from pounding.studies.fragility import (collapse_margin_ratio, fit_intensities, fit_stripes, kaplan_meier,
                                        kaplan_meier_median)


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


# --------------------------------------------------------------------------- #
# The Kaplan-Meier estimate and its median (S_CT of pounding p695)
# --------------------------------------------------------------------------- #

@pytest.mark.parametrize("values, expected", [
    # No censoring: the ceil(n/2)-th smallest collapse intensity (FEMA P695: half the records collapse).
    ([3.0, 1.0, 2.0], 2.0),                          # n = 3: the 2nd
    ([1.0, 2.0, 3.0, 4.0, 5.0], 3.0),                # n = 5: the 3rd
    ([4.0, 1.0, 3.0, 2.0], 2.0),                     # n = 4: the 2nd, not the average 2.5 of the 2nd and 3rd
    ([1.0, 2.0, math.inf, math.inf], 2.0),           # 4 records, 2 collapses: the 2nd collapse, a number
    ([1.0, math.inf, math.inf, math.inf], math.nan),  # 1 of 4 collapsed: half never reached
    ([1.0, 1.0, 2.0, 3.0], 1.0),                     # ties collapse together: 2 of 4 at 1.0
    ([2.0, 1.0, 1.0, 1.0, 5.0, 6.0], 1.0),           # 3 of 6 at 1.0
    ([2.0, 2.0, 1.0, 5.0, 6.0], 2.0),                # 1 of 5 at 1.0, 3 of 5 at 2.0 (ceil(5/2) = 3rd value)
])
def test_the_kaplan_meier_median_without_censoring_is_the_order_statistic(values, expected):
    x = np.array(values)
    got = kaplan_meier_median(x, np.isfinite(x))
    assert (math.isnan(got) and math.isnan(expected)) or got == expected


def test_the_kaplan_meier_estimate_of_kaplan_and_meier_1958():
    """The example of Kaplan & Meier (1958): N = 8 items, deaths at 0.8, 3.1, 5.4, 9.2, losses (censored)
    at 1.0, 2.7, 7.0, 12.1.  By hand, P(t) just after each death: 7/8; 7/8 x 4/5 = 0.7 (1.0 and 2.7 lost,
    5 at risk at 3.1); 0.7 x 3/4 = 0.525 (4 at risk at 5.4); 0.525 x 1/2 = 0.2625 (7.0 lost, 2 at risk at
    9.2).  The fraction dead first reaches 1/2 at 9.2 (at 5.4 it is 0.475)."""
    deaths, losses = [0.8, 3.1, 5.4, 9.2], [1.0, 2.7, 7.0, 12.1]
    x = np.array(deaths + losses)
    reached = np.array([True] * 4 + [False] * 4)
    times, fraction = kaplan_meier(x, reached)
    np.testing.assert_array_equal(times, deaths)
    assert fraction == [Fraction(1, 8), Fraction(3, 10), Fraction(19, 40), Fraction(59, 80)]
    assert kaplan_meier_median(x, reached) == 9.2


def test_the_kaplan_meier_estimate_of_the_6mp_leukaemia_data():
    """Klein & Moeschberger (2003), "Survival Analysis", 2nd ed., Table 4.1A: the 6-MP group of the leukaemia
    remission data (Freireich et al. 1963; 21 patients, weeks, + censored): 6, 6, 6, 6+, 7, 9+, 10, 10+,
    11+, 13, 16, 17+, 19+, 20+, 22, 23, 25+, 32+, 32+, 34+, 35+.  The table's S(t): 0.857, 0.807, 0.753,
    0.690, 0.627, 0.538, 0.448 at 6, 7, 10, 13, 16, 22, 23 (three decimals: the tolerance), median 23 weeks.
    The censoring at 6 (6+) and at 10 (10+) share a death time: they are at risk there (n = 21 and 15)."""
    events = [6, 6, 6, 7, 10, 13, 16, 22, 23]
    censored = [6, 9, 10, 11, 17, 19, 20, 25, 32, 32, 34, 35]
    x = np.array(events + censored, dtype=float)
    reached = np.array([True] * len(events) + [False] * len(censored))
    times, fraction = kaplan_meier(x, reached)
    np.testing.assert_array_equal(times, [6, 7, 10, 13, 16, 22, 23])
    survival = [1 - float(f) for f in fraction]
    np.testing.assert_allclose(survival, [0.857, 0.807, 0.753, 0.690, 0.627, 0.538, 0.448], atol=5e-4)
    assert kaplan_meier_median(x, reached) == 23.0


def test_a_record_censored_low_leaves_the_median_to_the_others_and_too_much_censoring_gives_none():
    # Censored at 0 (never seen standing): it leaves every risk set; the other 4 give their 2nd value.
    assert kaplan_meier_median(np.array([0.0, 1.0, 2.0, 3.0, 4.0]), np.array([False] + [True] * 4)) == 2.0
    # 2 collapses at 1 and 2 among 5, 3 censored at 1.5: F(1) = 1/5, F(2) = 1 - 4/5 x 0/1 = 1 -> 2.0
    x, hit = np.array([1.0, 2.0, 1.5, 1.5, 1.5]), np.array([True, True, False, False, False])
    assert kaplan_meier(x, hit)[1] == [Fraction(1, 5), Fraction(1)]
    assert kaplan_meier_median(x, hit) == 2.0
    # 1 collapse among 5, the other 4 censored above it: F = 1/5 only, not determinable
    assert math.isnan(kaplan_meier_median(np.array([1.0, 2.0, 2.0, 3.0, 3.0]), np.array([True] + [False] * 4)))
    with pytest.raises(PoundingError, match="one value"):
        kaplan_meier(np.array([1.0, math.nan]), np.array([True, True]))
