"""A site's seismic hazard curve: the mean annual frequency λ_IM(x) with which the intensity measure exceeds x.

Two sources (:func:`read_hazard`):

* a file of two columns, the intensity in g and the mean annual frequency of exceedance (1/yr), one
  row per intensity (comma, semicolon or blanks between them; ``#`` starts a comment; a first line of
  words is a header).  This is how the USGS Unified Hazard Tool and OpenQuake export a curve.
* ``power:k0,k``: the power law λ_IM(x) = k0 · x^(−k), x in g (Cornell, Jalayer, Hamburger & Foutch 2002,
  J. Struct. Eng. 128(4) 526–533,), the fit that gives the risk integrals their closed form.

Between the tabulated points the curve is interpolated linearly in log–log (a power law on each segment,
exact for a power-law curve); beyond its ends each end segment's power law is extended
(:meth:`HazardCurve.rate`).  Internally intensities are in m/s² (SI); files and ``power:`` are in g, as
hazard curves are published.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pounding.errors import PoundingError
from pounding.units import STANDARD_GRAVITY

__all__ = ["HazardCurve", "read_hazard", "power_law", "read_hazard_file", "MAX_INTENSITY_G", "POWER_SPAN_G",
           "EXAMPLE_HAZARD"]

#: Largest intensity a hazard curve in g may hold: no recorded spectral acceleration reaches 5 g; a larger
#: value is almost surely in cm/s² (gal) or m/s².
MAX_INTENSITY_G = 5.0
#: Intensities (g) over which a power law ``power:k0,k`` is tabulated: the integrals extend it beyond.
POWER_SPAN_G = (1e-3, MAX_INTENSITY_G)
#: The shipped example curve (``--hazard example``): synthetic, see its header.
EXAMPLE_HAZARD = "example"


@dataclass(frozen=True)
class HazardCurve:
    """A hazard curve tabulated at increasing intensities.

    Attributes
    ----------
    intensity : ndarray
        Intensities, m/s², strictly increasing, > 0.
    annual_rate : ndarray
        Mean annual frequency of exceedance at each intensity, 1/yr, strictly decreasing, > 0.
    source : str
        Where it comes from (a file name, or ``power:k0,k``), for messages and archives.
    """

    intensity: np.ndarray
    annual_rate: np.ndarray
    source: str

    def slopes(self) -> np.ndarray:
        """Each segment's log–log slope k_i = −Δ ln λ / Δ ln x (> 0), one per segment."""
        return -np.diff(np.log(self.annual_rate)) / np.diff(np.log(self.intensity))

    def rate(self, intensity) -> np.ndarray:
        """λ_IM(x) at intensities *x* (m/s²), 1/yr: log–log interpolation, end segments' power laws beyond."""
        x = np.log(np.asarray(intensity, dtype=float))
        lx, ly = np.log(self.intensity), np.log(self.annual_rate)
        k = self.slopes()
        i = np.clip(np.searchsorted(lx, x, side="right") - 1, 0, lx.size - 2)
        return np.exp(ly[i] - k[i] * (x - lx[i]))

    def slope(self, intensity) -> np.ndarray:
        """The local log–log slope k(x) = −d ln λ / d ln x at intensities *x* (m/s²), that of each segment."""
        x = np.log(np.asarray(intensity, dtype=float))
        lx = np.log(self.intensity)
        i = np.clip(np.searchsorted(lx, x, side="right") - 1, 0, lx.size - 2)
        return self.slopes()[i]

    def intensity_at(self, annual_rate) -> np.ndarray:
        """The intensity (m/s²) whose rate of exceedance is *annual_rate* (1/yr): the inverse of :meth:`rate`."""
        y = np.log(np.asarray(annual_rate, dtype=float))
        lx, ly = np.log(self.intensity), np.log(self.annual_rate)
        k = self.slopes()
        i = np.clip(np.searchsorted(-ly, -y, side="right") - 1, 0, lx.size - 2)
        return np.exp(lx[i] + (ly[i] - y) / k[i])

    def describe(self) -> str:
        g = self.intensity / STANDARD_GRAVITY
        return (f"hazard curve {self.source}: {self.intensity.size} points, {g[0]:.3g}-{g[-1]:.3g} g, "
                f"{self.annual_rate[0]:.3g}-{self.annual_rate[-1]:.3g} /yr")


