"""An independent reference for a shear building with IMK storeys: scipy ``solve_ivp``.

Shares nothing with ``pounding.solver``: the storey shears come from the
drift-driven material of ``pounding.studies.imk`` (the strain-driven rules,
checked against OpenSees in tests/test_imk.py), evaluated as a trial step from
its state at the last event; every place where that shear can change branch
is a terminal event after which the material is committed there and the
integration restarts: each storey's drift turning back, and its drift reaching
any point where a branch of its material ends (yield, capping, residual,
ultimate drifts of both directions, the last and global peaks, the pinching
point, the zero-force drift of the unloading line and, for ``imk-bilinear``, the
unloading line meeting the backbone).  Committing at a point that is not a
kink changes nothing (the rules are exact for a piecewise-linear drift
history), so a superfluous event costs time only.  DOP853 at a tight
tolerance between record samples; peaks on a fine grid of the dense output.
"""

from __future__ import annotations

import copy

import numpy as np
from scipy.integrate import solve_ivp

from inelastic_reference import Row, _drift, floor_forces
from pounding.hysteresis import ImkStorey
from pounding.studies.imk import ImkMaterial


#: Immutable types of an ImkMaterial's state, kept as they are by :func:`_copied`.
_SCALARS = frozenset({bool, int, float, str, np.float64, np.int64, np.bool_})


def _clone(material: ImkMaterial) -> ImkMaterial:
    """A deep copy of *material*, several times faster than ``copy.deepcopy`` (which took 80 % of a reference
    run): its numbers and flags are immutable, its dicts (the two Backbone records, the lost flags) are copied
    with their items; anything else is deep-copied."""
    return _copied(material)


def _copied(value):
    """*value* itself if immutable, a copy of its __dict__'s items, a dict of copies, else a deepcopy."""
    kind = type(value)
    if kind in _SCALARS:
        return value
    if kind is dict:
        return {k: _copied(v) for k, v in value.items()}
    if hasattr(value, "__dict__") and not hasattr(kind, "__slots__"):
        new = object.__new__(kind)
        new.__dict__ = {k: v if type(v) in _SCALARS else _copied(v) for k, v in value.__dict__.items()}
        return new
    return copy.deepcopy(value)


def _trial(material: ImkMaterial, u: float) -> float:
    return _clone(material).step(u)


def _kinks(material: ImkMaterial, ahead: bool = True) -> list[float]:
    """Every drift (m) where the material's branch can change, from its current state and (*ahead*) from
    the state past the zero-force point ahead, whose new excursion moves the backbone."""
    points = []
    for sigma, b in material.sides.items():
        rise = b.ucap + (b.fres - b.fcap) / b.kp if b.kp > 0 else np.nan
        # The residual drift of the current backbone (ImkMaterial keeps b.ures for the oriented variants only).
        ures = b.ucap + (b.fres - b.fcap) / b.kpc if b.kpc != 0 else np.nan
        for x in (b.uy, b.ucap, b.ures, ures, b.uu, b.u_local, b.u_global, rise):
            points.append(sigma * x)
    points.append(material.u_pinch)
    u, f, k = material.u, material.f, material.k_unload
    if (material.branch > 1 or material.on_backbone) and f != 0.0:
        # Just turned on a loading branch: the unloading stiffness ahead is the one the reversal deteriorates,
        # which the material applies at its next step (a step back toward zero force triggers it).
        probe = _clone(material)
        probe.step(u - 1e-9 * np.sign(f))
        k = probe.k_unload
    if k > 0 and f != 0.0:
        zero = u - f / k
        points.append(zero)
        if ahead:
            probe = _clone(material)
            probe.step(zero + 1e-9 * np.sign(zero - u))
            points += _kinks(probe, ahead=False)
    if material.variant == "bilinear":
        for sigma, b in material.sides.items():
            x0, f0 = sigma * u, sigma * f
            for slope in (b.kp, b.kpc):
                if k != slope:
                    points.append(sigma * (b.fcap - slope * b.ucap - f0 + k * x0) / (k - slope))
            if k > 0:
                points.append(sigma * (x0 + (b.fres - f0) / k))
    return [p for p in points if np.isfinite(p)]


