"""PNG figures of an archive (matplotlib, non-interactive Agg backend): a run's, of any model, and a sweep's.

:func:`plot_run` draws what the run archive holds, whatever its model:

``contact_displacements.png`` (a model with contacts)
    Displacement histories of the two sides of each contact, the right one shifted by the gap, so the
    curves touch where the gap closes; a floor in plan moves at the contact point along the face's normal
    (its translation and rotation).
``contact_forces.png`` (contacts)
    Contact-force history of each contact: every solver step where the archive has the full-resolution
    trace, else the sampled history with each impact's peak marked.
``drift_profiles.png`` (every run)
    Peak drift ratio per storey, one panel per building; where storeys are made of planes, each plane's
    peak drift ratio beside its storey's.
``force_penetration.png`` (contacts)
    Force against penetration for each contact (the hysteresis loops of the impacts).
``storey_hysteresis.png`` (yielding storeys or planes)
    Shear against drift ratio of the most yielded storeys or planes; a collapse is marked.
``plan_view.png`` (floors in plan)
    The plan at the onset of the largest impact: outlines at rest and displaced, each contact point's peak
    normal force and each friction face's peak friction force over the run, the corner that moves most.
``roof_rotation.png`` (floors that rotate beyond round-off, :data:`pounding.results.summary.ROUND_OFF`)
    Each building's roof rotation and the displacement of its roof's most displaced corner against time.

Every title states the model, the record and the intensity (:func:`pounding.results.describe.run_title`)
and is wrapped to lie within the figure (:func:`lay_out`).
"""

from __future__ import annotations

import os
import weakref
from pathlib import Path

import numpy as np
import xarray as xr

from pounding.errors import PoundingError
from pounding.results.corners import corner_weights, hermite_at
from pounding.results.describe import run_title
from pounding.results.summary import force_text, rotating_buildings, yielding_planes

__all__ = ["plot_run", "plot_sweep", "plot_directory", "save_figure", "lay_out", "fit_titles", "pyplot", "suptitle",
           "storey_spans", "draw_drift_profile", "finish_drift_axes", "finish_profile_panel", "hysteresis_storeys",
           "hysteresis_left_out", "LOOPS_SHOWN", "sweep_axis_is_numeric", "plan_view_instant", "shown_floors",
           "side_displacement", "contact_side", "ground_offsets", "magnification"]

def pyplot():
    """``matplotlib.pyplot`` on the non-interactive Agg backend (imported on first use: it is slow)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _wrapped(text: str, width: int) -> str:
    import textwrap

    return "\n".join(piece for line in text.split("\n") for piece in (textwrap.wrap(line, width) or [""]))


#: The text of each title :func:`suptitle` wrapped, before wrapping (rewrapped from it by :func:`fit_titles`).
_UNWRAPPED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def suptitle(fig, text: str, fontsize: float = 9):
    """*fig*'s title, each line wrapped to about the figure's width (a title states the record and the
    intensity, which makes it long; :func:`lay_out` rewraps it if it still reaches past an edge);
    returns the matplotlib ``Text``."""
    width = max(40, int(fig.get_figwidth() * 72 / (0.6 * fontsize)))
    title = fig.suptitle(_wrapped(text, width), fontsize=fontsize)
    _UNWRAPPED[title] = text
    return title


def _titles(fig) -> list:
    """The figure's title and its panels' titles that hold text (matplotlib ``Text`` objects)."""
    texts = [getattr(fig, "_suptitle", None)] + [ax.title for ax in fig.axes]
    return [t for t in texts if t is not None and t.get_text()]


def fit_titles(fig, margin: float = 4.0) -> bool:
    """Rewrap every title of *fig* that reaches past the canvas's left or right edge (less *margin*,
    pixels) to fit; True if one was rewrapped (lay the figure out again)."""
    renderer = fig.canvas.get_renderer()
    right = fig.bbox.width - margin
    changed = False
    for text in _titles(fig):
        box = text.get_window_extent(renderer)
        if box.x0 >= margin and box.x1 <= right:
            continue
        longest = max(len(line) for line in text.get_text().split("\n"))
        centre = 0.5 * (box.x0 + box.x1)
        room = 2.0 * min(centre - margin, right - centre)   # a centred title: the room either side of its centre
        width = max(10, int(longest * room / max(box.width, 1.0)) - 2)
        text.set_text(_wrapped(_UNWRAPPED.get(text, text.get_text()), width))
        changed = True
    return changed


def lay_out(fig) -> None:
    """Lay out *fig* (``tight_layout``) with every title within the canvas (:func:`fit_titles`).

    The figure's title is put 4 pt below the canvas's top edge: ``tight_layout`` keeps room for its
    height counted from the edge, and matplotlib's default place (2 % of the height down) pushed a tall
    figure's title onto its first panel's.
    """
    title = getattr(fig, "_suptitle", None)
    if title is not None:
        title.set_y(1.0 - 4.0 / 72.0 / fig.get_figheight())
    fig.tight_layout()
    for _ in range(4):
        if not fit_titles(fig):
            return
        fig.tight_layout()


def save_figure(fig, path: str | os.PathLike) -> Path:
    """Lay out *fig* (:func:`lay_out`), write it to *path* (PNG, 110 dpi) and close it; returns the path."""
    fig.set_dpi(110)
    lay_out(fig)
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return Path(path)


def _grid(plt, count: int, *, width: float = 9.0, height: float = 2.2, sharex: bool = True):
    fig, axes = plt.subplots(max(count, 1), 1, figsize=(width, 1.0 + height * max(count, 1)),
                             sharex=sharex, squeeze=False)
    return fig, axes[:, 0]


# --------------------------------------------------------------------------- #
# Contacts
# --------------------------------------------------------------------------- #


def _floor(ds: xr.Dataset, building: str, level: int) -> int:
    """Position of floor *level* of *building* along ``floor``."""
    return int(np.flatnonzero(ds.floor.values == f"{building}:{level}")[0])


def _in_plan(ds: xr.Dataset) -> bool:
    """Whether the floors move in plan (a ``direction`` per floor, and a rotation)."""
    return "direction" in ds.displacement.dims


def _point_motion(ds: xr.Dataset, i: int, floor: int) -> np.ndarray:
    """Displacement history (m) of *floor* at contact point *i* along the face's normal (small rotations)."""
    theta = ds.rotation.values[:, floor]
    if str(ds.point_normal.values[i]) == "x":
        return ds.displacement.values[:, floor, 0] - theta * (float(ds.point_y[i]) - float(ds.floor_centre_y[floor]))
    return ds.displacement.values[:, floor, 1] + theta * (float(ds.point_x[i]) - float(ds.floor_centre_x[floor]))


