"""The IDA's NetCDF layout and the fragility fitted on it."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from pounding.errors import PoundingError
from pounding.studies.common import base_model_text, records_text
from pounding.studies.ida.schedule import SA_DAMPING, IdaPlan, limit_label
from pounding.studies.ida.runs import building_drifts, collapse_building_of, run_collapses, run_outcome
from pounding.units import STANDARD_GRAVITY

__all__ = ["MAX_BETA", "assemble_ida_dataset", "exceeds", "ida_fragility"]

#: Largest dispersion reported; a larger one means the data do not define a fragility.
MAX_BETA = 5.0


def assemble_ida_dataset(plan: IdaPlan, results: dict[str, dict[str, Any]],
                         entries: list[tuple[str, int, float, str]], *, elapsed: float = float("nan"),
                         ran: int = 0):
    """The IDA's NetCDF layout from per-run results.

    *entries* lists every run as (variant, record index, level in g, key).
    With stripes the ``level`` dimension is the stripes; with a hunt it is
    each record's runs sorted by level (padded with NaN), and ``intensity``,
    ``scale_factor`` and ``level_value`` gain the ``variant`` dimension.
    """
    import xarray as xr

    from pounding import __version__

    variants = list(plan.variants)
    nv, nr, nb = len(variants), len(plan.records), len(plan.buildings)
    stripes = plan.hunt is None
    if stripes:
        slots = {(v, r, float(level)): j for v in variants for r in range(nr) for j, level in enumerate(plan.levels)}
        nl = len(plan.levels)
        run_order = None
    else:
        per_chain: dict[tuple[str, int], list[float]] = {}
        order: dict[tuple[str, int, float], int] = {}
        for v, r, level, _ in entries:
            order[(v, r, level)] = len(per_chain.setdefault((v, r), []))
            per_chain[(v, r)].append(level)
        slots = {}
        for (v, r), levels in per_chain.items():
            for j, level in enumerate(sorted(levels)):
                slots[(v, r, level)] = j
        nl = max((len(x) for x in per_chain.values()), default=0)
        run_order = np.full((nv, nr, nl), -1, np.int32)
    parts = {key: results.get(key) for *_, key in entries}
    first = next((p for p in parts.values() if run_outcome(p) != "failed"), None)
    storeys = first["storeys"]["storey"] if first else []
    storey_building = first["storeys"]["building"] if first else []
    # Contacts by label over every run (a plan model's runs without contacts have none: 0 impacts there).
    contacts = list(dict.fromkeys(c for p in parts.values() if run_outcome(p) != "failed"
                                  for c in p["contacts"]["contact"]))
    contact_index = {c: k for k, c in enumerate(contacts)}
    ns, nc = len(storeys), len(contacts)
    planes = (first or {}).get("planes")   # floors in plan: each plane of each storey
    plane_drift = np.full((nv, nr, nl, len(planes["plane"]) if planes else 0), np.nan)

    level_value = np.full((nv, nr, nl), np.nan)
    intensity = np.full((nv, nr, nl), np.nan)
    scale_factor = np.full((nv, nr, nl), np.nan)
    max_drift = np.full((nv, nr, nl, nb), np.nan)
    collapsed = np.zeros((nv, nr, nl, nb), np.int8)
    censored = np.zeros((nv, nr, nl, nb), np.int8)
    superposed = np.zeros((nv, nr, nl, nb), np.int8)
    collapse_building = np.full((nv, nr, nl), "", dtype=object)
    peak_drift = np.full((nv, nr, nl, ns), np.nan)
    residual = np.full((nv, nr, nl, ns), np.nan)
    impacts = np.full((nv, nr, nl, nc), -1, np.int32)
    force = np.full((nv, nr, nl, nc), np.nan)
    status = np.full((nv, nr, nl), "", dtype=object)
    error = np.full((nv, nr, nl), "", dtype=object)
    collapse_time = np.full((nv, nr, nl), np.nan)
    collapse_storey = np.full((nv, nr, nl), "", dtype=object)
    wall = np.full((nv, nr, nl), np.nan)
    for v, r, level, key in entries:
        i, j = variants.index(v), slots[(v, r, level)]
        part = parts[key]
        level_value[i, r, j] = level * STANDARD_GRAVITY
        factor = plan.factor(r, level) if plan.errors[r] is None else float("nan")
        intensity[i, r, j] = plan.intensity(r, level) if plan.errors[r] is None else float("nan")
        scale_factor[i, r, j] = factor
        if run_order is not None:
            run_order[i, r, j] = order[(v, r, level)]
        outcome = run_outcome(part)
        status[i, r, j] = outcome
        if outcome == "failed":
            error[i, r, j] = (part or {}).get("error") or "no result (the worker running it was lost)"
            continue
        wall[i, r, j] = part.get("solver_wall_time", np.nan)
        scale_factor[i, r, j] = part.get("scale_factor", factor)
        max_drift[i, r, j] = building_drifts(part, plan.buildings)
        collapsed[i, r, j], censored[i, r, j] = run_collapses(part, plan)
        superposed[i, r, j] = np.isin(np.array(plan.buildings, dtype=object),
                                      part.get("superposed", {}).get("building", []))
        collapse_building[i, r, j] = collapse_building_of(part)
        peak_drift[i, r, j] = part["storeys"]["peak_drift_ratio"]
        residual[i, r, j] = [np.nan if x is None else x for x in part["storeys"]["residual_drift_ratio"]]
        at = [contact_index[c] for c in part["contacts"]["contact"]]
        if len(at) < nc:
            impacts[i, r, j], force[i, r, j] = 0, 0.0
        impacts[i, r, j, at] = part["contacts"]["impact_count"]
        force[i, r, j, at] = part["contacts"]["peak_contact_force"]
        if planes:
            plane_drift[i, r, j] = part["planes"]["peak_drift_ratio"]
        collapse_time[i, r, j] = np.nan if part.get("collapse_time") is None else part["collapse_time"]
        collapse_storey[i, r, j] = part.get("collapse_storey", "")
    status[status == ""] = "not run"

    def var(dims, data, units, long_name, **extra):
        return (dims, data, {"units": units, "long_name": long_name, **extra})

    run = ("variant", "record", "level")
    if stripes:   # the same for both variants: (record, level)
        im_dims, level_values = ("record", "level"), plan.levels * STANDARD_GRAVITY
        intensity_data, factor_data = intensity[0], scale_factor[0]
    else:
        im_dims, level_values = run, np.arange(nl)
        intensity_data, factor_data = intensity, scale_factor
    data_vars = {
        "intensity": var(im_dims, intensity_data, "m s-2",
                         f"{plan.im.describe()} of the scaled record (the IM value reached)"),
        "scale_factor": var(im_dims, factor_data, "1",
                            "factor applied to the record as stored (catalogue or file), after processing (both "
                            "components of a record pair)"),
        "max_drift_ratio": var(run + ("building",), max_drift, "1",
                               "largest peak storey drift ratio of the building"),
        "peak_drift_ratio": var(run + ("storey",), peak_drift, "1", "peak absolute storey drift ratio (floors in plan: "
                                "the largest of the storey's planes')"),
        "residual_drift_ratio": var(run + ("storey",), residual, "1",
                                    "residual storey drift ratio at the end of the run (signed; NaN if the run "
                                    "does not report it)"),
        "impact_count": var(run + ("contact",), impacts, "1", "number of impacts (-1: run failed)"),
        "peak_contact_force": var(run + ("contact",), force, "N", "peak contact force"),
        "collapsed": var(run + ("building",), collapsed, "1",
                         "1 if the building collapsed in the run: its collapse ended the run, or its max drift "
                         "ratio >= its collapse_drift_ratio"),
        "censored": var(run + ("building",), censored, "1",
                        "1 if another building's collapse ended the run before this one collapsed: its outcome "
                        "at this intensity is unknown (right-censored)"),
        "superposed": var(run + ("building",), superposed, "1",
                          "1 if the building's peaks in the run are its run under the unscaled record, made at "
                          "tolerances 10 times tighter, times the scale factor (a building that responds "
                          "linearly, alone: superposition; no solver run of its own)"),
        "collapse_building": (run, collapse_building, {"long_name": "building whose collapse ended the run "
                                                                     "('' if none; buildings that ran alone, "
                                                                     "without contacts: every one that collapsed, "
                                                                     "comma-separated)"}),
        "collapse_drift_ratio": var(("building",), np.array(plan.collapse_drifts or (plan.collapse_drift,) * nb,
                                                            dtype=float), "1",
                                    "the building's collapse drift ratio in this study",
                                    source="; ".join(plan.collapse_sources)),
        "status": (run, status, {"long_name": "completed, collapsed, failed (or not run)"}),
        "error": (run, error, {"long_name": "error message of a failed run"}),
        "collapse_time": var(run, collapse_time, "s", "time at which the solver stopped the run at collapse"),
        "collapse_storey": (run, collapse_storey, {"long_name": "storey that collapsed (in plan: of the plane past its "
                                                                 "collapse drift ratio; '' if none)"}),
        "solver_wall_time": var(run, wall, "s", "solver wall time of the run"),
        "im_stored": var(("record",), plan.im_stored, "m s-2",
                         f"{plan.im.describe()} of the record as stored, after processing"),
        "normalisation_factor": var(("record",), plan.normalisation, "1",
                                    "FEMA P695 normalisation factor NM (1 with per-record scaling)"),
    }
    if planes:
        data_vars["peak_plane_drift_ratio"] = var(run + ("plane",), plane_drift, "1",
                                                  "peak absolute drift ratio of the plane (a frame or wall line of "
                                                  "the storey; drift / storey height)")
    if not stripes:
        data_vars["level_value"] = var(run, level_value, "m s-2", "the level of each run (the record's own "
                                       "IM with per-record scaling; the set's median with FEMA P695 scaling)")
        data_vars["run_order"] = var(run, run_order, "1", "position of the run in the record's hunt-and-fill "
                                     "sequence (-1: no run)")
    coords = {
        "variant": ("variant", np.array(variants, dtype=object), {"long_name": "with the model's contacts, or "
                                                                  "with the contacts held open"}),
        "record": ("record", np.array(plan.records, dtype=object), {"long_name": "record specification"}),
        "level": ("level", level_values,
                  {"units": "m s-2", "long_name": "intensity level (the set's median IM with FEMA P695 "
                   "scaling, each record's IM otherwise)"} if stripes else
                  {"units": "1", "long_name": "run of a record, in order of level"}),
        "building": ("building", np.array(plan.buildings, dtype=object), {"long_name": "building name"}),
        "storey": ("storey", np.array(storeys, dtype=object), {"long_name": "storey label BUILDING:LEVEL"}),
        "storey_building": ("storey", np.array(storey_building, dtype=object),
                            {"long_name": "building of the storey"}),
        "contact": ("contact", np.array(contacts, dtype=object), {"long_name": "gap element label"}),
        "limit": ("limit", np.array(plan.limits, dtype=float), {"units": "1",
                                                                "long_name": "peak storey drift ratio limit"}),
        **_pair_coords(plan),
    }
    if planes:
        coords["plane"] = ("plane", np.array(planes["plane"], dtype=object),
                           {"long_name": "plane label building:storey:direction@at (a frame or wall line)"})
        coords["plane_building"] = ("plane", np.array(planes["building"], dtype=object),
                                    {"long_name": "building of the plane"})
    under = f"record pairs in both orientations, {records_text(plan.records)}" if plan.pairs else \
        records_text(plan.records)
    ds = xr.Dataset(data_vars, coords=coords, attrs={
        "title": f"pounding IDA of model '{plan.model_name}' under {under}, "
                 f"{plan.im.describe()} {plan.describe_levels()}",
        "model_name": plan.model_name,
        "source": f"pounding {__version__}",
        "study": "ida",
        "history": f"{time.strftime('%Y-%m-%d %H:%M:%S')} pounding ida ({'stripes' if stripes else 'hunt-and-fill'}, "
                   f"{nr} records, {len(entries)} runs)",
        "model_path": plan.model_path,
        "base_model": base_model_text(plan.sweep.base_document),
        "im": plan.im.name,
        "im_building": plan.im.building,
        "im_period": plan.im.period,
        "im_damping": SA_DAMPING,
        "im_description": plan.im.describe(),
        "scaling": plan.scaling,
        "method": "stripes" if stripes else "hunt-and-fill",
        "hunt": "" if stripes else (f"start {plan.hunt.start:g} g, step {plan.hunt.step:g} g + k x "
                                    f"{plan.hunt.increment:g} g, tolerance {plan.hunt.tolerance:g} g, "
                                    f"{plan.hunt.runs} runs per record, ceiling {plan.hunt.ceiling:g} g"),
        "collapse_drift": plan.collapse_drift,
        "mce": float("nan") if plan.mce is None else plan.mce,
        "n_runs": len(entries),
        "n_failed": int(sum(run_outcome(p) == "failed" for p in parts.values())),
        "n_run": ran,
        "elapsed_time": elapsed,
        "Conventions": "CF-1.8",
    })
    fragility = ida_fragility(ds)
    names = ["theta", "beta"]
    limits = [limit_label(x) for x in plan.limits] + ["collapse"]
    arrays = {n: np.full((nv, nb, len(limits)), np.nan) for n in names}
    notes = np.full((nv, nb, len(limits)), "", dtype=object)
    for i, v in enumerate(variants):
        for b, name in enumerate(plan.buildings):
            for k, label in enumerate(limits):
                entry = fragility[v][name][label]
                arrays["theta"][i, b, k] = np.nan if entry["theta"] is None else entry["theta"] * STANDARD_GRAVITY
                arrays["beta"][i, b, k] = np.nan if entry["beta"] is None else entry["beta"]
                notes[i, b, k] = entry.get("note", "")
    ds = ds.assign_coords(fragility_limit=("fragility_limit", np.array(limits, dtype=object),
                                           {"long_name": "drift ratio limit as written, or collapse"}))
    ds["fragility_theta"] = (("variant", "building", "fragility_limit"), arrays["theta"],
                             {"units": "m s-2", "long_name": "lognormal fragility median (theta)"})
    ds["fragility_beta"] = (("variant", "building", "fragility_limit"), arrays["beta"],
                            {"units": "1", "long_name": "lognormal fragility dispersion (beta)"})
    ds["fragility_note"] = (("variant", "building", "fragility_limit"), notes,
                            {"long_name": "why a fragility could not be fitted, or how"})
    if plan.pairs:
        ds.attrs["angle"] = float((plan.documents[0].get("ground_motion") or {}).get("angle", 0.0))
    return ds


def _pair_coords(plan: IdaPlan) -> dict[str, tuple]:
    """The ``record`` coordinates of record pairs (each in one orientation): ``pair``, ``orientation``,
    ``component_x``, ``component_y``; none when each record is one component."""
    if not plan.pairs:
        return {}
    pair, orientation = zip(*(r.rsplit(" ", 1) for r in plan.records))
    angle = float((plan.documents[0].get("ground_motion") or {}).get("angle", 0.0))
    return {
        "pair": ("record", np.array(pair, dtype=object), {"long_name": "record pair (components a and b)"}),
        "orientation": ("record", np.array(orientation, dtype=object),
                        {"long_name": f"ab: component a along the model's angle ({angle:g} deg from +x), b 90 deg "
                                      "further; ba: b along the angle, a 90 deg further"}),
        "component_x": ("record", np.array([p[0] for p in plan.pairs], dtype=object),
                        {"long_name": "the component acting along the model's angle (ground_motion x)"}),
        "component_y": ("record", np.array([p[1] for p in plan.pairs], dtype=object),
                        {"long_name": "the component acting 90 deg further (ground_motion y)"}),
    }


# --------------------------------------------------------------------------- #
# Fragility from the dataset
# --------------------------------------------------------------------------- #


def exceeds(ds, limit: float | None) -> np.ndarray:
    """(variant, record, level, building): 1 exceed, 0 not, NaN failed, not run or censored (another
    building's collapse ended the run before this one reached the limit); limit None = collapse."""
    ok = np.isin(ds.status.values, ("completed", "collapsed"))[..., None]
    collapsed = ds.collapsed.values.astype(bool)
    hit = collapsed if limit is None else (collapsed | (ds.max_drift_ratio.values >= limit))
    hidden = ds.censored.values.astype(bool) & ~hit if "censored" in ds else np.zeros_like(hit)
    return np.where(ok & ~hidden, hit.astype(float), np.nan)


def _crossing(levels: np.ndarray, drift: np.ndarray, hit: np.ndarray, limit: float | None) -> float:
    """The level (g) at which one record's IDA curve first reaches the limit (NaN if never)."""
    good = np.isfinite(hit)
    levels, drift, hit = levels[good], drift[good], hit[good]
    order = np.argsort(levels)
    levels, drift, hit = levels[order], drift[order], hit[order]
    above = np.flatnonzero(hit > 0)
    if above.size == 0:
        return float("nan")
    j = int(above[0])
    low_level = levels[j - 1] if j > 0 else 0.0
    low_drift = drift[j - 1] if j > 0 else 0.0
    if limit is None or not (np.isfinite(drift[j]) and drift[j] >= limit) or drift[j] <= low_drift:
        return float(0.5 * (low_level + levels[j]))
    return float(low_level + (levels[j] - low_level) * (limit - low_drift) / (drift[j] - low_drift))


def _survived(levels: np.ndarray, hit: np.ndarray) -> float:
    """The highest level (g) at which one record was seen not to reach the limit (0 if none): where a
    record that never reached it is right-censored."""
    seen = np.isfinite(levels) & (hit == 0)
    return float(levels[seen].max()) if seen.any() else 0.0


def _undeterminable(reached: int, records: int, censored: int, how: str) -> str:
    return (f"not determinable: {reached} of {records} records reached it, {censored} censored (another "
            f"building collapsed first); {how}")


def _fit_stripes(levels: np.ndarray, hit: np.ndarray, ran: np.ndarray) -> dict[str, Any]:
    """The stripe fit of one building and limit (*hit*: (record, level) of :func:`exceeds`; *ran*: runs
    per stripe that ran, censored ones included)."""
    from pounding.studies.fragility import fit_stripes, median_observed_stripes

    n = np.sum(np.isfinite(hit), axis=0)
    z = np.nansum(hit, axis=0)
    fit = fit_stripes(levels, n, z)
    if not (0 < fit.theta < math.inf and fit.beta < MAX_BETA):
        raise PoundingError(f"the fraction exceeding hardly changes over the stripes (beta "
                            f"{fit.beta:.3g}): widen the range of levels")
    hidden = int(ran.sum() - n.sum())
    if not median_observed_stripes(z, ran):
        raise PoundingError(_undeterminable(int(z.sum()), int(ran.sum()), hidden,
                                            "a stripe fit needs a stripe where at least half the runs (censored "
                                            "ones included) exceeded, and 2 stripes (docs/ida.md)").replace(
                                                "records", "runs"))
    entry = {"theta": fit.theta, "beta": fit.beta, "method": "mle-stripes"}
    if hidden:
        entry["note"] = f"{hidden} censored runs left out of their stripes' counts (maximum likelihood on the rest)"
    return entry


def _fit_hunt(levels: np.ndarray, drift: np.ndarray, hit: np.ndarray, limit: float | None) -> dict[str, Any]:
    """The fit of one building and limit from each record's intensity at it (*levels*, *drift*, *hit*:
    (record, run)); records that never reached it are right-censored where last seen below it."""
    from pounding.studies.fragility import (MIN_DISTINCT_OBSERVATIONS, fit_censored_intensities, fit_intensities,
                                            median_observed)

    ran = np.any(np.isfinite(drift), axis=1)   # records with a run that ran (a failed run has no drift)
    values = np.array([_crossing(levels[r], drift[r], hit[r], limit) for r in range(hit.shape[0])])[ran]
    reached = np.isfinite(values)
    bounds = np.array([_survived(levels[r], hit[r]) for r in range(hit.shape[0])])[ran]
    hidden = int(np.sum(~reached & np.any(np.isnan(hit) & np.isfinite(drift), axis=1)[ran]))
    if not median_observed(int(reached.sum()), int(ran.sum())):
        raise PoundingError(_undeterminable(int(reached.sum()), int(ran.sum()), hidden,
                                            "the median needs at least half the records to reach it (docs/ida.md)"))
    if np.unique(values[reached]).size < MIN_DISTINCT_OBSERVATIONS:
        raise PoundingError(_undeterminable(int(reached.sum()), int(ran.sum()), hidden,
                                            f"beta needs {MIN_DISTINCT_OBSERVATIONS} distinct intensities at it"))
    if reached.all():
        fit = fit_intensities(values)
        return {"theta": fit.theta, "beta": fit.beta, "method": "intensities"}
    keep = reached | (bounds > 0)   # a record censored at 0 carries no information
    fit = fit_censored_intensities(np.where(reached, values, bounds)[keep], ~reached[keep])
    return {"theta": fit.theta, "beta": fit.beta, "method": "mle-censored",
            "note": f"{int((~reached).sum())} of {values.size} records censored ({hidden} by another building's "
                    "collapse, the rest never reached it); maximum likelihood with censoring"}


def ida_fragility(ds) -> dict[str, dict[str, dict[str, dict[str, Any]]]]:
    """Fragility per variant, building and limit (drift limits as written, and ``collapse``); θ in g.

    Each entry: ``theta`` (g), ``beta``, ``method`` and, when no fit was
    possible or records were censored, ``note``.  Stripes: MLE on the counts
    of the observed runs; hunt: from the per-record intensities, with the
    censored records' likelihood when there are any (see the module docstring
    of :mod:`pounding.studies.fragility`).  A fit whose median is not inside
    the data is "not determinable" (theta and beta None).
    """
    stripes = ds.attrs["method"] == "stripes"
    limits = [float(x) for x in ds.limit.values]
    out: dict[str, dict[str, dict[str, dict[str, Any]]]] = {}
    for i, variant in enumerate(ds.variant.values):
        out[str(variant)] = {}
        ran = np.sum(np.isin(ds.status.values[i], ("completed", "collapsed")), axis=0)
        for b, building in enumerate(ds.building.values):
            entries: dict[str, dict[str, Any]] = {}
            for limit in limits + [None]:
                label = "collapse" if limit is None else limit_label(limit)
                hit = exceeds(ds, limit)[i, :, :, b]
                entry: dict[str, Any] = {"theta": None, "beta": None}
                try:
                    if stripes:
                        entry.update(_fit_stripes(ds.level.values / STANDARD_GRAVITY, hit, ran))
                    else:
                        entry.update(_fit_hunt(ds.level_value.values[i] / STANDARD_GRAVITY,
                                               ds.max_drift_ratio.values[i, :, :, b], hit, limit))
                except PoundingError as exc:
                    entry["note"] = str(exc).replace("fragility fit: ", "")
                entries[label] = entry
            out[str(variant)][str(building)] = entries
    return out
