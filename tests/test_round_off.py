"""Results are continuous at round-off: a record shifted by a few ulps changes no decision of the solver.

Another CPU, BLAS kernel or compiler rounds the last bits of a run differently; every decision the solver
takes at a located event (a contact closing, a storey's branch, a face sticking, a collapse) must then come
out the same, or the results would depend on the machine.  Each case runs a shipped model, and variants with
events of other kinds, under its record scaled by (1 + ε) with ε a few times 1e-15: the status and the
impact counts must be identical and the peaks equal to round-off.  A changed decision moves peaks by 1e-3 or
more (an IMK storey that reloaded past its strength at a triple point of its backbone: 0.33 → 0.6 m); a run
that takes the same decisions differs by at most 7e-13 of its largest peak (measured on every case below
and on every shipped model), so 1e-9 separates them by orders of magnitude either way.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

import pounding
from pounding.model.model import model_from_data

MODELS = Path(__file__).resolve().parents[1] / "models"
#: Relative shifts of the record's scale: a few ulps each side.
SHIFTS = (-4.6e-15, 2.3e-15, 6.9e-15)
#: Simulated time, s: every case has its events by then (asserted).
DURATION = 12.0
#: Agreement of the peaks, relative to the largest: round-off (module docstring).
AGREE = 1e-9


def _shipped(name: str) -> dict:
    return yaml.safe_load((MODELS / f"{name}.yaml").read_text())


def _with_friction(name: str, coefficient: float) -> dict:
    document = _shipped(name)
    for contact in document["contacts"]:
        contact["friction"] = coefficient
    return document


def _with_gap(name: str, gap: float) -> dict:
    document = _shipped(name)
    for contact in document["contacts"]:
        contact["gap"] = gap
    return document


def _with_bilinear_storeys(name: str) -> dict:
    document = _shipped(name)
    law = {"model": "bilinear", "yield_drift_ratio": 0.004, "post_yield_ratio": 0.05}
    for building in document["buildings"]:
        storeys = building["storeys"]
        for storey in [storeys] if isinstance(storeys, dict) else storeys:
            storey["hysteresis"] = dict(law)
    return document


CASES = {
    "pair_collapse (IMK storeys, P-Delta)": lambda: _shipped("pair_collapse"),
    "pair_inelastic (Bouc-Wen)": lambda: _shipped("pair_inelastic"),
    "pair, bilinear storeys": lambda: _with_bilinear_storeys("pair"),
    "pair, gap 0 (contacts at rest)": lambda: _with_gap("pair", 0.0),
    "isolated_moat (walls)": lambda: _shipped("isolated_moat"),
    "corner_pair, friction 0.3 (in plan)": lambda: _with_friction("corner_pair", 0.3),
}


def _run(document: dict, shift: float):
    shifted = copy.deepcopy(document)
    shifted["ground_motion"]["scale"] = float(shifted["ground_motion"].get("scale", 1.0)) * (1.0 + shift)
    return pounding.simulate(model_from_data(shifted, name="case", base_dir=str(MODELS)), duration=DURATION)


@pytest.mark.parametrize("case", list(CASES))
def test_a_record_shifted_by_round_off_takes_the_same_decisions(case):
    document = CASES[case]()
    base = _run(document, 0.0)
    peak = "peak_drift_ratio" if "peak_drift_ratio" in base else "peak_plane_drift"
    assert int(base.impact_count.sum()) > 0   # the case has events to decide
    for shift in SHIFTS:
        ds = _run(document, shift)
        assert ds.attrs["status"] == base.attrs["status"], shift
        np.testing.assert_array_equal(ds.impact_count.values, base.impact_count.values)
        scale = float(np.max(np.abs(base[peak].values)))
        np.testing.assert_allclose(ds[peak].values, base[peak].values, rtol=0, atol=AGREE * scale)
        if "friction_state" in base:   # the same sticking and slipping
            assert np.array_equal(ds.friction_state.values, base.friction_state.values), shift