def imk_reference_run(model, ag: np.ndarray, dt: float, duration: float, *, rtol: float = 1e-11,
                      sample: float = 2e-5) -> dict:
    """Integrate a model of one building with IMK storeys under *ag* (m/s², step *dt*): peaks and more."""
    row = Row(model)
    n = row.n
    laws = [law for b in model.buildings for law in b.hysteresis]
    materials = [ImkMaterial(law, row.k[j], row.h[j]) if isinstance(law, ImkStorey) else None
                 for j, law in enumerate(laws)]
    branches = [set() for _ in range(n)]
    y = np.zeros(2 * n)
    peak_drift = np.zeros(n)

    def shear(j, d):
        return _trial(materials[j], d) if materials[j] is not None else row.k[j] * d

    def rhs(t, y, a_g):
        return np.concatenate([y[n:], -floor_forces(row, y, shear) / row.mass - a_g])

    def events_for(y):
        found = []
        for j, material in enumerate(materials):
            if material is None or material.failed:
                continue
            d, v = _drift(row, y, j)
            for point in _kinks(material):
                if abs(point - d) <= 1e-9:
                    continue  # the kink just committed at (its event is located to ~1e-12 m)

                def ev(t, yy, *args, j=j, point=point):
                    return _drift(row, yy, j)[0] - point
                ev.terminal = True
                ev.direction = 1 if point > d else -1
                found.append((ev, j, point))

            if abs(v) < 1e-9:
                continue  # at rest or just turned: a zero at the start would end the integration there

            def turn(t, yy, *args, j=j):
                return _drift(row, yy, j)[1]
            turn.terminal = True
            turn.direction = -np.sign(v)
            found.append((turn, j, None))
        return found

    def resting(y):
        """A storey whose drift rate is ~0 (its turn is not watched): integrate 0.1 ms at a time."""
        return any(m is not None and not m.failed and abs(_drift(row, y, j)[1]) < 1e-9 for j, m in enumerate(materials))

    history = {}

    def track(sol, a, b):
        nonlocal peak_drift
        for k in range(int(np.ceil(a / 0.01 - 1e-9)), int(np.floor(b / 0.01 + 1e-9)) + 1):
            state = sol.sol(min(max(k * 0.01, a), b))
            history[k] = np.array([_drift(row, state, j)[0] for j in range(n)]
                                  + [shear(j, _drift(row, state, j)[0]) for j in range(n)])
        grid = np.linspace(a, b, max(2, int(np.ceil((b - a) / sample)) + 1))
        u = sol.sol(grid)[:n]
        drift = u.copy()
        for j in range(n):
            if row.below[j] >= 0:
                drift[j] -= u[row.below[j]]
        peak_drift = np.maximum(peak_drift, np.abs(drift).max(axis=1))

    collapsed = None
    samples = np.arange(int(round(duration / dt)) + 1) * dt
    n_events = 0
    for i in range(samples.size - 1):
        t0, t1 = samples[i], samples[i + 1]
        g0, g1 = ag[i], ag[i + 1] if i + 1 < ag.size else ag[-1]
        t = t0
        while t < t1 - 1e-15 and collapsed is None:
            evs = events_for(y)
            end = min(t1, t + 1e-4) if resting(y) else t1
            sol = solve_ivp(lambda tt, yy: rhs(tt, yy, g0 + (g1 - g0) * (tt - t0) / dt), (t, end), y,
                            method="DOP853", rtol=rtol, atol=rtol * 1e-3, dense_output=True,
                            events=[e for e, _, _ in evs])
            if sol.status != 1:
                track(sol, t, end)
                y = sol.y[:, -1]
                t = end
                continue
            te = sol.t[-1]
            if te <= t:
                raise RuntimeError(f"a terminal event at the start of the integration (t = {t})")
            track(sol, t, te)
            y = sol.y[:, -1]
            t = te
            n_events += 1
            fired = {evs[i][1]: evs[i][2] for i, times in enumerate(sol.t_events) if times.size}
            for j, material in enumerate(materials):
                if material is not None:
                    # A kink is crossed in a step of 2e-12 m around it: the material, like OpenSees, reads
                    # the energy of its deterioration rules at the start of the step that changes the
                    # branch, and its energy is a trapezoid per step: both exact only for a short step
                    # across the kink (the solver's limit: zero).
                    point = fired.get(j)
                    d = _drift(row, y, j)[0]
                    if point is not None and point not in (material.sides[1].uu, -material.sides[-1].uu):
                        side = np.sign(_drift(row, y, j)[1])  # the direction of motion
                        material.step(point - 1e-12 * side)
                        d = point + 1e-12 * side
                    elif point is not None:
                        d = point  # the ultimate drift: reached (u ≥ θ_u h), zero strength from here
                    material.step(d)
                    branches[j].add(material.branch)
                    if material.residual:  # imk-bilinear's residual flag
                        branches[j].add(7)
                    if (material.failed or any(material.lost.values())) and collapsed is None:
                        collapsed = (j, te)
        if collapsed is not None:
            break
    final_drift = np.array([_drift(row, y, j)[0] for j in range(n)])
    for j, material in enumerate(materials):
        if material is not None and collapsed is None:
            material.step(final_drift[j])
    return {"peak_drift": peak_drift, "final_drift": final_drift, "branches": branches, "events": n_events,
            "collapse": collapsed, "time": t, "history": history,
            "energy": [m.energy if m is not None else 0.0 for m in materials]}
