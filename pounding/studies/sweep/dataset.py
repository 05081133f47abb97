"""The results dataset of a sweep: one NetCDF layout of peaks over the sweep's dimensions."""

from __future__ import annotations

import json
from datetime import datetime, timezone
from typing import Any, Iterable

from pounding import __version__
from pounding.studies.common import base_model_text, sweep_heading
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
        if part.get("status") != "ok" or name not in part:
            continue
        for i, label in enumerate(part[name]):
            if label not in seen:
                seen.add(label)
                labels.append(label)
                for k in extra:
                    info[k].append(part[k][i])
    return labels, info


class _Layout:
    """Where each scenario's labelled peaks go: the sweep's shape and the union of every scenario's labels."""

    def __init__(self, sweep: Sweep, parts: list[dict[str, Any]]):
        self.dims = tuple(d.name for d in sweep.dimensions)
        self.shape = sweep.shape
        self.index = [s.index for s in sweep.scenarios()]
        self.ok = [p if p.get("status") == "ok" else {} for p in parts]
        self.parts = parts

    def labels(self, name: str, extra: tuple[str, ...]) -> tuple[list, dict[str, list]]:
        """The union over the scenarios of labels *name* (in order of appearance) and their *extra* lists."""
        return _union(self.parts, name, extra)

    def spread(self, name: str, labels: list, key: str, fill: Any = float("nan"), dtype: Any = float):
        """Each scenario's list *key* (along its labels *name*) placed on the union *labels*; *fill* elsewhere."""
        import numpy as np

        tail = next((np.shape(p[key])[1:] for p in self.ok if p.get(key)), ())
        out = np.full(self.shape + (len(labels),) + tuple(tail), fill, dtype=dtype)
        at = {label: i for i, label in enumerate(labels)}
        for where, part in zip(self.index, self.ok):
            for label, value in zip(part.get(name, []), part.get(key, [])):
                out[where + (at[label],)] = value
        return out

    def scalar(self, key: str, fill: Any = float("nan"), dtype: Any = float, *, every: bool = False,
               missing: Any = None):
        """One value per scenario: *fill* where it failed (unless *every*), *missing* (default *fill*) where
        a scenario that ran has no *key* (a part stored before it was recorded)."""
        import numpy as np

        out = np.full(self.shape, fill, dtype=dtype)
        for where, part in zip(self.index, self.parts if every else self.ok):
            if part or every:
                out[where] = part.get(key, fill if missing is None else missing)
        return out

    def var(self, extra: tuple[str, ...], data: Any, units: str | None, long_name: str, **attrs: Any) -> tuple:
        attrs = {"units": units, "long_name": long_name, **attrs} if units is not None else \
            {"long_name": long_name, **attrs}
        return (self.dims + extra, data, attrs)


def _plan_extras(layout: _Layout, floors: list[str]) -> tuple[dict[str, tuple], dict[str, tuple]]:
    """The variables and coordinates of the peaks only floors in plan have, where the scenarios have them:
    rotations, corners, planes, the contact dissipation (module :mod:`~pounding.studies.sweep.scenario`)."""
    import numpy as np

    data: dict[str, tuple] = {}
    coords: dict[str, tuple] = {}
    if any("peak_rotation" in p for p in layout.ok):
        data["peak_rotation"] = layout.var(("floor",), layout.spread("floor", floors, "peak_rotation"), "rad",
                                           "peak |rotation| of the floor (full resolution)")
    corners = next((p["corner"] for p in layout.ok if "corner" in p), None)
    if corners is not None:
        data["peak_corner_displacement_magnitude"] = layout.var(
            ("floor", "corner"), layout.spread("floor", floors, "peak_corner_displacement_magnitude"), "m",
            "peak magnitude of the displacement of the outline's corner (stored samples)")
        coords["corner"] = ("corner", np.array(corners, dtype=str), {"long_name": "corner of the floor's outline"})
    planes, info = layout.labels("plane", ("plane_building", "plane_storey", "plane_direction", "plane_at",
                                           "plane_height"))
    if planes:
        data.update({
            "peak_plane_drift": layout.var(("plane",), layout.spread("plane", planes, "peak_plane_drift"), "m",
                                           "peak |drift| of the plane (full resolution)"),
            "peak_plane_drift_ratio": layout.var(("plane",), layout.spread("plane", planes, "peak_plane_drift_ratio"),
                                                 "1", "peak |drift ratio| of the plane (drift / storey height)"),
            "contact_dissipation": layout.var((), layout.scalar("contact_dissipation"), "J",
                                              "work of all contacts at the end of the run (energy they dissipated)"),
        })
        coords.update({
            "plane": ("plane", np.array(planes, dtype=str), {"long_name": "plane label building:storey:direction@line"}),
            "plane_building": ("plane", np.array(info["plane_building"], dtype=str),
                               {"long_name": "building of the plane"}),
            "plane_storey": ("plane", np.array(info["plane_storey"], dtype=np.int32),
                             {"units": "1", "long_name": "storey of the plane"}),
            "plane_direction": ("plane", np.array(info["plane_direction"], dtype=str),
                                {"long_name": "direction the plane resists"}),
            "plane_at": ("plane", np.array(info["plane_at"], dtype=float),
                         {"units": "m", "long_name": "the plane's line (y along x, x along y)"}),
            "plane_height": ("plane", np.array(info["plane_height"], dtype=float),
                             {"units": "m", "long_name": "height of the plane's storey"}),
        })
    return data, coords


