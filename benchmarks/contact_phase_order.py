"""Steps and right-hand-side evaluations per impact of a higher-order Runge–Kutta pair: Dormand–Prince 5(4)
against Dormand–Prince 8(5,3), on the same equations (a measurement for planning, not a feature).

    python benchmarks/contact_phase_order.py                  # models/pair.yaml, rtol 1e-6 (~15 s)
    python benchmarks/contact_phase_order.py --rtol 1e-8 --free-steps

Would contact phases (an impact under way) be cheaper with a higher-order pair?  ``pounding``'s solver uses
Dormand–Prince 5(4) (six new right-hand sides a step).  This script integrates the same model with scipy's
implementations of both pairs, ``RK45`` (the same tableau) and ``DOP853`` (twelve a step, three more for
the dense output that event location needs), and counts, for each, the accepted steps and the evaluations
spent while a contact is closed, per impact:

* the model's linear matrices (``pounding.solver.closed_form.linear_matrices``: storeys, P-Delta,
  damping), its Hertz-damp contacts with ξ from each impact's approach velocity by the model's own formula
  (``GapElement.law.damping_constant``), under the run's ground acceleration (its record, linear between
  samples);
* contact closure and opening located as scipy events (terminal), the phase restarted after each;
* by default every step ends at a record sample, as ``pounding``'s steps do (the ground acceleration has a
  kink there); ``--free-steps`` lets the steps straddle samples over a cubic spline of the record instead
  (what a pair could do on a smooth forcing).

Both pairs are scored on the model's own tolerances (``--rtol`` scales rtol and atol together).  The
impact counts are printed beside ``pounding``'s own run.  ``--out DIR`` receives ``contact_phase_order.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402


class Equations:
    """The model's equations of motion with its contacts, as scipy integrates them (relative coordinates)."""

    def __init__(self, model, ds, free_steps: bool) -> None:
        from scipy.interpolate import CubicSpline

        from pounding.solver.assembly import assemble
        from pounding.solver.closed_form import linear_matrices

        system = assemble(model).system
        mass, self.damping, self.stiffness = linear_matrices(system)
        self.n = mass.shape[0]
        self.inverse_mass = 1.0 / np.diag(mass)
        time_, ground = ds.time.values, ds.ground_acceleration.values
        self.record_step = float(time_[1] - time_[0])
        self.ground = CubicSpline(time_, ground) if free_steps else (lambda t: np.interp(t, time_, ground))
        self.contacts = [(model.floor_offset(g.left) + g.level_left - 1, model.floor_offset(g.right) + g.level_right - 1,
                          g.gap, g.law) for g in model.gaps]

    def rhs(self, closed: dict[int, float]):
        """The right-hand side with the contacts *closed* (contact: its impact's ξ) pushing."""
        n = self.n

        def f(t, y):
            u, v = y[:n], y[n:]
            force = -self.damping @ v - self.stiffness @ u
            for c, xi in closed.items():
                left, right, gap, law = self.contacts[c]
                delta = u[left] - u[right] - gap
                if delta > 0.0:
                    push = max(delta ** 1.5 * (law.kh + xi * (v[left] - v[right])), 0.0)
                    force[left] -= push
                    force[right] += push
            return np.r_[v, force * self.inverse_mass - self.ground(t)]
        return f

    def events(self, closed: dict[int, float]) -> list:
        """Each contact's δ = 0: rising for an open one, falling for a closed one (terminal)."""
        found = []
        for c, (left, right, gap, _) in enumerate(self.contacts):
            event = (lambda left, right, gap: lambda t, y: y[left] - y[right] - gap)(left, right, gap)
            event.terminal, event.direction = True, (-1.0 if c in closed else 1.0)
            found.append(event)
        return found


