"""Registry contract: every contact law, ξ formula, link law and storey hysteresis model keeps it.

Parametrised over the registries themselves (pounding.contact.laws.LAWS,
pounding.contact.xi.FORMULAS, pounding.contact.links.LINK_LAWS,
pounding.hysteresis.HYSTERESES), so a new entry is tested without editing
this file; its parameters come from its row in tests/data/registry_examples.yaml.

For every entry:
* its compiled branch exists (a kernel answers for its id with what only its
  own branch can give, not the fall-through default);
* the OpenSees export supports it or refuses it by name in one line.

Then the checks of its kind: each class declares the ones that apply in its
``checks`` class attribute, and each check here covers at least one class
(:func:`test_every_check_is_declared_and_used`).  A check a class declares
that this file does not define fails too.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from numba import njit

from pounding import hysteresis
from pounding.contact import laws, links, xi
from pounding.errors import PoundingError
from pounding.export import opensees, opensees_materials
from pounding.solver import kernels, storeys
from pounding.studies.verify import RIGID_MASS, RTOL, contact_phase

EXAMPLES = yaml.safe_load((Path(__file__).parent / "data" / "registry_examples.yaml").read_text())

#: Floor masses of the examples, kg (two storeys of a concrete building).
MASSES = (2.0e5, 3.0e5)
#: Penetrations (m) and rates (m/s) the pointwise checks sample: from grazing to deep (a bumper's
#: hard face engages at 5 mm in its example row) and from fast opening to fast closing.
DELTAS = (1e-5, 1e-4, 1e-3, 3e-3, 8e-3)
RATES = (-1.0, -0.1, -1e-3, 0.0, 1e-3, 0.1, 1.0)
#: Approach velocity (m/s) at which per-impact constants are fixed in the checks.
V0 = 0.5


@njit(cache=False)
def potential(law_id, prm, delta, q):
    """kernels.potential is compiled for compiled callers only (no Python wrapper): called through this."""
    return kernels.potential(law_id, prm, delta, q)


def law_of(name: str) -> laws.ContactLaw:
    return laws.LAWS[name](law=name, **EXAMPLES["contact_laws"][name])


def link_of(name: str) -> links.LinkLaw:
    return links.LINK_LAWS[name](law=name, **EXAMPLES["links"][name])


def model_of(name: str) -> hysteresis.StoreyHysteresis:
    return hysteresis.HYSTERESES[name](model=name, **EXAMPLES["hysteresis"][name])


def internal_states(law: laws.ContactLaw, prm: np.ndarray, delta: float) -> list[float]:
    """Internal states q worth sampling at *delta*: the bilinear loop's edges and middle; ξh of an engaged bumper."""
    if isinstance(law, laws.Bilinear):
        k1, k2, dy = law.stiffnesses
        lower, upper = k2 * delta, (k1 * delta if delta <= dy else k1 * dy + k2 * (delta - dy))
        return [lower, 0.5 * (lower + upper), upper]
    if isinstance(law, laws.Bumper) and delta > law.limit:
        return [law.p * law.kh / V0]
    return [0.0]


def reachable_modes(law_id: int, prm: np.ndarray) -> set[int]:
    """Modes a closed contact can be in: the onset modes and every next_mode of their switches."""
    found = {int(kernels.onset_mode(law_id, prm, V0)), int(kernels.onset_mode(law_id, prm, -V0))}
    todo = list(found)
    while todo:
        mode = todo.pop()
        for which in range(int(kernels.switch_count(law_id, prm))):
            new = int(kernels.next_mode(law_id, mode, which))
            if new not in found:
                found.add(new)
                todo.append(new)
    return found


# --------------------------------------------------------------------------- #
# Every entry: an example row, a compiled branch, an OpenSees answer
# --------------------------------------------------------------------------- #


def test_every_entry_has_an_example_row():
    assert set(EXAMPLES["contact_laws"]) == set(laws.LAWS)
    assert set(EXAMPLES["links"]) == set(links.LINK_LAWS)
    assert set(EXAMPLES["hysteresis"]) == set(hysteresis.HYSTERESES)


