"""What every study shares: the ``--records`` option, a study's record sweep, option checks.

``compare``, ``gap`` and ``ida`` each run a model over a list of records on
the study engine (:mod:`pounding.studies.engine`); they read their options
and build their record sweep here, the same way.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from pounding.errors import PoundingError
from pounding.records.catalogue import is_catalogued

__all__ = ["study_parts", "with_base_mats", "record_list", "record_values", "pair_values", "study_document", "study_sweep",
           "check_duration", "finite_or_none", "records_text", "scale_spec_text", "sweep_heading", "base_model_text",
           "record_sweep", "floor_states", "dof_peaks", "ground_pga"]


def record_list(text: str | list[str] | None, *, pairs: bool = False) -> list[str] | None:
    """Record specs of a `--records` option: a set (`fema-p695:farfield`) or a comma-separated list; None if not given.

    *pairs*: the model's ground motion has two components, so the records are pairs (``fema-p695:farfield``:
    the 22 pairs; a single component is refused in one line: :func:`pounding.studies.sweep.spec.expand_pairs`).
    """
    from pounding.studies.sweep.spec import record_expander

    if text is None:
        return None
    items = [r.strip() for r in (text.split(",") if isinstance(text, str) else text) if r.strip()]
    records: list[str] = []
    for item in items:
        try:
            expanded = record_expander(pairs)(item)
        except PoundingError as exc:
            raise PoundingError(f"--records: {exc}") from None
        records += [r for r in expanded if r not in records]
    if not records:
        raise PoundingError("--records needs record pairs, e.g. fema-p695:farfield or fema-p695:farfield/1,"
                            "fema-p695:farfield/2" if pairs else
                            "--records needs a set (fema-p695:farfield) or a comma-separated list of records")
    return records


def record_values(records: str | list[str] | None, model: Any = None, *, pairs: bool = False) -> list[str] | None:
    """The ``records`` axis of a study: the `--records` option (files made absolute), else *model*'s own record.

    Parameters
    ----------
    records : str or list of str, optional
        The option as given (see :func:`record_list`).
    model : pounding.model.model.Model, optional
        Whose record is the default; without it, None when *records* is None.
    pairs : bool
        The records are pairs (a ground motion of two components); *model*'s own is its pair (None when it gives
        its components one by one: the study runs them as they are).  A ground motion in plan that names one
        component (x or y alone) takes single records (*pairs* False), its own being that component's record.
    """
    listed = record_list(records, pairs=pairs)
    if listed is not None:
        return [os.path.abspath(r) if os.path.exists(r) else r for r in listed]
    if model is None:
        return None
    motion = model.ground_motion
    side = motion.one_component
    if side is not None:
        record = getattr(motion, side).record
        if is_catalogued(record) or os.path.isabs(record) or motion.base_dir is None:
            return [record]
        return [os.path.normpath(os.path.join(motion.base_dir, record))]
    if motion.two_components:
        return None if motion.record is None else [motion.record]
    return [motion.record if motion.is_catalogue else str(motion.record_path)]


def pair_values(records: str | list[str] | None) -> list[str] | None:
    """The record pairs of a ``--records`` option (``fema-p695:farfield``, or pairs separated by commas)."""
    return record_list(records, pairs=True)


def study_document(model: str | os.PathLike, prefix: str, axes: dict[str, Any], records: list[str] | None,
                   duration: float | None, scale: Any, settings: dict[str, Any] | None = None) -> dict[str, Any]:
    """The sweep document of a study over *axes* × *records* (compare, gap...) of the model file *model*.

    Parameters
    ----------
    model : path-like
        The model file.
    prefix : str
        The study (``compare``): the sweep is named ``PREFIX-STEM``.
    axes : dict
        The study's own axes; ``records`` is added after them unless *records* is None (the model's own).
    records : list of str, optional
        The records (or record pairs).
    duration : float, optional
        Simulated time, s (``ground_motion.duration``).
    scale : float or mapping, optional
        ``ground_motion.scale`` of every run: a factor or a target (``{pga: 0.4g}``; on a record pair the
        target of its geometric mean: :func:`pounding.records.processing.pair_scale_factor`).
    settings : dict, optional
        Further fixed changes (``set``), before the scale and duration.
    """
    path = os.path.abspath(os.fspath(model))
    if records is not None:
        axes = {**axes, "records": records}
    document: dict[str, Any] = {"name": f"{prefix}-{Path(path).stem}", "model": path, "axes": axes}
    settings = dict(settings or {})
    if scale is not None:
        settings["scale"] = scale
    if check_duration(duration) is not None:
        settings["ground_motion.duration"] = float(duration)
    if settings:
        document["set"] = settings
    return document


def study_sweep(document: dict[str, Any], label: str):
    """The :class:`~pounding.studies.sweep.spec.Sweep` of a study's sweep *document*, relative to the current folder.

    The first axis value that makes the model invalid is refused in one line.
    """
    import yaml

    from pounding.studies.sweep.spec import sweep_from_text

    sweep = sweep_from_text(yaml.safe_dump(document, sort_keys=False), label=label, base_dir=os.getcwd())
    invalid = sweep.invalid_values()
    if invalid:
        raise PoundingError(invalid[0].split(": ", 1)[-1])
    return sweep


def check_duration(duration: float | None) -> float | None:
    """``--duration`` in s as a float (None stays None); refused unless > 0."""
    if duration is None:
        return None
    if not duration > 0:
        raise PoundingError(f"--duration must be > 0 (got {duration:g})")
    return float(duration)


def finite_or_none(value: Any) -> float | None:
    """*value* as a float, or None when it is None, NaN or infinite (JSON has neither)."""
    if value is None:
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def records_text(records: list[str], shown: int = 3) -> str:
    """A record list in a title: ``record fema-p695:farfield/1a``, ``2 records (a, b)``, ``44 records (a, b, c, ...)``."""
    records = [str(r) for r in records]
    if len(records) == 1:
        return f"record {records[0]}"
    listed = ", ".join(records[:shown]) + (", ..." if len(records) > shown else "")
    return f"{len(records)} records ({listed})"


def scale_spec_text(value: Any) -> str:
    """A YAML ``ground_motion.scale`` value in words: ``scale factor 0.8``, ``scaled to pga 0.4g``."""
    if value is None:
        return "scale factor 1"
    if isinstance(value, dict):
        return "scaled to " + ", ".join(f"{k} {v}" if v is not True else str(k) for k, v in value.items())
    try:
        return f"scale factor {float(value):.4g}"
    except (TypeError, ValueError):
        return f"scaled to {value}"


def sweep_heading(sweep) -> str:
    """What a sweep-based study ran, for its archive title: model, records and intensity.

    E.g. ``model 'pair' under 2 records (fema-p695:farfield/1a, fema-p695:farfield/2a), scale factor 1``;
    ``scale swept`` when an axis sets the scale.
    """
    ground = sweep.base_document.get("ground_motion") or {}
    records: list[str] = [str(ground.get("record", ""))]
    swept = False
    for axis in sweep.axes:
        if axis.kind == "record":   # None: the model's own ground motion (components given one by one)
            records = [str(v) if v is not None else str(label) for v, label in zip(axis.values, axis.labels)]
        swept = swept or axis.kind == "scale" or "scale" in str(axis.key).split(".")[-1:]
    intensity = "scale swept" if swept else scale_spec_text(ground.get("scale"))
    return f"model '{sweep.model_name}' under {records_text(records)}, {intensity}"


def base_model_text(model: Any) -> str:
    """The ``base_model`` attribute of a study's archive: the model the study ran, as YAML text.

    A study's archive keeps it so that the model can be read again, and the study run again, after its file
    has changed or is gone (``pounding report`` rebuilds it with :func:`pounding.model.model.model_from_text`).

    Parameters
    ----------
    model : pounding.model.model.Model or dict
        A loaded model: its plain document with the record files of its ground motion made absolute
        against the model file's folder (:func:`pounding.studies.sweep.spec.model_document`); or a
        sweep's ``base_document``, already so and with the study's fixed settings (``set``) written in.
    """
    from pounding.model.document import dump_document
    from pounding.studies.sweep.spec import model_document

    return dump_document(model if isinstance(model, dict) else model_document(model))


def study_parts(scenarios: list, results: dict[str, dict[str, Any]], study: str) -> list[dict[str, Any]]:
    """Each scenario's result (``not run`` where missing; a stored part of another *study* kind is an error)."""
    parts = []
    for s in scenarios:
        part = results.get(s.key, {"status": "error", "error": "not run"})
        if part.get("status") == "ok" and part.get("study") != study:
            part = {"status": "error", "error": f"{s.label}: a stored result of another kind of study has the "
                                                "same key; delete the .parts folder and run again"}
        parts.append(part)
    return parts