def side_displacement(ds: xr.Dataset, i: int, side: str) -> tuple[str, np.ndarray]:
    """Label and displacement history (m) of one side of contact *i*: a floor, a wall (0) or a column point.

    A floor in plan moves at the contact point along the face's normal.  A column point at fraction ξ of
    storey s moves as ``N1·u_(s−1) + N2·u_s`` (Hermite shape functions of the fixed-fixed column,
    docs/physics.md §12).
    """
    building = str(ds[f"building_{side}"].values[i])
    level = int(ds[f"level_{side}"].values[i])
    if building == "wall":
        return "wall", np.zeros(ds.sizes["time"])
    if _in_plan(ds):
        return (f"{building}:{level} along {ds.point_normal.values[i]}",
                _point_motion(ds, i, _floor(ds, building, level)))
    at_name = f"at_{side}"
    at = float(ds[at_name].values[i]) if at_name in ds.coords else float("nan")
    if np.isnan(at):
        return f"{building}:{level}", ds.displacement.sel(floor=f"{building}:{level}").values
    n2 = at * at * (3.0 - 2.0 * at)
    above = ds.displacement.sel(floor=f"{building}:{level}").values
    below = ds.displacement.sel(floor=f"{building}:{level - 1}").values if level > 1 else 0.0 * above
    return f"{building} storey {level} at {at:g}", (1.0 - n2) * below + n2 * above


def ground_offsets(ds: xr.Dataset, order: list[str]) -> dict[str, np.ndarray]:
    """Per building of *order*, its ground's displacement less the first building's, m: (time,) in elevation,
    (time, direction) in plan; zeros under one ground motion; with a record or a time lag per building, the
    difference that closes or opens the gaps.

    A floor's ``displacement`` is relative to its own building's ground; adding its building's offset puts
    every building in the first one's frame, where ``left − right − gap`` is the contact's penetration.
    """
    in_plan = "direction" in ds.displacement.dims
    zero = np.zeros((ds.sizes["time"], 2) if in_plan else ds.sizes["time"])
    if "building_ground_displacement" not in ds or ds.sizes.get("ground", 0) < 2:
        return {b: zero for b in order}
    grounds = {str(g): ds.building_ground_displacement.values[:, k] for k, g in enumerate(ds.ground.values)}
    first = grounds.get(order[0], zero)
    return {b: grounds.get(b, first) - first for b in order}


def contact_side(ds: xr.Dataset, i: int, side: str, grounds: dict[str, np.ndarray]) -> tuple[str, np.ndarray]:
    """:func:`side_displacement` of one side of contact *i* in the first building's ground frame (*grounds*:
    :func:`ground_offsets`), m: a wall moves with the ground of the building it faces, a point in plan with its
    ground along the face's normal.  ``left − right − gap`` of the two sides is then the contact's
    penetration, under one ground motion or a ground per building."""
    name, motion = side_displacement(ds, i, side)
    building = str(ds[f"building_{side}"].values[i])
    if building == "wall":
        building = str(ds[f"building_{'right' if side == 'left' else 'left'}"].values[i])
    offset = grounds[building]
    if offset.ndim == 2:
        offset = offset[:, 0 if str(ds.point_normal.values[i]) == "x" else 1]
    return name, motion + offset