@pytest.mark.parametrize("name", list(laws.LAWS))
def test_contact_law_has_a_compiled_branch(name):
    # A missing branch falls through to 0.0 N / 0 N·s: a closing contact at 1 mm must push, or (the bilinear
    # law, whose force is its internal state, 0 at closure) its internal state must move.
    law = law_of(name)
    prm = law.kernel_parameters(*MASSES)
    if law.instantaneous:
        assert kernels.is_instantaneous(law.law_id)
        assert kernels.jump_impulse(law.law_id, prm, V0) > 0.0
        return
    assert not kernels.is_instantaneous(law.law_id)
    const = kernels.onset_constant(law.law_id, prm, V0)
    mode = kernels.onset_mode(law.law_id, prm, V0)
    assert kernels.mode_force(law.law_id, prm, const, mode, 1e-3, 0.1, 0.0) > 0.0 or \
        kernels.mode_internal_rate(law.law_id, prm, mode, 1e-3, 0.1) > 0.0
    assert potential(law.law_id, prm, 1e-3, 0.0) > 0.0
    assert kernels.contact_duration(law.law_id, prm, V0, 1e5) > 0.0


@pytest.mark.parametrize("name", list(links.LINK_LAWS))
def test_link_has_a_compiled_branch(name):
    # A missing branch gives 0 N; every link resists a relative velocity (a Maxwell element through q̇).
    link = link_of(name)
    prm = link.kernel_parameters()
    assert kernels.is_permanent(link.law_id)
    moving = abs(kernels.link_force(link.law_id, prm, 0.0, 0.1, 0.0)) + \
        abs(kernels.link_internal_rate(link.law_id, prm, 0.1, 0.0))
    assert moving > 0.0


@pytest.mark.parametrize("name", list(hysteresis.HYSTERESES))
def test_hysteresis_has_a_compiled_branch(name):
    # The elastic fall-through has no state rate; every model's state moves in some mode.
    model = model_of(name)
    k, h = 1.0e8, 3.0
    table = model.kernel_parameters(k, h)[None, :]
    rates = [storeys.state_rate(model.model_id, table, 0, mode, 0.1, 0.0)
             for mode in (storeys.ELASTIC, storeys.YIELD_POSITIVE)]
    assert any(r != 0.0 for r in rates)


@pytest.mark.parametrize("key", list(xi.FORMULAS))
def test_xi_formula_reaches_the_compiled_onset_constant(key):
    # ξ = p(e)·kh/v0 at the located closure: the kernel multiplies the packed p, in the same order.
    law = laws.HertzDamp(kh=2.0e9, restitution=0.5, xi=key)
    prm = law.kernel_parameters(*MASSES)
    p = xi.FORMULAS[key](0.5)
    assert math.isfinite(p) and p > 0.0
    assert xi.FORMULAS[key](1.0) == pytest.approx(0.0, abs=1e-12)  # e = 1: no damping (root finder: ~1e-16)
    assert kernels.onset_constant(law.law_id, prm, V0) == p * 2.0e9 / V0


def one_line_refusal(call, name: str) -> None:
    try:
        call()
    except PoundingError as exc:
        message = str(exc)
        assert f"'{name}'" in message and "\n" not in message, message
        return


@pytest.mark.parametrize("name", list(laws.LAWS))
def test_opensees_exports_or_refuses_contact_law_by_name(name):
    law = law_of(name)
    try:
        material, notes = opensees_materials.contact_material(law, 0.01)
    except PoundingError:
        one_line_refusal(lambda: opensees_materials.contact_material(law, 0.01), name)
        return
    assert isinstance(material[0], str) and all(isinstance(x, float) for x in material[1:])


@pytest.mark.parametrize("key", list(xi.FORMULAS))
def test_opensees_exports_every_xi_formula(key):
    law = laws.HertzDamp(kh=2.0e9, restitution=0.5, xi=key, tension="allow")
    material, _ = opensees_materials.contact_material(law, 0.01)
    assert material == ["Hertzdamp", 2.0e9, xi.FORMULAS[key](0.5), -0.01]


