"""The results dataset of a sweep: one NetCDF layout of peaks over the sweep's dimensions."""

from __future__ import annotations

import json
from datetime import datetime, timezone
from typing import Any, Iterable

from pounding import __version__
from pounding.model.document import dump_document
from pounding.studies.common import sweep_heading
from pounding.studies.sweep.spec import Axis, Sweep

__all__ = ["build_dataset", "sweep_attrs"]

# --------------------------------------------------------------------------- #
# The results dataset
# --------------------------------------------------------------------------- #


def _union(results: Iterable[dict[str, Any]], name: str, extra: tuple[str, ...]) -> tuple[list, dict[str, list]]:
    labels: list[str] = []
    info: dict[str, list] = {k: [] for k in extra}
    seen: set[str] = set()
    for part in results:
        if part.get("status") != "ok":
            continue
        for i, label in enumerate(part[name]):
            if label not in seen:
                seen.add(label)
                labels.append(label)
                for k in extra:
                    info[k].append(part[k][i])
    return labels, info


def build_dataset(sweep: Sweep, results: dict[str, dict[str, Any]], *, elapsed: float = float("nan"),
                  ran: int = 0):
    """Assemble the results NetCDF layout from per-scenario results."""
    import numpy as np
    import xarray as xr

    from pounding.results.checks import study_warnings
    from pounding.results.dataset import PGA_LONG_NAME

    scenarios = sweep.scenarios()
    parts = [results.get(s.key, {"status": "error", "error": "not run"}) for s in scenarios]
    storeys, storey_info = _union(parts, "storey", ("storey_building", "storey_level", "height"))
    floors, floor_info = _union(parts, "floor", ("building", "level", "elevation"))
    contacts, contact_info = _union(parts, "contact", ("building_left", "building_right", "level_left",
                                                       "level_right"))
    shape = sweep.shape
    dims = tuple(d.name for d in sweep.dimensions)

    def full(extra: int | None, value, dtype):
        return np.full(shape + ((extra,) if extra is not None else ()), value, dtype=dtype)

    drift = full(len(storeys), np.nan, float)
    displacement = full(len(floors), np.nan, float)
    force = full(len(contacts), np.nan, float)
    impacts = full(len(contacts), -1, np.int32)
    closure = full(None, np.nan, float)
    wall = full(None, np.nan, float)
    solver_wall = full(None, np.nan, float)
    scale_factor = full(None, np.nan, float)
    intensity = full(None, np.nan, float)
    status = np.empty(shape, dtype=object)
    run_status = np.full(shape, "", dtype=object)
    end_time = full(None, np.nan, float)
    error = np.empty(shape, dtype=object)
    scenario_id = np.empty(shape, dtype=object)
    storey_at = {s: i for i, s in enumerate(storeys)}
    floor_at = {s: i for i, s in enumerate(floors)}
    contact_at = {s: i for i, s in enumerate(contacts)}
    for scenario, part in zip(scenarios, parts):
        at = scenario.index
        status[at] = part.get("status", "error")
        error[at] = part.get("error", "") or ""
        scenario_id[at] = scenario.key[:16]
        wall[at] = part.get("wall_time", np.nan)
        if part.get("status") != "ok":
            continue
        for label, value in zip(part["storey"], part["peak_drift_ratio"]):
            drift[at + (storey_at[label],)] = value
        for label, value in zip(part["floor"], part["peak_displacement"]):
            displacement[at + (floor_at[label],)] = value
        for label, f, n in zip(part["contact"], part["peak_contact_force"], part["impact_count"]):
            force[at + (contact_at[label],)] = f
            impacts[at + (contact_at[label],)] = n
        closure[at] = part["energy_closure_error"]
        run_status[at] = part.get("run_status", "unknown")   # parts written before it was recorded
        end_time[at] = part.get("end_time", np.nan)
        scale_factor[at] = part.get("scale_factor", np.nan)
        intensity[at] = part.get("intensity", np.nan)
        solver_wall[at] = part["solver_wall_time"]

    def var(extra_dim, data, units, long_name, **attrs):
        attrs = {"units": units, "long_name": long_name, **attrs} if units is not None else \
            {"long_name": long_name, **attrs}
        return (dims + ((extra_dim,) if extra_dim else ()), data, attrs)

    data_vars = {
        "peak_drift_ratio": var("storey", drift, "1", "peak storey drift ratio (drift / storey height)"),
        "peak_displacement": var("floor", displacement, "m", "peak floor displacement relative to the ground"),
        "peak_contact_force": var("contact", force, "N", "peak contact force of the gap element"),
        "impact_count": var("contact", impacts, "1", "number of impacts (gap closures)",
                            comment="-1 where the scenario has no result (status != ok)"),
        "energy_closure_error": var(None, closure, "1", "max |E_in - sum of energies| / max |E_in|"),
        "scale_factor": var(None, scale_factor, "1",
                            "factor applied to the record as stored (catalogue or file), after processing"),
        "intensity": var(None, intensity, "m s-2", PGA_LONG_NAME),
        "wall_time": var(None, wall, "s", "wall time of the scenario on its worker (model, record, solver)"),
        "solver_wall_time": var(None, solver_wall, "s", "wall time of the integration alone"),
        "status": var(None, status.astype(str), None, "scenario status: ok or error"),
        "run_status": var(None, run_status.astype(str), None,
                          "how the run ended: completed, collapsed or unstable (peaks of a collapsed or unstable "
                          "run are those up to end_time); empty where status != ok, unknown for a resumed part "
                          "that predates it"),
        "end_time": var(None, end_time, "s", "time at which the run ended (the record's end unless it collapsed)"),
        "error": var(None, error.astype(str), None, "error message of a failed scenario (empty if ok)"),
        "scenario_id": var(None, scenario_id.astype(str), None,
                           "first 16 hex digits of the scenario hash (name of its part file)"),
    }
    coords: dict[str, Any] = {}
    for dim in sweep.dimensions:
        if dim.zipped:
            coords[dim.name] = (dim.name, np.arange(dim.size, dtype=np.int32),
                                {"long_name": "zip group of " + ", ".join(a.key for a in dim.axes)})
        for axis in dim.axes:
            coords[axis.name] = (dim.name, _coord_values(axis.labels), _axis_attrs(axis))
    coords.update({
        "storey": ("storey", np.array(storeys, dtype=str),
                   {"long_name": "storey label building:level (storey i between floors i-1 and i)"}),
        "storey_building": ("storey", np.array(storey_info["storey_building"], dtype=str),
                            {"long_name": "building of the storey"}),
        "storey_level": ("storey", np.array(storey_info["storey_level"], dtype=np.int32),
                         {"units": "1", "long_name": "storey number above ground"}),
        "height": ("storey", np.array(storey_info["height"], dtype=float),
                   {"units": "m", "long_name": "storey height"}),
        "floor": ("floor", np.array(floors, dtype=str), {"long_name": "floor label building:level"}),
        "building": ("floor", np.array(floor_info["building"], dtype=str), {"long_name": "building of the floor"}),
        "level": ("floor", np.array(floor_info["level"], dtype=np.int32),
                  {"units": "1", "long_name": "floor number above ground"}),
        "elevation": ("floor", np.array(floor_info["elevation"], dtype=float),
                      {"units": "m", "long_name": "floor elevation above ground"}),
        "contact": ("contact", np.array(contacts, dtype=str), {"long_name": "gap element label"}),
        "building_left": ("contact", np.array(contact_info["building_left"], dtype=str),
                          {"long_name": "left building of the gap element"}),
        "building_right": ("contact", np.array(contact_info["building_right"], dtype=str),
                           {"long_name": "right building of the gap element"}),
        "level_left": ("contact", np.array(contact_info["level_left"], dtype=np.int32),
                       {"units": "1", "long_name": "floor number in the left building"}),
        "level_right": ("contact", np.array(contact_info["level_right"], dtype=np.int32),
                        {"units": "1", "long_name": "floor number in the right building"}),
    })
    attrs = sweep_attrs(sweep, status, ran=ran, elapsed=elapsed,
                        title=f"pounding sweep '{sweep.name}' ({sweep.size} scenarios) of {sweep_heading(sweep)}")
    warnings = study_warnings(part.get("warnings") for part in parts if part.get("status") == "ok")
    if warnings:   # each kind once for the study (pounding.results.checks)
        attrs["warnings"] = json.dumps(warnings)
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def sweep_attrs(sweep, status, *, ran: int, elapsed: float, title: str, kind: str | None = None) -> dict[str, Any]:
    """The global attributes of a sweep's dataset, planar and plan.

    Parameters
    ----------
    sweep : Sweep or PlanSweep
        The sweep (its name, file, text, base model and axes).
    status : ndarray
        Each scenario's status (``n_errors``: those not ``ok``).
    ran : int
        Scenarios run by this call.
    elapsed : float
        Wall time of this call, s.
    title : str
        The dataset's title.
    kind : str, optional
        The dataset's ``kind`` attribute (a plan sweep's ``plan_sweep``), after ``history``.
    """
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    attrs: dict[str, Any] = {
        "Conventions": "CF-1.10",
        "title": title,
        "source": f"pounding {__version__}",
        "history": f"{now} swept with pounding {__version__} from {sweep.label}",
    }
    if kind is not None:
        attrs["kind"] = kind
    attrs.update({
        "sweep_name": sweep.name,
        "sweep_file": sweep.label,
        "sweep_text": sweep.text,
        "base_model": dump_document(sweep.base_document),
        "base_model_file": sweep.model_path or "",
        "axes": json.dumps({a.name: a.key for a in sweep.axes}),
        "n_scenarios": int(sweep.size),
        "n_errors": int((status != "ok").sum()),
        "n_run": int(ran),
        "elapsed_time": float(elapsed),
    })
    return attrs


def _coord_values(labels: tuple[Any, ...]):
    import numpy as np

    if all(isinstance(v, int) and not isinstance(v, bool) for v in labels):
        return np.array(labels, dtype=np.int64)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in labels):
        return np.array(labels, dtype=float)
    return np.array([str(v) for v in labels], dtype=str)


def _axis_attrs(axis: Axis) -> dict[str, str]:
    long_name = {"record": "ground-motion record", "scale": "scale factor on the record",
                 "xi": "xi formula of every hertz-damp contact",
                 "contacts": "with: the contacts as modelled; without: every contact held open (no pounding)"}.get(axis.kind, f"swept model value {axis.key}")
    attrs = {"long_name": long_name, "sweep_axis": axis.key}
    if axis.units:
        attrs["units"] = axis.units
    return attrs

