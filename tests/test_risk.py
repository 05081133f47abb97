"""``pounding risk``: the hazard curve reader, the risk integrals against their closed form, the study."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ndtri

from pounding.errors import PoundingError
from pounding.studies.risk.hazard import power_law, read_hazard
from pounding.studies.risk.integrals import (closed_form_rate, exceedance_rates, lognormal_rate, parse_target,
                                             probability_in, rate_for_probability, separation_for_rate)
from pounding.units import STANDARD_GRAVITY as G


# --------------------------------------------------------------------------- #
# The hazard file reader
# --------------------------------------------------------------------------- #

def _curve_file(tmp_path, text: str):
    path = tmp_path / "site.csv"
    path.write_text(text)
    return path


def test_reader_reads_header_comments_and_separators(tmp_path):
    path = _curve_file(tmp_path, "# a site\nSa_g rate\n0.1, 0.02\n0.5;0.002  # 475 years\n1.0\t4e-4\n")
    curve = read_hazard(path)
    assert np.allclose(curve.intensity / G, [0.1, 0.5, 1.0])
    assert np.allclose(curve.annual_rate, [0.02, 0.002, 4e-4])
    # log-log interpolation: halfway in ln x between two rows is the geometric mean of their rates
    assert curve.rate(math.sqrt(0.5 * 1.0) * G) == pytest.approx(math.sqrt(0.002 * 4e-4), rel=1e-12)
    assert curve.intensity_at(math.sqrt(0.002 * 4e-4)) == pytest.approx(math.sqrt(0.5) * G, rel=1e-12)


@pytest.mark.parametrize("text, words, line", [
    ("0.1 0.02\n0.5 0.03\n1.0 4e-4\n", "must decrease", 2),            # non-monotone rates
    ("0.1 0.02\n0.5 0.002\n0.4 4e-4\n", "intensities must increase", 3),
    ("0.1 0.02\n0.5 -0.002\n1.0 4e-4\n", "must be > 0", 2),            # negative rate
    ("-0.1 0.02\n0.5 0.002\n", "must be > 0", 1),                       # negative intensity
    ("10 0.02\n50 0.002\n490 4e-4\n", "above 5 g", 1),                  # cm/s2 (gal), not g
    ("0.1 0.02 7\n0.5 0.002\n", "two numbers", 1),
    ("0.1 0.02\n0.5 fast\n", "two numbers", 2),
])
def test_reader_errors_are_one_line_naming_the_row(tmp_path, text, words, line):
    path = _curve_file(tmp_path, text)
    with pytest.raises(PoundingError) as info:
        read_hazard(path)
    message = str(info.value)
    assert "\n" not in message and words in message
    assert message.startswith(f"{path}:{line}: ")


def test_reader_refuses_a_single_row_a_missing_file_and_a_bad_power_law(tmp_path):
    with pytest.raises(PoundingError, match="at least 2 rows"):
        read_hazard(_curve_file(tmp_path, "0.1 0.02\n"))
    with pytest.raises(PoundingError, match="no such file"):
        read_hazard(tmp_path / "nowhere.csv")
    for spec, words in (("power:4e-4", "power:k0,k"), ("power:0,3", "k0"), ("power:4e-4,-2", "k ")):
        with pytest.raises(PoundingError, match=words):
            read_hazard(spec)


def test_power_law_and_the_shipped_example():
    curve = read_hazard("power:4e-4,3")
    x = np.array([0.001, 0.3, 1.0, 7.0, 30.0])     # inside its table and beyond both ends
    assert np.allclose(curve.rate(x * G), 4e-4 * x ** -3.0, rtol=1e-12)
    example = read_hazard("example")
    assert np.all(np.diff(example.annual_rate) < 0) and example.intensity.size > 10


# --------------------------------------------------------------------------- #
# The integrals
# --------------------------------------------------------------------------- #

@pytest.mark.parametrize("theta_g, beta", [(0.5, 0.4), (1.2, 0.6), (0.05, 0.8), (2.0, 0.3)])
@pytest.mark.parametrize("k0, k", [(4e-4, 3.0), (1e-3, 2.2)])
def test_lognormal_rate_matches_cornell_closed_form(k0, k, theta_g, beta):
    """Numerical integration over a tabulated power law: within 1e-4 of k0 θ^-k exp(k²β²/2) (Cornell et al. 2002)."""
    numeric = lognormal_rate(power_law(k0, k), theta_g * G, beta)
    assert numeric == pytest.approx(closed_form_rate(k0, k, theta_g, beta), rel=1e-4)


def test_lognormal_rate_on_a_finely_tabulated_curve():
    """A power law tabulated at 60 points (each segment's own slope, read from a file-like table) gives the same."""
    from pounding.studies.risk.hazard import HazardCurve

    x = np.geomspace(0.005, 4.0, 60)
    curve = HazardCurve(x * G, 4e-4 * x ** -3.0, "table")
    assert lognormal_rate(curve, 0.8 * G, 0.5) == pytest.approx(closed_form_rate(4e-4, 3.0, 0.8, 0.5), rel=1e-4)


def _lognormal_demands(stripes_g, a, b, beta_d, z):
    """Demands D (m) at each stripe: median a x^b (x in g), lognormal with dispersion beta_d, standard normal z."""
    return a * stripes_g[:, None] ** b * np.exp(beta_d * z)


def test_empirical_route_against_closed_form_monte_carlo():
    """Demands lognormal given x (median a x^b, dispersion β_D): P(D > g | x) is a lognormal fragility in x with
    θ = (g/a)^(1/b), β = β_D/b, so λ(g) has Cornell's closed form.  40 stripes from 0.02 to 4 g, 2000 runs each.

    Tolerance 8 %: with 200 runs per stripe the relative error of λ(g) over 20 seeds has a standard deviation
    of 5-6.5 %, so with 2000 runs about 2 %; the linear interpolation of P between stripes 0.136 apart in ln x
    adds a bias of about 1 % (measured with stratified, noise-free samples: the test below).  3 sigma + bias.
    """
    stripes = np.geomspace(0.02, 4.0, 40)
    a, b, beta_d = 0.05, 1.0, 0.4
    demands = _lognormal_demands(stripes, a, b, beta_d, np.random.default_rng(7).standard_normal((40, 2000)))
    separations = np.array([0.02, 0.05, 0.1])
    rates = exceedance_rates(power_law(4e-4, 3.0), stripes * G, demands, separations)
    expected = [closed_form_rate(4e-4, 3.0, (g / a) ** (1 / b), beta_d / b) for g in separations]
    assert rates == pytest.approx(expected, rel=0.08)


def test_empirical_route_without_sampling_noise():
    """Stratified samples (the normal quantiles (i + ½)/n) leave only the interpolation between stripes: its
    error, of order Δ² with Δ = 0.136 the stripe spacing in ln x, measured 0.9-1.2 %; 2 % allowed.  With half
    the spacing the error must shrink (about 4x): the interpolation converges."""
    z = ndtri((np.arange(4000) + 0.5) / 4000)
    a, b, beta_d = 0.05, 1.2, 0.4
    separations = np.array([0.02, 0.05, 0.1])
    expected = np.array([closed_form_rate(4e-4, 3.0, (g / a) ** (1 / b), beta_d / b) for g in separations])
    errors = []
    for n in (40, 79):
        stripes = np.geomspace(0.02, 4.0, n)
        rates = exceedance_rates(power_law(4e-4, 3.0), stripes * G, _lognormal_demands(stripes, a, b, beta_d, z),
                                 separations)
        errors.append(np.abs(rates / expected - 1))
    assert np.all(errors[0] < 0.02)
    assert np.all(errors[1] < 0.5 * errors[0])


def test_separation_for_rate_is_where_the_rate_crosses_the_target():
    stripes = np.geomspace(0.05, 3.0, 12)
    z = ndtri((np.arange(400) + 0.5) / 400)
    demands = _lognormal_demands(stripes, 0.05, 1.0, 0.4, z)
    curve = power_law(4e-4, 3.0)
    target = rate_for_probability(0.02, 50.0)
    g = separation_for_rate(curve, stripes * G, demands, target)
    below, above = exceedance_rates(curve, stripes * G, demands, np.array([0.999 * g, g]))
    assert above <= target < below
    # unbounded demands (collapsed runs) pound at every separation: no finite separation meets a low target
    demands[-1, :] = np.inf
    assert separation_for_rate(curve, stripes * G, demands, 1e-6) == math.inf


def test_probability_and_target():
    assert probability_in(rate_for_probability(0.02, 50.0)) == pytest.approx(0.02, rel=1e-12)
    assert rate_for_probability(0.1, 50.0) == pytest.approx(1 / 474.56, rel=1e-4)   # the "475-year" event
    assert parse_target("2%/50y") == (0.02, 50.0)
    assert parse_target("0.1/50") == (0.1, 50.0)
    for bad in ("2%", "200%/50y", "2%/-5y", "x/50y"):
        with pytest.raises(PoundingError, match="--target"):
            parse_target(bad)


# --------------------------------------------------------------------------- #
# The study
# --------------------------------------------------------------------------- #

@pytest.fixture(scope="module")
def risk_run(in_process_client, tmp_path_factory):
    """models/pair.yaml, its own record, 3 stripes of the example curve, 6 s: 6 runs."""
    from pounding.data import data_path
    from pounding.studies.risk import build_risk_plan, read_hazard, risk_study

    plan = build_risk_plan(data_path("models", "pair.yaml"), read_hazard("example"), im="sa:1.0", stripes=3,
                           duration=6.0)
    out = tmp_path_factory.mktemp("risk") / "risk.nc"
    return plan, risk_study(plan, out, client=in_process_client, progress=False), out


def test_study_separations_are_the_gap_study_of_each_run(risk_run):
    """Each run without contacts' required separation is what `required_separations` gives for that run's
    full history, and the separation meeting the target lies where the archived curve crosses it.

    The pair is linear with its contacts held open, so the study takes each stripe's separations from one
    run of the record at factor 1 (tolerances 10 times tighter) times the factor (superposition,
    ``pounding.studies.ida.superposition``): that exactly, and closer to a converged run than the stripe's
    own run at the model's tolerances."""
    from pounding.model.model import load_model
    from pounding.simulation import simulate
    from pounding.data import data_path
    from pounding.studies.gap import required_separations
    from pounding.studies.ida.superposition import tightened

    plan, ds, _ = risk_run
    level = float(ds.level.values[1]) / G
    factor = plan.ida.factor(0, level)
    base = load_model(data_path("models", "pair.yaml")).with_ground_motion(duration=6.0).with_contacts_open()
    unit = tightened(base.with_ground_motion(scale=1.0))
    expected = required_separations(unit, simulate(unit))["required"] * factor
    assert np.allclose(ds.required_separation.values[0, 1], expected, rtol=1e-15, atol=0)   # one product
    model = base.with_ground_motion(scale=factor)
    direct = required_separations(model, simulate(model))["required"]
    converged_model = model.with_solver(rtol=1e-11, atol=1e-13, atol_velocity=1e-12)
    converged = required_separations(converged_model, simulate(converged_model))["required"]
    assert np.max(np.abs(ds.required_separation.values[0, 1] - converged)) <= np.max(np.abs(direct - converged))
    # demands grow with intensity (elastic model, one record): each stripe needs more than the one below
    assert np.all(np.diff(ds.required_separation.values[0], axis=0) > 0)
    p = ds.attrs["target_probability"]
    for c in range(ds.contact.size):
        g = float(ds.target_separation.values[c])
        assert g in ds.required_separation.values[0, :, c]
        below = ds.separation.values < g
        assert np.all(ds.pounding_probability.values[c][below] > p)
        assert np.all(ds.pounding_probability.values[c][~below] <= p)


def test_separations_of_a_yielding_pair_come_from_each_stripes_own_run(in_process_client, tmp_path):
    """With a yielding building the pair is not linear: each stripe's separations are `required_separations`
    of that stripe's own run, bit for bit (no superposition)."""
    import yaml

    from pounding.data import data_path
    from pounding.model.model import load_model
    from pounding.simulation import simulate
    from pounding.studies.gap import required_separations
    from pounding.studies.risk import build_risk_plan, risk_study

    document = yaml.safe_load(data_path("models", "pair.yaml").read_text())
    document["ground_motion"]["record"] = str(document["ground_motion"]["record"])
    for storey in document["buildings"][1]["storeys"]:
        storey["hysteresis"] = {"model": "bilinear", "yield_drift_ratio": 0.002, "post_yield_ratio": 0.03}
    path = tmp_path / "yielding_pair.yaml"
    path.write_text(yaml.safe_dump(document, sort_keys=False))
    plan = build_risk_plan(path, read_hazard("example"), im="sa:1.0", stripes=2, duration=5.0)
    ds = risk_study(plan, tmp_path / "risk.nc", client=in_process_client, progress=False)
    level = float(ds.level.values[1]) / G
    model = load_model(path).with_ground_motion(duration=5.0, scale=plan.ida.factor(0, level)).with_contacts_open()
    expected = required_separations(model, simulate(model))["required"]
    np.testing.assert_array_equal(ds.required_separation.values[0, 1], expected)


def test_study_archive_has_units_and_names_and_the_cli_prints_it(risk_run, tmp_path):
    import xarray as xr

    from pounding.studies.risk import risk_table

    _, ds, out = risk_run
    with xr.open_dataset(out) as stored:
        for name, var in stored.data_vars.items():
            assert "long_name" in var.attrs, name
        for name in ("pounding_rate", "target_separation", "collapse_rate", "hazard_rate", "required_separation"):
            assert "units" in stored[name].attrs, name
        assert stored.attrs["study"] == "risk"
    text = risk_table(ds)
    assert "separation for 2 % in 50 years" in text
    assert all(str(c) in text for c in ds.contact.values)
    assert all(f"  {b}: " in text for b in ds.building.values)


def test_cli_refuses_a_bad_hazard_and_a_bad_im_in_one_line(tmp_path):
    import subprocess
    import sys

    from pounding.data import data_path

    bad = tmp_path / "site.csv"
    bad.write_text("0.1 0.02\n0.5 0.03\n")
    for extra in (["--hazard", str(bad)], ["--hazard", "example", "--im", "sa:-1"],
                  ["--hazard", "example", "--target", "2%"]):
        done = subprocess.run([sys.executable, "-m", "pounding", "risk", str(data_path("models", "pair.yaml")), *extra],
                              capture_output=True, text=True)
        assert done.returncode == 2
        assert done.stderr.strip().count("\n") == 0 and done.stderr.startswith("pounding: error: ")


# --------------------------------------------------------------------------- #
# The codes' separations (--code)
# --------------------------------------------------------------------------- #

ASCE = {"sds": 1.0, "sd1": 0.6, "tl": 8.0}
EC8 = {"type": 1, "ground": "B", "ag": 0.25, "beta": 0.2}


@pytest.fixture(scope="module")
def code_risk(in_process_client, tmp_path_factory):
    """models/pair.yaml (it has design: factors), 3 stripes of its own record, 5 s, with both codes."""
    from pounding.data import data_path
    from pounding.studies.risk import build_risk_plan, read_hazard, risk_study

    plan = build_risk_plan(data_path("models", "pair.yaml"), read_hazard("example"), im="sa:1.0", stripes=3,
                           duration=5.0, codes={"asce7-22": ASCE, "ec8": EC8})
    out = tmp_path_factory.mktemp("code-risk") / "risk.nc"
    return risk_study(plan, out, client=in_process_client, progress=False), out


def test_each_codes_separation_is_the_gap_checks_and_its_risk_is_read_on_the_pounding_curve(code_risk):
    """The separations are those `pounding gap --code` checks (the same rows: same property, per level pair); the
    probability at each is the archived λ(g) curve's there: λ is non-increasing in g, so it lies between the
    curve's values at the grid points either side of the separation."""
    from pounding.data import data_path
    from pounding.model.model import load_model
    from pounding.studies.design_check import code_separation_rows

    ds, _ = code_risk
    path = data_path("models", "pair.yaml")
    assert list(ds.code.values) == ["asce7-22", "ec8"]
    for k, (code, options) in enumerate((("asce7-22", ASCE), ("ec8", EC8))):
        rows, _ = code_separation_rows(load_model(path), path, code, options)
        expected = {row["contact"]: row["separation"].same_property for row in rows}
        for c, label in enumerate(ds.contact.values):
            g = float(ds.code_separation.values[k, c])
            assert g == expected[str(label)] and g > 0
            j = int(np.searchsorted(ds.separation.values, g))
            lower, upper = ds.pounding_rate.values[c, j], ds.pounding_rate.values[c, j - 1]
            # (each point's integral is summed on its own: equal values on a flat stretch differ in the last bits)
            assert lower * (1 - 1e-12) <= float(ds.code_pounding_rate.values[k, c]) <= upper * (1 + 1e-12)
    # the code's separations grow up the buildings (their design displacements do), and Eurocode 8's 0.7
    # at matching levels with its smaller spectrum asks less than ASCE 7-22 here
    assert np.all(np.diff(ds.code_separation.values, axis=1) > 0)
    assert np.all(ds.code_separation.values[1] < ds.code_separation.values[0])
    for name in ("code_separation", "code_pounding_rate", "code_pounding_probability"):
        assert ds[name].attrs["units"] and ds[name].attrs["long_name"]


def test_the_cli_prints_the_codes_risk_and_refuses_a_half_given_code(tmp_path, capsys, studies_in_process):
    from pounding.cli import main
    from pounding.data import data_path

    model = str(data_path("models", "pair.yaml"))
    base = ["risk", model, "--hazard", "example", "--im", "sa:1.0", "--stripes", "2", "--duration", "3",
            "--workers", "1", "--no-progress"]
    assert main(base + ["--code", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--csv", str(tmp_path / "r.csv"),
                        "--plot", str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    assert "risk of pounding at the codes' separations" in printed and "ASCE 7-22 111 mm" in printed
    assert (tmp_path / "r.codes.csv").exists() and (tmp_path / "pounding_risk.png").exists()
    for extra, words in ((["--sds", "1.0"], "--sds sets a design spectrum"),
                         (["--code", "asce7-22", "--sds", "1.0"], "--code asce7-22 needs --sd1"),
                         (["--code", "nzs"], "--code: unknown code 'nzs'")):
        assert main(base + extra) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and words in err, err
