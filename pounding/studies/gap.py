"""How far apart must two buildings be? The separation that avoids pounding, by simulation and by the code rules.

For every contact (level pair) of a model and every record, the model is run
with its contacts held open, and the **required separation** is the largest
relative approach of the two floors::

    required = max(0, max over t of (u_left(t) − u_right(t)))

(``u_left`` the floor of the left building, ``u_right`` that of its right
neighbour, relative to the ground, positive to the right.)  A gap larger than
this never closes under that record; a smaller one closes at least once — the
motion of a model is the same with or without contacts until the first
closure.

Beside it, the **combination rules** of the codes applied to the same run's
peak floor displacements u₁ = max |u_left|, u₂ = max |u_right| (a registry
keyed by name, like the ξ formulas; each entry cites its source):

``abs``   u₁ + u₂ (the absolute sum; never unconservative);
``srss``  √(u₁² + u₂²) (ASCE 7-22 §12.12.2, δ_MT — §12.12.3 in ASCE 7-16; Eurocode 8 §4.4.2.7);
``ddc``   √(u₁² + u₂² − 2ρ u₁ u₂), the double difference combination
          (Jeng, Kasai & Maison 1992; Penzien 1997), with ρ the correlation of
          the two responses taken as the CQC coefficient of the buildings'
          first modes (:func:`cqc_correlation`, Der Kiureghian 1981).

Over a record set: the median, 84th percentile and maximum of each, the
fraction of records for which each rule is unconservative (rule < required),
and the verdict against the model's own gap ("enough for N of M records").

The exact maximum of u_left − u_right is taken on the cubic Hermite
interpolant of the stored samples (displacement difference and its rate at
every ``output_dt``), not on the samples alone: with the default
``output_dt = 0.01 s`` the interpolation error is below 1e-6 m for the
shipped models (O(Δt⁴ ω⁴ u)), far below the 1 mm a separation is quoted to.
See ``docs/gap.md``.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from pounding.errors import PoundingError
from pounding.registry import add_unique

__all__ = ["SeparationRule", "RULES", "register_rule", "cqc_correlation", "max_hermite", "over_records", "gap_attrs",
           "required_separations", "run_gap_scenario", "build_gap_sweep", "gap_study", "assemble_gap_dataset",
           "gap_summary", "gap_table", "gap_tables", "plot_gap"]

#: Version of this study's part layout (stored in each part, checked when parts are reused).
GAP_PART = "gap-1"


# --------------------------------------------------------------------------- #
# The combination rules: a registry, one entry per published rule
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class SeparationRule:
    """A code rule for the separation of two adjacent floors.

    Attributes
    ----------
    key : str
        Registry key (``abs``, ``srss``, ``ddc``).
    title : str
        One-line description.
    reference : str
        The source of the rule.
    function : callable
        ``function(u_left, u_right, rho) -> separation`` (m), with the peak
        floor displacements u (m, ≥ 0) and the correlation ρ of the two responses.
    """

    key: str
    title: str
    reference: str
    function: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


RULES: dict[str, SeparationRule] = {}


def register_rule(rule: SeparationRule) -> SeparationRule:
    """Add *rule* to :data:`RULES`; a key registered twice is refused."""
    add_unique(RULES, rule.key, rule, "separation rule")
    return rule


register_rule(SeparationRule(
    "abs", "absolute sum u1 + u2", "the upper bound of any combination (no code needed)",
    lambda u1, u2, rho: u1 + u2))
register_rule(SeparationRule(
    "srss", "square root of the sum of squares sqrt(u1^2 + u2^2)",
    "ASCE 7-22 §12.12.2 (delta_MT; §12.12.3 in ASCE 7-16); Eurocode 8 (EN 1998-1) §4.4.2.7",
    lambda u1, u2, rho: np.hypot(u1, u2)))
register_rule(SeparationRule(
    "ddc", "double difference combination sqrt(u1^2 + u2^2 - 2 rho u1 u2)",
    "Jeng, Kasai & Maison, Earthquake Spectra 8 (1992) 201-223; Penzien, EESD 26 (1997) 849-858; "
    "rho: CQC coefficient of the first modes, Der Kiureghian, EESD 9 (1981) 419-435",
    lambda u1, u2, rho: np.sqrt(np.maximum(u1 * u1 + u2 * u2 - 2.0 * rho * u1 * u2, 0.0))))


def cqc_correlation(period_a: float, period_b: float, damping_a: float, damping_b: float) -> float:
    """Correlation of two oscillators' responses to white noise: the CQC coefficient (Der Kiureghian 1981).

    With r = T_a / T_b = ω_b / ω_a::

        ρ = 8 √(ζa ζb) (ζa + r ζb) r^{3/2}
            / [(1 − r²)² + 4 ζa ζb r (1 + r²) + 4 (ζa² + ζb²) r²]

    ρ = 1 for identical oscillators, and falls towards 0 as the periods part.

    Parameters
    ----------
    period_a, period_b : float
        Natural periods, s (> 0).
    damping_a, damping_b : float
        Damping ratios (> 0).

    Returns
    -------
    float
        ρ in (0, 1].
    """
    r = period_a / period_b
    za, zb = damping_a, damping_b
    numerator = 8.0 * math.sqrt(za * zb) * (za + r * zb) * r ** 1.5
    denominator = (1.0 - r * r) ** 2 + 4.0 * za * zb * r * (1.0 + r * r) + 4.0 * (za * za + zb * zb) * r * r
    return numerator / denominator


# --------------------------------------------------------------------------- #
# One record: the contact-free run and its required separations
# --------------------------------------------------------------------------- #


def max_hermite(time: np.ndarray, value: np.ndarray, rate: np.ndarray) -> float:
    """Largest value of the piecewise cubic Hermite interpolant through samples of a function and its rate.

    Parameters
    ----------
    time : (n,) array
        Sample times, s, increasing.
    value, rate : (n,) array
        The function (m) and its time derivative (m/s) at *time*.

    Returns
    -------
    float
        max over the whole span of the interpolant (≥ the largest sample).
    """
    best = float(np.max(value))
    h = np.diff(time)
    y0, y1 = value[:-1], value[1:]
    m0, m1 = rate[:-1] * h, rate[1:] * h
    # y(s) = h00 y0 + h10 m0 + h01 y1 + h11 m1, s in [0, 1]; y'(s) = a s² + b s + c
    a = 6.0 * y0 + 3.0 * m0 - 6.0 * y1 + 3.0 * m1
    b = -6.0 * y0 - 4.0 * m0 + 6.0 * y1 - 2.0 * m1
    c = m0
    # Only intervals whose ends bracket a maximum can hold an interior one above both ends.
    candidates = np.flatnonzero((m0 > 0.0) | (m1 < 0.0))
    for k in candidates:
        roots = np.roots([a[k], b[k], c[k]]) if a[k] != 0.0 or b[k] != 0.0 else np.empty(0)
        for s in roots:
            if abs(s.imag) > 1e-12 or not 0.0 < s.real < 1.0:
                continue
            s = s.real
            s2, s3 = s * s, s * s * s
            y = ((2 * s3 - 3 * s2 + 1) * y0[k] + (s3 - 2 * s2 + s) * m0[k]
                 + (-2 * s3 + 3 * s2) * y1[k] + (s3 - s2) * m1[k])
            best = max(best, float(y))
    return best


def required_separations(ds) -> dict[str, np.ndarray]:
    """Required separation and peak floor displacements per contact of a contact-free run.

    Parameters
    ----------
    ds : xarray.Dataset
        Results of :func:`pounding.simulation.simulate` on a model with its contacts held open
        (:meth:`pounding.model.model.Model.with_contacts_open`).

    Returns
    -------
    dict
        ``required`` (m, ≥ 0), ``peak_left``, ``peak_right`` (m): arrays along ``ds.contact``.
    """
    floors = {str(f): i for i, f in enumerate(ds.floor.values)}
    u = ds.displacement.values
    v = ds.velocity.values
    t = ds.time.values
    peak = ds.peak_displacement.values
    required, peak_left, peak_right = [], [], []
    for bl, ll, br, lr in zip(ds.building_left.values, ds.level_left.values, ds.building_right.values,
                              ds.level_right.values):
        i, j = floors[f"{bl}:{int(ll)}"], floors[f"{br}:{int(lr)}"]
        approach = max_hermite(t, u[:, i] - u[:, j], v[:, i] - v[:, j])
        required.append(max(0.0, approach))
        peak_left.append(float(peak[i]))
        peak_right.append(float(peak[j]))
    return {"required": np.array(required), "peak_left": np.array(peak_left), "peak_right": np.array(peak_right)}


def _first_mode(building) -> tuple[float, float]:
    return float(building.periods[0]), float(building.modal_damping_ratios[0])


def run_gap_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """One record of a gap study, on a worker: the contact-free run and its separations (plain data).

    Never raises for a problem of the scenario: the result then has
    ``status = "error"`` and the message.
    """
    from pounding.model.model import model_from_text
    from pounding.results.checks import run_warnings
    from pounding.results.dataset import record_pga
    from pounding.simulation import simulate
    from pounding.studies.engine.keys import PARTS_FORMAT
    from pounding.studies.engine.tasks import one_line

    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "study": GAP_PART,
                              "format": PARTS_FORMAT}
    try:
        model = model_from_text(task["document"], name=task.get("name", "model"), base_dir=task.get("base_dir"))
        ds = simulate(model.with_contacts_open())
        if ds.attrs.get("status", "completed") != "completed":
            # A building that collapsed or lost its resistance stops the run: the peaks of a truncated
            # history are no separation (they would understate it), so the record is an error.
            raise PoundingError(f"{ds.attrs.get('status_message', ds.attrs['status'])}; no separation is derived "
                                "from a run that did not reach the record's end (lower --scale, or check the "
                                "model's strength)")
        found = required_separations(ds)
        names = [b.name for b in model.buildings]
        modes = {b.name: _first_mode(b) for b in model.buildings}
        result.update({
            "status": "ok",
            "contact": [str(c) for c in ds.contact.values],
            "building_left": [str(x) for x in ds.building_left.values],
            "building_right": [str(x) for x in ds.building_right.values],
            "level_left": [int(x) for x in ds.level_left.values],
            "level_right": [int(x) for x in ds.level_right.values],
            "gap": [float(g.gap) for g in model.gaps],
            "elevation_left": [float(model.buildings[g.left].elevation[g.level_left - 1]) for g in model.gaps],
            "elevation_right": [float(model.buildings[g.right].elevation[g.level_right - 1]) for g in model.gaps],
            "period_left": [modes[names[g.left]][0] for g in model.gaps],
            "period_right": [modes[names[g.right]][0] for g in model.gaps],
            "damping_left": [modes[names[g.left]][1] for g in model.gaps],
            "damping_right": [modes[names[g.right]][1] for g in model.gaps],
            "required": found["required"].tolist(),
            "peak_left": found["peak_left"].tolist(),
            "peak_right": found["peak_right"].tolist(),
            "scale_factor": float(ds.attrs.get("record_scale", 1.0)),
            "intensity": record_pga(ds)[1],
            "warnings": run_warnings(ds, gaps=[g.gap for g in model.gaps]),
            "solver_wall_time": float(ds.attrs["wall_time"]),
        })
    except Exception as exc:  # noqa: BLE001 - a failing record is a result, not a crash
        result["error"] = f"{task.get('where', 'record')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


# --------------------------------------------------------------------------- #
# A record set on the sweep engine
# --------------------------------------------------------------------------- #


def build_gap_sweep(model: str | os.PathLike, records: str | list[str] | None = None, *,
                    scale: Any = None, duration: float | None = None):
    """The sweep behind ``pounding gap``: one scenario per record.

    Parameters
    ----------
    model : path-like
        YAML model with at least one contact.
    records : str or list of str, optional
        A set (``fema-p695:farfield``) or a comma-separated list; default: the model's record.
    scale : float or mapping, optional
        ``ground_motion.scale`` for every record (a factor, or ``{pga: 0.4g}``...).
    duration : float, optional
        Simulated time, s.
    """
    from pounding.model.model import load_model
    from pounding.studies.common import check_duration, record_values, study_sweep

    base = load_model(model)  # the model's own errors, with its file name
    base.refuse_building_records("the gap study (it runs the model under one record at a time)")
    names = [b.name for b in base.buildings]
    for g in base.gaps:
        if g.has_wall or g.has_column_point:
            what = "a fixed wall" if g.has_wall else "a point of a column between floors"
            raise PoundingError(f"{os.fspath(model)}: contacts[{g.contact}] ({g.label(names)}) joins {what}; the gap "
                                "study's separation rules compare the floors of two buildings: keep only "
                                "floor-to-floor level pairs between buildings in the model you study")
    if not base.gaps:
        raise PoundingError(f"{os.fspath(model)}: the model has no contacts; list the level pairs to check in "
                            "'contacts' (gap: 0 is fine: only the levels and buildings are used)")
    path = os.path.abspath(os.fspath(model))
    settings: dict[str, Any] = {"name": f"{base.name} (gap study)"}
    if scale is not None:
        settings["scale"] = scale
    if check_duration(duration) is not None:
        settings["ground_motion.duration"] = float(duration)
    document: dict[str, Any] = {"name": f"gap-{Path(path).stem}", "model": path, "set": settings,
                                "axes": {"records": record_values(records, base)}}
    return study_sweep(document, f"<gap {os.fspath(model)}>")


def over_records(values: np.ndarray, ok: np.ndarray) -> dict[str, np.ndarray]:
    """Median, 84th percentile (linear interpolation) and maximum over the records of the *ok* ones.

    Parameters
    ----------
    values : ndarray
        Per record along axis −2 (``record`` × contact or point, or ``rule`` × ``record`` × ...), in m.
    ok : ndarray of bool
        Which records ran.

    Returns
    -------
    dict
        ``median``, ``p84`` and ``max``: *values* without the record axis (nan where no record ran), in m.
    """
    good = values[..., ok, :]
    if good.shape[-2] == 0:
        nan = np.full(good.shape[:-2] + good.shape[-1:], np.nan)
        return {"median": nan, "p84": nan, "max": nan}
    return {"median": np.median(good, axis=-2), "p84": np.percentile(good, 84.0, axis=-2), "max": good.max(axis=-2)}


def gap_attrs(sweep, title: str, ok: np.ndarray, *, ran: int, elapsed: float, kind: str | None = None) -> dict:
    """The global attributes of a gap study's dataset, planar and plan.

    Parameters
    ----------
    sweep : Sweep or PlanSweep
        The study's sweep (its heading, model name and path).
    title : str
        The title's opening, followed by ``of`` and the sweep's heading.
    ok : ndarray of bool
        Which records ran (``n_records``, ``n_failed``).
    ran : int
        Records run by this call.
    elapsed : float
        Wall time of this call, s.
    kind : str, optional
        The dataset's ``kind`` attribute (a plan study's ``plan_gap``), after ``study``.
    """
    from pounding import __version__
    from pounding.studies.common import sweep_heading

    attrs: dict[str, Any] = {"title": f"{title} of {sweep_heading(sweep)}", "model_name": sweep.model_name,
                             "source": f"pounding {__version__}", "study": "gap"}
    if kind is not None:
        attrs["kind"] = kind
    attrs.update({"model_path": sweep.model_path or "",
                  "rules": "; ".join(f"{r.key}: {r.title} ({r.reference})" for r in RULES.values()),
                  "n_records": len(ok), "n_failed": int((~ok).sum()), "n_run": ran, "elapsed_time": elapsed,
                  "Conventions": "CF-1.8"})
    return attrs


def assemble_gap_dataset(sweep, results: dict[str, dict[str, Any]], *, elapsed: float = float("nan"),
                         ran: int = 0):
    """The gap study's NetCDF layout (dims ``record`` × ``contact``, and ``rule``) from per-record results."""
    import xarray as xr

    from pounding.studies.common import study_parts
    from pounding.results.checks import study_warnings
    from pounding.results.dataset import PGA_LONG_NAME

    scenarios = sweep.scenarios()
    parts = study_parts(scenarios, results, GAP_PART)
    records = [str(s.coords["record"]) for s in scenarios]
    first = next((p for p in parts if p.get("status") == "ok"), None)
    contacts = first["contact"] if first else []
    nr, nc = len(records), len(contacts)
    required = np.full((nr, nc), np.nan)
    peak_left = np.full((nr, nc), np.nan)
    peak_right = np.full((nr, nc), np.nan)
    scale_factor = np.full(nr, np.nan)
    intensity = np.full(nr, np.nan)
    status = np.array([p.get("status", "error") for p in parts], dtype=object)
    error = np.array([p.get("error", "") or "" for p in parts], dtype=object)
    for r, part in enumerate(parts):
        if part.get("status") != "ok":
            continue
        required[r] = part["required"]
        peak_left[r] = part["peak_left"]
        peak_right[r] = part["peak_right"]
        scale_factor[r] = part.get("scale_factor", np.nan)
        intensity[r] = part.get("intensity", np.nan)

    def info(name: str, dtype=float):
        return np.array(first[name] if first else [], dtype=dtype)

    rho = np.array([cqc_correlation(ta, tb, za, zb) for ta, tb, za, zb in
                    zip(info("period_left"), info("period_right"), info("damping_left"), info("damping_right"))])
    rules = list(RULES)
    separation = np.stack([RULES[k].function(peak_left, peak_right, rho[None, :]) for k in rules]) \
        if nc else np.zeros((len(rules), nr, 0))
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = separation / required[None, :, :]
    ok = status == "ok"
    gap = info("gap")

    req = over_records(required, ok)
    sep = over_records(separation, ok)
    unconservative = (separation[:, ok] < required[None, ok]).mean(axis=1) if ok.any() \
        else np.full((len(rules), nc), np.nan)
    enough = (gap[None, :] >= required[ok]).sum(axis=0).astype(np.int32) if nc else np.zeros(0, np.int32)

    def var(dims, data, units, long_name, **extra):
        return (dims, data, {"units": units, "long_name": long_name, **extra})

    ds = xr.Dataset(
        {
            "required_gap": var(("record", "contact"), required, "m",
                                "separation needed to avoid pounding: max over t of u_left - u_right, floored at 0"),
            "peak_displacement_left": var(("record", "contact"), peak_left, "m",
                                          "peak absolute displacement of the left floor (contact-free run)"),
            "peak_displacement_right": var(("record", "contact"), peak_right, "m",
                                           "peak absolute displacement of the right floor (contact-free run)"),
            "rule_gap": var(("rule", "record", "contact"), separation, "m", "separation by the combination rule"),
            "rule_ratio": var(("rule", "record", "contact"), ratio, "1",
                              "rule separation / required separation (< 1: unconservative)"),
            "required_gap_median": var(("contact",), req["median"], "m", "median required separation over records"),
            "required_gap_p84": var(("contact",), req["p84"], "m",
                                    "84th percentile of the required separation over records (linear interpolation)"),
            "required_gap_max": var(("contact",), req["max"], "m", "largest required separation over records"),
            "rule_gap_median": var(("rule", "contact"), sep["median"], "m", "median rule separation over records"),
            "rule_gap_p84": var(("rule", "contact"), sep["p84"], "m", "84th percentile of the rule separation"),
            "rule_gap_max": var(("rule", "contact"), sep["max"], "m", "largest rule separation over records"),
            "unconservative_fraction": var(("rule", "contact"), unconservative, "1",
                                           "fraction of records for which the rule is below the required separation"),
            "records_enough": var(("contact",), enough, "1",
                                  "number of records for which the model's gap is at least the required separation"),
            "correlation": var(("contact",), rho, "1",
                               "CQC correlation of the two buildings' first modes (Der Kiureghian 1981)"),
            "scale_factor": var(("record",), scale_factor, "1", "factor applied to the record"),
            "intensity": var(("record",), intensity, "m s-2", PGA_LONG_NAME),
            "status": (("record",), status, {"long_name": "ok, or error (see variable error)"}),
            "error": (("record",), error, {"long_name": "error message of a failed record"}),
        },
        coords={
            "record": ("record", np.array(records, dtype=object), {"long_name": "record specification"}),
            "contact": ("contact", np.array(contacts, dtype=object), {"long_name": "gap element label"}),
            "rule": ("rule", np.array(rules, dtype=object), {"long_name": "separation rule"}),
            "gap": ("contact", gap, {"units": "m", "long_name": "the model's gap at rest"}),
            "building_left": ("contact", info("building_left", object), {"long_name": "left building"}),
            "building_right": ("contact", info("building_right", object), {"long_name": "right building"}),
            "level_left": ("contact", info("level_left", np.int32), {"units": "1", "long_name": "left floor"}),
            "level_right": ("contact", info("level_right", np.int32), {"units": "1", "long_name": "right floor"}),
            "elevation_left": ("contact", info("elevation_left"), {"units": "m", "long_name": "left floor elevation"}),
            "elevation_right": ("contact", info("elevation_right"),
                                {"units": "m", "long_name": "right floor elevation"}),
            "period_left": ("contact", info("period_left"), {"units": "s", "long_name": "left building T1"}),
            "period_right": ("contact", info("period_right"), {"units": "s", "long_name": "right building T1"}),
            "damping_left": ("contact", info("damping_left"), {"units": "1", "long_name": "left building zeta1"}),
            "damping_right": ("contact", info("damping_right"), {"units": "1", "long_name": "right building zeta1"}),
        },
        attrs=gap_attrs(sweep, "pounding gap study", ok, ran=ran, elapsed=elapsed),
    )
    warnings = study_warnings(p.get("warnings") for p in parts if p.get("status") == "ok")
    if warnings:   # each kind once for the study (pounding.results.checks)
        ds.attrs["warnings"] = json.dumps(warnings)
    return ds


