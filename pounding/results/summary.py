"""A run in a few lines: the peaks a reader looks for first, and how a rerun compares with its archive.

For floors in plan: peak displacements and roof rotation per building, its largest corner
displacement, friction, impacts and the energy closure (:func:`plan_summary`);
:func:`compare_runs` compares a rerun with its archive, variable by variable.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from pounding.results.corners import peak_corner

__all__ = ["plan_summary", "compare_runs"]


def plan_summary(ds: xr.Dataset) -> str:
    """A few lines: peak displacement and roof rotation per building, impacts, energy closure."""
    lines = [f"{ds.attrs.get('model', '')}: plan run to {float(ds.time[-1]):.3f} s"]
    for name in dict.fromkeys(ds.building.values):
        floors = ds.building.values == name
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
                 f"{ds.sizes.get('contact', 0)} points; energy closure {ds.attrs['energy_closure']:.1e}")
    return "\n".join(lines)


def _friction_line(ds: xr.Dataset) -> str:
    """One summary line: the friction faces' largest force and slip, their stuck samples, the energy dissipated."""
    force = float(np.abs(ds.friction_force).max())
    slip = float(np.abs(ds.face_slip).max())
    stuck = int((ds.friction_state == 2).any("face").sum())
    return (f"  friction on {ds.sizes['face']} face(s): peak force {force / 1e3:.1f} kN, peak slip "
            f"{1e3 * slip:.2f} mm, sticking at {stuck} of {ds.sizes['time']} samples, "
            f"dissipated {float(ds.energy_friction[-1]) / 1e3:.1f} kJ")


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
