"""What a study's worker keeps between runs, and the shortcuts around the solver, give the runs' own results.

A worker that runs one model many times (an IDA: every stripe of a variant and a record) keeps the
model's assembly (:func:`pounding.simulation.reused_assembly`); a cache keyed wrong would hand one
model another's stiffnesses.  The energy audit is summed on plain arrays; xarray is kept from
importing ``dask.array`` where nothing is a dask array (:mod:`pounding.results.lazy_dask`).  A sweep's,
compare's or gap study's worker reads each run's values from its plain arrays
(:func:`pounding.simulation.simulate_arrays`), which must hold the archive's values.
"""

from __future__ import annotations

import gc
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from pounding.model.model import model_from_data
from pounding.simulation import ground_rows, reused_assembly, simulate, simulate_peaks, support_motions

ROOT = Path(__file__).resolve().parents[1]
PAIR = ROOT / "models" / "pair.yaml"

#: Every peak of simulate_peaks that a study keeps.
PEAKS = ("peak_drift_ratio", "residual_drift_ratio", "impact_count", "peak_contact_force")


def pair(duration: float = 4.0, **storey_a) -> object:
    """models/pair.yaml on its record's first *duration* s, building A's storeys changed by *storey_a*."""
    data = yaml.safe_load(PAIR.read_text())
    data["ground_motion"]["duration"] = duration
    data["buildings"][0]["storeys"].update(storey_a)
    return model_from_data(data, name="pair", source=PAIR.read_text(), base_dir=str(PAIR.parent))


def assert_same_peaks(a: dict, b: dict) -> None:
    for key in PEAKS:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)   # bit for bit: the same run
    assert a["status"] == b["status"]


def test_each_model_object_has_its_own_assembly_and_keeps_it():
    """Two models, even built from one document, never share an assembly; a model that is gone takes
    its entry along; the same model on the same ground and duration gets the same assembly."""
    first, twin, stiffer = pair(), pair(), pair(stiffness=7.0e8)
    ground = ground_rows(support_motions(first, where="yaml"))
    a = reused_assembly(first, ground, 4.0)
    assert reused_assembly(first, ground, 4.0) is a
    assert reused_assembly(twin, ground, 4.0) is not a
    assert reused_assembly(first, ground, 5.0) is not a   # another duration: checked and assembled again
    # building A's 8 storeys come first in the solver's storey arrays: 3.5e8 N/m each, doubled in *stiffer*
    np.testing.assert_array_equal(a.system.storey_stiffness[:8], 3.5e8)
    np.testing.assert_array_equal(reused_assembly(stiffer, ground, 4.0).system.storey_stiffness[:8], 7.0e8)
    from pounding import simulation

    held = len(simulation._ASSEMBLIES)
    del stiffer
    gc.collect()
    assert len(simulation._ASSEMBLIES) == held - 1


def test_models_run_in_turn_with_reuse_give_their_fresh_runs_peaks():
    """Two different models run alternately with their assemblies kept give, each time, exactly the
    peaks of a fresh run (the solver never writes into an assembly), and not each other's."""
    soft, stiff = pair(), pair(stiffness=7.0e8)
    fresh = {"soft": simulate_peaks(pair()), "stiff": simulate_peaks(pair(stiffness=7.0e8))}
    assert not np.array_equal(fresh["soft"]["peak_drift_ratio"], fresh["stiff"]["peak_drift_ratio"])
    for name, model in (("soft", soft), ("stiff", stiff), ("soft", soft), ("stiff", stiff)):
        assert_same_peaks(simulate_peaks(model, reuse=True), fresh[name])


