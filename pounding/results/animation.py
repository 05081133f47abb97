"""Animations of a run archive (``pounding animate``): the buildings swaying and striking.

A planar model is drawn in elevation: each building a column of floors (slabs as lines, storeys as the
columns between them) side by side in the contacts' left-to-right order, each floor displaced by its
recorded displacement times the exaggeration.  The gap between two buildings is drawn exaggerated as much
as the displacements, so the drawn floors touch exactly when the gap closes.  A model with floors in plan is
drawn in plan: every floor's outline displaced and rotated (the roof's solid, its corners marked), the
contact points moving with their floor; a building across a gap is drawn shifted along the face's normal so
that its gap is exaggerated as the displacements are.  With a ground motion per building (wave passage, a
record each) every building is drawn on its own ground's displacement less the first building's, in
elevation and in plan: floors are archived relative to their own ground, and drawn so the faces still
touch exactly when the gap closes.

Impacts flash: a frame marks each contact that carried a force since the previous frame, its marker sized
and coloured by the largest force in that interval (the stored samples, every solver step of the
full-resolution trace and each impact's located peak at its onset), labelled in kN or MN.  Below the
buildings, the ground acceleration with a cursor at the frame's time.

Frames are the archive's stored samples (every ``output_dt``), one every ``stride`` samples: ``stride`` is
the number of samples that makes the frame rate closest to :data:`FRAME_RATE` frames per second at the
chosen speed (simulated seconds per real second), at least one; the frame rate is then
``speed / (stride · output_dt)``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.animation import FFMpegWriter, PillowWriter

from pounding.errors import PoundingError
from pounding.results.describe import run_title
from pounding.results.plots import ground_offsets, lay_out, magnification, pyplot, side_displacement, suptitle
from pounding.results.summary import force_text
from pounding.units import STANDARD_GRAVITY

__all__ = ["RunAnimation", "frame_indices", "frame_forces", "building_order", "film_format", "parse_window",
           "FRAME_RATE", "SUFFIXES", "FIGURE_SIZE"]

#: Frames per real second aimed at (a film's 24-25; the rate is lower in slow motion, where every stored
#: sample is a frame).
FRAME_RATE = 25.0

#: The files ``pounding animate`` writes, by suffix.
SUFFIXES = {".mp4": "MP4 video (ffmpeg, H.264)", ".gif": "animated GIF (Pillow)"}


def parse_window(text: str | None) -> tuple[float, float] | None:
    """``--window T0,T1`` as two floats, s (None stays None); refused in one line unless T0 < T1."""
    if text is None:
        return None
    parts = text.split(",")
    try:
        start, end = (float(p) for p in parts)
    except ValueError:
        raise PoundingError(f"--window {text}: give two times in s, T0,T1 (e.g. --window 2.5,6)") from None
    if not start < end:
        raise PoundingError(f"--window {text}: the start must come before the end (T0 < T1)")
    return start, end


def _output_dt(ds: xr.Dataset) -> float:
    """The archive's sampling interval, s (the median step of ``time``)."""
    t = ds.time.values
    return float(np.median(np.diff(t))) if t.size > 1 else float(ds.attrs.get("solver_output_dt", 0.01))


