"""Located and pending events, of any kind: the bookkeeping of the driver's retaken steps.

Each kind of event — a contact's, a yielding storey's, a friction face's — keeps three arrays: the
located event of each element (its kind code, 0 for none), its fraction of the trial step, and the
event the retaken step was shortened to end at (pending).  The driver (:mod:`pounding.solver.integrator`)
marks, drops and restores them for every kind alike, with these kernels.
"""

from __future__ import annotations

from numba import njit

from pounding.solver import jit

__all__ = ["NO_EVENT", "mark_pending", "drop_later", "add_pending"]

#: Every kind's code for "no event" (contact_events.EVENT_NONE, storey_events.STOREY_NONE,
#: friction_events.FRICTION_EVENT_NONE).
NO_EVENT = 0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def mark_pending(kind, s, pending, s_first) -> None:
    """Mark the events at or before fraction *s_first* as those the retaken step ends at (all others
    cleared; *s_first* < 0 clears every one)."""
    for i in range(kind.size):
        ok = s_first >= 0.0 and kind[i] != NO_EVENT and s[i] <= s_first
        pending[i] = kind[i] if ok else NO_EVENT


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def drop_later(kind, s, h, tiny) -> None:
    """Drop the located events later than *tiny* seconds into a step of *h* s (those at its start stay)."""
    for i in range(kind.size):
        if kind[i] != NO_EVENT and s[i] * h > tiny:
            kind[i] = NO_EVENT


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.INLINED, **jit.NO_REFCOUNT)
def add_pending(kind, pending) -> bool:
    """Add the pending events to the located ones; any left?"""
    found = False
    for i in range(kind.size):
        if kind[i] == NO_EVENT:
            kind[i] = pending[i]
        if kind[i] != NO_EVENT:
            found = True
    return found


jit.stamp_solver_kernels(globals())
