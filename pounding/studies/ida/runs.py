"""One IDA run on a worker: the scaled model simulated for its peaks, and the run's outcome.

One runner for every model: the peaks of :func:`pounding.simulation.simulate_peaks` (a storey's drift
ratio is, for floors in plan, the largest of its planes'; a contact is a gap element, a contact point in
plan), and for floors in plan each plane's peak drift ratio beside them.
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable

import numpy as np

from pounding.recently_used import RecentlyUsed
from pounding.studies.ida.schedule import IdaPlan
from pounding.studies.ida.superposition import superposed_peaks, unit_factor

__all__ = ["IDA_PART", "run_ida_scenario", "run_outcome", "building_drifts", "collapsed_in", "collapse_building_of",
           "run_collapses", "buildings_alone", "separate_peaks"]

#: Version of this study's part layout (stored in each part, checked when parts are reused).
IDA_PART = "ida-1"


def _plain(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


#: This worker process's validated models and processed (unscaled) records of the last few IDA
#: templates (a variant and a record).  The runs of one template differ only in their
#: ``ground_motion.scale``, a plain factor; validating the model and reading and processing the
#: record took ~3 ms of every ~30 ms run, and is now done once per worker and template.
_TEMPLATES: RecentlyUsed[tuple] = RecentlyUsed(8)


def _model_and_record(task: dict[str, Any]) -> tuple[Any, Any, list | None]:
    """The run's model, its scaled record (None: the model loads its own) and its buildings alone (one model
    each, :func:`buildings_alone`; None: they run together), reusing its template's.

    A run is keyed by its document data with the scale left out (``repr`` of plain data: exact
    for floats), its base folder and name; a scaled record is
    ``scale_record(processed, factor)``, exactly what :func:`~pounding.simulation.record_for`
    makes of ``scale: factor``.  The first run of a template validates its own document, so a
    model or record error is that run's error, raised again by every run of it (nothing is kept).
    """
    from pounding.model.model import model_from_data
    from pounding.records.processing import scale_record
    from pounding.simulation import processed_record_for

    data = task["data"]
    ground_motion = data.get("ground_motion") if isinstance(data, dict) else None
    scale = ground_motion.get("scale") if isinstance(ground_motion, dict) else None
    name = task.get("name", "model")
    if not isinstance(scale, (int, float)) or isinstance(scale, bool) or "x" in ground_motion or "y" in ground_motion:
        # a target, or components given one by one (scaled in their own ``scale``): the model loads its own
        model = model_from_data(data, name=name, source=task["document"], base_dir=task.get("base_dir"))
        return model, None, _alone_models(task, model)
    key = repr((dict(data, ground_motion=dict(ground_motion, scale=None)), task.get("base_dir"), name))
    template = _TEMPLATES.find(key)
    if template is None:
        model = model_from_data(data, name=name, source=task["document"], base_dir=task.get("base_dir"))
        if model.has_building_records:
            return model, None, None
        template = (model, processed_record_for(model, where="yaml"), _alone_models(task, model))
        _TEMPLATES.put(key, template)
    model, processed, alone = template
    return model, scale_record(processed, float(scale)), alone


def _alone_models(task: dict[str, Any], model) -> list | None:
    """Each building of the run's *model* alone, validated (:func:`buildings_alone`), or None."""
    from pounding.model.model import model_from_data

    documents = buildings_alone(task["data"], model)
    if documents is None:
        return None
    return [model_from_data(d, name=task.get("name", "model"), source=task["document"], base_dir=task.get("base_dir"))
            for d in documents]