@pytest.mark.parametrize("name", list(links.LINK_LAWS))
def test_opensees_exports_or_refuses_link_by_name(name):
    link = link_of(name)
    try:
        parts = opensees_materials.link_materials(link, 1)
    except PoundingError:
        one_line_refusal(lambda: opensees_materials.link_materials(link, 1), name)
        return
    assert parts and all(isinstance(p[1], str) for p in parts)


@pytest.mark.parametrize("name", list(hysteresis.HYSTERESES))
def test_opensees_exports_or_refuses_hysteresis_by_name(name):
    model = model_of(name)
    try:
        material = opensees.storey_material(model, 1.0e8, 3.0)
    except PoundingError:
        one_line_refusal(lambda: opensees.storey_material(model, 1.0e8, 3.0), name)
        return
    assert isinstance(material[0], str)


# --------------------------------------------------------------------------- #
# Checks of a kind, as each class declares
# --------------------------------------------------------------------------- #


def check_implied_mode_force(law: laws.ContactLaw) -> None:
    """In every reachable mode whose switch functions all hold (> 0), the mode force is the implied-mode force.

    The solver integrates ``mode_force`` in the mode its located events left
    it in; ``force`` (what the ball drop used to integrate) picks the mode
    from the state.  Where both are defined they must be the same number:
    exact equality, since they are the same formula.
    """
    prm = law.kernel_parameters(*MASSES)
    const = kernels.onset_constant(law.law_id, prm, V0)
    modes = reachable_modes(law.law_id, prm)
    compared = 0
    for delta, rate in itertools.product(DELTAS, RATES):
        for q in internal_states(law, prm, delta):
            for mode in modes:
                holds = all(kernels.switch_value(law.law_id, prm, const, mode, which, delta, rate, q) > 0.0
                            for which in range(kernels.switch_count(law.law_id, prm)))
                if holds:
                    compared += 1
                    assert kernels.mode_force(law.law_id, prm, const, mode, delta, rate, q) == \
                        kernels.force(law.law_id, prm, const, delta, rate, q), (mode, delta, rate, q)
    assert compared > 0


def check_elastic_potential(law) -> None:
    """The elastic force is the derivative of the stored energy: dV/dδ = F at δ̇ = 0.

    Central difference with h = 1e-6·δ: truncation ~h²·V''' ~ 1e-12 relative
    for these smooth laws, rounding ~eps·V/h ~ 1e-10 relative: 1e-6 bounds both
    with margin and still fails a wrong exponent or factor (≥ 1e-1 off).
    """
    if isinstance(law, links.LinkLaw):
        prm = law.kernel_parameters()
        samples = [(d, 0.0) for d in (-1e-2, -1e-3, 1e-3, 1e-2)]
    else:
        prm = law.kernel_parameters(*MASSES)
        samples = [(d, q) for d in DELTAS for q in internal_states(law, prm, d)]
    for delta, q in samples:
        h = 1e-6 * abs(delta)
        dv = (potential(law.law_id, prm, delta + h, q) - potential(law.law_id, prm, delta - h, q)) / (2 * h)
        f = kernels.force(law.law_id, prm, 0.0, delta, 0.0, q)
        assert dv == pytest.approx(f, rel=1e-6, abs=1e-9), (delta, q, dv, f)


def check_never_pulls(law: laws.ContactLaw) -> None:
    """A closed contact's force is ≥ 0 in the state's mode (clamped laws, laws damped only while approaching)."""
    prm = law.kernel_parameters(*MASSES)
    const = kernels.onset_constant(law.law_id, prm, V0)
    for delta, rate in itertools.product(DELTAS, RATES):
        for q in internal_states(law, prm, delta):
            assert kernels.force(law.law_id, prm, const, delta, rate, q) >= 0.0, (delta, rate, q)


