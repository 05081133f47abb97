"""An IDA's report: its JSON summary, the printed table and the plots."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from pounding.studies.ida.dataset import exceeds
from pounding.studies.ida.schedule import SA_DAMPING
from pounding.units import STANDARD_GRAVITY

__all__ = ["ida_summary", "ida_table", "ida_tables", "plot_ida"]



def _drift_of(ds) -> str:
    """What reaches a collapse drift ratio in the IDA's buildings: a ``storey``, or a ``plane`` of a storey for
    floors in plan (their archive has the ``plane`` dimension; docs/ida.md)."""
    return "plane" if "plane" in ds.dims else "storey"

def ida_summary(ds) -> dict[str, Any]:
    """The study as one JSON-ready document: ``{"im", "fragility", "cmr"}`` (θ and IMs in g)."""
    from pounding.studies.common import finite_or_none

    fragility = {}
    for i, variant in enumerate(ds.variant.values):
        fragility[str(variant)] = {}
        for b, building in enumerate(ds.building.values):
            fragility[str(variant)][str(building)] = {
                str(label): {"theta": finite_or_none(ds.fragility_theta.values[i, b, k] / STANDARD_GRAVITY),
                             "beta": finite_or_none(ds.fragility_beta.values[i, b, k])}
                for k, label in enumerate(ds.fragility_limit.values)}
    im = {"name": ds.attrs["im"], "units": "g", "scaling": ds.attrs["scaling"], "method": ds.attrs["method"]}
    if ds.attrs["im"] == "sa-t1":
        im.update(building=ds.attrs["im_building"], period=float(ds.attrs["im_period"]), damping=SA_DAMPING)
    out: dict[str, Any] = {"im": im, "fragility": fragility}
    mce = float(ds.attrs.get("mce", float("nan")))
    if math.isfinite(mce):
        from pounding.studies.fragility import collapse_margin_ratio

        collapse = list(ds.fragility_limit.values).index("collapse")
        out["cmr"] = {str(v): {str(b): finite_or_none(collapse_margin_ratio(ds.fragility_theta.values[i, k, collapse], mce))
                               for k, b in enumerate(ds.building.values)}
                      for i, v in enumerate(ds.variant.values)}
        out["mce"] = mce / STANDARD_GRAVITY
    failed = {}
    for index in np.ndindex(ds.status.shape):
        if ds.status.values[index] == "failed":
            v, r, j = index
            failed.setdefault(str(ds.error.values[index]), []).append(
                f"{ds.variant.values[v]}, {ds.record.values[r]}, level {j}")
    if failed:
        out["failed"] = failed
    return out


def _g(value: float | None, digits: int = 3) -> str:
    return "-" if value is None or not math.isfinite(value) else f"{value:.{digits}f}"


def _collapse_drifts(ds) -> np.ndarray:
    """Each building's collapse drift ratio in the study (an archive before them: the one ``collapse_drift``)."""
    if "collapse_drift_ratio" in ds:
        return np.asarray(ds.collapse_drift_ratio.values, dtype=float)
    return np.full(ds.building.size, float(ds.attrs["collapse_drift"]))


def _collapse_line(ds) -> str:
    """How a building collapses in this study: its collapse ending the run, or its drift past its limit."""
    if "collapse_drift_ratio" not in ds:
        return f"collapse: run status collapsed, or max storey drift ratio >= {ds.attrs['collapse_drift']:g}"
    sources = str(ds.collapse_drift_ratio.attrs.get("source", "")).split("; ")
    each = ", ".join(f"{b} {x:g}" + (f" ({sources[k]})" if k < len(sources) and sources[k] else "")
                     for k, (b, x) in enumerate(zip(ds.building.values, _collapse_drifts(ds))))
    censored = int(ds.censored.values.sum()) if "censored" in ds else 0
    drifts = _drift_of(ds)
    return (f"collapse: a {drifts} past its building's collapse drift ratio ({each}), an IMK {drifts} at zero "
            f"strength, or a loss of resistance to P-Delta; the first building to collapse ends the run, the "
            f"others are censored there ({censored} building-runs censored)")


