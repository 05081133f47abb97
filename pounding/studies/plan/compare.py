"""``pounding compare`` on plan models: ξ formulas (or with and without pounding) on plane drifts and corners.

A plan sweep (:mod:`pounding.studies.plan.sweep`) over the ξ formula of every
hertz-damp contact × record pairs.  Per building it prints, for each storey,
the largest peak *plane* drift ratio of the storey (the plan counterpart of
the storey drift: every frame or wall of the storey drifts on its own line),
then the building's largest peak corner displacement, centre-of-mass
displacement and rotation; each formula's value is the mean over the records,
beside ``[mean, max |.|]`` over the records of its difference from the
reference formula (``exact`` by default), ``(d − d_ref) / d_ref``.

``--contacts with,without`` compares the model as given with the model
without contacts instead; the archive gains ``pounding_drift_change`` (per
record and plane).  The archive is the plan sweep's layout (dims ``xi`` or
``pounding``, ``record``, then ``plane``, ``floor`` × ``direction``,
``corner``, ``point``; every variable with units and long_name), with the
attribute ``reference_xi``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from pounding.errors import PoundingError

__all__ = ["build_plan_compare", "plan_compare", "plan_comparison_table", "plan_rows", "pair_values",
           "pair_scale", "study_document"]


def pair_values(records: str | list[str] | None) -> list[str] | None:
    """The record pairs of a ``--records`` option (``fema-p695:farfield``, or pairs separated by commas)."""
    from pounding.studies.plan.sweep import expand_pairs

    if records is None:
        return None
    found: list[str] = []
    for item in (records.split(",") if isinstance(records, str) else records):
        if item.strip():
            try:
                found += [p for p in expand_pairs(item) if p not in found]
            except PoundingError as exc:
                raise PoundingError(f"--records: {exc}") from None
    if not found:
        raise PoundingError("--records needs record pairs, e.g. fema-p695:farfield or fema-p695:farfield/1,"
                            "fema-p695:farfield/2")
    return found


def pair_scale(scale: Any) -> float | None:
    """A ``--scale`` for a plan model: a factor on both components (targets such as a PGA are refused)."""
    if scale is None:
        return None
    if isinstance(scale, dict):
        raise PoundingError("--scale: a plan model's record pair takes a factor (e.g. --scale 1.5), not a target "
                            "intensity")
    return float(scale)


def study_document(model: str | os.PathLike, prefix: str, axes: dict[str, Any], records: list[str] | None,
                    duration: float | None, scale: Any, settings: dict[str, Any] | None = None) -> dict[str, Any]:
    """The sweep document of a plan study over *axes* × record pairs (compare, gap)."""
    from pounding.studies.common import check_duration

    path = os.path.abspath(os.fspath(model))
    if records is not None:
        axes = {**axes, "records": records}
    document: dict[str, Any] = {"name": f"{prefix}-{Path(path).stem}", "model": path, "axes": axes}
    settings = dict(settings or {})
    if pair_scale(scale) is not None:
        settings["scale"] = pair_scale(scale)
    if check_duration(duration) is not None:
        settings["ground_motion.duration"] = float(duration)
    if settings:
        document["set"] = settings
    return document


def build_plan_compare(model: str | os.PathLike, formulas: str | list[str] | None = None,
                       records: str | list[str] | None = None, *, duration: float | None = None,
                       reference: str = "exact", contacts: str | list[str] | None = None, scale: Any = None):
    """The plan sweep behind ``pounding compare`` on a plan model: formulas (or with, without) × record pairs."""
    from pounding.model.model import load_model as load_plan_model
    from pounding.studies.compare import compared_axis
    from pounding.studies.plan.sweep import plan_study_sweep

    base = load_plan_model(model)             # the model's own errors, with its file name
    axes = compared_axis(model, [c.law for c in base.faces], formulas, contacts, reference)
    document = study_document(model, "compare", axes, pair_values(records), duration, scale)
    return plan_study_sweep(document, f"<compare {os.fspath(model)}>")


def plan_compare(model: str | os.PathLike, formulas: str | list[str] | None = None,
                 records: str | list[str] | None = None, *, output: str | os.PathLike | None = None,
                 duration: float | None = None, reference: str = "exact", contacts: str | list[str] | None = None,
                 scale: Any = None, **run_options):
    """Run the plan comparison and return its dataset (see the module docstring).

    Parameters are those of :func:`pounding.studies.compare.compare`; *records* are record pairs and
    *scale* a factor.
    """
    from pounding.studies.plan.runs import assemble_plan_sweep, run_plan_scenario
    from pounding.studies.sweep.execution import plan_line, run_sweep

    sweep = build_plan_compare(model, formulas, records, duration=duration, reference=reference,
                               contacts=contacts, scale=scale)
    run_options.setdefault("plan", plan_line(sweep, "compare"))

    def assemble(sweep, results, **kwargs):
        from pounding.studies.common import sweep_heading

        what = "with and without pounding" if contacts is not None else "per xi formula"
        ds = assemble_plan_sweep(sweep, results, title=f"pounding compare '{sweep.name}' (plan): plane drifts and "
                                 f"corner displacements {what} ({sweep.size} scenarios) of {sweep_heading(sweep)}",
                                 **kwargs)
        if contacts is not None:
            from pounding.studies.compare import pounding_change

            ds["pounding_drift_change"] = pounding_change(ds, "peak_plane_drift_ratio").assign_attrs(
                units="1", long_name="change of the peak plane drift ratio due to pounding: (with - without) / "
                                     "without")
        else:
            ds.attrs["reference_xi"] = reference
        return ds

    return run_sweep(sweep, output, runner=run_plan_scenario, assemble=assemble, **run_options)


def plan_rows(ds, building: str) -> list[tuple[str, str, Any]]:
    """The rows of *building* in a plan compare: ``(label, unit, values)`` with values over the study dims.

    A storey's row is the largest peak plane drift ratio of its planes (%); then the building's largest
    peak corner displacement (mm), centre-of-mass displacement (mm, either direction) and rotation (mrad).
    """
    planes = (ds.plane_building == building).values
    floors = (ds.building == building).values
    rows: list[tuple[str, str, Any]] = []
    drift = ds.peak_plane_drift_ratio.isel(plane=planes)
    storeys = ds.plane_storey.values[planes]
    for storey in sorted(set(int(s) for s in storeys)):
        rows.append((str(storey), "%", 100 * drift.isel(plane=storeys == storey).max("plane", skipna=True)))
    rows.append(("corner", "mm", 1e3 * ds.peak_corner_displacement.isel(floor=floors).max(("floor", "corner"),
                                                                                          skipna=True)))
    rows.append(("CM", "mm", 1e3 * ds.peak_displacement.isel(floor=floors).max(("floor", "direction"),
                                                                               skipna=True)))
    rows.append(("rotation", "mrad", 1e3 * ds.peak_rotation.isel(floor=floors).max("floor", skipna=True)))
    return rows


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[i]) for r in [header] + rows) for i in range(len(header))]
    return ["  " + "  ".join(f"{c:>{w}}" for c, w in zip(row, widths)) for row in [header] + rows]


def plan_comparison_table(ds, reference: str = "exact") -> str:
    """The per-building table printed by ``pounding compare`` on a plan model."""
    from pounding.studies.compare import reference_formula

    variant = "pounding" if "pounding" in ds.dims else "xi"
    names = [str(x) for x in ds[variant].values]
    if variant == "xi":
        reference = reference if reference in names else reference_formula(ds)
    else:
        reference = "without"
    records = [str(r) for r in ds.record.values]
    lines = [f"plane drifts and corner displacements over {len(records)} record pair"
             f"{'s' if len(records) != 1 else ''}: " + ", ".join(records[:4]) + (", ..." if len(records) > 4 else "")]
    failed = int((ds.status != "ok").sum())
    if failed:
        lines.append(f"{failed} of {ds.status.size} scenario(s) failed and are left out of the means below")
    for building in dict.fromkeys(str(b) for b in ds.building.values):
        lines += ["", f"building {building}: storey rows = largest peak plane drift ratio of the storey, %; corner, "
                      "CM (mm) and rotation (mrad) = the building's largest; mean over records, and [mean, max |.|] "
                      f"over records of the difference from {reference}, % of {reference}"]
        body = []
        for label, unit, values in plan_rows(ds, building):
            ref = values.sel({variant: reference})
            with np.errstate(invalid="ignore", divide="ignore"):
                rel = 100 * (values - ref) / ref
            cells = [f"{label} ({unit})"]
            for name in names:
                mean = float(values.sel({variant: name}).mean("record", skipna=True))
                if name == reference:
                    cells.append(f"{mean:.4g}")
                    continue
                diff = rel.sel({variant: name})
                cells.append(f"{mean:.4g} [{float(diff.mean('record', skipna=True)):+.1f}, "
                             f"{float(np.abs(diff).max('record', skipna=True)):.1f}]")
            body.append(cells)
        lines += _table(["row"] + names, body)
    return "\n".join(lines)
