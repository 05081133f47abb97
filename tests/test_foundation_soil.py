"""A building's foundation given by the soil and the footing: the springs used, the run, the archive, errors.

The springs are checked against the impedance module's own functions called here at a frequency found
independently (the root of ω = 2π/T̃(ω) by bracketing, from a fixed-base mode computed with scipy), and
the run against the same model written with those springs given explicitly.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.linalg
from scipy.optimize import brentq

import pounding
from pounding.errors import ModelError
from pounding.model.foundation_impedance import Footing, Soil, equivalent_oscillator, impedances, \
    veletsos_meek_period
from pounding.results.summary import run_summary
from pounding.simulation import rerun

MODEL = """\
name: on_soil
buildings:
  - name: A
    storeys: {{count: 4, mass: 2.0e5, stiffness: 2.0e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 3]}}
    foundation:
      mass: 8.0e5
      rotary_inertia: 4.0e7
{springs}  - name: B
    storeys: {{count: 3, mass: 1.5e5, stiffness: 3.5e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 2]}}
contacts:
  - {{between: [A, B], levels: matching, gap: 0.004, law: linear, k: 2.0e9}}
ground_motion: {{record: sine.txt, units: g, dt: 0.01, duration: 1.5}}
solver: {{rtol: 1.0e-8, atol: 1.0e-11, atol_velocity: 1.0e-10, output_dt: 0.01}}
"""

SOIL = """      soil: {shear_wave_velocity: 150, poisson: 0.33, density: 1900}
      footing: {length: 16, width: 12, embedment: 1.5}
"""

SPRINGS = """      sway: {{stiffness: {kx!r}, damping: {cx!r}}}
      rocking: {{stiffness: {kt!r}, damping: {ct!r}}}
