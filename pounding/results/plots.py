"""PNG plots of a results dataset (matplotlib, non-interactive Agg backend).

:func:`plot_run` writes four figures:

``contact_displacements.png``
    Displacement histories of each pair of contacting floors; the right
    floor is drawn shifted by the gap, so the curves touch where the gap
    closes.
``contact_forces.png``
    Contact-force history of each gap element, impacts marked.
``drift_profiles.png``
    Peak drift ratio per storey, one panel per building.
``force_penetration.png``
    Force against penetration for each gap element, from the full-resolution
    contact trace (the hysteresis loops of the impacts).
``storey_hysteresis.png``
    Only for a model with yielding storeys: storey shear against drift
    ratio for the most-yielded storeys (largest peak ductility), yield
    levels dashed; a collapse is marked.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from pounding.errors import PoundingError
from pounding.results.describe import run_title

__all__ = ["plot_run", "plot_sweep", "plot_directory", "save_figure", "pyplot", "suptitle", "storey_spans", "draw_drift_profile",
           "finish_drift_axes", "finish_profile_panel", "hysteresis_storeys", "hysteresis_left_out", "LOOPS_SHOWN",
           "sweep_axis_is_numeric"]


def pyplot():
    """``matplotlib.pyplot`` on the non-interactive Agg backend (imported on first use: it is slow)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def suptitle(fig, text: str, fontsize: float = 9):
    """*fig*'s title, each line wrapped to the figure's width (a title states the record and the intensity,
    which makes it long); returns the matplotlib ``Text``."""
    import textwrap

    width = max(40, int(fig.get_figwidth() * 72 / (0.52 * fontsize)))
    lines = [piece for line in text.split("\n") for piece in (textwrap.wrap(line, width) or [""])]
    return fig.suptitle("\n".join(lines), fontsize=fontsize)


def save_figure(fig, path: str | os.PathLike) -> Path:
    """Lay out *fig*, write it to *path* (PNG, 110 dpi) and close it; returns the path."""
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return Path(path)


def _grid(plt, count: int, *, width: float = 9.0, height: float = 2.2, sharex: bool = True):
    fig, axes = plt.subplots(max(count, 1), 1, figsize=(width, 1.0 + height * max(count, 1)),
                             sharex=sharex, squeeze=False)
    return fig, axes[:, 0]


def _side_displacement(ds: xr.Dataset, i: int, side: str) -> tuple[str, np.ndarray]:
    """Label and displacement history (m) of one side of contact *i*: a floor, a wall (0) or a column point.

    A column point at fraction ξ of storey s moves as ``N1·u_(s−1) + N2·u_s``
    (Hermite shape functions of the fixed-fixed column, docs/physics.md §12).
    """
    building = str(ds[f"building_{side}"].values[i])
    level = int(ds[f"level_{side}"].values[i])
    if building == "wall":
        return "wall", np.zeros(ds.sizes["time"])
    at_name = f"at_{side}"
    at = float(ds[at_name].values[i]) if at_name in ds.coords else float("nan")
    if np.isnan(at):
        return f"{building}:{level}", ds.displacement.sel(floor=f"{building}:{level}").values
    n2 = at * at * (3.0 - 2.0 * at)
    above = ds.displacement.sel(floor=f"{building}:{level}").values
    below = ds.displacement.sel(floor=f"{building}:{level - 1}").values if level > 1 else 0.0 * above
    return f"{building} storey {level} at {at:g}", (1.0 - n2) * below + n2 * above


