"""A run in a few lines: what its archive holds, the peaks a reader looks for first, and how a rerun compares.

:func:`run_summary` is printed by ``pounding run``, ``rerun`` and ``info`` for the run of any model; each
part is there when the archive holds its data:

* the record and its intensity; the ground motion as run (each building's ground with several grounds;
  both components along x and y with two);
* the periods; the buildings' outlines and planes (floors in plan);
* the peak drift ratio per storey; the yielding storeys (or planes) and a collapse;
* the peak displacement, roof rotation and most displaced corner per building (floors in plan);
* the contacts (impacts, peak force, law), friction, links; the energy closure and the solver.

:func:`compare_runs` compares a rerun with its archive, variable by variable.  :data:`ROUND_OFF` is the
relative size below which a rotation, or a departure from elasticity, is taken for round-off
(:func:`rotating_buildings`, :func:`yielding_planes`).
"""

from __future__ import annotations

import json
import math

import numpy as np
import xarray as xr

from pounding.results.corners import peak_corner
from pounding.results.describe import record_event
from pounding.units import STANDARD_GRAVITY

__all__ = ["run_summary", "compare_runs", "ROUND_OFF", "rotating_buildings", "yielding_planes", "force_text"]

#: Relative size below which a rotation or a departure from elasticity is round-off: a building's roof
#: rotation whose largest corner motion (|θ| times the farthest corner's distance from the roof's centre of
#: mass) is at most this times the building's peak displacement, or a plane whose shear departs from k·Δ by
#: at most this times its peak k·Δ.  Float64 round-off leaves ~1e-16 of the translation (a symmetric plan
#: shaken along x twists by 4e-19 rad for 58 mm), the solver controls its error to rtol >= 1e-10 of it, and
#: a real eccentricity of 1 mm in 10 m already gives ~1e-4: 1e-9 lies far from both.
ROUND_OFF = 1e-9


def force_text(newtons: float) -> str:
    """A force in MN, kN or N, three significant digits."""
    if newtons >= 1e6:
        return f"{newtons / 1e6:.3g} MN"
    if newtons >= 1e3:
        return f"{newtons / 1e3:.3g} kN"
    return f"{newtons:.3g} N"


def rotating_buildings(ds: xr.Dataset) -> dict[str, bool]:
    """Per building with floors in plan, whether its roof rotates beyond round-off (:data:`ROUND_OFF`): its peak
    roof rotation times the distance from the roof's centre of mass to its farthest corner exceeds ROUND_OFF
    times the building's peak displacement (the largest over its floors and directions), m."""
    found = {}
    for name in dict.fromkeys(str(b) for b in ds.building.values):
        floors = np.flatnonzero(ds.building.values == name)
        roof = floors[-1]
        reach = float(np.hypot(ds.corner_x.values[roof] - float(ds.floor_centre_x[roof]),
                               ds.corner_y.values[roof] - float(ds.floor_centre_y[roof])).max())
        translation = float(ds.peak_displacement.values[floors].max(initial=0.0))
        found[name] = float(ds.peak_rotation.values[roof]) * reach > ROUND_OFF * translation
    return found


def yielding_planes(ds: xr.Dataset) -> np.ndarray:
    """Whether each plane yielded: its shear (N) departs from k·Δ by more than :data:`ROUND_OFF` of its peak
    k·Δ at some stored sample (an archive without planes: no rows)."""
    if "plane_shear" not in ds:
        return np.zeros(0, dtype=bool)
    elastic = ds.plane_drift.values * ds.plane_stiffness.values
    departure = np.abs(ds.plane_shear.values - elastic).max(axis=0, initial=0.0)
    return departure > ROUND_OFF * np.abs(elastic).max(axis=0, initial=0.0)