def count(eq: Equations, method: str, end: float, rtol: float, atol: np.ndarray, free_steps: bool) -> dict:
    """Accepted steps and evaluations of *method* with a contact closed and with every contact open."""
    from scipy.integrate import solve_ivp

    t, y, closed = 0.0, np.zeros(2 * eq.n), {}
    tally = {"impacts": 0, "closed_steps": 0, "closed_evaluations": 0, "open_steps": 0, "open_evaluations": 0}
    last_step = None
    while t < end - 1e-12:
        kind = "closed" if closed else "open"
        rhs, events = eq.rhs(closed), eq.events(closed)
        while True:   # to the next event; sample by sample unless the steps are free
            stop = end if free_steps else min(end, (np.floor(t / eq.record_step + 1e-9) + 1.0) * eq.record_step)
            sol = solve_ivp(rhs, (t, stop), y, method=method, rtol=rtol, atol=atol, events=events,
                            first_step=None if last_step is None else min(last_step, stop - t))
            tally[f"{kind}_steps"] += sol.t.size - 1
            tally[f"{kind}_evaluations"] += sol.nfev
            if sol.t.size > 2:
                last_step = sol.t[-2] - sol.t[-3] if sol.t.size > 3 else sol.t[-1] - sol.t[-2]
            t, y = sol.t[-1], sol.y[:, -1].copy()
            if sol.status == 1 or t >= end - 1e-12:
                break
        if sol.status != 1:
            break
        for c, times in enumerate(sol.t_events):
            if not len(times):
                continue
            left, right, _, law = eq.contacts[c]
            if c in closed:
                del closed[c]
            elif y[eq.n + left] - y[eq.n + right] > 0.0:
                closed[c] = law.damping_constant(float(y[eq.n + left] - y[eq.n + right]))
                tally["impacts"] += 1
    return tally


def main() -> None:
    parser = argparse.ArgumentParser(description="Steps and evaluations per impact: Dormand-Prince 5(4) against "
                                                 "8(5,3) on the same equations (a measurement for planning).")
    parser.add_argument("--model", default="pair", help="a shipped model with planar contacts (name in models/)")
    parser.add_argument("--rtol", type=float, default=None, help="relative tolerance (atol scaled with it; "
                                                                  "default the model's)")
    parser.add_argument("--free-steps", action="store_true",
                        help="let the steps straddle record samples (over a cubic spline of the record)")
    add_output_arguments(parser, "contact_phase_order")
    args = parser.parse_args()
    from pounding.model.model import model_from_text
    from pounding.simulation import simulate

    path = ROOT / "models" / f"{args.model}.yaml"
    model = model_from_text(path.read_text(), name=path.stem, path=str(path))
    ds = simulate(model)
    eq = Equations(model, ds, args.free_steps)
    rtol = args.rtol or model.solver.rtol
    scale = rtol / model.solver.rtol
    atol = np.r_[np.full(eq.n, model.solver.atol), np.full(eq.n, model.solver.atol_velocity)] * scale
    print(f"{path.stem}: pounding's own run {int(ds.impact_count.sum())} impacts; rtol {rtol:g}; steps "
          f"{'free' if args.free_steps else 'ending at every record sample'}")
    results = {}
    for method in ("RK45", "DOP853"):
        started = time.perf_counter()
        tally = count(eq, method, float(ds.time[-1]), rtol, atol, args.free_steps)
        impacts = max(1, tally["impacts"])
        results[method] = tally
        print(f"  {method:7s} {tally['impacts']} impacts; per impact {tally['closed_steps'] / impacts:.1f} steps, "
              f"{tally['closed_evaluations'] / impacts:.0f} evaluations; contacts open: {tally['open_steps']} steps, "
              f"{tally['open_evaluations']} evaluations ({time.perf_counter() - started:.0f} s)")
    folder = out_dir(args, "contact_phase_order")
    (folder / "contact_phase_order.json").write_text(json.dumps({"model": path.stem, "rtol": rtol,
                                                                "free_steps": args.free_steps, **results}, indent=1))
    print(f"written: {folder / 'contact_phase_order.json'}")


if __name__ == "__main__":
    main()
