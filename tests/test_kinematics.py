"""One kinematics (pounding/solver/kinematics.py) for the solver and the results.

The archive's ``penetration`` (sampled histories, by :func:`pounding.solver.kinematics.penetration`)
and the impact trace's ``trace_penetration`` (the solver's closed-contact samples on a step's
interpolant) are the same δ = Σ w·u + u_g,L − u_g,R − gap: where a trace sample falls on an
output time they agree to round-off, on one ground and with wave passage (ground offsets).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pounding import load_model, simulate
from pounding.solver import kinematics
from pounding.solver.layout import state_layout

MODELS = Path(__file__).resolve().parents[1] / "models"


@pytest.mark.parametrize("name", ["pair", "pair_wave_passage"])
def test_archive_penetration_equals_the_trace_at_the_trace_times(name):
    model = load_model(MODELS / f"{name}.yaml")
    ds = simulate(model, duration=8.0)  # output every 0.01 s: record samples, where steps end
    time = ds.time.values
    trace_time = ds.trace_time.values
    # Trace samples that fall on an output time (steps never straddle a record sample).
    at = np.searchsorted(time, trace_time)
    at = np.clip(at, 0, time.size - 1)
    on = np.abs(time[at] - trace_time) <= 1e-9
    assert on.sum() >= 20, "too few trace samples on output times to compare"
    contact = ds.trace_contact.values[on]
    archived = ds.penetration.values[at[on], contact]
    traced = ds.trace_penetration.values[on]
    assert np.all(traced > 0.0)  # closed contacts: overlapping
    np.testing.assert_allclose(archived, traced, rtol=0.0, atol=1e-12)


def test_results_penetration_is_the_solvers_sum():
    # A floor pair, a column point (two weighted terms) and a wall, against combo's own terms.
    floors = np.array([[0, -1, 2, -1], [0, 1, 3, -1], [1, -1, -1, -1]])
    weights = np.array([[1.0, 0.0, -1.0, 0.0], [0.25, 0.75, -1.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    gap = np.array([0.01, 0.02, 0.03])
    rng = np.random.default_rng(7)
    u = rng.normal(scale=0.05, size=(5, 4))
    ground = rng.normal(scale=1e-3, size=(5, 3))
    got = kinematics.penetration(u, floors, weights, gap, ground)
    cf, cw = kinematics.kernel_terms(floors, weights)
    for i in range(u.shape[0]):
        for c in range(gap.size):
            expected = kinematics.combo.py_func(u[i], 0, cf, cw, c) + ground[i, c] - gap[c]
            assert got[i, c] == expected


def test_layout_offsets():
    lay = state_layout(5, 2, 3)
    assert (lay.velocity, lay.impulse, lay.work, lay.internal) == (5, 10, 12, 14)
    assert (lay.input_energy, lay.damping_energy, lay.hysteretic, lay.storey_work) == (16, 17, 18, 21)
    assert (lay.ground_work, lay.size) == (24, 25)
