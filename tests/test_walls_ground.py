"""Walls under wave passage: a wall moves with the ground of the building it faces (docs/physics.md §11).

A pair A–B on a lagged record (wave passage) with a fixed wall on A's left.
The wall contact's two ends share A's ground row, so it sees no differential
ground motion; the A–B contact sees the differential ground displacement.
Checks: the energy balance closes with the ground-work term; with zero lag the
run is bit-identical to the single-ground run (through the YAML and through the
solver's general several-ground path); and, independently of the solver's
ground bookkeeping, when only A is lagged and B is out of reach, A's response
equals a single-ground run under the record delayed by the lag — which holds
only if the wall moves with A's ground (with B's, the wall would shake 0.3 s
ahead of A's base).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import pounding
from pounding.simulation import assemble, record_for
from pounding.solver.assembly import GroundRows
from pounding.solver.integrator import integrate

DT = 0.01
DURATION = 3.0

MODEL = """\
name: wall_wave
buildings:
  - name: A
    storeys: {count: 2, mass: 1.0e5, stiffness: 4.0e7, height: 3.0}
    damping: {ratio: 0.05, modes: [1, 2]}
  - name: B
    storeys: [{mass: 8.0e4, stiffness: 9.0e7, height: 3.0}]
    damping: {modal: [0.05]}
contacts:
  - {between: [wall, A], levels: [2], gap: WALL_GAP, law: hertz-damp, kh: 2.0e9, restitution: 0.6, xi: ye}
  - {between: [A, B], levels: [[1, 1]], gap: PAIR_GAP, law: hertz-damp, kh: 2.0e9, restitution: 0.6, xi: ye}
GROUND
solver: {rtol: 1.0e-9, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}
"""


def _record(tmp_path: Path, name: str = "a.txt", delay_steps: int = 0) -> np.ndarray:
    """A cosine accelerogram (m/s², dt 0.01 s; ground displacement ~1 cm), optionally delayed by zeros."""
    t = np.arange(int(round(DURATION / DT)) + 1) * DT
    a = 3.0 * np.cos(2 * math.pi * 2.5 * t) + 1.5 * np.cos(2 * math.pi * 1.7 * t)
    a = np.concatenate([np.zeros(delay_steps), a])
    (tmp_path / name).write_text("# units: m/s2; dt = 0.01 s\n" + "\n".join(repr(float(v)) for v in a) + "\n")
    return a


def _model(tmp_path: Path, ground: str, *, wall_gap: float = 0.003, pair_gap: float = 0.004,
           name: str = "m.yaml"):
    text = (MODEL.replace("GROUND", ground).replace("WALL_GAP", repr(wall_gap))
            .replace("PAIR_GAP", repr(pair_gap)))
    (tmp_path / name).write_text(text)
    return pounding.load_model(tmp_path / name)


def _wave(a_position: float, b_position: float) -> str:
    return ("ground_motion: {record: a.txt, wave_passage: {apparent_velocity: 100.0, "
            f"position: {{A: {a_position}, B: {b_position}}}}}}}")


def test_wall_and_wave_passage_close_the_energy_balance(tmp_path):
    _record(tmp_path)
    ds = pounding.simulate(_model(tmp_path, _wave(0.0, 30.0)))   # B reached 0.3 s after A
    counts = ds.impact_count.values
    assert counts[0] > 0 and counts[1] > 0          # the wall and the pair both pound
    assert ds.attrs["energy_status"] == "ok" and ds.attrs["energy_closure_error"] < 1e-5
    # The differential ground motion does work on the A-B contact (the term is exercised).
    assert np.abs(ds.energy_ground_work.values).max() > 1e-4 * np.abs(ds.energy_input.values).max()
    # The wall moves with A's ground: its penetration is -u_A,2 - gap in A's own coordinates
    # (exactly: the ground difference of its two ends is 0 - 0).
    u_a2 = ds.displacement.sel(floor="A:2").values
    np.testing.assert_array_equal(ds.penetration.isel(contact=0).values, -u_a2 - 0.003)


def test_zero_lag_with_a_wall_is_bit_identical_to_the_single_ground_run(tmp_path):
    _record(tmp_path)
    single = pounding.simulate(_model(tmp_path, "ground_motion: {record: a.txt}"))
    zero_lag = pounding.simulate(_model(tmp_path, _wave(5.0, 5.0), name="z.yaml"))
    assert int(single.impact_count.sum()) > 0
    for name in ("displacement", "velocity", "contact_force", "penetration", "impact_time", "energy_input"):
        np.testing.assert_array_equal(zero_lag[name].values, single[name].values)


def test_the_several_ground_kernel_path_with_a_wall_and_identical_grounds_equals_the_one_ground_path(tmp_path):
    # Two identical rows (the general path: ground offsets, per-floor ground acceleration, the wall's
    # row taken from A) against one row: every offset is exactly 0, so the motion is bit-identical.
    _record(tmp_path)
    model = _model(tmp_path, "ground_motion: {record: a.txt}")
    ground = np.r_[record_for(model).acceleration, 0.0]
    settings = dict(rtol=1e-9, atol=1e-12, atol_velocity=1e-11, output_dt=0.01)
    one = integrate(assemble(model).system, ground, DT, DURATION, **settings)
    two_system = assemble(model, GroundRows((1, 0))).system     # A on row 1, B on row 0: the wall must take row 1
    assert two_system.contact_ground_left[0] == 1 and two_system.contact_ground_right[0] == 1
    two = integrate(two_system, np.vstack([ground, ground]), DT, DURATION, **settings)
    assert one.impact_time.size > 0
    np.testing.assert_array_equal(two.state, one.state)
    np.testing.assert_array_equal(two.impact_time, one.impact_time)


def test_the_wall_moves_with_the_ground_of_the_building_it_faces(tmp_path):
    # Only A lagged (0.3 s = 30 steps), B far away: A and its wall are then a single-ground system under
    # the delayed record.  Reference: the same model on one ground, the record delayed by 30 zero samples.
    _record(tmp_path)
    _record(tmp_path, "late.txt", delay_steps=30)
    lagged = pounding.simulate(_model(tmp_path, _wave(30.0, 0.0), pair_gap=10.0))
    reference = pounding.simulate(_model(tmp_path, "ground_motion: {record: late.txt}", pair_gap=10.0,
                                         name="r.yaml"), duration=float(lagged.time[-1]))
    assert float(lagged.ground_lag.sel(ground="A")) == 0.3 and int(lagged.impact_count[0]) > 0
    assert int(lagged.impact_count[0]) == int(reference.impact_count[0])
    u = lagged.displacement.sel(floor=["A:1", "A:2"]).values
    u_ref = reference.displacement.sel(floor=["A:1", "A:2"]).values
    # Both at rtol 1e-9 with different step sequences (B's states differ and share the error norm):
    # agreement to 1e-6 of the peak is far tighter than the change a wall on B's ground would make
    # (it would move 0.3 s out of phase with A's base, by up to ~1 cm against a 3 mm gap).
    np.testing.assert_allclose(u, u_ref, atol=1e-6 * np.abs(u_ref).max())
    np.testing.assert_allclose(lagged.impact_time.values[lagged.impact_contact.values == 0],
                               reference.impact_time.values[reference.impact_contact.values == 0], atol=1e-6)
