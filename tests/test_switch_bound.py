"""The bound that spares a closed contact's switch search (``kernels.switch_may_cross``).

A clamped Hertz-damp contact's switch function ``±(kh + ξ·δ̇)`` is searched for a sign change at
nine points of the step's interpolant of δ̇ on every step the contact is closed.  The search is
skipped when the interpolant's range, bounded by its ends and ``HERMITE_REACH·h·(|a0| + |a1|)``,
keeps the function positive.  Skipping must never hide a crossing the search would find: these
tests sample the interpolant far more densely than the search does wherever the bound skips.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pounding.contact.laws import N_PARAMETERS
from pounding.solver import kernels
from pounding.solver.contact_events import EVENT_SAMPLES, HERMITE_REACH

HERTZ_DAMP = kernels.LAW_HERTZ_DAMP
#: The dense check's points: 64 times the search's own, the ends included.
DENSE = np.linspace(0.0, 1.0, 64 * EVENT_SAMPLES + 1)


def hermite(y0: float, r0: float, y1: float, r1: float, h: float, s: np.ndarray) -> np.ndarray:
    """The cubic Hermite interpolant at fractions *s* (the formula of ``pounding.solver.dense.hermite``)."""
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * r0 + (-2 * s3 + 3 * s2) * y1
            + (s3 - s2) * h * r1)


def prm(kh: float) -> np.ndarray:
    """Hertz-damp's kernel parameters with the tension clamp on (``prm[3] == 0``: one switch)."""
    out = np.zeros(N_PARAMETERS)
    out[0] = kh
    return out


def may_cross(kh: float, xi: float, mode: int, v0: float, a0: float, v1: float, a1: float, h: float) -> bool:
    """The bound as the search applies it to the interpolant of δ̇ over a step of *h* s."""
    reach = HERMITE_REACH * h * (abs(a0) + abs(a1))
    return kernels.switch_may_cross(HERTZ_DAMP, prm(kh), xi, mode, 0, min(v0, v1) - reach, max(v0, v1) + reach)


def switch_on_interpolant(kh, xi, mode, v0, a0, v1, a1, h) -> np.ndarray:
    rates = hermite(v0, a0, v1, a1, h, DENSE)
    return np.array([kernels.switch_value(HERTZ_DAMP, prm(kh), xi, mode, 0, 1e-3, r, 0.0) for r in rates])


def test_the_law_has_the_switch_the_bound_is_for():
    assert kernels.switch_count(HERTZ_DAMP, prm(1e9)) == 1


@settings(max_examples=400, deadline=None)
@given(kh=st.floats(1e6, 1e12), xi_ratio=st.floats(0.01, 100.0), mode=st.sampled_from([kernels.MODE_PUSH,
                                                                                         kernels.MODE_CLAMPED]),
       v0=st.floats(-3.0, 3.0), v1=st.floats(-3.0, 3.0), a0=st.floats(-2000.0, 2000.0),
       a1=st.floats(-2000.0, 2000.0), h=st.floats(1e-5, 1e-2))
def test_a_skipped_search_has_no_crossing_to_find(kh, xi_ratio, mode, v0, v1, a0, a1, h):
    """Wherever the bound skips the search, the switch function is positive at every dense point.

    ξ is drawn as kh / (ξ_ratio · 1 m/s), so the switch's root ``δ̇ = −kh/ξ`` lies within the drawn rates'
    range as often as not.
    """
    xi = kh / xi_ratio
    if may_cross(kh, xi, mode, v0, a0, v1, a1, h):
        return
    assert np.all(switch_on_interpolant(kh, xi, mode, v0, a0, v1, a1, h) > 0.0)


def test_the_bound_skips_an_ordinary_step_and_keeps_a_crossing():
    """A test that could fail both ways: a step of a pushing contact far from its clamp is skipped; a
    step whose rate passes the clamp's root ``−kh/ξ`` only between the search's samples is not."""
    kh, xi, h = 1e10, 2e10, 0.002   # root at δ̇ = −0.5 m/s
    assert not may_cross(kh, xi, kernels.MODE_PUSH, 0.2, -50.0, 0.1, -50.0, h)
    # rate ends at -0.45 and -0.45, dipping between samples: the cubic's minimum is below -0.5
    v0, v1, a0, a1 = -0.45, -0.45, -150.0, 150.0
    dips = switch_on_interpolant(kh, xi, kernels.MODE_PUSH, v0, a0, v1, a1, h)
    assert dips.min() < 0.0 < dips[0]
    assert may_cross(kh, xi, kernels.MODE_PUSH, v0, a0, v1, a1, h)


def test_the_bound_is_the_laws_only():
    """Any other law's switches are always searched (the bound knows only Hertz-damp's clamp)."""
    other = kernels.LAW_KELVIN
    out = np.zeros(N_PARAMETERS)
    out[0], out[1] = 1e8, 1e5
    assert kernels.switch_may_cross(other, out, 0.0, kernels.MODE_PUSH, 0, 1.0, 2.0)