def frame_indices(ds: xr.Dataset, speed: float = 1.0,
                  window: tuple[float, float] | None = None) -> tuple[np.ndarray, float]:
    """The positions along ``time`` of the frames and the frame rate, frames per second.

    Parameters
    ----------
    speed : float
        Simulated seconds shown per real second (1: real time, 0.1: ten times slower).
    window : (float, float), optional
        The part of the run shown, s; the whole run by default.

    Raises
    ------
    PoundingError
        A speed that is not positive, or a window that reaches outside the run.
    """
    if not (np.isfinite(speed) and speed > 0):
        raise PoundingError(f"--speed {speed:g}: give a positive number of simulated seconds per second")
    t = ds.time.values
    step = _output_dt(ds)
    start, end = window if window is not None else (float(t[0]), float(t[-1]))
    slack = 0.5 * step
    if start < t[0] - slack or end > t[-1] + slack:
        raise PoundingError(f"--window {start:g},{end:g}: the run spans {t[0]:g} to {t[-1]:g} s; choose a window "
                            "inside it")
    stride = max(1, int(round(speed / (FRAME_RATE * step))))
    first = int(np.searchsorted(t, start - 1e-9 * max(1.0, abs(start))))
    last = int(np.searchsorted(t, end + 1e-9 * max(1.0, abs(end)), side="right")) - 1
    if last < first:
        raise PoundingError(f"--window {start:g},{end:g}: no stored sample lies inside it (every {step:g} s); "
                            "widen it")
    return np.arange(first, last + 1, stride), speed / (stride * step)


def frame_forces(ds: xr.Dataset, indices: np.ndarray) -> np.ndarray:
    """(frame, contact) the largest contact force, N, since the previous frame (0: none).

    Frame k covers ``(t[k-1], t[k]]`` (the first frame one frame interval back): the stored samples, the
    full-resolution trace where the archive has one, and each impact's located peak at its onset, so that no
    impact between two frames is missed.
    """
    times = ds.time.values[indices]
    gap = float(times[1] - times[0]) if times.size > 1 else _output_dt(ds)
    low = np.r_[times[0] - gap, times[:-1]]
    count = ds.sizes.get("contact", 0)
    out = np.zeros((times.size, count))
    if not count:
        return out
    sources = [(np.repeat(ds.time.values, count), np.tile(np.arange(count), ds.sizes["time"]),
                ds.contact_force.values.ravel())]
    for at, contact, force in (("trace_time", "trace_contact", "trace_force"),
                               ("impact_time", "impact_contact", "impact_peak_force")):
        if force in ds and ds[force].size:
            sources.append((ds[at].values, ds[contact].values.astype(int), ds[force].values))
    for at, contact, force in sources:
        k = np.searchsorted(times, at, side="left")
        inside = (k < times.size) & (force > 0.0)
        inside[inside] &= at[inside] > low[k[inside]]
        np.maximum.at(out, (k[inside], contact[inside]), force[inside])
    return out


def building_order(ds: xr.Dataset) -> list[str]:
    """The buildings from left to right: each contact's left building before its right one, else as listed."""
    names = list(dict.fromkeys(str(b) for b in ds.building.values))
    right_of = {n: set() for n in names}
    for left, right in zip(ds.building_left.values, ds.building_right.values) if "building_left" in ds else ():
        if str(left) in right_of and str(right) in right_of and left != right:
            right_of[str(left)].add(str(right))
    order: list[str] = []
    while len(order) < len(names):
        rest = [n for n in names if n not in order]
        free = [n for n in rest if not any(n in right_of[m] for m in rest)]
        order.append((free or rest)[0])   # a cycle of contacts: the listed order
    return order


#: The film's size, in: the buildings above, the ground trace below (800 × 700 pixels at 100 dpi: even, as
#: H.264's 4:2:0 colour needs).
FIGURE_SIZE = (8.0, 7.0)


