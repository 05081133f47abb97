"""Is the model's gap enough?  The code's separations, the records' needs and the model's own gap (``pounding gap --code``).

One study for every model: per contact (a level pair of a planar row; a contact point of a face
between floors in plan) the model's gap at rest, the code's separation (:mod:`pounding.studies.design`
for floors of one degree of freedom, :mod:`pounding.studies.design_directions` for floors in plan:
the two directions and accidental torsion) and the separation the records need, scaled to the code's
spectrum and run with the contacts open (:func:`pounding.studies.gap.gap_study`).  A planar model is
the one-direction case: its records are single components and its contacts one per level pair; a plan
model's records are pairs and its contacts the points of each face.  Only these data differ.

Per contact and intensity, over the records that ran (a failed record is left out; a collapsed one
needs +inf, more than any gap):

* the mean and maximum (the statistic the code uses: ASCE 7-22 ch. 16 the mean; Eurocode 8
  §4.3.3.4.3(3) the mean with 7 records or more, else the maximum), the median and the 84th
  percentile (:func:`pounding.studies.gap.order_statistic`: "not bounded" where it falls on a
  collapsed record);
* the fraction of records whose need exceeds the model's gap (need > gap).

Per level pair (a planar contact; every point of a face in plan), at the code's design intensity
(the first: the level of the code's separation), the **verdict**:

* enough for the code: the model's gap ≥ the code's same-property separation (at every point);
* enough for the records: the model's gap ≥ the 84th percentile of the records' need (a face: of
  each record's largest excess of need over gap among its points, ≤ 0);
* both: ``enough for the code and the records``; one: ``enough for the code, not the records`` or
  ``enough for the records, not the code``; neither: ``not enough``.  No record ran: the records
  part is "not determined".

and one plain-language answer per pair of buildings (:func:`plain_answers`).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from pounding.errors import PoundingError
from pounding.model.outline import place_label
from pounding.studies.design import (ASCE_RECORDS, EC8_MEAN_RECORDS, SUITE_PERIODS, code_displacements,
                                     code_separations, dof_per_floor, record_set_spectra, simulated_requirement,
                                     suite_scale_factor, suite_warnings)
from pounding.studies.design_directions import (building_designs, building_summary, own_pair, pair_set_spectra,
                                                plan_code_displacements, plan_code_separations, principal_mode)
from pounding.studies.gap import NOT_BOUNDED, bounded_value, order_statistic

__all__ = ["code_separation_rows", "CODE_NAMES", "PERCENTILE", "VERDICTS", "code_check_source", "record_needs", "code_gap_study",
           "level_pairs", "verdict_words", "plain_answers", "code_gap_table", "code_gap_summary", "code_gap_dataset",
           "code_gap_tables", "code_gap_figure", "plot_code_gap", "code_gap_info", "CODE_GAP_KIND"]

#: The codes' names in the answers.
CODE_NAMES = {"asce7-22": "ASCE 7-22", "ec8": "Eurocode 8"}
#: The percentile of the records' need a gap must reach to be enough for the records.
PERCENTILE = 84.0
#: The verdicts per level pair, from the best.
VERDICTS = ("enough for the code and the records", "enough for the code, not the records",
            "enough for the records, not the code", "not enough")
#: The ``kind`` attribute of the archive (:func:`code_gap_dataset`).
CODE_GAP_KIND = "gap-code"


# --------------------------------------------------------------------------- #
# The study
# --------------------------------------------------------------------------- #


def code_separation_rows(model, model_path, code: str, options: dict[str, Any]) -> tuple[list[dict[str, Any]], dict]:
    """The code's separation at each contact of *model* from each building's ``design:`` factors and the code's
    design spectrum (*options*: ``--sds``... as :func:`pounding.studies.design.code_setup`), no record read:
    ``(rows, found)``, each row with ``contact`` (its label: a level pair, or face@point in plan) and
    ``separation`` (:class:`pounding.studies.design.Separation`, m); *found*: the buildings' analyses."""
    if any(dof_per_floor(b) > 1 for b in model.buildings):
        found = plan_code_displacements(model, code, options, building_designs(model, model_path))
        return plan_code_separations(model, code, found), found
    found = code_displacements(model, code, options)
    return code_separations(model, code, found["displacement"]), found


def _planar_source(model, model_path, code: str, options: dict[str, Any], records: Any,
                   duration: float | None) -> dict[str, Any]:
    """Rows, records and the records' spectra of a row of planar buildings (one direction, single records)."""
    from pounding.studies.common import record_values
    from pounding.studies.gap import build_gap_sweep

    model.refuse_building_records("the code check (it runs the model under one record at a time)")
    build_gap_sweep(model_path, records, duration=duration)   # the gap study's own refusals (walls, no contacts...)
    rows, found = code_separation_rows(model, model_path, code, options)
    specs = record_values(records, model)
    first = [float(b.periods[0]) for b in model.buildings]
    periods = np.geomspace(0.2 * min(first), 2.0 * max(first), SUITE_PERIODS)
    read: list = []
    psa, pga = record_set_spectra(model, specs, periods, duration=_simulated_time(model, duration), read=read)
    buildings = {name: {"modes": r.n_modes, "mass_fraction": r.mass_fraction, "periods": r.periods.tolist(),
                        "spectrum": found["spectra"][name].name, "elastic_displacement": r.displacement.tolist(),
                        "design_displacement": np.asarray(found["displacement"][name]).tolist()}
                 for name, r in found["rsa"].items()}
    return {"found": found, "rows": rows, "records": specs,
            "periods": periods, "psa": psa, "pga": pga, "read": [[r] for r in read], "sides": ("left", "right"),
            "spectrum_kind": "spectrum", "buildings": buildings}


