"""pounding.prebuild: the groups of compiling runs, each compiled in a process of its own, merged into the one
folder of kernels an install ships (pounding/solver/prebuilt), and that folder serving the runs beside the
shipped models (friction, friction with yielding planes, a slab striking a column in plan) without compiling."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from numba.core.caching import IndexDataCacheFile

from pounding.prebuild import merge_caches

ROOT = Path(__file__).resolve().parents[1]
STAMP = ("sha256", "0" * 64)


def _cache(folder: Path, base: str, entries: dict, stamp: tuple = STAMP) -> None:
    """numba's own cache files of kernel *base*: each signature key of *entries* saved with its data."""
    folder.mkdir(exist_ok=True)
    files = IndexDataCacheFile(cache_path=str(folder), filename_base=base, source_stamp=stamp)
    for key, data in entries.items():
        files.save(key, data)


def _read(folder: Path, base: str, key: tuple):
    return IndexDataCacheFile(cache_path=str(folder), filename_base=base, source_stamp=STAMP).load(key)


def test_merged_caches_hold_every_signature_of_every_folder(tmp_path):
    shipped, extra, merged = tmp_path / "shipped", tmp_path / "extra", tmp_path / "merged"
    _cache(shipped, "integrator._integrate-696.py311", {("narrow", "cpu"): ("narrow",), ("storeys", "cpu"): ("s1",)})
    _cache(extra, "integrator._integrate-696.py311", {("storeys", "cpu"): ("s2",), ("wide", "cpu"): ("wide",)})
    _cache(extra, "rhs.rhs-68.py311", {("wide", "cpu"): ("rhs",)})
    written = merge_caches([shipped, extra], merged)
    # numba's reader finds every signature; one both folders compiled comes from the first folder
    assert _read(merged, "integrator._integrate-696.py311", ("narrow", "cpu")) == ("narrow",)
    assert _read(merged, "integrator._integrate-696.py311", ("storeys", "cpu")) == ("s1",)
    assert _read(merged, "integrator._integrate-696.py311", ("wide", "cpu")) == ("wide",)
    assert _read(merged, "rhs.rhs-68.py311", ("wide", "cpu")) == ("rhs",)
    names = sorted(p.name for p in merged.iterdir())
    assert names == ["integrator._integrate-696.py311.1.nbc", "integrator._integrate-696.py311.2.nbc",
                     "integrator._integrate-696.py311.3.nbc", "integrator._integrate-696.py311.nbi",
                     "rhs.rhs-68.py311.1.nbc", "rhs.rhs-68.py311.nbi"]
    assert written == len(names)


def test_merging_kernels_of_other_sources_is_refused(tmp_path):
    _cache(tmp_path / "a", "rhs.rhs-68.py311", {("narrow", "cpu"): ("a",)})
    _cache(tmp_path / "b", "rhs.rhs-68.py311", {("wide", "cpu"): ("b",)}, stamp=("sha256", "1" * 64))
    with pytest.raises(ValueError, match="rhs.rhs-68.py311.nbi: the folders' kernels come from other sources"):
        merge_caches([tmp_path / "a", tmp_path / "b"], tmp_path / "merged")


EXTRA_PROBE = r"""
import json, os, sys
from pounding.solver import jit
jit.PREBUILT = sys.argv[1]
from pounding.data import data_path
from pounding.model.model import model_from_data
from pounding.prebuild import columns_on_one_ground, extra_runs
from pounding.simulation import simulate
from pounding.solver.integrator import _integrate
import numpy as np
for label, document in extra_runs(data_path("models")):
    simulate(model_from_data(document, base_dir=str(data_path("models"))), duration=0.05)
columns_on_one_ground(data_path("models"), np.zeros(10), 0.05)
user = os.environ["NUMBA_CACHE_DIR"]
print(json.dumps({"cache_hits": int(sum(_integrate.stats.cache_hits.values())),
                  "written": sorted(f for _, _, files in os.walk(user) for f in files)}))
"""


def test_the_runs_beside_the_shipped_models_load_their_solvers_without_compiling(tmp_path):
    """Friction, friction with yielding planes and a slab striking a column in plan (its model, and its arrays
    integrated on one ground) each need a compiled solver of their own; from the install's kernels (or, where the checkout's sources changed since it was installed,
    the extra group compiled here: ~3 min) a first run compiles and writes nothing."""
    status = subprocess.run([sys.executable, "-c", "import json, pounding.solver.kernels; from pounding.solver "
                             "import jit; print(json.dumps([jit.prebuilt_status()[0], jit.PREBUILT]))"],
                            capture_output=True, text=True, check=True, cwd=ROOT)
    current, folder = json.loads(status.stdout.splitlines()[-1])
    if not current:
        folder = str(tmp_path / "extra")
        subprocess.run([sys.executable, "-m", "pounding.prebuild", folder, "--group", "extra"], check=True, cwd=ROOT,
                       capture_output=True)
    done = subprocess.run([sys.executable, "-c", EXTRA_PROBE, folder], capture_output=True, text=True, cwd=ROOT,
                          env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "user")), timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    probe = json.loads(done.stdout.splitlines()[-1])
    assert probe["cache_hits"] == 4 and probe["written"] == [], probe
