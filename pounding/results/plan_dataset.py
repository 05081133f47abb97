"""The archive of a plan-model run: floors per DOF with a ``direction`` dimension, planes, contact points, energy.

A plan run is lowered by :mod:`pounding.solver.plan_assembly` (every DOF a
solver floor, planes and P-Delta terms in each building's stiffness block, contact
points as gap elements); this module labels what the solver returns:

* ``displacement`` / ``velocity`` (time, floor, direction) m, m/s and ``rotation`` /
  ``rotation_rate`` (time, floor) rad, rad/s: each floor's centre of mass relative to the
  ground; their full-resolution peaks ``peak_displacement`` (floor, direction) and
  ``peak_rotation`` (floor);
* ``plane_drift`` (time, plane) m and ``peak_plane_drift`` (plane, full resolution); ``plane_shear``
  (time, plane) N, a yielding plane's by its hysteresis (its state from the solver's storey rows);
* ``corner_displacement`` (time, floor, corner, direction) m of the outline's four corners
  (small rotations: ``u_x − θ (p_y − y_c)``, ``u_y + θ (p_x − x_c)``),
  ``corner_displacement_magnitude`` (time, floor, corner) their hypot, and their peaks over the
  stored samples ``peak_corner_displacement`` (floor, corner, direction) and
  ``peak_corner_displacement_magnitude`` (floor, corner);
* ``contact_force`` (time, point) N, ``peak_contact_force`` and ``impact_count`` (point),
  and the impact table (``impact`` dimension) with the point's location (``impact_x``,
  ``impact_y``) and the face's tangential slip at the onset (``impact_slip``);
* with Coulomb friction on a face (``friction:``), per friction face (``face`` dimension):
  ``friction_normal`` and ``friction_force`` (time, face) N — the face's normal force and the
  friction on its low side along +tangent (the high side takes the opposite) —, ``friction_state``
  (0 open, ±1 slipping along ±tangent, 2 sticking), ``face_slip`` (time, face) m, the tangential slip
  of the low side's face relative to the high side's, and ``energy_friction`` (time) J, the energy
  the friction dissipated;
* the energy audit ``energy_*`` (time) J and its closure (attribute ``energy_closure``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from pounding.model.model import WALL
from pounding.model.plan import DOF_PER_FLOOR, point_weights
from pounding.model.plan_model import PlanModel
from pounding.solver.integrator import RawSolution
from pounding.solver.kinematics import penetration
from pounding.solver.plan_assembly import PlanSystem
from pounding.solver.storeys import restoring_force

__all__ = ["CORNERS", "plan_dataset", "plan_energy_closure", "plan_summary", "corner_weights", "floor_corners",
           "hermite_at", "peak_corner", "compare_plan_runs"]

#: The outline's corners, counter-clockwise from the south-west one (the ``corner`` coordinate).
CORNERS = ("south-west", "south-east", "north-east", "north-west")


def _var(dims, data, units: str, long_name: str) -> tuple:
    return dims, np.asarray(data), {"units": units, "long_name": long_name}


def floor_corners(model: PlanModel) -> np.ndarray:
    """(floors, 4, 2) the outline's corners of every floor at rest (:data:`CORNERS` order), m."""
    rows = []
    for b in model.buildings:
        (x0, y0), (x1, y1) = b.outline
        rows += [[(x0, y0), (x1, y0), (x1, y1), (x0, y1)]] * b.n_floors
    return np.asarray(rows, dtype=float).reshape(-1, 4, 2)


