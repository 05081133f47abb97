"""One plan scenario on a worker (its peaks as plain data), and the plan sweep's NetCDF layout.

Peaks of a plan run (:func:`pounding.simulation.simulate_plan`), labelled so that
scenarios with different contacts still line up (a union over labels):

* ``floor`` (``A:1``) × ``direction`` (x, y): the centre of mass's peak |u| (full resolution), m;
  ``peak_rotation`` (floor), rad;
* ``corner`` (floor × ``sw, se, ne, nw`` of the outline): the peak magnitude of the corner's
  displacement (the rigid floor's ``u + θ ẑ × (p − c)``) at the stored samples, m;
* ``plane`` (``A:1:x@10``, the plan counterpart of a storey): peak |drift| (full resolution), m, and drift
  ratio (drift / storey height);
* ``point`` (``A:1-B:1@(20,2)``): peak normal force, N, and impact count;
* ``contact_dissipation``: the work of all contacts at the end (the energy they dissipated), J.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from pounding.errors import ModelError
from pounding.studies.common import study_parts
from pounding.studies.engine.keys import PARTS_FORMAT
from pounding.studies.engine.tasks import one_line
from pounding.studies.sweep.spec import strip_location

__all__ = ["run_plan_scenario", "plan_peaks", "corner_peaks", "assemble_plan_sweep", "CORNERS", "PLAN_PART",
           "floor_states"]

#: Version of the plan scenario's part layout.
PLAN_PART = "plan-1"
#: Outline corners, in order.
CORNERS = ("sw", "se", "ne", "nw")


def floor_states(ds) -> tuple[np.ndarray, np.ndarray]:
    """``(q, q̇)`` (time, DOF) of a plan archive in the model's DOF order (u_x, u_y, θ per floor; m, rad)."""
    q = np.concatenate([ds.displacement.values, ds.rotation.values[:, :, None]], axis=2)
    qd = np.concatenate([ds.velocity.values, ds.rotation_rate.values[:, :, None]], axis=2)
    return q.reshape(q.shape[0], -1), qd.reshape(qd.shape[0], -1)


def corner_peaks(model, ds) -> np.ndarray:
    """(floor, 4) peak corner displacement magnitudes (m) at the stored samples, corners :data:`CORNERS`."""
    u, theta = ds.displacement.values, ds.rotation.values
    peaks = []
    floor = 0
    for building in model.buildings:
        (x0, y0), (x1, y1) = building.outline
        for centre in building.centres:
            row = []
            for px, py in ((x0, y0), (x1, y0), (x1, y1), (x0, y1)):
                dx = u[:, floor, 0] - theta[:, floor] * (py - centre[1])
                dy = u[:, floor, 1] + theta[:, floor] * (px - centre[0])
                row.append(float(np.max(np.hypot(dx, dy))) if dx.size else 0.0)
            peaks.append(row)
            floor += 1
    return np.array(peaks).reshape(-1, len(CORNERS))


def _plane_labels(ds) -> list[str]:
    return [f"{b}:{int(s)}:{d}@{float(a):g}" for b, s, d, a in
            zip(ds.plane_building.values, ds.plane_storey.values, ds.plane_direction.values, ds.plane_at.values)]


def plan_peaks(model, ds) -> dict[str, Any]:
    """The peaks of a plan run *ds* of *model* as plain data (module docstring)."""
    floors = [f"{b}:{int(lv)}" for b, lv in zip(ds.building.values, ds.level.values)]
    heights = {b.name: [s.height for s in b.storeys] for b in model.buildings}
    plane_height = [heights[str(b)][int(s) - 1] for b, s in zip(ds.plane_building.values, ds.plane_storey.values)]
    points = [f"{between}@({float(x):g},{float(y):g})" for between, x, y in
              zip(ds.point_between.values, ds.point_x.values, ds.point_y.values)]
    energy = ds.energy_contact.values
    return {
        "floor": floors,
        "floor_building": [str(b) for b in ds.building.values],
        "floor_level": [int(x) for x in ds.level.values],
        "peak_displacement": ds.peak_displacement.values.tolist(),
        "peak_rotation": ds.peak_rotation.values.tolist(),
        "peak_corner_displacement": corner_peaks(model, ds).tolist(),
        "plane": _plane_labels(ds),
        "plane_building": [str(b) for b in ds.plane_building.values],
        "plane_storey": [int(x) for x in ds.plane_storey.values],
        "plane_direction": [str(x) for x in ds.plane_direction.values],
        "plane_at": [float(x) for x in ds.plane_at.values],
        "plane_height": plane_height,
        "peak_plane_drift": ds.peak_plane_drift.values.tolist(),
        "point": points,
        "point_x": [float(x) for x in ds.point_x.values],
        "point_y": [float(x) for x in ds.point_y.values],
        "point_normal": [str(x) for x in ds.point_normal.values],
        "peak_contact_force": ds.peak_contact_force.values.tolist(),
        "impact_count": [int(x) for x in ds.impact_count.values],
        "contact_dissipation": float(energy[-1]) if energy.size else 0.0,
        "energy_closure_error": float(ds.attrs["energy_closure"]),
        "end_time": float(ds.time.values[-1]),
        "solver_wall_time": float(ds.attrs.get("wall_time", np.nan)),
    }


