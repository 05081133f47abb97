"""How many record samples of a run's linear phases a bound on the modes could skip: a measurement for
planning, not a feature.

    python benchmarks/open_phase_bound.py                    # pair, row_of_three, pair_bumper (~10 s)
    python benchmarks/open_phase_bound.py --models pair --margin 1.5

The closed form of a linear phase (every contact open, every storey elastic; ``docs/numerics.md``) could
advance its modes over a record sample without rebuilding the floors' motion, the peaks, the contacts'
penetrations and the energy audit, where a bound shows that nothing can happen in that sample: no floor
or storey passes its running peak and no contact closes.  How often that would be is what this script
measures, on a finished run of each shipped model (its histories sampled at every record sample):

* the modal state at each sample, ``z = V⁻¹x`` per group of floors (the closed form's own modes;
  the floors' motion rebuilt from it is checked to round-off first);
* a sample interval is *open* when no contact force acts at either end;
* its bound: ``|Σ_i row_i·w_i·z_i(τ)| ≤ Σ_i |row_i|·w_i·max(|z_i(0)|, |z_i(h)|)·margin`` for each floor's
  displacement, each storey's drift and each contact's ``Σ w·u`` (the ends' moduli times ``--margin``, 1.05
  by default, stand in for a rigorous bound inside the interval, which would be larger);
* *skippable by rows*: every floor and storey bound below its running peak and every contact's below its gap
  (n·m products per sample: no cheaper than rebuilding the floors);
* *skippable by one number*: ``Σ_i c_i·w_i·max|z_i| < 1`` with ``c_i`` the largest ``|row_i|`` over
  every row divided by its peak or gap (m products per sample, ``c`` redone only when a peak grows).

Printed per model: the open intervals, and the share of them each test could skip (in the whole record and
in its second half).  ``--out DIR`` receives ``open_phase_bound.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402

MODELS = ("pair", "row_of_three", "pair_bumper")


def group_blocks(cf):
    """Per group of floors: ``(state rows, first mode, last mode + 1, V (2n, m) , V⁻¹ rows (m, 2n))``."""
    for g in range(cf.row_start.size - 1):
        r0, r1, m0, m1 = (int(cf.row_start[g]), int(cf.row_start[g + 1]), int(cf.mode_start[g]),
                          int(cf.mode_start[g + 1]))
        size = (r1 - r0) * (m1 - m0)
        start = int(cf.vector_start[g])
        yield (cf.rows[r0:r1], m0, m1, cf.vectors[start:start + size].reshape(r1 - r0, m1 - m0),
               cf.inverse[start:start + size].reshape(m1 - m0, r1 - r0))


def modal_history(cf, state: np.ndarray) -> tuple[np.ndarray, float]:
    """The modal state at every sample of *state* (nt, 2N), and the relative error of the motion rebuilt
    from it."""
    z = np.zeros((state.shape[0], cf.eigenvalue.size), dtype=complex)
    rebuilt = np.zeros_like(state)
    for rows, m0, m1, vectors, inverse in group_blocks(cf):
        z[:, m0:m1] = state[:, rows] @ inverse.T
        rebuilt[:, rows] = ((z[:, m0:m1] * cf.weight[m0:m1]) @ vectors.T).real
    return z, float(np.abs(rebuilt - state).max() / np.abs(state).max())


def skippable(path: Path, margin: float) -> dict:
    """The counts of :mod:`this script <open_phase_bound>` for the model file *path*."""
    from pounding.model.model import model_from_text
    from pounding.simulation import simulate
    from pounding.solver.assembly import assemble
    from pounding.solver.closed_form import closed_form

    model = model_from_text(path.read_text(), name=path.stem, path=str(path))
    ds = simulate(model)
    step = float(ds.time[1] - ds.time[0])
    cf = closed_form(assemble(model).system, step, 1)
    if cf is None:
        return {"model": path.stem, "refused": "no closed form"}
    state = np.concatenate([ds.displacement.values, ds.velocity.values], axis=1)
    z, rebuild_error = modal_history(cf, state)
    size = np.abs(z) * cf.weight
    reach = np.maximum(size[:-1], size[1:]) * margin          # each mode's reach over each interval
    peak_u = np.maximum.accumulate(np.abs(ds.displacement.values), axis=0)[:-1]
    peak_d = np.maximum.accumulate(np.abs(ds.storey_drift.values), axis=0)[:-1]
    gaps = np.array([g.gap for g in model.gaps])
    force = ds.contact_force.values
    open_ = ~((force[:-1] > 0) | (force[1:] > 0)).any(axis=1)
    rows = ((reach @ cf.floor_size.T < peak_u).all(1) & (reach @ cf.drift_size.T < peak_d).all(1)
            & (reach @ cf.contact_size.T < gaps).all(1))
    with np.errstate(divide="ignore", invalid="ignore"):   # a floor at rest so far: no peak yet, never skipped
        weights = np.maximum((cf.floor_size[None] / peak_u[:, :, None]).max(1),
                             (cf.drift_size[None] / peak_d[:, :, None]).max(1))
    weights = np.maximum(weights, (cf.contact_size / gaps[:, None]).max(0)[None])
    one = np.nan_to_num((reach * weights).sum(1), nan=np.inf) < 1.0
    half = open_.size // 2
    share = lambda mask, part=slice(None): float((mask & open_)[part].sum() / max(1, open_[part].sum()))  # noqa: E731
    return {"model": path.stem, "intervals": int(open_.size), "open": int(open_.sum()),
            "rebuild_error": rebuild_error, "rows": share(rows), "rows_second_half": share(rows, slice(half, None)),
            "one_number": share(one), "one_number_second_half": share(one, slice(half, None))}


def main() -> None:
    parser = argparse.ArgumentParser(description="How many samples of the linear phases a bound on the modes "
                                                 "could skip (a measurement for planning).")
    parser.add_argument("--models", nargs="+", default=list(MODELS), help="shipped models (names in models/)")
    parser.add_argument("--margin", type=float, default=1.05,
                        help="factor on the interval ends' modal moduli standing in for a bound inside it")
    add_output_arguments(parser, "open_phase_bound")
    args = parser.parse_args()
    results = []
    for name in args.models:
        found = skippable(ROOT / "models" / f"{name}.yaml", args.margin)
        results.append(found)
        if "refused" in found:
            print(f"{name}: {found['refused']}")
            continue
        print(f"{name}: {found['intervals']} sample intervals, {found['open']} open (rebuilt from the modes to "
              f"{found['rebuild_error']:.1e}); skippable by rows {found['rows']:.0%} (second half "
              f"{found['rows_second_half']:.0%}), by one number {found['one_number']:.0%} (second half "
              f"{found['one_number_second_half']:.0%})")
    folder = out_dir(args, "open_phase_bound")
    (folder / "open_phase_bound.json").write_text(json.dumps({"margin": args.margin, "models": results}, indent=1))
    print(f"written: {folder / 'open_phase_bound.json'}")


if __name__ == "__main__":
    main()