def gap_study(model: str | os.PathLike, records: str | list[str] | None = None, *, scale: Any = None,
              duration: float | None = None, output: str | os.PathLike | None = None, **run_options):
    """Run the gap study of *model* over *records*; returns its dataset (see :func:`assemble_gap_dataset`).

    *run_options* go to :func:`pounding.studies.sweep.execution.run_sweep` and the study engine
    (workers, scheduler, client, progress, overwrite...).
    """
    from pounding.studies.sweep.execution import plan_line, run_sweep

    sweep = build_gap_sweep(model, records, scale=scale, duration=duration)
    run_options.setdefault("plan", plan_line(sweep, "gap"))
    return run_sweep(sweep, output, runner=run_gap_scenario, assemble=assemble_gap_dataset, **run_options)


# --------------------------------------------------------------------------- #
# Summary, table and plot
# --------------------------------------------------------------------------- #


def gap_summary(ds, model: str = "") -> dict[str, Any]:
    """The study as one JSON-ready document (SI units, metres)."""
    from pounding.studies.common import finite_or_none

    ok = ds.status.values == "ok"
    records = [str(r) for r in ds.record.values]
    out: dict[str, Any] = {"model": model or ds.attrs.get("model_name", ds.attrs.get("title", "")), "records": records, "contacts": {}}
    for c, label in enumerate(ds.contact.values):
        def shape(values: np.ndarray, median: Any, p84: Any, largest: Any) -> dict[str, Any]:
            return {"per_record": {rec: finite_or_none(v) for rec, v, good in zip(records, values, ok) if good},
                    "median": finite_or_none(median), "p84": finite_or_none(p84), "max": finite_or_none(largest)}

        entry = {
            "gap": float(ds.gap.values[c]),
            "required": shape(ds.required_gap.values[:, c], ds.required_gap_median.values[c],
                              ds.required_gap_p84.values[c], ds.required_gap_max.values[c]),
            "rules": {str(rule): shape(ds.rule_gap.values[k, :, c], ds.rule_gap_median.values[k, c],
                                       ds.rule_gap_p84.values[k, c], ds.rule_gap_max.values[k, c])
                      for k, rule in enumerate(ds.rule.values)},
            "unconservative_fraction": {str(rule): finite_or_none(ds.unconservative_fraction.values[k, c])
                                        for k, rule in enumerate(ds.rule.values)},
            "correlation": finite_or_none(ds.correlation.values[c]),
            "records_enough": int(ds.records_enough.values[c]),
            "records_ok": int(ok.sum()),
        }
        out["contacts"][str(label)] = entry
    failed = {rec: str(err) for rec, err, good in zip(records, ds.error.values, ok) if not good}
    if failed:
        out["failed"] = failed
    return out