def run_ida_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """One run of an IDA, on a worker: simulate the scaled model and keep its peaks (plain data).

    Never raises for a problem of the scenario: the result then has
    ``status = "error"`` and the message (the run ``failed``).  NaN values
    are stored as None (JSON has no NaN).
    """
    from pounding.simulation import refuse_failed_run, simulate_peaks
    from pounding.studies.engine.keys import PARTS_FORMAT
    from pounding.studies.engine.tasks import one_line

    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "study": IDA_PART,
                              "format": PARTS_FORMAT}
    try:
        model, record, alone = _model_and_record(task)
        if alone is None:
            # the peaks of simulate(model), without histories or dataset; the model's assembly kept with it
            peaks = simulate_peaks(model, record, reuse=True)
            refuse_failed_run(peaks["status"], peaks["status_message"])   # energy_inconsistent: failed
        else:   # buildings that cannot act on each other: each its own run, so no collapse ends another's
            peaks = separate_peaks(alone, record, _unit_models(task))
        result.update({
            "status": "ok",
            # A storey that lost its lateral resistance (unstable) is a sidesway collapse of the building.
            "outcome": "collapsed" if peaks["status"] in ("collapsed", "unstable") else peaks["status"],
            "run_status": peaks["status"],
            "collapse_time": _plain(peaks["collapse_time"]),
            "collapse_storey": peaks["collapse_storey"],
            "collapse_building": peaks["collapse_building"],
            **({"collapse_buildings": peaks["collapse_buildings"],
                # a group of its own: a part's top-level lists are of one length (the store's check)
                "superposed": {"building": peaks["superposed_buildings"]}} if alone is not None else {}),
            "storeys": {
                "storey": list(peaks["storey"]),
                "building": list(peaks["storey_building"]),
                "peak_drift_ratio": [float(x) for x in peaks["peak_drift_ratio"]],
                "residual_drift_ratio": [_plain(float(x)) for x in peaks["residual_drift_ratio"]],
            },
            "contacts": {
                "contact": list(peaks["contact"]),
                "impact_count": [int(x) for x in peaks["impact_count"]],
                "peak_contact_force": [float(x) for x in peaks["peak_contact_force"]],
            },
            "scale_factor": peaks["record_scale"],
            "solver_wall_time": peaks["wall_time"],
        })
        if "plane" in peaks:   # floors in plan: each plane (a frame or wall line) of each storey
            result["planes"] = {"plane": list(peaks["plane"]),
                                "building": [label.rsplit(":", 2)[0] for label in peaks["plane"]],
                                "peak_drift_ratio": [float(x) for x in peaks["peak_plane_drift_ratio"]]}
    except Exception as exc:  # noqa: BLE001 - a failing run is a result, not a crash
        result["error"] = f"{task.get('where', 'scenario')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


def _unit_models(task: dict[str, Any]) -> tuple[float, list[tuple[str, Callable]]] | None:
    """``(factor, [(key, unit model) per building])`` of a run of buildings alone whose record is scaled by one
    plain factor (:func:`.superposition.unit_factor`): each building's key (its template's, the factor left
    out) and its model at factor 1, validated when called; None otherwise."""
    from pounding.model.model import model_from_data

    factor, unit = unit_factor(task["data"])
    if factor is None:
        return None
    name, base_dir = task.get("name", "model"), task.get("base_dir")
    documents = _one_building_each(unit)
    template = repr((unit, base_dir, name))

    def validated(document: dict[str, Any]) -> Callable:
        return lambda: model_from_data(document, name=name, source=task["document"], base_dir=base_dir)

    return factor, [(f"{template}#{k}", validated(d)) for k, d in enumerate(documents)]


def buildings_alone(document: dict[str, Any], model) -> list[dict[str, Any]] | None:
    """One model document per building of *model* (its *document*, plain data) when its buildings cannot act
    on each other, else None.

    They cannot when the model has more than one building, no links, no contact that can close (none, or
    every one held open: the variant without contacts) and one ground motion that reaches every building at
    once (no wave passage, no per-building records).  Each document then keeps one building and everything
    else of the model but its contacts: the run of that building alone is its run in the model, and a
    neighbour's collapse can no longer end it (docs/ida.md "Collapse of each building").
    """
    if (len(model.buildings) < 2 or model.links or (model.gaps and not model.contacts_held_open)
            or model.is_multi_support):
        return None
    return _one_building_each(document)


def _one_building_each(document: dict[str, Any]) -> list[dict[str, Any]]:
    """One document per building of *document*: that building and everything else but the contacts and links."""
    rest = {k: v for k, v in document.items() if k not in ("buildings", "contacts", "links")}
    return [dict(rest, buildings=[building]) for building in document["buildings"]]