def _plan_source(model, model_path, code: str, options: dict[str, Any], records: Any,
                 duration: float | None) -> dict[str, Any]:
    """Rows (contact points), record pairs and their spectra of a model whose floors are in plan."""
    from pounding.studies.common import pair_values

    if not model.faces:
        raise PoundingError(f"{os.fspath(model_path)}: the model has no contacts; list the faces to check in "
                            "'contacts' (their gaps come from the outlines)")
    rows, found = code_separation_rows(model, model_path, code, options)
    pairs = pair_values(records) if records is not None else own_pair(model_path)
    principal = [float(b.periods[principal_mode(b, d)]) for b in model.buildings for d in ("x", "y")]
    periods = np.geomspace(0.2 * min(principal), 2.0 * max(principal), SUITE_PERIODS)
    read: list = []
    psa, pga = pair_set_spectra(model_path, pairs, periods, code, duration=_simulated_time(model, duration),
                                read=read)
    return {"found": found, "rows": rows, "records": pairs,
            "periods": periods, "psa": psa, "pga": pga, "read": read, "sides": ("first", "second"),
            "spectrum_kind": "RotD100 spectrum of the pairs" if code == "asce7-22" else "spectrum of the components",
            "buildings": {b.name: building_summary(b, found, code) for b in model.buildings}}


def _simulated_time(model, duration: float | None) -> float | None:
    """The time the records' spectra are taken over: --duration, else the model's ground_motion.duration, s."""
    return duration if duration is not None else model.ground_motion.duration


def code_check_source(model, model_path, code: str, options: dict[str, Any], records: Any = None,
                      duration: float | None = None) -> dict[str, Any]:
    """What the code check of *model* works on: its contacts with the code's separations (``rows``), its
    ground motions (``records``: single records, or pairs for floors in plan) with their spectra (``psa``,
    ``pga`` in g at ``periods`` s, ``read``), the names of each contact's two sides (``sides``) and each
    building's analysis (``buildings``, ``found``: the code's spectra, intensities, statistic and rule)."""
    plan = any(dof_per_floor(b) > 1 for b in model.buildings)
    return (_plan_source if plan else _planar_source)(model, model_path, code, options, records, duration)


def _archive_labels(ds) -> list[str]:
    """Each contact of a gap archive named as the code check's rows name it (a point in plan: face@place)."""
    if "point_x" in ds.coords:
        return [f"{face}@{place_label((float(x), float(y)))}" for face, x, y in
                zip(ds.point_face.values, ds.point_x.values, ds.point_y.values)]
    return [str(c) for c in ds.contact.values]


def record_needs(ds, rows: list[dict[str, Any]]) -> np.ndarray:
    """(records, rows) the separation each record needs at each row's contact, m, from a gap archive *ds*.

    +inf for a record on which a building collapsed, NaN for one that failed (and everywhere when no
    record ran: the archive then has no contacts).
    """
    out = np.full((ds.sizes["record"], len(rows)), np.nan)
    if ds.sizes.get("contact", 0) == 0:
        return out
    labels = _archive_labels(ds)
    for c, row in enumerate(rows):
        out[:, c] = ds.required_gap.values[:, labels.index(row["contact"])]
    return out


def _run_intensity(model_path, code: str, source: dict[str, Any], intensity, duration: float | None,
                   run_options: dict[str, Any]) -> tuple[dict[str, Any], float]:
    """Scale the records to *intensity*, run them with the contacts open and set each row's requirement there."""
    from pounding.studies.gap import gap_study, record_outcomes, records_ran

    periods = source["periods"]
    factor = suite_scale_factor(source["psa"], intensity.spectrum.sa(periods), pga=source["pga"],
                                pga_target=intensity.pga_target)
    ds = gap_study(model_path, source["records"], scale=factor, duration=duration, **run_options)
    ok = records_ran(ds)   # completed or collapsed (+inf); a failed record is left out
    use_max = code == "ec8" and int(ok.sum()) < EC8_MEAN_RECORDS
    needs = record_needs(ds, source["rows"])
    for c, row in enumerate(source["rows"]):
        found = simulated_requirement(needs[ok, c], row["separation"].same_property, use_max, row["gap"])
        row.setdefault("simulated", {})[intensity.name] = {**found, "needs": needs[:, c].tolist()}
    return {"name": intensity.name, "why": intensity.why, "target": intensity.spectrum.name, "factor": factor,
            "period_range": (float(periods[0]), float(periods[-1])), "spectrum_kind": source["spectrum_kind"],
            "records_ok": int(ok.sum()), "statistic": "max" if use_max else "mean",
            "status": [str(s) for s in ds.status.values], **record_outcomes(ds)}, factor