def run_plan_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """Simulate one plan scenario and return its peaks (never raises for a problem of the scenario)."""
    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "format": PARTS_FORMAT,
                              "study": PLAN_PART}
    try:
        from pounding.model.model import model_from_text as plan_model_from_text
        from pounding.simulation import simulate as simulate_plan

        try:
            model = plan_model_from_text(task["document"], name=task.get("name", "model"),
                                         base_dir=task.get("base_dir"))
        except ModelError as exc:
            raise ModelError(f"invalid model: {strip_location(str(exc))}") from None
        ds = simulate_plan(model)
        result.update(plan_peaks(model, ds), status="ok", run_status="completed", warnings=list(model.warnings))
    except Exception as exc:  # noqa: BLE001 - a failing scenario is a result, not a crash
        result["error"] = f"{task.get('where', 'scenario')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


def _union(parts: list[dict], name: str, extra: tuple[str, ...]) -> tuple[list[str], dict[str, list]]:
    labels: list[str] = []
    info: dict[str, list] = {k: [] for k in extra}
    for part in parts:
        for i, label in enumerate(part.get(name, [])):
            if label not in labels:
                labels.append(label)
                for k in extra:
                    info[k].append(part[k][i])
    return labels, info


def _spread(shape: tuple, parts: list[dict], index: list[tuple], name: str, labels: list[str], key: str,
            tail: tuple = (), fill: Any = np.nan, dtype=float) -> np.ndarray:
    """Per-scenario lists *key* (labelled by *name*) placed on the union *labels*."""
    out = np.full(shape + (len(labels),) + tail, fill, dtype=dtype)
    at = {label: i for i, label in enumerate(labels)}
    for where, part in zip(index, parts):
        for label, value in zip(part.get(name, []), part.get(key, [])):
            out[where + (at[label],)] = value
    return out


