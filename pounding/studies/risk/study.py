"""The risk study (``pounding risk``): a multi-stripe analysis on the IDA's machinery, integrated over a hazard curve.

The stripes are those of ``pounding ida --levels ... --without-contacts`` (:mod:`pounding.studies.ida`):
every record at every level, with the model's contacts and with them held open.  A run without contacts
also keeps, per contact (a level pair), the separation it would have needed: the largest approach of the
two sides, :func:`pounding.studies.gap.required_separations` of the run's full history (a run in which a
building collapsed needs an unbounded separation).  The archive is the IDA's, plus:

* per contact, λ(g) = ∫ P(D > g | x) |dλ_IM(x)| over a grid of separations g, its probability in the
  target's years, the separation that meets the target (``--target``, 2 % in 50 years by default) and the
  risk of the model's own gap (:mod:`pounding.studies.risk.integrals`, the empirical route);
* per building and variant, the mean annual frequency of collapse from the stripes' lognormal collapse
  fragility (the IDA's fit, censored runs left out), and from the stripes' collapse fractions without a
  fit (the empirical route), each with its 50-year probability, against the 1 % in 50 years that
  ASCE 7-22's risk-targeted ground motions (Chapter 21) aim at.

Default stripes (:func:`default_levels`): :data:`DEFAULT_STRIPES` intensities evenly spaced in ln x from
the hazard curve's intensity at 2e-2 /yr (a 50-year event) to that at 1e-4 /yr (10,000 years).
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
from typing import Any

import numpy as np

from pounding.errors import PoundingError
from pounding.studies.risk.hazard import HazardCurve
from pounding.units import STANDARD_GRAVITY

__all__ = ["RiskPlan", "build_risk_plan", "code_separations", "default_levels", "run_risk_scenario", "risk_study", "RISK_KEY",
           "DEFAULT_STRIPES", "STRIPE_RATES"]

#: What makes a risk run's part key differ from the same IDA run's (a risk part also holds the separations).
RISK_KEY = "risk-1"
#: Stripes by default.
DEFAULT_STRIPES = 8
#: Annual rates of exceedance of the lowest and highest default stripes, 1/yr.
STRIPE_RATES = (2e-2, 1e-4)


@dataclasses.dataclass
class RiskPlan:
    """An IDA plan (stripes, both variants), the hazard curve and the pounding target.

    Attributes
    ----------
    ida : pounding.studies.ida.IdaPlan
        The stripes.
    curve : HazardCurve
        The site's hazard curve, of the plan's IM.
    target : tuple of float
        (probability, years) of pounding to meet.
    gaps : ndarray
        The model's own gap of each contact, m.
    codes : dict
        Per design code (``asce7-22``, ``ec8``) its separation of each contact, {contact label: m}
        (:func:`pounding.studies.design_check.code_separation_rows`, same property); empty without ``--code``.
    """

    ida: Any
    curve: HazardCurve
    target: tuple[float, float]
    gaps: np.ndarray
    codes: dict = dataclasses.field(default_factory=dict)


def default_levels(curve: HazardCurve, count: int = DEFAULT_STRIPES) -> np.ndarray:
    """*count* stripes (g, 4 significant digits) evenly spaced in ln x between the curve's intensities at
    :data:`STRIPE_RATES`."""
    if count < 2:
        raise PoundingError(f"--stripes must be >= 2 (got {count})")
    low, high = curve.intensity_at(np.array(STRIPE_RATES)) / STANDARD_GRAVITY
    return np.array([float(f"{x:.4g}") for x in np.geomspace(low, high, count)])


def build_risk_plan(model: str | os.PathLike, hazard: HazardCurve, *, im: str | None = None,
                    records: Any = None, levels: Any = None, stripes: int = DEFAULT_STRIPES,
                    building: str | None = None, target: str = "2%/50y", duration: float | None = None,
                    collapse_drift: float | None = None, codes: dict[str, dict] | None = None) -> RiskPlan:
    """Check the inputs of a risk study and plan its stripes (before any run).

    Parameters
    ----------
    model : path-like
        YAML model with contacts.
    hazard : HazardCurve
        The site's hazard curve (:func:`pounding.studies.risk.hazard.read_hazard`), of the IM *im*.
    im : str, optional
        ``pga``, ``sa-t1`` (default), ``sa:T`` or ``sa-avg:T1,T2`` (:func:`~pounding.studies.risk.measures.parse_risk_im`).
    records, building, duration, collapse_drift
        As for :func:`pounding.studies.ida.build_ida_plan`.
    levels : str or array, optional
        Stripes in g (``--levels``); default :func:`default_levels` with *stripes* stripes.
    target : str
        ``--target``, the probability of pounding to meet (``2%/50y``).
    codes : dict, optional
        {code: its design spectrum's options} (``--code``, as ``pounding gap --code``): the risk that each code's
        separation implies is reported beside the target's (each building needs its ``design:`` factors).
    """
    from pounding.model.model import load_model
    from pounding.studies.ida import build_ida_plan
    from pounding.studies.risk.integrals import parse_target
    from pounding.studies.risk.measures import parse_risk_im, with_measure

    goal = parse_target(target)
    name, periods = parse_risk_im(im)
    if levels is None:
        levels = default_levels(hazard, stripes)
    plan = build_ida_plan(model, records, im="pga" if name == "pga" else "sa-t1", building=building,
                          levels=levels, without_contacts=True, collapse_drift=collapse_drift, duration=duration)
    if periods:
        plan = with_measure(plan, name, periods)
    loaded = load_model(model)
    gaps = np.array([float(g.gap) for g in loaded.gaps])
    return RiskPlan(plan, hazard, goal, gaps, code_separations(loaded, model, codes or {}))


def code_separations(model, path, codes: dict[str, dict]) -> dict[str, dict[str, float]]:
    """{code: {contact label: the code's separation (same property), m}} for each code of *codes* ({code: its
    spectrum options}), from the buildings' ``design:`` factors (no record read)."""
    from pounding.studies.design_check import code_separation_rows

    found = {}
    for code, options in codes.items():
        rows, _ = code_separation_rows(model, path, code, options)
        found[code] = {str(row["contact"]): float(row["separation"].same_property) for row in rows}
    return found


def _risk_key(key: str) -> str:
    return hashlib.sha256(f"{key}|{RISK_KEY}".encode()).hexdigest()


def run_risk_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """One run of a risk study, on a worker: the IDA's run (:func:`pounding.studies.ida.run_ida_scenario`)
    and, with the contacts held open, each contact's required separation (group ``separation``: ``contact``,
    ``required`` in m; ``unbounded`` true when a building collapsed)."""
    from pounding.model.model import model_from_data
    from pounding.simulation import refuse_failed_run, simulate
    from pounding.studies.engine.tasks import one_line
    from pounding.studies.gap import COLLAPSE_STATUSES, required_separations
    from pounding.studies.ida import run_ida_scenario

    result = run_ida_scenario(task)
    if result["status"] != "ok":
        return result
    try:
        model = model_from_data(task["data"], name=task.get("name", "model"), source=task["document"],
                                base_dir=task.get("base_dir"))
        if model.contacts_held_open:
            superposed = _superposed_separations(task, result, model)
            if superposed is not None:
                result["separation"], result["unbounded"] = superposed, False
                return result
            ds = simulate(model)
            status = ds.attrs.get("status", "completed")
            refuse_failed_run(status, str(ds.attrs.get("status_message", status)))
            found = required_separations(model, ds)
            result["separation"] = {"contact": [str(c) for c in ds.contact.values],
                                    "required": [float(x) for x in found["required"]]}
            result["unbounded"] = status in COLLAPSE_STATUSES
    except Exception as exc:  # noqa: BLE001 - a failing run is a result, not a crash
        result.update(status="error", error=f"{task.get('where', 'scenario')}: {one_line(exc)}")
    return result


def _superposed_separations(task: dict[str, Any], result: dict[str, Any], model) -> dict[str, list] | None:
    """The required separations of a run with the contacts held open whose buildings the IDA's run took by
    superposition (every one linear: :mod:`pounding.studies.ida.superposition`): its unit run's (the record at
    factor 1, tolerances 10 times tighter), computed once per worker and record, times the factor, since the
    largest approach of a response λ times another's is λ times its own.  None where the IDA's run was not
    superposed in whole (the caller runs it)."""
    from pounding.model.model import model_from_data
    from pounding.simulation import simulate
    from pounding.studies.gap import required_separations
    from pounding.studies.ida.superposition import UNIT_TIGHTENING, tightened, unit_factor, unit_result

    buildings = [b.name for b in model.buildings]
    factor, unit = unit_factor(task["data"])
    if (result.get("superposed", {}).get("building") != buildings or factor is None
            or not 0.0 < factor <= UNIT_TIGHTENING):
        return None
    name, base_dir = task.get("name", "model"), task.get("base_dir")

    def unit_separations() -> dict[str, Any] | None:
        run = tightened(model_from_data(unit, name=name, source=task["document"], base_dir=base_dir))
        ds = simulate(run)
        if ds.attrs.get("status", "completed") != "completed":
            return None
        return {"contact": [str(c) for c in ds.contact.values],
                "required": np.asarray(required_separations(run, ds)["required"], dtype=float)}

    found = unit_result(("separation", repr((unit, base_dir, name))), unit_separations)
    if found is None:
        return None
    return {"contact": list(found["contact"]), "required": [float(x) for x in found["required"] * factor]}


def risk_study(plan: RiskPlan, output: str | os.PathLike | None = None, **run_options):
    """Run the stripes of *plan* on the study engine and assemble the risk archive
    (:func:`pounding.studies.risk.report.assemble_risk_dataset`); *run_options* go to
    :func:`pounding.studies.engine.execution.run_study` (workers, overwrite, progress...)."""
    from pounding.studies.engine.execution import run_study
    from pounding.studies.risk.report import assemble_risk_dataset
    from pounding.studies.sweep.execution import sweep_tasks

    ida = plan.ida
    scenarios = [dataclasses.replace(s, key=_risk_key(s.key)) for s in ida.stripe_scenarios()]
    entries = [(v, r, float(level), _risk_key(ida.scenario(v, r, float(level)).key)) for v in ida.variants
               for r in range(len(ida.records)) for level in ida.levels]

    def assemble(_sweep, results, *, elapsed=float("nan"), ran=0):
        return assemble_risk_dataset(plan, results, entries, elapsed=elapsed, ran=ran)

    tasks = sweep_tasks(ida.sweep, runner=run_risk_scenario, assemble=assemble, scenarios=scenarios)
    return run_study(tasks, output, **run_options)