class RunAnimation:
    """The frames of a run archive's animation: a matplotlib figure redrawn for each frame.

    Parameters
    ----------
    ds : xarray.Dataset
        A run archive (``pounding run``), planar or in plan.
    exaggerate : float, optional
        Displacements and gaps drawn ×this; by default the largest displacement is drawn as about a
        quarter of a building's drawn width (elevation) or a tenth of the plan (1, 2 or 5 times a power of 10).
    speed : float
        Simulated seconds per real second.
    window : (float, float), optional
        The part of the run shown, s.
    dpi : float
        Pixels per inch of the frames.
    """

    def __init__(self, ds: xr.Dataset, *, exaggerate: float | None = None, speed: float = 1.0,
                 window: tuple[float, float] | None = None, dpi: float = 100.0):
        if exaggerate is not None and not (np.isfinite(exaggerate) and exaggerate > 0):
            raise PoundingError(f"--exaggerate {exaggerate:g}: give a positive factor (1: true scale)")
        self.ds = ds
        self.indices, self.fps = frame_indices(ds, speed, window)
        self.times = ds.time.values[self.indices]
        self.forces = frame_forces(ds, self.indices)
        plt = pyplot()
        self.fig = plt.figure(figsize=FIGURE_SIZE, dpi=dpi)
        grid = self.fig.add_gridspec(2, 1, height_ratios=[4.0, 1.0])
        self.ax = self.fig.add_subplot(grid[0])
        self.ground_ax = self.fig.add_subplot(grid[1])
        in_plan = "direction" in ds.displacement.dims
        self.scene = (_PlanScene if in_plan else _ElevationScene)(ds, self.ax, exaggerate)
        self.exaggerate = self.scene.factor
        self._impacts(plt)
        self._ground_trace()
        self.clock = self.ax.text(0.02, 0.97, "", transform=self.ax.transAxes, va="top", fontsize=9)
        suptitle(self.fig, f"{run_title(ds)}\n{self.scene.words}; displacements and gaps x{self.exaggerate:g}; "
                           "impacts: marker sized and coloured by the largest contact force since the last frame", 8)
        lay_out(self.fig)
        _fit_aspect(self.ax)
        self.label_offset = 0.03 * float(np.diff(self.ax.get_xlim())[0])

    @property
    def n_frames(self) -> int:
        """The number of frames."""
        return int(self.indices.size)

    def _impacts(self, plt) -> None:
        """The impact markers (one per contact, hidden until it carries a force) and their labels."""
        from matplotlib.colors import Normalize

        count = self.forces.shape[1]
        self.norm = Normalize(0.0, float(self.forces.max(initial=0.0)) or 1.0)
        self.flash = self.ax.scatter(np.zeros(count), np.zeros(count), s=np.zeros(count), c=np.zeros(count),
                                     cmap="autumn_r", norm=self.norm, edgecolors="k", linewidths=0.6, zorder=6,
                                     gid="impacts")
        proxy = plt.Line2D([], [], ls="none", marker="o", ms=8, mfc="orange", mec="k", mew=0.6,
                           label="impact (size and colour: force)")
        self.ax.legend(handles=self.ax.get_legend_handles_labels()[0] + ([proxy] if count else []), fontsize=7,
                       loc="upper right")
        self.labels = [self.ax.text(0.0, 0.0, "", fontsize=7, color="C3", zorder=7, visible=False,
                                    bbox=dict(boxstyle="square,pad=0.1", fc="w", ec="none", alpha=0.8))
                       for _ in range(count)]

    def _ground_trace(self) -> None:
        """The ground acceleration (g) over the window with the time cursor."""
        ds, ax = self.ds, self.ground_ax
        t = ds.time.values
        inside = (t >= self.times[0]) & (t <= self.times[-1])
        ground = ds.ground_acceleration
        if "direction" in ground.dims:
            for k, direction in enumerate(ds.direction.values):
                ax.plot(t[inside], ground.values[inside, k] / STANDARD_GRAVITY, lw=0.7, color=f"C{k}",
                        label=f"along {direction}")
            ax.legend(fontsize=7, loc="upper right")
        else:
            ax.plot(t[inside], ground.values[inside] / STANDARD_GRAVITY, lw=0.7, color="0.3")
        self.cursor = ax.axvline(self.times[0], color="C3", lw=1.0)
        ax.set_xlim(self.times[0], max(self.times[-1], self.times[0] + 1e-6))
        ax.set_xlabel("time (s)")
        ax.set_ylabel("ground acc. (g)")
        ax.grid(alpha=0.3)

    def draw(self, k: int) -> None:
        """Set every artist to frame *k*."""
        i = int(self.indices[k])
        at = self.scene.draw(i)
        force = self.forces[k]
        top = self.norm.vmax
        self.flash.set_offsets(at)
        self.flash.set_sizes(np.where(force > 0.0, 40.0 + 260.0 * force / top, 0.0))
        self.flash.set_array(force)
        for label, (x, y), f in zip(self.labels, at, force):
            label.set_visible(bool(f > 0.0))
            if f > 0.0:
                label.set_position((x + self.label_offset, y))
                label.set_text(force_text(float(f)))
        self.cursor.set_xdata([self.times[k], self.times[k]])
        self.clock.set_text(f"t = {self.times[k]:.2f} s")

    def frame(self, k: int) -> np.ndarray:
        """Frame *k* as an (height, width, 3) array of 8-bit RGB pixels."""
        self.draw(k)
        self.fig.canvas.draw()
        return np.asarray(self.fig.canvas.buffer_rgba())[..., :3].copy()

    def pixel(self, x: float, y: float) -> tuple[int, int]:
        """Row and column of the frame's pixel at the scene's point (*x*, *y*), m."""
        col, row = self.ax.transData.transform((x, y))
        return int(round(self.fig.bbox.height - row)), int(round(col))

    def save(self, path: str | os.PathLike) -> Path:
        """Write every frame to *path* (``.mp4`` or ``.gif``, :data:`SUFFIXES`) atomically; returns the path."""
        from pounding.results.archive import atomic_path

        target = Path(path)
        writer = _writer(target, self.fps)
        try:
            with atomic_path(target) as temporary, writer.saving(self.fig, temporary, self.fig.dpi):
                for k in range(self.n_frames):
                    self.draw(k)
                    writer.grab_frame()
        except (OSError, RuntimeError) as exc:   # ffmpeg's own failure (a broken pipe, an encoder error)
            if isinstance(exc, PoundingError):
                raise
            raise PoundingError(f"cannot write {target}: {' '.join(str(exc).split())[:200]}") from exc
        finally:
            pyplot().close(self.fig)
        return target