"""


def load(tmp_path, springs: str, name: str = "m.yaml"):
    t = np.arange(0.0, 1.5 + 1e-9, 0.01)
    ag = 3.0 * np.sin(2 * np.pi * 1.6 * t) * np.minimum(1.0, t / 0.5)
    np.savetxt(tmp_path / "sine.txt", ag / 9.80665, header="units: g; dt = 0.01 s", comments="# ")
    path = tmp_path / name
    path.write_text(MODEL.format(springs=springs))
    return pounding.load_model(path)


def flexible_frequency(soil: Soil, footing: Footing) -> float:
    """ω̃ of building A on the footing: the root of ω − 2π/T̃(ω), T̃ Veletsos & Meek's period with the
    springs at ω, from A's first fixed-base mode (scipy's symmetric eigensolver on the shear building)."""
    n, m, k, h = 4, 2.0e5, 2.0e8, 3.2
    stiffness = np.diag(np.r_[[2 * k] * (n - 1), k]) - np.diag([k] * (n - 1), 1) - np.diag([k] * (n - 1), -1)
    omega2, phi = scipy.linalg.eigh(stiffness, m * np.eye(n))
    oscillator = equivalent_oscillator([m] * n, phi[:, 0], h * np.arange(1, n + 1), math.sqrt(omega2[0]))

    def residual(omega: float) -> float:
        sway, rocking = impedances(soil, footing, omega).along("x")
        period = veletsos_meek_period(oscillator.period, oscillator.stiffness, oscillator.height, sway.stiffness,
                                      rocking.stiffness)
        return omega - 2 * math.pi / period

    # The foundation only lengthens the period: the root lies below the fixed-base frequency.
    return brentq(residual, 0.2 * math.sqrt(omega2[0]), math.sqrt(omega2[0]), xtol=1e-14, rtol=1e-14)


def test_the_springs_are_the_footings_impedances_at_the_flexible_base_frequency(tmp_path):
    foundation = load(tmp_path, SOIL).buildings[0].foundation
    soil, footing = Soil(150.0, 0.33, 1900.0), Footing(16.0, 12.0, 1.5)
    omega = flexible_frequency(soil, footing)
    # The model's fixed point stops when two iterates agree within 1e-10; the bracketing root is to 1e-14.
    assert foundation.frequency == pytest.approx(omega, rel=1e-9)
    # At the frequency it reports, the springs are exactly the module's (the same call, bit for bit).
    sway, rocking = impedances(soil, footing, foundation.frequency).along("x")
    assert (foundation.sway_stiffness, foundation.sway_damping, foundation.rocking_stiffness,
            foundation.rocking_damping) == (sway.stiffness, sway.damping, rocking.stiffness, rocking.damping)
    # Along x: the footing's 16 m side, so rocking about y (the stiffer rocking, Table 2-2a's K_yy).
    assert rocking.stiffness > impedances(soil, footing, omega).rocking_x.stiffness
    # The frequency matters: the rocking spring softens with it (α_yy < 1 above a0 = 0).
    assert foundation.rocking_stiffness < impedances(soil, footing, 0.0).rocking_y.stiffness


def test_a_model_on_soil_runs_as_the_model_with_those_springs_given(tmp_path):
    on_soil = load(tmp_path, SOIL)
    f = on_soil.buildings[0].foundation
    given = load(tmp_path, SPRINGS.format(kx=f.sway_stiffness, cx=f.sway_damping, kt=f.rocking_stiffness,
                                          ct=f.rocking_damping), "given.yaml")
    a, b = pounding.simulate(on_soil), pounding.simulate(given)
    assert int(a.impact_count.sum()) > 0
    for name in ("peak_displacement", "peak_storey_drift", "peak_contact_force", "peak_base_sway",
                 "peak_base_rocking", "impact_count"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    # The archive records the springs and the frequency; the summary prints them; the other model has none.
    springs = json.loads(a.attrs["foundations"])["A"]["springs"]
    assert springs["rocking_stiffness"] == f.rocking_stiffness and springs["frequency"] == f.frequency
    text = run_summary(a)
    assert f"springs from the soil and footing at {f.frequency:.4g} rad/s" in text
    assert f"K_x {f.sway_stiffness:.4g} N/m" in text
    assert "from the soil and footing" not in run_summary(b)
    # rerun rebuilds the model (soil and footing) from the archive and gives the same run.
    path = tmp_path / "a.nc"
    a.to_netcdf(path)
    again = rerun(path)
    assert again.attrs["foundations"] == a.attrs["foundations"]
    np.testing.assert_array_equal(again.displacement.values, a.displacement.values)


@pytest.mark.parametrize("edit, message", [
    (("      footing: {length: 16, width: 12, embedment: 1.5}\n", "      sway: {stiffness: 1.0e9, damping: 0}\n"
      "      rocking: {stiffness: 1.0e11, damping: 0}\n      footing: {length: 16, width: 12, embedment: 1.5}\n"),
     "foundation of building A gives springs and soil together"),
    ((SOIL, ""), "foundation of building A gives neither springs nor soil"),
    (("      footing: {length: 16, width: 12, embedment: 1.5}\n", ""), "gives soil without footing"),
    (("shear_wave_velocity: 150", "shear_wave_velocity: 0"), "foundation.soil.shear_wave_velocity must be > 0"),
    (("poisson: 0.33", "poisson: 0.6"), "foundation.soil.poisson must be in [0, 0.5]"),
    (("poisson: 0.33", "poisson: -0.1"), "foundation.soil.poisson must be in [0, 0.5]"),
    (("density: 1900", "density: -1900"), "foundation.soil.density must be > 0"),
    (("length: 16", "length: 0"), "foundation.footing.length must be > 0"),
    (("width: 12", "width: -12"), "foundation.footing.width must be > 0"),
    (("embedment: 1.5", "embedment: -1"), "foundation.footing.embedment must be >= 0"),
    (("      mass: 8.0e5\n", ""), "foundation: missing required key 'mass'"),
])
def test_a_bad_soil_or_footing_is_one_located_line(tmp_path, edit, message):
    text = MODEL.format(springs=SOIL)
    assert edit[0] in text
    path = tmp_path / "bad.yaml"
    path.write_text(text.replace(edit[0], edit[1], 1))
    with pytest.raises(ModelError) as caught:
        pounding.load_model(path)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_the_readme_table_of_what_soil_changes_is_the_two_runs():
    """README's "What the site changes" table quotes the runs of models/pair.yaml and models/pair_on_soil.yaml
    under record 1a: each number is the runs', at the digits printed."""
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    rows = {}
    for line in (root / "README.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 3 and cells[0] in ("first periods A / B", "impacts", "peak contact force (A:5-B:5)",
                                            "largest peak storey drift ratio A / B"):
            rows[cells[0]] = [re.findall(r"[\d.]+", c) for c in cells[1:]]
    assert len(rows) == 4, rows
    for column, name in enumerate(("pair", "pair_on_soil")):
        model = pounding.load_model(root / "models" / f"{name}.yaml")
        ds = pounding.simulate(model)
        assert int(ds.impact_count.sum()) == int(rows["impacts"][column][0])
        force = float(ds.peak_contact_force.sel(contact="A:5-B:5")) / 1e6
        assert f"{force:.1f}" == rows["peak contact force (A:5-B:5)"][column][0]
        drifts = [f"{100 * float(ds.peak_drift_ratio.where(ds.storey_building == b, drop=True).max()):.3f}"
                  for b in ("A", "B")]
        assert drifts == rows["largest peak storey drift ratio A / B"][column]
        periods = [float((b.flexible_periods if b.foundation is not None else b.periods)[0]) for b in model.buildings]
        assert [f"{t:.3f}" for t in periods] == rows["first periods A / B"][column]