def _record_lines(ds: xr.Dataset) -> list[str]:
    """The record's PGA as recorded and as run, per building on its own record; with two components (floors
    in plan) the peak ground acceleration along x and y as run."""
    if "direction" in ds.ground_acceleration.dims:
        peak = np.abs(ds.ground_acceleration.values).max(axis=0, initial=0.0)
        along = ", ".join(f"{a / STANDARD_GRAVITY:.3g} g ({a:.3g} m/s2) along {d}"
                          for a, d in zip(peak, ds.direction.values))
        angle = float(ds.attrs.get("angle", 0.0))
        several = ds.attrs.get("multi_support")   # wave passage, a record pair per building: the first one's ground
        return [f"peak ground acceleration as run (x{float(ds.attrs['record_scale']):.4g}"
                f"{f', component a at {angle:g} deg from +x' if angle else ''}"
                f"{f', {several}: under the first building' if several else ''}): {along}"]

    def line(label: str, own: float, scaled: float, factor: float) -> str:
        return (f"{label} {own / STANDARD_GRAVITY:.3g} g ({own:.3g} m/s2) as recorded, "
                f"{scaled / STANDARD_GRAVITY:.3g} g ({scaled:.3g} m/s2) as run (x{factor:.4g})")

    if "ground_pga" in ds.attrs:   # each building on its own record: one line each
        return [line(f"record PGA under {name} ({g['record']})", g["pga_recorded"], g["pga"], g["scale"])
                for name, g in json.loads(ds.attrs["ground_pga"]).items()]
    from pounding.results.dataset import record_pga

    own, scaled = record_pga(ds)
    return [line("record PGA", own, scaled, ds.attrs["record_scale"])]


def _grounds_lines(ds: xr.Dataset) -> list[str]:
    """With a ground per building (wave passage, a record each): each building's record, lag and peak ground
    displacement (in plan, of its magnitude over x and y), m."""
    if not (ds.attrs.get("multi_support") and "ground" in ds.dims and "building_ground_displacement" in ds):
        return []
    lines = [f"ground under each building ({ds.attrs['multi_support']}):"]
    for name in ds.ground.values:
        g = ds.sel(ground=name)
        displacement = g.building_ground_displacement.values
        peak = np.hypot(displacement[:, 0], displacement[:, 1]) if displacement.ndim == 2 else np.abs(displacement)
        record = f"{g.ground_record.item()} x{float(g.ground_scale):g}, " if "ground_record" in ds else ""
        lines.append(f"  {name}: {record}lag {float(g.ground_lag):.3g} s, peak ground displacement "
                     f"{float(peak.max(initial=0.0)):.3g} m")
    return lines


def _building_lines(ds: xr.Dataset, periods: dict) -> list[str]:
    """The periods per building and, for floors in plan, each building's floors, outline and planes."""
    lines = ["periods (s):"]
    for name, values in periods.items():
        shown = " ".join(f"{v:.3f}" for v in values[:5]) + (" ..." if len(values) > 5 else "")
        lines.append(f"  {name}: {shown}")
    if "corner_x" not in ds:
        return lines
    lines.append("buildings (floors, outline m, planes per direction):")
    for name in dict.fromkeys(ds.building.values):
        floors = np.flatnonzero(ds.building.values == name)
        xs, ys = ds.corner_x.values[floors[0]], ds.corner_y.values[floors[0]]
        directions = ds.plane_direction.values[ds.plane_building.values == name]
        lines.append(f"  {name}: {floors.size} floor{'s' if floors.size > 1 else ''}, "
                     f"[[{xs.min():g}, {ys.min():g}], [{xs.max():g}, {ys.max():g}]], "
                     f"{int((directions == 'x').sum())} along x and {int((directions == 'y').sum())} along y")
    return lines


