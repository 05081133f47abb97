"""Compiled contact-law kernels: force, internal rates, modes and switches of every registered law.

The law classes (parameters, citations, packing into ``prm``) are in
:mod:`pounding.contact.laws`; these are their numba kernels, one branch per
law, inlined by the integrator (:mod:`pounding.solver.integrator`).  No
Python objects inside.  Each law's force is written once, in
:func:`mode_force`; :func:`force` is that routine in the mode the state
implies (:func:`implied_mode`).  Laws written in modules of their own
(``laws.LAW_MODULES``) bring their kernels as plain functions
(``laws.LawKernels``), compiled and dispatched here by ``law_id``
(docs/adding-a-law.md).
"""

from __future__ import annotations

import math
import sys

import numpy as np
from numba import njit

from pounding.contact import laws
from pounding.contact import links
from pounding.numba_cache import use_writable_cache
from pounding.solver import jit
from pounding.contact.laws import MIN_IMPACT_VELOCITY


# --------------------------------------------------------------------------- #
# Compiled kernels.  One branch per law; no Python objects inside.
# --------------------------------------------------------------------------- #


use_writable_cache(__file__)  # a read-only install caches its kernels in the user's cache folder

# Branch ids, read from the registries (pounding.registry.add_numbered): compile-time constants here.
LAW_LINEAR = laws.Linear.law_id
LAW_HERTZ = laws.Hertz.law_id
LAW_HERTZ_DAMP = laws.HertzDamp.law_id
LAW_KELVIN = laws.Kelvin.law_id
LAW_JANKOWSKI = laws.Jankowski.law_id
LAW_BILINEAR = laws.Bilinear.law_id
LAW_STEREO = laws.StereoMechanical.law_id
LAW_BUMPER = laws.Bumper.law_id
LINK_VISCOUS = links.LINK_VISCOUS
LINK_KELVIN = links.LINK_KELVIN
LINK_MAXWELL = links.LINK_MAXWELL
FIRST_LINK_ID = links.FIRST_LINK_ID


# --------------------------------------------------------------------------- #
# Laws written in modules of their own (laws.LAW_MODULES; docs/adding-a-law.md).
# Their kernels are plain Python functions (laws.LawKernels), compiled here; a
# law's routine is reached through a chain of small compiled functions, one per
# such law, selected by law_id.  The laws with branches of their own below are
# registered first, so these ids start at FIRST_PLUGIN_ID.
# --------------------------------------------------------------------------- #

PLUGIN_LAWS = [cls for cls in laws.LAWS.values() if cls.kernels is not None]
FIRST_PLUGIN_ID = min((cls.law_id for cls in PLUGIN_LAWS), default=FIRST_LINK_ID)
if any(cls.law_id >= FIRST_PLUGIN_ID for cls in laws.LAWS.values() if cls.kernels is None) or \
        max((cls.law_id for cls in laws.LAWS.values()), default=0) >= FIRST_LINK_ID:
    raise RuntimeError(f"contact laws with kernels of their own are registered after the others and "
                       f"below id {FIRST_LINK_ID}: {[(c.name, c.law_id) for c in laws.LAWS.values()]}")


#: numba options of a dispatch-chain function: cached, called from compiled code only, no reference counting.
_CHAIN_OPTIONS = dict(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)


def _chain_end(law_id, *args):
    return 0  # never reached: the callers test FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID


def _chain_link(head, number, tail):
    """Compiled ``f(law_id, *args)``: *head(*args)* for law *number*, else *tail*."""
    def routine(law_id, *args):
        if law_id == number:
            return head(*args)
        return tail(law_id, *args)
    return njit(**_CHAIN_OPTIONS)(routine)


def _chain(routine: str):
    """The compiled dispatch of one :class:`pounding.contact.laws.LawKernels` routine over the plugin laws."""
    tail = njit(**_CHAIN_OPTIONS)(_chain_end)
    for cls in reversed(PLUGIN_LAWS):
        tail = _chain_link(njit(**_CHAIN_OPTIONS)(getattr(cls.kernels, routine)), cls.law_id, tail)
    return tail