def _mm(value: float) -> str:
    return "-" if not math.isfinite(value) else f"{1000 * value:.1f}"


def gap_table(ds) -> str:
    """The study as a printed table (millimetres)."""
    ok = ds.status.values == "ok"
    n_ok = int(ok.sum())
    rules = [str(r) for r in ds.rule.values]
    lines = [f"required separation over {n_ok} record{'s' if n_ok != 1 else ''} (mm; contact-free runs), "
             "and the code rules on the same runs"]
    head = f"{'contact':<14} {'gap':>7} {'median':>7} {'p84':>7} {'max':>7}  " + \
           "  ".join(f"{r + ' p84':>9} {'unsafe':>6}" for r in rules) + "  verdict"
    lines.append(head)
    for c, label in enumerate(ds.contact.values):
        row = (f"{str(label):<14} {_mm(float(ds.gap.values[c])):>7} {_mm(float(ds.required_gap_median.values[c])):>7} "
               f"{_mm(float(ds.required_gap_p84.values[c])):>7} {_mm(float(ds.required_gap_max.values[c])):>7}  ")
        cells = []
        for k in range(len(rules)):
            fraction = float(ds.unconservative_fraction.values[k, c])
            cells.append(f"{_mm(float(ds.rule_gap_p84.values[k, c])):>9} "
                         f"{('-' if not math.isfinite(fraction) else f'{100 * fraction:.0f}%'):>6}")
        enough = int(ds.records_enough.values[c])
        row += "  ".join(cells) + f"  enough for {enough} of {n_ok}"
        lines.append(row)
    lines.append("unsafe: fraction of records for which the rule is below the required separation; "
                 f"ddc uses rho = CQC of the first modes ({', '.join(f'{x:.3f}' for x in ds.correlation.values)})")
    return "\n".join(lines)


