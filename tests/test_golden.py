"""Golden test of the README's headline run: ``pounding run models/pair.yaml``.

The reference values are in ``tests/data/golden_pair.json``, written by
``python3 tests/data/make_golden.py`` from an actual run (the script's
docstring says what it stores).  A fresh run must reproduce:

* the impact count of every gap element **exactly** (101 in all) — an
  impact gained or lost is a change of behaviour, never noise;
* every storey's peak drift ratio to 2e-5 relative and every gap element's
  peak contact force to 1e-3 relative.  These bounds are 10× the global
  error of the run at its own solver settings (rtol 1e-6, atol 1e-8 m,
  1e-7 m/s), measured against the same run at rtol 1e-9 (atol scaled alike):
  2.4e-6 on the drifts, 8.7e-5 on the peak forces, with every impact count
  unchanged.  So a change of the solver that keeps its stated accuracy
  passes; a change of the physics (a contact law, ξ, damping, the record)
  does not.

Another engineer is changing the solver's numerics (grazing detection, Zeno
behaviour, step control).  Such a fix may legitimately move an impact count.
Then regenerate the file — ``python3 tests/data/make_golden.py`` (``--check``
shows what moves without writing) — say why in the commit message, and update
the README block "What the first command prints", which
:func:`test_readme_block_matches_golden` checks against the golden file.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import pounding
from pounding.simulation import simulate

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = json.loads((ROOT / "tests" / "data" / "golden_pair.json").read_text())

DRIFT_RTOL = 2e-5  # 10x the measured global error of the default settings (module docstring)
FORCE_RTOL = 1e-3  # likewise (8.7e-5 measured)


@pytest.fixture(scope="module")
def run():
    return simulate(pounding.load_model(ROOT / "models" / "pair.yaml"))


def test_same_record(run):
    # The golden numbers belong to one record: a changed file changes everything.
    assert run.attrs["record_name"] == GOLDEN["record_name"]
    assert run.attrs["record_sha256"] == GOLDEN["record_sha256"]


def test_impact_counts_exactly(run):
    counts = {str(c): int(n) for c, n in zip(run.contact.values, run.impact_count.values)}
    assert counts == GOLDEN["impact_count"]
    assert sum(counts.values()) == GOLDEN["total_impacts"] == 101
    assert run.impact_time.size == 101


def test_peak_drift_ratios(run):
    got = {str(s): float(d) for s, d in zip(run.storey.values, run.peak_drift_ratio.values)}
    assert list(got) == list(GOLDEN["peak_drift_ratio"])
    for storey, ref in GOLDEN["peak_drift_ratio"].items():
        assert got[storey] == pytest.approx(ref, rel=DRIFT_RTOL), storey


def test_peak_contact_forces(run):
    got = {str(c): float(f) for c, f in zip(run.contact.values, run.peak_contact_force.values)}
    for contact, ref in GOLDEN["peak_contact_force_N"].items():
        assert got[contact] == pytest.approx(ref, rel=FORCE_RTOL), contact


def _readme_block() -> str:
    text = (ROOT / "README.md").read_text()
    start = text.index("What the first command prints")
    return text[start: text.index("```", text.index("```", start) + 3)]


def test_readme_block_matches_golden():
    # The README prints drifts in % to 3 decimals, forces to 3 significant
    # digits and the counts: the golden values must round to exactly what is
    # printed, so README and golden file cannot drift apart.
    block = _readme_block()
    for building in ("A", "B"):
        printed = re.search(rf"^\s+{building}: ([\d. ]+)$", block.split("peak drift ratio")[1], re.M).group(1)
        printed = [float(x) for x in printed.split()]
        ref = [v for k, v in GOLDEN["peak_drift_ratio"].items() if k.startswith(building + ":")]
        assert printed == [round(100 * v, 3) for v in ref], building
    for contact, count in GOLDEN["impact_count"].items():
        line = re.search(rf"{re.escape(contact)}: (\d+) impacts, peak ([\d.]+) (kN|MN)", block)
        assert int(line.group(1)) == count, contact
        scale = {"kN": 1e3, "MN": 1e6}[line.group(3)]
        force = GOLDEN["peak_contact_force_N"][contact] / scale
        assert float(line.group(2)) == float(f"{force:.3g}"), contact
    assert f"{GOLDEN['total_impacts']} impacts in all" in block


def test_golden_file_is_self_consistent():
    assert GOLDEN["total_impacts"] == sum(GOLDEN["impact_count"].values())
    assert np.all(np.array(list(GOLDEN["peak_drift_ratio"].values())) > 0.0)