def corner_weights(centres: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(floors, 4, 2, 3) weights over each floor's own (u_x, u_y, θ) giving its corners' displacements (x, y), m.

    *centres* (floors, 2) and *corners* (floors, 4, 2) in m; small rotations
    (:func:`pounding.model.plan.point_weights`).
    """
    return np.array([[[point_weights(tuple(c), tuple(p), d) for d in ("x", "y")] for p in floor]
                     for c, floor in zip(centres, corners)]).reshape(len(centres), 4, 2, DOF_PER_FLOOR)


def hermite_at(time: np.ndarray, y: np.ndarray, rate: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Samples *y* (nt, k) with their rates *rate* at times *time* (nt,), s, interpolated at *at* (m,) s.

    Cubic Hermite between the two samples around each time (exact for cubics); times
    outside the samples take the end values.  Returns (m, k).
    """
    at = np.clip(np.asarray(at, dtype=float), time[0], time[-1])
    if time.size < 2:
        return np.repeat(y[:1], at.size, axis=0)
    k = np.clip(np.searchsorted(time, at, side="right") - 1, 0, time.size - 2)
    h = (time[k + 1] - time[k])[:, None]
    s = ((at - time[k]) / h[:, 0])[:, None]
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * y[k] + (s3 - 2 * s2 + s) * h * rate[k]
            + (3 * s2 - 2 * s3) * y[k + 1] + (s3 - s2) * h * rate[k + 1])


def _floor_labels(model: PlanModel) -> dict[str, Any]:
    buildings = [b.name for b in model.buildings for _ in range(b.n_floors)]
    levels = [i + 1 for b in model.buildings for i in range(b.n_floors)]
    centres = np.array([c for b in model.buildings for c in b.centres], dtype=float).reshape(-1, 2)
    corners = floor_corners(model)
    return {"floor_building": (("floor",), np.array(buildings, dtype=object), {"long_name": "building of the floor"}),
            "floor_level": (("floor",), np.array(levels, dtype=np.int64),
                            {"units": "1", "long_name": "floor number from the ground up"}),
            "floor_centre_x": (("floor",), centres[:, 0], {"units": "m", "long_name": "x of the floor's centre of mass"}),
            "floor_centre_y": (("floor",), centres[:, 1], {"units": "m", "long_name": "y of the floor's centre of mass"}),
            "corner": (("corner",), np.array(CORNERS, dtype=object), {"long_name": "corner of the floor's outline"}),
            "corner_x": (("floor", "corner"), corners[:, :, 0], {"units": "m", "long_name": "x of the corner at rest"}),
            "corner_y": (("floor", "corner"), corners[:, :, 1], {"units": "m", "long_name": "y of the corner at rest"})}


def _plane_labels(model: PlanModel) -> dict[str, Any]:
    rows = [(b.name, storey, b.storeys[storey - 1].planes[j])
            for b in model.buildings for storey, j, _ in b.plane_weights()]
    return {"plane_building": (("plane",), np.array([r[0] for r in rows], dtype=object),
                               {"long_name": "building of the plane"}),
            "plane_storey": (("plane",), np.array([r[1] for r in rows], dtype=np.int64),
                             {"units": "1", "long_name": "storey of the plane"}),
            "plane_direction": (("plane",), np.array([r[2].direction for r in rows], dtype=object),
                                {"long_name": "direction the plane resists"}),
            "plane_at": (("plane",), np.array([r[2].at for r in rows], dtype=float),
                         {"units": "m", "long_name": "the plane's line (y along x, x along y)"})}


def _between(model: PlanModel, contact) -> str:
    """``A:3-B:3`` (or ``A:1-wall``): the two floors of a contact face."""
    names = [b.name for b in model.buildings]
    second = "wall" if contact.second == WALL else f"{names[contact.second]}:{contact.level_second}"
    return f"{names[contact.first]}:{contact.level_first}-{second}"


def _point_labels(model: PlanModel, psys: PlanSystem) -> dict[str, Any]:
    faces = [model.contacts[f] for f in psys.point_face]
    between = [_between(model, c) for c in faces]
    return {"point_between": (("point",), np.array(between, dtype=object),
                              {"long_name": "the two floors of the contact point (building:floor)"}),
            "point_face": (("point",), psys.point_face, {"units": "1", "long_name": "index of the point's face"}),
            "point_normal": (("point",), np.array([c.face.normal for c in faces], dtype=object),
                             {"long_name": "normal direction of the point's face"}),
            "point_x": (("point",), psys.point_location[:, 0], {"units": "m", "long_name": "x of the point at rest"}),
            "point_y": (("point",), psys.point_location[:, 1], {"units": "m", "long_name": "y of the point at rest"})}


