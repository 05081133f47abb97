"""Consistency of the Dormand–Prince 5(4) tableau compiled into :mod:`pounding.solver`.

The constants are imported from the module (``C2…C5``, ``A21…A65``,
``B1, B3…B6``, ``E1, E3…E7``); the numba kernel uses exactly these names, so
these tests check the numbers the integrator runs with.  Entries the module
does not define are structural zeros of the method and of the kernel's
formulas: ``B2 = 0`` and ``E2 = 0`` (stage 2 does not enter the solution or
the error estimate), ``B7 = 0`` (FSAL), and ``c1 = 0``.

The checks are those scipy applies to its own tableaux (``scipy.integrate``
test suite): row sums ``c_i = Σ_j a_ij``, the order conditions (all 17
rooted trees up to order 5 for the 5th-order weights ``b``, the 8 up to
order 4 for the embedded weights ``b̂ = b − e``), the first-same-as-last
property, and agreement with scipy's own ``RK45`` tableau as an independent
transcription of Dormand & Prince (1980).  The solver's interpolant is a cubic
Hermite on step-end values and rates (not the DP continuous extension), so
its consistency is checked directly.

All constants are ratios of small integers evaluated in double precision, so
every identity below holds to a few ulp: tolerance 1e-14 throughout (a wrong
digit in any constant moves some condition by ≥ 1e-6).
"""

from __future__ import annotations

import numpy as np
import pytest

from pounding.solver import dense
from pounding.solver import dormand_prince as solver

TOL = 1e-14  # a few ulp of O(1) sums of ~10 products; see the module docstring


