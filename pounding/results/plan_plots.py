"""PNG figures of a plan-model run (:mod:`pounding.results.plan_dataset`), matplotlib on the Agg backend.

:func:`plot_plan_run` writes two figures:

``plan_view.png``
    The plan at the instant of the largest impact (the stored sample with the
    largest normal force at any contact point; without impacts, the instant of
    the largest corner displacement): every building's outline at rest (dashed)
    and displaced (solid, displacements magnified, the factor in the title) for
    the floor in that impact (other buildings: the roof), the contact points (a wall's
    on the low side's face),
    the normal forces at that instant as arrows scaled to the largest, and the
    corner that moves most, with its displacement.
``roof_rotation.png``
    The roof rotation history of each building (mrad), the plan view's instant
    marked.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from pounding.results.plots import plot_directory, pyplot, save_figure, suptitle

__all__ = ["plot_plan_run", "plan_view_instant", "shown_floors"]


def plan_view_instant(ds: xr.Dataset) -> tuple[int, int | None]:
    """The sample of the plan view and the contact point of the largest force there (None without impacts)."""
    force = ds.contact_force.values if ds.sizes.get("contact", 0) else np.zeros((ds.sizes["time"], 0))
    if force.size and float(force.max()) > 0.0:
        sample, point = np.unravel_index(int(np.argmax(force)), force.shape)
        return int(sample), int(point)
    magnitude = ds.corner_displacement_magnitude.values.reshape(ds.sizes["time"], -1)
    return int(np.argmax(magnitude.max(axis=1))), None


def shown_floors(ds: xr.Dataset, point: int | None) -> dict[str, int]:
    """The floor index drawn per building: the one in the contact *point* (``A:2-B:1``, ``A:1-wall``), else the roof."""
    buildings, levels = ds.building.values, ds.level.values
    shown = {str(b): int(np.flatnonzero(buildings == b)[-1]) for b in dict.fromkeys(buildings)}
    if point is not None:
        for side in str(ds.point_between.values[point]).split("-"):
            name, _, level = side.partition(":")
            if level:
                shown[name] = int(np.flatnonzero((buildings == name) & (levels == int(level)))[0])
    return shown


def _magnification(ds: xr.Dataset, extent: float) -> float:
    """Displacements drawn ×this: the largest corner displacement of the run as about 10 % of the plan's extent
    (1, 2 or 5 times a power of ten, at least 1)."""
    peak = float(ds.peak_corner_displacement_magnitude.max()) if ds.sizes.get("floor", 0) else 0.0
    if peak <= 0.0 or 0.1 * extent / peak <= 1.0:
        return 1.0
    factor = 0.1 * extent / peak
    decade = 10.0 ** np.floor(np.log10(factor))
    return float(max(m for m in (1.0, 2.0, 5.0) if m * decade <= factor) * decade)


def _force_text(newtons: float) -> str:
    return f"{newtons / 1e6:.3g} MN" if newtons >= 1e6 else f"{newtons / 1e3:.3g} kN"


def _plan_view(plt, ds: xr.Dataset, path: Path) -> float:
    """Draw ``plan_view.png``; returns the instant drawn (s)."""
    sample, point = plan_view_instant(ds)
    shown = shown_floors(ds, point)
    xs, ys = ds.corner_x.values, ds.corner_y.values
    extent = float(max(np.ptp(xs), np.ptp(ys), 1.0))
    factor = _magnification(ds, extent)
    fig, ax = plt.subplots(figsize=(8.0, 7.0))
    corner = ds.corner_displacement.values[sample]
    best = (None, -1.0)
    for k, (name, f) in enumerate(shown.items()):
        colour = f"C{k}"
        rest = np.c_[xs[f], ys[f]]
        moved = rest + factor * corner[f]
        ax.fill(*np.r_[rest, rest[:1]].T, fill=False, ls="--", lw=0.8, color=colour)
        ax.plot(*np.r_[moved, moved[:1]].T, lw=1.6, color=colour,
                label=f"{name} floor {int(ds.level.values[f])}")
        magnitude = np.hypot(corner[f, :, 0], corner[f, :, 1])
        c = int(np.argmax(magnitude))
        if magnitude[c] > best[1]:
            best = ((f, c, moved[c]), float(magnitude[c]))
    if best[0] is not None and best[1] > 0.0:
        f, c, at = best[0]
        ax.plot(*at, marker="*", ms=14, color="k", zorder=5)
        ax.annotate(f"{ds.building.values[f]}:{int(ds.level.values[f])} {ds.corner.values[c]}: "
                    f"{1e3 * best[1]:.1f} mm", at, textcoords="offset points", xytext=(8, 8), fontsize=8)
    if ds.sizes.get("contact", 0):
        ax.plot(ds.point_x.values, ds.point_y.values, "o", ms=4, color="0.3", label="contact points")
        force = ds.contact_force.values[sample]
        top = float(force.max())
        for p in np.flatnonzero(force > 0.0):
            length = 0.1 * extent * float(force[p]) / top
            dx, dy = (length, 0.0) if str(ds.point_normal.values[p]) == "x" else (0.0, length)
            for sign in (-1.0, 1.0):   # the pair of forces: on the low side towards −n, on the high side +n
                ax.annotate("", (ds.point_x.values[p] + sign * dx, ds.point_y.values[p] + sign * dy),
                            (ds.point_x.values[p], ds.point_y.values[p]),
                            arrowprops=dict(arrowstyle="->", color="C3", lw=1.4))
        if point is not None:
            ax.annotate(_force_text(top), (ds.point_x.values[point], ds.point_y.values[point]),
                        textcoords="offset points", xytext=(6, -12), fontsize=8, color="C3")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(fontsize=8, loc="best")
    t = float(ds.time.values[sample])
    what = (f"largest impact at {ds.point_between.values[point]} (point x {float(ds.point_x[point]):.2f}, "
            f"y {float(ds.point_y[point]):.2f} m)" if point is not None else "no impacts: largest corner displacement")
    suptitle(fig, f"{ds.attrs.get('model', '')}: plan at t = {t:.3f} s, {what}\n"
                  f"displacements x{factor:g}; dashed: at rest; arrows: normal forces (largest "
                  f"{_force_text(float(ds.contact_force.values[sample].max())) if ds.sizes.get('contact', 0) else '0'})")
    save_figure(fig, path)
    return t


def _roof_rotation(plt, ds: xr.Dataset, path: Path, instant: float) -> None:
    names = list(dict.fromkeys(ds.building.values))
    fig, axes = plt.subplots(len(names), 1, figsize=(9.0, 1.0 + 2.2 * len(names)), sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        roof = int(np.flatnonzero(ds.building.values == name)[-1])
        ax.plot(ds.time.values, 1e3 * ds.rotation.values[:, roof], lw=0.8)
        ax.axvline(instant, ls="--", lw=0.8, color="C3")
        ax.set_ylabel(f"{name} roof θ (mrad)")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time (s)")
    suptitle(fig, f"{ds.attrs.get('model', '')}: roof rotation (counter-clockwise), dashed: the plan view's instant")
    save_figure(fig, path)


def plot_plan_run(ds: xr.Dataset, directory: str | os.PathLike) -> list[Path]:
    """Write ``plan_view.png`` and ``roof_rotation.png`` of a plan run to *directory* (created if needed)."""
    out = plot_directory(directory)
    plt = pyplot()
    instant = _plan_view(plt, ds, out / "plan_view.png")
    _roof_rotation(plt, ds, out / "roof_rotation.png", instant)
    return [out / "plan_view.png", out / "roof_rotation.png"]
