"""Where one run's time goes: the compiled solver's steps by kind, and what is around it.

    python benchmarks/time_split.py                       # pair, pair_inelastic, corner_pair (~1 min)
    python benchmarks/time_split.py --models pair --rtol 1e-10 --repeat 9

For each shipped model under its own record, ``pounding.simulate`` is run ``--repeat`` times after a
warm-up run (kernels loaded) and split, median of the runs, into:

* **the compiled solver** (the ``_integrate`` kernel's wall time), itself split by its own counts
  (``RawSolution``): Runge-Kutta steps without an impact under way, accepted steps with an impact
  under way, closed-form steps (accepted exact steps of linear phases), and *event location and error
  control*: the trial steps that were not accepted (retaken to end at a located event, redone after
  events applied at their start, halved by the graze guard, rejected by the error control).  The steps
  without an impact under way are charged at the time per trial step of the same buildings without
  contacts (measured: no event, no impact), the rest of the solver's time is shared by the other kinds
  in proportion to their counts (each is a trial step with a contact's force, its samples and its
  event search); an exact step's cost is printed beside it (the same model with every linear phase in
  closed form).
* **the closed form's build** (``run_closed_form``: the modes, cached per structure);
* **the rest of ``integrate``** (the kernel's arguments, the raw solution's arrays);
* **outside the solver** (``simulate`` minus ``integrate``: the model's assembly, the record, the
  xarray Dataset with its labels and attributes).

Printed only; ``--out DIR`` (default ``<user cache>/pounding/benchmarks/time_split``) receives
``time_split.json``.  The tables of ``docs/performance.md`` are written by hand from this output.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import pounding  # noqa: E402
import pounding.simulation as simulation  # noqa: E402
import pounding.solver.integrator as integrator  # noqa: E402
from pounding.model.model import model_from_text  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402

MODELS = ("pair", "pair_inelastic", "corner_pair")


class Clocks:
    """Wall time of each timed call of the last run, and the last raw solution."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self.raw = None
        self._wrap(integrator, "_integrate", "kernel")
        self._wrap(integrator, "run_closed_form", "closed_form_build")
        self._wrap(simulation, "integrate", "integrate", keep=True)

    def _wrap(self, module, name: str, label: str, keep: bool = False) -> None:
        inner = getattr(module, name)

        def timed(*args, **kwargs):
            started = time.perf_counter()
            result = inner(*args, **kwargs)
            self.seconds[label] = self.seconds.get(label, 0.0) + time.perf_counter() - started
            if keep:
                self.raw = result
            return result

        setattr(module, name, timed)

    def run(self, model) -> dict:
        """One ``simulate`` of *model*: its clocks (s) and the raw solution's counts."""
        self.seconds = {}
        started = time.perf_counter()
        pounding.simulate(model)
        seconds = dict(self.seconds, simulate=time.perf_counter() - started)
        raw = self.raw
        counts = {"trial_steps": raw.trial_steps, "accepted": raw.n_steps, "rejected": raw.n_rejected,
                  "exact": raw.exact_steps, "contact": raw.contact_steps, "impacts": int(raw.impact_time.size)}
        return {"seconds": seconds, "counts": counts}


def variant(path: Path, rtol: float | None, drop_contacts: bool = False):
    """The model of *path* at *rtol* (its atol scaled with it; None: its own); without its contacts if
    *drop_contacts*."""
    model = pounding.load_model(path)
    if rtol is not None:
        scale = rtol / model.solver.rtol
        model = model.with_solver(rtol=rtol, atol=model.solver.atol * scale,
                                  atol_velocity=model.solver.atol_velocity * scale)
    if drop_contacts:
        model = model_without_contacts(model, path)
    return model


def model_without_contacts(model, path: Path):
    """*model* with its contacts removed (the same buildings and record), read from its own text."""
    import yaml

    document = yaml.safe_load(path.read_text())
    document.pop("contacts", None)
    document["solver"] = {**(document.get("solver") or {}),
                          **{k: float(getattr(model.solver, k)) for k in ("rtol", "atol", "atol_velocity")}}
    return model_from_text(yaml.safe_dump(document, sort_keys=False), name=path.stem, base_dir=str(path.parent))


def measured(clocks: Clocks, model, repeat: int) -> dict:
    """Median clocks over *repeat* runs after a warm-up run, and the counts (the same every run)."""
    clocks.run(model)
    runs = [clocks.run(model) for _ in range(repeat)]
    keys = runs[0]["seconds"].keys()
    return {"seconds": {k: statistics.median(r["seconds"].get(k, 0.0) for r in runs) for k in keys},
            "counts": runs[-1]["counts"]}