def _contact_places(layout: _Layout, contacts: list[str]) -> dict[str, tuple]:
    """The contact points' places (x, y at rest, the face's normal) when the scenarios have them (in plan)."""
    import numpy as np

    if not any("point_x" in p for p in layout.ok):
        return {}
    _, info = layout.labels("contact", ("point_x", "point_y", "point_normal"))
    return {"point_x": ("contact", np.array(info["point_x"], dtype=float),
                        {"units": "m", "long_name": "x of the contact point at rest"}),
            "point_y": ("contact", np.array(info["point_y"], dtype=float),
                        {"units": "m", "long_name": "y of the contact point at rest"}),
            "point_normal": ("contact", np.array(info["point_normal"], dtype=str),
                             {"long_name": "normal direction of the contact point's face"})}


def _label_coords(layout: _Layout) -> tuple[dict[str, tuple], list[str], list[str], list[str]]:
    """The storey, floor and contact coordinates (unions over the scenarios) and the three label lists."""
    import numpy as np

    storeys, storey_info = layout.labels("storey", ("storey_building", "storey_level", "height"))
    floors, floor_info = layout.labels("floor", ("building", "level", "elevation"))
    contacts, contact_info = layout.labels("contact", ("building_left", "building_right", "level_left",
                                                       "level_right"))
    coords = {
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
    }
    return coords, storeys, floors, contacts