def code_gap_study(model_path: str | os.PathLike, code: str, spectrum_options: dict[str, Any], records: Any = None,
                   *, duration: float | None = None, **run_options) -> dict[str, Any]:
    """Each contact's gap beside the code's separation and the need of records scaled to the code's spectrum.

    The record set (single records; pairs for floors in plan; default the model's own) is scaled by one
    factor per intensity (:func:`pounding.studies.design.suite_scale_factor` over 0.2 T_min to 2 T_max
    of the buildings' first periods, or principal periods along x and y in plan) and run with the
    contacts open (:func:`pounding.studies.gap.gap_study`; *run_options* go to it).

    Returns
    -------
    dict
        ``code``, ``model``, ``rule``, ``statistic``, ``records``, ``sides``, ``buildings`` (each one's
        analysis), ``intensities`` (factor, period range, clause, per record ``status``),
        ``contacts`` (per contact: ``gap``, the sides' design displacements, ``separation``, and per
        intensity ``simulated``: mean, max, median, p84, exceeding, fraction, per record ``needs``; m),
        ``level_pairs`` (:func:`level_pairs`), ``answers`` (:func:`plain_answers`), ``warnings``, and
        ``base_model``: the model checked, as YAML text (:func:`pounding.studies.common.base_model_text`).
    """
    from pounding.model.model import load_model
    from pounding.studies.common import base_model_text

    model = load_model(model_path)
    source = code_check_source(model, model_path, code, spectrum_options, records, duration)
    intensities, factors = [], []
    for intensity in source["found"]["intensities"]:
        item, factor = _run_intensity(model_path, code, source, intensity, duration, run_options)
        intensities.append(item)
        factors.append(factor)
    result = {"code": code, "model": str(model_path), "rule": source["found"]["rule"],
              "statistic": source["found"]["statistic"], "records": source["records"], "intensities": intensities,
              "contacts": source["rows"], "sides": source["sides"], "buildings": source["buildings"],
              "options": dict(spectrum_options), "duration": duration, "base_model": base_model_text(model),
              "warnings": suite_warnings(model, source["records"], source["read"], factors)}
    result["level_pairs"] = level_pairs(result)
    result["answers"] = plain_answers(result)
    return result


# --------------------------------------------------------------------------- #
# The verdict per level pair, and the answer per pair of buildings
# --------------------------------------------------------------------------- #


def _pair_statistics(rows: list[dict[str, Any]], name: str, ran: np.ndarray) -> dict[str, Any]:
    """A level pair's need at intensity *name* over the records that *ran*: per record the largest need of its
    contacts (median, p84) and the largest excess of need over gap (> 0: the record needs more than the gap)."""
    gaps = np.array([row["gap"] for row in rows])
    needs = np.array([row["simulated"][name]["needs"] for row in rows], dtype=float)[:, ran]   # (points, records)
    if needs.shape[1] == 0:
        return {"median": math.nan, "p84": math.nan, "excess_p84": math.nan, "exceeding": 0, "fraction": math.nan,
                "records": 0}
    excess = np.max(needs - gaps[:, None], axis=0)
    exceeding = int(np.count_nonzero(excess > 0.0))
    return {"median": float(order_statistic(needs.max(axis=0)[:, None], 50.0)[0]),
            "p84": float(order_statistic(needs.max(axis=0)[:, None], PERCENTILE)[0]),
            "excess_p84": float(order_statistic(excess[:, None], PERCENTILE)[0]),
            "exceeding": exceeding, "fraction": exceeding / needs.shape[1], "records": int(needs.shape[1])}


def verdict_words(code_enough: bool, records_enough: bool | None) -> str:
    """The verdict of a level pair (:data:`VERDICTS`; the records not determined where none ran: None)."""
    if records_enough is None:
        return ("enough for the code" if code_enough else "not enough for the code") + "; the records not determined"
    return VERDICTS[[(True, True), (True, False), (False, True), (False, False)].index((code_enough,
                                                                                          records_enough))]


def level_pairs(result: dict[str, Any]) -> list[dict[str, Any]]:
    """Per level pair (a planar contact; a face's points in plan): the gap, the code's separation, the records'
    need per intensity and the verdict at the first intensity (the code's design level), m.

    Returns
    -------
    list of dict
        ``level_pair``, ``buildings``, ``levels``, ``elevation``, ``contacts`` (its rows' labels), ``gap`` (the
        smallest of its points'), ``code`` (the largest same-property separation), ``property_lines``,
        ``simulated`` {intensity: median, p84, excess_p84, exceeding, fraction, records}, ``code_enough``,
        ``records_enough`` (None: no record ran), ``verdict``, ``verdict_intensity``.
    """
    names = [item["name"] for item in result["intensities"]]
    ran = {item["name"]: np.isin(np.array(item["status"], dtype=object), ("ok", "collapsed"))
           for item in result["intensities"]}
    groups: dict[str, list[dict[str, Any]]] = {}
    for row in result["contacts"]:
        groups.setdefault(row["level_pair"], []).append(row)
    out = []
    for label, rows in groups.items():
        simulated = {name: _pair_statistics(rows, name, ran[name]) for name in names}
        code_enough = all(row["gap"] >= row["separation"].same_property for row in rows)
        first = simulated[names[0]] if names else {"records": 0}
        records_enough = None if first["records"] == 0 else bool(first["excess_p84"] <= 0.0)
        out.append({"level_pair": label, "buildings": tuple(rows[0]["buildings"]), "levels": tuple(rows[0]["levels"]),
                    "elevation": max(row["elevation"] for row in rows), "contacts": [row["contact"] for row in rows],
                    "gap": min(row["gap"] for row in rows),
                    "code": max(row["separation"].same_property for row in rows),
                    "property_lines": max(row["separation"].property_lines for row in rows),
                    "simulated": simulated, "code_enough": code_enough, "records_enough": records_enough,
                    "verdict": verdict_words(code_enough, records_enough),
                    "verdict_intensity": names[0] if names else ""})
    return out


