"""numba start-up and cache handling (pounding/jit.py): faster, and never stale or different."""

from __future__ import annotations

import functools
import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

# A fresh process running the shipped pair, as `pounding run` does, in one of three modes:
# "fast" keeps the solver's start-up shortcuts, "numba" restores numba's own cache loader,
# "untested" takes the installed numba out of jit.TESTED_NUMBA before the solver is imported
# (numba.__version__ itself is left alone: numba keys its cache index on it, so changing it
# would recompile and rewrite the cache instead of testing the loader).
STARTUP_PROBE = r"""
import json, sys
import numpy as np
if sys.argv[2] == "untested":
    from pounding.solver import jit
    jit.TESTED_NUMBA = ((0, 1),)
    assert not jit.shortcuts_supported()
from pounding import load_model, simulate
from pounding.solver.integrator import _integrate
if sys.argv[2] == "numba":
    del _integrate._cache.load_overload  # back to numba's loader (refreshes every registry)
ds = simulate(load_model(sys.argv[1]))
scipy_linalg_during_run = "scipy.linalg" in sys.modules
from numba import njit
@njit
def dot(a, b):  # needs BLAS, hence scipy.linalg, compiled after the run
    return np.dot(a, b)
print(json.dumps({
    "shortcut_loader": "load_overload" in vars(_integrate._cache),
    "scipy_linalg_during_run": scipy_linalg_during_run,
    "cache_hits": int(sum(_integrate.stats.cache_hits.values())),
    "dot": float(dot(np.arange(3.0), np.arange(3.0))),
    "peak_drift_ratio": ds.peak_drift_ratio.values.tolist(),
    "peak_contact_force": ds.peak_contact_force.values.tolist(),
    "impact_time": ds.impact_time.values.tolist(),
    "impact_velocity": ds.impact_velocity.values.tolist(),
}))
"""


def _last_json_line(command: list[str], **kwargs) -> dict:
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, **kwargs)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout.strip().splitlines()[-1])


@functools.lru_cache(maxsize=None)
def _probe_once(mode: str) -> str:
    return json.dumps(_last_json_line([sys.executable, "-c", STARTUP_PROBE, str(ROOT / "models" / "pair.yaml"), mode]))


def _probe(mode: str) -> dict:
    """The probe's results in *mode*, run once per mode for the module: the shortcut tests and the prebuilt
    test compare the same fresh processes (the "fast" and "numba" runs of the shipped pair, ~3 s each), which
    are deterministic; each caller gets its own copy."""
    return json.loads(_probe_once(mode))


def test_start_up_shortcuts_change_nothing_but_time():
    # numba's own path first (it compiles if the cache is cold), then the
    # solver's loader, which must find the cached solver.
    reference = _probe("numba")
    fast = _probe("fast")
    assert fast["cache_hits"] == 1
    # The same machine code runs either way: results are bit-identical.
    for key in ("peak_drift_ratio", "peak_contact_force", "impact_time", "impact_velocity"):
        assert fast[key] == reference[key], key
    # More impacts than the table's first 64 rows: every grown row is a real impact.
    assert len(fast["impact_time"]) > 64
    assert np.all(np.isfinite(fast["impact_time"])) and np.all(np.isfinite(fast["impact_velocity"]))
    # The run itself never imports scipy.linalg (numba's BLAS probe is answered
    # without it), yet numba code compiled afterwards still gets BLAS.
    assert fast["scipy_linalg_during_run"] is False
    assert fast["dot"] == 5.0
    assert fast["shortcut_loader"] is True


def test_start_up_shortcuts_are_off_on_an_untested_numba():
    # On a numba release outside jit.TESTED_NUMBA (and the pyproject pin) neither
    # shortcut is applied: numba's own loader, numba's own BLAS probe.  The same
    # cached machine code runs, so the results are bit-identical to the fast path.
    from pounding.solver import jit

    assert jit.shortcuts_supported()  # this machine's numba is a tested one (the pin says so)
    untested = _probe("untested")
    fast = _probe("fast")
    assert untested["shortcut_loader"] is False and fast["shortcut_loader"] is True
    assert untested["scipy_linalg_during_run"] is True  # numba probed for BLAS by itself
    assert untested["cache_hits"] == 1
    for key in ("peak_drift_ratio", "peak_contact_force", "impact_time", "impact_velocity"):
        assert untested[key] == fast[key], key