def _contact_displacements(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    fig, axes = _grid(plt, n)
    t = ds.time.values
    for i, ax in enumerate(axes[:n]):
        left_name, left = _side_displacement(ds, i, "left")
        right_name, right = _side_displacement(ds, i, "right")
        gap = float(ds.gap.values[i])
        ax.plot(t, 1e3 * left, lw=0.8, label=f"{left_name} (left)")
        ax.plot(t, 1e3 * (right + gap), lw=0.8, label=f"{right_name} (right) + gap")
        hits = ds.impact_time.values[ds.impact_contact.values == i]
        if hits.size:
            ax.plot(hits, 1e3 * np.interp(hits, t, left), "k|", ms=10, label="impact")
        ax.set_ylabel("displacement (mm)")
        ax.set_title(f"{ds.contact.values[i]}, gap {1e3 * gap:.1f} mm", fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
    if n == 0:
        axes[0].text(0.5, 0.5, "no contacts in this model", ha="center", transform=axes[0].transAxes)
    axes[-1].set_xlabel("time (s)")
    suptitle(fig, f"contact displacements — {run_title(ds)}", fontsize=9)
    save_figure(fig, path)


def _contact_forces(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    fig, axes = _grid(plt, n)
    output_dt = float(ds.attrs.get("solver_output_dt", 0.01))
    for i, ax in enumerate(axes[:n]):
        mask = ds.trace_contact.values == i
        # The trace holds every solver sample of a closed contact; join it with
        # zeros between impacts so the plot shows the true peaks.
        t = ds.trace_time.values[mask]
        f = ds.trace_force.values[mask]
        impacts = int(ds.impact_count.values[i])
        if impacts == 0 or t.size == 0:
            ax.text(0.5, 0.5, "no impacts: the gap never closed", ha="center", va="center",
                    transform=ax.transAxes, fontsize=9, color="0.3")
            ax.set_ylim(0.0, 1.0)
            ax.set_xlim(0.0, float(ds.time.values[-1]))
            ax.set_yticks([])
            ax.set_title(f"{ds.contact.values[i]}: no impacts", fontsize=9)
            continue
        order = np.argsort(t, kind="stable")
        t, f = t[order], f[order]
        breaks = np.flatnonzero(np.diff(t) > 2.0 * output_dt)
        t = np.insert(t, breaks + 1, np.nan)
        f = np.insert(f, breaks + 1, np.nan)
        # Only the trace (every solver step of a closed contact): impacts last a
        # few ms, so contact_force, sampled every output_dt, misses most peaks.
        ax.plot(t, f / 1e6, lw=0.8, color="C3")
        ax.set_xlim(0.0, float(ds.time.values[-1]))
        ax.set_ylim(bottom=0.0)
        ax.set_ylabel("force (MN)")
        ax.set_title(f"{ds.contact.values[i]}: {impacts} impacts, "
                     f"peak {float(ds.peak_contact_force.values[i]) / 1e6:.3g} MN", fontsize=9)
    if n == 0:
        axes[0].text(0.5, 0.5, "no contacts in this model", ha="center", transform=axes[0].transAxes)
    axes[-1].set_xlabel("time (s)")
    suptitle(fig, f"contact forces (every solver step: trace_force) — {run_title(ds)}", fontsize=9)
    save_figure(fig, path)


def storey_spans(ds: xr.Dataset, building: str, *, elevation: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Bottom and top of each storey of *building* on a drift profile's vertical axis.

    Storey k spans k−1 … k (storey numbers), or the elevations of the floors
    below and above it, m (``elevation=True``).
    """
    mask = (ds.storey_building == building).values
    if elevation:
        top = np.cumsum(ds.height.values[mask].astype(float))
        return np.r_[0.0, top[:-1]], top
    levels = ds.storey_level.values[mask].astype(float)
    return levels - 1.0, levels


def draw_drift_profile(ax, bottom: np.ndarray, top: np.ndarray, ratio_pct: np.ndarray, **style) -> None:
    """One drift profile: a vertical segment per storey at its drift ratio (%), joined, dot at mid-height."""
    ax.plot(np.repeat(ratio_pct, 2), np.column_stack([bottom, top]).ravel(), **style)
    ax.plot(ratio_pct, (bottom + top) / 2, "o", color=style.get("color"), ms=3.5)


def finish_drift_axes(ax, bottom: np.ndarray, top: np.ndarray, *, elevation: bool = False,
                      drift_limit: float | None = None, xlabel: str = "peak storey drift ratio (%)",
                      ymax: float | None = None) -> None:
    """Axes of a drift profile: x from 0, integer storey ticks (or elevation, m), optional limit line (%)."""
    from matplotlib.ticker import MaxNLocator

    ax.set_xlim(left=0.0)
    if drift_limit is not None:
        ax.axvline(drift_limit, color="C3", lw=1.2, ls="--", label=f"limit {drift_limit:g} %")
        ax.set_xlim(0.0, max(ax.get_xlim()[1], 1.1 * drift_limit))
    ax.set_ylim(0.0, float(top.max()) if ymax is None else ymax)
    if elevation:
        ax.set_ylabel("elevation (m)")
    else:
        n = top.size
        step = max(1, int(np.ceil(n / 12)))   # at most about 12 labels
        ticks = np.arange(1, n + 1)[::step]
        ax.set_yticks(ticks - 0.5)
        ax.set_yticklabels([str(k) for k in ticks])
        ax.set_ylabel("storey")
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.set_xlabel(xlabel)
    ax.grid(alpha=0.3)


def finish_profile_panel(ax, xlabel: str, ylabel: str, title: str, *, title_size: float,
                         right: float | None = None) -> None:
    """Dress a panel of a quantity against height (a study's profile or curve).

    Both axes start at 0 (x up to *right* if given), then the labels, the title (font size *title_size*,
    points), a light grid and the legend at the lower right.
    """
    ax.set_xlim(0, right)
    ax.set_ylim(bottom=0)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=title_size)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")


def _drift_profiles(plt, ds: xr.Dataset, path: Path, *, drift_limit: float | None = None,
                    elevation: bool = False) -> None:
    names = list(dict.fromkeys(ds.storey_building.values.tolist()))
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names) + 0.4, 4.5), squeeze=False, sharex=True)
    tallest = max(float(storey_spans(ds, name, elevation=True)[1].max()) for name in names) if elevation else None
    for ax, name in zip(axes[0], names):
        sel = ds.peak_drift_ratio.where(ds.storey_building == name, drop=True)
        bottom, top = storey_spans(ds, name, elevation=elevation)
        draw_drift_profile(ax, bottom, top, 100 * sel.values, color="C0", lw=1.4)
        peak = 100 * float(sel.max())
        ax.set_title(f"building {name}: max {peak:.2f} %", fontsize=9)
        finish_drift_axes(ax, bottom, top, elevation=elevation, drift_limit=drift_limit, ymax=tallest)
    if drift_limit is not None:
        axes[0][-1].legend(fontsize=7, loc="lower right")
    suptitle(fig, f"peak storey drift ratio — {run_title(ds)}", 9)
    save_figure(fig, path)


def _force_penetration(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    cols = min(max(n, 1), 3)
    rows = int(np.ceil(max(n, 1) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.2 * rows), squeeze=False)
    for i in range(rows * cols):
        ax = axes[i // cols][i % cols]
        if i >= n:
            ax.axis("off")
            continue
        mask = ds.trace_contact.values == i
        pen = ds.trace_penetration.values[mask]
        force = ds.trace_force.values[mask]
        t = ds.trace_time.values[mask]
        ax.set_title(str(ds.contact.values[i]), fontsize=9)
        if int(ds.impact_count.values[i]) == 0 or pen.size == 0:
            ax.text(0.5, 0.5, "no impacts", ha="center", va="center", transform=ax.transAxes, color="0.3")
            ax.set_xticks([])
            ax.set_yticks([])
            continue
        breaks = np.flatnonzero(np.diff(t) > 2.0 * float(ds.attrs.get("solver_output_dt", 0.01)))
        pen = np.insert(pen, breaks + 1, np.nan)
        force = np.insert(force, breaks + 1, np.nan)
        ax.plot(1e3 * np.where(pen > 0, pen, 0.0), force / 1e6, lw=0.8)
        ax.set_xlim(left=0.0)
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel("penetration (mm)")
        ax.set_ylabel("force (MN)")
        ax.set_title(f"{ds.contact.values[i]}: peak {float(ds.peak_contact_force.values[i]) / 1e6:.3g} MN",
                     fontsize=9)
        ax.grid(alpha=0.3)
    suptitle(fig, f"force-penetration loops (full solver resolution) — {run_title(ds)}", 9)
    save_figure(fig, path)


#: Storeys shown in ``storey_hysteresis.png`` (the most yielded first).
LOOPS_SHOWN = 6


def hysteresis_storeys(ds: xr.Dataset) -> tuple[list[int], list[int]]:
    """Positions of the yielding storeys drawn in ``storey_hysteresis.png`` (the :data:`LOOPS_SHOWN` most
    yielded, largest peak ductility first) and of those it leaves out (same order)."""
    ductility = np.nan_to_num(ds.peak_ductility.values, nan=-1.0)
    ranked = [int(i) for i in np.argsort(-ductility, kind="stable") if ductility[i] >= 0]
    return ranked[:LOOPS_SHOWN], ranked[LOOPS_SHOWN:]


def hysteresis_left_out(ds: xr.Dataset) -> str:
    """The note naming the yielding storeys the hysteresis figure leaves out, with their ductility ("" if none)."""
    _, rest = hysteresis_storeys(ds)
    if not rest:
        return ""
    names = ", ".join(f"{ds.storey.values[i]} ({float(ds.peak_ductility.values[i]):.2f})" for i in rest)
    return (f"not shown: {len(rest)} less yielded storey{'s' if len(rest) != 1 else ''} (peak ductility): {names}; "
            "every storey's values are in `pounding table`")


def _storey_hysteresis(plt, ds: xr.Dataset, path: Path) -> None:
    ductility = np.nan_to_num(ds.peak_ductility.values, nan=-1.0)
    order, _ = hysteresis_storeys(ds)
    cols = min(len(order), 3)
    rows = int(np.ceil(len(order) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.2 * rows), squeeze=False)
    for slot in range(rows * cols):
        ax = axes[slot // cols][slot % cols]
        if slot >= len(order):
            ax.axis("off")
            continue
        i = order[slot]
        height = float(ds.height.values[i])
        ratio = 100.0 * ds.storey_drift.values[:, i] / height
        shear = ds.storey_shear.values[:, i] / 1e6
        ax.plot(ratio, shear, lw=0.7)
        yield_force = float(ds.yield_force.values[i]) / 1e6
        ax.axhline(yield_force, color="0.5", ls="--", lw=0.7)
        ax.axhline(-yield_force, color="0.5", ls="--", lw=0.7)
        ax.axhline(0.0, color="0.8", lw=0.6)
        ax.axvline(0.0, color="0.8", lw=0.6)
        ax.set_xlabel("storey drift ratio (%)")
        ax.set_ylabel("storey shear (MN)")
        ax.set_title(f"storey {ds.storey.values[i]}: ductility {ductility[i]:.2f}, "
                     f"residual {100 * float(ds.residual_drift_ratio.values[i]):+.2f} %", fontsize=8)
        ax.grid(alpha=0.3)
    title = f"storey hysteresis — {run_title(ds)}\n(column shear, without P-Delta and damping; dashed: yield force ±F_y)"
    if ds.attrs.get("status") in ("collapsed", "unstable"):
        title += (f" - {ds.attrs['status'].upper()} at {ds.attrs['collapse_time']:.2f} s "
                  f"(storey {ds.attrs['collapse_storey']})")
    left_out = hysteresis_left_out(ds)
    suptitle(fig, title + (f"\n{left_out}" if left_out else ""), fontsize=8)
    save_figure(fig, path)


def plot_run(ds: xr.Dataset, directory: str | os.PathLike, *, drift_limit: float | None = None,
             elevation: bool = False) -> list[Path]:
    """Write the standard figures of a run to *directory* (created if needed).

    Four figures always; ``storey_hysteresis.png`` too when storeys yield.

    Parameters
    ----------
    drift_limit : float, optional
        A drift-ratio limit, in %, drawn on the drift profiles.
    elevation : bool
        Drift profiles against floor elevation (m) instead of storey number.

    Returns
    -------
    list of pathlib.Path
        The PNG files written.
    """
    out = plot_directory(directory)
    plt = pyplot()
    written = []
    for name, draw in (("contact_displacements.png", _contact_displacements),
                       ("contact_forces.png", _contact_forces),
                       ("drift_profiles.png", lambda p, d, f: _drift_profiles(p, d, f, drift_limit=drift_limit,
                                                                              elevation=elevation)),
                       ("force_penetration.png", _force_penetration)):
        path = out / name
        draw(plt, ds, path)
        written.append(path)
    if "peak_ductility" in ds and bool(np.isfinite(ds.peak_ductility.values).any()):
        path = out / "storey_hysteresis.png"
        _storey_hysteresis(plt, ds, path)
        written.append(path)
    return written


def plot_directory(directory: str | os.PathLike) -> Path:
    """The ``--plot`` folder, created if missing; refused in one line if it is a file."""
    out = Path(directory)
    if out.exists() and not out.is_dir():
        raise PoundingError(f"{out} is a file; --plot needs a directory")
    out.mkdir(parents=True, exist_ok=True)
    return out


def sweep_axis_is_numeric(ds: xr.Dataset, dim: str) -> bool:
    """Whether sweep dimension *dim* holds numbers (drawn on a numeric axis) rather than labels (records, formulas)."""
    return dim != "record" and np.issubdtype(ds[dim].values.dtype, np.number) and \
        not np.issubdtype(ds[dim].values.dtype, np.bool_)


def plot_sweep(ds: xr.Dataset, directory: str | os.PathLike) -> list[Path]:
    """``sweep_peak_drift.png``: each building's largest peak storey drift ratio against each sweep axis.

    One row per sweep dimension (``record`` excluded when it has one value);
    a line per building at the mean over the other dimensions, with a band
    from their minimum to their maximum.  A dimension of numbers is drawn on
    a numeric axis (logarithmic when its values span two decades or more);
    records and other labels as markers at evenly spaced ticks, with a bar
    from minimum to maximum.  Failed scenarios are left out.
    """
    out = plot_directory(directory)
    plt = pyplot()
    names = list(dict.fromkeys(str(b) for b in ds.storey_building.values))
    dims = [d for d in ds.status.dims if ds.sizes[d] > 1] or list(ds.status.dims[:1])
    fig, axes = plt.subplots(len(dims), 1, figsize=(6.4, 2.6 * len(dims) + 0.6), squeeze=False)
    drift = ds.peak_drift_ratio.where(ds.status == "ok") * 100
    for ax, dim in zip(axes[:, 0], dims):
        labels = [str(v) for v in ds[dim].values]
        numeric = sweep_axis_is_numeric(ds, dim)
        x = ds[dim].values.astype(float) if numeric else np.arange(len(labels))
        for k, name in enumerate(names):
            largest = drift.isel(storey=(ds.storey_building == name).values).max("storey", skipna=True)
            others = [d for d in largest.dims if d != dim]
            mean = largest.mean(others, skipna=True).values if others else largest.values
            # numbers: a line on a numeric axis; records and other labels: markers only (no order between
            # them), the buildings side by side
            where = x if numeric else x + 0.1 * (k - (len(names) - 1) / 2)
            ax.plot(where, mean, "o-" if numeric else "o", color=f"C{k}", label=f"building {name}", ms=4)
            if others and numeric:
                ax.fill_between(x, largest.min(others, skipna=True).values, largest.max(others, skipna=True).values,
                                color=f"C{k}", alpha=0.15, lw=0)
            elif others:
                ax.vlines(where, largest.min(others, skipna=True).values, largest.max(others, skipna=True).values,
                          color=f"C{k}", alpha=0.4, lw=3)
        if numeric:
            if x.min() > 0 and x.max() >= 100 * x.min():   # values over decades (a stiffness): log axis
                ax.set_xscale("log")
        else:
            ax.set_xticks(x)
            ax.set_xticklabels(labels, rotation=20 if max(len(t) for t in labels) > 6 else 0, ha="right"
                               if max(len(t) for t in labels) > 6 else "center", fontsize=7)
            ax.set_xlim(-0.5, len(labels) - 0.5)
        units = ds[dim].attrs.get("units", "")
        ax.set_xlabel(f"{dim} ({units})" if units and units != "1" else dim)
        ax.set_ylabel("largest peak storey\ndrift ratio (%)", fontsize=8)
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    failed = int((ds.status != "ok").sum())
    suptitle(fig, f"{ds.attrs.get('title', '')}\nmean over the other dimensions, band (bar) = min-max"
                 + (f"; {failed} failed scenario(s) left out" if failed else ""), 8)
    path = out / "sweep_peak_drift.png"
    save_figure(fig, path)
    return [path]