def test_a_scaled_record_on_a_kept_assembly_gives_the_fresh_run():
    """An IDA's runs of one model differ only in the record's factor: the kept assembly (built at the
    first factor) with another factor is the fresh run at that factor."""
    from pounding.records.processing import scale_record
    from pounding.simulation import processed_record_for

    model = pair()
    record = processed_record_for(model, where="yaml")
    for factor in (0.5, 2.0, 0.5):
        kept = simulate_peaks(model, scale_record(record, factor), reuse=True)
        assert_same_peaks(kept, simulate_peaks(pair(), scale_record(record, factor)))
        assert kept["record_scale"] == pytest.approx(factor * record.scale, rel=0, abs=0)


@pytest.mark.parametrize("path", ["models/pair_inelastic.yaml", "models/corner_pair.yaml"])
def test_energy_closure_is_the_documented_sum_of_the_archive(path):
    """The closure error equals the formula of its docstring evaluated with xarray's arithmetic on the
    archive's own energy histories, bit for bit (the sum on plain arrays is the same sum)."""
    from pounding.model.model import load_model

    ds = simulate(load_model(ROOT / path))
    if "plane" in ds.dims:   # floors in plan: max |E_0 + E_in − Σ parts| / max |E_0 + E_in|
        parts = (ds.energy_kinetic + ds.energy_damping + ds.energy_plane_strain + ds.energy_p_delta
                 + ds.energy_contact + ds.get("energy_hysteretic", 0.0) + ds.get("energy_friction", 0.0)
                 + ds.get("energy_link_dissipated", 0.0) + ds.get("energy_link_strain", 0.0))
        supplied = float(parts[0]) + ds.energy_input + ds.get("energy_ground_work", 0.0)
    else:                    # max |E_in − Σ parts| / max |E_in|
        parts = (ds.energy_kinetic + ds.energy_strain + ds.energy_damping + ds.energy_contact_dissipated
                 + ds.energy_contact_strain + ds.energy_hysteretic)
        supplied = ds.energy_input
    expected = float(np.abs(supplied - parts).max()) / float(np.abs(supplied).max())
    assert ds.attrs["energy_closure_error"] == expected
    assert 0.0 < expected < 1e-3   # a converged run closes; a zero would mean nothing was summed