def _impact_slip(model: PlanModel, psys: PlanSystem, raw: RawSolution) -> np.ndarray:
    """(impacts,) the face's tangential slip (low side minus high side along +tangent, m) at each impact's onset.

    The state at the onset is the cubic Hermite interpolant of the stored samples
    (displacements with their velocities; :func:`hermite_at`).
    """
    n = psys.system.n_floors
    if raw.impact_contact.size == 0:
        return np.zeros(0)
    slip = np.array([model.scatter(c, p.slip) for c in model.contacts for p in c.points]).reshape(-1, n)
    q = hermite_at(raw.time, raw.state[:, :n], raw.state[:, n:2 * n], raw.impact_time)
    return np.einsum("ij,ij->i", q, slip[raw.impact_contact])


def _energies(psys: PlanSystem, raw: RawSolution, drift: np.ndarray) -> dict[str, np.ndarray]:
    """Energy histories (J): input, kinetic, damping, plane strain, P-Delta, contacts; initial energy first.

    The planes' strain energy is ``Σ ½ k Δ²`` of the elastic ones at the stored states (*drift*: (nt, plane),
    m) plus the yielding ones' recoverable energy, the P-Delta potential ``Σ ½ k_G (a · q)²``.
    """
    system = psys.system
    lay = system.layout
    n, npt = lay.n_floors, psys.n_points
    state = raw.state
    v = state[:, n:2 * n]
    work = state[:, lay.work:lay.work + lay.n_contacts]
    elastic = np.ones(psys.n_planes, dtype=bool)
    elastic[_yielding_planes(psys)] = False  # a yielding plane's energy: recoverable here, the rest dissipated
    strain = 0.5 * (drift[:, elastic] ** 2) @ psys.plane_stiffness[elastic]
    geometric = 0.5 * ((state[:, :n] @ psys.p_delta_weights.T) ** 2) @ psys.p_delta_stiffness
    hysteretic = state[:, lay.storey_work:lay.ground_work].sum(axis=1) - raw.storey_energy[:, 1]
    return {"energy_input": state[:, lay.input_energy],
            "energy_kinetic": 0.5 * (v * v) @ system.mass,
            "energy_damping": state[:, lay.damping_energy],
            "energy_plane_strain": strain + raw.storey_energy[:, 1],
            "energy_p_delta": geometric,
            "energy_contact": work[:, :npt].sum(axis=1),
            "energy_hysteretic": hysteretic}


def _friction_variables(psys: PlanSystem, raw: RawSolution) -> dict[str, tuple]:
    """The friction faces' histories (module docstring), {} without friction."""
    system = psys.system
    if raw.friction_history is None:
        return {}
    nf, lay = system.n_faces, system.layout
    history = raw.friction_history
    slip = penetration(raw.state[:, :system.n_floors], system.friction_floors, system.friction_weights,
                       np.zeros(nf), np.zeros((raw.time.size, nf)))
    dissipated = raw.state[:, lay.friction_work:lay.friction_work + nf].sum(axis=1)
    return {"friction_normal": _var(("time", "face"), history[:, :nf], "N", "normal force on the friction face"),
            "friction_force": _var(("time", "face"), -history[:, nf:2 * nf], "N",
                                   "friction on the face's low side along +tangent (the high side: the opposite)"),
            "friction_state": _var(("time", "face"), history[:, 2 * nf:].astype(np.int64), "1",
                                   "face: 0 open, +1/-1 slipping along +/-tangent, 2 sticking"),
            "face_slip": _var(("time", "face"), slip, "m",
                              "tangential slip of the low side's face relative to the high side's, along +tangent"),
            "energy_friction": _var(("time",), dissipated, "J", "energy: friction (dissipated)")}


