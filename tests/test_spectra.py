"""Response spectra (pounding.spectra): physics, exactness, and an independent implementation."""

from __future__ import annotations

import math

import numpy as np
import pyrotd
import pytest
import scipy.signal

from pounding.errors import RecordError
from pounding.records.record import STANDARD_GRAVITY
from pounding.records.load import load_record
from pounding.records.spectra import Spectrum, default_periods, response_spectrum, sdof_response, spectral_acceleration
from pounding.records.spectra import _closed_form


@pytest.fixture(scope="module")
def mul009():
    return load_record("northridge-1994-beverly-hills-mul009")


def _steady_state(amplitude, forcing, omega, zeta):
    """Steady state of ü + 2ζωu̇ + ω²u = −A sin(Ωt): u = X sin(Ωt − θ), X = A/ω² · D."""
    r = forcing / omega
    amplification = 1.0 / math.sqrt((1 - r * r) ** 2 + (2 * zeta * r) ** 2)
    theta = math.atan2(2 * zeta * r, 1 - r * r)
    x = -amplitude / omega ** 2 * amplification
    return x, theta, amplification


@pytest.mark.parametrize("ratio", [0.5, 1.0, 2.0])
def test_harmonic_steady_state_equals_the_sdof_amplification(ratio):
    period, zeta, amplitude = 0.8, 0.05, 3.0
    omega = 2 * math.pi / period
    forcing = ratio * omega
    dt = (2 * math.pi / forcing) / 2000
    t = np.arange(int(5 * 2000) + 1) * dt
    acc = amplitude * np.sin(forcing * t)
    x, theta, amplification = _steady_state(amplitude, forcing, omega, zeta)
    u0, v0 = x * math.sin(-theta), x * forcing * math.cos(-theta)
    spectrum = response_spectrum(acc, dt, [period], zeta, initial_displacement=u0, initial_velocity=v0)
    # Started on the steady state, the oscillator stays on it: Sa = A·D exactly for a
    # true sine.  The record is the sine linear between samples, which differs from it
    # by at most (Ω dt)²/8 = 1.2e-6 relative (2000 samples per cycle): 1e-5 covers it.
    assert spectrum.psa[0] == pytest.approx(amplitude * amplification, rel=1e-5)
    assert spectrum.sd[0] == pytest.approx(abs(x), rel=1e-5)
    assert spectrum.psv[0] == pytest.approx(omega * abs(x), rel=1e-5)
    if ratio == 1.0:
        assert amplification == pytest.approx(1 / (2 * zeta))


def test_sa_at_vanishing_period_is_the_pga(mul009):
    # A very stiff oscillator follows the ground: ω²u = −a_g − (2ζ/ω) ȧ_g + ringing at the
    # slope changes of the piecewise-linear record, both O(T/dt); at T = 1e-4 s (dt = 0.01 s)
    # they are ~1e-5 of the PGA, far inside the 1e-3 asked for.
    assert spectral_acceleration(mul009, period=1e-4) == pytest.approx(mul009.pga, rel=1e-3)
    spectrum = response_spectrum(mul009, periods=[0.0, 1e-4])
    assert spectrum.psa[0] == mul009.pga and spectrum.sd[0] == 0.0


def test_recurrence_matches_scipy_exact_discretisation(mul009):
    # scipy.signal.lsim with interp=True integrates the same ODE exactly for input linear
    # between samples (matrix exponential): the two agree to round-off.
    period, zeta = 0.7, 0.05
    omega = 2 * math.pi / period
    u, v = sdof_response(mul009.acceleration, mul009.time_step, period, zeta)
    system = scipy.signal.StateSpace([[0, 1], [-omega ** 2, -2 * zeta * omega]], [[0], [-1]], np.eye(2),
                                     np.zeros((2, 1)))
    _, _, state = scipy.signal.lsim(system, mul009.acceleration, mul009.time, interp=True)
    scale_u, scale_v = np.abs(state[:, 0]).max(), np.abs(state[:, 1]).max()
    assert np.abs(u - state[:, 0]).max() < 1e-9 * scale_u
    assert np.abs(v - state[:, 1]).max() < 1e-9 * scale_v