def test_shortcuts_are_on_only_for_tested_numba_releases(monkeypatch):
    import numba

    from pounding.solver import jit

    for version, supported in (("0.68.1", True), ("0.67.0", True), ("0.69.0", False), ("0.66.0", False),
                               ("1.0.0", False), ("0.68.0rc1", True), ("dev", False), ("", False)):
        monkeypatch.setattr(numba, "__version__", version)
        assert jit.shortcuts_supported() is supported, version


def test_tested_numba_matches_the_pin():
    # The releases the shortcuts are switched on for are exactly those pyproject.toml allows.
    import re

    from pounding.solver import jit

    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    low, high = re.search(r'"numba>=0\.(\d+),<0\.(\d+)"', text).groups()
    assert set(jit.TESTED_NUMBA) == {(0, minor) for minor in range(int(low), int(high))}


# A kernel (main.py) that inlines a function of another file (law.py), cached like the solver, loaded
# from numba's cache or (argv[1], if given) a prebuilt folder; it prints what it wrote to numba's cache.
TOY_LAW = "from numba import njit\n\n@njit(cache=True)\ndef stiffness():\n    return {value}\n"
TOY_MAIN = textwrap.dedent("""
    import json, os, sys
    from numba import njit
    from pounding.solver import jit
    from . import law

    @njit(cache=True)
    def force(penetration):
        return law.stiffness() * penetration

    jit.stamp_caches_with_sources([force], [__file__, law.__file__])
    jit.load_from_cache_without_refresh(force)
    if len(sys.argv) > 1:
        jit.PREBUILT = sys.argv[1]
    folder = force._cache._cache_path
    print(json.dumps({"force": force(2.0), "cache_hits": int(sum(force.stats.cache_hits.values())),
                      "written": sorted(os.listdir(folder)) if os.path.isdir(folder) else []}))
""")


def test_cached_kernel_is_recompiled_when_a_file_it_inlines_changes(tmp_path):
    package = tmp_path / "toy"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "main.py").write_text(TOY_MAIN)
    law = package / "law.py"
    law.write_text(TOY_LAW.format(value="3.0"))
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"),
               PYTHONPATH=os.pathsep.join([str(tmp_path), str(ROOT), os.environ.get("PYTHONPATH", "")]))
    run = [sys.executable, "-c", "import toy.main"]

    def force_and_hits(found: dict) -> dict:
        return {key: found[key] for key in ("force", "cache_hits")}

    assert force_and_hits(_last_json_line(run, env=env)) == {"force": 6.0, "cache_hits": 0}  # compiled and cached
    assert force_and_hits(_last_json_line(run, env=env)) == {"force": 6.0, "cache_hits": 1}  # loaded from the cache
    # Edit only law.py (same size; its time moved on, as an editor would).
    law.write_text(TOY_LAW.format(value="5.0"))
    stat = law.stat()
    os.utime(law, (stat.st_atime + 10, stat.st_mtime + 10))
    # numba alone would load the cached force() with the old stiffness inlined (6.0).
    assert force_and_hits(_last_json_line(run, env=env)) == {"force": 10.0, "cache_hits": 0}
    assert force_and_hits(_last_json_line(run, env=env)) == {"force": 10.0, "cache_hits": 1}


def test_the_solver_frees_every_array_it_allocates_and_nothing_more():
    """Most solver kernels are compiled without reference counting (jit.NO_REFCOUNT): they may
    neither keep an array alive nor release one.  A kernel that returned an array, or handed a
    view it made to a counting caller, would leak it or free it while in use.  Over runs that take
    every path of the compiled solver (yielding storeys with P-Delta, impacts with grown tables,
    bumpers, links, a wall, several grounds, and stuck contacts that release), numba's allocator
    must count exactly as many frees as allocations once the results are dropped."""
    import gc

    from numba.core.runtime import _nrt_python as nrt
    from test_solver import pairs   # independent one-storey pairs, built directly

    from pounding.contact import laws as contact
    from pounding.model.model import load_model
    from pounding.simulation import _solve, support_motions
    from pounding.solver.integrator import integrate

    runs = [(model, support_motions(model)) for model in
            (load_model(ROOT / "models" / f"{name}.yaml") for name in
             ("pair_inelastic", "pair_links", "pair_wave_passage", "pair_bumper", "pair_column", "isolated_moat"))]
    # A floor resting against its neighbour, pushed onto it and then pulled away (as in
    # test_solver_adversarial): a stuck stereo-mechanical contact that releases.
    m1, m2, gap, dt = 1e5, 2e5, 0.01, 0.01
    sticky = pairs(m1, m2, 0.0, m2 * (2 * np.pi / 0.5) ** 2, [gap], contact.StereoMechanical(restitution=0.5))
    push_pull = np.where(np.arange(61) * dt < 0.305, -2.0, 3.0)

    def run_sticky():
        return integrate(sticky, push_pull, dt, 0.6, rtol=1e-6, atol=1e-8, atol_velocity=1e-7, output_dt=0.01,
                         initial_displacement=np.array([gap, 0.0]))

    for model, supports in runs:
        _solve(model, supports, 1.0, 0.01)   # compiled (or loaded) before counting
    run_sticky()
    counters = (nrt.memsys_get_stats_alloc, nrt.memsys_get_stats_free, nrt.memsys_get_stats_mi_alloc,
                nrt.memsys_get_stats_mi_free)
    was_enabled = nrt.memsys_stats_enabled()
    nrt.memsys_enable_stats()
    try:
        gc.collect()
        before = [count() for count in counters]
        impacts = 0
        for model, supports in runs:
            system, raw, _, rows = _solve(model, supports, supports.end_time, 0.01)
            impacts = max(impacts, raw.impact_time.size)
            del system, raw, rows
        raw = run_sticky()
        released_at = float(raw.impact_end_time[0])
        del raw
        gc.collect()
        allocated, freed, made, released = (count() - start for count, start in zip(counters, before))
    finally:
        if not was_enabled:
            nrt.memsys_disable_stats()
    assert impacts > 64               # a run's impacts outgrew the first table (64 rows): tables were grown
    assert 0.31 < released_at < 0.6   # the stuck contact released (its constraint path ran)
    assert allocated > 0 and made > 0
    assert (freed, released) == (allocated, made)


