"""A scenario's model from its document, a record pair scaled to a target, and the intensity a run reached.

A model file's ``ground_motion.scale`` is a factor or a target (``{pga: 0.4g}``, ``{sa: 0.8g,
period: building A}``, ``{fema-p695: true}``).  For one component the model applies the target
itself.  For a record pair (a ground motion of two components) the target applies to the pair:
FEMA P695 normalises and scales a pair by the geometric mean of its two components'
intensities, and both components take the one factor that reaches it
(:func:`pounding.records.processing.pair_scale_factor`).  The plan model's schema
(:mod:`pounding.model.plan_schema`) takes a factor only, so a study resolves a pair's target
here, on the worker, into that factor before the run: :func:`scenario_model` reads the
document with the factor 1, :func:`pair_scaled` finds the factor from the pair as stored.

The ``intensity`` every study archive records per scenario is the PGA reached
(:func:`run_intensity`): the record's own PGA times the factor on it, and for a pair the
geometric mean of its two components' (each with its own factor).
"""

from __future__ import annotations

import math
from typing import Any

from pounding.errors import ModelError, RecordError
from pounding.model.document import is_plan_document

__all__ = ["split_pair_target", "scenario_model", "pair_scaled", "run_intensity", "PAIR_PGA_LONG_NAME"]

#: long_name of a study's ``intensity`` when its records are pairs.
PAIR_PGA_LONG_NAME = ("peak ground acceleration (PGA) of the scaled record pair: the geometric mean of its two "
                      "components' own PGAs, each times the factors on it")


def split_pair_target(data: Any) -> tuple[Any, Any]:
    """*data* (a plain model document) with the target scaling of its record pair replaced by the factor 1,
    and that target as a :class:`~pounding.records.processing.Scaling` (None: no target to resolve).

    Raises
    ------
    ModelError
        One line: the target is malformed, or it is given to components ``x``/``y`` (each takes its own
        factor, as the model file says).
    """
    from pounding.records.processing import SpecProblem, parse_scale

    ground = data.get("ground_motion") if isinstance(data, dict) else None
    target = ground.get("scale") if isinstance(ground, dict) else None
    if not isinstance(target, dict) or not is_plan_document(data):
        return data, None
    if ground.get("record") is None:
        raise ModelError("ground_motion.scale applies to a record pair (record: fema-p695:farfield/1); "
                         "components x and y each take their own factor")
    names = [str(b.get("name")) for b in data.get("buildings") or [] if isinstance(b, dict)]
    try:
        scaling = parse_scale(target, names)
    except SpecProblem as failed:
        raise ModelError(failed.message("ground_motion.scale", target)) from None
    return {**data, "ground_motion": {**ground, "scale": 1.0}}, scaling


def scenario_model(data: dict[str, Any], *, name: str = "model", source: str = "", base_dir: str | None = None):
    """The model of a scenario's plain *data* and the target its record pair is to be scaled to (None: the
    document's own scale applies); :func:`pounding.model.model.model_from_data` otherwise.

    Returns
    -------
    (Model, Scaling or None)
    """
    from pounding.model.model import model_from_data

    data, target = split_pair_target(data)
    return model_from_data(data, name=name, source=source, base_dir=base_dir), target


def pair_scaled(model, target):
    """*model* (its pair at the factor 1) with the one factor that takes its pair to *target*.

    Sa at ``period: building X`` is at that building's first period (of its 3-D modes).

    Raises
    ------
    RecordError
        The factor is beyond what a record can represent (as a planar target, 1/100 to 100).
    """
    from pounding.records.processing import SCALE_FACTOR_MAX, pair_scale_factor
    from pounding.simulation import component_records

    period = None
    if target.building is not None:
        period = float(model.buildings[model.building_index(target.building)].periods[0])
    records = [r for r in component_records(model) if r is not None]
    factor = pair_scale_factor(records, target, period=period)
    if not 1.0 / SCALE_FACTOR_MAX <= factor <= SCALE_FACTOR_MAX:
        raise RecordError(f"scaling the pair {model.ground_motion.record} to {target.describe(period)} needs a "
                          f"factor of {factor:.3g}, beyond {1.0 / SCALE_FACTOR_MAX:g}-{SCALE_FACTOR_MAX:g}; check the "
                          "target's units and the period, or choose another pair")
    return model.with_ground_motion(scale=factor)


def run_intensity(model, ds) -> float:
    """The PGA a run of *model* reached, m/s²: its record's (:func:`pounding.results.dataset.record_pga`),
    or with two components the geometric mean of theirs (each the component's own PGA times the factors on
    it; the peak of its samples as run when the file does not say)."""
    from pounding.results.dataset import record_pga
    from pounding.simulation import component_records
    from pounding.units import STANDARD_GRAVITY

    if not model.ground_motion.two_components:
        return record_pga(ds)[1]
    peaks = []
    for record in component_records(model, factor=float(ds.attrs["record_scale"])):
        if record is not None:
            own = record.metadata.get("pga_g")
            peaks.append(float(own) * STANDARD_GRAVITY * float(record.scale) if own is not None else record.pga)
    return float(math.prod(peaks) ** (1.0 / len(peaks))) if peaks else float("nan")
