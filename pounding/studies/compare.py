"""Compare ξ formulas on storey drifts: ``pounding compare MODEL.yaml --xi ye,lankarani-nikravesh,exact``.

A sweep (:mod:`pounding.studies.sweep`) over the ξ formula of every hertz-damp
contact × a list of records.  For each building it prints the peak storey
drift ratio profile of each formula (mean over the records) and its
difference from the reference formula (``exact`` by default): for each
record ``(d_formula − d_exact) / d_exact``, summarised by its mean and its
largest magnitude over the records.  ``--plot DIR`` draws the profiles (one
panel per building) and the distribution over records of each building's
largest storey drift ratio and of its difference from the reference.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from pounding.errors import PoundingError, did_you_mean

__all__ = ["compare", "comparison_table", "compare_tables", "differences", "reference_formula", "plot_comparison"]

REFERENCE = "exact"


def _formulas(text: str | list[str], reference: str) -> list[str]:
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


def build_sweep(model: str | os.PathLike, formulas: str | list[str], records: str | list[str] | None = None, *,
                duration: float | None = None, reference: str = REFERENCE):
    """The sweep behind ``pounding compare`` (formulas × records)."""
    from pounding.contact.laws import HertzDamp
    from pounding.model.model import load_model
    from pounding.studies.common import check_duration, record_values, study_sweep

    path = os.path.abspath(os.fspath(model))

    base = load_model(model)                # the model's own errors, with its file name
    base.refuse_building_records("pounding compare (it runs the model under one record at a time)")
    if not any(isinstance(g.law, HertzDamp) for g in base.gaps):
        raise PoundingError(f"{os.fspath(model)}: the model has no hertz-damp contacts; xi formulas apply only to "
                            "law hertz-damp")
    keys = _formulas(formulas, reference)
    axes: dict[str, Any] = {"xi": keys}
    listed = record_values(records)
    if listed is not None:
        axes["records"] = listed
    document: dict[str, Any] = {"name": f"compare-{Path(path).stem}", "model": path, "axes": axes}
    if check_duration(duration) is not None:
        document["set"] = {"ground_motion.duration": float(duration)}
    return study_sweep(document, f"<compare {os.fspath(model)}>")


def compare(model: str | os.PathLike, formulas: str | list[str] = ("ye", "lankarani-nikravesh", "exact"),
            records: str | list[str] | None = None, *, output: str | os.PathLike | None = None,
            duration: float | None = None, reference: str = REFERENCE, **run_options):
    """Run the comparison and return the sweep results dataset (dims ``xi``, ``record``, ...).

    Parameters
    ----------
    model : path-like
        The YAML model (with at least one hertz-damp contact).
    formulas : str or list of str
        ξ formulas; the reference is added if missing.
    records : str or list of str, optional
        Record specs or a set (``fema-p695:farfield``); default: the model's record.
    output : path-like, optional
        NetCDF file for the results (resumable, like ``pounding sweep``).
    duration : float, optional
        Simulated time, s.
    run_options
        Passed to :func:`pounding.studies.sweep.execution.run_sweep` (workers, scheduler, client, progress, overwrite...).
    """
    from pounding.studies.sweep.execution import run_sweep

    sweep = build_sweep(model, formulas, records, duration=duration, reference=reference)
    ds = run_sweep(sweep, output, **run_options)
    ds.attrs["reference_xi"] = reference
    return ds


def differences(ds, reference: str = REFERENCE):
    """``(d − d_ref) / d_ref`` of the peak drift ratios, per formula, record and storey."""
    ref = ds.peak_drift_ratio.sel(xi=reference)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (ds.peak_drift_ratio - ref) / ref


def _buildings(ds) -> list[str]:
    return list(dict.fromkeys(str(b) for b in ds.storey_building.values))


def comparison_table(ds, reference: str = REFERENCE) -> str:
    """The per-building text table printed by ``pounding compare``."""
    formulas = [str(x) for x in ds.xi.values]
    records = [str(r) for r in ds.record.values]
    ok = (ds.status == "ok")
    lines = [f"xi formulas compared over {len(records)} record{'s' if len(records) != 1 else ''}: "
             + ", ".join(records[:4]) + (f", ... ({len(records)} in all)" if len(records) > 4 else "")]
    failed = int((~ok).sum())
    if failed:
        from pounding.studies.sweep.execution import failure_report

        lines.append(f"{failed} of {ok.size} scenario(s) failed and are left out of the means below:")
        lines += failure_report(ds)
    rel = differences(ds, reference)
    drift = ds.peak_drift_ratio
    for building in _buildings(ds):
        mask = (ds.storey_building == building).values
        d = drift.isel(storey=mask)
        r = rel.isel(storey=mask)
        levels = ds.storey_level.values[mask]
        lines.append("")
        lines.append(f"building {building}: peak storey drift ratio, % (mean over records); "
                     f"[mean, max |.|] over records of the difference from {reference}, % of {reference}; "
                     "max = largest storey drift of the building")
        cells = {}
        for f in formulas:
            mean = d.sel(xi=f).mean("record", skipna=True).values * 100
            if f == reference:
                cells[f] = [f"{m:.4f}" for m in mean]
                continue
            dm = r.sel(xi=f).mean("record", skipna=True).values * 100
            dx = np.abs(r.sel(xi=f)).max("record", skipna=True).values * 100
            cells[f] = [f"{m:.4f} [{a:+.1f}, {b:.1f}]" for m, a, b in zip(mean, dm, dx)]
        # the building's largest storey drift, per record, then averaged
        peak = d.max("storey", skipna=True)
        peak_ref = peak.sel(xi=reference)
        with np.errstate(invalid="ignore", divide="ignore"):
            peak_rel = (peak - peak_ref) / peak_ref
        for f in formulas:
            m = float(peak.sel(xi=f).mean("record", skipna=True)) * 100
            if f == reference:
                cells[f].append(f"{m:.4f}")
            else:
                a = float(peak_rel.sel(xi=f).mean("record", skipna=True)) * 100
                b = float(np.abs(peak_rel.sel(xi=f)).max("record", skipna=True)) * 100
                cells[f].append(f"{m:.4f} [{a:+.1f}, {b:.1f}]")
        rows = [f"{int(lv)}" for lv in levels] + ["max"]   # max: the building's largest storey drift
        widths = [max(len(f), *(len(c) for c in cells[f])) for f in formulas]
        lines.append("  storey  " + "  ".join(f"{f:>{w}}" for f, w in zip(formulas, widths)))
        for i, row in enumerate(rows):
            lines.append(f"  {row:>6}  " + "  ".join(f"{cells[f][i]:>{w}}" for f, w in zip(formulas, widths)))
    return "\n".join(lines)


def reference_formula(ds) -> str:
    """The formula a compare archive is compared with (``exact`` unless it was not run: then the last one)."""
    formulas = [str(x) for x in ds.xi.values]
    reference = str(ds.attrs.get("reference_xi", REFERENCE))
    return reference if reference in formulas else formulas[-1]


def compare_tables(ds, reference: str | None = None) -> dict:
    """Tables of a compare archive: those of a sweep (:func:`pounding.results.tables.sweep_tables`), the
    storey table with ``difference_from_REFERENCE [-]``, (d − d_ref) / d_ref of each record (see
    :func:`differences`), when the archive has an ``xi`` dimension holding *reference*
    (default :func:`reference_formula`)."""
    from pounding.results.tables import sweep_tables

    tables = sweep_tables(ds)
    if reference is None and "xi" in ds.dims:
        reference = reference_formula(ds)
    if "xi" in ds.dims and reference in [str(x) for x in ds.xi.values]:
        column = differences(ds, reference).transpose(*ds.peak_drift_ratio.dims).values.ravel()
        tables["storeys"][f"difference_from_{reference} [-]"] = column
    return tables


def plot_comparison(ds, directory: str | os.PathLike, reference: str = REFERENCE, *,
                    drift_limit: float | None = None) -> list[Path]:
    """Write ``xi_drift_profiles.png`` and ``xi_drift_distribution.png`` to *directory*.

    The profiles are drawn as ``pounding run --plot`` draws them (x from 0,
    integer storey ticks); *drift_limit*, in %, adds a limit line.  With
    fewer than 3 records the distribution is a strip plot (every record a
    dot), not boxes.
    """
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
        ref = peak.sel(xi=reference)
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = (peak - ref) / ref * 100
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