def trial_costs(result: dict, bare: dict) -> tuple[float, float]:
    """The time of the steps without an impact under way (s, at *bare*'s time per trial step) and the
    time per other trial step (s): the rest of the compiled solver's time over their count."""
    c, kernel = result["counts"], result["seconds"]["kernel"]
    open_cost = bare["seconds"]["kernel"] / max(bare["counts"]["trial_steps"], 1)
    open_rk = min(kernel, (c["accepted"] - c["contact"] - c["exact"]) * open_cost)
    others = c["trial_steps"] - c["accepted"] + c["contact"] + c["exact"]
    return open_rk, (kernel - open_rk) / max(others, 1)


def split(result: dict, bare: dict) -> dict:
    """The run's time split (s) from its clocks and counts (module docstring): the steps without an impact
    under way at the time per trial step of the same buildings without contacts (*bare*), the rest of the
    compiled solver's time shared by the steps with an impact under way and the trial steps not accepted
    (event location and error control) in proportion to their counts."""
    s, c = result["seconds"], result["counts"]
    open_rk, rest_cost = trial_costs(result, bare)
    not_accepted = c["trial_steps"] - c["accepted"]
    return {
        "Runge-Kutta steps, no impact under way": open_rk,
        "steps with an impact under way": c["contact"] * rest_cost,
        "closed-form steps": c["exact"] * rest_cost,
        "event location and error control": not_accepted * rest_cost,
        "closed form's build": s.get("closed_form_build", 0.0),
        "rest of integrate()": s["integrate"] - s["kernel"] - s.get("closed_form_build", 0.0),
        "outside the solver": s["simulate"] - s["integrate"],
    }


def report(name: str, result: dict, exact: dict, bare: dict) -> dict:
    """Print one model's split; returns it (:func:`split`)."""
    s, c = result["seconds"], result["counts"]
    print(f"\n{name}: simulate() {1e3 * s['simulate']:.2f} ms, compiled solver {1e3 * s['kernel']:.2f} ms; "
          f"{c['trial_steps']} trial steps ({c['accepted']} accepted, {c['exact']} exact, {c['contact']} with an "
          f"impact under way, {c['rejected']} rejected), {c['impacts']} impacts"
          + (f", {c['contact'] / c['impacts']:.1f} steps per impact" if c["impacts"] else ""))
    total, parts = s["simulate"], split(result, bare)
    for label, seconds in parts.items():
        print(f"  {label:42s} {1e3 * seconds:8.2f} ms  {100 * seconds / total:5.1f} %")
    per = 1e6 * s["kernel"] / max(c["trial_steps"], 1)
    per_bare = 1e6 * bare["seconds"]["kernel"] / max(bare["counts"]["trial_steps"], 1)
    print(f"  time per trial step: {per:.2f} us; without an impact under way (the same buildings without "
          f"contacts) {per_bare:.2f} us; with one, or not accepted, {1e6 * trial_costs(result, bare)[1]:.2f} us")
    ce = exact["counts"]
    if ce["exact"]:
        rk_trials = ce["trial_steps"] - ce["exact"]
        per_exact = (1e6 * exact["seconds"]["kernel"] - per * rk_trials) / ce["exact"]
        print(f"  every linear phase in closed form: {1e3 * exact['seconds']['kernel']:.2f} ms, {ce['exact']} exact "
              f"steps, about {per_exact:.2f} us each ({per_exact / per:.1f} Runge-Kutta trial steps)")
    return parts


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", nargs="+", default=list(MODELS), help="shipped models (names in models/)")
    parser.add_argument("--repeat", type=int, default=7, help="runs per measurement (median; default 7)")
    parser.add_argument("--rtol", type=float, default=None, help="relative tolerance (atol scaled with it)")
    add_output_arguments(parser, "time_split")
    args = parser.parse_args(argv)
    clocks = Clocks()
    results = {}
    for name in args.models:
        path = ROOT / "models" / f"{name}.yaml"
        result = measured(clocks, variant(path, args.rtol), args.repeat)
        bare = measured(clocks, variant(path, args.rtol, drop_contacts=True), args.repeat)
        parts = report(name, result, forced_exact(clocks, path, args), bare)
        results[name] = {"default": result, "split": parts, "without_contacts": bare}
    out = out_dir(args, "time_split") / "time_split.json"
    out.write_text(json.dumps(results, indent=1))
    print(f"\nwritten: {out}")
    return 0


def forced_exact(clocks: Clocks, path: Path, args: argparse.Namespace) -> dict:
    """The model with every linear phase in closed form (the solver's threshold set negative)."""
    threshold = integrator.run_closed_form

    def always(*a, **k):
        return threshold(*a[:3], -1.0, *a[4:], **k)

    integrator.run_closed_form = always
    try:
        return measured(clocks, variant(path, args.rtol), 1)
    finally:
        integrator.run_closed_form = threshold


if __name__ == "__main__":
    raise SystemExit(main())