def _contact_displacements(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    fig, axes = _grid(plt, n)
    t = ds.time.values
    order = list(dict.fromkeys(str(b) for b in ds.building.values))
    grounds = ground_offsets(ds, order)
    frame = f" on {order[0]}'s ground" if any(g.any() for g in grounds.values()) else ""
    for i, ax in enumerate(axes[:n]):
        left_name, left = contact_side(ds, i, "left", grounds)
        right_name, right = contact_side(ds, i, "right", grounds)
        gap = float(ds.gap.values[i])
        ax.plot(t, 1e3 * left, lw=0.8, label=f"{left_name} (left)")
        ax.plot(t, 1e3 * (right + gap), lw=0.8, label=f"{right_name} (right) + gap")
        hits = ds.impact_time.values[ds.impact_contact.values == i]
        if hits.size:
            ax.plot(hits, 1e3 * np.interp(hits, t, left), "k|", ms=10, label="impact")
        ax.set_ylabel(f"displacement (mm){frame}")
        ax.set_title(f"{ds.contact.values[i]}, gap {1e3 * gap:.1f} mm", fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time (s)")
    suptitle(fig, f"contact displacements — {run_title(ds)}", fontsize=9)
    save_figure(fig, path)


def _contact_samples(ds: xr.Dataset, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (s), penetration (m) and force (N) of contact *i* while it is closed, in time order, NaN between
    impacts: every solver step of the full-resolution trace where the archive has one, else the samples
    (every ``output_dt``) with a positive force."""
    if "trace_force" in ds:
        mask = ds.trace_contact.values == i
        t, pen, force = ds.trace_time.values[mask], ds.trace_penetration.values[mask], ds.trace_force.values[mask]
        order = np.argsort(t, kind="stable")
        t, pen, force = t[order], pen[order], force[order]
    else:
        force = ds.contact_force.values[:, i]
        mask = force > 0.0
        t, pen, force = ds.time.values[mask], ds.penetration.values[mask, i], force[mask]
    breaks = np.flatnonzero(np.diff(t) > 2.0 * float(ds.attrs.get("solver_output_dt", 0.01))) + 1
    return np.insert(t, breaks, np.nan), np.insert(pen, breaks, np.nan), np.insert(force, breaks, np.nan)


def _no_impacts(ax, ds: xr.Dataset, i: int) -> None:
    ax.text(0.5, 0.5, "no impacts: the gap never closed", ha="center", va="center", transform=ax.transAxes,
            fontsize=9, color="0.3")
    ax.set_ylim(0.0, 1.0)
    ax.set_xlim(0.0, float(ds.time.values[-1]))
    ax.set_yticks([])
    ax.set_title(f"{ds.contact.values[i]}: no impacts", fontsize=9)


def _contact_forces(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    fig, axes = _grid(plt, n)
    traced = "trace_force" in ds
    for i, ax in enumerate(axes[:n]):
        impacts = int(ds.impact_count.values[i])
        if impacts == 0:
            _no_impacts(ax, ds, i)
            continue
        if traced:   # every solver step of a closed contact: impacts last a few ms, so a sampled force misses most peaks
            t, _, f = _contact_samples(ds, i)
            ax.plot(t, f / 1e6, lw=0.8, color="C3")
        else:        # the samples, and each impact's peak at its onset
            ax.plot(ds.time.values, ds.contact_force.values[:, i] / 1e6, lw=0.8, color="C3", label="sampled")
            mine = ds.impact_contact.values == i
            ax.plot(ds.impact_time.values[mine], ds.impact_peak_force.values[mine] / 1e6, "v", ms=4, color="k",
                    label="impact peak (at its onset)")
            ax.legend(fontsize=7, loc="upper right")
        ax.set_xlim(0.0, float(ds.time.values[-1]))
        ax.set_ylim(bottom=0.0)
        ax.set_ylabel("force (MN)")
        ax.set_title(f"{ds.contact.values[i]}: {impacts} impacts, "
                     f"peak {float(ds.peak_contact_force.values[i]) / 1e6:.3g} MN", fontsize=9)
    axes[-1].set_xlabel("time (s)")
    how = ("every solver step: trace_force" if traced else
           f"sampled every {float(ds.attrs.get('solver_output_dt', 0.01)):g} s; markers: each impact's peak")
    suptitle(fig, f"contact forces ({how}) — {run_title(ds)}", fontsize=9)
    save_figure(fig, path)


def _force_penetration(plt, ds: xr.Dataset, path: Path) -> None:
    n = ds.sizes["contact"]
    cols = min(max(n, 1), 3)
    rows = int(np.ceil(max(n, 1) / cols))
    traced = "trace_force" in ds
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.2 * rows), squeeze=False)
    for i in range(rows * cols):
        ax = axes[i // cols][i % cols]
        if i >= n:
            ax.axis("off")
            continue
        _, pen, force = _contact_samples(ds, i)
        ax.set_title(str(ds.contact.values[i]), fontsize=9)
        if int(ds.impact_count.values[i]) == 0 or not np.isfinite(force).any():
            ax.text(0.5, 0.5, "no impacts", ha="center", va="center", transform=ax.transAxes, color="0.3")
            ax.set_xticks([])
            ax.set_yticks([])
            continue
        ax.plot(1e3 * np.where(pen > 0, pen, 0.0), force / 1e6, "-" if traced else ".-", lw=0.8, ms=3)
        ax.set_xlim(left=0.0)
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel("penetration (mm)")
        ax.set_ylabel("force (MN)")
        ax.set_title(f"{ds.contact.values[i]}: peak {float(ds.peak_contact_force.values[i]) / 1e6:.3g} MN",
                     fontsize=9)
        ax.grid(alpha=0.3)
    how = ("full solver resolution" if traced else
           f"sampled every {float(ds.attrs.get('solver_output_dt', 0.01)):g} s: the archive holds no "
           "full-resolution trace, so the loops miss most of each impact; peaks are every step's")
    suptitle(fig, f"force-penetration loops ({how}) — {run_title(ds)}", 9)
    save_figure(fig, path)


# --------------------------------------------------------------------------- #
# Drift profiles
# --------------------------------------------------------------------------- #


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


def _draw_planes(ax, ds: xr.Dataset, building: str, bottom: np.ndarray, top: np.ndarray) -> None:
    """Each plane of *building* as a thin segment over its storey at its peak drift ratio (%), by direction."""
    levels = ds.storey_level.values[(ds.storey_building == building).values]
    mine = np.flatnonzero(ds.plane_building.values == building)
    for k, direction in enumerate(("x", "y")):
        rows = [p for p in mine if str(ds.plane_direction.values[p]) == direction]
        for j, p in enumerate(rows):
            s = int(np.flatnonzero(levels == int(ds.plane_storey.values[p]))[0])
            ratio = 100 * float(ds.peak_plane_drift_ratio.values[p])
            ax.plot([ratio, ratio], [bottom[s], top[s]], color=f"C{k + 1}", lw=0.8, ls=(0, (3, 1.5)),
                    label=f"a plane along {direction}" if j == 0 else None, gid=f"plane {ds.plane.values[p]}")


def _drift_profiles(plt, ds: xr.Dataset, path: Path, *, drift_limit: float | None = None,
                    elevation: bool = False) -> None:
    names = list(dict.fromkeys(ds.storey_building.values.tolist()))
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names) + 0.4, 4.5), squeeze=False, sharex=True)
    tallest = max(float(storey_spans(ds, name, elevation=True)[1].max()) for name in names) if elevation else None
    planes = "peak_plane_drift_ratio" in ds
    for ax, name in zip(axes[0], names):
        sel = ds.peak_drift_ratio.where(ds.storey_building == name, drop=True)
        bottom, top = storey_spans(ds, name, elevation=elevation)
        if planes:
            _draw_planes(ax, ds, name, bottom, top)
        draw_drift_profile(ax, bottom, top, 100 * sel.values, color="C0", lw=1.4,
                           label="storey (its largest plane)" if planes else None)
        peak = 100 * float(sel.max())
        ax.set_title(f"building {name}: max {peak:.2f} %", fontsize=9)
        finish_drift_axes(ax, bottom, top, elevation=elevation, drift_limit=drift_limit, ymax=tallest)
    if drift_limit is not None or planes:
        axes[0][-1].legend(fontsize=7, loc="lower right")
    suptitle(fig, f"peak storey drift ratio — {run_title(ds)}", 9)
    save_figure(fig, path)


# --------------------------------------------------------------------------- #
# Hysteresis of yielding storeys or planes
# --------------------------------------------------------------------------- #

#: Storeys (or planes) shown in ``storey_hysteresis.png`` (the most yielded first).
LOOPS_SHOWN = 6


def _loop_rows(ds: xr.Dataset) -> tuple[str, np.ndarray]:
    """The dimension whose loops are drawn (``storey``, or ``plane`` for storeys made of planes) and each row's
    rank (peak ductility of a storey, peak drift ratio of a yielded plane; NaN: elastic)."""
    if "peak_ductility" in ds:
        return "storey", ds.peak_ductility.values
    if "plane_shear" in ds:
        return "plane", np.where(yielding_planes(ds), ds.peak_plane_drift_ratio.values, np.nan)
    return "storey", np.full(ds.sizes.get("storey", 0), np.nan)


def hysteresis_storeys(ds: xr.Dataset) -> tuple[list[int], list[int]]:
    """Positions of the yielding storeys (or planes) drawn in ``storey_hysteresis.png`` (the
    :data:`LOOPS_SHOWN` most yielded: largest peak ductility, or a plane's largest peak drift ratio, first)
    and of those it leaves out (same order)."""
    ductility = np.nan_to_num(_loop_rows(ds)[1], nan=-1.0)
    ranked = [int(i) for i in np.argsort(-ductility, kind="stable") if ductility[i] >= 0]
    return ranked[:LOOPS_SHOWN], ranked[LOOPS_SHOWN:]


def hysteresis_left_out(ds: xr.Dataset) -> str:
    """The note naming the yielding storeys (or planes) the hysteresis figure leaves out, with their peak
    ductility (a plane's peak drift ratio, %) ("" if none)."""
    _, rest = hysteresis_storeys(ds)
    if not rest:
        return ""
    dim, rank = _loop_rows(ds)
    if dim == "storey":
        names = ", ".join(f"{ds.storey.values[i]} ({float(rank[i]):.2f})" for i in rest)
        what = "peak ductility"
    else:
        names = ", ".join(f"{ds.plane.values[i]} ({100 * float(rank[i]):.2f} %)" for i in rest)
        what = "peak drift ratio"
    return (f"not shown: {len(rest)} less yielded {dim}{'s' if len(rest) != 1 else ''} ({what}): {names}; "
            "every storey's values are in `pounding table`")


def _loop(ds: xr.Dataset, dim: str, i: int) -> tuple[np.ndarray, np.ndarray, float, str]:
    """Drift ratio (%) and shear (MN) histories of row *i* of *dim*, its yield force (MN; NaN: not in the
    archive) and its panel title."""
    if dim == "storey":
        ratio = 100.0 * ds.storey_drift.values[:, i] / float(ds.height.values[i])
        return (ratio, ds.storey_shear.values[:, i] / 1e6, float(ds.yield_force.values[i]) / 1e6,
                f"storey {ds.storey.values[i]}: ductility {float(ds.peak_ductility.values[i]):.2f}, "
                f"residual {100 * float(ds.residual_drift_ratio.values[i]):+.2f} %")
    ratio = 100.0 * ds.plane_drift_ratio.values[:, i]
    return (ratio, ds.plane_shear.values[:, i] / 1e6, float("nan"),
            f"plane {ds.plane.values[i]}: peak {100 * float(ds.peak_plane_drift_ratio.values[i]):.2f} %, "
            f"at the end {ratio[-1]:+.2f} %")


def _storey_hysteresis(plt, ds: xr.Dataset, path: Path) -> None:
    dim, _ = _loop_rows(ds)
    order, _ = hysteresis_storeys(ds)
    cols = min(len(order), 3)
    rows = int(np.ceil(len(order) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.2 * rows), squeeze=False)
    for slot in range(rows * cols):
        ax = axes[slot // cols][slot % cols]
        if slot >= len(order):
            ax.axis("off")
            continue
        ratio, shear, yield_force, title = _loop(ds, dim, order[slot])
        ax.plot(ratio, shear, lw=0.7)
        if np.isfinite(yield_force):
            ax.axhline(yield_force, color="0.5", ls="--", lw=0.7)
            ax.axhline(-yield_force, color="0.5", ls="--", lw=0.7)
        ax.axhline(0.0, color="0.8", lw=0.6)
        ax.axvline(0.0, color="0.8", lw=0.6)
        ax.set_xlabel(f"{dim} drift ratio (%)")
        ax.set_ylabel(f"{dim} shear (MN)")
        ax.set_title(title, fontsize=8)
        ax.grid(alpha=0.3)
    title = (f"storey hysteresis — {run_title(ds)}\n(column shear, without P-Delta and damping; dashed: yield force "
             "±F_y)" if dim == "storey" else
             f"plane hysteresis — {run_title(ds)}\n(the yielded planes' shear, without P-Delta and damping)")
    if ds.attrs.get("status") in ("collapsed", "unstable"):
        title += (f" - {ds.attrs['status'].upper()} at {ds.attrs['collapse_time']:.2f} s "
                  f"(storey {ds.attrs['collapse_storey']})")
    left_out = hysteresis_left_out(ds)
    suptitle(fig, title + (f"\n{left_out}" if left_out else ""), fontsize=8)
    save_figure(fig, path)


# --------------------------------------------------------------------------- #
# Floors in plan: the plan view and the roof rotation
# --------------------------------------------------------------------------- #


def plan_view_instant(ds: xr.Dataset) -> tuple[float, int | None]:
    """The instant of the plan view, s, and the contact point struck then (None without impacts).

    The onset of the impact with the largest peak force (``impact_peak_force``, tracked at every solver
    step); without impacts, the stored sample with the largest corner displacement.
    """
    if ds.sizes.get("impact", 0):
        k = int(np.argmax(ds.impact_peak_force.values))
        return float(ds.impact_time.values[k]), int(ds.impact_contact.values[k])
    magnitude = ds.corner_displacement_magnitude.values.reshape(ds.sizes["time"], -1)
    return float(ds.time.values[int(np.argmax(magnitude.max(axis=1)))]), None


def shown_floors(ds: xr.Dataset, point: int | None) -> dict[str, int]:
    """The floor (position along ``floor``) drawn per building: each side's floor of contact *point*, else the
    roof."""
    buildings = ds.building.values
    shown = {str(b): int(np.flatnonzero(buildings == b)[-1]) for b in dict.fromkeys(buildings)}
    if point is not None:
        for side in ("left", "right"):
            name = str(ds[f"building_{side}"].values[point])
            if name in shown:
                shown[name] = _floor(ds, name, int(ds[f"level_{side}"].values[point]))
    return shown


def _corners_at(ds: xr.Dataset, at: float) -> np.ndarray:
    """(floor, 4, 2) every outline corner's displacement (m) at time *at*, s: the floors' displacements and
    rotations interpolated between stored samples with their rates (cubic Hermite)."""
    nt, nf = ds.sizes["time"], ds.sizes["floor"]
    y = np.concatenate([ds.displacement.values.reshape(nt, -1), ds.rotation.values], axis=1)
    rate = np.concatenate([ds.velocity.values.reshape(nt, -1), ds.rotation_rate.values], axis=1)
    q = hermite_at(ds.time.values, y, rate, np.array([at]))[0]
    floors = np.c_[q[:2 * nf].reshape(nf, 2), q[2 * nf:]]
    centres = np.c_[ds.floor_centre_x.values, ds.floor_centre_y.values]
    corners = np.stack([ds.corner_x.values, ds.corner_y.values], axis=-1)
    return np.einsum("fk,fcdk->fcd", floors, corner_weights(centres, corners))


def magnification(peak: float, drawn: float) -> float:
    """Displacements drawn ×this: a displacement of *peak* (m) drawn as about *drawn* (m), the factor rounded
    down to 1, 2 or 5 times a power of ten, at least 1."""
    if peak <= 0.0 or drawn / peak <= 1.0:
        return 1.0
    factor = drawn / peak
    decade = 10.0 ** np.floor(np.log10(factor))
    return float(max(m for m in (1.0, 2.0, 5.0) if m * decade <= factor) * decade)


def _magnification(ds: xr.Dataset, extent: float) -> float:
    """Displacements drawn ×this: the largest corner displacement of the run as about 10 % of the plan's extent
    (:func:`magnification`)."""
    peak = float(ds.peak_corner_displacement_magnitude.max()) if ds.sizes.get("floor", 0) else 0.0
    return magnification(peak, 0.1 * extent)


def _peak_friction(ds: xr.Dataset) -> list[tuple[float, float, str, float]]:
    """Per friction face that carried a force: the mean location of its points (x, y, m), its tangent and its
    largest sampled friction force on the low side (signed, N)."""
    if "friction_force" not in ds:
        return []
    faces = []
    for f in range(ds.sizes["face"]):
        history = ds.friction_force.values[:, f]
        k = int(np.argmax(np.abs(history)))
        points = np.flatnonzero(ds.point_face.values == int(ds.face_index.values[f]))
        if history[k] == 0.0 or points.size == 0:
            continue
        faces.append((float(ds.point_x.values[points].mean()), float(ds.point_y.values[points].mean()),
                      str(ds.face_tangent.values[f]), float(history[k])))
    return faces


def _arrow_pair(ax, at: tuple[float, float], along: tuple[float, float], colour: str,
                offset: tuple[float, float] = (0.0, 0.0)) -> None:
    """Two opposite arrows from *at* (m): the force on the high side along *along*, on the low side against it;
    each drawn from *at* shifted by ±*offset*."""
    for sign in (-1.0, 1.0):
        start = (at[0] + sign * offset[0], at[1] + sign * offset[1])
        ax.annotate("", (start[0] + sign * along[0], start[1] + sign * along[1]), start,
                    arrowprops=dict(arrowstyle="->", color=colour, lw=1.4))


def _draw_forces(ax, ds: xr.Dataset, extent: float) -> str:
    """The contact points, each location's peak normal force over the run and each friction face's peak
    friction force as arrow pairs scaled to the largest; returns the title's words for them."""
    peaks = ds.peak_contact_force.values
    ax.plot(ds.point_x.values, ds.point_y.values, "o", ms=4, color="0.3", label="contact points")
    friction = _peak_friction(ds)
    top = max([float(peaks.max(initial=0.0))] + [abs(f[3]) for f in friction])
    if top <= 0.0:
        return "no impacts"
    locations: dict[tuple[float, float, str], int] = {}
    for p in np.flatnonzero(peaks > 0.0):   # a location's floors overlap in plan: its largest peak
        key = (float(ds.point_x.values[p]), float(ds.point_y.values[p]), str(ds.point_normal.values[p]))
        if key not in locations or peaks[p] > peaks[locations[key]]:
            locations[key] = int(p)
    ax.plot([], [], color="C3", lw=1.4, label="peak normal force (arrow pair)")   # the arrows' legend entry
    for (x, y, normal), p in locations.items():
        length = 0.1 * extent * float(peaks[p]) / top
        along = (length, 0.0) if normal == "x" else (0.0, length)
        _arrow_pair(ax, (x, y), along, "C3")
        ax.annotate(force_text(float(peaks[p])), (x + along[0], y + along[1]), textcoords="offset points",
                    xytext=(3, 0) if normal == "x" else (0, 3), ha="left" if normal == "x" else "center",
                    va="center" if normal == "x" else "bottom", fontsize=7, color="C3")
    if friction:
        ax.plot([], [], color="C2", lw=1.4, label="peak friction force (arrow pair)")
    for x, y, tangent, force in friction:
        length = 0.1 * extent * force / top
        shift = 0.01 * extent
        _arrow_pair(ax, (x, y), (-length, 0.0) if tangent == "x" else (0.0, -length), "C2",
                    (0.0, shift) if tangent == "x" else (shift, 0.0))
        ax.annotate(f"friction {force_text(abs(force))}", (x, y), textcoords="offset points",
                    xytext=(6, 8) if tangent == "y" else (0, 8), fontsize=7, color="C2")
    words = "red arrows: each contact point's peak normal force over the run"
    if friction:
        sampled = float(ds.attrs.get("solver_output_dt", 0.01))
        words += f"; green: each friction face's peak friction force (sampled every {sampled:g} s)"
    return words


def _draw_walls(ax, ds: xr.Dataset, extent: float, factor: float) -> None:
    """Each wall a contact point strikes, as a thick grey line along its face, its gap magnified as the
    displacements (×*factor*: the displaced outline touches it where the building strikes it).  A contact point
    lies on its low side's face: a wall on the high side stands the gap beyond the building's face through the
    points, one on the low side the gap before it.  A wall held open (its gap wider than the plan) is left out."""
    drawn = False
    for face in np.unique(ds.point_face.values):
        points = np.flatnonzero(ds.point_face.values == face)
        i = int(points[0])
        high, low = str(ds.building_right.values[i]) == "wall", str(ds.building_left.values[i]) == "wall"
        gap = float(ds.gap.values[i])
        if not (high or low) or gap > extent:
            continue
        shift = factor * gap if high else (1.0 - factor) * gap
        x, y = ds.point_x.values[points].astype(float), ds.point_y.values[points].astype(float)
        reach = 0.05 * extent
        if str(ds.point_normal.values[i]) == "x":
            xs, ys = [x.mean() + shift] * 2, [y.min() - reach, y.max() + reach]
        else:
            xs, ys = [x.min() - reach, x.max() + reach], [y.mean() + shift] * 2
        ax.plot(xs, ys, color="0.5", lw=4, solid_capstyle="butt",
                label=None if drawn else f"wall (gap x{factor:g})" if factor != 1.0 else "wall")
        drawn = True


def _plan_view(plt, ds: xr.Dataset, path: Path) -> float:
    """Draw ``plan_view.png``; returns the instant drawn (s)."""
    instant, point = plan_view_instant(ds)
    shown = shown_floors(ds, point)
    xs, ys = ds.corner_x.values, ds.corner_y.values
    extent = float(max(np.ptp(xs), np.ptp(ys), 1.0))
    factor = _magnification(ds, extent)
    aspect = (np.ptp(ys) + 0.3 * extent) / (np.ptp(xs) + 0.3 * extent)
    fig, ax = plt.subplots(figsize=(8.0, float(np.clip(2.0 + 6.4 * aspect, 4.0, 9.0))))
    corner = _corners_at(ds, instant)
    best = (None, -1.0)
    for k, (name, f) in enumerate(shown.items()):
        rest = np.c_[xs[f], ys[f]]
        moved = rest + factor * corner[f]
        ax.fill(*np.r_[rest, rest[:1]].T, fill=False, ls="--", lw=0.8, color=f"C{k}")
        ax.plot(*np.r_[moved, moved[:1]].T, lw=1.6, color=f"C{k}", label=f"{name} floor {int(ds.level.values[f])}")
        magnitude = np.hypot(corner[f, :, 0], corner[f, :, 1])
        c = int(np.argmax(magnitude))
        if magnitude[c] > best[1]:
            best = ((f, c, moved[c]), float(magnitude[c]))
    if best[0] is not None and best[1] > 0.0:
        f, c, at = best[0]
        ax.plot(*at, marker="*", ms=14, color="k", zorder=5, ls="none", label="most displaced corner")
        ax.annotate(f"{ds.floor.values[f]} {ds.corner.values[c]}: {1e3 * best[1]:.1f} mm", at,
                    textcoords="offset points", xytext=(8, 8), fontsize=8)
    if ds.sizes.get("contact", 0):
        _draw_walls(ax, ds, extent, factor)
        forces = _draw_forces(ax, ds, extent)
    else:
        forces = "no contact points"
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(fontsize=8, loc="best")
    what = (f"onset of the largest impact, at {ds.contact.values[point]} "
            f"(peak {force_text(float(ds.impact_peak_force.max()))})" if point is not None
            else "no impacts: the largest corner displacement")
    suptitle(fig, f"plan at t = {instant:.3f} s, {what} — {run_title(ds)}\n"
                  f"displacements x{factor:g}, dashed: at rest; {forces}", fontsize=8)
    save_figure(fig, path)
    return instant


def _roof_rotation(plt, ds: xr.Dataset, path: Path, instant: float) -> None:
    """Draw ``roof_rotation.png``: per building its roof rotation (or a note where it is round-off) and its roof's
    most displaced corner beside its centre of mass, the plan view's *instant* (s) dashed."""
    rotating = rotating_buildings(ds)
    fig, axes = plt.subplots(len(rotating), 2, figsize=(10.0, 1.2 + 2.2 * len(rotating)), sharex=True,
                             squeeze=False)
    t = ds.time.values
    for (left, right), (name, turns) in zip(axes, rotating.items()):
        roof = int(np.flatnonzero(ds.building.values == name)[-1])
        if turns:
            left.plot(t, 1e3 * ds.rotation.values[:, roof], lw=0.8)
        else:
            left.text(0.5, 0.5, f"no rotation beyond round-off\n(peak {float(ds.peak_rotation[roof]):.1e} rad)",
                      ha="center", va="center", transform=left.transAxes, fontsize=8, color="0.3")
            left.set_yticks([])
        magnitude = ds.corner_displacement_magnitude.values[:, roof]
        c = int(np.argmax(magnitude.max(axis=0)))
        right.plot(t, 1e3 * magnitude[:, c], lw=0.8, color="C1", label=f"{ds.corner.values[c]} corner")
        right.plot(t, 1e3 * np.hypot(*ds.displacement.values[:, roof].T), lw=0.8, color="0.4",
                   label="centre of mass")
        right.legend(fontsize=7, loc="upper right")
        left.set_ylabel(f"{name} roof θ (mrad)")
        right.set_ylabel(f"{name} roof |u| (mm)")
        for ax in (left, right):
            ax.axvline(instant, ls="--", lw=0.8, color="C3")
            ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time (s)")
    axes[-1, 1].set_xlabel("time (s)")
    suptitle(fig, f"roof rotation (counter-clockwise) and roof displacement — {run_title(ds)}\n"
                  "dashed: the plan view's instant", fontsize=8)
    save_figure(fig, path)


# --------------------------------------------------------------------------- #
# All of a run's figures
# --------------------------------------------------------------------------- #


def plot_run(ds: xr.Dataset, directory: str | os.PathLike, *, drift_limit: float | None = None,
             elevation: bool = False) -> list[Path]:
    """Write the figures of a run archive to *directory* (created if needed), those its data call for.

    The drift profiles always; with contacts the contact displacements, forces and force-penetration
    loops; with yielding storeys or planes their hysteresis; with floors in plan the plan view, and the
    roof rotation where a roof rotates beyond round-off (module docstring).

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
    contacts = ds.sizes.get("contact", 0) > 0
    figures = [("contact_displacements.png", contacts, _contact_displacements),
               ("contact_forces.png", contacts, _contact_forces),
               ("drift_profiles.png", True, lambda p, d, f: _drift_profiles(p, d, f, drift_limit=drift_limit,
                                                                           elevation=elevation)),
               ("force_penetration.png", contacts, _force_penetration),
               ("storey_hysteresis.png", bool(hysteresis_storeys(ds)[0]), _storey_hysteresis)]
    written = []
    for name, wanted, draw in figures:
        if wanted:
            draw(plt, ds, out / name)
            written.append(out / name)
    if _in_plan(ds):
        instant = _plan_view(plt, ds, out / "plan_view.png")
        written.append(out / "plan_view.png")
        if any(rotating_buildings(ds).values()):
            _roof_rotation(plt, ds, out / "roof_rotation.png", instant)
            written.append(out / "roof_rotation.png")
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