def test_every_solver_kernel_states_whether_it_is_inlined():
    """Every compiled kernel of ``pounding.solver`` sets numba's ``forceinline`` explicitly (jit.INLINED
    or jit.CALLED).  numba copies an unset ``forceinline`` from the compilation that triggers a
    kernel's first compile, so a kernel without it would be inlined everywhere or nowhere depending on
    which caller compiled it first (compile time and speed would depend on the order models ran)."""
    import importlib
    import pkgutil

    import pounding.solver
    from numba.core.registry import CPUDispatcher

    unset, inlined = [], []
    for info in pkgutil.iter_modules(pounding.solver.__path__):
        module = importlib.import_module(f"pounding.solver.{info.name}")
        for name, value in vars(module).items():
            if isinstance(value, CPUDispatcher) and value.py_func.__module__ == module.__name__:
                options = value.targetoptions
                if options.get("inline", "never") != "never":
                    continue  # numba-IR inlined into its caller: never compiled on its own
                if "forceinline" not in options:
                    unset.append(f"{info.name}.{name}")
                elif options["forceinline"]:
                    inlined.append(name)
    assert unset == []
    # the driver's per-step kernels are the inlined ones (the argument copies they save: docs/development/performance-log.md)
    assert {"stages", "error_norm", "locate_contact_events", "record_sample", "rhs"} <= set(inlined)




def _toy_package(tmp_path: Path, stiffness: str) -> tuple[list[str], dict[str, str]]:
    package = tmp_path / "toy"
    package.mkdir(exist_ok=True)
    (package / "__init__.py").write_text("")
    (package / "main.py").write_text(TOY_MAIN)
    (package / "law.py").write_text(TOY_LAW.format(value=stiffness))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(ROOT), os.environ.get("PYTHONPATH", "")]))
    return [sys.executable, "-c", "import toy.main", str(tmp_path / "prebuilt")], env


