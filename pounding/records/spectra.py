"""Elastic response spectra by the exact piecewise-linear method.

The ground acceleration is taken as **linear between samples** (the usual
reading of a digitised record).  For that input the response of a damped
single-degree-of-freedom oscillator

    ü + 2ζω u̇ + ω² u = −a_g(t)          (u relative to the ground)

is known in closed form inside each step, so the state at the samples follows
from the exact two-term recurrence of Nigam & Jennings (1969)::

    [u, u̇]_{i+1} = A [u, u̇]_i + B₀ a_i + B₁ a_{i+1}

with A, B₀, B₁ depending only on ω, ζ and the step.  The recurrence runs once
over the record for all periods at once (vectorised over periods).

Peaks are then found **exactly**, not read off the samples: inside every step
that can hold the peak (a closed-form upper bound on |u| in the step is
compared with the largest sampled |u|) the closed form is sampled at 20 or
more points per oscillator period, and every sample that can belong to the
largest extremum is polished by Newton's method on u̇(τ) = 0, again in closed
form.  The spectral displacement is therefore the true maximum of |u(t)| of
the piecewise-linear input (to round-off), for periods far below the record's
step as well (``Sa(T→0) → PGA``).

Spectral values: ``sd = max|u|``, pseudo-velocity ``psv = ω·sd``,
pseudo-acceleration ``psa = ω²·sd`` (the "Sa" used for scaling, as in ASCE 7
and FEMA P695).  The response is taken over the record's duration only (no
free vibration after the last sample), as in PEER's and most codes'
spectra.

Reference: Nigam, N.C. & Jennings, P.C. (1969) Calculation of response
spectra from strong-motion earthquake records. BSSA 59(2), 909-922.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.errors import RecordError

__all__ = ["DEFAULT_DAMPING", "Spectrum", "default_periods", "response_spectrum", "spectral_acceleration",
           "sdof_response"]

#: Damping ratio of the standard elastic spectrum.
DEFAULT_DAMPING = 0.05

# Samples per oscillator period when the closed form is sampled inside a step
# before Newton polishing; 20 puts a sample within T/40 of every extremum.
_SAMPLES_PER_PERIOD = 20
_NEWTON_ITERATIONS = 6
# Largest number of closed-form samples evaluated at once (memory bound).
_CHUNK = 2_000_000


def default_periods() -> np.ndarray:
    """100 periods from 0.01 s to 10 s, evenly spaced in log(T)."""
    return np.logspace(-2, 1, 100)


@dataclass(frozen=True, eq=False)
class Spectrum:
    """A response spectrum.

    Attributes
    ----------
    periods : (p,) ndarray
        Oscillator periods, s (0 allowed: the rigid oscillator, psa = PGA).
    damping : float
        Damping ratio ζ.
    sd : (p,) ndarray
        Spectral displacement max|u|, m.
    psv : (p,) ndarray
        Pseudo-spectral velocity ω·sd, m/s.
    psa : (p,) ndarray
        Pseudo-spectral acceleration ω²·sd, m/s².
    pga : float
        Peak ground acceleration of the input, m/s².
    """

    periods: np.ndarray
    damping: float
    sd: np.ndarray
    psv: np.ndarray
    psa: np.ndarray
    pga: float

    def sa(self, period: float) -> float:
        """Pseudo-spectral acceleration at *period*, log-log interpolated between the computed periods.

        For an exact value at one period use :func:`spectral_acceleration`.
        """
        t = np.asarray(self.periods)
        if not (t.min() <= period <= t.max()):
            raise ValueError(f"period {period} s is outside the spectrum's {t.min():g}-{t.max():g} s")
        positive = t > 0
        return float(np.exp(np.interp(math.log(period), np.log(t[positive]), np.log(self.psa[positive]))))


def _check_input(acc: Any, dt: Any) -> tuple[np.ndarray, float]:
    a = np.asarray(acc, dtype=np.float64)
    if a.ndim != 1 or a.size < 2:
        raise RecordError(f"a response spectrum needs a 1-D record of at least 2 samples (got shape {a.shape})")
    if not np.all(np.isfinite(a)):
        raise RecordError("the record has non-finite samples; fix the record")
    step = float(dt)
    if not math.isfinite(step) or step <= 0:
        raise RecordError(f"the time step must be > 0 (got {dt!r})")
    return a, step


def _check_periods(periods: Any, damping: Any) -> tuple[np.ndarray, float]:
    t = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if t.ndim != 1 or t.size == 0:
        raise RecordError("give at least one period")
    if not np.all(np.isfinite(t)) or np.any(t < 0):
        bad = t[~(np.isfinite(t) & (t >= 0))][0]
        raise RecordError(f"periods must be finite and >= 0 s (got {bad:g})")
    zeta = float(damping)
    if not math.isfinite(zeta) or not 0.0 <= zeta < 1.0:
        raise RecordError(f"the damping ratio must be in [0, 1) (got {damping!r})")
    return t, zeta


def _closed_form(u0, v0, a0, slope, omega, zeta, tau):
    """Exact u, u̇, ü (relative) at *tau* after a state (u0, v0), for a_g = a0 + slope·τ.

    All arguments broadcast.  Particular solution α + βτ plus the damped
    free vibration that matches the initial state.
    """
    wd = omega * np.sqrt(1.0 - zeta * zeta)
    zw = zeta * omega
    beta = -slope / omega ** 2
    alpha = -a0 / omega ** 2 + 2.0 * zeta * slope / omega ** 3
    c1 = u0 - alpha
    c2 = (v0 - beta + zw * c1) / wd
    e = np.exp(-zw * tau)
    c, s = np.cos(wd * tau), np.sin(wd * tau)
    u = e * (c1 * c + c2 * s) + alpha + beta * tau
    v = e * ((wd * c2 - zw * c1) * c - (wd * c1 + zw * c2) * s) + beta
    acc = -(a0 + slope * tau) - 2.0 * zw * v - omega ** 2 * u
    return u, v, acc


def _recurrence(a: np.ndarray, dt: float, omega: np.ndarray, zeta: float, u0, v0) -> tuple[np.ndarray, np.ndarray]:
    """u, u̇ at every sample (n, p) by the Nigam-Jennings recurrence, all periods at once."""
    n, p = a.size, omega.size
    one, zero = np.ones(p), np.zeros(p)
    # Columns of the exact step map, from the closed form with unit inputs.
    a_uu, a_vu, _ = _closed_form(one, zero, zero, zero, omega, zeta, dt)
    a_uv, a_vv, _ = _closed_form(zero, one, zero, zero, omega, zeta, dt)
    b0_u, b0_v, _ = _closed_form(zero, zero, one, -one / dt, omega, zeta, dt)   # a_i = 1, a_{i+1} = 0
    b1_u, b1_v, _ = _closed_form(zero, zero, zero, one / dt, omega, zeta, dt)   # a_i = 0, a_{i+1} = 1
    force_u = np.outer(a[:-1], b0_u) + np.outer(a[1:], b1_u)
    force_v = np.outer(a[:-1], b0_v) + np.outer(a[1:], b1_v)
    u = np.empty((n, p))
    v = np.empty((n, p))
    u[0] = u0
    v[0] = v0
    for i in range(n - 1):
        ui, vi = u[i], v[i]
        u[i + 1] = a_uu * ui + a_uv * vi + force_u[i]
        v[i + 1] = a_vu * ui + a_vv * vi + force_v[i]
    return u, v


def _peak(a: np.ndarray, dt: float, u: np.ndarray, v: np.ndarray, omega: float, zeta: float,
          amax: float) -> float:
    """Exact max |u(t)| over the record for one oscillator, given its sampled states."""
    n = a.size
    absu = np.abs(u)
    best = float(absu.max())
    wd = omega * math.sqrt(1.0 - zeta * zeta)
    r = max(1, math.ceil(_SAMPLES_PER_PERIOD * wd * dt / (2.0 * math.pi)))
    slope = np.diff(a) / dt
    if r == 1:
        # The samples are dense enough: candidates are samples near the top.
        h = dt
        threshold = best - 0.125 * (amax + omega ** 2 * best) * h * h * 1.01
        near = np.flatnonzero(absu >= threshold)
        steps = np.concatenate([near[near < n - 1], near[near > 0] - 1])
        taus = np.concatenate([np.zeros(np.count_nonzero(near < n - 1)), np.full(np.count_nonzero(near > 0), dt)])
    else:
        # Steps whose closed-form bound |α + βτ| + |free vibration| can exceed the best sample.
        zw = zeta * omega
        beta = -slope / omega ** 2
        alpha = -a[:-1] / omega ** 2 + 2.0 * zeta * slope / omega ** 3
        c1 = u[:-1] - alpha
        c2 = (v[:-1] - beta + zw * c1) / wd
        bound = np.maximum(np.abs(alpha), np.abs(alpha + beta * dt)) + np.hypot(c1, c2)
        candidates = np.flatnonzero(bound >= best)
        h = dt / r
        tau_grid = np.arange(r + 1) * h
        per_chunk = max(1, _CHUNK // (r + 1))
        samples_u: list[np.ndarray] = []
        for start in range(0, candidates.size, per_chunk):
            idx = candidates[start:start + per_chunk, None]
            uu, _, _ = _closed_form(u[idx], v[idx], a[idx], slope[idx], omega, zeta, tau_grid[None, :])
            samples_u.append(np.abs(uu))
        if samples_u:
            dense = np.concatenate(samples_u)
            best = max(best, float(dense.max()))
            threshold = best - 0.125 * (amax + omega ** 2 * best) * h * h * 1.01
            rows, cols = np.nonzero(dense >= threshold)
            steps, taus = candidates[rows], tau_grid[cols]
        else:  # pragma: no cover - the best sample's own step always qualifies
            steps, taus = np.zeros(0, dtype=int), np.zeros(0)
    if steps.size == 0:
        return best
    # Newton on u̇(τ) = 0 inside each candidate step, clamped to the step.
    u0, v0, a0, s0 = u[steps], v[steps], a[steps], slope[steps]
    tau = taus.astype(float)
    for _ in range(_NEWTON_ITERATIONS):
        _, vel, acc = _closed_form(u0, v0, a0, s0, omega, zeta, tau)
        with np.errstate(divide="ignore", invalid="ignore"):
            move = np.where(acc != 0.0, vel / acc, 0.0)
        tau = np.clip(tau - move, 0.0, dt)
    polished, _, _ = _closed_form(u0, v0, a0, s0, omega, zeta, tau)
    return max(best, float(np.abs(polished).max()))


def sdof_response(acc: Any, dt: float, period: float, damping: float = DEFAULT_DAMPING, *,
                  initial_displacement: float = 0.0, initial_velocity: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Relative displacement and velocity of one oscillator at the record's samples.

    Parameters
    ----------
    acc : (n,) array
        Ground acceleration, m/s², linear between samples.
    dt : float
        Time step, s.
    period : float
        Oscillator period, s (> 0).
    damping : float
        Damping ratio.
    initial_displacement, initial_velocity : float
        State at t = 0 (default at rest).

    Returns
    -------
    u, v : (n,) ndarray
        m and m/s.
    """
    a, step = _check_input(acc, dt)
    t, zeta = _check_periods(period, damping)
    if t.size != 1 or t[0] <= 0:
        raise RecordError(f"give one period > 0 s (got {period!r})")
    u, v = _recurrence(a, step, 2.0 * math.pi / t, zeta, initial_displacement, initial_velocity)
    return u[:, 0], v[:, 0]


