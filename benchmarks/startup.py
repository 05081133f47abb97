"""Whole-process time of the first and of a warm ``pounding run models/pair.yaml -o pair.nc``,
this checkout against a baseline checkout, measured alternately in the same run (issue 24 §4).

``python benchmarks/startup.py --baseline DIR|REF [--cold 3] [--warm 7] [--no-prebuilt] [--out DIR]``

``--baseline`` is another checkout of pounding, or a git ref of this one (a commit, ``HEAD``,
a branch): that tree is then checked out for the measurement in a temporary worktree
(``git worktree add --detach``), removed afterwards, with this checkout's kernels compiled ahead of
time copied into it (used only if the solver's sources are the same: their stamp is checked).
Each tree runs as ``python -m pounding`` with ``PYTHONPATH`` set to it, from the tree's root.

* **first run**: an empty numba cache (a fresh ``NUMBA_CACHE_DIR``) and an empty FEMA P695
  and record cache (a fresh ``XDG_CACHE_HOME``), as on a new machine; ``--cold`` runs of
  each tree, alternating baseline / this tree;
* **warm run**: both caches filled (each tree its own, filled by one run that is not
  counted); ``--warm`` runs of each, alternating.

Printed per tree and figure: the median of wall seconds and of CPU seconds (user + system of
the process and its children, from ``resource.getrusage``), and the ratio this / baseline of
the medians.  Issue 24's targets: first run ≤ 0.5×, warm run ≤ 0.8×.  The figures also go to
``startup.json`` in ``--out``.

A tree may hold kernels compiled ahead of time (``pounding/solver/prebuilt``, written by ``pip
install -e .`` or ``python -m pounding.prebuild pounding/solver/prebuilt``; a wheel carries its own):
each tree's state is printed first, and a first run of a tree with kernels for its sources does not
compile.  ``--no-prebuilt`` sets ``POUNDING_PREBUILT=0`` for every run: the first run compiles, as a
checkout without them (or the tree before issue 24) does.

Both trees' Python bytecode is compiled first (``compileall``), as ``pip install`` does for a
user: with ``PYTHONDONTWRITEBYTECODE`` set (as on the project's VM) every process would
otherwise compile each module from source, ~0.1 s that no installed copy pays.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402


def timed_run(tree: Path, env: dict[str, str], output: Path) -> tuple[float, float]:
    """(wall s, CPU s) of one ``pounding run models/pair.yaml`` of *tree*."""
    command = [sys.executable, "-m", "pounding", "run", "models/pair.yaml", "-o", str(output), "--overwrite"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(command, cwd=tree, env=dict(env, PYTHONPATH=str(tree)), capture_output=True, text=True)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"{tree}: pounding run failed:\n{done.stderr[-1500:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def compile_bytecode(tree: Path) -> None:
    """Write the ``.pyc`` files of *tree*'s package, as ``pip install`` does for a user."""
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "pounding")], check=True)


def fresh_caches(folder: Path, label: str) -> dict[str, str]:
    """Environment with empty numba and user caches under *folder*."""
    numba_dir, xdg = folder / f"numba-{label}", folder / f"xdg-{label}"
    numba_dir.mkdir(parents=True)
    xdg.mkdir(parents=True)
    return dict(os.environ, NUMBA_CACHE_DIR=str(numba_dir), XDG_CACHE_HOME=str(xdg))


def prebuilt_status(tree: Path) -> str:
    """What *tree* holds of kernels compiled ahead of time, and whether they are used (one line)."""
    if not (tree / "pounding" / "prebuild.py").is_file():
        return "no kernels compiled ahead of time (a tree from before them)"
    done = subprocess.run([sys.executable, "-m", "pounding.prebuild", "--status"], cwd=tree,
                          env=dict(os.environ, PYTHONPATH=str(tree)), capture_output=True, text=True)
    return done.stdout.strip() or done.stderr.strip().splitlines()[-1]


