"""The ξ-formula registry: values, limits, the exact-restitution root, look-up errors."""

from __future__ import annotations

import math

import mpmath
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pounding.contact import xi
from pounding.errors import PoundingError


def relation(p: float, e: float) -> mpmath.mpf:
    """g(p) = ln((1+p)/(1−e·p)) − (1+e)·p in 60-digit arithmetic (nan beyond p = 1/e)."""
    with mpmath.workdps(60):
        p_, e_ = mpmath.mpf(p), mpmath.mpf(e)
        if 1 - e_ * p_ <= 0:
            return mpmath.inf
        return mpmath.log((1 + p_) / (1 - e_ * p_)) - (1 + e_) * p_


@pytest.mark.parametrize("e", [1e-3, 2e-3, 0.01, 0.05, 0.1, 0.3, 0.5, 0.65, 0.9, 0.99, 0.999999, 1 - 1e-12])
def test_exact_root_brackets_the_relation_to_1e_12(e):
    # The root is checked in 60-digit arithmetic: g changes sign between
    # p·(1 − 1e-12) and p·(1 + 1e-12) (or p is 1/e to double precision, where
    # 1 − e·p underflows).  1e-12 relative is the accuracy the issue asks for;
    # double precision allows ~1e-15.
    p = xi.exact(e)
    assert 0.0 < p <= 1.0 / e * (1 + 1e-15)
    below = relation(p * (1 - 1e-12), e)
    above = relation(p * (1 + 1e-12), e)
    assert below < 0
    assert above > 0


def test_exact_is_zero_at_elastic_impact():
    assert xi.exact(1.0) == 0.0


@given(st.floats(min_value=0.05, max_value=0.999))
@settings(max_examples=60, deadline=None)
def test_exact_lies_between_its_limits(e):
    # p ≥ 1.5(1−e)·(1 − something) near e → 1 and p < 1/e everywhere; the exact
    # root is bounded below by the Hunt-Crossley first-order term's e→1 limit
    # and above by the pole of the relation.
    p = xi.exact(e)
    assert p < 1.0 / e
    assert p > 1.5 * (1 - e) * 0.9


def test_exact_tends_to_hunt_crossley_near_one():
    # p = 1.5(1−e) + O((1−e)²): at 1−e = 1e-6 the relative difference is ~1e-6.
    e = 1 - 1e-6
    assert xi.exact(e) == pytest.approx(1.5 * (1 - e), rel=1e-5)


@pytest.mark.parametrize("key,e,expected", [
    ("lankarani-nikravesh", 0.65, 0.75 * (1 - 0.65**2)),
    ("ye", 0.65, 8 * (1 - 0.65) / (5 * 0.65)),
    ("hunt-crossley", 0.4, 1.5 * 0.6),
    ("gonthier", 0.5, (1 - 0.25) / 0.5),
])
def test_formula_values_match_their_published_expressions(key, e, expected):
    assert xi.p(key, e) == pytest.approx(expected, rel=1e-15)


def test_every_formula_gives_no_damping_at_e_equal_one():
    for key in xi.names():
        assert xi.p(key, 1.0) == pytest.approx(0.0, abs=1e-15), key


def test_bounded_formulas_stay_finite_and_unbounded_diverge():
    for key, formula in xi.FORMULAS.items():
        small = formula(1e-6)
        # "bounded" means p stays O(1) (≤ 3·e²/4 ≈ 5.5 for zhiying-qishao) as e → 0;
        # the others exceed 10 (carvalho-martins tends to 16.5, 1/e-types diverge).
        if formula.bounded:
            assert small < 6.0, key
        else:
            assert small > 10.0, key


def test_damping_constant_scales_with_kh_over_v0():
    value = xi.damping_constant("ye", 0.5, kh=2e9, v0=3.0)
    assert value == pytest.approx(1.6 * 0.5 / 0.5 * 2e9 / 3.0, rel=1e-15)


def test_aliases_resolve():
    assert xi.get("flores") is xi.get("ye")
    assert xi.get("muthukumar-desroches") is xi.get("lankarani-nikravesh")


def test_unknown_formula_suggests_the_closest_name():
    with pytest.raises(PoundingError, match=r"unknown xi formula 'lankarani' \(did you mean 'lankarani-nikravesh'\?\)"):
        xi.get("lankarani")


@pytest.mark.parametrize("e", [0.0, -0.1, 1.2, math.nan])
def test_restitution_outside_unit_interval_is_rejected(e):
    with pytest.raises(PoundingError, match=r"restitution must be in \(0, 1\]"):
        xi.p("ye", e)


def test_module_examples_are_right():
    import doctest

    assert doctest.testmod(xi).failed == 0
