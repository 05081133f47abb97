"""Coulomb friction on the faces of a plan model: the forces (slipping) and the stick constraints.

docs/physics.md, "Coulomb friction on a face": a face's slip rate ``v_t`` is the same at all its
points (each building's lever arm to its own face); its normal force N is the sum of its points'
contact forces (never below 0).

* **Slipping** (direction s = ±1): the friction is ``λ = μ N s``, resisting the slip.
* **Sticking**: λ is the constraint force that keeps ``v̇_t = 0``; the sticking faces are solved
  together (Gauss–Seidel sweeps on their Delassus operator, exact in one sweep when no two
  sticking faces share a floor), so several sticking faces of one floor hold jointly.

λ enters the floors as ``weights·λ`` (virtual work) and its power ``λ·v_t`` (≥ 0) is each face's
dissipated energy, a state of its own (``Layout.friction_work``).  The modes change only at located
events (:mod:`pounding.solver.friction_events`); the right-hand side (:mod:`pounding.solver.rhs`)
calls :func:`friction_forces` after every contact force.
"""

from __future__ import annotations

from numba import njit

from pounding.solver import jit
from pounding.solver.kinematics import combo, compliance, push

__all__ = ["FRICTION_OFF", "FRICTION_SLIP", "FRICTION_STICK", "friction_forces", "stick_margin"]

#: A face's modes: open (no point closed), slipping, sticking.
FRICTION_OFF, FRICTION_SLIP, FRICTION_STICK = 0, 1, 2
#: Gauss–Seidel sweeps of the sticking faces (converged far sooner: one sweep when no floor is shared).
STICK_SWEEPS = 100


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _ground_term(friction, f, ag_t, ground) -> float:
    """Σ_k w_k·a_g,k (m/s²): the ground acceleration's part of the face's relative slip acceleration."""
    total = 0.0
    terms = len(friction.width)
    for k in range(terms * f, terms * f + terms):
        if ground is None:
            total += friction.weights[k] * ag_t
        else:
            total += friction.weights[k] * ground.now[0, ground.floor_row[friction.floors[k]]]
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _stick(friction, mass, fbuf, ag_t, ground) -> None:
    """Add the sticking faces' constraint forces (``v̇_t = 0``) to ``friction.force`` and *fbuf*."""
    ff, fw, width = friction.floors, friction.weights, friction.width
    terms = len(width)
    for _ in range(STICK_SWEEPS):
        largest = 0.0
        scale = 0.0
        for f in range(friction.mode.size):
            if friction.mode[f] != FRICTION_STICK:
                continue
            rate = -_ground_term(friction, f, ag_t, ground)
            for k in range(terms * f, terms * f + terms):
                rate -= fw[k] * fbuf[ff[k]] / mass[ff[k]]
            change = rate / compliance(mass, ff, fw, width, f)
            friction.force[f] += change
            push(fbuf, ff, fw, width, f, change)
            largest = max(largest, abs(change))
            scale = max(scale, abs(friction.force[f]))
        if largest <= 1e-13 * scale:
            break


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def friction_forces(y, ag_t, mass, friction, forces, fbuf, out, first_work, ground) -> None:
    """Each face's N and λ (``friction.normal``, ``friction.force``), λ into the floor forces *fbuf*,
    and its dissipated power ``λ·v_t`` into ``out[first_work + f]`` (W).

    Called by the right-hand side after every contact force (*forces*) is in *fbuf*.
    """
    n = mass.size
    ff, fw, width = friction.floors, friction.weights, friction.width
    n_stick = 0
    for f in range(friction.mode.size):
        normal = 0.0
        for c in range(friction.first_point[f], friction.first_point[f] + friction.point_count[f]):
            normal += forces[c]
        friction.normal[f] = max(normal, 0.0)
        force = 0.0
        if friction.mode[f] == FRICTION_SLIP:
            force = friction.coefficient[f] * friction.normal[f] * friction.direction[f]
            push(fbuf, ff, fw, width, f, force)
        elif friction.mode[f] == FRICTION_STICK:
            n_stick += 1
        friction.force[f] = force
    if n_stick > 0:
        _stick(friction, mass, fbuf, ag_t, ground)
    for f in range(friction.mode.size):
        out[first_work + f] = friction.force[f] * combo(y, n, ff, fw, width, f)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def stick_margin(friction, f) -> float:
    """μN − |λ| of a sticking face at the last right-hand side (N; < 0: the stick is lost)."""
    return friction.coefficient[f] * friction.normal[f] - abs(friction.force[f])


jit.stamp_solver_kernels(globals())