def _level_words(pair: dict[str, Any]) -> str:
    """``level 3`` (the same floor on both sides, or a wall), else the pair's label ``A:5-B:4``."""
    first, second = pair["levels"]
    if second == 0 or first == second:
        return f"level {first}"
    return pair["level_pair"]


def _mm(value: float) -> str:
    """Millimetres for the answers: ``57`` (two significant figures below 10 mm: ``0.1``), the words for +inf,
    ``-`` for NaN."""
    if value == math.inf:
        return NOT_BOUNDED
    if not math.isfinite(value):
        return "-"
    return f"{1000 * value:.0f}" if abs(value) >= 0.01 or value == 0.0 else f"{1000 * value:.2g}"


def _listed(places: list[str]) -> str:
    """``level 2``, ``levels 1, 2 and 4`` (levels by number), or the labels as they are."""
    if len(places) > 1 and all(p.startswith("level ") and p[6:].isdigit() for p in places):
        numbers = [p[6:] for p in places]
        return f"levels {', '.join(numbers[:-1])} and {numbers[-1]}"
    return ", ".join(places)


def _answer(pairs: list[dict[str, Any]], code: str) -> str:
    """The plain-language answer of one pair of buildings from its level pairs (:func:`level_pairs`)."""
    name = CODE_NAMES.get(code, code)
    intensity = pairs[0]["verdict_intensity"]

    def demand(pair: dict[str, Any]) -> float:   # how far the gap falls short of the larger of the two
        need = pair["simulated"][intensity]["p84"] if intensity else math.nan
        return max(pair["code"], need if math.isfinite(need) or need == math.inf else -math.inf) - pair["gap"]

    short = [p for p in pairs if p["verdict"] != VERDICTS[0]]
    top = max(short or pairs, key=demand)
    found = top["simulated"].get(intensity, {"p84": math.nan, "exceeding": 0, "records": 0})
    records = (f"the records {_mm(found['p84'])}" + (" mm" if math.isfinite(found["p84"]) else "")
               + f" ({PERCENTILE:.0f}th percentile of {found['records']} at {intensity} level)"
               if found["records"] else "the records not determined (none ran)")
    asks = f"{name} asks {_mm(top['code'])} mm, {records}"
    head = f"{top['buildings'][0]} | {top['buildings'][1]}: your {_mm(top['gap'])} mm"
    if not short:
        return f"{head} is enough for {name} and the records at every level pair; the most demanding, " \
               f"{_level_words(top)}: {asks}"
    verdict = {(True, False): f"is enough for {name} but not for the records",
               (False, True): f"is enough for the records but not for {name}", (False, False): "is not enough",
               (True, None): f"is enough for {name} (the records not determined)",
               (False, None): f"is not enough for {name} (the records not determined)"}[
        (top["code_enough"], top["records_enough"])]
    tail = ""
    if found["records"]:
        tail = f"; {found['exceeding']} of {found['records']} records need more than {_mm(top['gap'])} mm"
    others = [_level_words(p) for p in short if p is not top]
    if others:
        tail += f"; also short at {_listed(others)}"
    return f"{head} {verdict} at {_level_words(top)}: {asks}{tail}"


def plain_answers(result: dict[str, Any]) -> list[str]:
    """One line per pair of buildings (a building and a wall): is the model's gap enough, where it falls
    shortest, what the code asks and what the records need there."""
    by_pair: dict[tuple, list[dict[str, Any]]] = {}
    for pair in result["level_pairs"]:
        by_pair.setdefault(pair["buildings"], []).append(pair)
    return [_answer(pairs, result["code"]) for pairs in by_pair.values()]


# --------------------------------------------------------------------------- #
# Text and JSON
# --------------------------------------------------------------------------- #


def _cell_mm(value: float) -> str:
    """A table's millimetres: three significant figures below 1 mm (a flag never compares two values printed
    alike as 0.0), the words for +inf (a collapsed record's need), ``-`` for NaN."""
    if value == math.inf:
        return NOT_BOUNDED
    if not math.isfinite(value):
        return "-"
    return f"{1000 * value:.1f}" if abs(value) >= 1e-3 or value == 0.0 else f"{1000 * value:.3g}"


def _pair_cell(first: float, second: float) -> str:
    """``a/b`` in mm, or the words once where the first is not bounded (then so is the second)."""
    return NOT_BOUNDED if first == math.inf else f"{_cell_mm(first)}/{_cell_mm(second)}"


def _fraction(exceeding: int, records: int) -> str:
    return f"{exceeding}/{records}" if records else "-"


def _heading_lines(result: dict[str, Any]) -> list[str]:
    """The rule, each building's analysis and each intensity's scaling and outcomes."""
    lines = [f"code {result['code']}: {result['rule']}"]
    for name, b in result["buildings"].items():
        lines.append(f"  {name}: " + (b.get("description") or f"RSA with {b['spectrum']}, {b['modes']} mode(s), "
                                      f"{100 * b['mass_fraction']:.1f} % of the mass, CQC"))
    for item in result["intensities"]:
        low, high = item["period_range"]
        lines.append(f"records at {item['name']} level: x{item['factor']:.3f} on every record (mean "
                     f"{item.get('spectrum_kind', 'spectrum')} >= 90 % of {item['target']} over {low:.3f}-{high:.3f} "
                     f"s) - {item['why']}; {item['records_ok']} record(s), {item['statistic']} used")
        for record, error in item["failed"].items():
            lines.append(f"  record failed at {item['name']} level: {record}: {error}")
        for record, why in item.get("collapsed", {}).items():
            lines.append(f"  record collapsed at {item['name']} level (its need is {NOT_BOUNDED}): {record}: {why}")
    if result["code"] == "asce7-22" and any(i["records_ok"] < ASCE_RECORDS for i in result["intensities"]):
        lines.append(f"  (ASCE 7-22 ch. 16 asks for {ASCE_RECORDS} records; fewer were run)")
    return lines


