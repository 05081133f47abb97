"""Regression tests of issue 25 §2–§4 (third adversarial audit): one test per item, each failing before its fix.

Cases that would take hours or allocate hundreds of GiB are run in a
subprocess under ``RLIMIT_AS`` and a time limit (:func:`tests.test_fuzz.pounding`;
one-run commands in a child forked from a warmed process, :func:`one_run`)
and must be refused before any run starts.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr

from pounding.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_fuzz import ForkServer, _write_case, base_model, pounding, verdict  # noqa: E402
from test_hostile import _error  # noqa: E402


@pytest.fixture(scope="module")
def one_run(tmp_path_factory):
    """``pounding ARGS`` of a one-run command (run, rerun, info) as tests/test_fuzz.py runs its cases: a child
    forked from a process that has imported pounding and loaded its solver, under the same memory cap
    (3 GB) and time limit as a fresh ``python -m pounding``; (exit status, stdout, stderr).  What a refusal
    before allocating costs is then its own work, not the ~2 s start-up of an interpreter per case."""
    server = ForkServer(tmp_path_factory.mktemp("one-run") / "server")
    yield server.pounding
    server.close()

ROOT = Path(__file__).resolve().parents[1]


# --------------------------------------------------------------------------- #
# §4 Data loss: two runs onto one output
# --------------------------------------------------------------------------- #


def test_a_file_written_meanwhile_is_not_replaced(case, tmp_path, capsys, monkeypatch):
    # Before: `run -o same.nc` replaced a same.nc that another run wrote while this one computed.
    import pounding.simulation as simulation

    target = tmp_path / "same.nc"
    real = simulation.simulate

    def simulate_while_another_writes(*args, **kwargs):
        ds = real(*args, **kwargs)
        target.write_bytes(b"the other run's archive")
        return ds

    monkeypatch.setattr(simulation, "simulate", simulate_while_another_writes)
    assert main(["run", str(case / "model.yaml"), "-o", str(target)]) == 2
    line = _error(capsys)
    assert "was written by another process" in line and f"same.{os.getpid()}.nc" in line
    assert target.read_bytes() == b"the other run's archive"
    kept = tmp_path / f"same.{os.getpid()}.nc"
    assert xr.open_dataset(kept).attrs["model_name"] == "fuzz"   # nothing computed is lost
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["same.nc", kept.name])


def test_a_live_writer_of_the_same_output_is_refused_before_running(case, tmp_path):
    # Before: the second run computed and silently replaced the first one's archive.
    target = tmp_path / "same.nc"
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from pounding.results.archive import output_lock\n"
         f"with output_lock({str(target)!r}):\n    print('held', flush=True); time.sleep(60)"],
        stdout=subprocess.PIPE, text=True, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    try:
        assert holder.stdout.readline().strip() == "held"
        started = time.perf_counter()
        status, out, err = pounding(["run", str(case / "model.yaml"), "-o", str(target)], tmp_path)
        assert status == 2 and verdict(status, out, err, None) is None, err
        assert f"is being written by another pounding run (pid {holder.pid} on" in err
        assert "wrote" not in out and not target.exists()
        assert time.perf_counter() - started < 30
    finally:
        holder.kill()   # a killed holder leaves no claim: the next run proceeds
        holder.wait()
    status, out, err = pounding(["run", str(case / "model.yaml"), "-o", str(target)], tmp_path)
    assert status == 0 and f"wrote {target}" in out, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["same.nc"]


def test_two_runs_started_together(case, tmp_path):
    # Before: both said "wrote same.nc" and one archive silently replaced the other.
    target = tmp_path / "same.nc"
    environ = dict(os.environ, PYTHONPATH=str(ROOT))
    runs = [subprocess.Popen([sys.executable, "-m", "pounding", "run", str(case / "model.yaml"), "-o", str(target)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=environ)
            for _ in range(2)]
    outcomes = [(run.wait(timeout=120), run.stdout.read(), run.stderr.read()) for run in runs]
    assert sorted(status for status, _, _ in outcomes) == [0, 2], outcomes
    assert sum(f"wrote {target}" in out for _, out, _ in outcomes) == 1
    assert all(verdict(*outcome, None) is None for outcome in outcomes)
    assert [p.name for p in tmp_path.iterdir()] == ["same.nc"]


def test_overwrite_still_replaces(case, tmp_path):
    target = tmp_path / "same.nc"
    target.write_bytes(b"old")
    assert main(["run", str(case / "model.yaml"), "-o", str(target), "--overwrite"]) == 0
    assert xr.open_dataset(target).attrs["model_name"] == "fuzz"


# --------------------------------------------------------------------------- #
# §4 One-line errors
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("command", ["info", "plot"])
def test_a_study_archive_without_status(tmp_path, capsys, command):
    # Before: AttributeError: 'Dataset' object has no attribute 'status'.
    archive = tmp_path / "sweep.nc"
    xr.Dataset({"peak_drift_ratio": ("scenario", [0.01, 0.02])},
               attrs={"source": "pounding 1.0", "sweep_name": "s", "title": "sweep s"}).to_netcdf(archive)
    args = ["info", str(archive)] if command == "info" else ["plot", str(archive), "-o", str(tmp_path / "png")]
    assert main(args) == 2
    line = _error(capsys)
    assert f"damaged archive: {archive}" in line and "status" in line


def test_an_output_name_that_is_not_utf8_is_refused_before_running(case, tmp_path, capsys, monkeypatch):
    # Before: UnicodeEncodeError from netCDF4 after the whole simulation.
    import pounding.simulation as simulation

    monkeypatch.setattr(simulation, "simulate", lambda *a, **k: pytest.fail("simulated before refusing"))
    name = os.fsdecode(b"bad\xff.nc")
    assert main(["run", str(case / "model.yaml"), "-o", str(tmp_path / name)]) == 2
    line = _error(capsys)
    assert "bad\\xff.nc" in line and "not valid UTF-8" in line and "choose a UTF-8 name" in line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("where", ["under-a-file", "yaml", "no-suffix", "read-only"])
def test_records_show_plot_targets(case, tmp_path, capsys, monkeypatch, where):
    # Before: FileNotFoundError / ValueError (format 'yaml') / PermissionError tracebacks, or `--plot foreign`
    # wrote foreign.png and said it wrote foreign.
    record = str(case / "quake.txt")
    target = {"under-a-file": case / "quake.txt" / "r.png", "yaml": tmp_path / "r.yaml",
              "no-suffix": tmp_path / "foreign", "read-only": tmp_path / "ro" / "r.png"}[where]
    if where == "read-only":
        (tmp_path / "ro").mkdir()
        real = os.access
        monkeypatch.setattr(os, "access", lambda p, mode: False if str(p) == str(tmp_path / "ro") else real(p, mode))
        (tmp_path / "ro").chmod(0o555)
    try:
        assert main(["records", "show", record, "--dt", "0.01", "--units", "g", "--plot", str(target)]) == 2
        captured = capsys.readouterr()
    finally:
        (tmp_path / "ro").exists() and (tmp_path / "ro").chmod(0o755)
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pounding: error: ") and str(target) in err[0], err
    assert {"under-a-file": "is a file", "yaml": "ending in .png", "no-suffix": "foreign.png",
            "read-only": "not writable"}[where] in err[0]
    assert "wrote" not in captured.out and not list(tmp_path.glob("**/*.png"))


def test_dask_workers_that_cannot_start_are_one_line(case, tmp_path):
    # Before: 75-164 lines of nanny tracebacks and exit 1 (here the workers run out of file descriptors).
    import resource

    (tmp_path / "s.yaml").write_text(f"model: {case / 'model.yaml'}\naxes:\n  contacts[*].gap: [0.002, 0.003]\n")

    def few_files() -> None:
        resource.setrlimit(resource.RLIMIT_NOFILE, (30, 30))

    done = subprocess.run([sys.executable, "-m", "pounding", "sweep", str(tmp_path / "s.yaml"), "-o",
                           str(tmp_path / "s.nc"), "--workers", "2", "--no-progress"], capture_output=True, text=True,
                          timeout=120, preexec_fn=few_files, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert verdict(done.returncode, done.stdout, done.stderr, None) is None and done.returncode == 2, done.stderr
    assert "could not start 2 Dask worker processes (OSError: [Errno 24] Too many open files)" in done.stderr
    assert len(done.stderr.strip().splitlines()) <= 2   # the sweep's own "N scenarios" note and the error


# --------------------------------------------------------------------------- #
# §2 Every run and study has a bound on its work
# --------------------------------------------------------------------------- #


def _linked(folder: Path, law: str, **parameters) -> Path:
    model = base_model()
    model["ground_motion"]["duration"] = 8.0
    model["links"] = [{"between": ["A", "B"], "levels": [[2, 2]], "law": law, **parameters}]
    return _write_case(folder, model)


@pytest.mark.parametrize("law, parameters, expected", [
    ("maxwell", {"stiffness": 1.0e9, "damping": 1.0}, "relaxation time c/k = 1e-09 s is 7e+07 times shorter than "
                                                      "the shortest period"),
    ("viscous", {"damping": 1.0e15}, "relaxes the floors' relative motion in m/c = 1e-10 s"),
])
def test_a_stiff_link_is_refused_before_running(tmp_path, one_run, law, parameters, expected):
    # Before: hours of solver steps for 8 s of record, silently (2.4e9 and 2.4e10 steps).
    path = _linked(tmp_path, law, **parameters)
    started = time.perf_counter()
    status, out, err = one_run(["run", str(path), "-o", str(tmp_path / "out.nc")], tmp_path, 60)
    assert status == 2 and verdict(status, out, err, None) is None, err
    assert expected in err and "the solver would take about" in err and "steps for 8 s" in err
    assert time.perf_counter() - started < 60 and not (tmp_path / "out.nc").exists()


def test_the_step_estimate_matches_the_solver(tmp_path):
    """The estimate behind the refusal is the step count of a stiff run, within 30 %."""
    from pounding.model.model import load_model
    from pounding.model.scales import check_work
    from pounding.simulation import simulate

    path = _linked(tmp_path, "maxwell", stiffness=1.0e9, damping=1.0e4)   # c/k = 1e-5 s
    model = load_model(path)
    ds = simulate(model, duration=0.2)
    estimate = check_work(model, 0.2)
    assert 0.7 < ds.attrs["solver_steps"] / estimate < 1.3


@pytest.mark.parametrize("options, expected", [
    (["--hunt-step", "1e-7", "--hunt-increment", "0"], "--hunt-step 1e-07 g is below the resolution of the levels"),
    (["--hunt-ceiling", "1e9", "--hunt-step", "1e-3"], "--hunt would make up to 2e+05 runs per record"),
    (["--hunt-ceiling", "1e9", "--hunt-step", "1e-3", "--hunt-increment", "0"], "up to 1e+12 runs per record"),
    (["--tolerance", "1e-9"], "--tolerance 1e-09 g is below the resolution"),
])
def test_hunt_settings_that_never_end_are_refused(case, tmp_path, options, expected):
    # Before: --hunt-step 1e-7 --hunt-increment 0 ran one level forever with growing memory; a ceiling of
    # 1e9 g was accepted (~1e12 runs).
    started = time.perf_counter()
    status, out, err = pounding(["ida", str(case / "model.yaml"), "--hunt", *options, "--workers", "1",
                                 "--no-progress"], tmp_path, limit=60)
    assert status == 2 and verdict(status, out, err, None) is None, err
    assert expected in err
    assert time.perf_counter() - started < 60


def test_a_hunt_never_repeats_a_level_and_stays_within_its_estimate():
    import itertools

    from pounding.studies.ida.hunt import next_hunt_level
    from pounding.studies.ida.schedule import Hunt

    for start, step, increment, tolerance, runs, ceiling, collapse in itertools.product(
            [0.1, 1.0], [1e-6, 0.01, 0.37], [0.0, 1e-6, 0.05], [2e-6, 0.05], [1, 12], [1.0, 5.0],
            [None, 0.0, 0.25, 0.999999, 3.3]):
        hunt = Hunt(start=start, step=step, increment=increment, tolerance=tolerance, runs=runs, ceiling=ceiling)
        if hunt.ceiling < hunt.start or hunt.max_runs() > 5000:
            continue
        hunt.check()
        done: list[tuple[float, bool]] = []
        # The levels run so far, kept as they are appended (a set rebuilt from *done* at every level was
        # two thirds of this test's time: up to 5,000 levels a hunt); the estimate is the hunt's, fixed.
        levels, estimate = set(), hunt.max_runs()
        while (level := next_hunt_level(hunt, done)) is not None:
            assert level not in levels
            done.append((level, collapse is not None and level >= collapse))
            levels.add(level)
            assert len(done) <= estimate, hunt


def test_an_ida_prints_its_number_of_runs_before_it_starts(case, tmp_path):
    status, out, err = pounding(["ida", str(case / "model.yaml"), "--levels", "0.1,0.2", "--duration", "0.3",
                                 "--workers", "1", "--no-progress"], tmp_path, limit=120)
    assert status == 0, err
    assert "1 records x 2 levels x 1 variant(s) = 2 runs" in err.splitlines()[0]
    status, out, err = pounding(["ida", str(case / "model.yaml"), "--hunt", "--hunt-ceiling", "2e4",
                                 "--hunt-increment", "0", "--workers", "1", "--no-progress"], tmp_path, limit=60)
    assert status == 2 and "--hunt would make up to 2e+05 runs per record" in err, err



@pytest.mark.parametrize("command, expected", [
    (["gap"], "gap 'gap-model': 1 scenarios = 1 record"),
    (["compare", "--xi", "ye,exact"], "compare 'compare-model': 2 scenarios = 2 xi x 1 record"),
])
def test_gap_and_compare_print_their_number_of_runs_before_they_start(case, tmp_path, command, expected):
    status, out, err = pounding([command[0], str(case / "model.yaml"), *command[1:], "--duration", "0.3",
                                 "--workers", "1", "--no-progress", "-o", str(tmp_path / "study.nc")],
                                tmp_path, limit=120)
    assert status == 0, err
    assert err.splitlines()[0] == expected, err

# --------------------------------------------------------------------------- #
# §3 Memory checked before allocating
# --------------------------------------------------------------------------- #


def _wave_model(folder: Path, position: float, velocity: float, west: float = 0.0) -> Path:
    model = base_model()
    model["ground_motion"]["wave_passage"] = {"apparent_velocity": velocity, "position": {"A": west, "B": position}}
    return _write_case(folder, model)


@pytest.mark.parametrize("position, velocity, west, expected", [
    (1e9, 1.0, 0.0, "a lag of 1e+09 s (building B) on a 0.01 s record step would need about 4.8 TB"),
    (3e6, 1.0, 0.0, "a lag of 3e+06 s (building B) on a 0.01 s record step would need about 14.4 GB"),
    (1e308, 1e-300, 0.0, "the lag of building B is inf s (position difference 1e+308 m / apparent velocity"),
    (1.7e308, 500.0, -1.7e308, "the lag of building B is inf s (position difference inf m"),
])
def test_wave_passage_lags_are_checked_before_allocating(tmp_path, one_run, position, velocity, west, expected):
    # Before: MemoryError / ValueError (negative dimensions) / OverflowError tracebacks from the lag arrays.
    path = _wave_model(tmp_path, position, velocity, west)
    status, out, err = one_run(["run", str(path), "-o", str(tmp_path / "out.nc")], tmp_path, 60)
    assert status == 2 and verdict(status, out, err, None) is None, err
    assert f"{path.name}: ground_motion.wave_passage: " in err and expected in err


@pytest.mark.parametrize("damping", [{"modal": [0.05]}, {"ratio": 0.05, "modes": [1, 2]}])
def test_ten_thousand_storeys_are_checked_before_the_eigensolver(tmp_path, one_run, damping):
    # Before: MemoryError from numpy's eigh (dense 10,000 x 10,000 matrices under a 3 GB cap).
    model = base_model()
    model["buildings"][0]["storeys"]["count"] = 10_000
    model["buildings"][0]["damping"] = damping
    path = _write_case(tmp_path, model)
    status, out, err = one_run(["run", str(path), "-o", str(tmp_path / "out.nc")], tmp_path, 60)
    assert status == 2 and verdict(status, out, err, None) is None, err
    assert "building A: the modes of its 10000 storeys (dense 10000 x 10000 matrices) would need about" in err
    assert "lump several storeys into one" in err


def _huge_netcdf(path: Path, **attributes) -> None:
    import netCDF4

    with netCDF4.Dataset(path, "w") as nc:   # 2.4 GB declared, 16 kB on disk (unwritten chunks)
        nc.createDimension("x", 300_000_000)
        nc.createVariable("v", "f8", ("x",), zlib=True, chunksizes=(1_000_000,))[:10] = 1.0
        for key, value in attributes.items():
            nc.setncattr(key, value)


@pytest.mark.parametrize("kind, command, expected", [
    ("foreign", "rerun", "not a pounding run archive"),
    ("run", "rerun", "reading its 1 variables (2.4 GB) would need about 4.8 GB"),
    ("run", "info", "reading its 1 variables (2.4 GB)"),
    ("sweep", "info", "reading its 1 variables (2.4 GB)"),
])
def test_a_huge_netcdf_is_not_loaded_whole(tmp_path, one_run, kind, command, expected):
    # Before: the 2.4 GB variable was loaded (MemoryError under the cap) before anything was checked.
    attributes = {"foreign": {}, "run": {"source": "pounding 1", "run_spec": "{}"},
                  "sweep": {"source": "pounding 1", "sweep_name": "s"}}[kind]
    archive = tmp_path / "big.nc"
    _huge_netcdf(archive, **attributes)
    args = ["rerun", str(archive), "-o", str(tmp_path / "again.nc")] if command == "rerun" else ["info", str(archive)]
    status, out, err = one_run(args, tmp_path, 60)
    assert status == 2 and verdict(status, out, err, None) is None, err
    assert expected in err


def test_a_sweep_over_lags_reports_the_refusal_per_scenario(case, tmp_path):
    # Before: the scenario's error was numpy's "Unable to allocate 745 GiB for an array ...".
    from pounding.studies.sweep import load_sweep, run_sweep

    _wave_model(tmp_path, 30.0, 500.0)
    (tmp_path / "s.yaml").write_text("model: model.yaml\naxes:\n  ground_motion.wave_passage.apparent_velocity: "
                                     "[500.0, 3.0e-8]\n")
    ds = run_sweep(load_sweep(tmp_path / "s.yaml"), None, workers=1, progress=False)
    errors = [str(e) for e in ds.error.values.ravel() if str(e)]
    assert list(ds.status.values.ravel()) == ["ok", "error"], errors
    assert "a lag of 1e+09 s (building B) on a 0.01 s record step would need about 4.8 TB" in errors[0]


# --------------------------------------------------------------------------- #
# §1 smaller items (not the contact numerics)
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("levels, expected", [
    ([[1, 1], [1, {"storey": 2, "at": 1e-17}]], "levels[1][1].at: is 1e-17, within 1e-06 of the storey height of "
                                               "floor 1: write the floor number (1)"),
    ([[2, 2], [2, {"storey": 2, "at": 1 - 1e-12}]], "of floor 2: write the floor number (2)"),
    ([[1, {"storey": 1, "at": 1e-9}]], "of the ground, which does not move"),
    ([[1, {"storey": 2, "at": 0.5}], [1, {"storey": 2, "at": 0.5 + 1e-12}]], "are already joined by this entry"),
])
def test_equivalent_contacts_are_refused(tmp_path, capsys, levels, expected):
    # Before: a column point at 1e-17 beside the same floor contact was accepted and its impacts counted twice.
    model = base_model()
    model["contacts"][0]["levels"] = levels
    path = _write_case(tmp_path, model)
    assert main(["run", str(path), "-o", str(tmp_path / "out.nc")]) == 2
    line = _error(capsys)
    assert f"{path}:" in line and expected in line
    assert not (tmp_path / "out.nc").exists()


def test_a_stop_drift_ratio_below_resolution_is_refused(tmp_path, capsys):
    # Before: stop_drift_ratio 1e-300 reported a collapse at t = 0 with zero drift.
    model = base_model()
    model["solver"]["stop_drift_ratio"] = 1e-300
    path = _write_case(tmp_path, model)
    assert main(["run", str(path), "-o", str(tmp_path / "out.nc")]) == 2
    assert "solver.stop_drift_ratio must be >= 0.0001 (0.01 %" in _error(capsys)
    model["solver"]["stop_drift_ratio"] = 0.1   # a real collapse limit still runs
    path = _write_case(tmp_path, model)
    assert main(["run", str(path), "-o", str(tmp_path / "out.nc")]) == 0
