"""``pounding pushover`` (issue 27 §2): capacity curves of each building alone and FEMA P695's quantities."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

import pounding
from pounding.cli import main
from pounding.studies import cyclic
from pounding.studies.pushover import fema_p695_quantities, pushover, pushover_building
from pounding.units import STANDARD_GRAVITY

IMK = ("{model: imk-peak-oriented, yield_drift_ratio: 0.004, capping_strength_ratio: 1.15, plastic_drift_ratio: 0.01, "
       "post_capping_drift_ratio: 0.06, residual_strength_ratio: 0.3, ultimate_drift_ratio: 0.09, "
       "deterioration: {lambda_s: 4, lambda_c: 4, lambda_a: 4, lambda_k: 4}}")

MODEL = f"""\
name: pushover_pair
buildings:
  - name: A
    storeys:
      - {{mass: 1.0e5, stiffness: 4.0e7, height: 3.0, hysteresis: {IMK}}}
      - {{mass: 1.0e5, stiffness: 4.0e7, height: 3.0, hysteresis: {IMK.replace("yield_drift_ratio: 0.004", "yield_force: 5.0e5")}}}
    damping: {{ratio: 0.05, modes: [1, 2]}}
    p_delta: true
  - name: B
    storeys:
      count: 3
      mass: 1.0e5
      stiffness: 5.0e7
      height: 3.0
    damping: {{ratio: 0.05, modes: [1, 2]}}
contacts:
  - {{between: [A, B], levels: matching, gap: 0.02, law: hertz-damp, kh: 2.0e9, restitution: 0.5}}