def _contact_lines(result: dict[str, Any]) -> list[str]:
    """The table of contacts: gap, code, and per intensity the records' mean/max, median/p84 and count over the gap."""
    first, second = result.get("sides", ("left", "right"))
    short = {"left": "L", "right": "R", "first": "1", "second": "2"}
    names = [i["name"] for i in result["intensities"]]
    rows = result["contacts"]
    width = max([12] + [len(row["contact"]) for row in rows])
    head = (f"{'contact':<{width}} {'gap':>6} {'code ' + short[first]:>7} {'code ' + short[second]:>7} "
            f"{'same prop':>9} {'prop lines':>10}  "
            + "  ".join(f"{n + ' mean/max':>18} {'median/p84':>13} {'> gap':>6}" for n in names) + "  flag")
    lines = [f"separations (mm): the model's gap, the code's design displacements of the {first} and {second} "
             f"{'sides at the point' if first == 'first' else 'floors'}, the code's separation on one property and "
             "between property lines, and per intensity the records' need (mean/max, median/84th percentile) and "
             "how many records need more than the gap", head]
    for row in rows:
        sep = row["separation"]
        cells = "  ".join(f"{_pair_cell(s['mean'], s['max']):>18} {_pair_cell(s['median'], s['p84']):>13} "
                          f"{_fraction(s['exceeding'], s['records']):>6}"
                          for s in (row["simulated"][n] for n in names))
        unsafe = [n for n in names if row["simulated"][n]["unconservative"]]
        unknown = [n for n in names if row["simulated"][n]["unconservative"] is None]
        flag = "; ".join(([f"UNCONSERVATIVE at {', '.join(unsafe)}"] if unsafe else [])
                         + ([f"not determined at {', '.join(unknown)} (no record ran)"] if unknown else [])) or "ok"
        lines.append(f"{row['contact']:<{width}} {_cell_mm(row.get('gap', math.nan)):>6} {_cell_mm(row[first]):>7} "
                     f"{_cell_mm(row[second]):>7} {_cell_mm(sep.same_property):>9} {_cell_mm(sep.property_lines):>10}"
                     f"  {cells}  {flag}")
    lines.append("flag: the code's same-property separation is below the records' need (the statistic the code "
                 "uses) at that intensity")
    return lines


def _verdict_lines(result: dict[str, Any]) -> list[str]:
    """The table of level pairs with their verdict, and the answers."""
    pairs = result.get("level_pairs", [])
    if not pairs:
        return []
    intensity = pairs[0]["verdict_intensity"]
    width = max([12] + [len(p["level_pair"]) for p in pairs])
    lines = [f"is the gap enough? per level pair (mm; the records at {intensity} level; enough for the code: gap >= "
             f"same prop; enough for the records: gap >= the {PERCENTILE:.0f}th percentile of the need)",
             f"  {'level pair':<{width}} {'gap':>6} {'same prop':>9} {'median/p84':>13} {'> gap':>6}  verdict"]
    for p in pairs:
        s = p["simulated"].get(intensity, {"median": math.nan, "p84": math.nan, "exceeding": 0, "records": 0})
        lines.append(f"  {p['level_pair']:<{width}} {_cell_mm(p['gap']):>6} {_cell_mm(p['code']):>9} "
                     f"{_pair_cell(s['median'], s['p84']):>13} {_fraction(s['exceeding'], s['records']):>6}  "
                     f"{p['verdict']}")
    return lines + result.get("answers", [])


def code_gap_table(result: dict[str, Any]) -> str:
    """The code check as printed text (millimetres): the analysis, one row per contact (per contact point in
    plan), the verdict per level pair and one answer per pair of buildings (the last lines)."""
    return "\n".join(_heading_lines(result) + _contact_lines(result) + _verdict_lines(result))


def _json_simulated(entry: dict[str, Any], records: list[str]) -> dict[str, Any]:
    out = {k: bounded_value(v) if k in ("mean", "max", "used", "median", "p84", "excess_p84", "fraction") else v
           for k, v in entry.items() if k != "needs"}
    if "needs" in entry:
        out["needs"] = {record: bounded_value(v) for record, v in zip(records, entry["needs"])}
    return out