def response_spectrum(acc: Any, dt: float | None = None, periods: Any = None,
                      damping: float = DEFAULT_DAMPING, *, initial_displacement: Any = 0.0,
                      initial_velocity: Any = 0.0) -> Spectrum:
    """Response spectrum of a ground-acceleration record (exact for linear-between-samples input).

    Parameters
    ----------
    acc : (n,) array or Record
        Ground acceleration, m/s²; a :class:`~pounding.ground_motion.Record`
        brings its own time step.
    dt : float
        Time step, s (taken from the record if *acc* is a Record).
    periods : array, optional
        Periods, s, ≥ 0 (default :func:`default_periods`).
    damping : float
        Damping ratio ζ (default 5 %).
    initial_displacement, initial_velocity : float or (p,) array
        Oscillator state at t = 0 (default at rest); used to start an
        oscillator on a known steady state.

    Returns
    -------
    Spectrum
    """
    if hasattr(acc, "acceleration") and hasattr(acc, "time_step"):
        dt = acc.time_step if dt is None else dt
        acc = acc.acceleration
    if dt is None:
        raise RecordError("give the time step dt of the record")
    a, step = _check_input(acc, dt)
    t, zeta = _check_periods(default_periods() if periods is None else periods, damping)
    pga = float(np.max(np.abs(a)))
    sd = np.zeros(t.size)
    moving = t > 0
    if np.any(moving):
        omega = 2.0 * math.pi / t[moving]
        u0 = np.broadcast_to(np.asarray(initial_displacement, dtype=float), t.shape)[moving]
        v0 = np.broadcast_to(np.asarray(initial_velocity, dtype=float), t.shape)[moving]
        u, v = _recurrence(a, step, omega, zeta, u0, v0)
        sd[moving] = [_peak(a, step, u[:, j], v[:, j], float(omega[j]), zeta, pga) for j in range(omega.size)]
    omega_all = np.where(moving, 2.0 * math.pi / np.where(moving, t, 1.0), 0.0)
    psa = np.where(moving, omega_all ** 2 * sd, pga)
    psv = omega_all * sd
    for array in (t, sd, psv, psa):
        array.setflags(write=False)
    return Spectrum(periods=t, damping=zeta, sd=sd, psv=psv, psa=psa, pga=pga)


def spectral_acceleration(acc: Any, dt: float | None = None, period: float = 1.0,
                          damping: float = DEFAULT_DAMPING) -> float:
    """Pseudo-spectral acceleration Sa(T, ζ) = ω²·max|u|, m/s², at one period."""
    return float(response_spectrum(acc, dt, [period], damping).psa[0])
