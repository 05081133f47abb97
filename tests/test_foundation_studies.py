"""The studies on founded buildings: compare, sweep, IDA (with and without contacts) and risk.

Each study runs its scenarios through the same model description as `pounding run`, so a study's result for
one scenario must be that of `simulate` on the model the scenario describes: with the foundation's sway and
rocking in the floors' motion (relative to the free field) and the deformations as the storeys' drifts.  A
study that dropped or rebuilt the foundation (a building taken out of the model alone, a sweep's edited
document, a scaled record) would differ from it by the foundation's whole effect, orders above these bounds.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import pounding
from pounding.cli import main
from pounding.model.model import load_model
from test_foundation import SOFT_A, SOFT_B, pair

#: Study and direct run integrate the same equations with the same settings (rtol 1e-10, the same record
#: samples): they agree to the solver's round-off, measured < 1e-12 relative; 1e-9 leaves room for the order of
#: floating-point sums in a study's scaled records.
SAME_RUN = 1e-9
HERTZ = "hertz-damp, kh: 2.0e10, restitution: 0.6, xi: ye"


def founded(tmp_path, *, law: str = HERTZ, duration: float = 2.0):
    """The founded pair of tests/test_foundation.py (soft foundations under both buildings) and its file."""
    model = pair(tmp_path, SOFT_A, SOFT_B, law=law, duration=duration)
    return model, tmp_path / "m.yaml"


def test_the_foundation_moves_the_founded_pair(tmp_path):
    """The premise of the tests below: the foundation changes the response by far more than their bounds."""
    model, _ = founded(tmp_path)
    ds = pounding.simulate(model)
    assert int(ds.impact_count.sum()) > 0
    assert float(ds.peak_base_sway.max()) > 1e-4 and float(ds.peak_base_rocking.max()) > 1e-6


def test_compare_of_xi_formulas_on_a_founded_pair_is_each_formulas_run(tmp_path, studies_in_process):
    model, path = founded(tmp_path)
    out = tmp_path / "cmp.nc"
    assert main(["compare", str(path), "--xi", "ye,lankarani-nikravesh", "--workers", "1", "--no-progress",
                 "-o", str(out)]) == 0
    with xr.open_dataset(out) as ds:
        assert (ds.status == "ok").all()
        for xi in ("ye", "lankarani-nikravesh"):
            direct = pounding.simulate(model.with_xi(xi))
            got = ds.peak_drift_ratio.sel(xi=xi).values.reshape(-1)
            np.testing.assert_allclose(got, direct.peak_drift_ratio.values, rtol=SAME_RUN, err_msg=xi)


def test_a_sweep_over_the_sway_stiffness_runs_each_founded_model(tmp_path, studies_in_process):
    model, path = founded(tmp_path)
    sweep = tmp_path / "s.yaml"
    stiffness = [1.5e9, 6.0e9]
    sweep.write_text(f"name: sway\nmodel: m.yaml\naxes:\n  buildings[A].foundation.sway.stiffness: {stiffness}\n")
    out = tmp_path / "s.nc"
    assert main(["sweep", str(sweep), "--workers", "1", "--no-progress", "-o", str(out)]) == 0
    with xr.open_dataset(out) as ds:
        peaks = ds.peak_drift_ratio.values.reshape(len(stiffness), -1)
    for row, k in zip(peaks, stiffness):
        text = path.read_text().replace("sway: {stiffness: 1.5e9", f"sway: {{stiffness: {k:.1e}", 1)
        edited = tmp_path / f"k{k:.0e}.yaml"
        edited.write_text(text)
        direct = pounding.simulate(load_model(edited))
        np.testing.assert_allclose(row, direct.peak_drift_ratio.values, rtol=SAME_RUN, err_msg=f"{k}")
    assert not np.allclose(peaks[0], peaks[1], rtol=1e-3)   # the axis does change the response


def test_ida_of_a_founded_pair_is_the_scaled_runs_with_and_without_contacts(tmp_path, studies_in_process):
    """Each stripe is the model run at that scale; without contacts each founded building runs alone, which
    must be the founded pair's run with its contacts held open."""
    model, path = founded(tmp_path)
    out = tmp_path / "ida.nc"
    assert main(["ida", str(path), "--levels", "0.5,1.0", "--im", "pga", "--without-contacts", "--workers", "1",
                 "--no-progress", "-o", str(out)]) == 0
    with xr.open_dataset(out) as ds:
        for v, variant in enumerate(ds.variant.values):
            for j in range(ds.level.size):
                factor = float(ds.scale_factor.values[0, j])
                scaled = model.with_ground_motion(scale=factor)
                if variant == "without_contacts":
                    scaled = scaled.with_contacts_open()
                direct = pounding.simulate(scaled)
                np.testing.assert_allclose(ds.peak_drift_ratio.values[v, 0, j], direct.peak_drift_ratio.values,
                                           rtol=SAME_RUN, err_msg=f"{variant} level {j}")


def test_risk_separations_of_a_founded_pair_include_base_sway_and_rocking(tmp_path, in_process_client):
    """The separation each stripe's run needs is the peak approach of the floors' motion relative to the free
    field (base sway and rocking included): `required_separations` of the founded model's own run."""
    from pounding.studies.gap import required_separations
    from pounding.studies.risk import build_risk_plan, read_hazard, risk_study

    model, path = founded(tmp_path)
    plan = build_risk_plan(path, read_hazard("example"), im="pga", stripes=2)
    ds = risk_study(plan, tmp_path / "risk.nc", client=in_process_client, progress=False)
    for j in range(ds.level.size):
        scaled = model.with_ground_motion(scale=plan.ida.factor(0, float(ds.level.values[j]) / 9.80665))
        expected = required_separations(scaled, pounding.simulate(scaled.with_contacts_open()))["required"]
        np.testing.assert_allclose(ds.required_separation.values[0, j], expected, rtol=SAME_RUN)