# --------------------------------------------------------------------------- #
# A planar model in elevation
# --------------------------------------------------------------------------- #


class _ElevationScene:
    """The buildings of a planar model side by side in elevation, drawn on *ax*; ``draw(i)`` sets them to
    stored sample *i* and returns each contact's marker position, m."""

    words = "elevation"

    def __init__(self, ds: xr.Dataset, ax, exaggerate: float | None):
        self.ds, self.ax = ds, ax
        order = building_order(ds)
        self.width = max(0.3 * float(ds.elevation.values.max()), 3.0)   # drawn width of a building, m
        self.floors = {b: np.flatnonzero(ds.building.values == b)[np.argsort(
            ds.level.values[ds.building.values == b])] for b in order}
        self.ground = ground_offsets(ds, order)
        peak = max(float(np.abs(ds.displacement.values[:, f] + self.ground[b][:, None]).max(initial=0.0))
                   for b, f in self.floors.items())
        self.factor = float(exaggerate) if exaggerate else _default_factor(ds, peak, 0.25 * self.width, self.width)
        self.x0 = self._positions(order)
        self.sides = self._contact_sides()
        self.lines = {b: ax.plot([], [], lw=1.4, color=f"C{k}", label=f"building {b}", gid=f"building {b}")[0]
                      for k, b in enumerate(order)}
        self.walls = [(ax.plot([], [], color="0.5", lw=4, solid_capstyle="butt",
                               label="wall" if k == 0 else None)[0], *wall) for k, wall in enumerate(self._walls())]
        self.rest = ax.plot([], [], "o", ms=3, color="0.4", label="contact", zorder=5, gid="contacts")[0]
        self._frame_axes()

    def _positions(self, order: list[str]) -> dict[str, float]:
        """Each building's left face at rest, m: the next one the exaggerated smallest gap between them
        beyond, or 0.3 widths where no contact joins them."""
        ds, x0, x = self.ds, {}, 0.0
        for k, b in enumerate(order):
            if k:
                pair = {order[k - 1], b}
                gaps = [float(g) for g, left, right in zip(ds.gap.values, ds.building_left.values,
                                                           ds.building_right.values) if {left, right} == pair]
                x += self.width + (self.factor * min(gaps) if gaps else 0.3 * self.width)
            x0[b] = x
        return x0

    def _side(self, i: int, side: str) -> tuple[np.ndarray, float]:
        """The drawn position history (m) of one side of contact *i*, and its elevation (m, NaN for a wall)."""
        ds = self.ds
        building = str(ds[f"building_{side}"].values[i])
        gap = float(ds.gap.values[i])
        if building == "wall":
            other = str(ds[f"building_{'right' if side == 'left' else 'left'}"].values[i])
            face = self.x0[other] + (-self.factor * gap if side == "left" else self.width + self.factor * gap)
            return face + self.factor * self.ground[other], float("nan")
        _, motion = side_displacement(ds, i, side)
        level = int(ds[f"level_{side}"].values[i])
        floors = self.floors[building]
        at = float(ds[f"at_{side}"].values[i]) if f"at_{side}" in ds.coords else float("nan")
        top = float(ds.elevation.values[floors[level - 1]])
        below = float(ds.elevation.values[floors[level - 2]]) if level > 1 else 0.0
        z = top if np.isnan(at) else below + at * (top - below)
        face = self.x0[building] + (self.width if side == "left" else 0.0)
        return face + self.factor * (motion + self.ground[building]), z

    def _contact_sides(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(time, contact) the drawn position of each contact's left and right side, m, and each contact's
        elevation, m (the floor's, or the column point's)."""
        count = self.ds.sizes.get("contact", 0)
        left, right, z = (np.zeros((self.ds.sizes["time"], count)), np.zeros((self.ds.sizes["time"], count)),
                          np.zeros(count))
        for i in range(count):
            left[:, i], z_left = self._side(i, "left")
            right[:, i], z_right = self._side(i, "right")
            z[i] = z_left if np.isfinite(z_left) else z_right   # a wall has none; a column point, its floor's
        return left, right, z

    def _walls(self) -> list[tuple[str, float, float]]:
        """Each wall as (building it stands by, drawn position at rest, m, top, m)."""
        ds, walls = self.ds, []
        for i in range(ds.sizes.get("contact", 0)):
            for side, other in (("left", "right"), ("right", "left")):
                if str(ds[f"building_{side}"].values[i]) == "wall":
                    building = str(ds[f"building_{other}"].values[i])
                    at = self.sides[0 if side == "left" else 1][0, i] - self.factor * self.ground[building][0]
                    walls.append((building, float(at), float(self.sides[2][i]) + 1.0))
        return walls

    def _frame_axes(self) -> None:
        ax = self.ax
        reach = self.factor * max(float(np.abs(self.ds.displacement.values).max(initial=0.0)), 1e-9) + \
            self.factor * max((float(np.abs(g).max(initial=0.0)) for g in self.ground.values()), default=0.0)
        low = min(self.x0.values()) - max(reach, 0.3 * self.width)
        high = max(self.x0.values()) + self.width + max(reach, 0.3 * self.width)
        for _, _, at, _ in self.walls:
            low, high = min(low, at - 0.3 * self.width), max(high, at + 0.3 * self.width)
        ax.axhline(0.0, color="0.3", lw=1.0)
        ax.set_xlim(low, high)
        ax.set_ylim(-0.02 * float(self.ds.elevation.values.max()), 1.08 * float(self.ds.elevation.values.max()))
        ax.set_xlabel(f"horizontal position (m; displacements and gaps x{self.factor:g})")
        ax.set_ylabel("elevation (m)")

    def draw(self, i: int) -> np.ndarray:
        ds, factor = self.ds, self.factor
        for b, line in self.lines.items():
            floors = self.floors[b]
            shift = self.ground[b][i]
            x = self.x0[b] + factor * np.r_[shift, ds.displacement.values[i, floors] + shift]
            z = np.r_[0.0, ds.elevation.values[floors]]
            slabs_x = np.column_stack([x[1:], x[1:] + self.width, np.full(x.size - 1, np.nan)]).ravel()
            slabs_z = np.column_stack([z[1:], z[1:], np.full(z.size - 1, np.nan)]).ravel()
            line.set_data(np.r_[x, np.nan, x + self.width, np.nan, slabs_x],
                          np.r_[z, np.nan, z, np.nan, slabs_z])
        for line, building, at, top in self.walls:
            shifted = at + factor * self.ground[building][i]
            line.set_data([shifted, shifted], [0.0, top])
        left, right, z = self.sides
        at = np.column_stack([0.5 * (left[i] + right[i]), z])
        self.rest.set_data(at[:, 0], at[:, 1])
        return at

# --------------------------------------------------------------------------- #
# Floors in plan
# --------------------------------------------------------------------------- #


class _PlanScene:
    """The floors of a model in plan, drawn on *ax*; ``draw(i)`` sets them to stored sample *i* and returns
    each contact point's marker position, m."""

    words = "plan (roofs solid, floors below thin, dashed: roofs at rest)"

    def __init__(self, ds: xr.Dataset, ax, exaggerate: float | None):
        self.ds, self.ax = ds, ax
        rest = np.stack([ds.corner_x.values, ds.corner_y.values], axis=-1)          # (floor, corner, 2)
        self.extent = float(max(np.ptp(rest[..., 0]), np.ptp(rest[..., 1]), 1.0))
        peak = float(ds.peak_corner_displacement_magnitude.max()) if ds.sizes.get("floor", 0) else 0.0
        self.factor = float(exaggerate) if exaggerate else _default_factor(ds, peak, 0.1 * self.extent,
                                                                            0.2 * self.extent)
        shift = self._shifts()
        names = [str(b) for b in ds.building.values]
        self.rest = rest + np.array([shift[b] for b in names])[:, None, :]
        # each floor's ground less the first building's (time, floor, 2): zeros under one ground motion
        grounds = ground_offsets(ds, list(dict.fromkeys(names)))
        self.ground = np.stack([grounds[b] for b in names], axis=1) if names else np.zeros((ds.sizes["time"], 0, 2))
        roofs = {b: int(np.flatnonzero(ds.building.values == b)[-1]) for b in dict.fromkeys(names)}
        self.outlines = []
        for k, (b, roof) in enumerate(roofs.items()):
            ax.plot(*np.r_[self.rest[roof], self.rest[roof][:1]].T, ls="--", lw=0.8, color=f"C{k}")
            for f in np.flatnonzero(ds.building.values == b):
                solid = f == roof
                line = ax.plot([], [], lw=1.6 if solid else 0.6, alpha=1.0 if solid else 0.45, color=f"C{k}",
                               label=f"building {b}" if solid else None, gid=f"floor {ds.floor.values[f]}")[0]
                self.outlines.append((int(f), line))
        self.roofs = list(roofs.values())
        self.corners = ax.plot([], [], "s", ms=3.5, color="k", label="roof corners", zorder=5)[0]
        self.points = self._points(shift)
        self.point_marks = ax.plot([], [], "o", ms=3, color="0.4", label="contact points", zorder=5,
                                   gid="contacts")[0]
        self._walls(shift)
        self._frame_axes()

    def _shifts(self) -> dict[str, np.ndarray]:
        """Each building's drawn shift from its place at rest, m (2,): across each gap (the smallest first) the
        building on the high side moves along the face's normal by (exaggeration − 1) × gap, so that drawn
        outlines touch when the gap closes."""
        ds = self.ds
        names = list(dict.fromkeys(str(b) for b in ds.building.values))
        shift = {names[0]: np.zeros(2)}
        joints = sorted((float(g), str(lo), str(hi), str(n)) for g, lo, hi, n in
                        zip(ds.gap.values, ds.building_left.values, ds.building_right.values, ds.point_normal.values)
                        if lo != "wall" and hi != "wall") if ds.sizes.get("contact", 0) else []
        grown = True
        while grown:
            grown = False
            for gap, low, high, normal in joints:
                step = (self.factor - 1.0) * gap * (np.array([1.0, 0.0]) if normal == "x" else np.array([0.0, 1.0]))
                if low in shift and high not in shift:
                    shift[high], grown = shift[low] + step, True
                elif high in shift and low not in shift:
                    shift[low], grown = shift[high] - step, True
        return {b: shift.get(b, np.zeros(2)) for b in names}

    def _points(self, shift: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Per contact point: the floor it moves with (its low side's, or the high side's against a wall on
        the low side), its drawn place at rest (m, on that floor's face) and its arm from the floor's centre."""
        ds = self.ds
        count = ds.sizes.get("contact", 0)
        floors, place, arm = np.zeros(count, int), np.zeros((count, 2)), np.zeros((count, 2))
        for i in range(count):
            side = "right" if str(ds.building_left.values[i]) == "wall" else "left"
            building = str(ds[f"building_{side}"].values[i])
            f = int(np.flatnonzero(ds.floor.values == f"{building}:{int(ds[f'level_{side}'].values[i])}")[0])
            normal = np.array([1.0, 0.0]) if str(ds.point_normal.values[i]) == "x" else np.array([0.0, 1.0])
            point = np.array([float(ds.point_x.values[i]), float(ds.point_y.values[i])])
            point = point + (float(ds.gap.values[i]) * normal if side == "right" else 0.0)
            floors[i], place[i] = f, point + shift[building]
            arm[i] = point - np.array([float(ds.floor_centre_x.values[f]), float(ds.floor_centre_y.values[f])])
        return {"floor": floors, "place": place, "arm": arm}

    def _walls(self, shift: dict[str, np.ndarray]) -> None:
        """Each wall a contact point strikes, a thick grey line, its gap exaggerated as the displacements."""
        ds, drawn = self.ds, False
        for face in np.unique(ds.point_face.values) if ds.sizes.get("contact", 0) else ():
            mine = np.flatnonzero(ds.point_face.values == face)
            i = int(mine[0])
            high, low = str(ds.building_right.values[i]) == "wall", str(ds.building_left.values[i]) == "wall"
            gap = float(ds.gap.values[i])
            if not (high or low) or gap > self.extent:   # a wall held open beyond the plan: left out
                continue
            axis = 0 if str(ds.point_normal.values[i]) == "x" else 1
            place = self.points["place"][mine]
            across = place[:, axis].mean() + (self.factor * gap if high else -self.factor * gap)
            along = [place[:, 1 - axis].min() - 0.05 * self.extent, place[:, 1 - axis].max() + 0.05 * self.extent]
            xs, ys = ([across] * 2, along) if axis == 0 else (along, [across] * 2)
            self.ax.plot(xs, ys, color="0.5", lw=4, solid_capstyle="butt", label=None if drawn else "wall")
            drawn = True

    def _frame_axes(self) -> None:
        ax = self.ax
        reach = 0.15 * self.extent + self.factor * float(np.abs(self.ds.corner_displacement.values).max(initial=0.0))
        low, high = self.rest.reshape(-1, 2).min(axis=0) - reach, self.rest.reshape(-1, 2).max(axis=0) + reach
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        ax.set_xlabel(f"x (m; displacements and gaps x{self.factor:g})")
        ax.set_ylabel("y (m)")

    def draw(self, i: int) -> np.ndarray:
        ds, factor = self.ds, self.factor
        moved = self.rest + factor * (ds.corner_displacement.values[i] + self.ground[i][:, None, :])
        for f, line in self.outlines:
            line.set_data(*np.r_[moved[f], moved[f][:1]].T)
        self.corners.set_data(*moved[self.roofs].reshape(-1, 2).T)
        floors, arm = self.points["floor"], self.points["arm"]
        theta = ds.rotation.values[i, floors]
        motion = (ds.displacement.values[i, floors] + self.ground[i, floors]
                  + theta[:, None] * np.column_stack([-arm[:, 1], arm[:, 0]]))
        at = self.points["place"] + factor * motion
        self.point_marks.set_data(at[:, 0], at[:, 1])
        return at


def _default_factor(ds: xr.Dataset, peak: float, drawn: float, room: float) -> float:
    """The default exaggeration: the largest displacement *peak* (m) drawn as about *drawn* (m), yet no gap
    drawn wider than *room* (m; a run that hardly moves would push its buildings apart); a gap wider than
    *room* at true scale (a wall held open) does not count."""
    factor = magnification(peak, drawn)
    gaps = [float(g) for g in (ds.gap.values if ds.sizes.get("contact", 0) else ()) if 0.0 < g < room]
    return min(factor, magnification(max(gaps), room)) if gaps else factor


def _fit_aspect(ax) -> None:
    """Widen *ax*'s x or y limits about their middle so that a metre is as long across as up (its box laid
    out: matplotlib's own equal aspect shrank the fixed limits of a tall elevation instead)."""
    box = ax.get_window_extent()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    ratio = (box.width / box.height) / ((x1 - x0) / (y1 - y0))
    if ratio > 1.0:
        middle, half = 0.5 * (x0 + x1), 0.5 * (x1 - x0) * ratio
        ax.set_xlim(middle - half, middle + half)
    else:
        middle, half = 0.5 * (y0 + y1), 0.5 * (y1 - y0) / ratio
        ax.set_ylim(middle - half, middle + half)


def film_format(path: str | os.PathLike) -> str:
    """The suffix of the film *path* (``.mp4`` or ``.gif``), refused in one line if unknown, or if it is an
    MP4 and ffmpeg is not installed (checked before any work)."""
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in SUFFIXES:
        raise PoundingError(f"-o {target}: unknown suffix {target.suffix or '(none)'}; write "
                            + " or ".join(f"{s} ({what})" for s, what in SUFFIXES.items()))
    if suffix == ".mp4" and not FFMpegWriter.isAvailable():
        raise PoundingError(f"-o {target}: writing an .mp4 needs ffmpeg, which is not installed (Debian: apt-get "
                            "install ffmpeg); or write a .gif instead")
    return suffix


def _writer(path: Path, fps: float):
    """The matplotlib movie writer of *path*: ffmpeg for ``.mp4``, Pillow for ``.gif``."""
    if film_format(path) == ".mp4":   # the temporary file has no .mp4 suffix: the container is named (-f)
        return FFMpegWriter(fps=fps, codec="h264", extra_args=["-pix_fmt", "yuv420p", "-f", "mp4"])
    return _GifWriter(fps=fps)


class _GifWriter(PillowWriter):
    """Pillow's writer with each frame kept in 256 colours (a quarter of the memory of RGB) and the file
    written as GIF whatever its name (the atomic write's temporary name has no .gif)."""

    def grab_frame(self, **savefig_kwargs):
        super().grab_frame(**savefig_kwargs)
        self._frames[-1] = self._frames[-1].convert("RGB").quantize(colors=256)

    def finish(self):
        self._frames[0].save(self.outfile, format="GIF", save_all=True, append_images=self._frames[1:],
                             duration=int(round(1000.0 / self.fps)), loop=0)
