"""IMK storeys in the building solver (issue 27 §1): located branch changes, energy audit, collapse.

The reference is tests/imk_reference.py: scipy solve_ivp with every place a
branch can change a terminal event, its storey shears from the drift-driven
material (pounding.studies.imk, itself equal to OpenSees' IMK materials to
rounding, tests/test_imk.py).  The solver locates the same branch changes as
events of its own (pounding.solver.imk); both integrate to ~1e-9, so their
peak drifts agree within 1e-6.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import pounding
from imk_reference import imk_reference_run
from pounding.simulation import record_for

DETERIORATION = "{lambda_s: 4.0, lambda_c: 4.0, lambda_a: 4.0, lambda_k: 4.0}"
BACKBONE = ("yield_drift_ratio: 0.004, capping_strength_ratio: 1.15, plastic_drift_ratio: 0.01, "
            "post_capping_drift_ratio: 0.06, residual_strength_ratio: 0.3, ultimate_drift_ratio: ULTIMATE")
VARIANTS = {
    "imk-bilinear": "{lambda_s: 4.0, lambda_c: 4.0, lambda_k: 4.0}",
    "imk-peak-oriented": DETERIORATION,
    "imk-pinching": DETERIORATION + ", pinching: {kappa_f: 0.4, kappa_d: 0.3}",
}


def building(tmp_path, name: str, *, ultimate: float = 0.2, amplitude: float = 4.0, duration: float = 6.0,
             p_delta: bool = False, ramp: float = 3.0):
    """Two storeys (the first the weaker), 1 Hz sine growing over *ramp* s (amplitude in m/s²): the first storey
    caps and reaches its residual."""
    t = np.arange(0.0, duration + 1e-9, 0.01)
    ag = amplitude * np.sin(2 * np.pi * 1.0 * t) * np.minimum(1.0, t / ramp)
    np.savetxt(tmp_path / "sine.txt", ag / 9.80665, header="units: g; dt = 0.01 s", comments="# ")
    backbone = BACKBONE.replace("ULTIMATE", str(ultimate))
    text = f"""\
name: imk_building
buildings:
  - name: A
    storeys:
      - {{mass: 1.0e5, stiffness: 4.0e7, height: 3.0,
          hysteresis: {{model: {name}, {backbone}, deterioration: {VARIANTS[name].split(", pinching")[0]}
                       {", pinching: {kappa_f: 0.4, kappa_d: 0.3}" if name == "imk-pinching" else ""}}}}}
      - {{mass: 1.0e5, stiffness: 4.0e7, height: 3.0,
          hysteresis: {{model: {name}, yield_force: 4.0e5, capping_strength_ratio: 1.15, plastic_drift_ratio: 0.01,
                       post_capping_drift_ratio: 0.06, residual_strength_ratio: 0.3, ultimate_drift_ratio: {ultimate},
                       deterioration: {VARIANTS[name].split(", pinching")[0]}
                       {", pinching: {kappa_f: 0.4, kappa_d: 0.3}" if name == "imk-pinching" else ""}}}}}
    damping: {{ratio: 0.02, modes: [1, 2]}}
    p_delta: {str(p_delta).lower()}