def code_gap_summary(result: dict[str, Any]) -> dict[str, Any]:
    """The code check as one JSON-ready document (metres); a value that is not bounded (a collapsed record) is
    the words :data:`pounding.studies.gap.NOT_BOUNDED`, one that is not determined (no record ran) null.  The
    model's YAML text (``base_model``) is left to the archive."""
    first, second = result.get("sides", ("left", "right"))
    records = [str(r) for r in result.get("records", [])]
    out = {k: v for k, v in result.items() if k != "base_model"}
    out["contacts"] = [{**{k: v for k, v in row.items() if k not in ("separation", "simulated")},
                        "simulated": {name: _json_simulated(entry, records)
                                      for name, entry in row.get("simulated", {}).items()},
                        "same_property": row["separation"].same_property,
                        f"setback_{first}": row["separation"].setback_left,
                        f"setback_{second}": row["separation"].setback_right,
                        "property_lines": row["separation"].property_lines} for row in result["contacts"]]
    out["level_pairs"] = [{**p, "simulated": {name: _json_simulated(entry, records)
                                              for name, entry in p["simulated"].items()}}
                          for p in result.get("level_pairs", [])]
    return out


# --------------------------------------------------------------------------- #
# The archive, its tables and the figure
# --------------------------------------------------------------------------- #


def _per_intensity(result: dict[str, Any], key: str, where: str = "contacts") -> np.ndarray:
    """(intensity, row) of ``simulated[intensity][key]`` of the contacts (or level pairs), float."""
    rows = result[where]
    return np.array([[float(row["simulated"][i["name"]][key]) for row in rows] for i in result["intensities"]],
                    dtype=float).reshape(len(result["intensities"]), len(rows))


def _unconservative(result: dict[str, Any]) -> np.ndarray:
    """(intensity, contact): 1 where the code's separation is below the statistic it uses, 0 where not, NaN
    where no record ran."""
    return np.array([[math.nan if row["simulated"][i["name"]]["unconservative"] is None
                      else float(row["simulated"][i["name"]]["unconservative"]) for row in result["contacts"]]
                     for i in result["intensities"]], dtype=float).reshape(len(result["intensities"]), -1)


def _archive_attrs(result: dict[str, Any], command: str) -> dict[str, Any]:
    """The archive's global attributes: what was checked, how, and the command that reruns it."""
    from pounding import __version__

    model = result["model"]
    return {"title": f"pounding gap --code {result['code']} of {os.path.basename(model)}",
            "source": f"pounding {__version__}", "kind": CODE_GAP_KIND, "code": result["code"],
            "rule": result["rule"], "statistic": result["statistic"], "model_path": model,
            "base_model": result.get("base_model", ""),
            "model_name": os.path.splitext(os.path.basename(model))[0],
            "spectrum_options": json.dumps(result.get("options", {})), "records": json.dumps(result["records"]),
            "duration": "" if result.get("duration") is None else float(result["duration"]),
            "sides": ",".join(result["sides"]), "verdict_intensity": (result["level_pairs"] or [{}])[0].get(
                "verdict_intensity", ""), "percentile": PERCENTILE,
            "buildings": json.dumps(result["buildings"]), "answers": "\n".join(result.get("answers", [])),
            "warnings": json.dumps(result.get("warnings", [])), "rerun_command": command, "history": command,
            "Conventions": "CF-1.8"}


def _contact_variables(result: dict[str, Any]) -> dict[str, tuple]:
    """Per contact: the gap, the code's displacements and separations; per intensity the records' need, m."""
    rows = result["contacts"]
    first, second = result["sides"]
    unbounded = "; +inf: not bounded (it falls on a record on which a building collapsed)"

    def var(dims, data, units, long_name):
        return (dims, np.asarray(data), {"units": units, "long_name": long_name})

    needs = np.array([[row["simulated"][i["name"]]["needs"] for row in rows] for i in result["intensities"]],
                     dtype=float).reshape(len(result["intensities"]), len(rows), len(result["records"]))
    stats = {key: _per_intensity(result, key) for key in ("mean", "max", "median", "p84", "fraction", "exceeding")}
    return {
        "gap": var(("contact",), [row["gap"] for row in rows], "m", "the model's gap at rest"),
        "elevation": var(("contact",), [row["elevation"] for row in rows], "m", "elevation of the contact (the "
                                                                               "higher of its two floors)"),
        "code_displacement": var(("contact", "side"), [[row[first], row[second]] for row in rows], "m",
                                 "the code's design displacement of each side at the contact along its normal"),
        "code_separation": var(("contact",), [row["separation"].same_property for row in rows], "m",
                               "the code's separation of the two sides on one property"),
        "code_setback": var(("contact", "side"), [[row["separation"].setback_left, row["separation"].setback_right]
                                                  for row in rows], "m",
                            "each side's setback from a property line between them (NaN: the code has none)"),
        "code_property_lines": var(("contact",), [row["separation"].property_lines for row in rows], "m",
                                   "the two setbacks together: the separation of buildings on two properties"),
        "required_gap": var(("intensity", "record", "contact"), needs.transpose(0, 2, 1), "m",
                            "separation the record needs to avoid pounding (contact-free run); +inf for a record on "
                            "which a building collapsed, NaN for a record that failed"),
        "required_gap_mean": var(("intensity", "contact"), stats["mean"], "m",
                                 "mean need over the records that ran" + unbounded),
        "required_gap_max": var(("intensity", "contact"), stats["max"], "m",
                                "largest need over the records that ran" + unbounded),
        "required_gap_median": var(("intensity", "contact"), stats["median"], "m",
                                   "median need over the records that ran" + unbounded),
        "required_gap_p84": var(("intensity", "contact"), stats["p84"], "m",
                                "84th percentile of the need over the records that ran (linear interpolation "
                                "between order statistics)" + unbounded),
        "exceeding_fraction": var(("intensity", "contact"), stats["fraction"], "1",
                                  "fraction of the records that ran whose need exceeds the model's gap (a collapsed "
                                  "record always does)"),
        "records_exceeding": var(("intensity", "contact"), stats["exceeding"].astype(np.int32), "1",
                                 "number of records whose need exceeds the model's gap"),
        "code_unconservative": var(("intensity", "contact"), _unconservative(result), "1",
                                   "1 where the code's separation is below the records' need by the statistic the "
                                   "code uses (mean, or max), 0 where not, NaN where no record ran"),
    }