def record_sweep(model: str | os.PathLike, base: Any, prefix: str, settings: dict[str, Any],
                 records: str | list[str] | None, label: str):
    """The record sweep of a study that runs *model* under each of *records* (gap, ida): one scenario per record.

    A model shaken by one component takes records (a set such as ``fema-p695:farfield`` is its 44
    components); a model shaken by two (floors in plan) takes record pairs (``fema-p695:farfield`` is
    its 22 pairs), both components of a pair in one scenario.  Default: the model's own record (pair; its
    components given one by one: one scenario, its ``record`` coordinate ``x=FILE...``).

    Parameters
    ----------
    model : path-like
        The model file.
    base : pounding.model.model.Model
        The model loaded (its own record, whether it is shaken by one component or two).
    prefix : str
        The sweep's name is ``PREFIX-<model file stem>``.
    settings : dict
        The sweep's ``set`` (``name``, ``scale``, ``ground_motion.duration``...).
    records : str or list of str, optional
        The ``--records`` option as given.
    label : str
        Where an error is said to be (``<gap models/pair.yaml>``).
    """
    path = os.path.abspath(os.fspath(model))
    pairs = bool(base.ground_motion.record_pairs)
    values = record_values(records, base, pairs=pairs)
    document: dict[str, Any] = {"name": f"{prefix}-{Path(path).stem}", "model": path, "set": settings,
                                "axes": {} if values is None else {"records": values}}
    return study_sweep(document, label)