# One chain per LawKernels routine (named globals: the kernels below call them by name).
_plugin_mode_force = _chain("mode_force")
_plugin_potential = _chain("potential")
_plugin_onset_constant = _chain("onset_constant")
_plugin_onset_mode = _chain("onset_mode")
_plugin_switch_count = _chain("switch_count")
_plugin_switch_value = _chain("switch_value")
_plugin_next_mode = _chain("next_mode")
_plugin_snapped_internal = _chain("snapped_internal")
_plugin_mode_internal_rate = _chain("mode_internal_rate")
_plugin_implied_mode = _chain("implied_mode")
_plugin_internal_tolerance = _chain("internal_tolerance")
_plugin_contact_duration = _chain("contact_duration")


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def is_permanent(law_id: int) -> bool:
    """True for link elements (pounding.contact.links): always engaged, no gap, no events, tension allowed."""
    return law_id >= FIRST_LINK_ID


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def link_force(law_id: int, prm: np.ndarray, delta: float, delta_rate: float, q: float) -> float:
    """Force of a link (N, may be negative: a pull) at relative displacement *delta* and its rate."""
    if law_id == LINK_VISCOUS:
        return prm[1] * delta_rate
    if law_id == LINK_KELVIN:
        return prm[0] * delta + prm[1] * delta_rate
    if law_id == LINK_MAXWELL:
        return q
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def onset_constant(law_id: int, prm: np.ndarray, v0: float) -> float:
    """Per-impact constant fixed at the located gap closure (ξ for Hertz-damp, the rubber's ξb for a bumper)."""
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_onset_constant(law_id, prm, v0)
    if law_id == LAW_HERTZ_DAMP or law_id == LAW_BUMPER:
        return prm[1] * prm[0] / max(v0, prm[2])
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def is_instantaneous(law_id: int) -> bool:
    """True for laws applied as a velocity jump at closure (stereo-mechanical)."""
    return law_id == LAW_STEREO


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def restitution(law_id: int, prm: np.ndarray) -> float:
    """Coefficient of restitution e of an instantaneous law (0 for the others)."""
    if law_id == LAW_STEREO:
        return prm[0]
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def jump_impulse(law_id: int, prm: np.ndarray, v0: float) -> float:
    """Impulse (N·s) of an instantaneous law for approach velocity *v0*: (1+e)·m_eff·v0."""
    if law_id == LAW_STEREO:
        return (1.0 + restitution(law_id, prm)) * prm[1] * v0
    return 0.0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)  # called from compiled code only