def _pair_variables(result: dict[str, Any]) -> dict[str, tuple]:
    """Per level pair: its gap, the code's separation, the records' need per intensity and the verdict."""
    pairs = result["level_pairs"]

    def var(dims, data, units, long_name):
        return (dims, np.asarray(data), {"units": units, "long_name": long_name})

    records_enough = [math.nan if p["records_enough"] is None else float(p["records_enough"]) for p in pairs]
    return {
        "pair_gap": var(("level_pair",), [p["gap"] for p in pairs], "m", "the model's gap (the smallest of the "
                                                                         "level pair's contacts)"),
        "pair_elevation": var(("level_pair",), [p["elevation"] for p in pairs], "m", "elevation of the level pair"),
        "pair_code_separation": var(("level_pair",), [p["code"] for p in pairs], "m",
                                    "the code's separation on one property (the largest of its contacts)"),
        "pair_code_property_lines": var(("level_pair",), [p["property_lines"] for p in pairs], "m",
                                        "the code's separation of buildings on two properties"),
        "pair_required_median": var(("intensity", "level_pair"), _per_intensity(result, "median", "level_pairs"),
                                    "m", "median over the records of each record's largest need at the level pair"),
        "pair_required_p84": var(("intensity", "level_pair"), _per_intensity(result, "p84", "level_pairs"), "m",
                                 "84th percentile over the records of each record's largest need at the level pair"),
        "pair_exceeding_fraction": var(("intensity", "level_pair"),
                                       _per_intensity(result, "fraction", "level_pairs"), "1",
                                       "fraction of the records that ran whose need exceeds the gap somewhere on the "
                                       "level pair"),
        "code_enough": var(("level_pair",), [float(p["code_enough"]) for p in pairs], "1",
                           "1 where the gap is at least the code's separation at every contact of the level pair"),
        "records_enough": var(("level_pair",), records_enough, "1",
                              "1 where the gap is at least the 84th percentile of the records' need at the verdict "
                              "intensity, 0 where not, NaN where no record ran"),
        "verdict": (("level_pair",), np.array([p["verdict"] for p in pairs], dtype=object),
                    {"long_name": "enough for the code and the records, enough for the code, not the records, "
                                  "enough for the records, not the code, or not enough"}),
    }


def code_gap_dataset(result: dict[str, Any], command: str = ""):
    """The code check as an xarray Dataset (dims ``intensity``, ``record``, ``contact``, ``side``,
    ``level_pair``; SI units, a ``long_name`` on every variable); *command* reruns it."""
    import xarray as xr

    rows, pairs = result["contacts"], result["level_pairs"]
    status = np.array([item["status"] for item in result["intensities"]], dtype=object).reshape(
        len(result["intensities"]), len(result["records"]))
    coords = {
        "intensity": ("intensity", np.array([i["name"] for i in result["intensities"]], dtype=object),
                      {"long_name": "intensity the records are scaled to (design: the code's separation's level)"}),
        "record": ("record", np.array(result["records"], dtype=object),
                   {"long_name": "record specification (a record pair for floors in plan)"}),
        "contact": ("contact", np.array([row["contact"] for row in rows], dtype=object),
                    {"long_name": "contact: a level pair, or a contact point of a face in plan (@(x,y))"}),
        "side": ("side", np.array(result["sides"], dtype=object), {"long_name": "side of the contact"}),
        "level_pair": ("level_pair", np.array([p["level_pair"] for p in pairs], dtype=object),
                       {"long_name": "the two floors (building:floor) of a level pair"}),
        "contact_level_pair": ("contact", np.array([row["level_pair"] for row in rows], dtype=object),
                               {"long_name": "the level pair of the contact"}),
        "building_left": ("level_pair", np.array([p["buildings"][0] for p in pairs], dtype=object),
                          {"long_name": "first building of the level pair"}),
        "building_right": ("level_pair", np.array([p["buildings"][1] for p in pairs], dtype=object),
                           {"long_name": "second building of the level pair ('wall' for a fixed wall)"}),
    }
    variables = {
        **_contact_variables(result), **_pair_variables(result),
        "scale_factor": (("intensity",), np.array([i["factor"] for i in result["intensities"]], dtype=float),
                         {"units": "1", "long_name": "factor on every record at the intensity"}),
        "records_ran": (("intensity",), np.array([i["records_ok"] for i in result["intensities"]], dtype=np.int32),
                        {"units": "1", "long_name": "records that ran (completed or collapsed)"}),
        "status": (("intensity", "record"), status,
                   {"long_name": "ok, collapsed (its need is unbounded) or error (left out)"}),
    }
    return xr.Dataset(variables, coords=coords, attrs=_archive_attrs(result, command))


