"""A gap study's separation search, all of a run's histories at once, against the search one history at a time.

:func:`pounding.studies.gap.hermite_maxima` searches every history of a run in one pass (its candidate
intervals' roots in one call, the interpolant evaluated at them elementwise); each history's maximum must be
the one the search of that history alone, interval by interval with ``numpy.roots``, finds — bit for bit,
not within a tolerance: a gap study's results do not depend on how its search is batched.  The side vectors
a process keeps (:func:`pounding.studies.gap.side_layout`) must be the model's own, and a model that
differs in any number they are made of must get its own.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from pounding.model.model import load_model
from pounding.simulation import simulate_arrays
from pounding.studies import gap
from pounding.studies.common import dof_peaks, floor_states

ROOT = Path(__file__).resolve().parents[1]


def scalar_max_hermite(time: np.ndarray, value: np.ndarray, rate: np.ndarray) -> float:
    """The search of one history, interval by interval: the candidate intervals as ``max_hermite`` picks them,
    ``numpy.roots`` of each one's slope, the interpolant evaluated at each real root in (0, 1) in turn."""
    best = float(np.max(value))
    h = np.diff(time)
    y0, y1 = value[:-1], value[1:]
    m0, m1 = rate[:-1] * h, rate[1:] * h
    rise = np.maximum(y0, y1) + (4.0 / 27.0) * (np.abs(m0) + np.abs(m1))
    pad = 1e-12 * (abs(best) + float(np.max(np.abs(rise), initial=0.0)))
    for k in np.flatnonzero(((m0 > 0.0) | (m1 < 0.0)) & (rise >= best - pad)):
        a = 6.0 * y0[k] + 3.0 * m0[k] - 6.0 * y1[k] + 3.0 * m1[k]
        b = -6.0 * y0[k] - 4.0 * m0[k] + 6.0 * y1[k] - 2.0 * m1[k]
        for s in np.roots([a, b, m0[k]]) if a != 0.0 or b != 0.0 else ():
            if abs(s.imag) > 1e-12 or not 0.0 < s.real < 1.0:
                continue
            s = s.real
            s2, s3 = s * s, s * s * s
            y = ((2 * s3 - 3 * s2 + 1) * y0[k] + (s3 - 2 * s2 + s) * m0[k]
                 + (-2 * s3 + 3 * s2) * y1[k] + (s3 - s2) * m1[k])
            best = max(best, float(y))
    return best