def test_datasets_are_built_without_importing_dask_array_and_dask_arrays_still_work():
    """A process that builds and writes a run's dataset does not import dask.array (0.3-1.2 s); once
    the process imports it, xarray keeps a dask array lazy, as it always did."""
    pytest.importorskip("dask.array")
    script = (
        "import sys, numpy as np, xarray as xr\n"
        "import pounding.results.dataset\n"
        "ds = xr.Dataset({'a': ('t', np.arange(4.0))}, coords={'t': np.arange(4)})\n"
        "assert float(ds.a.sum()) == 6.0\n"
        "print('dask.array' in sys.modules)\n"
        "import dask.array as da\n"
        "v = xr.DataArray(da.ones(6, chunks=3), dims='t')\n"
        "print(v.chunks, type(v.data).__module__.split('.')[0], float(v.sum()))\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, cwd=ROOT,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    imported, chunks = out.stdout.splitlines()
    assert imported == "False"
    assert chunks == "((3, 3),) dask 6.0"


@pytest.mark.parametrize("path", ["models/pair_links.yaml", "models/pair_on_soil.yaml", "models/corner_pair.yaml"])
def test_a_run_left_as_arrays_holds_its_archive_values(path):
    """What a sweep's or gap study's worker reads instead of the dataset (simulate_arrays) holds every
    variable, coordinate and attribute of simulate()'s archive, bit for bit, less run_spec (what a rerun
    needs; the worker never writes the run's archive).  Models of one chain of storeys, of weighted rows
    (a foundation) and in plan."""
    from pounding.model.model import load_model
    from pounding.simulation import simulate_arrays

    model = load_model(ROOT / path).with_ground_motion(duration=3.0)
    ds, run = simulate(model), simulate_arrays(model)
    assert set(ds.variables) == set(run.variables)
    assert set(ds.coords) == set(run.coords)
    assert dict(ds.sizes) == run.dims
    for name, variable in ds.variables.items():
        assert variable.dims == run[name].dims, name
        np.testing.assert_array_equal(variable.values, run[name].values, err_msg=name)   # bit for bit
    moving = {"history", "created", "wall_time", "run_spec"}   # the clock, and the archive's own
    assert {k: repr(v) for k, v in ds.attrs.items() if k not in moving} == \
        {k: repr(v) for k, v in run.attrs.items() if k not in moving}   # repr: a NaN equals a NaN
    assert "run_spec" in ds.attrs and "run_spec" not in run.attrs


def test_a_sweep_scenario_keeps_the_same_values_whether_its_archive_is_written_or_not():
    """A scenario run with --keep-histories (its dataset built and returned) and without (plain arrays)
    gives the same part: peaks, energy closure error, warnings, intensity."""
    from pounding.studies.sweep.scenario import run_scenario
    from pounding.studies.sweep.spec import load_sweep

    sweep = load_sweep(ROOT / "tests" / "data" / "fingerprint_sweep.yaml")
    task = next(iter(sweep.scenarios())).task(sweep_label=sweep.label, name=sweep.model_name)
    kept, light = run_scenario({**task, "keep_history": True}), run_scenario(task)
    assert kept["status"] == light["status"] == "ok", (kept["error"], light["error"])
    assert "dataset" in kept and "dataset" not in light
    for part in (kept, light):
        for name in ("dataset", "wall_time", "solver_wall_time"):   # the clock; the archive kept
            part.pop(name, None)
    assert kept == light


def test_buildings_of_the_same_storeys_share_their_modes_and_a_changed_storey_gets_its_own():
    """A sweep's worker builds a new model for every scenario; the modes of a building whose storeys are
    unchanged are kept (pounding.model.building.modes_key), those of a changed one computed: each equal,
    bit for bit, to the eigensolution of its own matrices."""
    from pounding.model import floors

    first, twin, stiffer = pair(), pair(), pair(stiffness=7.0e8)
    assert twin.buildings[0] is not first.buildings[0]
    assert twin.buildings[0].modes[1] is first.buildings[0].modes[1]   # kept: solved once for both
    assert stiffer.buildings[1].modes[1] is first.buildings[1].modes[1]   # B is the same in all three
    assert not np.array_equal(stiffer.buildings[0].modes[0], first.buildings[0].modes[0])
    # building A: 8 storeys of 3.5e8 N/m, 2.5e5 kg; first period 0.91 s (models/pair.yaml), 0.91 / sqrt(2) stiffer
    assert first.buildings[0].periods[0] == pytest.approx(0.91, abs=0.005)   # the file's own 2-digit figure
    assert stiffer.buildings[0].periods[0] == pytest.approx(first.buildings[0].periods[0] / np.sqrt(2.0),
                                                            rel=1e-12)   # K doubled, M the same: round-off only
    for building in (first.buildings[0], stiffer.buildings[0], first.buildings[1]):
        omega, phi = floors.natural_modes(building.stiffness_matrix(), building.mass_matrix(),
                                          building.dofs_per_floor)
        np.testing.assert_array_equal(building.modes[0], omega)   # bit for bit: the same solution
        np.testing.assert_array_equal(building.modes[1], phi)


def test_the_modes_key_holds_every_bit_the_matrices_are_made_of():
    """Storeys that differ in any number a building's mass or stiffness matrix reads get two keys, down to the
    sign of a zero (equal as floats, but not the same bits); numbers written as an integer or a float are one."""
    from pounding.model.building import modes_key
    from pounding.model.floors import Plane, Storey

    def storey(**changed) -> Storey:
        fields = dict(mass=2.5e5, height=3.2, centre=(0.0, 0.0), radius_of_gyration=0.0,
                      planes=(Plane("x", 0.0, 3.5e8),))
        fields.update(changed)
        return Storey(**fields)

    base = modes_key((storey(),), 1)
    assert modes_key((storey(),), 1) == base
    assert modes_key((storey(mass=250000),), 1) == base   # the same float
    assert modes_key((storey(height=3.0),), 1) == base   # a height is in neither matrix
    for other in (storey(mass=2.5e5 * (1 + 2 ** -52)), storey(centre=(-0.0, 0.0)), storey(radius_of_gyration=1.0),
                  storey(planes=(Plane("x", 0.0, 3.5e8 + 1.0),)), storey(planes=(Plane("y", 0.0, 3.5e8),)),
                  storey(planes=(Plane("x", 1.0, 3.5e8),))):
        assert modes_key((other,), 1) != base, other
    assert modes_key((storey(),), 3) != base   # floors in plan
    assert modes_key((storey(), storey()), 1) != base


def test_a_run_left_as_arrays_computes_a_history_only_when_it_is_read():
    """The histories a study's worker does not read (here the floors' absolute accelerations) are computed
    when read, once, and then hold the archive's values; the worker's own reads leave them uncomputed."""
    from pounding.results.checks import run_warnings
    from pounding.results.run_arrays import Deferred
    from pounding.simulation import simulate_arrays
    from pounding.studies.sweep.scenario import scenario_peaks

    model = pair(duration=3.0)
    run = simulate_arrays(model)
    scenario_peaks(run), run_warnings(run), run.dims
    assert isinstance(run.data_vars["absolute_acceleration"][1], Deferred)   # not read: not computed
    values = run["absolute_acceleration"].values
    assert run["absolute_acceleration"].values is values   # computed once
    np.testing.assert_array_equal(values, simulate(model).absolute_acceleration.values)   # bit for bit
    calls = []
    later = Deferred(lambda: calls.append(1) or 7.0)
    assert calls == [] and later() == later() == 7.0 and calls == [1]


def test_a_run_in_plan_left_as_arrays_computes_the_histories_no_worker_reads_only_when_read():
    """In plan as on one axis: a sweep's and gap study's worker reads the peaks, labels, energies and the floors'
    states; the points' penetrations, the planes' shears and drift ratios are computed when read, and then
    hold the archive's values bit for bit."""
    from pounding.model.model import load_model
    from pounding.results.checks import run_warnings
    from pounding.results.run_arrays import Deferred
    from pounding.simulation import simulate_arrays
    from pounding.studies.common import floor_states
    from pounding.studies.sweep.scenario import scenario_peaks

    model = load_model(ROOT / "models/corner_pair.yaml").with_ground_motion(duration=3.0)
    run = simulate_arrays(model)
    scenario_peaks(run), run_warnings(run), floor_states(run), run.dims
    deferred = ("penetration", "plane_shear", "plane_drift_ratio")
    assert all(isinstance(run.data_vars[name][1], Deferred) for name in deferred)   # not read: not computed
    ds = simulate(model)
    for name in deferred:
        np.testing.assert_array_equal(run[name].values, ds[name].values, err_msg=name)   # bit for bit


def test_a_sweep_worker_gives_the_same_part_with_the_modes_kept_or_solved_afresh():
    """run_scenario on a scenario, with every kept mode forgotten first and then with the modes the first run
    kept: the same part, bit for bit (less the clock)."""
    from pounding.model.building import forget_modes
    from pounding.studies.sweep.scenario import run_scenario
    from pounding.studies.sweep.spec import load_sweep

    sweep = load_sweep(ROOT / "tests" / "data" / "fingerprint_sweep.yaml")
    task = next(iter(sweep.scenarios())).task(sweep_label=sweep.label, name=sweep.model_name)
    forget_modes()
    fresh, kept = run_scenario(task), run_scenario(task)
    assert fresh["status"] == "ok", fresh["error"]
    for part in (fresh, kept):
        for name in ("wall_time", "solver_wall_time"):
            part.pop(name)
    assert repr(fresh) == repr(kept)   # repr: every float to the bit, a NaN equal to a NaN