def check_dissipation_nonnegative(law) -> None:
    """Power in minus the stored energy's rate is ≥ 0: F·δ̇ − dV/dt ≥ 0 (no element creates energy).

    dV/dt by a central difference along the state's own rates (δ̇, q̇) over
    h = 1e-7·δ/|δ̇|; tolerance 1e-6 of |F·δ̇| + |dV/dt| (rounding and
    truncation are ~1e-9 of that) and 1e-9 W absolute for states at rest.
    """
    if isinstance(law, links.LinkLaw):
        prm = law.kernel_parameters()
        samples = [(d, r, q) for d in (-1e-2, 1e-3) for r in RATES for q in (-1e5, 0.0, 1e5)]
        rate_of_q = lambda d, r, q: kernels.link_internal_rate(law.law_id, prm, r, q)  # noqa: E731
        const = 0.0
    else:
        prm = law.kernel_parameters(*MASSES)
        samples = [(d, r, q) for d in DELTAS for r in RATES for q in internal_states(law, prm, d)]
        rate_of_q = lambda d, r, q: kernels.internal_rate(law.law_id, prm, d, r, q)  # noqa: E731
        const = kernels.onset_constant(law.law_id, prm, V0)
    for delta, rate, q in samples:
        if rate == 0.0:
            continue
        f = kernels.force(law.law_id, prm, const, delta, rate, q)
        q_rate = rate_of_q(delta, rate, q)
        h = 1e-7 * abs(delta) / abs(rate)
        dv = (potential(law.law_id, prm, delta + h * rate, q + h * q_rate)
              - potential(law.law_id, prm, delta - h * rate, q - h * q_rate)) / (2 * h)
        power = f * rate
        assert power - dv >= -1e-6 * (abs(power) + abs(dv)) - 1e-9, (delta, rate, q, power, dv)


def check_free_restitution(law: laws.ContactLaw) -> None:
    """A free impact (no gravity) on a rigid body rebounds with the law's own restitution.

    Integrated with the solver's routines (pounding.studies.verify.contact_phase,
    DOP853 at rtol 1e-12); 1e-6 is the bound of tests/test_verify.py for an
    exact relation (the integration error is ~1e-10).
    """
    mass, v0 = 1.0e3, V0
    prm = law.kernel_parameters(mass, RIGID_MASS)
    if law.instantaneous:
        rebound = kernels.jump_impulse(law.law_id, prm, v0) / mass - v0
    else:
        const = kernels.onset_constant(law.law_id, prm, v0)
        duration = kernels.contact_duration(law.law_id, prm, v0, mass)
        scale = v0 * duration
        atol = [RTOL * scale, RTOL * v0, RTOL * scale * prm[0]]
        rebound, _, _ = contact_phase(law.law_id, prm, const, v0, mass=mass, gravity=0.0, t_contact=duration,
                                      atol=atol, where=law.name)
    assert rebound / v0 == pytest.approx(law.restitution, abs=1e-6)


def check_bounded_state(model: hysteresis.StoreyHysteresis) -> None:
    """Bouc–Wen with A = 1, β + γ = 1: at |z| = 1 the state does not grow outward (|z| ≤ 1)."""
    table = model.kernel_parameters(1.0e8, 3.0)[None, :]
    for z, rate in itertools.product((-1.0, 1.0), (-0.1, 0.1)):
        assert z * storeys.state_rate(model.model_id, table, 0, storeys.ELASTIC, rate, z) <= 1e-12


def check_hysteresis_elastic_potential(model: hysteresis.StoreyHysteresis) -> None:
    """Recoverable energy V(Δ, r) at fixed state: dV/dΔ = restoring force (central difference, as above)."""
    k, h = 1.0e8, 3.0
    table = model.kernel_parameters(k, h)[None, :]
    uy = table[0, 0]
    for drift, r in itertools.product((-3 * uy, -0.5 * uy, 0.5 * uy, 3 * uy), (-uy, 0.0, 2 * uy)):
        step = 1e-6 * abs(drift)
        dv = (storeys.recoverable_energy(model.model_id, table, 0, k, drift + step, r)
              - storeys.recoverable_energy(model.model_id, table, 0, k, drift - step, r)) / (2 * step)
        f = storeys.restoring_force(model.model_id, table, 0, k, drift, r)
        assert dv == pytest.approx(f, rel=1e-6), (drift, r)


