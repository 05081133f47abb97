"""One scenario of a sweep, run on a worker: a model document in, a small dict of peaks out."""

from __future__ import annotations

import time
from typing import Any

from pounding.errors import ModelError
from pounding.studies.engine.keys import PARTS_FORMAT
from pounding.studies.engine.tasks import one_line
from pounding.studies.sweep.spec import strip_location

__all__ = ["run_scenario"]

# --------------------------------------------------------------------------- #
# One scenario (runs on a worker)
# --------------------------------------------------------------------------- #


def run_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """Simulate one scenario and return its peaks (a small dict of plain data).

    Never raises for a problem of the scenario itself: the result then has
    ``status = "error"`` and the message.  With ``task["keep_history"]`` the
    full results dataset is returned under ``"dataset"``.
    """
    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "format": PARTS_FORMAT}
    try:
        from pounding.model.model import model_from_data, model_from_text
        from pounding.results.checks import run_warnings
        from pounding.results.dataset import record_pga
        from pounding.simulation import refuse_failed_run, simulate

        try:
            if task.get("data") is not None:
                model = model_from_data(task["data"], name=task.get("name", "model"), source=task["document"],
                                        base_dir=task.get("base_dir"))
            else:
                model = model_from_text(task["document"], name=task.get("name", "model"), base_dir=task.get("base_dir"))
        except ModelError as exc:
            raise ModelError(f"invalid model: {strip_location(str(exc))}") from None
        ds = simulate(model)
        refuse_failed_run(ds.attrs["status"], ds.attrs.get("status_message", ""))   # energy_inconsistent: an error
        result.update({
            "warnings": run_warnings(ds),
            "scale_factor": float(ds.attrs["record_scale"]),
            "intensity": record_pga(ds)[1],
            "status": "ok",
            "run_status": str(ds.attrs["status"]),   # completed, collapsed or unstable
            "end_time": float(ds.time.values[-1]),
            "storey": [str(x) for x in ds.storey.values],
            "storey_building": [str(x) for x in ds.storey_building.values],
            "storey_level": [int(x) for x in ds.storey_level.values],
            "height": [float(x) for x in ds.height.values],
            "floor": [str(x) for x in ds.floor.values],
            "building": [str(x) for x in ds.building.values],
            "level": [int(x) for x in ds.level.values],
            "elevation": [float(x) for x in ds.elevation.values],
            "contact": [str(x) for x in ds.contact.values],
            "building_left": [str(x) for x in ds.building_left.values],
            "building_right": [str(x) for x in ds.building_right.values],
            "level_left": [int(x) for x in ds.level_left.values],
            "level_right": [int(x) for x in ds.level_right.values],
            "peak_drift_ratio": [float(x) for x in ds.peak_drift_ratio.values],
            "peak_displacement": [float(x) for x in ds.peak_displacement.values],
            "peak_contact_force": [float(x) for x in ds.peak_contact_force.values],
            "impact_count": [int(x) for x in ds.impact_count.values],
            "energy_closure_error": float(ds.attrs["energy_closure_error"]),
            "solver_wall_time": float(ds.attrs["wall_time"]),
        })
        if task.get("keep_history"):
            result["dataset"] = ds
    except Exception as exc:  # noqa: BLE001 - a failing scenario is a result, not a crash
        result["error"] = f"{task.get('where', 'scenario')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result