def _bilinear_bounds(prm: np.ndarray, delta: float) -> tuple:
    """Lower (K2·δ) and upper (K1·δy + K2·(δ − δy)) envelopes of the bilinear loop, N."""
    k1, k2, dy = prm[0], prm[1], prm[2]
    upper = k1 * delta if delta <= dy else k1 * dy + k2 * (delta - dy)
    return k2 * delta, upper


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)  # called from compiled code only
def _bumper_force(prm: np.ndarray, xi_bumper: float, delta: float, delta_rate: float, xi_hard: float,
                  bumper_on: bool, hard_engaged: bool, hard_on: bool) -> float:
    """Bumper law: rubber ``δ^1.5·(kb + ξb·δ̇)`` plus, when engaged, the hard face on ``δ − δlim``, N.

    With ``tension: clamp`` each part is at least 0; a part that is off (clamped
    in its mode) contributes nothing.  *xi_hard* is ξh, the law's internal state.
    """
    clamp = prm[3] == 0.0
    f = 0.0
    if bumper_on:
        f = delta * math.sqrt(delta) * (prm[0] + xi_bumper * delta_rate)
        if clamp and f < 0.0:
            f = 0.0
    dh = delta - prm[6]
    if hard_engaged and hard_on and dh > 0.0:
        fh = dh * math.sqrt(dh) * (prm[4] + xi_hard * delta_rate)
        if clamp and fh < 0.0:
            fh = 0.0
        f += fh
    return f


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)  # called from compiled code only
def potential(law_id: int, prm: np.ndarray, delta: float, q: float) -> float:
    """Elastic energy stored in the contact (J): what unloading would give back.

    Links: ½kδ² in a Kelvin spring, q²/(2k) in a Maxwell spring, none in a dashpot.
    """
    if law_id == LINK_KELVIN:
        return 0.5 * prm[0] * delta * delta
    if law_id == LINK_MAXWELL:
        return 0.5 * q * q / prm[0]
    if law_id == LINK_VISCOUS:
        return 0.0
    if delta <= 0.0:
        return 0.0
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_potential(law_id, prm, delta, q)
    if law_id == LAW_HERTZ_DAMP or law_id == LAW_HERTZ or law_id == LAW_JANKOWSKI:
        return prm[0] * delta * delta * math.sqrt(delta) / 2.5
    if law_id == LAW_LINEAR or law_id == LAW_KELVIN:
        return 0.5 * prm[0] * delta * delta
    if law_id == LAW_BILINEAR:
        k1, k2 = prm[0], prm[1]
        lower, upper = _bilinear_bounds(prm, delta)
        f = min(max(q, lower), upper)  # the loop's force at this state (q off the loop by round-off: its edge)
        # Unloading: slope K1 from (δ, f) down to the line K2·δ at δ*, then that line to 0.
        d_star = (k1 * delta - f) / (k1 - k2)
        d_star = min(max(d_star, 0.0), delta)
        return 0.5 * (f + k2 * d_star) * (delta - d_star) + 0.5 * k2 * d_star * d_star
    if law_id == LAW_BUMPER:
        energy = prm[0] * delta * delta * math.sqrt(delta) / 2.5
        dh = delta - prm[6]
        if dh > 0.0:
            energy += prm[4] * dh * dh * math.sqrt(dh) / 2.5
        return energy
    return 0.0


# --------------------------------------------------------------------------- #
# Modes of a closed contact (the solver locates every switch as an event).
#
# A law whose force or internal rate changes formula inside a contact (the
# tension clamp, Jankowski's approach/recede damping, the bilinear loop's
# branches) carries an integer *mode* per closed contact.  Inside a step the
# mode is fixed, so the force is smooth there and the error control sees it;
# a mode ends where one of its switch functions ``switch_value(…, which)``
# (positive while the mode holds) crosses zero, which the solver locates on
# the step's interpolant and then applies ``next_mode`` / ``snapped_internal``.
# --------------------------------------------------------------------------- #

#: Hertz-damp / Kelvin: the law pushes (formula) or the clamp holds it at 0 N.
MODE_PUSH = 0
MODE_CLAMPED = 1
#: Jankowski: damping term on while approaching (δ̇ > 0), off while receding.
MODE_APPROACH = 0
MODE_RECEDE = 1
#: Bilinear loop, written as a spring K2 in parallel with an elastic-perfectly-plastic
#: spring (K1 − K2) whose force lies in [0, (K1 − K2)·δy]: elastic (slope K1), yielding at
#: the top (upper envelope, slope K2, loading) or at the bottom (line K2·δ, unloading).
MODE_ELASTIC = 0
MODE_YIELD_TOP = 1
MODE_YIELD_BOTTOM = 2
#: Stereo-mechanical persistent (resting) contact: a bilateral constraint δ̈ = 0
#: whose force the solver computes; it ends where that force would turn tensile.
MODE_STUCK = 3
#: Bumper: bit flags (never the value MODE_STUCK): the rubber's clamp holds it at 0 N,
#: the hard face is engaged (δ > δlim), the hard face's clamp holds it at 0 N.
BUMPER_CLAMPED = 1
BUMPER_HARD = 4
BUMPER_HARD_CLAMPED = 8