def check_hysteresis_dissipation(model: hysteresis.StoreyHysteresis) -> None:
    """F·Δ̇ − dV/dt ≥ 0 in the mode the state is in (bilinear: elastic inside, yielding on the edge outward)."""
    k, h = 1.0e8, 3.0
    table = model.kernel_parameters(k, h)[None, :]
    uy = table[0, 0]
    if isinstance(model, hysteresis.BilinearStorey):
        states = [(0.5 * uy, 0.0, storeys.ELASTIC, 0.1), (0.5 * uy, 0.0, storeys.ELASTIC, -0.1),
                  (3 * uy, 2 * uy, storeys.YIELD_POSITIVE, 0.1), (-3 * uy, -2 * uy, storeys.YIELD_NEGATIVE, -0.1)]
    else:
        states = [(d, z, storeys.ELASTIC, r) for d in (-2 * uy, 0.5 * uy, 2 * uy) for z in (-0.9, 0.0, 0.5, 1.0)
                  for r in (-0.1, 0.1)]
    for drift, r, mode, rate in states:
        f = storeys.restoring_force(model.model_id, table, 0, k, drift, r)
        r_rate = storeys.state_rate(model.model_id, table, 0, mode, rate, r)
        step = 1e-7 * abs(drift) / abs(rate)
        dv = (storeys.recoverable_energy(model.model_id, table, 0, k, drift + step * rate, r + step * r_rate)
              - storeys.recoverable_energy(model.model_id, table, 0, k, drift - step * rate, r - step * r_rate)) / (2 * step)
        assert f * rate - dv >= -1e-6 * (abs(f * rate) + abs(dv)), (drift, r, mode, rate)


def check_cyclic_response(model: hysteresis.StoreyHysteresis) -> None:
    """Driven alone through FEMA 461 cycles to 6 % drift: the work done on the storey is ≥ 0 at every
    return to zero drift (no model creates energy over a cycle) and |F| stays within the highest capping
    force (a deteriorating backbone only shrinks)."""
    from pounding.studies import cyclic

    k, h = 1.0e8, 3.0
    drifts = cyclic.named_protocol("fema461", 0.06 * h)
    shear = cyclic.storey_response(model, k, h, drifts)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (shear[1:] + shear[:-1]) * np.diff(drifts))])
    cap = max(model.backbone(k, h)[s]["fy"] * model.backbone(k, h)[s]["fcap_ratio"] for s in ("positive", "negative"))
    assert np.all(work[drifts == 0.0] >= -1e-9 * cap * h)
    assert np.abs(shear).max() <= cap * (1.0 + 1e-12)
    assert np.abs(shear).max() > 0.5 * cap


CONTACT_CHECKS = {"implied_mode_force": check_implied_mode_force, "elastic_potential": check_elastic_potential,
                  "never_pulls": check_never_pulls, "dissipation_nonnegative": check_dissipation_nonnegative,
                  "free_restitution": check_free_restitution}
LINK_CHECKS = {"elastic_potential": check_elastic_potential, "dissipation_nonnegative": check_dissipation_nonnegative}
HYSTERESIS_CHECKS = {"elastic_potential": check_hysteresis_elastic_potential,
                     "dissipation_nonnegative": check_hysteresis_dissipation, "bounded_state": check_bounded_state,
                     "cyclic_response": check_cyclic_response}

CASES = ([("contact", n, c) for n, cls in laws.LAWS.items() for c in cls.checks]
         + [("link", n, c) for n, cls in links.LINK_LAWS.items() for c in cls.checks]
         + [("hysteresis", n, c) for n, cls in hysteresis.HYSTERESES.items() for c in cls.checks])


@pytest.mark.parametrize("kind, name, check", CASES, ids=[f"{k}:{n}:{c}" for k, n, c in CASES])
def test_declared_check(kind, name, check):
    table, build = {"contact": (CONTACT_CHECKS, law_of), "link": (LINK_CHECKS, link_of),
                    "hysteresis": (HYSTERESIS_CHECKS, model_of)}[kind]
    assert check in table, f"{kind} {name} declares check '{check}', which this file does not define"
    table[check](build(name))