def ida_table(ds) -> str:
    """The printed summary: θ (g) and β per building, limit and variant, and the change of θ due to pounding."""
    summary = ida_summary(ds)
    status = ds.status.values
    counts = {s: int((status == s).sum()) for s in ("completed", "collapsed", "failed")}
    variants = [str(v) for v in ds.variant.values]
    lines = [f"IDA of {ds.attrs.get('model_name') or ds.attrs['title'].split(': ', 1)[-1]}: {ds.record.size} records, "
             f"{ds.attrs['method']}, {status.size if ds.attrs['method'] == 'stripes' else ds.attrs['n_runs']} runs "
             f"({counts['completed']} completed, {counts['collapsed']} collapsed, {counts['failed']} failed)",
             f"IM: {ds.attrs['im_description']}, in g; scaling: "
             + ("FEMA P695 (records normalised, the set's median IM at the level)"
                if ds.attrs["scaling"] == "fema-p695" else "each record to the level"),
             _collapse_line(ds),
             "fragility P(exceed | IM) = Phi(ln(IM/theta)/beta), "
             + ("maximum likelihood on the stripe counts" if ds.attrs["method"] == "stripes"
                else "from each record's intensity at the limit")]
    head = f"{'building':<9} {'limit':<9}" + "".join(f" {v + ' theta':>22} {'beta':>6}" for v in variants)
    if len(variants) == 2:
        head += f" {'pounding: theta change':>23}"
    lines.append(head)
    notes = []
    for building in ds.building.values:
        for label in ds.fragility_limit.values:
            row = f"{str(building):<9} {str(label):<9}"
            thetas = []
            for v in variants:
                entry = summary["fragility"][v][str(building)][str(label)]
                thetas.append(entry["theta"])
                row += f" {_g(entry['theta']):>22} {_g(entry['beta'], 2):>6}"
                note = ds.fragility_note.sel(variant=v, building=building, fragility_limit=label).item()
                if note:
                    notes.append(f"  {v}, {building}, {label}: {note}")
            if len(variants) == 2:
                a, b = thetas
                change = "-" if a is None or b is None else f"{100 * (a / b - 1):+.1f} %"
                row += f" {change:>23}"
            lines.append(row)
    if len(variants) == 2:
        lines.append("pounding: theta change = theta with contacts / theta without - 1 (negative: pounding makes "
                     "the limit easier to reach)")
    if "cmr" in summary:
        lines.append(f"collapse margin ratio CMR = theta(collapse) / S_MT, S_MT = {summary['mce']:.3f} g: "
                     + "; ".join(f"{v}: " + ", ".join(f"{b} {'not determinable' if x is None else _g(x, 2)}"
                                                      for b, x in summary["cmr"][v].items())
                                 for v in variants))
    if notes:
        lines.append("not fitted or partly fitted:")
        lines += notes
    return "\n".join(lines)


def ida_tables(ds) -> dict:
    """Tables of an IDA archive: ``fragility`` (θ in m s-2 and in g, β, the note, per variant, building
    and limit) and ``runs`` (per variant, record, level and building: the intensity reached, the scale
    factor, the status, the largest storey drift ratio and whether the building collapsed)."""
    from pounding.results.tables import long_table

    fragility = long_table(ds, ["fragility_theta", "fragility_beta", "fragility_note"])
    fragility.insert(fragility.columns.get_loc("fragility_theta [m s-2]") + 1, "fragility_theta [g]",
                     fragility["fragility_theta [m s-2]"] / STANDARD_GRAVITY)
    extra = [n for n in ("level_value", "intensity", "scale_factor", "status") if n in ds.variables]
    return {"fragility": fragility, "runs": long_table(ds, ["max_drift_ratio", "collapsed"], extra=extra)}


# --------------------------------------------------------------------------- #
# Plots
# --------------------------------------------------------------------------- #