def gap_tables(ds) -> dict:
    """Tables of a gap archive (metres): ``contacts`` (the model's gap, the required separation's median,
    84th percentile and maximum, the records it suffices for), ``rules`` (each rule's separation and how
    often it is unconservative), ``records`` (per record and contact: the required separation and the
    peak displacements it came from) and ``rule_records`` (each rule per record and contact)."""
    from pounding.results.tables import long_table

    place = ["building_left", "level_left", "elevation_left", "building_right", "level_right", "elevation_right"]
    return {
        "contacts": long_table(ds, ["gap", "required_gap_median", "required_gap_p84", "required_gap_max",
                                    "records_enough", "correlation"], extra=place),
        "rules": long_table(ds, ["rule_gap_median", "rule_gap_p84", "rule_gap_max", "unconservative_fraction"]),
        "records": long_table(ds, ["required_gap", "peak_displacement_left", "peak_displacement_right"],
                              extra=["status", "scale_factor", "gap"]),
        "rule_records": long_table(ds, ["rule_gap", "rule_ratio"], extra=["status"]),
    }


def plot_gap(ds, directory: str | os.PathLike) -> list[Path]:
    """``gap_profile.png``: required separation against elevation per record, the rules and the model's gap."""
    from pounding.results.plots import finish_profile_panel, plot_directory, pyplot, save_figure, suptitle

    plt = pyplot()
    out = plot_directory(directory)
    pairs = sorted({(str(a), str(b)) for a, b in zip(ds.building_left.values, ds.building_right.values)})
    fig, axes = plt.subplots(1, len(pairs), figsize=(5.2 * len(pairs), 4.6), squeeze=False)
    ok = ds.status.values == "ok"
    for ax, (left, right) in zip(axes[0], pairs):
        sel = np.flatnonzero((ds.building_left.values == left) & (ds.building_right.values == right))
        order = sel[np.argsort(ds.elevation_left.values[sel])]
        z = np.maximum(ds.elevation_left.values[order], ds.elevation_right.values[order])
        for r in np.flatnonzero(ok):
            ax.plot(1000 * ds.required_gap.values[r, order], z, color="0.75", lw=0.8, marker=".", ms=3,
                    label="required, one record" if r == np.flatnonzero(ok)[0] else None)
        ax.plot(1000 * ds.required_gap_median.values[order], z, color="k", lw=2, marker="o", ms=4,
                label="required, median")
        ax.plot(1000 * ds.required_gap_p84.values[order], z, color="k", lw=1.2, ls="--", label="required, 84th pct")
        for k, rule in enumerate(ds.rule.values):
            ax.plot(1000 * ds.rule_gap_p84.values[k, order], z, lw=1.4, marker="s", ms=3, color=f"C{k}",
                    label=f"{rule} (84th pct)")
        ax.plot(1000 * ds.gap.values[order], z, color="C3", lw=2.2, ls=":", label="model gap")
        rho = float(np.mean(ds.correlation.values[order]))
        finish_profile_panel(ax, "separation (mm)", "elevation of the contact (m)",
                             f"{left} | {right}   (ddc with rho = {rho:.3f}; rho near 0: ddc = srss)", title_size=9)
    suptitle(fig, f"separation needed to avoid pounding, {int(ok.sum())} record(s) run\n{ds.attrs.get('title', '')}",
                 9)
    path = out / "gap_profile.png"
    save_figure(fig, path)
    return [path]