def code_gap_tables(ds) -> dict:
    """Tables of a code-check archive (metres): ``contacts`` (per intensity and contact: the gap, the code's
    separations, the records' need and how many exceed the gap), ``level_pairs`` (the verdict),
    ``code`` (each side's design displacement and setback) and ``records`` (each record's need).  A value
    that is not bounded (+inf) is written :data:`pounding.studies.gap.NOT_BOUNDED`."""
    from pounding.results.tables import long_table
    from pounding.studies.gap import not_bounded_words

    tables = {
        "contacts": long_table(ds, ["required_gap_mean", "required_gap_max", "required_gap_median",
                                    "required_gap_p84", "records_exceeding", "exceeding_fraction",
                                    "code_unconservative"],
                               extra=["contact_level_pair", "elevation", "gap", "code_separation",
                                      "code_property_lines", "scale_factor"]),
        "level_pairs": long_table(ds, ["pair_gap", "pair_code_separation", "pair_code_property_lines",
                                       "code_enough", "records_enough", "verdict"],
                                  extra=["building_left", "building_right", "pair_elevation"]),
        "level_pair_needs": long_table(ds, ["pair_required_median", "pair_required_p84", "pair_exceeding_fraction"],
                                       extra=["pair_gap"]),
        "code": long_table(ds, ["code_displacement", "code_setback"]),
        "records": long_table(ds, ["required_gap"], extra=["status", "gap"]),
    }
    return {name: not_bounded_words(frame) for name, frame in tables.items()}


def code_gap_figure(ds):
    """The gap profile of a code-check archive: per pair of buildings, elevation against separation with the
    model's gap, the code's separations and the records' need (median, 84th percentile) per intensity."""
    from pounding.results.plots import finish_profile_panel, pyplot, suptitle

    plt = pyplot()
    buildings = list(dict.fromkeys(zip(ds.building_left.values, ds.building_right.values)))
    fig, axes = plt.subplots(1, len(buildings), figsize=(5.4 * len(buildings), 4.8), squeeze=False)
    for ax, (left, right) in zip(axes[0], buildings):
        sel = np.flatnonzero((ds.building_left.values == left) & (ds.building_right.values == right))
        sel = sel[np.argsort(ds.pair_elevation.values[sel], kind="stable")]
        z = ds.pair_elevation.values[sel]
        for k, intensity in enumerate(ds.intensity.values):
            tone = "k" if k == 0 else "0.55"
            for name, style, words in (("median", "-", "median"), ("p84", "--", "84th percentile")):
                values = 1000 * ds[f"pair_required_{name}"].values[k, sel]
                shown = np.where(np.isfinite(values), values, np.nan)   # not bounded: not drawn
                ax.plot(shown, z, color=tone, ls=style, lw=2.0 if name == "p84" else 1.2, marker="o", ms=3,
                        label=f"records at {intensity} level, {words}")
        ax.plot(1000 * ds.pair_code_separation.values[sel], z, color="C0", lw=1.8, marker="s", ms=4,
                label=f"{CODE_NAMES.get(ds.attrs.get('code'), ds.attrs.get('code'))}, one property")
        lines = 1000 * ds.pair_code_property_lines.values[sel]
        if np.isfinite(lines).any():
            ax.plot(lines, z, color="C0", lw=1.0, ls=":", marker="s", ms=3, label=f"{CODE_NAMES.get(ds.attrs.get('code'), ds.attrs.get('code'))}, property lines")
        ax.plot(1000 * ds.pair_gap.values[sel], z, color="C3", lw=2.4, label="the model's gap")
        short = sel[ds.verdict.values[sel] != VERDICTS[0]]
        if short.size:
            ax.plot(1000 * ds.pair_gap.values[short], ds.pair_elevation.values[short], "x", color="C3", ms=9,
                    mew=2, label="gap not enough")
        finish_profile_panel(ax, "separation (mm)", "elevation (m)", f"{left} | {right}", title_size=9)
    factors = ", ".join(f"{i} x{f:.3f}" for i, f in zip(ds.intensity.values, ds.scale_factor.values))
    names = [str(r) for r in ds.record.values]
    shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    suptitle(fig, f"is the gap enough? {ds.attrs.get('title', '')}; {len(names)} record(s) ({shown}) scaled to "
                  f"the code's spectrum ({factors})", 9)
    return fig


def plot_code_gap(ds, directory: str | os.PathLike) -> list[Path]:
    """``gap_profile.png`` in *directory*: :func:`code_gap_figure` laid out with its titles within the canvas."""
    from pounding.results.plots import plot_directory, save_figure

    out = plot_directory(directory)
    path = out / "gap_profile.png"
    save_figure(code_gap_figure(ds), path)
    return [path]


def code_gap_info(ds) -> str:
    """What ``pounding info`` prints of a code-check archive: the verdict per level pair and the answers."""
    lines = [f"code {ds.attrs.get('code', '')}: {ds.attrs.get('rule', '')}",
             f"verdict per level pair (records at {ds.attrs.get('verdict_intensity', '')} level; mm): gap, the code's "
             "separation on one property, the records' 84th percentile, verdict"]
    for p, label in enumerate(ds.level_pair.values):
        lines.append(f"  {label}: {_cell_mm(float(ds.pair_gap.values[p]))}, "
                     f"{_cell_mm(float(ds.pair_code_separation.values[p]))}, "
                     f"{_cell_mm(float(ds.pair_required_p84.values[0, p])) if ds.sizes['intensity'] else '-'}, "
                     f"{ds.verdict.values[p]}")
    return "\n".join(lines + [f"  {line}" for line in str(ds.attrs.get("answers", "")).splitlines()])