def test_every_check_is_declared_and_used():
    for kind, table in (("contact", CONTACT_CHECKS), ("link", LINK_CHECKS), ("hysteresis", HYSTERESIS_CHECKS)):
        used = {c for k, _, c in CASES if k == kind}
        assert used == set(table), (kind, set(table) - used, used - set(table))


def test_a_wrong_potential_fails_the_check(monkeypatch):
    # The checks can fail: a law whose force disagrees with its stored energy is caught.
    law = law_of("linear")
    monkeypatch.setattr(law.__class__, "kernel_parameters", lambda self, m1, m2: np.array([5e8] + [0.0] * 7))
    monkeypatch.setitem(globals(), "potential", lambda i, prm, d, q, original=potential: 1.01 * original(i, prm, d, q))
    with pytest.raises(AssertionError):
        check_elastic_potential(law)


def test_ids_come_from_the_registries():
    assert [cls.law_id for cls in laws.LAWS.values()] == list(range(len(laws.LAWS)))
    assert [cls.law_id for cls in links.LINK_LAWS.values()] == list(
        range(links.FIRST_LINK_ID, links.FIRST_LINK_ID + len(links.LINK_LAWS)))
    assert [cls.model_id for cls in hysteresis.HYSTERESES.values()] == list(range(1, 1 + len(hysteresis.HYSTERESES)))
    with pytest.raises(ValueError, match="registered twice"):
        laws.register(laws.Linear)


@pytest.mark.parametrize("name", [n for n, cls in laws.LAWS.items() if not cls.instantaneous])
def test_modes_leave_the_stuck_mode_to_the_solver(name):
    # MODE_STUCK (3) is the solver's resting stereo-mechanical contact: a law's own mode must never be 3,
    # and a mode has at most N_SWITCHES switch functions (the solver's event arrays are that wide).
    law = law_of(name)
    prm = law.kernel_parameters(*MASSES)
    assert kernels.MODE_STUCK not in reachable_modes(law.law_id, prm)
    assert 0 <= kernels.switch_count(law.law_id, prm) <= kernels.N_SWITCHES


@pytest.mark.parametrize("name", [n for n, cls in laws.LAWS.items() if cls.kernels is not None])
def test_law_modules_are_in_every_solver_cache_stamp(name):
    # Editing a law's own module must recompile the cached solver that inlines its kernels.
    import sys

    from pounding.solver import jit

    assert sys.modules[laws.LAWS[name].__module__].__file__ in jit.EXTRA_SOURCES


@pytest.mark.parametrize("name", list(hysteresis.HYSTERESES))
def test_storey_modes_follow_the_integrators_rule(name):
    # The integrator's storey-event search gives modes (yield onset, unloading; IMK branch changes) to the
    # bilinear and IMK models only, by id (pounding.solver.storey_events). A new model with modes fails here
    # until that search reads StoreyHysteresis.has_modes instead of the id.
    cls = hysteresis.HYSTERESES[name]
    assert cls.has_modes == (cls.model_id in (hysteresis.MODEL_BILINEAR, hysteresis.MODEL_IMK_BILINEAR,
                                              hysteresis.MODEL_IMK_PEAK, hysteresis.MODEL_IMK_PINCHING))


def test_the_checks_bite():
    # Each check fails on an element that breaks it: the pull of Kelvin with tension allowed, the restitution
    # of Hertz-damp with the ye formula (it over-damps: 0.47 for 0.5), energy created by a negative damper
    # (built without validation, which would refuse it).
    with pytest.raises(AssertionError):
        check_never_pulls(laws.Kelvin(k=5.0e8, restitution=0.5, tension="allow"))
    with pytest.raises(AssertionError):
        check_free_restitution(laws.HertzDamp(kh=2.0e9, restitution=0.5, xi="ye"))
    with pytest.raises(AssertionError):
        check_dissipation_nonnegative(links.KelvinLink.model_construct(law="kelvin", stiffness=1.0e7,
                                                                       damping=-1.0e6))