def power_law(k0: float, k: float, *, source: str | None = None) -> HazardCurve:
    """The power-law curve λ_IM(x) = k0 · x^(−k) (x in g) tabulated at the ends of :data:`POWER_SPAN_G`
    (one segment: log–log interpolation and its extension are then the power law everywhere)."""
    what = source or f"power:{k0:g},{k:g}"
    if not (math.isfinite(k0) and k0 > 0):
        raise PoundingError(f"--hazard {what}: k0 (the rate of exceedance of 1 g, 1/yr) must be > 0, e.g. "
                            "power:4e-4,3")
    if not (math.isfinite(k) and k > 0):
        raise PoundingError(f"--hazard {what}: k (the log-log slope of the curve) must be > 0, e.g. power:4e-4,3")
    g = np.array(POWER_SPAN_G)
    return HazardCurve(g * STANDARD_GRAVITY, k0 * g ** -k, what)


def read_hazard(spec: str | os.PathLike) -> HazardCurve:
    """``--hazard``: a file of two columns (intensity in g, annual rate of exceedance), ``power:k0,k``, or
    ``example`` (the shipped synthetic curve, :data:`EXAMPLE_HAZARD`)."""
    text = os.fspath(spec).strip()
    if text.lower().startswith("power:"):
        pieces = text.split(":", 1)[1].split(",")
        try:
            k0, k = (float(p) for p in pieces)
        except ValueError:
            raise PoundingError(f"--hazard {text!r}: write power:k0,k (the curve k0 x^-k, x in g), e.g. "
                                "power:4e-4,3") from None
        return power_law(k0, k, source=text)
    if text == EXAMPLE_HAZARD and not Path(text).exists():
        from pounding.data import data_path

        return read_hazard_file(data_path("hazard", "example_sa1s.csv"))
    return read_hazard_file(text)


_SPLIT = re.compile(r"[,;\s]+")


def _rows(path: Path, text: str) -> list[tuple[int, float, float]]:
    """The (line, intensity in g, rate) rows of a hazard file; a first line of words is a header."""
    rows: list[tuple[int, float, float]] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        cells = [c for c in _SPLIT.split(line) if c]
        try:
            values = [float(c) for c in cells]
        except ValueError:
            if not rows and not any(_is_number(c) for c in cells):   # a header of words
                continue
            raise PoundingError(f"a row must be two numbers: the intensity in g and its annual rate of "
                                f"exceedance (got {line!r})", file=str(path), line=number) from None
        if len(values) != 2:
            raise PoundingError(f"a row must be two numbers, the intensity in g and its annual rate of "
                                f"exceedance (got {len(values)})", file=str(path), line=number)
        if not all(math.isfinite(v) for v in values):
            raise PoundingError(f"{line!r} is not two finite numbers", file=str(path), line=number)
        rows.append((number, values[0], values[1]))
    return rows


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def read_hazard_file(path: str | os.PathLike) -> HazardCurve:
    """A hazard curve file (module docstring), checked row by row: each error one line naming the row."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise PoundingError(f"--hazard {os.fspath(path)}: no such file; give a file of two columns (intensity "
                            "in g, annual rate of exceedance), power:k0,k, or example") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise PoundingError(f"--hazard {os.fspath(path)}: cannot read it ({exc})") from None
    rows = _rows(path, text)
    if len(rows) < 2:
        raise PoundingError("a hazard curve needs at least 2 rows (intensity in g, annual rate of exceedance); "
                            f"found {len(rows)}", file=str(path))
    where = str(path)
    for (line, x, rate), previous in zip(rows, [None] + rows[:-1]):
        if x <= 0 or rate <= 0:
            what = "intensity" if x <= 0 else "annual rate of exceedance"
            raise PoundingError(f"the {what} must be > 0 (got {x if x <= 0 else rate:g}); drop rows of rate 0 "
                                "beyond the curve's end", file=where, line=line)
        if x > MAX_INTENSITY_G:
            raise PoundingError(f"intensity {x:g} is above {MAX_INTENSITY_G:g} g: the first column must be in g "
                                f"(a value in cm/s2 divides by 981, in m/s2 by 9.81)", file=where, line=line)
        if previous is not None:
            if x <= previous[1]:
                raise PoundingError(f"intensities must increase down the file ({x:g} g after {previous[1]:g} g "
                                    f"on line {previous[0]})", file=where, line=line)
            if rate >= previous[2]:
                raise PoundingError(f"the annual rate of exceedance must decrease as the intensity increases "
                                    f"({rate:g} /yr at {x:g} g after {previous[2]:g} /yr at {previous[1]:g} g): "
                                    "is the second column a rate of exceedance, 1/yr?", file=where, line=line)
    g = np.array([r[1] for r in rows])
    return HazardCurve(g * STANDARD_GRAVITY, np.array([r[2] for r in rows]), where)
