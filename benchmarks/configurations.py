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

#: name → (model of the configuration, the plain model of the same size it is compared with)
CASES: dict[str, tuple[str, str]] = {
    "pair_links": ("models/pair_links.yaml", "models/pair.yaml"),   # Maxwell links at A4-B4, A5-B5 (issue 16)
    # Wave passage (issue 16 part 4): pair.yaml with B's ground lagged 0.3 s; the lagged run lasts 0.3 s
    # longer (the whole record reaches B), about 1 % more simulated time.
    "pair_wave_passage": ("models/pair_wave_passage.yaml", "models/pair.yaml"),
}

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
    model, plain = pounding.load_model(ROOT / path), pounding.load_model(ROOT / plain_path)
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