def test_peak_is_the_true_maximum_between_samples(mul009):
    # Sample the closed form 400 times per step: the spectral displacement is never below
    # any of those values (it is the exact maximum) and above the densest of them by no
    # more than the sampling can miss near a peak, |ü| h²/8 with |ü| ≤ PGA + ω²·sd
    # (u̇ = 0 there) and h = dt/400.
    acc, dt = mul009.acceleration[:1500], mul009.time_step
    zeta = 0.05
    for period in (0.013, 0.05, 0.3, 2.0):
        omega = 2 * math.pi / period
        u, v = sdof_response(acc, dt, period, zeta)
        tau = np.linspace(0.0, dt, 401)[None, :]
        slope = (np.diff(acc) / dt)[:, None]
        dense, _, _ = _closed_form(u[:-1, None], v[:-1, None], acc[:-1, None], slope, omega, zeta, tau)
        dense_max = float(np.abs(dense).max())
        sd = float(response_spectrum(acc, dt, [period], zeta).sd[0])
        assert sd >= dense_max * (1 - 1e-12)
        assert sd - dense_max <= (np.abs(acc).max() + omega ** 2 * sd) * (dt / 400) ** 2 / 8 * 1.01


def test_cross_check_against_pyrotd(mul009):
    """pyrotd (frequency domain, FFT) against this time-domain method, to 1e-3 relative.

    The two read the samples differently — pyrotd as a band-limited periodic signal,
    this module as linear between samples — so the record is first made smooth on its
    own grid: band-limited resampling to dt/8 (then both readings agree to
    (2π f dt/8)²/12 ≲ 1e-3 even at the 50 Hz Nyquist of the original), and 100 s of
    zeros are appended so that pyrotd's wrap-around sees an oscillator at rest
    (e^(−ζωt) < 1e-8 after 100 s at T = 5 s) and both see the same free vibration.
    pyrotd's peak is sampled at ≥ 20·max_freq_ratio points per period (error ≤ 1e-4).
    """
    padded = np.r_[mul009.acceleration, np.zeros(int(100 / mul009.time_step))]
    fine = scipy.signal.resample(padded, padded.size * 8)
    dt = mul009.time_step / 8
    periods = np.array([0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 3.0, 5.0])
    ours = response_spectrum(fine, dt, periods, 0.05).psa
    theirs = pyrotd.calc_spec_accels(dt, fine, 1 / periods, 0.05, max_freq_ratio=20).spec_accel
    np.testing.assert_allclose(ours, theirs, rtol=1e-3)


def test_spectrum_is_linear_in_the_record(mul009):
    base = response_spectrum(mul009)
    doubled = response_spectrum(2.5 * mul009.acceleration, mul009.time_step)
    # Same arithmetic up to one rounding per operation.
    np.testing.assert_allclose(doubled.psa, 2.5 * base.psa, rtol=1e-12)
    assert isinstance(base, Spectrum) and base.damping == 0.05
    np.testing.assert_array_equal(base.periods, default_periods())
    assert base.sa(1.0) == pytest.approx(spectral_acceleration(mul009, period=1.0), rel=2e-2)


def test_more_damping_lowers_the_resonant_peak(mul009):
    low = spectral_acceleration(mul009, period=0.5, damping=0.02)
    five = spectral_acceleration(mul009, period=0.5)
    high = spectral_acceleration(mul009, period=0.5, damping=0.2)
    assert low > five > high


def test_pga_of_the_example_record_in_g(mul009):
    assert response_spectrum(mul009, periods=[0.0]).psa[0] / STANDARD_GRAVITY == pytest.approx(0.4158, abs=5e-5)


@pytest.mark.parametrize("kwargs, message", [
    (dict(periods=[-1.0]), "periods must be finite and >= 0 s (got -1)"),
    (dict(periods=[1.0], damping=1.0), "the damping ratio must be in [0, 1) (got 1.0)"),
    (dict(periods=[]), "give at least one period"),
])
def test_bad_arguments(mul009, kwargs, message):
    with pytest.raises(RecordError) as info:
        response_spectrum(mul009, **kwargs)
    assert str(info.value) == message


def test_bad_records():
    with pytest.raises(RecordError, match="at least 2 samples"):
        response_spectrum([1.0], 0.01)
    with pytest.raises(RecordError, match="non-finite"):
        response_spectrum([0.0, math.nan, 1.0], 0.01)
    with pytest.raises(RecordError, match="time step must be > 0"):
        response_spectrum([0.0, 1.0], 0.0)
    with pytest.raises(RecordError, match="give the time step"):
        response_spectrum([0.0, 1.0])