ground_motion: {{record: sine.txt, units: g, dt: 0.01}}
solver: {{rtol: 1.0e-10, atol: 1.0e-13, atol_velocity: 1.0e-12, output_dt: 0.01}}
"""
    path = tmp_path / "imk.yaml"
    path.write_text(text)
    return pounding.load_model(path)


#: Each variant's shortest sine that still takes the first storey through capping into its residual branch
#: (asserted below): amplitude m/s², duration s, ramp s.  imk-bilinear's fast growth (1.5 s) takes the first storey
#: into its residual branch in both directions, the second time where the post-capping line meets the residual
#: floor only to round-off (the solver once stayed on the falling line there: peak drift ratio 0.1375 against
#: the reference's 0.1100).
MATCH = {"imk-bilinear": (5.0, 3.0, 1.5), "imk-peak-oriented": (4.0, 3.0, 1.5), "imk-pinching": (4.0, 3.0, 1.5)}


@pytest.mark.parametrize("name", list(VARIANTS))
def test_imk_building_matches_an_independent_scipy_integration(tmp_path, name):
    amplitude, duration, ramp = MATCH[name]
    model = building(tmp_path, name, amplitude=amplitude, duration=duration, ramp=ramp)
    ds = pounding.simulate(model)
    record = record_for(model)
    ref = imk_reference_run(model, record.acceleration, record.time_step, duration)
    # The first storey goes through capping into its residual branch (ImkMaterial's branches 6 and 7;
    # imk-bilinear has no branch numbers: its residual flag counts as 7, past 3x its capping drift).
    if name == "imk-bilinear":
        assert 7 in ref["branches"][0] and ref["peak_drift"][0] > 3 * 0.042
    else:
        assert {6, 7} <= ref["branches"][0], ref["branches"]
    assert ds.attrs["status"] == "completed" and ref["collapse"] is None
    # Measured: ≤ 4e-9 relative (both integrate to ~1e-10).
    np.testing.assert_allclose(ds.peak_storey_drift.values, ref["peak_drift"], rtol=1e-6)
    np.testing.assert_allclose(ds.residual_drift_ratio.values * 3.0, ref["final_drift"], rtol=1e-6, atol=1e-9)
    assert ds.attrs["energy_status"] == "ok"
    assert float(ds.storey_hysteretic_energy[0]) > 0.0


@pytest.mark.parametrize("name, ultimate, p_delta", [("imk-peak-oriented", 0.08, False), ("imk-bilinear", 0.06, True)])
def test_reaching_the_ultimate_drift_collapses_the_building_there(tmp_path, name, ultimate, p_delta):
    # At 5 m/s² both collapse by 3.6 s (4 m/s² took imk-bilinear to 5.98 s): 4 s holds the collapse, asserted.
    model = building(tmp_path, name, ultimate=ultimate, p_delta=p_delta, amplitude=5.0, duration=4.0)
    ds = pounding.simulate(model)
    record = record_for(model)
    ref = imk_reference_run(model, record.acceleration, record.time_step, 4.0)
    assert ds.attrs["status"] == "collapsed" and ds.attrs["collapse_storey"] == "A:1"
    assert ref["collapse"] is not None and ref["collapse"][0] == 0
    # Located: the run ends where the first storey's drift reaches θ_u·h, at the reference's instant.
    assert float(ds.attrs["collapse_time"]) == pytest.approx(ref["collapse"][1], rel=1e-6)
    assert float(ds.peak_storey_drift[0]) == pytest.approx(ultimate * 3.0, rel=1e-9)
    np.testing.assert_allclose(ds.peak_storey_drift.values, ref["peak_drift"], rtol=1e-6)


@pytest.mark.parametrize("name", list(VARIANTS))
def test_opensees_export_of_imk_storeys_agrees_on_peaks(tmp_path, name):
    # The exported script (IMKBilin / IMKPeakOriented / IMKPinching, Newmark at a fixed step) over a 4 s window
    # through capping: peak drift ratios within 1 % (measured 3e-4 at dt = 1e-3 s, 1.5e-5 at 2.5e-4 s: second
    # order in OpenSees' step).
    pytest.importorskip("openseespy")
    from pounding.export.opensees import run_opensees

    model = building(tmp_path, name)
    ds = pounding.simulate(model, duration=4.0)
    peaks = run_opensees(model, dt=1e-3, duration=4.0)
    assert peaks["converged"]
    np.testing.assert_allclose(peaks["peak_drift_ratio"], ds.peak_drift_ratio.values, rtol=0.01)
    assert float(ds.peak_storey_drift[0]) > 3 * 0.012  # past the capping drift (yield 0.012 m + θ_p h 0.03 m)


def test_opensees_export_of_the_shipped_collapse_pair_agrees_on_peaks():
    # models/pair_collapse.yaml (IMK peak-oriented A beside IMK pinching B, P-Delta, Hertz-damp contacts) at 1.45x
    # record 1a over a 6 s window: B:1 past capping on its post-capping branch (peak 0.0216, its ultimate drift
    # ratio 0.024; at 1.5x it reaches it within 6 s), A:1 yielded, 11 impacts, before any collapse. The exported
    # script (IMKPeakOriented / IMKPinching, Newmark at dt 2.5e-4) against our solver at rtol 1e-9: measured
    # 3.8e-4 on peak drift ratios, 3.9e-5 on peak floor displacements and 1.4e-4 of the largest peak contact
    # force (5.0e-3, 3.7e-4, 9.5e-4 at dt 1e-3: the difference is OpenSees' step); the issue's bound is 1 %.
    # The check tightens the model's own rtol 1e-6: on the post-capping branch (negative stiffness, steeper with
    # P-Delta) the response amplifies small differences (without contacts B:1's peak drift moves by 0.35 % and
    # B:5's by 3.3 % between rtol 1e-6 and 1e-9; docs/hysteresis.md).
    pytest.importorskip("openseespy")
    from pathlib import Path

    from pounding.export.opensees import run_opensees
    from pounding.model.model import model_from_text

    text = (Path(__file__).resolve().parents[1] / "models" / "pair_collapse.yaml").read_text()
    for old, new in (("  scale: 1.0\n", "  scale: 1.45\n"), ("rtol: 1.0e-6", "rtol: 1.0e-9"),
                     ("atol: 1.0e-8", "atol: 1.0e-11"), ("atol_velocity: 1.0e-7", "atol_velocity: 1.0e-10")):
        assert old in text
        text = text.replace(old, new)
    model = model_from_text(text)
    ds = pounding.simulate(model, duration=6.0)
    assert ds.attrs["status"] == "completed"
    drift = ds.peak_drift_ratio.values
    assert drift[8] > 0.0022 + 0.016 and drift[0] > 6.7e6 / 3.5e8 / 3.2   # B:1 past capping, A:1 yielded
    peaks = run_opensees(model, dt=2.5e-4, duration=6.0)
    assert peaks["converged"]
    assert peaks["impact_count"] == [int(n) for n in ds.impact_count.values] and sum(peaks["impact_count"]) > 0
    np.testing.assert_allclose(peaks["peak_drift_ratio"], drift, rtol=0.01)
    np.testing.assert_allclose(peaks["peak_displacement"], ds.peak_displacement.values, rtol=0.01)
    force = ds.peak_contact_force.values
    np.testing.assert_allclose(peaks["peak_contact_force"], force, rtol=0, atol=0.01 * force.max())


def _on_the_backbone_state() -> np.ndarray:
    """An IMKBilin state on its backbone, loading towards +: hardening line 4e5 → 4.6e5 N over 0.01 → 0.05 m
    (1.5e6 N/m), residual floor 1.2e5 N; the hardening line rises from the floor at 0.05 − 3.4e5/1.5e6 m."""
    from pounding.solver import imk

    st = np.zeros(imk.N_STATE)
    for offset in (0, imk.SIDE):
        for index, value in ((imk.FY, 4.0e5), (imk.UY, 0.01), (imk.KP, 1.5e6), (imk.KPC, -2.0e6), (imk.UCAP, 0.05),
                             (imk.FCAP, 4.6e5), (imk.FRES, 1.2e5), (imk.URES, 0.22), (imk.UU, 0.3)):
            st[offset + index] = value
    st[imk.KE] = st[imk.KUN] = st[imk.KRE] = 4.0e7
    st[imk.DIR], st[imk.ONBB], st[imk.VARIANT] = 1.0, 1.0, imk.V_BILINEAR
    return st


@pytest.mark.parametrize("relative, rising", [(-1e-14, True), (1e-14, True), (-1e-9, False)])
def test_a_branch_decided_at_the_rise_from_the_residual_floor_is_the_rising_line(relative, rising):
    """Reloading onto the backbone where the hardening line rises from the residual floor, the limit is
    that intersection, so the line there is F_r only to round-off: a hair (1e-14) below F_r is the rising
    line, not the floor (deciding by ``line > F_r`` sent a storey onto the floor from 3e-15 m of round-off
    and lost its collapse); 1e-9 below, far beyond round-off, is the floor."""
    from pounding.solver import imk

    st = _on_the_backbone_state()
    at = 0.05 + (1.2e5 * (1.0 + relative) - 4.6e5) / 1.5e6   # the hardening line at F_r·(1 + relative)
    row = np.zeros(6)
    imk.set_row(st, row, at, at)
    assert row[imk.P_SLOPE] == (1.5e6 if rising else 0.0)


@pytest.mark.parametrize("relative", [k * 1e-15 for k in range(-20, 21, 2)] + [-1e-6, 1e-6])
def test_a_reloading_line_through_the_rise_from_the_residual_floor_stops_there(relative):
    """IMKBilin places the hardening line through the point where the reloading line reaches F_r, so the
    reloading line, the floor and the hardening line meet in one point, to round-off.  The reloading
    line's limit is that point whichever side of F_r round-off puts the hardening line (a 1e-14 shift of
    the record once rejected both candidates: the storey reloaded with no limit past its strength, to the
    ultimate drift and a collapse the reference run does not have); beyond round-off (1e-6) the hardening
    line's own intersection (above F_r there) or the floor's (below)."""
    from pounding.solver import imk

    st = _on_the_backbone_state()
    u0, fres, kp, fcap, kun = -0.2, 1.2e5, 1.5e6, 4.6e5, 2.0e7
    floor = u0 + fres / kun   # where the reloading line from (u0, 0) reaches F_r
    st[imk.ONBB], st[imk.YIELDED], st[imk.RESID], st[imk.KUN] = 0.0, 1.0, 1.0, kun
    st[imk.UREF], st[imk.FREF] = u0, 0.0
    # the hardening line at the floor point: F_r (1 + relative)
    st[imk.UCAP] = floor - (fres * (1.0 + relative) - fcap) / kp
    st[imk.URES] = st[imk.UCAP] + (fres - fcap) / st[imk.KPC]
    row = np.zeros(6)
    imk.set_row(st, row, u0, u0)
    # the hardening line's own crossing of the reloading line, (f_cap − k_p u_cap + k_un u0)/(k_un − k_p)
    crossing = (fcap - kp * st[imk.UCAP] + kun * u0) / (kun - kp)
    expected = crossing if relative > 0 else floor   # above F_r at the floor point: the hardening line is the backbone there
    # the two candidates differ by round-off at the triple point (1e-15 m seen); 1e-12 m is far below any drift
    assert row[imk.P_UPPER] == pytest.approx(expected, abs=1e-12), (row[imk.P_UPPER], expected)


def test_the_reloading_limit_at_the_triple_point_a_record_shift_produced():
    """The state a 1e-14 relative shift of the record gave the first storey of the imk-bilinear building below
    (its force back at zero after the residual branch, the backbone deteriorated ahead): the hardening line's
    crossing came out 1.2e-10 N under F_r and the floor's point 5.8e-11 N over it, so exact tests rejected
    both and the reloading line had no limit short of the ultimate drift (0.6 m)."""
    from pounding.solver import imk

    st = _on_the_backbone_state()
    for offset in (0, imk.SIDE):
        for index, value in ((imk.FCAP, 544387.9705579279), (imk.UCAP, 0.0420743621999021),
                             (imk.KP, 1481695.3876804921), (imk.FRES, 144000.0), (imk.KPC, -3001509.4303544615),
                             (imk.UU, 0.6)):
            st[offset + index] = value
        st[offset + imk.URES] = st[offset + imk.UCAP] + (st[offset + imk.FRES] - st[offset + imk.FCAP]) / st[offset + imk.KPC]
    st[imk.ONBB], st[imk.YIELDED], st[imk.RESID], st[imk.KUN] = 0.0, 1.0, 1.0, 2.0e7
    st[imk.UREF], st[imk.FREF] = -0.23534850134340143, 0.0
    row = np.zeros(6)
    imk.set_row(st, row, st[imk.UREF], st[imk.UREF])
    # the floor's point u_ref + F_r/k_un, the hardening line's crossing within round-off of it
    assert row[imk.P_UPPER] == pytest.approx(-0.23534850134340143 + 144000.0 / 2.0e7, abs=1e-15)


@pytest.mark.parametrize("shift", [-1.35e-14, 1.0e-14, 1.35e-14])
def test_a_record_shifted_by_round_off_gives_the_same_run(tmp_path, shift):
    """The imk-bilinear building of the reference comparison under its record times (1 + shift): round-off
    of the input must not change a branch (1.35e-14 once collapsed it at 2.45 s, peak drift 0.6 m against
    the reference's 0.33 m)."""
    amplitude, duration, ramp = MATCH["imk-bilinear"]
    model = building(tmp_path, "imk-bilinear", amplitude=amplitude, duration=duration, ramp=ramp)
    record = record_for(model)
    shifted = dataclasses.replace(record, acceleration=record.acceleration * (1.0 + shift))
    base, ds = pounding.simulate(model, record), pounding.simulate(model, shifted)
    assert ds.attrs["status"] == base.attrs["status"] == "completed"
    # the same branches: the peaks move by the shift's round-off only (measured ≤ 2e-13); 1e-9 is far below a
    # changed branch (1e-2 and more)
    np.testing.assert_allclose(ds.peak_storey_drift.values, base.peak_storey_drift.values, rtol=1e-9)