def build_dataset(sweep: Sweep, results: dict[str, dict[str, Any]], *, elapsed: float = float("nan"),
                  ran: int = 0):
    """Assemble the results NetCDF layout from per-scenario results (planar and plan models alike).

    Over the sweep's dimensions: ``peak_drift_ratio`` (storey), ``peak_displacement`` (floor; floors in plan:
    floor × direction), ``peak_contact_force`` and ``impact_count`` (contact), ``scale_factor``, ``intensity``
    and the scenario's status; floors in plan add ``peak_rotation``, ``peak_corner_displacement_magnitude``
    (floor × corner), ``peak_plane_drift(_ratio)`` (plane) and ``contact_dissipation``.
    """
    import numpy as np
    import xarray as xr

    from pounding.results.checks import study_warnings
    from pounding.results.dataset import PGA_LONG_NAME
    from pounding.studies.sweep.scenario import PAIR_PGA_LONG_NAME

    scenarios = sweep.scenarios()
    parts = [results.get(s.key, {"status": "error", "error": "not run"}) for s in scenarios]
    layout = _Layout(sweep, parts)
    coords, storeys, floors, contacts = _label_coords(layout)
    displacement = layout.spread("floor", floors, "peak_displacement")
    in_plan = displacement.ndim > len(layout.shape) + 1
    status = layout.scalar("status", "error", object, every=True)
    var = layout.var
    data_vars = {
        "peak_drift_ratio": var(("storey",), layout.spread("storey", storeys, "peak_drift_ratio"), "1",
                                "peak storey drift ratio (drift / storey height)"
                                + ("; a storey in plan: the largest of its planes'" if in_plan else "")),
        "peak_displacement": var(("floor", "direction") if in_plan else ("floor",), displacement, "m",
                                 "peak |displacement| of the floor's centre of mass relative to the ground"
                                 if in_plan else "peak floor displacement relative to the ground"),
        "peak_contact_force": var(("contact",), layout.spread("contact", contacts, "peak_contact_force"), "N",
                                  "peak contact force of the gap element"),
        "impact_count": var(("contact",), layout.spread("contact", contacts, "impact_count", -1, np.int32), "1",
                            "number of impacts (gap closures)",
                            comment="-1 where the scenario has no result (status != ok)"),
        "energy_closure_error": var((), layout.scalar("energy_closure_error"), "1",
                                    "max |E_in - sum of energies| / max |E_in|"),
        "scale_factor": var((), layout.scalar("scale_factor"), "1",
                            "factor applied to the record as stored (catalogue or file), after processing"
                            + ("; one factor on both components of the pair" if sweep.pairs else "")),
        "intensity": var((), layout.scalar("intensity"), "m s-2", PAIR_PGA_LONG_NAME if sweep.pairs else
                         PGA_LONG_NAME),
        "wall_time": var((), layout.scalar("wall_time", every=True), "s",
                         "wall time of the scenario on its worker (model, record, solver)"),
        "solver_wall_time": var((), layout.scalar("solver_wall_time"), "s", "wall time of the integration alone"),
        "status": var((), status.astype(str), None, "scenario status: ok or error"),
        "run_status": var((), layout.scalar("run_status", "", object, missing="unknown").astype(str), None,
                          "how the run ended: completed, collapsed or unstable (peaks of a collapsed or unstable "
                          "run are those up to end_time); empty where status != ok, unknown for a resumed part "
                          "that predates it"),
        "end_time": var((), layout.scalar("end_time"), "s",
                        "time at which the run ended (the record's end unless it collapsed)"),
        "error": var((), np.array([p.get("error", "") or "" for p in parts], dtype=object).reshape(layout.shape)
                     .astype(str), None, "error message of a failed scenario (empty if ok)"),
        "scenario_id": var((), np.array([s.key[:16] for s in scenarios], dtype=object).reshape(layout.shape)
                           .astype(str), None, "first 16 hex digits of the scenario hash (name of its part file)"),
    }
    extras, extra_coords = _plan_extras(layout, floors)
    data_vars.update(extras)
    for dim in sweep.dimensions:
        if dim.zipped:
            coords[dim.name] = (dim.name, np.arange(dim.size, dtype=np.int32),
                                {"long_name": "zip group of " + ", ".join(a.key for a in dim.axes)})
        for axis in dim.axes:
            coords[axis.name] = (dim.name, _coord_values(axis.labels), _axis_attrs(axis, sweep))
    coords.update(extra_coords)
    coords.update(_contact_places(layout, contacts))
    if in_plan:
        coords["direction"] = ("direction", np.array(["x", "y"], dtype=str), {"long_name": "plan direction"})
    attrs = sweep_attrs(sweep, status, ran=ran, elapsed=elapsed,
                        title=f"pounding sweep '{sweep.name}' ({sweep.size} scenarios) of {sweep_heading(sweep)}")
    warnings = study_warnings(part.get("warnings") for part in parts if part.get("status") == "ok")
    if warnings:   # each kind once for the study (pounding.results.checks)
        attrs["warnings"] = json.dumps(warnings)
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def sweep_attrs(sweep, status, *, ran: int, elapsed: float, title: str) -> dict[str, Any]:
    """The global attributes of a sweep's dataset.

    Parameters
    ----------
    sweep : Sweep
        The sweep (its name, file, text, base model and axes).
    status : ndarray
        Each scenario's status (``n_errors``: those not ``ok``).
    ran : int
        Scenarios run by this call.
    elapsed : float
        Wall time of this call, s.
    title : str
        The dataset's title.
    """
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    attrs: dict[str, Any] = {
        "Conventions": "CF-1.10",
        "title": title,
        "source": f"pounding {__version__}",
        "history": f"{now} swept with pounding {__version__} from {sweep.label}",
    }
    attrs.update({
        "sweep_name": sweep.name,
        "sweep_file": sweep.label,
        "sweep_text": sweep.text,
        "base_model": base_model_text(sweep.base_document),
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


def _axis_attrs(axis: Axis, sweep: Sweep) -> dict[str, str]:
    """``long_name``, ``sweep_axis`` and ``units`` of an axis's coordinate (its records pairs when *sweep*'s are)."""
    if axis.kind == "eccentricity":
        building, direction, _ = axis.target
        name = sweep.base_document["buildings"][building]["name"]
        long_name = f"shift of every floor's centre of mass of building {name} along {'xy'[direction]}"
    else:
        long_name = {"record": "ground-motion record pair (components a and b)" if sweep.pairs else
                     "ground-motion record",
                     "scale": "scale factor on both components of the pair" if sweep.pairs else
                     "scale factor on the record",
                     "xi": "xi formula of every hertz-damp contact",
                     "contacts": "with: the contacts as modelled; without: every contact held open (no pounding)"
                     }.get(axis.kind, f"swept model value {axis.key}")
    attrs = {"long_name": long_name, "sweep_axis": axis.key}
    if axis.units:
        attrs["units"] = axis.units
    return attrs