def _curve(ds, i: int, r: int, b: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One record's IDA curve: levels (g, sorted), max drift, collapsed flags (runs that ran)."""
    if ds.attrs["method"] == "stripes":
        levels = ds.level.values / STANDARD_GRAVITY
    else:
        levels = ds.level_value.values[i, r] / STANDARD_GRAVITY
    ok = np.isin(ds.status.values[i, r], ("completed", "collapsed")) & np.isfinite(levels)
    drift = ds.max_drift_ratio.values[i, r, :, b]
    collapsed = ds.collapsed.values[i, r, :, b].astype(bool)
    order = np.argsort(levels[ok])
    return levels[ok][order], drift[ok][order], collapsed[ok][order]


def _im_label(ds) -> str:
    return "PGA" if ds.attrs["im"] == "pga" else f"Sa(T1 of {ds.attrs['im_building']})"


def plot_ida(ds, directory: str | os.PathLike) -> list[Path]:
    """``ida_curves.png`` (IM against max drift ratio per record, median and 16/84 % stripes, per variant) and
    ``fragility.png`` (fitted curves with the stripe fractions as points), per building."""
    from scipy.special import ndtr

    from pounding.results.plots import finish_profile_panel, plot_directory, pyplot, save_figure, suptitle

    plt = pyplot()
    out = plot_directory(directory)
    variants = [str(v) for v in ds.variant.values]
    buildings = [str(b) for b in ds.building.values]
    stripes = ds.attrs["method"] == "stripes"
    collapse_drifts = _collapse_drifts(ds)
    titles = {"with_contacts": "with contacts (pounding)", "without_contacts": "contacts held open"}
    paths = []

    # IDA curves: one row per building, one column per variant
    fig, axes = plt.subplots(len(buildings), len(variants), figsize=(5.4 * len(variants), 4.2 * len(buildings)),
                             squeeze=False, sharey=True)
    largest = float(np.nanmax(ds.max_drift_ratio.values, initial=0.0))
    widest = float(np.max(collapse_drifts))
    top = 115 * widest if largest >= 0.5 * widest else 120 * max(largest, 1e-6)
    for b, building in enumerate(buildings):
        collapse_drift = float(collapse_drifts[b])
        for i, variant in enumerate(variants):
            ax = axes[b, i]
            collapse_labelled = False
            for r in range(ds.record.size):
                levels, drift, collapsed = _curve(ds, i, r, b)
                if levels.size == 0:
                    continue
                shown = np.where(collapsed, top, 100 * np.minimum(drift, top / 100))
                ax.plot(shown, levels, color="0.65", lw=0.8, marker=".", ms=3,
                        label=None if any(line.get_label() == "one record" for line in ax.lines) else "one record")
                if collapsed.any():   # the legend names the marker with the first collapse drawn, whichever record
                    ax.plot(shown[collapsed][:1], levels[collapsed][:1], "x", color="C3", ms=6,
                            label=None if collapse_labelled else "collapse")
                    collapse_labelled = True
            if stripes:
                drift = np.where(ds.collapsed.values[i, :, :, b].astype(bool), np.inf,
                                 ds.max_drift_ratio.values[i, :, :, b])
                ok = np.isin(ds.status.values[i], ("completed", "collapsed"))
                levels = ds.level.values / STANDARD_GRAVITY
                for q, style, name in ((50, "-", "median"), (16, "--", "16 % and 84 %"), (84, "--", None)):
                    values = []
                    for j in range(levels.size):
                        column = drift[ok[:, j], j]
                        values.append(np.percentile(column, q, method="inverted_cdf") if column.size else np.nan)
                    values = np.array(values)
                    keep = np.isfinite(values)
                    ax.plot(100 * values[keep], levels[keep], style, color="k", lw=1.8 if q == 50 else 1.1,
                            label=name)
            if 100 * collapse_drift <= top:
                ax.axvline(100 * collapse_drift, color="C3", lw=0.8, ls=":", label="collapse drift")
            finish_profile_panel(ax, f"max {_drift_of(ds)} drift ratio of {building} (%)",
                                 f"{_im_label(ds)} level (g)", f"building {building}, {titles.get(variant, variant)}",
                                 title_size=10, right=top * 1.02)
    suptitle(fig, f"IDA curves, {ds.record.size} records; IM = {ds.attrs['im_description']}\n{ds.attrs.get('title', '')}",
                 9)
    path = out / "ida_curves.png"
    save_figure(fig, path)
    paths.append(path)

    # Fragility curves: one panel per building, a colour per limit, solid with contacts, dashed without
    summary = ida_summary(ds)
    fig, axes = plt.subplots(1, len(buildings), figsize=(5.8 * len(buildings), 5.6), squeeze=False)
    labels = [str(x) for x in ds.fragility_limit.values]
    limits = [float(x) for x in ds.limit.values] + [None]
    if stripes:
        grid_top = float(ds.level.values.max() / STANDARD_GRAVITY) * 1.1
    else:
        grid_top = float(np.nanmax(ds.level_value.values) / STANDARD_GRAVITY) * 1.1
    x = np.linspace(grid_top / 400, grid_top, 400)
    for b, building in enumerate(buildings):
        ax = axes[0, b]
        undetermined = [f"{variant}: {ds.fragility_note.values[i, b, -1]}" for i, variant in enumerate(variants)
                        if str(ds.fragility_note.values[i, b, -1]).startswith("not determinable")]
        if undetermined:   # marked, not drawn: no collapse curve from fewer observations than the fit needs
            from textwrap import fill

            ax.text(0.02, 0.98, "collapse fragility NOT DETERMINABLE\n" + "\n".join(fill(u, 70) for u in undetermined),
                    fontsize=6, va="top", ha="left", transform=ax.transAxes, color="C3",
                    bbox={"facecolor": "white", "edgecolor": "C3", "alpha": 0.9})
        for k, (label, limit) in enumerate(zip(labels, limits)):
            color = f"C{k}" if limit is not None else "k"
            name = f"{100 * limit:g} %" if limit is not None else "collapse"
            for i, variant in enumerate(variants):
                entry = summary["fragility"][variant][building][label]
                style = "-" if variant == "with_contacts" else "--"
                if entry["theta"] is not None:
                    ax.plot(x, ndtr(np.log(x / entry["theta"]) / entry["beta"]), style, color=color, lw=1.5,
                            label=f"{name}, {'contacts' if variant == 'with_contacts' else 'open'}: "
                                  f"\u03b8 {entry['theta']:.2f} g, \u03b2 {entry['beta']:.2f}")
                if stripes:
                    hit = exceeds(ds, limit)[i, :, :, b]
                    n = np.sum(np.isfinite(hit), axis=0)
                    with np.errstate(invalid="ignore", divide="ignore"):
                        fraction = np.nansum(hit, axis=0) / n
                    # points without a fitted curve still get their legend entry (a collapse drawn is named)
                    unfitted = None if entry["theta"] is not None else \
                        f"{name}, {'contacts' if variant == 'with_contacts' else 'open'}: not fitted"
                    ax.plot(ds.level.values / STANDARD_GRAVITY, fraction, "o", color=color, ms=4,
                            mfc=color if variant == "with_contacts" else "white", label=unfitted)
        ax.set_xlim(0, grid_top)
        ax.set_ylim(-0.02, 1.02)
        ax.set_xlabel(f"{_im_label(ds)} (g)")
        ax.set_ylabel("P(exceed | IM)")
        ax.set_title(f"building {building}: max {_drift_of(ds)} drift ratio > limit, or collapse"
                     + ("\npoints: fraction of records at each stripe (filled: with contacts, open: without)"
                        if stripes else "\nsolid: with contacts; dashed: contacts held open"), fontsize=9)
        ax.grid(alpha=0.3)
        handles, names = ax.get_legend_handles_labels()
        if handles:   # below the axes
            ax.legend(handles, names, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
                      frameon=False)
    suptitle(fig, f"fragility, {ds.record.size} records ({ds.attrs['method']})\n{ds.attrs.get('title', '')}", 9)
    path = out / "fragility.png"
    save_figure(fig, path)
    paths.append(path)
    return paths