def _face_labels(model: PlanModel, psys: PlanSystem) -> dict[str, Any]:
    """Coordinates of the friction faces (``face`` dimension), {} without friction."""
    if psys.system.n_faces == 0:
        return {}
    faces = [(i, c) for i, c in enumerate(model.contacts) if c.friction]
    between = [_between(model, c) for _, c in faces]
    return {"face_index": (("face",), np.array([i for i, _ in faces], dtype=np.int64),
                           {"units": "1", "long_name": "index of the face (as point_face)"}),
            "face_between": (("face",), np.array(between, dtype=object), {"long_name": "the two floors of the face"}),
            "face_tangent": (("face",), np.array([c.face.tangent for _, c in faces], dtype=object),
                             {"long_name": "tangential direction of the face"}),
            "face_friction_coefficient": (("face",), np.array([float(c.friction) for _, c in faces]),
                                          {"units": "1", "long_name": "Coulomb friction coefficient"})}


def _yielding_planes(psys: PlanSystem) -> np.ndarray:
    """Indices of the yielding planes, in the order of their hysteretic states (none without storey rows)."""
    system = psys.system
    if system.storey_floors is None:
        return np.zeros(0, dtype=np.int64)
    planes = np.flatnonzero(system.storey_state >= 0)
    return planes[np.argsort(system.storey_state[planes])]


def _plane_shear(psys: PlanSystem, raw: RawSolution, drift: np.ndarray) -> np.ndarray:
    """(nt, plane) shear of every plane, N: kΔ, a yielding plane's by its hysteresis at its state."""
    system = psys.system
    shear = drift * psys.plane_stiffness
    first = system.layout.hysteretic
    for index, p in enumerate(_yielding_planes(psys)):
        shear[:, p] = restoring_force.py_func(int(system.storey_model[p]), system.storey_parameters, int(p),
                                              float(psys.plane_stiffness[p]), drift[:, p], raw.state[:, first + index])
    return shear


def plan_energy_closure(ds: xr.Dataset) -> float:
    """``max |E_0 + E_in − Σ parts| / max (E_0 + |E_in|)`` of a plan archive (dimensionless)."""
    parts = (ds.energy_kinetic + ds.energy_damping + ds.energy_plane_strain + ds.energy_p_delta + ds.energy_contact
             + ds.get("energy_hysteretic", 0.0) + ds.get("energy_friction", 0.0))
    initial = float(parts[0])
    supplied = initial + ds.energy_input
    scale = float(np.abs(supplied).max())
    return 0.0 if scale == 0.0 else float(np.abs(supplied - parts).max()) / scale