#: Largest number of switch functions of one mode (the bumper's: hard face, two clamps).
N_SWITCHES = 3


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def onset_mode(law_id: int, prm: np.ndarray, v0: float) -> int:
    """Mode of a contact at its located gap closure with approach velocity *v0* (m/s)."""
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_onset_mode(law_id, prm, v0)
    if law_id == LAW_JANKOWSKI:
        return MODE_APPROACH if v0 > 0.0 else MODE_RECEDE
    if law_id == LAW_STEREO:
        return MODE_STUCK
    return 0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def switch_count(law_id: int, prm: np.ndarray) -> int:
    """How many switch functions the law has (0: the force is one formula while closed)."""
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_switch_count(law_id, prm)
    if law_id == LAW_HERTZ_DAMP:
        return 1 if prm[3] == 0.0 else 0
    if law_id == LAW_KELVIN:
        return 1 if prm[2] == 0.0 else 0
    if law_id == LAW_JANKOWSKI:
        return 1
    if law_id == LAW_BILINEAR:
        return 2
    if law_id == LAW_BUMPER:
        return 1 if prm[3] != 0.0 else 3
    return 0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def mode_force(law_id: int, prm: np.ndarray, impact_constant: float, mode: int, delta: float,
               delta_rate: float, q: float) -> float:
    """Contact force (N) of a closed contact in *mode* (no branch on the state inside a mode).

    The one force routine of every law: :func:`force` is this routine in the
    mode the state implies (:func:`implied_mode`).  Inside a mode the formula
    does not switch before the located event (just past an event the clamp
    still holds the force at ≥ 0).
    """
    if law_id >= FIRST_LINK_ID:
        return link_force(law_id, prm, delta, delta_rate, q)
    if delta <= 0.0:
        return 0.0
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_mode_force(law_id, prm, impact_constant, mode, delta, delta_rate, q)
    if law_id == LAW_HERTZ_DAMP:
        if mode == MODE_CLAMPED:
            return 0.0
        f = delta * math.sqrt(delta) * (prm[0] + impact_constant * delta_rate)
        if prm[3] == 0.0 and f < 0.0:
            return 0.0
        return f
    if law_id == LAW_KELVIN:
        if mode == MODE_CLAMPED:
            return 0.0
        f = prm[0] * delta + prm[1] * delta_rate
        if prm[2] == 0.0 and f < 0.0:
            return 0.0
        return f
    if law_id == LAW_JANKOWSKI:
        f = prm[0] * delta * math.sqrt(delta)
        if mode == MODE_APPROACH:
            f += 2.0 * prm[1] * math.sqrt(prm[0] * math.sqrt(delta) * prm[2]) * delta_rate
        return f
    if law_id == LAW_BILINEAR:
        return q
    if law_id == LAW_BUMPER:
        return _bumper_force(prm, impact_constant, delta, delta_rate, q, (mode & BUMPER_CLAMPED) == 0,
                             (mode & BUMPER_HARD) != 0, (mode & BUMPER_HARD_CLAMPED) == 0)
    if law_id == LAW_HERTZ:
        return prm[0] * delta * math.sqrt(delta)
    if law_id == LAW_LINEAR:
        return prm[0] * delta
    return 0.0  # stereo-mechanical: no force history (a velocity jump; a stuck contact's force is the solver's)


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def mode_internal_rate(law_id: int, prm: np.ndarray, mode: int, delta: float, delta_rate: float) -> float:
    """Rate of the internal state in *mode* (N/s): the bilinear force follows K1 (elastic) or K2 (yielding)."""
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_mode_internal_rate(law_id, prm, mode, delta, delta_rate)
    if law_id == LAW_BILINEAR:
        if mode == MODE_ELASTIC:
            return prm[0] * delta_rate
        return prm[1] * delta_rate
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def link_internal_rate(law_id: int, prm: np.ndarray, delta_rate: float, q: float) -> float:
    """Rate of a link's internal state (N/s): a Maxwell element's force, ``k·(δ̇ − q/c)``."""
    if law_id == LINK_MAXWELL:
        return prm[0] * (delta_rate - q / prm[1])
    return 0.0