def test_prebuilt_kernels_are_loaded_instead_of_compiled_and_only_for_their_own_sources(tmp_path):
    """jit.PREBUILT (the kernels compiled when the package is built, pounding.prebuild): with numba's
    own cache empty, a kernel is loaded from it, not compiled, and nothing is written; a kernel built
    from other sources (a file it inlines edited since) is never loaded; a damaged file is a miss."""
    run, env = _toy_package(tmp_path, "3.0")
    built = tmp_path / "build-cache"
    # "the build": compile into a cache of its own, whose files become the prebuilt folder
    assert _last_json_line(run, env=dict(env, NUMBA_CACHE_DIR=str(built)))["cache_hits"] == 0
    (folder,) = [p for p in built.iterdir() if p.is_dir()]
    (tmp_path / "prebuilt").mkdir()
    for file in folder.iterdir():
        (tmp_path / "prebuilt" / file.name).write_bytes(file.read_bytes())
    # "a user's first run": an empty numba cache, the kernel comes from the prebuilt folder
    first = _last_json_line(run, env=dict(env, NUMBA_CACHE_DIR=str(tmp_path / "user-1")))
    assert first == {"force": 6.0, "cache_hits": 1, "written": []}
    # the same file saved again, unchanged but with a new time: still the same kernel (contents count)
    law = tmp_path / "toy" / "law.py"
    law.write_text(TOY_LAW.format(value="3.0"))
    os.utime(law, (law.stat().st_atime + 10, law.stat().st_mtime + 10))
    assert _last_json_line(run, env=dict(env, NUMBA_CACHE_DIR=str(tmp_path / "user-2")))["cache_hits"] == 1
    # an edited law: the prebuilt kernel (old stiffness inlined) must not run; compiled and cached instead
    law.write_text(TOY_LAW.format(value="5.0"))
    edited = _last_json_line(run, env=dict(env, NUMBA_CACHE_DIR=str(tmp_path / "user-3")))
    assert edited["force"] == 10.0 and edited["cache_hits"] == 0 and any(n.endswith(".nbi") for n in edited["written"])
    # a damaged prebuilt data file (the sources match again): compiled, never a crash
    law.write_text(TOY_LAW.format(value="3.0"))
    for file in (tmp_path / "prebuilt").glob("*.nbc"):
        file.write_bytes(b"not a kernel")
    damaged = _last_json_line(run, env=dict(env, NUMBA_CACHE_DIR=str(tmp_path / "user-4")))
    assert damaged["force"] == 6.0 and damaged["cache_hits"] == 0


def _prebuilt_copy(tmp_path: Path) -> tuple[Path, dict]:
    """A copy of a prebuilt folder made for these sources, and the results of the shipped pair under numba's
    own loader.  The package's own folder when it holds the kernels of these sources (the reference then
    comes from numba's cache, where the start-up tests above compiled it once); else the files numba caches
    while it compiles the solver for a first run in a cache of its own (the build: ~20 s of CPU)."""
    import pounding.solver.kernels  # noqa: F401  (the status is that of the solver's kernels)
    from pounding.solver import jit

    prebuilt = tmp_path / "prebuilt"
    prebuilt.mkdir()
    if jit.prebuilt_status()[0]:
        for file in Path(jit.PREBUILT).iterdir():
            (prebuilt / file.name).write_bytes(file.read_bytes())
        return prebuilt, _probe("numba")
    reference = _last_json_line([sys.executable, "-c", STARTUP_PROBE, str(ROOT / "models" / "pair.yaml"), "numba"],
                                env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "build-cache")))
    for folder in (tmp_path / "build-cache").iterdir():
        for file in folder.iterdir():
            (prebuilt / file.name).write_bytes(file.read_bytes())
    return prebuilt, reference


def test_the_solver_loads_its_prebuilt_kernels_with_an_empty_numba_cache(tmp_path):
    """The shipped pair run from a prebuilt folder (a copy of the package's, or the files numba cached for
    a first run) with an empty numba cache: nothing compiled, nothing written, results bit-identical to
    numba's own."""
    prebuilt, reference = _prebuilt_copy(tmp_path)
    user = tmp_path / "user"
    probe = STARTUP_PROBE.replace("from pounding import load_model", "from pounding.solver import jit as _jit\n"
                                  f"_jit.PREBUILT = {str(prebuilt)!r}\nfrom pounding import load_model")
    fast = _last_json_line([sys.executable, "-c", probe, str(ROOT / "models" / "pair.yaml"), "fast"],
                           env=dict(os.environ, NUMBA_CACHE_DIR=str(user)))
    assert fast["cache_hits"] == 1
    assert not [p for p in user.rglob("*") if p.is_file()]   # loaded, not compiled: the user cache stays empty
    for key in ("peak_drift_ratio", "peak_contact_force", "impact_time", "impact_velocity"):
        assert fast[key] == reference[key], key
    # `python -m pounding.prebuild --status` (jit.prebuilt_status): used here, and not when switched off
    status = ("import json; import pounding.solver.kernels; from pounding.solver import jit; "
              f"jit.PREBUILT = {str(prebuilt)!r}; print(json.dumps(jit.prebuilt_status()))")
    used, message = _last_json_line([sys.executable, "-c", status])
    assert used is True and "for these sources" in message, message
    used, message = _last_json_line([sys.executable, "-c", status], env=dict(os.environ, POUNDING_PREBUILT="off"))
    assert used is False and "POUNDING_PREBUILT=off" in message, message


def test_build_environment_pins_the_same_numba_as_the_package():
    # Kernels compiled ahead of time (setup.py, pounding.prebuild) load only under the numba that built
    # them: the build environment's numba range must be the runtime's.
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    pins = re.findall(r'"numba[^"]*"', text)
    assert len(pins) == 2 and pins[0] == pins[1], pins