def measure(trees: dict[str, Path], cold: int, warm: int) -> dict[str, dict[str, list[float]]]:
    """Alternated first and warm runs of every tree: {tree: {figure: [values]}}."""
    found = {name: {"first_wall": [], "first_cpu": [], "warm_wall": [], "warm_cpu": []} for name in trees}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for i in range(cold):
            for name, tree in trees.items():
                wall, cpu = timed_run(tree, fresh_caches(folder, f"{name}-cold-{i}"), folder / "pair.nc")
                found[name]["first_wall"].append(wall)
                found[name]["first_cpu"].append(cpu)
                print(f"  first run {i + 1}/{cold} {name}: {wall:.2f} s wall, {cpu:.2f} s CPU", flush=True)
        warm_env = {name: fresh_caches(folder, f"{name}-warm") for name in trees}
        for name, tree in trees.items():
            timed_run(tree, warm_env[name], folder / "pair.nc")  # fill the caches; not counted
        for _ in range(warm):
            for name, tree in trees.items():
                wall, cpu = timed_run(tree, warm_env[name], folder / "pair.nc")
                found[name]["warm_wall"].append(wall)
                found[name]["warm_cpu"].append(cpu)
    return found


@contextmanager
def baseline_tree(given: str) -> Iterator[Path]:
    """The checkout *given* names: a folder as it is, else a git ref checked out in a temporary worktree."""
    folder = Path(given).expanduser()
    if folder.is_dir():
        yield folder.resolve()
        return
    with tempfile.TemporaryDirectory(prefix="pounding-baseline-") as tmp:
        tree = Path(tmp) / "tree"
        added = subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), given],
                               capture_output=True, text=True)
        if added.returncode != 0:
            raise SystemExit(f"--baseline {given}: neither a folder nor a git ref of {ROOT} "
                             f"({added.stderr.strip().splitlines()[-1] if added.stderr.strip() else 'git failed'})")
        kernels = ROOT / "pounding" / "solver" / "prebuilt"
        if kernels.is_dir():   # kernels built for other solver sources are ignored (their stamp): spares a compile
            shutil.copytree(kernels, tree / "pounding" / "solver" / "prebuilt")
        try:
            yield tree
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], capture_output=True)


def report(found: dict[str, dict[str, list[float]]]) -> dict[str, dict[str, float]]:
    medians = {name: {figure: statistics.median(values) for figure, values in figures.items() if values}
               for name, figures in found.items()}
    print(f"\n{'figure':<12} {'baseline':>10} {'this tree':>10} {'ratio':>7}")
    for figure in ("first_wall", "first_cpu", "warm_wall", "warm_cpu"):
        if figure not in medians["this"]:
            continue  # --cold 0 or --warm 0
        base, this = medians["baseline"][figure], medians["this"][figure]
        print(f"{figure:<12} {base:>9.2f}s {this:>9.2f}s {this / base:>7.2f}")
    print("targets (issue 24): first run <= 0.50, warm run <= 0.80 (wall, medians)")
    return medians


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", required=True,
                        help="another checkout of pounding, or a git ref of this one (e.g. HEAD, main, a commit)")
    parser.add_argument("--cold", type=int, default=3, help="first runs of each tree (median; 0: none)")
    parser.add_argument("--warm", type=int, default=7, help="warm runs of each tree (median)")
    parser.add_argument("--no-prebuilt", action="store_true",
                        help="POUNDING_PREBUILT=0: kernels compiled ahead of time are not used (first runs compile)")
    add_output_arguments(parser, "startup")
    args = parser.parse_args(argv)
    if args.no_prebuilt:
        os.environ["POUNDING_PREBUILT"] = "0"
    with baseline_tree(args.baseline) as baseline:
        if not (baseline / "pounding" / "__init__.py").is_file():
            parser.error(f"--baseline {baseline}: not a pounding checkout (no pounding/__init__.py)")
        trees = {"baseline": baseline, "this": ROOT}
        for name, tree in trees.items():
            compile_bytecode(tree)
            print(f"{name} ({tree}): {prebuilt_status(tree)}")
        found = measure(trees, args.cold, args.warm)
    medians = report(found)
    path = out_dir(args, "startup") / "startup.json"
    path.write_text(json.dumps({"runs": found, "medians": medians, "no_prebuilt": args.no_prebuilt}, indent=1))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