def floor_states(ds) -> tuple[Any, Any]:
    """``(q, q̇)`` (time, DOF) of a run archive in the model's order of degrees of freedom (m, rad; m/s, rad/s).

    Floors of one degree of freedom: ``displacement`` and ``velocity`` (time, floor) as they are (a founded
    building's base mat after its floors: :func:`with_base_mats`); floors in
    plan: u_x, u_y (``displacement`` (time, floor, direction)) and θ (``rotation``) of each floor in turn.
    """
    import numpy as np

    u, v = ds.displacement.values, ds.velocity.values
    if u.ndim == 2:
        if "foundation" in ds.coords:   # a founded building's base mat: its sway and rocking after its floors
            return (with_base_mats(ds, u, ds.base_sway.values, ds.base_rocking.values),
                    with_base_mats(ds, v, ds.base_sway_rate.values, ds.base_rocking_rate.values))
        return u, v
    q = np.concatenate([u, ds.rotation.values[:, :, None]], axis=2)
    qd = np.concatenate([v, ds.rotation_rate.values[:, :, None]], axis=2)
    return q.reshape(q.shape[0], -1), qd.reshape(qd.shape[0], -1)


def with_base_mats(ds, floors: Any, sway: Any, rocking: Any) -> Any:
    """(time, DOF) in the model's order from (time, floor) *floors* and (time, foundation) *sway* and *rocking*:
    each building's floors, then its base mat's sway and rocking where it stands on a foundation
    (:attr:`pounding.model.model.Model.dof_offsets`)."""
    import numpy as np

    owners = [str(b) for b in ds.building.values]
    founded = [str(b) for b in ds.foundation.values]
    columns = []
    for name in dict.fromkeys(owners):
        columns.append(floors[:, [i for i, owner in enumerate(owners) if owner == name]])
        if name in founded:
            k = founded.index(name)
            columns.append(np.stack([sway[:, k], rocking[:, k]], axis=1))
    return np.concatenate(columns, axis=1)


def dof_peaks(ds) -> Any:
    """(DOF,) each degree of freedom's peak |value| over the run at the solver's full resolution (m, rad), in the
    order of :func:`floor_states`."""
    import numpy as np

    peak = ds.peak_displacement.values
    if peak.ndim == 1:
        if "foundation" in ds.coords:
            return with_base_mats(ds, peak[None, :], ds.peak_base_sway.values[None, :],
                                  ds.peak_base_rocking.values[None, :])[0]
        return peak
    return np.concatenate([peak, ds.peak_rotation.values[:, None]], axis=1).reshape(-1)


def ground_pga(records: list) -> float:
    """The PGA of a ground motion as run, m/s²: of one record, its own PGA (``pga_g`` of the file, before
    processing and truncation, else its samples') times its factor; of a record pair, the geometric mean of
    its two components' (as :func:`pounding.records.processing.pair_scale_factor` takes a pair's intensity).

    Parameters
    ----------
    records : list of pounding.records.record.Record
        The scaled components (one or two).
    """
    import math

    from pounding.units import STANDARD_GRAVITY

    def pga(record) -> float:
        own = record.metadata.get("pga_g")
        return float(own) * STANDARD_GRAVITY * float(record.scale) if own is not None else float(record.pga)

    values = [pga(r) for r in records]
    return values[0] if len(values) == 1 else math.sqrt(values[0] * values[1])
