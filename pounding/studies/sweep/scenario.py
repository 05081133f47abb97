"""One scenario of a sweep, run on a worker: a model document in, a small dict of peaks out.

The peaks are read from the run's archive by what it holds (:func:`scenario_peaks`), for
every model: the storeys (peak drift ratio; a storey of a building in plan: the largest of its
planes'), the floors (peak displacement; in plan per direction x, y), the contacts (impacts and
peak force; in plan each contact point, with its place and normal), the scale factor, the
intensity reached and how the run ended.  A run whose floors move in plan also has rotations,
corners and planes: their peaks are kept when the archive has their dimensions.  The intensity of a record
pair is the geometric mean of its two components' PGAs (:func:`run_intensity`).
"""

from __future__ import annotations

import time
from typing import Any

from pounding.errors import ModelError
from pounding.studies.engine.keys import PARTS_FORMAT
from pounding.studies.engine.tasks import one_line
from pounding.studies.sweep.spec import strip_location

__all__ = ["run_scenario", "scenario_model", "scenario_peaks", "run_intensity", "PAIR_PGA_LONG_NAME"]

#: long_name of a study's ``intensity`` when its records are pairs (:func:`run_intensity`).
PAIR_PGA_LONG_NAME = ("peak ground acceleration (PGA) of the scaled record pair: the geometric mean of its two "
                      "components' own PGAs, each times the factors on it")

# --------------------------------------------------------------------------- #
# One scenario (runs on a worker)
# --------------------------------------------------------------------------- #


def _texts(values) -> list[str]:
    return [str(x) for x in values]


def _floats(values) -> list[float]:
    return [float(x) for x in values]


def _ints(values) -> list[int]:
    return [int(x) for x in values]


def _values(ds, name: str):
    """The array of variable or coordinate *name* of *ds*, read from its Variable (building a DataArray for
    each of a run's ~25 values took ~10 ms of every sweep run)."""
    return ds.variables[name].values


def _plan_peaks(ds) -> dict[str, Any]:
    """The peaks of a run's floors in plan, where the archive has them (module docstring): rotations,
    corners, planes, the contact points' places and the contacts' dissipated energy."""
    out: dict[str, Any] = {}
    if "peak_rotation" in ds:
        out["peak_rotation"] = _floats(_values(ds, "peak_rotation"))
    if "corner" in ds.dims and "peak_corner_displacement_magnitude" in ds:
        out["corner"] = _texts(_values(ds, "corner"))
        out["peak_corner_displacement_magnitude"] = _values(ds, "peak_corner_displacement_magnitude").tolist()
    if "plane" in ds.dims:
        out.update(plane=_texts(_values(ds, "plane")), plane_building=_texts(_values(ds, "plane_building")),
                   plane_storey=_ints(_values(ds, "plane_storey")),
                   plane_direction=_texts(_values(ds, "plane_direction")),
                   plane_at=_floats(_values(ds, "plane_at")), plane_height=_floats(_values(ds, "plane_height")),
                   peak_plane_drift=_floats(_values(ds, "peak_plane_drift")),
                   peak_plane_drift_ratio=_floats(_values(ds, "peak_plane_drift_ratio")))
        energy = _values(ds, "energy_contact")
        out["contact_dissipation"] = float(energy[-1]) if energy.size else 0.0
    if "point_x" in ds.coords:
        out.update(point_x=_floats(_values(ds, "point_x")), point_y=_floats(_values(ds, "point_y")),
                   point_normal=_texts(_values(ds, "point_normal")))
    return out


def scenario_peaks(ds) -> dict[str, Any]:
    """What a study keeps of a run archive *ds* as plain data (module docstring): labels and peaks."""
    return {
        "run_status": str(ds.attrs["status"]),   # completed, collapsed or unstable
        "end_time": float(_values(ds, "time")[-1]),
        "storey": _texts(_values(ds, "storey")),
        "storey_building": _texts(_values(ds, "storey_building")),
        "storey_level": _ints(_values(ds, "storey_level")),
        "height": _floats(_values(ds, "height")),
        "floor": _texts(_values(ds, "floor")),
        "building": _texts(_values(ds, "building")),
        "level": _ints(_values(ds, "level")),
        "elevation": _floats(_values(ds, "elevation")),
        "contact": _texts(_values(ds, "contact")),
        "building_left": _texts(_values(ds, "building_left")),
        "building_right": _texts(_values(ds, "building_right")),
        "level_left": _ints(_values(ds, "level_left")),
        "level_right": _ints(_values(ds, "level_right")),
        "peak_drift_ratio": _floats(_values(ds, "peak_drift_ratio")),
        "peak_displacement": _values(ds, "peak_displacement").tolist(),   # (floor,) or in plan (floor, direction)
        "peak_contact_force": _floats(_values(ds, "peak_contact_force")),
        "impact_count": _ints(_values(ds, "impact_count")),
        "energy_closure_error": float(ds.attrs["energy_closure_error"]),
        "solver_wall_time": float(ds.attrs["wall_time"]),
        **_plan_peaks(ds),
    }


def run_intensity(model, ds) -> float:
    """The PGA a run of *model* (its archive *ds*) reached, m/s²: its record's own PGA times the factor on it
    (:func:`pounding.results.dataset.record_pga`); with two components the geometric mean of theirs
    (:func:`pounding.studies.common.ground_pga`), as a target on a pair applies to the pair's geometric mean."""
    from pounding.results.dataset import record_pga
    from pounding.simulation import component_records
    from pounding.studies.common import ground_pga

    if not model.ground_motion.two_components:
        return record_pga(ds)[1]
    return ground_pga([r for r in component_records(model, factor=float(ds.attrs["record_scale"])) if r is not None])


def scenario_model(task: dict[str, Any]):
    """The model a worker's *task* runs: validated from its plain data when the task carries it (no YAML
    parse, ~20 ms of a run), else from its document.

    Raises
    ------
    ModelError
        ``invalid model: <location> <problem>``.
    """
    from pounding.model.model import model_from_data, model_from_text

    try:
        if task.get("data") is not None:
            return model_from_data(task["data"], name=task.get("name", "model"), source=task["document"],
                                   base_dir=task.get("base_dir"))
        return model_from_text(task["document"], name=task.get("name", "model"), base_dir=task.get("base_dir"))
    except ModelError as exc:
        raise ModelError(f"invalid model: {strip_location(str(exc))}") from None


def run_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """Simulate one scenario and return its peaks (a small dict of plain data).

    Never raises for a problem of the scenario itself: the result then has
    ``status = "error"`` and the message.  With ``task["keep_history"]`` the
    full results dataset is returned under ``"dataset"``.
    """
    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "format": PARTS_FORMAT}
    try:
        from pounding.results.checks import run_warnings
        from pounding.simulation import refuse_failed_run, simulate, simulate_arrays

        model = scenario_model(task)
        # Its archive written (--keep-histories): the dataset; else its values as plain arrays, the same values.
        ds = simulate(model) if task.get("keep_history") else simulate_arrays(model)
        refuse_failed_run(ds.attrs["status"], ds.attrs.get("status_message", ""))   # energy_inconsistent: an error
        result.update({"warnings": run_warnings(ds), "scale_factor": float(ds.attrs["record_scale"]),
                       "intensity": run_intensity(model, ds), "status": "ok", **scenario_peaks(ds)})
        if task.get("keep_history"):
            result["dataset"] = ds
    except Exception as exc:  # noqa: BLE001 - a failing scenario is a result, not a crash
        result["error"] = f"{task.get('where', 'scenario')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result