def separate_peaks(models: list, record, units: tuple[float, list[tuple[str, Callable]]] | None = None
                   ) -> dict[str, Any]:
    """The peaks of one run of independent buildings: each building's model alone (:func:`buildings_alone`)
    run on the same scaled *record* (None: each model loads its own), merged in the model's order.

    With *units* (:func:`_unit_models`) a building that responds linearly takes its unit run's peaks times
    the factor (:func:`.superposition.superposed_peaks`), and is listed in ``superposed_buildings``.  Every
    building that collapsed is in ``collapse_buildings``; ``collapse_building``, ``collapse_time`` and
    ``collapse_storey`` are the first collapse's; the wall time is the sum.  A failed run of any building
    (energy_inconsistent) fails the whole run, as it would the model's.
    """
    from pounding.simulation import refuse_failed_run, simulate_peaks

    runs, superposed = [], []
    for index, model in enumerate(models):
        peaks = None
        if units is not None:
            factor, buildings = units
            key, unit_model = buildings[index]
            peaks = superposed_peaks(key, unit_model, factor)
        if peaks is None:
            peaks = simulate_peaks(model, record, reuse=True)
            refuse_failed_run(peaks["status"], peaks["status_message"])
        else:
            superposed.append(model.buildings[0].name)
        runs.append(peaks)
    fallen = [p for p in runs if p["collapse_building"]]
    first = min(fallen, key=lambda p: p["collapse_time"]) if fallen else runs[0]
    merged = {key: first[key] for key in ("status", "status_message", "collapse_time", "collapse_storey",
                                          "collapse_building", "record_scale")}
    merged["collapse_buildings"] = [p["collapse_building"] for p in fallen]
    merged["superposed_buildings"] = superposed
    merged["wall_time"] = float(sum(p["wall_time"] for p in runs))
    for key in ("storey", "storey_building", "contact", "plane"):
        if key in first:
            merged[key] = [label for p in runs for label in p[key]]
    for key in ("peak_drift_ratio", "residual_drift_ratio", "impact_count", "peak_contact_force",
                "peak_plane_drift_ratio"):
        if key in first:
            merged[key] = np.concatenate([np.asarray(p[key]) for p in runs])
    return merged


def run_outcome(part: dict[str, Any] | None) -> str:
    """``completed``, ``collapsed`` or ``failed`` (no result, or an error) of one run's part."""
    if not part or part.get("status") != "ok" or part.get("study") != IDA_PART:
        return "failed"
    return "collapsed" if part.get("outcome") == "collapsed" else "completed"


def building_drifts(part: dict[str, Any], buildings: list[str]) -> np.ndarray:
    storeys = part["storeys"]
    drift = np.array(storeys["peak_drift_ratio"], dtype=float)
    owner = np.array(storeys["building"], dtype=object)
    return np.array([float(np.max(np.abs(drift[owner == b]))) if np.any(owner == b) else np.nan
                     for b in buildings])


def collapse_building_of(part: dict[str, Any]) -> str:
    """The building whose collapse ended a run ("" if none; buildings that ran alone: every one that collapsed,
    comma-separated; a part stored before parts named it: the
    building of its ``collapse_storey``)."""
    if part.get("outcome") != "collapsed":
        return ""
    if "collapse_buildings" in part:   # buildings that ran alone: every one that collapsed
        return ",".join(part["collapse_buildings"])
    if part.get("collapse_building"):
        return str(part["collapse_building"])
    storeys = part["storeys"]
    label = part.get("collapse_storey", "")
    return str(storeys["building"][storeys["storey"].index(label)]) if label in storeys["storey"] else ""


def run_collapses(part: dict[str, Any] | None, plan: IdaPlan) -> tuple[np.ndarray, np.ndarray] | None:
    """Per building of ``plan.buildings``: ``(collapsed, censored)`` in one run, None if the run failed.

    A building collapsed when its collapse ended the run (a storey past its collapse drift ratio, an
    IMK storey at zero strength, or a loss of resistance to P-Delta) or when its largest peak storey
    drift ratio reached its collapse drift in the study (``plan.collapse_drifts``).  It is censored when
    another building's collapse ended the run before it collapsed: its outcome at this intensity is
    unknown (docs/ida.md "Collapse of each building").  In a run of buildings that ran alone
    (``collapse_buildings``, :func:`buildings_alone`) no building is censored.
    """
    if run_outcome(part) == "failed":
        return None
    names = np.array(plan.buildings, dtype=object)
    limits = np.array(plan.collapse_drifts or (plan.collapse_drift,) * names.size, dtype=float)
    drifts = building_drifts(part, plan.buildings)
    if "collapse_buildings" in part:   # each building ran alone: none was stopped by another's collapse
        return np.isin(names, part["collapse_buildings"]) | (drifts >= limits), np.zeros(names.size, bool)
    stopper = collapse_building_of(part)
    collapsed = (names == stopper) | (drifts >= limits)
    stopped = part.get("outcome") == "collapsed"
    if stopped and not stopper:   # the collapse of a building not named: every building, as parts before
        collapsed[:] = True
    return collapsed, stopped & ~collapsed


def collapsed_in(part: dict[str, Any] | None, plan: IdaPlan, building: str | None = None) -> bool | None:
    """Whether *building* collapsed in a run (None: whether any building did, the event a hunt brackets);
    None if the run failed."""
    found = run_collapses(part, plan)
    if found is None:
        return None
    collapsed, _ = found
    if building is None:
        return bool(collapsed.any())
    return bool(collapsed[list(plan.buildings).index(building)])