def random_history(rng: np.random.Generator, case: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(time, value, rate)`` of a random piecewise cubic; every fourth on whole seconds with small whole values
    and rates, so that its intervals are often degenerate: flat (all zero), linear (a = b = 0), a = 0 alone,
    slopes with a root at 0 (m0 = 0) or at 1 (m1 = 0); the others with real and complex roots over decades."""
    n = int(rng.integers(1, 80))
    if case % 4 == 0:
        time = np.arange(n, dtype=float)
        value, rate = rng.integers(-2, 3, n).astype(float), rng.integers(-2, 3, n).astype(float)
        value[rng.random(n) < 0.2] = -0.0
    else:
        scale = 10.0 ** rng.uniform(-4, 2)
        time = np.cumsum(rng.uniform(0.001, 0.05, n))
        value, rate = rng.normal(0.0, scale, n), rng.normal(0.0, 30.0 * scale, n)
        if case % 4 == 1:
            value -= 3.0 * scale   # every sample below zero
    return time, value, rate


def bits(x: float) -> str:
    return float(x).hex()


def test_the_search_of_one_history_is_the_interval_by_interval_search_bit_for_bit():
    """:func:`max_hermite` equals :func:`scalar_max_hermite` exactly on 600 random piecewise cubics, the
    degenerate ones included (some of which do change the maximum: checked, so the cases are not vacuous)."""
    rng = np.random.default_rng(2024)
    interior = 0
    for case in range(600):
        time, value, rate = random_history(rng, case)
        expected = scalar_max_hermite(time, value, rate)
        assert bits(gap.max_hermite(time, value, rate)) == bits(expected), case
        interior += expected > float(np.max(value))
    assert interior > 100   # many maxima lie between samples: the roots and the cubic are exercised


def test_the_search_of_many_histories_at_once_gives_each_its_own_maximum():
    """:func:`hermite_maxima` of several histories on one time axis: each history's maximum, bit for bit, that of
    the history searched alone — among them a flat one, a linear one, one whose maximum is an interior root
    and one whose maximum is -0.0 (the sign of a zero is kept)."""
    rng = np.random.default_rng(7)
    for case in range(100):
        time, _, _ = random_history(rng, 2 * case + 1)
        n = time.size
        values = [rng.normal(0.0, 1e-2, n) for _ in range(4)] + [np.zeros(n), 0.5 * time, np.full(n, -0.0)]
        rates = [rng.normal(0.0, 1.0, n) for _ in range(4)] + [np.zeros(n), np.full(n, 0.5), np.zeros(n)]
        found = gap.hermite_maxima(time, values, rates)
        assert [bits(x) for x in found] == [bits(scalar_max_hermite(time, v, r)) for v, r in zip(values, rates)]
    assert bits(found[-1]) == bits(-0.0)
    assert gap.hermite_maxima(np.arange(3.0), [], []).shape == (0,)


def test_the_slope_root_table_is_numpy_roots_padded_with_nan():
    """:func:`slope_root_table`: each row ``numpy.roots`` of its quadratic, then NaN: two roots, one when a = 0,
    none when a = b = 0; a root at 0 kept where c = 0."""
    a, b, c = np.array([1.0, 0.0, 0.0, 2.0, 1.0]), np.array([-3.0, 2.0, 0.0, -2.0, 0.0]), \
        np.array([2.0, -1.0, 5.0, 0.0, 1.0])
    table = gap.slope_root_table(a, b, c)
    assert table.shape == (5, 2)
    for k in range(5):
        expected = np.roots([a[k], b[k], c[k]]) if a[k] != 0.0 or b[k] != 0.0 else np.empty(0)
        assert table[k, :expected.size].tobytes() == expected.astype(complex).tobytes()
        assert np.isnan(table[k, expected.size:].real).all()
    assert sorted(table[0].real) == [1.0, 2.0] and table[1, 0] == 0.5 and np.isnan(table[2].real).all()
    assert 0.0 in table[3].real and (table[4].imag != 0.0).all()   # c = 0: a root at 0; s² + 1: complex


@pytest.mark.parametrize("name", ["pair", "corner_pair", "isolated_moat_plan"])
def test_required_separations_are_each_history_searched_alone(name):
    """:func:`required_separations` (every history of the run in one search, the side vectors kept) against
    each contact's approach and each side's displacement searched alone with :func:`scalar_max_hermite` on
    the side vectors worked out afresh: a planar pair, floors in plan (points whose sides turn with their
    floor) and a building in plan against a wall — bit for bit."""
    model = load_model(ROOT / "models" / f"{name}.yaml").with_ground_motion(duration=6.0)
    run = simulate_arrays(model.with_contacts_open())
    found = gap.required_separations(model, run)
    q, qd = floor_states(run)
    t = run.time.values

    def peak(a):
        if a is None:
            return 0.0
        pick = gap.one_dof(a)
        if pick is not None:
            return float(dof_peaks(run)[pick])
        return max(scalar_max_hermite(t, q @ a, qd @ a), scalar_max_hermite(t, -(q @ a), -(qd @ a)))

    for c, (w, left, right) in enumerate(gap.computed_side_vectors(model)):
        assert bits(found["required"][c]) == bits(max(0.0, scalar_max_hermite(t, q @ w, qd @ w)))
        assert bits(found["peak_left"][c]) == bits(peak(left))
        assert bits(found["peak_right"][c]) == bits(peak(right))
    if name != "pair":   # points in plan: some sides searched on the interpolant, not read from the peaks
        assert any(gap.one_dof(a) is None for _, *sides in gap.side_vectors(model) for a in sides if a is not None)


def test_a_process_keeps_each_models_side_vectors_by_the_bits_they_are_made_of():
    """:func:`side_vectors` is :func:`computed_side_vectors` bit for bit, read-only; a model that differs only in
    its record or its gaps meets the same arrays, one whose buildings, contacts or a point's weights differ
    (down to the sign of a zero) gets its own."""
    model = load_model(ROOT / "models" / "corner_pair.yaml")
    kept = gap.side_vectors(model)
    for got, fresh in zip(kept, gap.computed_side_vectors(model)):
        for a, b in zip(got, fresh):
            assert (a is None and b is None) or (a.tobytes() == b.tobytes() and not a.flags.writeable)
    other_record = model.with_ground_motion(duration=3.0).with_contacts_open()
    assert all(a is b for a, b in zip(gap.side_vectors(other_record)[0], kept[0]))
    assert gap.side_vectors_key(other_record) == gap.side_vectors_key(model)
    planar = load_model(ROOT / "models" / "pair.yaml")
    assert gap.side_vectors_key(planar) != gap.side_vectors_key(load_model(ROOT / "models" / "row_of_three.yaml"))
    fewer = dataclasses.replace(planar, gaps=planar.gaps[:-1])
    assert gap.side_vectors_key(fewer) != gap.side_vectors_key(planar) and len(gap.side_vectors(fewer)) == \
        len(planar.gaps) - 1
    face = model.faces[0]
    point = face.points[0]
    weights = point.weights.copy()
    zero = np.flatnonzero(weights.reshape(-1) == 0.0)[0]
    weights.reshape(-1)[zero] = -0.0   # the same numbers as far as == can tell
    signed = dataclasses.replace(face, points=(dataclasses.replace(point, weights=weights), *face.points[1:]))
    changed = dataclasses.replace(model, faces=(signed, *model.faces[1:]))
    assert gap.side_vectors_key(changed) != gap.side_vectors_key(model)