def plan_dataset(model: PlanModel, psys: PlanSystem, raw: RawSolution, *,
                 attrs: dict[str, Any] | None = None) -> xr.Dataset:
    """The archive of a plan run (module docstring); *attrs* join the dataset's attributes."""
    system = psys.system
    n = system.n_floors
    nf = n // DOF_PER_FLOOR
    npt = psys.n_points
    u = raw.state[:, :n].reshape(-1, nf, DOF_PER_FLOOR)
    v = raw.state[:, n:2 * n].reshape(-1, nf, DOF_PER_FLOOR)
    delta = penetration(raw.state[:, :n], system.contact_floors, system.contact_weights, system.contact_gap,
                        np.zeros((raw.time.size, system.n_contacts)))
    drift = raw.state[:, :n] @ psys.plane_weights.T
    peak_u = raw.peak_displacement.reshape(nf, DOF_PER_FLOOR)
    counts = np.bincount(raw.impact_contact, minlength=npt)[:npt] if raw.impact_contact.size else np.zeros(npt, int)
    centres = np.array([c for b in model.buildings for c in b.centres], dtype=float).reshape(nf, 2)
    corner = np.einsum("tfk,fcdk->tfcd", u, corner_weights(centres, floor_corners(model)))
    magnitude = np.hypot(corner[..., 0], corner[..., 1])
    location = psys.point_location[raw.impact_contact] if raw.impact_contact.size else np.zeros((0, 2))
    data = {
        "displacement": _var(("time", "floor", "direction"), u[:, :, :2], "m",
                             "displacement of the floor's centre of mass relative to the ground"),
        "rotation": _var(("time", "floor"), u[:, :, 2], "rad", "rotation of the floor, counter-clockwise"),
        "velocity": _var(("time", "floor", "direction"), v[:, :, :2], "m/s",
                         "velocity of the floor's centre of mass relative to the ground"),
        "rotation_rate": _var(("time", "floor"), v[:, :, 2], "rad/s", "rotation rate of the floor"),
        "peak_displacement": _var(("floor", "direction"), peak_u[:, :2], "m",
                                  "peak |displacement| of the centre of mass (full resolution)"),
        "peak_rotation": _var(("floor",), peak_u[:, 2], "rad", "peak |rotation| of the floor (full resolution)"),
        "corner_displacement": _var(("time", "floor", "corner", "direction"), corner, "m",
                                    "displacement of the outline's corner (small rotations)"),
        "corner_displacement_magnitude": _var(("time", "floor", "corner"), magnitude, "m",
                                              "magnitude of the corner's displacement"),
        "peak_corner_displacement": _var(("floor", "corner", "direction"), np.abs(corner).max(axis=0, initial=0.0),
                                         "m", "peak |displacement| of the corner (stored samples)"),
        "peak_corner_displacement_magnitude": _var(("floor", "corner"), magnitude.max(axis=0, initial=0.0), "m",
                                                   "peak magnitude of the corner's displacement (stored samples)"),
        "plane_drift": _var(("time", "plane"), drift, "m", "drift of the plane's line"),
        "peak_plane_drift": _var(("plane",), raw.peak_plane_drift, "m", "peak |drift| of the plane (full resolution)"),
        "plane_stiffness": _var(("plane",), psys.plane_stiffness, "N/m", "elastic stiffness of the plane"),
        "plane_shear": _var(("time", "plane"), _plane_shear(psys, raw, drift), "N",
                            "shear of the plane (restoring force, without P-Delta)"),
        "contact_force": _var(("time", "point"), raw.contact_force[:, :npt], "N",
                              "normal contact force at the point (compression positive)"),
        "penetration": _var(("time", "point"), delta[:, :npt], "m", "penetration at the point (overlap positive)"),
        "peak_contact_force": _var(("point",), raw.peak_contact_force[:npt], "N",
                                   "peak normal contact force at the point (full resolution)"),
        "impact_count": _var(("point",), counts, "1", "number of impacts at the point"),
        "impact_point": _var(("impact",), raw.impact_contact, "1", "contact point of the impact"),
        "impact_time": _var(("impact",), raw.impact_time, "s", "time of contact onset"),
        "impact_x": _var(("impact",), location[:, 0], "m", "x of the impact's contact point at rest"),
        "impact_y": _var(("impact",), location[:, 1], "m", "y of the impact's contact point at rest"),
        "impact_slip": _var(("impact",), _impact_slip(model, psys, raw), "m",
                            "tangential slip of the face at the onset (low side minus high side, along +tangent)"),
        "impact_velocity": _var(("impact",), raw.impact_velocity, "m/s", "approach velocity at the point at onset"),
        "impact_peak_force": _var(("impact",), raw.impact_peak_force, "N", "peak force of the impact"),
        "impact_impulse": _var(("impact",), raw.impact_impulse, "N s", "impulse of the impact"),
    }
    data.update(_friction_variables(psys, raw))
    for name, values in _energies(psys, raw, drift).items():
        label = name.removeprefix("energy_").replace("_", " ")
        data[name] = _var(("time",), values, "J", f"energy: {label}")
    if raw.support_acceleration is not None:
        data["ground_acceleration"] = _var(("time", "direction"), raw.support_acceleration[:, :2], "m/s²",
                                           "ground acceleration along x and y")
    coords = {"time": ("time", raw.time, {"units": "s", "long_name": "time"}),
              "direction": ("direction", np.array(["x", "y"], dtype=object), {"long_name": "plan direction"}),
              **_floor_labels(model), **_plane_labels(model), **_point_labels(model, psys),
              **_face_labels(model, psys)}
    ds = xr.Dataset(data, coords=coords, attrs={"title": f"pounding plan run: {model.name}", "model": model.name,
                                                "kind": "plan_run", **(attrs or {})})
    ds.attrs["energy_closure"] = plan_energy_closure(ds)
    return ds