ground_motion: {{record: fema-p695:farfield/1a}}
"""


@pytest.fixture()
def model_file(tmp_path):
    path = tmp_path / "pushover.yaml"
    path.write_text(MODEL)
    return path


def test_elastic_building_follows_its_stiffness(model_file):
    b = pounding.load_model(model_file).buildings[1]
    curve = pushover_building(b, "uniform", steps=50, drift_limit_ratio=0.01)
    share = np.array([1.0, 2.0 / 3.0, 1.0 / 3.0])
    np.testing.assert_allclose(curve["share"], share)
    # Roof displacement of an elastic chain: Σ V·S_i / k_i.
    np.testing.assert_allclose(curve["roof_displacement"], curve["base_shear"] * np.sum(share / 5.0e7), rtol=1e-12)
    assert curve["end"] == "drift limit" and curve["control_storey"] == 1


def test_softening_storey_controls_and_every_storey_is_in_equilibrium(model_file):
    model = pounding.load_model(model_file)
    b = model.buildings[0]
    curve = pushover_building(b, "first-mode", steps=300, drift_limit_ratio=0.1)
    assert curve["control_storey"] == 1 and curve["end"] == "zero strength"
    v = curve["base_shear"]
    # Each storey's own (drift-driven) shear, with P-Delta, carries its share of the base shear at every step.
    for i in range(2):
        shear = cyclic.storey_response(b.hysteresis[i], b.stiffness[i], b.height[i], curve["storey_drift"][i])
        resistance = shear + b.p_delta_stiffness[i] * curve["storey_drift"][i]
        np.testing.assert_allclose(resistance[:-1], (v * curve["share"][i])[:-1], atol=1e-6 * v.max())
    # After the peak the second storey unloads (its drift falls back) while the first softens.
    peak = int(np.argmax(v))
    assert curve["storey_drift"][1, -2] < curve["storey_drift"][1, peak]
    assert curve["storey_drift"][0, -2] > curve["storey_drift"][0, peak]


def test_fema_p695_quantities(model_file):
    model = pounding.load_model(model_file)
    ds = pushover(model, building="A", steps=300, design_cs=0.2)
    b = model.buildings[0]
    row = ds.sel(building="A")
    m, phi = b.mass, b.modes[1][:, 0]
    c0 = phi[-1] * np.sum(m * phi) / np.sum(m * phi ** 2)
    weight = STANDARD_GRAVITY * m.sum()
    t1 = float(b.periods[0])
    assert float(row.c0) == pytest.approx(c0, rel=1e-12)
    assert float(row.effective_yield_roof_displacement) == pytest.approx(
        c0 * float(row.v_max) / weight * STANDARD_GRAVITY / (4 * math.pi ** 2) * t1 ** 2, rel=1e-12)
    # δ_u: on the descending branch where the base shear is 0.8 V_max (linear between the steps).
    # (the roof can move back as the other storeys unload: δ_u is read between the two steps around 0.8 V_max).
    v, roof = row.base_shear.values, row.roof_displacement.values
    peak = int(np.nanargmax(v))
    j = peak + int(np.flatnonzero(v[peak:] <= 0.8 * float(row.v_max))[0])
    assert v[j - 1] > 0.8 * float(row.v_max) >= v[j]
    assert min(roof[j - 1], roof[j]) <= float(row.ultimate_roof_displacement) <= max(roof[j - 1], roof[j])
    assert float(row.ultimate_roof_displacement) > roof[peak]
    assert float(row.period_based_ductility) == pytest.approx(
        float(row.ultimate_roof_displacement / row.effective_yield_roof_displacement))
    assert float(row.overstrength) == pytest.approx(float(row.v_max) / (0.2 * weight))
    direct = fema_p695_quantities(b, pushover_building(b, steps=300), period=0.1)
    assert direct["period"] == t1  # max(T, T1)


def test_the_parser_offers_the_studys_patterns():
    from pounding.cli import pushover as cli_pushover
    from pounding.studies import pushover as study

    assert cli_pushover.PATTERNS == study.PATTERNS


def test_pushover_command_writes_table_archive_and_plot(model_file, tmp_path, capsys):
    out, plots = tmp_path / "po.nc", tmp_path / "plots"
    assert main(["pushover", str(model_file), "--pattern", "triangular", "-o", str(out), "--plot", str(plots)]) == 0
    text = capsys.readouterr().out
    assert "V_max kN" in text and "zero strength" in text
    with xr.open_dataset(out) as ds:
        assert ds.attrs["kind"] == "pushover" and list(ds.building.values) == ["A", "B"]
        assert ds.base_shear.attrs["units"] == "N" and ds.roof_displacement.attrs["units"] == "m"
        assert ds.storey_drift.dims == ("building", "storey", "step")
    assert (plots / "pushover.png").stat().st_size > 0
    assert main(["info", str(out)]) == 0 and "[pushover archive]" in capsys.readouterr().out
    assert main(["plot", str(out), "-o", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "pushover.png").exists()
    for argv, message in ((["--building", "C"], "no building 'C'"), (["--steps", "0"], "--steps must be at least 1"),
                          # one step once landed past the strength loss: V_max 0 N, exit 0
                          (["--steps", "1"], "--steps must be at least 10 (got 1)"),
                          # no bound once: a billion steps ran for hours
                          (["--steps", "1000000000"], "--steps must be at most 20000 (got 1000000000)"),
                          (["--design-cs", "-1"], "--design-cs must be a number > 0")):
        assert main(["pushover", str(model_file), *argv]) == 2
        err = capsys.readouterr().err.strip()
        assert message in err and "\n" not in err


def test_table_reads_pushover_and_hysteresis_archives(model_file, tmp_path, capsys):
    # `pounding table` (and its --csv) on the archives of `pounding pushover` and `pounding hysteresis`
    # (issue 27 §5): the per-building quantities, the curves and the storeys; the cyclic test's steps.
    import pandas as pd

    po, hy = tmp_path / "po.nc", tmp_path / "hy.nc"
    assert main(["pushover", str(model_file), "-o", str(po)]) == 0
    assert main(["hysteresis", str(model_file), "--storey", "A:1", "--protocol", "fema461", "--amplitude", "0.03",
                 "-o", str(hy)]) == 0
    capsys.readouterr()
    assert main(["table", str(po)]) == 0
    text = capsys.readouterr().out
    assert "[pushover archive]" in text and "buildings:" in text and "curves:" in text and "storeys:" in text
    assert "v_max [N]" in text and "period_based_ductility [-]" in text and "zero strength" in text
    assert main(["table", str(po), "--csv", str(tmp_path / "po.csv")]) == 0
    buildings = pd.read_csv(tmp_path / "po.csv")
    curves = pd.read_csv(tmp_path / "po.curves.csv")
    storeys = pd.read_csv(tmp_path / "po.storeys.csv")
    with xr.open_dataset(po) as ds:
        np.testing.assert_array_equal(buildings["v_max [N]"], ds.v_max.values)
        for i, name in enumerate(ds.building.values):
            taken = np.isfinite(ds.base_shear.values[i])
            np.testing.assert_array_equal(curves[curves.building == name]["base_shear [N]"], ds.base_shear.values[i][taken])
            # B has 3 storeys: its padded storeys 4..n are left out, as are the steps it did not take.
            rows = storeys[storeys.building == name]
            assert set(rows["storey"]) == set(range(1, (2 if name == "A" else 3) + 1))
        assert not curves.isna().any().any() and not storeys.isna().any().any()
    assert main(["table", str(hy)]) == 0
    text = capsys.readouterr().out
    assert "[hysteresis archive]" in text and "storey_drift [m]" in text and "storey_shear [N]" in text
    assert main(["table", str(hy), "--csv", str(tmp_path / "hy.csv")]) == 0
    steps = pd.read_csv(tmp_path / "hy.csv")
    with xr.open_dataset(hy) as ds:
        np.testing.assert_array_equal(steps["storey_shear [N]"], ds.storey_shear.values)
        np.testing.assert_array_equal(steps["step"], ds.step.values)
