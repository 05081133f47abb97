"""Every shipped model's archive, and a small study of each kind, agree with the fingerprints in
``tests/data/fingerprints.json`` (written by ``tests/data/make_fingerprints.py``).

On the machine that wrote the file every digest matches bit for bit.  On another machine (another
CPU, another BLAS kernel) the eigen-analysis of a model in plan rounds differently in its last bits,
so a digest may move: the variable's values are then compared at the tolerance the module states
(``make_fingerprints.TOLERANCE``, set by the round-off measured across BLAS kernels), which a change of
physics exceeds by orders of magnitude.  Bit-identity between two trees is checked in one
environment by ``python tests/data/make_fingerprints.py --against TREE`` (what a refactoring runs).
A change of results *by design* regenerates the file in a commit of its own that names the cause and
the largest change.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).resolve().parent / "data"
_spec = importlib.util.spec_from_file_location("make_fingerprints", DATA / "make_fingerprints.py")
make_fingerprints = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_fingerprints)

REFERENCE = json.loads((DATA / "fingerprints.json").read_text())


@pytest.fixture(scope="module")
def found():
    return make_fingerprints.all_fingerprints()


@pytest.mark.parametrize("archive", sorted(REFERENCE))
def test_archive_agrees_with_its_fingerprint(found, archive):
    moved = make_fingerprints.compare({archive: REFERENCE[archive]}, {archive: found[archive]})
    assert not moved, "\n".join(moved[:20])


def test_every_shipped_model_is_fingerprinted():
    shipped = {p.stem for p in (DATA.parents[1] / "models").glob("*.yaml")}
    assert shipped == set(make_fingerprints.MODELS)


def test_fingerprint_sees_one_ulp():
    a = np.linspace(0.0, 1.0, 7)
    b = a.copy()
    b[3] = np.nextafter(b[3], 2.0)
    assert make_fingerprints.digest(a) != make_fingerprints.digest(b)


def _entries(values: np.ndarray) -> dict:
    mf = make_fingerprints
    return {"var:x": f"('time',):{mf.digest(values)}", "values:var:x": mf.summary(values)}


def test_values_compare_at_round_off_but_not_at_a_change_of_physics():
    """A history moved by a few ulps everywhere agrees; one sample of 3001 moved by 1e-5 of the peak, the
    history scaled by 1 + 1e-7 (a tenth of the solver's rtol), or a sample's sign flipped do not."""
    mf = make_fingerprints
    t = np.linspace(0.0, 30.0, 3001)
    x = 0.12 * np.sin(2.1 * t) * np.exp(-0.05 * t)
    rounded = x * (1.0 + 4e-16 * np.cos(7.0 * t))              # round-off of every sample
    assert not np.array_equal(rounded, x)
    assert not mf.compare({"a": _entries(x)}, {"a": _entries(rounded)})
    assert mf.compare({"a": _entries(x)}, {"a": _entries(rounded)}, exact=True)
    one = x.copy()
    one[1500] += 1e-5 * np.abs(x).max()
    flipped = x.copy()
    flipped[700] = -flipped[700]
    for changed in (one, x * (1.0 + 1e-7), flipped):
        assert mf.compare({"a": _entries(x)}, {"a": _entries(changed)})


def test_attribute_numbers_compare_at_round_off():
    mf = make_fingerprints
    text = '{"A": [0.8265636602407374, 0.33]}'
    same = '{"A": [0.8265636602407437, 0.33]}'                  # a BLAS kernel's periods
    assert mf.attributes_agree(mf.attribute_summary(text), mf.attribute_summary(same))
    assert not mf.attributes_agree(mf.attribute_summary(text), mf.attribute_summary('{"A": [0.8266, 0.33]}'))
    assert not mf.attributes_agree(mf.attribute_summary(text), mf.attribute_summary('{"B": [0.8265636602407374, 0.33]}'))


def test_step_counts_agree_across_machines_within_a_few_flipped_steps_but_not_at_another_tolerance():
    mf = make_fingerprints
    steps = mf.attribute_summary("4092")
    assert mf.attributes_agree(steps, mf.attribute_summary("4090"), "solver_steps")   # seen on an AMD EPYC
    assert not mf.attributes_agree(steps, mf.attribute_summary("4090"), "record_step")  # other numbers: 1e-9
    assert not mf.attributes_agree(steps, mf.attribute_summary("4200"), "solver_steps")  # 2.6 % more: not round-off
    assert mf.attributes_agree(mf.attribute_summary("84"), mf.attribute_summary("88"), "solver_rejected_steps")