def peak_corner(ds: xr.Dataset, building: str) -> tuple[int, int, float]:
    """Building *building*'s largest peak corner displacement magnitude: (floor level, corner index, m)."""
    floors = np.flatnonzero(ds.floor_building.values == building)
    peaks = ds.peak_corner_displacement_magnitude.values[floors]
    row, corner = np.unravel_index(int(np.argmax(peaks)), peaks.shape)
    return int(ds.floor_level.values[floors[row]]), int(corner), float(peaks[row, corner])


def plan_summary(ds: xr.Dataset) -> str:
    """A few lines: peak displacement and roof rotation per building, impacts, energy closure."""
    lines = [f"{ds.attrs.get('model', '')}: plan run to {float(ds.time[-1]):.3f} s"]
    for name in dict.fromkeys(ds.floor_building.values):
        floors = ds.floor_building.values == name
        peak = ds.peak_displacement.values[floors]
        roof = ds.peak_rotation.values[floors][-1]
        lines.append(f"  {name}: peak displacement x {1e3 * peak[:, 0].max():.2f} mm, "
                     f"y {1e3 * peak[:, 1].max():.2f} mm; peak roof rotation {roof:.3e} rad")
        if "peak_corner_displacement_magnitude" in ds:
            floor, corner, value = peak_corner(ds, name)
            lines.append(f"    peak corner displacement {1e3 * value:.2f} mm at floor {floor}, "
                         f"{ds.corner.values[corner]} corner")
    if "energy_friction" in ds:
        lines.append(_friction_line(ds))
    lines.append(f"  impacts {int(ds.impact_count.sum())} at {int((ds.impact_count > 0).sum())} of "
                 f"{ds.sizes.get('point', 0)} points; energy closure {ds.attrs['energy_closure']:.1e}")
    return "\n".join(lines)


def _friction_line(ds: xr.Dataset) -> str:
    """One summary line: the friction faces' largest force and slip, their stuck samples, the energy dissipated."""
    force = float(np.abs(ds.friction_force).max())
    slip = float(np.abs(ds.face_slip).max())
    stuck = int((ds.friction_state == 2).any("face").sum())
    return (f"  friction on {ds.sizes['face']} face(s): peak force {force / 1e3:.1f} kN, peak slip "
            f"{1e3 * slip:.2f} mm, sticking at {stuck} of {ds.sizes['time']} samples, "
            f"dissipated {float(ds.energy_friction[-1]) / 1e3:.1f} kJ")


def compare_plan_runs(before: xr.Dataset, after: xr.Dataset, name: str = "archive") -> str:
    """One line comparing a rerun *after* with its archive *before*: every variable identical, or those that
    differ with their largest difference relative to the variable's largest magnitude."""
    differ = []
    for var in before.data_vars:
        old = before[var].values
        new = after[var].values if var in after.data_vars else None
        if new is None or old.shape != new.shape:
            differ.append(f"{var} (shape)")
        elif not np.array_equal(old, new, equal_nan=old.dtype.kind == "f"):
            scale = float(np.nanmax(np.abs(old))) if old.size else 0.0
            gap = float(np.nanmax(np.abs(old - new)))
            differ.append(f"{var} ({gap / scale if scale else gap:.1e})")
    if not differ:
        return f"rerun reproduces {name}: all {len(before.data_vars)} variables identical"
    return f"rerun differs from {name} in {len(differ)} variable(s): {', '.join(differ[:8])}" + \
        (" ..." if len(differ) > 8 else "")