def assemble_plan_sweep(sweep, results: dict[str, dict[str, Any]], *, elapsed: float = float("nan"),
                        ran: int = 0, title: str | None = None):
    """The plan sweep's NetCDF layout: peaks over the sweep's dimensions × floor/direction, corner, plane, point."""
    import xarray as xr

    from pounding.studies.common import sweep_heading
    from pounding.studies.sweep.dataset import sweep_attrs

    scenarios = sweep.scenarios()
    parts = study_parts(scenarios, results, PLAN_PART)
    ok_parts = [p if p.get("status") == "ok" else {} for p in parts]
    index = [s.index for s in scenarios]
    shape = sweep.shape
    dims = tuple(d.name for d in sweep.dimensions)
    floors, floor_info = _union(ok_parts, "floor", ("floor_building", "floor_level"))
    planes, plane_info = _union(ok_parts, "plane", ("plane_building", "plane_storey", "plane_direction", "plane_at",
                                                    "plane_height"))
    points, point_info = _union(ok_parts, "point", ("point_x", "point_y", "point_normal"))
    drift = _spread(shape, ok_parts, index, "plane", planes, "peak_plane_drift")
    height = np.array(plane_info["plane_height"], dtype=float)

    def scalar(key: str, fill: Any = np.nan, dtype=float) -> np.ndarray:
        out = np.full(shape, fill, dtype=dtype)
        for where, part in zip(index, parts):
            out[where] = part.get(key, fill) if part.get("status") == "ok" or key in ("status", "error",
                                                                                      "wall_time") else fill
        return out

    def var(extra: tuple, data, units: str | None, long_name: str, **attrs) -> tuple:
        attrs = {"long_name": long_name, **({"units": units} if units else {}), **attrs}
        return (dims + extra, data, attrs)

    status = scalar("status", "error", object)
    data = {
        "peak_displacement": var(("floor", "direction"),
                                 _spread(shape, ok_parts, index, "floor", floors, "peak_displacement", (2,)), "m",
                                 "peak |displacement| of the floor's centre of mass relative to the ground"),
        "peak_rotation": var(("floor",), _spread(shape, ok_parts, index, "floor", floors, "peak_rotation"), "rad",
                             "peak |rotation| of the floor"),
        "peak_corner_displacement": var(("floor", "corner"), _spread(shape, ok_parts, index, "floor", floors,
                                                                     "peak_corner_displacement", (len(CORNERS),)),
                                        "m", "peak magnitude of the displacement of the outline's corner "
                                             "(at the stored samples)"),
        "peak_plane_drift": var(("plane",), drift, "m", "peak |drift| of the plane (full resolution)"),
        "peak_plane_drift_ratio": var(("plane",), drift / height if height.size else drift, "1",
                                      "peak plane drift ratio (drift / storey height)"),
        "peak_contact_force": var(("point",), _spread(shape, ok_parts, index, "point", points,
                                                      "peak_contact_force"), "N",
                                  "peak normal contact force at the point"),
        "impact_count": var(("point",), _spread(shape, ok_parts, index, "point", points, "impact_count",
                                                fill=-1, dtype=np.int32), "1", "number of impacts at the point",
                            comment="-1 where the scenario has no result or not this point"),
        "contact_dissipation": var((), scalar("contact_dissipation"), "J",
                                   "work of all contacts at the end of the run (energy they dissipated)"),
        "energy_closure_error": var((), scalar("energy_closure_error"), "1", "energy closure of the run"),
        "end_time": var((), scalar("end_time"), "s", "time at which the run ended"),
        "wall_time": var((), scalar("wall_time"), "s", "wall time of the scenario on its worker"),
        "solver_wall_time": var((), scalar("solver_wall_time"), "s", "wall time of the integration alone"),
        "status": var((), status.astype(str), None, "scenario status: ok or error"),
        "run_status": var((), scalar("run_status", "", object).astype(str), None,
                          "how the run ended (completed); empty where status != ok"),
        "error": var((), scalar("error", "", object).astype(str),
                     None, "error message of a failed scenario (empty if ok)"),
        "scenario_id": var((), np.array([s.key[:16] for s in scenarios], dtype=object).reshape(shape).astype(str),
                           None, "first 16 hex digits of the scenario hash (name of its part file)"),
    }
    coords: dict[str, Any] = {}
    for dim in sweep.dimensions:
        for axis in dim.axes:
            labels = axis.labels
            numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in labels)
            values = np.array(labels, dtype=float) if numeric else np.array([str(v) for v in labels], dtype=str)
            attrs = {"long_name": axis.long_name, "sweep_axis": axis.key}
            if axis.units:
                attrs["units"] = axis.units
            coords[axis.name] = (dim.name, values, attrs)
    coords.update({
        "floor": ("floor", np.array(floors, dtype=str), {"long_name": "floor label building:level"}),
        "floor_building": ("floor", np.array(floor_info["floor_building"], dtype=str),
                           {"long_name": "building of the floor"}),
        "floor_level": ("floor", np.array(floor_info["floor_level"], dtype=np.int32),
                        {"units": "1", "long_name": "floor number from the ground up"}),
        "direction": ("direction", np.array(["x", "y"], dtype=str), {"long_name": "plan direction"}),
        "corner": ("corner", np.array(CORNERS, dtype=str),
                   {"long_name": "corner of the outline: south-west, south-east, north-east, north-west"}),
        "plane": ("plane", np.array(planes, dtype=str), {"long_name": "plane label building:storey:direction@at"}),
        "plane_building": ("plane", np.array(plane_info["plane_building"], dtype=str),
                           {"long_name": "building of the plane"}),
        "plane_storey": ("plane", np.array(plane_info["plane_storey"], dtype=np.int32),
                         {"units": "1", "long_name": "storey of the plane"}),
        "plane_direction": ("plane", np.array(plane_info["plane_direction"], dtype=str),
                            {"long_name": "direction the plane resists"}),
        "plane_at": ("plane", np.array(plane_info["plane_at"], dtype=float),
                     {"units": "m", "long_name": "the plane's line (y along x, x along y)"}),
        "point": ("point", np.array(points, dtype=str),
                  {"long_name": "contact point label first:floor-second:floor@(x,y)"}),
        "point_x": ("point", np.array(point_info["point_x"], dtype=float),
                    {"units": "m", "long_name": "x of the point at rest"}),
        "point_y": ("point", np.array(point_info["point_y"], dtype=float),
                    {"units": "m", "long_name": "y of the point at rest"}),
        "point_normal": ("point", np.array(point_info["point_normal"], dtype=str),
                         {"long_name": "normal direction of the point's face"}),
    })
    attrs = sweep_attrs(sweep, status, ran=ran, elapsed=elapsed, kind="plan_sweep",
                        title=title or f"pounding plan sweep '{sweep.name}' ({sweep.size} scenarios) of "
                                       f"{sweep_heading(sweep)}")
    return xr.Dataset(data, coords=coords, attrs=attrs)
