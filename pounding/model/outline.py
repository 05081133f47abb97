"""Contacts from plan geometry: facing edges, gaps, contact points and their weight vectors.

Pure functions on outlines ``((x0, y0), (x1, y1))`` (m, one global plan frame) and
floor centres of mass; no YAML.  Two outlines *face* each other along x when
their y-ranges overlap over a positive length and their x-ranges do not overlap:
the low building's face x = x1_L faces the high building's x = x0_H, the gap is
``x0_H − x1_L`` (0 when they touch) and the contact points are the two ends of
the overlap of the facing edges, fixed at their rest positions.  Likewise along y.

Penetration at a point p (positive is overlap), small rotations::

    δ = [u_n,L − …θ_L…](p) − [u_n,H − …θ_H…](p) − g = w_L · q_L + w_H · q_H − g

with w the point's displacement weights along the normal
(:func:`pounding.model.plan.point_weights`), each floor about its own centre of
mass.  The penetration is linear along the face, so its largest value is at
an end of the overlap: two points are exact.  The tangential slip of a face
(for friction) is the same at every point: the tangential displacement of the
low building's material point on its face minus the high building's on its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pounding.model.floors import Outline, point_weights

__all__ = ["Face", "ContactPoint", "WALL_FACES", "place_label", "facing", "edge_distance", "GAP_DECIMALS", "overlap_at_rest", "face_points", "wall_face", "wall_side", "wall_blocked_by",
           "penetration_weights", "slip_weights"]

#: A wall's face of a building: (normal direction, True if the building is on the low side).
WALL_FACES = {"east": ("x", True), "west": ("x", False), "north": ("y", True), "south": ("y", False)}


@dataclass(frozen=True)
class Face:
    """Two facing edges at rest.

    Attributes
    ----------
    normal : {"x", "y"}
        The face normal (the direction of the impacts).
    first_low : bool
        True if the contact's first side (``between[0]``) is the low one (smaller coordinate along the normal).
    gap : float
        Distance between the edges at rest, m (≥ 0).
    face_low, face_high : float
        The edges' coordinates along the normal: the low side's far edge, the high side's near edge, m.
    span : (float, float)
        The two ends of the overlap along the tangent, m (ascending).
    """

    normal: str
    first_low: bool
    gap: float
    face_low: float
    face_high: float
    span: tuple[float, float]

    @property
    def tangent(self) -> str:
        """The face's tangential direction."""
        return "y" if self.normal == "x" else "x"


@dataclass(frozen=True)
class ContactPoint:
    """One contact point of a face between floor ``level_first`` and floor ``level_second``.

    Attributes
    ----------
    location : (float, float)
        The point at rest: at an end of the overlap along the tangent, on the low side's edge (on the
        building's own edge at a wall), m.
    weights : (2, 3) ndarray
        Penetration weights over (u_x, u_y, θ) of the first side's floor (row 0) and the second's (row 1;
        zeros for a wall): ``δ = weights[0]·q_first + weights[1]·q_second − gap``.
    slip : (2, 3) ndarray
        The face's tangential slip weights (low minus high side, along +tangent), the same rows.
    """

    location: tuple[float, float]
    weights: np.ndarray
    slip: np.ndarray


def _intervals(outline: Outline) -> tuple[tuple[float, float], tuple[float, float]]:
    (x0, y0), (x1, y1) = outline
    return (x0, x1), (y0, y1)


def _overlap(a: tuple[float, float], b: tuple[float, float]) -> float:
    return min(a[1], b[1]) - max(a[0], b[0])


def overlap_at_rest(first: Outline, second: Outline) -> bool:
    """True if two outlines share an area of positive size at rest (touching edges do not)."""
    (ax, ay), (bx, by) = _intervals(first), _intervals(second)
    return _overlap(ax, bx) > 0.0 and _overlap(ay, by) > 0.0


#: Decimal places (m) a gap between two outlines is rounded to: the picometre.
GAP_DECIMALS = 12


def place_label(point: tuple[float, float]) -> str:
    """``(24,10)``, ``(24.05,10)``: a point in plan (m) to the millimetre, trailing zeros dropped.

    Site coordinates keep every digit (``(500024,4100016)``), where ``:g`` would print
    ``4.10002e+06`` and give two points 4 m apart one label.
    """
    def metres(value: float) -> str:
        text = f"{value:.3f}".rstrip("0").rstrip(".")
        return "0" if text in ("-0", "") else text

    return f"({metres(point[0])},{metres(point[1])})"


def edge_distance(low: float, high: float) -> float:
    """The gap (m) between a face at *low* and the facing one at *high*, rounded to :data:`GAP_DECIMALS`.

    Outline coordinates are decimal metres that binary floats hold inexactly, so their difference carries
    round-off (20.05 − 20.0 = 0.05000000000000071); rounded to the picometre, reports and archives show the
    gap the user wrote, 1e4 times below the solver's displacement tolerance.
    """
    return round(high - low, GAP_DECIMALS)