def tableau() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A 7×7, b 7, c 7, e 7) of the solver, with stage 7 the FSAL stage (row 7 of A = b)."""
    s = solver
    A = np.zeros((7, 7))
    A[1, 0] = s.A21
    A[2, :2] = s.A31, s.A32
    A[3, :3] = s.A41, s.A42, s.A43
    A[4, :4] = s.A51, s.A52, s.A53, s.A54
    A[5, :5] = s.A61, s.A62, s.A63, s.A64, s.A65
    b = np.array([s.B1, 0.0, s.B3, s.B4, s.B5, s.B6, 0.0])
    A[6, :] = b  # FSAL: the 7th stage is f at the new solution
    c = np.array([0.0, s.C2, s.C3, s.C4, s.C5, 1.0, 1.0])
    e = np.array([s.E1, 0.0, s.E3, s.E4, s.E5, s.E6, s.E7])
    return A, b, c, e


def order_conditions(A: np.ndarray, b: np.ndarray, c: np.ndarray) -> dict[str, tuple[int, float, float]]:
    """Elementary weights Φ(t) and 1/γ(t) of every rooted tree t up to order 5: {name: (order, Φ, 1/γ)}."""
    Ac = A @ c
    Ac2 = A @ c**2
    AAc = A @ Ac
    return {
        "b.1": (1, b.sum(), 1.0),
        "b.c": (2, b @ c, 1 / 2),
        "b.c^2": (3, b @ c**2, 1 / 3),
        "b.Ac": (3, b @ Ac, 1 / 6),
        "b.c^3": (4, b @ c**3, 1 / 4),
        "b.(c*Ac)": (4, b @ (c * Ac), 1 / 8),
        "b.Ac^2": (4, b @ Ac2, 1 / 12),
        "b.AAc": (4, b @ AAc, 1 / 24),
        "b.c^4": (5, b @ c**4, 1 / 5),
        "b.(c^2*Ac)": (5, b @ (c**2 * Ac), 1 / 10),
        "b.(c*Ac^2)": (5, b @ (c * Ac2), 1 / 15),
        "b.(c*AAc)": (5, b @ (c * AAc), 1 / 30),
        "b.(Ac)^2": (5, b @ (Ac * Ac), 1 / 20),
        "b.Ac^3": (5, b @ (A @ c**3), 1 / 20),
        "b.A(c*Ac)": (5, b @ (A @ (c * Ac)), 1 / 40),
        "b.AAc^2": (5, b @ (A @ Ac2), 1 / 60),
        "b.AAAc": (5, b @ (A @ AAc), 1 / 120),
    }


def test_row_sums_are_the_nodes():
    A, _, c, _ = tableau()
    np.testing.assert_allclose(A.sum(axis=1), c, rtol=0, atol=TOL)


def test_explicit_method():
    A, *_ = tableau()
    assert np.all(np.triu(A[:6, :6]) == 0.0)  # the kernel evaluates stage i from stages < i only


def test_there_are_17_conditions_up_to_order_5():
    # The number of rooted trees of order 1..5 is 1, 1, 2, 4, 9: the list is complete.
    counts = np.bincount([order for order, _, _ in order_conditions(*tableau()[:3]).values()])
    assert list(counts[1:]) == [1, 1, 2, 4, 9]


@pytest.mark.parametrize("name", list(order_conditions(*tableau()[:3])))
def test_fifth_order_weights_satisfy_every_condition_to_order_5(name):
    _, phi, expected = order_conditions(*tableau()[:3])[name]
    assert abs(phi - expected) < TOL, (name, phi, expected)


def test_embedded_weights_are_fourth_order_and_not_fifth():
    A, b, c, e = tableau()
    b_hat = b - e  # the kernel's error estimate is h·Σ e_i k_i = y5 − y4
    conditions = order_conditions(A, b_hat, c)
    for name, (order, phi, expected) in conditions.items():
        if order <= 4:
            assert abs(phi - expected) < TOL, (name, phi, expected)
    # A genuine 4th-order embedding: some 5th-order condition fails by far more
    # than round-off, otherwise the error estimate would vanish at 5th order.
    worst = max(abs(phi - expected) for order, phi, expected in conditions.values() if order == 5)
    assert worst > 1e-4


def test_error_weights_sum_to_zero_and_use_the_fsal_stage():
    # Σ e_i = Σ b_i − Σ b̂_i = 0 (both consistent); e_7 ≠ 0: the estimate needs
    # the FSAL stage f(t+h, y_new), which the kernel computes as k7 and reuses as
    # the next step's k1.
    _, b, _, e = tableau()
    assert abs(e.sum()) < TOL
    assert e[6] != 0.0
    assert b[6] == 0.0 and b[1] == 0.0


def test_fsal_last_stage_is_the_new_solution():
    # Stage 6 of DP5 sits at c6 = 1 and the 7th (FSAL) stage at c7 = 1 with
    # a_7j = b_j: f evaluated there is f(t + h, y_new), so k7 of one step is
    # exactly k1 of the next.  Check on a linear problem y' = λy: the 7th
    # stage argument Y7 = y + h Σ b_j k_j equals the propagated solution.
    A, b, c, _ = tableau()
    lam, h, y0 = -1.3, 0.37, 1.0
    k = np.zeros(7)
    for i in range(7):
        k[i] = lam * (y0 + h * A[i, :i] @ k[:i])
    y_new = y0 + h * b @ k
    assert k[6] == pytest.approx(lam * y_new, abs=TOL)
    # … and y_new is the stability polynomial of DOPRI5 (Hairer & Wanner, Solving
    # ODEs II, §IV.2): the degree-5 Taylor polynomial of exp(z) plus z⁶/600
    # (6 stages, order 5: b·A⁵·1 = 1/600).
    z = lam * h
    taylor5 = sum(z**j / np.prod(range(1, j + 1)) for j in range(6))
    assert y_new == pytest.approx(taylor5 + z**6 / 600, abs=1e-15)
    assert b @ np.linalg.matrix_power(A, 5) @ np.ones(7) == pytest.approx(1 / 600, abs=TOL)


def test_agrees_with_scipy_rk45_tableau():
    # scipy transcribes the same Dormand & Prince (1980) tableau independently.
    # Its error vector E is b̂ − b (ours is b − b̂, as the kernel's E1 > 0).
    from scipy.integrate._ivp.rk import RK45

    A, b, c, e = tableau()
    np.testing.assert_allclose(A[:6, :5], RK45.A, rtol=0, atol=TOL)
    np.testing.assert_allclose(b[:6], RK45.B, rtol=0, atol=TOL)
    np.testing.assert_allclose(c[:6], RK45.C, rtol=0, atol=TOL)
    np.testing.assert_allclose(e, -RK45.E, rtol=0, atol=TOL)


def test_step_controller_exponent_matches_the_embedded_order():
    # The controller scales h by err^(−1/(q+1)) with q = 4 the lower order of the
    # pair (Hairer, Nørsett & Wanner §II.4): −0.2 in the kernel; its safety and
    # limits are the usual ones (0.9, [0.2, 5] like scipy's [0.2, 10] lower end).
    assert solver.SAFETY == 0.9
    assert solver.MIN_FACTOR == 0.2
    assert solver.MAX_FACTOR > 1.0


# --------------------------------------------------------------------------- #
# The interpolant used for events, peaks and output (cubic Hermite)
# --------------------------------------------------------------------------- #

hermite = dense.hermite.py_func  # the pure-Python body of the compiled kernel


def test_hermite_matches_end_values_and_rates():
    y0, r0, y1, r1, h = 0.3, -1.7, -0.8, 2.4, 0.05
    assert hermite(y0, r0, y1, r1, h, 0.0) == y0
    assert hermite(y0, r0, y1, r1, h, 1.0) == pytest.approx(y1, abs=1e-15)
    ds = 1e-6  # central differences: O(ds²) = 1e-12 relative error on the rate
    for s, rate in ((0.0, r0), (1.0, r1)):
        slope = (hermite(y0, r0, y1, r1, h, s + ds) - hermite(y0, r0, y1, r1, h, s - ds)) / (2 * ds * h)
        assert slope == pytest.approx(rate, rel=1e-7)


def test_hermite_reproduces_cubics_exactly():
    # A cubic is determined by end values and slopes: the interpolant is exact.
    p = np.poly1d([2.5, -1.0, 0.7, 0.2])
    dp = p.deriv()
    t0, h = 0.4, 0.3
    for s in np.linspace(0.0, 1.0, 11):
        value = hermite(p(t0), dp(t0), p(t0 + h), dp(t0 + h), h, s)
        assert value == pytest.approx(p(t0 + s * h), abs=1e-14)


def test_hermite_error_is_fourth_order():
    # At mid-step the error of a cubic Hermite is h⁴/384·f⁗(t_mid) + O(h⁶)
    # (the odd term cancels by symmetry): for sin, h⁴/384·sin(t_mid).  At
    # h = 0.02 the remainder is ~1e-5 relative (measured 7e-6): bound 1e-3.
    # Halving h divides the error by 16·(1 + O(h)) (measured 16.38): 15.5-16.5.
    t0 = 0.2

    def mid_error(h):
        return abs(hermite(np.sin(t0), np.cos(t0), np.sin(t0 + h), np.cos(t0 + h), h, 0.5) - np.sin(t0 + 0.5 * h))

    h = 0.02
    assert mid_error(h) == pytest.approx(h**4 / 384 * np.sin(t0 + h / 2), rel=1e-3)
    assert 15.5 < mid_error(h) / mid_error(h / 2) < 16.5