#: Relative margin of :func:`switch_may_cross`'s bound over the switch's round-off (the samples' own).
SWITCH_MARGIN = 1e-9


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def switch_value(law_id: int, prm: np.ndarray, impact_constant: float, mode: int, which: int, delta: float,
                 delta_rate: float, q: float) -> float:
    """Switch function *which* of *mode*: positive while the mode holds, crossing 0 where it ends.

    Hertz-damp (clamped): ``kh + ξ·δ̇`` while pushing (the sign of the
    unclamped force), its negative while clamped (a *reload* is its crossing).
    Kelvin (clamped): ``k·δ + c·δ̇`` likewise.  Jankowski: ``±δ̇``.
    Bilinear: elastic — distance to the top (``K2·δ + (K1 − K2)·δy − q``) and to
    the bottom (``q − K2·δ``) of the loop; yielding — ``±δ̇``.  Bumper: 0 — the
    hard face, ``±(δ − δlim)``; 1 — the rubber's clamp, ``±(kb + ξb·δ̇)``; 2 — the
    hard face's clamp, ``±(kh + ξh·δ̇)`` (engaged modes only).  Units vary (only
    the sign is used); 1.0 for a switch the mode does not have.
    """
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_switch_value(law_id, prm, impact_constant, mode, which, delta, delta_rate, q)
    if law_id == LAW_HERTZ_DAMP and which == 0:
        g = prm[0] + impact_constant * delta_rate
        return g if mode == MODE_PUSH else -g
    if law_id == LAW_KELVIN and which == 0:
        g = prm[0] * delta + prm[1] * delta_rate
        return g if mode == MODE_PUSH else -g
    if law_id == LAW_JANKOWSKI and which == 0:
        return delta_rate if mode == MODE_APPROACH else -delta_rate
    if law_id == LAW_BILINEAR:
        k1, k2, dy = prm[0], prm[1], prm[2]
        if mode == MODE_ELASTIC:
            if which == 0:
                return k2 * delta + (k1 - k2) * dy - q
            return q - k2 * delta
        if which == 0:
            return delta_rate if mode == MODE_YIELD_TOP else -delta_rate
    if law_id == LAW_BUMPER:
        if which == 0:
            g = delta - prm[6]
            return g if (mode & BUMPER_HARD) != 0 else -g
        if which == 1:
            g = prm[0] + impact_constant * delta_rate
            return -g if (mode & BUMPER_CLAMPED) != 0 else g
        if which == 2 and (mode & BUMPER_HARD) != 0:
            g = prm[4] + q * delta_rate
            return -g if (mode & BUMPER_HARD_CLAMPED) != 0 else g
    return 1.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def switch_may_cross(law_id: int, prm: np.ndarray, impact_constant: float, mode: int, which: int, rate_low: float,
                     rate_high: float) -> bool:
    """False only where switch function *which* of *mode* stays positive for every δ̇ in
    [*rate_low*, *rate_high*] (m/s), whatever δ and the internal state: a switch linear in δ̇ alone
    (Hertz-damp's clamp ``±(kh + ξ·δ̇)``), bounded by its value at the interval's worse end.  True
    otherwise (every other switch: the caller samples it)."""
    if law_id == LAW_HERTZ_DAMP and which == 0:
        kh, xi = prm[0], impact_constant
        if mode == MODE_PUSH:
            worst = kh + xi * rate_low if xi >= 0.0 else kh + xi * rate_high
        else:
            worst = -(kh + xi * rate_high) if xi >= 0.0 else -(kh + xi * rate_low)
        return not worst > SWITCH_MARGIN * (kh + abs(xi) * max(abs(rate_low), abs(rate_high)))
    return True


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def next_mode(law_id: int, mode: int, which: int) -> int:
    """Mode entered when switch function *which* of *mode* crosses zero."""
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_next_mode(law_id, mode, which)
    if law_id == LAW_BILINEAR:
        if mode == MODE_ELASTIC:
            return MODE_YIELD_TOP if which == 0 else MODE_YIELD_BOTTOM
        return MODE_ELASTIC
    if law_id == LAW_BUMPER:
        if which == 0:
            return mode & BUMPER_CLAMPED if (mode & BUMPER_HARD) != 0 else mode | BUMPER_HARD
        if which == 1:
            return mode ^ BUMPER_CLAMPED
        return mode ^ BUMPER_HARD_CLAMPED
    return 1 - mode


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def snapped_internal(law_id: int, prm: np.ndarray, mode: int, delta: float, delta_rate: float, q: float) -> float:
    """Internal state put exactly on the branch *mode* starts on (removes the event's round-off).

    Bumper: the state is ξh of the hard face, set where the face engages from
    its approach velocity ``δ̇`` (``p(e)·kh/max(δ̇, v_min)``), kept while engaged
    (clamp switches) and reset to 0 where it disengages.
    """
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_snapped_internal(law_id, prm, mode, delta, delta_rate, q)
    if law_id == LAW_BUMPER:
        if (mode & BUMPER_HARD) == 0:
            return 0.0
        if q == 0.0:
            return prm[5] * prm[4] / max(delta_rate, prm[2])
        return q
    if law_id == LAW_BILINEAR:
        if mode == MODE_YIELD_TOP:
            return prm[1] * delta + (prm[0] - prm[1]) * prm[2]
        if mode == MODE_YIELD_BOTTOM:
            return prm[1] * delta
    return q


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def implied_mode(law_id: int, prm: np.ndarray, impact_constant: float, delta: float, delta_rate: float,
                 q: float) -> int:
    """Mode a closed contact's state implies, without the history the solver's located events carry.

    Hertz-damp and Kelvin: clamped where the clamp is on and the formula
    would pull.  Jankowski: approaching while δ̇ > 0.  Bilinear: yielding at
    the top where ``q`` is on or above the upper envelope while loading past
    δy, at the bottom where it is on or below the line ``K2·δ`` while
    unloading, elastic otherwise.  Bumper: the hard face engaged where
    ``δ > δlim``, each clamp where its part would pull.  Other laws: 0.
    """
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_implied_mode(law_id, prm, impact_constant, delta, delta_rate, q)
    if law_id == LAW_HERTZ_DAMP or law_id == LAW_KELVIN or law_id == LAW_BUMPER:
        mode = 0
        first = 0
        if law_id == LAW_BUMPER:
            first = 1  # switch 0 of a bumper is the hard face, set here from δ; 1 and 2 are its clamps
            if delta > prm[6]:
                mode = BUMPER_HARD
        for which in range(first, switch_count(law_id, prm)):
            # a clamp's switch function is negative where its part would pull: its next mode is clamped
            if switch_value(law_id, prm, impact_constant, mode, which, delta, delta_rate, q) < 0.0:
                mode = next_mode(law_id, mode, which)
        return mode
    if law_id == LAW_JANKOWSKI:
        return MODE_APPROACH if delta_rate > 0.0 else MODE_RECEDE
    if law_id == LAW_BILINEAR:
        lower, upper = _bilinear_bounds(prm, delta)
        if delta_rate > 0.0 and q >= upper and delta > prm[2]:
            return MODE_YIELD_TOP
        if delta_rate < 0.0 and q <= lower:
            return MODE_YIELD_BOTTOM
        return MODE_ELASTIC
    return 0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def force(law_id: int, prm: np.ndarray, impact_constant: float, delta: float,
          delta_rate: float, q: float) -> float:
    """Contact force (N) at penetration *delta* (m), its rate (m/s) and internal state *q*, no mode given.

    :func:`mode_force` in the mode the state implies (:func:`implied_mode`):
    one formula per law.  The bilinear force is its internal state ``q`` in
    every mode (the loop's branches are located by the solver's events).
    """
    mode = implied_mode(law_id, prm, impact_constant, delta, delta_rate, q)
    return mode_force(law_id, prm, impact_constant, mode, delta, delta_rate, q)


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def internal_rate(law_id: int, prm: np.ndarray, delta: float, delta_rate: float, q: float) -> float:
    """Rate of the internal state (N/s) in the mode the state implies (:func:`mode_internal_rate`); links too."""
    if law_id >= FIRST_LINK_ID:
        return link_internal_rate(law_id, prm, delta_rate, q)
    if delta <= 0.0:
        return 0.0
    return mode_internal_rate(law_id, prm, implied_mode(law_id, prm, 0.0, delta, delta_rate, q), delta, delta_rate)


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def internal_tolerance(law_id: int, prm: np.ndarray, atol_displacement: float) -> float:
    """Absolute error tolerance of the internal state (N): K1·atol for the bilinear force, 0 if unused."""
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_internal_tolerance(law_id, prm, atol_displacement)
    if law_id == LAW_BILINEAR or law_id == LINK_MAXWELL:
        return prm[0] * atol_displacement
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def contact_duration(law_id: int, prm: np.ndarray, v0: float, effective_mass: float) -> float:
    """Duration estimate (s) of a free impact at approach velocity *v0* (m/s); 0 for instantaneous laws.

    Hertz-type laws: ``2.94·δmax/v0`` with ``δmax = (5·m·v0²/(4·kh))^(2/5)``
    (physics.md §2; the rubber's kb for a bumper); linear-type laws: the half period ``π·sqrt(m/k)`` (K1 for
    the bilinear law).  Used only to choose the first step inside a contact.
    """
    if FIRST_PLUGIN_ID <= law_id < FIRST_LINK_ID:
        return _plugin_contact_duration(law_id, prm, v0, effective_mass)
    v = max(v0, 1e-12)
    m = effective_mass
    if law_id == LAW_HERTZ_DAMP or law_id == LAW_HERTZ or law_id == LAW_JANKOWSKI or law_id == LAW_BUMPER:
        dmax = (1.25 * m * v * v / prm[0]) ** 0.4
        return 2.94 * dmax / v
    if law_id == LAW_LINEAR or law_id == LAW_KELVIN or law_id == LAW_BILINEAR:
        return math.pi * math.sqrt(m / prm[0])
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def rest_velocity(law_id: int, prm: np.ndarray) -> float:
    """Approach velocity (m/s) at or below which a closure is a contact at rest (docs/numerics.md).

    Stereo-mechanical: :data:`MIN_IMPACT_VELOCITY` (1 mm/s): what remains of a
    rigid impact sequence below it lasts at most ``2·e·v/((1 − e)·a)`` and moves
    the floors by at most ``v·`` that; the closure may become a stuck contact.
    Compliant laws: their own floor on v0 (``min_impact_velocity`` of Hertz-damp
    and the bumper, 1 mm/s for the others): the contact is then *resting*, and
    parting by less than the solver resolves is not a separation.  Links: 0.
    """
    if law_id >= FIRST_LINK_ID:
        return 0.0
    if law_id == LAW_HERTZ_DAMP or law_id == LAW_BUMPER:
        return prm[2]  # their min_impact_velocity (contact/laws.py: kernel_parameters)
    return MIN_IMPACT_VELOCITY


# The kernels inline the law ids and sizes of contact/laws.py: their cached code is stale when it changes.
jit.EXTRA_SOURCES.extend(sys.modules[cls.__module__].__file__ for cls in PLUGIN_LAWS)  # compiled into every solver
jit.stamp_solver_kernels(globals())