def facing(first: Outline, second: Outline) -> Face | None:
    """The face between two outlines, or None when they do not face each other (diagonal, or overlapping)."""
    first_ranges, second_ranges = _intervals(first), _intervals(second)
    for normal, axis in (("x", 0), ("y", 1)):
        tangent = 1 - axis
        a_n, b_n = first_ranges[axis], second_ranges[axis]
        a_t, b_t = first_ranges[tangent], second_ranges[tangent]
        if _overlap(a_t, b_t) <= 0.0 or _overlap(a_n, b_n) > 0.0:
            continue
        first_low = a_n[1] <= b_n[0]
        low, high = (a_n, b_n) if first_low else (b_n, a_n)
        span = (max(a_t[0], b_t[0]), min(a_t[1], b_t[1]))
        return Face(normal, first_low, edge_distance(low[1], high[0]), low[1], high[0], span)
    return None


def wall_face(outline: Outline, side: str, gap: float) -> Face:
    """The face between a building and a wall on its *side* (east, west, north, south) spanning that whole edge.

    The building is the contact's first side; the wall stands *gap* m beyond its edge.
    """
    normal, building_low = WALL_FACES[side]
    (x0, x1), (y0, y1) = _intervals(outline)
    low_edge, high_edge, span = ((x1, x0, (y0, y1)) if normal == "x" else (y1, y0, (x0, x1)))
    edge = low_edge if building_low else high_edge
    face_low, face_high = (edge, edge + gap) if building_low else (edge - gap, edge)
    return Face(normal, building_low, float(gap), face_low, face_high, span)


def wall_blocked_by(face: Face, outlines: list[Outline]) -> int | None:
    """The index of the first of *outlines* standing between a building's edge and its wall's *face* (or
    beyond the wall, over the face's span), None if the strip is open ground.

    The strip runs from the building's edge to the wall along the normal (``face_low``..``face_high``)
    and over ``face.span`` along the tangent; an outline overlapping it by a positive area blocks it.
    """
    axis = 0 if face.normal == "x" else 1
    for index, outline in enumerate(outlines):
        ranges = _intervals(outline)
        along, across = ranges[axis], ranges[1 - axis]
        if _overlap(across, face.span) <= 0.0:
            continue
        beyond = along[0] >= face.face_high if face.first_low else along[1] <= face.face_low
        if not beyond and _overlap(along, (face.face_low, face.face_high)) > 0.0:
            return index
    return None


def wall_side(face: Face) -> str:
    """The side of the building (``east``, ``west``, ``north``, ``south``) that a wall's *face* stands beside."""
    return next(side for side, (normal, low) in WALL_FACES.items() if normal == face.normal and low == face.first_low)


def _on_tangent(face: Face, s: float, normal_coordinate: float) -> tuple[float, float]:
    return (normal_coordinate, s) if face.normal == "x" else (s, normal_coordinate)


def penetration_weights(face: Face, point: float, centre_first: tuple[float, float],
                        centre_second: tuple[float, float] | None) -> np.ndarray:
    """(2, 3) penetration weights at tangential coordinate *point* (m) of *face*.

    Rows: the first side's floor (u_x, u_y, θ about *centre_first*), the second's
    (about *centre_second*; None for a wall: zeros).  ``δ = Σ rows·q − gap``.
    """
    location = _on_tangent(face, point, face.face_low)
    sign = 1.0 if face.first_low else -1.0
    rows = np.zeros((2, 3))
    rows[0] = sign * point_weights(centre_first, location, face.normal)
    if centre_second is not None:
        rows[1] = -sign * point_weights(centre_second, location, face.normal)
    return rows


def slip_weights(face: Face, centre_first: tuple[float, float], centre_second: tuple[float, float] | None) -> np.ndarray:
    """(2, 3) tangential slip weights of *face*: low side's material point on its face minus the high side's on its own.

    A rigid floor's (small-rotation) motion along a line is the same at every point
    of the line, so one vector serves every point of the face; each side's lever
    arm runs from its own centre of mass to its own face.
    """
    lever = {True: face.face_low, False: face.face_high}     # first side low -> its face is face_low
    rows = np.zeros((2, 3))
    sign = 1.0 if face.first_low else -1.0
    rows[0] = sign * point_weights(centre_first, _on_tangent(face, 0.0, lever[face.first_low]), face.tangent)
    if centre_second is not None:
        rows[1] = -sign * point_weights(centre_second, _on_tangent(face, 0.0, lever[not face.first_low]), face.tangent)
    return rows


def face_points(face: Face, centre_first: tuple[float, float],
                centre_second: tuple[float, float] | None) -> tuple[ContactPoint, ContactPoint]:
    """The face's two contact points (the ends of the overlap), with their penetration and slip weights.

    A point lies on the low side's edge between two buildings, and on the building's own edge at a wall, so it
    stays where it is when the gap changes (a wall 1e6 m away in a run without contacts).  Along the normal its
    coordinate does not enter the weights (a rigid floor moves alike along a line normal to the face).
    """
    slip = slip_weights(face, centre_first, centre_second)
    edge = face.face_low if centre_second is not None or face.first_low else face.face_high
    return tuple(ContactPoint(_on_tangent(face, s, edge),
                              penetration_weights(face, s, centre_first, centre_second), slip)
                 for s in face.span)   # type: ignore[return-value]