def _yield_lines(ds: xr.Dataset, periods: dict) -> list[str]:
    """Yielding storeys (peak ductility, residual drift ratio) or yielded planes (peak and final drift ratio),
    the hysteretic energy; the collapse drift ratios; a status other than completed."""
    lines = []
    energy = float(ds.energy_hysteretic.values[-1]) if "energy_hysteretic" in ds else 0.0
    if "peak_ductility" in ds and bool(np.isfinite(ds.peak_ductility.values).any()):
        lines.append("yielding storeys: peak ductility (peak drift / yield drift) and residual drift ratio (%):")
        for name in periods:
            mine = ds.storey_building.values == name
            ductility = ds.peak_ductility.values[mine]
            if not np.isfinite(ductility).any():
                continue
            residual = ds.residual_drift_ratio.values[mine]
            lines.append(f"  {name} ductility: " + " ".join("-" if not np.isfinite(v) else f"{v:.2f}"
                                                            for v in ductility))
            lines.append(f"  {name} residual: " + " ".join(f"{100 * v:+.3f}" for v in residual))
        lines.append(f"  hysteretic energy dissipated: {energy / 1e3:.4g} kJ")
    yielded = np.flatnonzero(yielding_planes(ds))
    if yielded.size:
        lines.append("yielded planes: peak and final drift ratio (%):")
        lines += [f"  {ds.plane.values[p]}: {100 * float(ds.peak_plane_drift_ratio.values[p]):.3f}, "
                  f"{100 * float(ds.plane_drift_ratio.values[-1, p]):+.3f}" for p in yielded]
        lines.append(f"  hysteretic energy dissipated: {energy / 1e3:.4g} kJ")
    if "collapse_drift_ratio" in ds and bool(np.isfinite(ds.collapse_drift_ratio.values).any()):
        limits = {str(b): float(r) for b, r in zip(ds.storey_building.values, ds.collapse_drift_ratio.values)}
        lines.append("collapse drift ratio (a building collapses, and the run ends, past it): "
                     + ", ".join(f"{b} {'none' if not np.isfinite(r) else f'{r:g}'}" for b, r in limits.items()))
    if ds.attrs.get("status") in ("collapsed", "unstable", "energy_inconsistent"):
        status, _, why = str(ds.attrs.get("status_message", ds.attrs["status"])).partition(": ")
        lines.append(f"{status.upper().replace('_', ' ')}: {why}")
    return lines


def _plan_peak_lines(ds: xr.Dataset) -> list[str]:
    """Floors in plan: per building the peak displacement of its centre of mass along x and y, its peak roof
    rotation and its most displaced corner."""
    if "peak_rotation" not in ds:
        return []
    lines = ["peak displacement (centre of mass), roof rotation and corner displacement:"]
    for name in dict.fromkeys(ds.building.values):
        floors = ds.building.values == name
        peak = ds.peak_displacement.values[floors]
        roof = ds.peak_rotation.values[floors][-1]
        lines.append(f"  {name}: peak displacement x {1e3 * peak[:, 0].max():.2f} mm, "
                     f"y {1e3 * peak[:, 1].max():.2f} mm; peak roof rotation {roof:.3e} rad")
        floor, corner, value = peak_corner(ds, name)
        lines.append(f"    peak corner displacement {1e3 * value:.2f} mm at floor {floor}, "
                     f"{ds.corner.values[corner]} corner")
    return lines


def _contact_lines(ds: xr.Dataset) -> list[str]:
    """Each contact's impacts, peak force and law; the impacts in all; friction; each link's peaks."""
    lines = []
    if ds.sizes.get("contact", 0):
        lines.append("contacts (gap element: impacts, peak force, formula):")
        for i in range(ds.sizes["contact"]):
            formula = str(ds.xi_formula.values[i]) or str(ds.law.values[i])
            lines.append(f"  {ds.contact.values[i]}: {int(ds.impact_count.values[i])} impacts, "
                         f"peak {force_text(float(ds.peak_contact_force.values[i]))}, {ds.law.values[i]}"
                         f"{'/' + formula if formula != str(ds.law.values[i]) else ''}")
        total = int(ds.impact_count.sum())
        if total:
            v0 = ds.impact_velocity.values
            lines.append(f"  {total} impacts in all; approach velocity {np.nanmin(v0):.3g}-{np.nanmax(v0):.3g} m/s")
    if "friction_force" in ds:
        lines.append(_friction_line(ds))
    if ds.sizes.get("link", 0):
        lines.append("links (floors: peak |force|, peak |deformation|, energy dissipated, element):")
        for i in range(ds.sizes["link"]):
            peak_deformation = float(np.abs(ds.link_deformation.values[:, i]).max())
            lines.append(f"  {ds.link.values[i]}: peak {force_text(float(ds.peak_link_force.values[i]))}, "
                         f"{1000 * peak_deformation:.3g} mm, {float(ds.link_dissipated_energy.values[i]) / 1e3:.4g} kJ, "
                         f"{ds.link_law.values[i]}")
    return lines


