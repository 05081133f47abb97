"""Every shipped model's archive, and a small study of each kind, are bit-identical to the
fingerprints in ``tests/data/fingerprints.json`` (written by ``tests/data/make_fingerprints.py``).

The solver, the results and the studies are restructured under this test: a value that moves by
one unit in the last place fails it.  A change of results *by design* regenerates the file in a
commit of its own that names the cause and the largest change.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

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
def test_archive_bit_identical(found, archive):
    moved = make_fingerprints.compare({archive: REFERENCE[archive]}, {archive: found[archive]})
    assert not moved, "\n".join(moved[:20])


def test_every_shipped_model_is_fingerprinted():
    shipped = {p.stem for p in (DATA.parents[1] / "models").glob("*.yaml")}
    assert shipped == set(make_fingerprints.MODELS)


def test_fingerprint_sees_one_ulp():
    import numpy as np
    a = np.linspace(0.0, 1.0, 7)
    b = a.copy()
    b[3] = np.nextafter(b[3], 2.0)
    assert make_fingerprints.digest(a) != make_fingerprints.digest(b)
