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
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from pounding.errors import PoundingError

__all__ = ["plot_run"]


def pyplot():
    """``matplotlib.pyplot`` on the non-interactive Agg backend (imported on first use: it is slow)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _grid(plt, count: int, *, width: float = 9.0, height: float = 2.2, sharex: bool = True):
    fig, axes = plt.subplots(max(count, 1), 1, figsize=(width, 1.0 + height * max(count, 1)),
                             sharex=sharex, squeeze=False)
    return fig, axes[:, 0]


def _contact_displacements(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    fig, axes = _grid(plt, n)
    t = ds.time.values
    for i, ax in enumerate(axes[:n]):
        left = ds.displacement.sel(floor=f"{ds.building_left.values[i]}:{int(ds.level_left.values[i])}")
        right = ds.displacement.sel(floor=f"{ds.building_right.values[i]}:{int(ds.level_right.values[i])}")
        gap = float(ds.gap.values[i])
        ax.plot(t, 1e3 * left.values, lw=0.8, label=f"{left.floor.item()} (left)")
        ax.plot(t, 1e3 * (right.values + gap), lw=0.8, label=f"{right.floor.item()} (right) + gap")
        hits = ds.impact_time.values[ds.impact_contact.values == i]
        if hits.size:
            ax.plot(hits, 1e3 * np.interp(hits, t, left.values), "k|", ms=10, label="impact")
        ax.set_ylabel("displacement (mm)")
        ax.set_title(f"{ds.contact.values[i]}, gap {1e3 * gap:.1f} mm", fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
    if n == 0:
        axes[0].text(0.5, 0.5, "no contacts in this model", ha="center", transform=axes[0].transAxes)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(ds.attrs.get("title", ""), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _contact_forces(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    fig, axes = _grid(plt, n)
    for i, ax in enumerate(axes[:n]):
        mask = ds.trace_contact.values == i
        # The trace holds every solver sample of a closed contact; join it with
        # zeros between impacts so the plot shows the true peaks.
        t = ds.trace_time.values[mask]
        f = ds.trace_force.values[mask]
        if t.size:
            order = np.argsort(t, kind="stable")
            t, f = t[order], f[order]
            breaks = np.flatnonzero(np.diff(t) > 2.0 * float(ds.attrs.get("solver_output_dt", 0.01)))
            t = np.insert(t, breaks + 1, np.nan)
            f = np.insert(f, breaks + 1, np.nan)
        ax.plot(ds.time.values, ds.contact_force.values[:, i] / 1e6, lw=0.5, color="0.7",
                label=f"sampled every {ds.attrs.get('solver_output_dt', '')} s")
        ax.plot(t, f / 1e6, lw=0.9, color="C3", label="full resolution")
        ax.set_ylabel("force (MN)")
        ax.set_title(f"{ds.contact.values[i]}: {int(ds.impact_count.values[i])} impacts, "
                     f"peak {float(ds.peak_contact_force.values[i]) / 1e6:.3g} MN", fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
    if n == 0:
        axes[0].text(0.5, 0.5, "no contacts in this model", ha="center", transform=axes[0].transAxes)
    axes[-1].set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _drift_profiles(plt, ds: xr.Dataset, path: Path) -> None:
    names = list(dict.fromkeys(ds.storey_building.values.tolist()))
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 4.5), squeeze=False, sharex=True)
    for ax, name in zip(axes[0], names):
        sel = ds.peak_drift_ratio.where(ds.storey_building == name, drop=True)
        levels = ds.storey_level.where(ds.storey_building == name, drop=True).values
        # Storey k spans heights k−1 … k on the vertical axis: a vertical
        # segment at its drift ratio, joined to the next storey's.
        ratio = 100 * sel.values
        ax.plot(np.repeat(ratio, 2), np.column_stack([levels - 1, levels]).ravel(), color="C0")
        ax.plot(ratio, levels - 0.5, "o", color="C0", ms=4)
        ax.set_title(f"building {name}", fontsize=9)
        ax.set_xlabel("peak drift ratio (%)")
        ax.set_ylim(0, levels.max())
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("storey")
    fig.suptitle(f"peak storey drift ratios — {ds.attrs.get('record_name', '')}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


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
        if pen.size:
            breaks = np.flatnonzero(np.diff(t) > 2.0 * float(ds.attrs.get("solver_output_dt", 0.01)))
            pen = np.insert(pen, breaks + 1, np.nan)
            force = np.insert(force, breaks + 1, np.nan)
        ax.plot(1e3 * np.where(pen > 0, pen, 0.0), force / 1e6, lw=0.8)
        ax.set_xlabel("penetration (mm)")
        ax.set_ylabel("force (MN)")
        ax.set_title(str(ds.contact.values[i]), fontsize=9)
        ax.grid(alpha=0.3)
    fig.suptitle("force-penetration loops (full solver resolution)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_run(ds: xr.Dataset, directory: str | os.PathLike) -> list[Path]:
    """Write the four standard figures of a run to *directory* (created if needed).

    Returns
    -------
    list of pathlib.Path
        The PNG files written.
    """
    out = Path(directory)
    if out.exists() and not out.is_dir():
        raise PoundingError(f"{out} is a file; --plot needs a directory")
    out.mkdir(parents=True, exist_ok=True)
    plt = pyplot()
    written = []
    for name, draw in (("contact_displacements.png", _contact_displacements),
                       ("contact_forces.png", _contact_forces),
                       ("drift_profiles.png", _drift_profiles),
                       ("force_penetration.png", _force_penetration)):
        path = out / name
        draw(plt, ds, path)
        written.append(path)
    return written