def _friction_line(ds: xr.Dataset) -> str:
    """One summary line: the friction faces' largest force and slip, their stuck samples, the energy dissipated."""
    force = float(np.abs(ds.friction_force).max())
    slip = float(np.abs(ds.face_slip).max())
    stuck = int((ds.friction_state == 2).any("face").sum())
    return (f"  friction on {ds.sizes['face']} face(s): peak force {force / 1e3:.1f} kN, peak slip "
            f"{1e3 * slip:.2f} mm, sticking at {stuck} of {ds.sizes['time']} samples, "
            f"dissipated {float(ds.energy_friction[-1]) / 1e3:.1f} kJ")


def _foundation_lines(ds: xr.Dataset) -> list[str]:
    """Per building on a foundation: fixed- and flexible-base first period, effective damping, the base mat's
    peak sway and rocking, and the foundation dashpots' share of the damping energy (docs/foundations.md)."""
    if not ds.attrs.get("foundations"):
        return []
    found = json.loads(ds.attrs["foundations"])
    lines = ["foundations (first period fixed / flexible base, damping ratio fixed / effective):"]
    damping = float(ds.energy_damping[-1])
    share = float(ds.energy_foundation_damping[-1]) / damping if damping > 0 else float("nan")
    for name, f in found.items():
        fixed, flexible = f["fixed_base_periods"][0], f["flexible_base_periods"][0]
        sway = float(ds.peak_base_sway.sel(foundation=name))
        rocking = float(ds.peak_base_rocking.sel(foundation=name))
        lines.append(f"  {name}: T {fixed:.3f} / {flexible:.3f} s (x{flexible / fixed:.3f}), "
                     f"{100 * f['fixed_base_damping']:.2f} / {100 * f['effective_damping']:.2f} %; peak base sway "
                     f"{1e3 * sway:.2f} mm, rocking {rocking:.2e} rad")
        springs = f.get("springs", {})
        if "frequency" in springs:   # from the soil and the footing: the springs used, and where they were evaluated
            omega = springs["frequency"]
            lines.append(f"    springs from the soil and footing at {omega:.4g} rad/s "
                         f"(T̃ {2 * math.pi / omega:.3f} s, Veletsos & Meek): "
                         f"K_x {springs['sway_stiffness']:.4g} N/m, c_x {springs['sway_damping']:.4g} N s/m, "
                         f"K_θ {springs['rocking_stiffness']:.4g} N m/rad, "
                         f"c_θ {springs['rocking_damping']:.4g} N m s/rad")
    lines.append(f"  foundation dashpots: {100 * share:.1f} % of the damping energy")
    return lines


def run_summary(ds: xr.Dataset) -> str:
    """A run archive's summary, a few lines, each part where the archive holds its data (module docstring).

    Returns
    -------
    str
        Lines without a final newline; forces in N, kN or MN, drift ratios in %, displacements in mm.
    """
    event = record_event(ds)
    lines = [f"model '{ds.attrs['model_name']}' under {ds.attrs['record_name']} x{ds.attrs['record_scale']:g}"
             f"{f' ({event})' if event else ''}, {ds.attrs['duration']:.2f} s"]
    lines += _record_lines(ds) + _grounds_lines(ds)
    if ds.attrs.get("contacts"):
        lines.append(f"contacts {ds.attrs['contacts']}")
    periods = json.loads(ds.attrs["periods"])
    lines += _building_lines(ds, periods)
    lines.append("peak drift ratio per storey (%), from the ground up:")
    peaks, owners = ds.peak_drift_ratio.values, ds.storey_building.values   # per storey (numpy: xarray's where is ~10 ms)
    for name in periods:
        lines.append(f"  {name}: " + " ".join(f"{100 * v:.3f}" for v in peaks[owners == name]))
    lines += _yield_lines(ds, periods)
    lines += _foundation_lines(ds)
    lines += _plan_peak_lines(ds)
    lines += _contact_lines(ds)
    lines.append(f"energy closure error {ds.attrs['energy_closure_error']:.2e}; "
                 f"{ds.attrs['solver_steps']} steps ({ds.attrs['solver_rejected_steps']} rejected); "
                 f"solver wall time {ds.attrs['wall_time']:.3f} s")
    status = str(ds.attrs.get("energy_status", "ok"))
    if status != "ok":
        lines.append(f"WARNING: {status.removeprefix('warning: ')}")
    return "\n".join(lines)


def compare_runs(before: xr.Dataset, after: xr.Dataset, name: str = "archive") -> str:
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
