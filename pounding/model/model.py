"""The one description of a structure: buildings, contacts, links, ground motion and solver settings.

Every model file lowers into a :class:`Model` (docs/architecture.md).  A planar file
(buildings in a row, storeys with a stiffness) and a plan file (buildings with
``plan:``, storeys with planes) are validated by their own YAML front-ends
(:mod:`pounding.model.schema`, :mod:`pounding.model.plan_schema`) and give the same
objects: :class:`~pounding.model.building.Building` (floors with one or three
degrees of freedom, storeys whose planes resist their drift, damping), one
:class:`GapElement` per contact point between two floors (or a floor and a fixed
wall; a point of a column), the :class:`ContactFace` of every contact between two
floors in plan (its geometry, points and friction), the :class:`Link` elements, the
:class:`~pounding.model.ground.GroundMotionSpec` (one component, or two with an
angle; one per building or one for all) and the solver settings.  The solver's
assembly, the results and every study read this description; where the physics
differs (two components, corners, friction) the difference is in its data.
SI units throughout (kg, N/m, m, s).

>>> from pounding.model import load_model
>>> model = load_model("models/pair.yaml")            # doctest: +SKIP
>>> model.periods["A"][:3]                             # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from collections.abc import Mapping
from typing import Any

import numpy as np

from pounding.model import floors, outline, schema
from pounding.model.building import Building, Damping, planar_storeys
from pounding.model.foundation import Foundation, on_soil
from pounding.model.foundation_impedance import Footing, Soil
from pounding.model.document import dump_document, is_plan_document, parse_document
from pounding.model.ground import Component, GroundMotionSpec
from pounding.contact import xi as xi_formulas
from pounding.contact.laws import ContactLaw, HertzDamp
from pounding.contact.links import LinkLaw
from pounding.errors import ModelError, PoundingError, did_you_mean

__all__ = [
    "Damping",
    "Building",
    "GapElement",
    "ContactFace",
    "Link",
    "Component",
    "GroundMotionSpec",
    "SolverSettings",
    "Model",
    "load_model",
    "model_from_text",
    "model_from_data",
    "read_yaml_text",
    "is_plan_file",
    "WALL",
    "column_weights",
    "OPEN_GAP",
    "hold_contacts_open",
]

#: Gap (m) of a contact held open (:data:`pounding.model.schema.OPEN_GAP`).
OPEN_GAP = schema.OPEN_GAP


def hold_contacts_open(document: dict[str, Any]) -> dict[str, Any]:
    """Set every contact of a plain model *document* to :data:`OPEN_GAP` (in place; returned).

    The document form of :meth:`Model.with_contacts_open`, for the studies that edit model documents.
    """
    for contact in document.get("contacts") or []:
        contact["gap"] = OPEN_GAP
    return document


#: Building index of a fixed wall in a gap element's sides (:data:`pounding.model.schema.WALL`).
WALL = schema.WALL


def column_weights(at: float) -> tuple[float, float]:
    """Hermite shape functions ``(N1, N2)`` of a fixed-fixed column at fraction *at* of its height.

    ``N1 = 1 − 3ξ² + 2ξ³`` (floor below), ``N2 = 3ξ² − 2ξ³`` (floor above): the
    column point's displacement ``N1·u_below + N2·u_above`` under end
    displacements of rigid floors, and the shares of a point force there taken
    by the floor below and the floor above (the fixed-fixed beam's end shears
    ``P(1−ξ)²(1+2ξ)`` and ``Pξ²(3−2ξ)``; docs/physics.md §12).
    """
    xi = float(at)
    n2 = xi * xi * (3.0 - 2.0 * xi)
    return 1.0 - n2, n2


def _trusted(cls: type, **values: Any) -> Any:
    """An instance of dataclass *cls* from values already validated (no second check)."""
    obj = cls.__new__(cls)
    for key, value in values.items():
        object.__setattr__(obj, key, value)
    return obj


# --------------------------------------------------------------------------- #
# Gaps, ground motion, solver settings
# --------------------------------------------------------------------------- #


#: The side of the building a wall stands beside, by the contact's normal and the wall's side of the gap element.
_WALL_SIDES = {("x", "right"): "east", ("x", "left"): "west", ("y", "right"): "north", ("y", "left"): "south"}


@dataclass(frozen=True)
class GapElement:
    """One contact point between floor ``level_left`` of building ``left`` (the low side along the
    normal) and floor ``level_right`` of building ``right``, or between a building and a fixed wall
    (``left`` or ``right`` is :data:`WALL`, its level 0).

    Penetration ``δ = u_left − u_right − gap`` (m, positive = overlap), each side's displacement
    along the ``normal`` at the ``point`` (a floor of one degree of freedom moves alike
    everywhere); a wall's displacement relative to the ground is 0.  A side with ``at_*``
    set is a point of a column: ``level_*`` is then its storey and ``at_*`` the fraction of
    the storey height above the floor below (0 < at < 1).  In a planar row ``right = left + 1``.

    Attributes
    ----------
    contact : int
        Index of the YAML ``contacts`` entry it came from.
    left, right : int
        Building indices (left to right).
    level_left, level_right : int
        1-based floor numbers (storey numbers for a column point; 0 for a wall).
    gap : float
        Separation at rest, m.
    law : ContactLaw
    at_left, at_right : float or None
        Column point: fraction of the storey height; None for a floor or a wall.
    normal : {"x", "y"}
        Direction of the impacts (a planar row: x).
    point : (float, float) or None
        The point in plan at rest, m (None: floors of one degree of freedom).
    face : int or None
        Index of its :class:`ContactFace` in ``Model.faces`` (None in a planar model).
    """

    contact: int
    left: int
    right: int
    level_left: int
    level_right: int
    gap: float
    law: ContactLaw
    at_left: float | None = None
    at_right: float | None = None
    normal: str = "x"
    point: tuple[float, float] | None = None
    face: int | None = None

    @property
    def has_wall(self) -> bool:
        """True if one side is a fixed wall."""
        return WALL in (self.left, self.right)

    @property
    def has_column_point(self) -> bool:
        """True if one side is a point of a column between floors."""
        return self.at_left is not None or self.at_right is not None

    def side_label(self, names: list[str], side: str) -> str:
        """``A:3`` (floor), ``A:s4@0.5`` (storey 4's column at half its height) or ``wall``."""
        building, level, at = ((self.left, self.level_left, self.at_left) if side == "left"
                               else (self.right, self.level_right, self.at_right))
        if building == WALL and self.point is not None:   # in plan: the wall's side of the building
            return f"{schema.WALL_NAME}:{_WALL_SIDES[(self.normal, side)]}"
        if building == WALL:
            return schema.WALL_NAME
        return f"{names[building]}:{level}" if at is None else f"{names[building]}:s{level}@{at:g}"

    def label(self, names: list[str]) -> str:
        """Gap element label, e.g. ``A:3-B:3``, ``A:1-wall``, ``A:3-B:s4@0.5``; a point in plan adds its place,
        ``A:3-B:3@(24,10)``."""
        where = "" if self.point is None else f"@{outline.place_label(self.point)}"
        return f"{self.side_label(names, 'left')}-{self.side_label(names, 'right')}{where}"

    def level_document(self, side: str) -> Any:
        """The YAML of one side: a floor number, or ``{storey: s, at: x}``."""
        level, at = (self.level_left, self.at_left) if side == "left" else (self.level_right, self.at_right)
        return int(level) if at is None else {"storey": int(level), "at": float(at)}


@dataclass(frozen=True)
class ContactFace:
    """One face of a contact entry between floors in plan: floor ``level_first`` of ``first`` and
    ``level_second`` of ``second`` (YAML order; ``second`` is :data:`WALL` for a wall).

    Attributes
    ----------
    contact : int
        Index of the YAML ``contacts`` entry.
    first, second : int
        Building indices (``second`` is :data:`WALL` for a wall).
    level_first, level_second : int
        1-based floors (0 for the wall).
    face : pounding.model.outline.Face
        Normal, gap, the overlap's ends.
    points : tuple of ContactPoint
        The face's contact points with their penetration and slip weights (their gap elements
        follow one another in ``Model.gaps``).
    law : ContactLaw
        Applied at each point.
    friction : float or None
        Coulomb μ on the face.
    at_first, at_second : float or None
        A side that is a point of a column: ``level_*`` is its storey and ``at_*`` the fraction of its
        height above the floor below (None: a floor).
    """

    contact: int
    first: int
    second: int
    level_first: int
    level_second: int
    face: outline.Face
    points: tuple[outline.ContactPoint, ...]
    law: Any
    friction: float | None = None
    at_first: float | None = None
    at_second: float | None = None

    @property
    def gap(self) -> float:
        """Separation at rest, m."""
        return self.face.gap

    def label(self, names: list[str]) -> str:
        """``A:3-B:3`` (or ``A:1-wall``): the two floors of the face, in the YAML order."""
        second = schema.WALL_NAME if self.second == WALL else f"{names[self.second]}:{self.level_second}"
        return f"{names[self.first]}:{self.level_first}-{second}"

    def point_elements(self, index: int) -> tuple[GapElement, ...]:
        """The face's gap elements (one per point, the low side on the left), *index* its place in ``Model.faces``."""
        first, second = (self.first, self.level_first, self.at_first), (self.second, self.level_second, self.at_second)
        low, high = (first, second) if self.face.first_low else (second, first)
        return tuple(GapElement(self.contact, low[0], high[0], low[1], high[1], self.face.gap, self.law, low[2],
                                high[2], normal=self.face.normal, point=tuple(float(v) for v in p.location), face=index)
                     for p in self.points)


@dataclass(frozen=True)
class Link:
    """A permanent link (damper) between floor ``level_left`` of building ``left``
    and floor ``level_right`` of building ``right`` (in a planar row ``right = left + 1``): always
    engaged, no gap, pulls as well as pushes (docs/physics.md §9).

    Attributes
    ----------
    entry : int
        Index of the YAML ``links`` entry it came from.
    left, right : int
        Building indices (the low side along the normal on the left).
    level_left, level_right : int
        1-based floor numbers.
    law : LinkLaw
    normal : {"x", "y"}
        The direction it acts along (a planar row: x).
    point : (float, float) or None
        Where it joins the floors in plan, m: the middle of the facing edges' overlap (None: floors of
        one degree of freedom).
    """

    entry: int
    left: int
    right: int
    level_left: int
    level_right: int
    law: LinkLaw
    normal: str = "x"
    point: tuple[float, float] | None = None

    def label(self, names: list[str]) -> str:
        """``A:4-B:4`` (a point in plan adds its place, ``A:4-B:4@(24,13)``)."""
        where = "" if self.point is None else f"@{outline.place_label(self.point)}"
        return f"{names[self.left]}:{self.level_left}-{names[self.right]}:{self.level_right}{where}"


@dataclass(frozen=True)
class SolverSettings:
    """Integration settings.

    Attributes
    ----------
    rtol : float
        Relative tolerance, ≥ 1e-12.
    atol : float
        Absolute tolerance on displacements, m.
    atol_velocity : float
        Absolute tolerance on velocities, m/s.
    output_dt : float
        Sampling interval of the stored histories, s.
    stop_drift_ratio : float or None
        End the run (status ``collapsed``) when a storey's |drift ratio| first
        exceeds this; None: never.
    tolerance_scaling : bool
        Tighten ``atol`` and ``atol_velocity`` for a building far stiffer than
        the row moves (its static drift scale below 100·atol;
        :mod:`pounding.solver.tolerances`).  False: the given values for every floor.
    linear_phases : str
        ``exact``: phases with every contact open and every storey on its elastic branch are advanced
        by their exact state transition where that is cheaper than Runge–Kutta steps
        (:mod:`pounding.solver.closed_form`); ``runge-kutta``: Runge–Kutta steps throughout.
    """

    rtol: float = 1e-6
    atol: float = 1e-8
    atol_velocity: float = 1e-7
    output_dt: float = 0.01
    stop_drift_ratio: float | None = None
    tolerance_scaling: bool = True
    linear_phases: str = "exact"

    def __post_init__(self) -> None:
        entry = schema.checked(schema.SolverEntry, dataclasses.asdict(self), ("solver",))
        for key, value in entry.model_dump().items():
            object.__setattr__(self, key, value)


# --------------------------------------------------------------------------- #
# Model
# --------------------------------------------------------------------------- #


@dataclass(frozen=True, eq=False)
class Model:
    """Buildings with contact points, links, a ground motion and solver settings: the one description.

    Attributes
    ----------
    name : str
    buildings : tuple of Building
        Left to right (planar); in the file's order (in plan).
    gaps : tuple of GapElement
        One per contact point, in ``contacts`` order (a planar contact: one per joined floor pair;
        in plan: the points of each face, face after face).
    links : tuple of Link
        One per linked floor pair, in ``links`` order (default: none).
    ground_motion : GroundMotionSpec
    solver : SolverSettings
    source : str
        The YAML text this model was loaded from, as the user wrote it; a
        model derived with ``with_xi`` / ``with_ground_motion`` /
        ``with_solver`` keeps it.  :meth:`to_document` gives the YAML of the
        model as it actually is (derived changes included), which rebuilds it
        exactly with :func:`model_from_text`.
    path : str or None
        The model file as given by the user.
    building_ground_motions : tuple of GroundMotionSpec
        One record per building (``buildings[i].ground_motion`` in the YAML),
        left to right; empty when one model-level ``ground_motion`` (possibly
        with ``wave_passage``) moves every building.  With per-building
        records ``ground_motion`` is the first building's, for display only.
    faces : tuple of ContactFace
        The contact faces between floors in plan (their points are ``gaps``); empty for floors
        of one degree of freedom.
    """

    name: str
    buildings: tuple[Building, ...]
    gaps: tuple[GapElement, ...]
    ground_motion: GroundMotionSpec
    solver: SolverSettings
    source: str
    path: str | None = None
    building_ground_motions: tuple = ()
    links: tuple[Link, ...] = ()
    faces: tuple[ContactFace, ...] = ()

    def __post_init__(self) -> None:
        for key in ("buildings", "gaps", "links", "faces"):
            object.__setattr__(self, key, tuple(getattr(self, key)))
        if self.in_plan:
            from pounding.model import plan_schema   # plan models only (~50 ms of pydantic classes)

            schema.checked(plan_schema.PlanModelEntry, self.plain_document())
            return
        last = len(self.buildings) - 1
        for gap in self.gaps + self.links:
            if gap.left == WALL and gap.right == 0 or gap.right == WALL and gap.left == last:
                continue
            if not (0 <= gap.left < len(self.buildings) - 1 and gap.right == gap.left + 1):
                raise ModelError(f"gap element joins buildings {gap.left} and {gap.right}, which are not "
                                 "adjacent in the row")
        schema.checked(schema.ModelEntry, self.plain_document())

    # ----------------------------------------------------------- kind of floors, degrees of freedom
    @property
    def in_plan(self) -> bool:
        """True if the buildings' floors are rigid diaphragms in plan (u_x, u_y, θ each)."""
        return any(b.in_plan for b in self.buildings)

    @cached_property
    def dof_offsets(self) -> tuple[int, ...]:
        """Index of each building's first degree of freedom in the model's vector (worked out once per model:
        assembling and labelling a run read it ~20 times)."""
        offsets, total = [], 0
        for b in self.buildings:
            offsets.append(total)
            total += b.n_model_dof
        return tuple(offsets)

    @property
    def n_dof(self) -> int:
        """Degrees of freedom of the model (a founded building's base mat's included)."""
        return sum(b.n_model_dof for b in self.buildings)

    def floor_slice(self, building: int, level: int) -> slice:
        """The degrees of freedom of floor *level* (1-based) of *building* in the model's vector."""
        per = self.buildings[building].dofs_per_floor
        start = self.dof_offsets[building] + per * (level - 1)
        return slice(start, start + per)

    def scatter(self, face: ContactFace, rows: np.ndarray) -> np.ndarray:
        """(N,) model-wide weights from a face's (2, 3) rows (first side's floor, second's)."""
        w = np.zeros(self.n_dof)
        w[self.floor_slice(face.first, face.level_first)] += rows[0]
        if face.second != WALL:
            w[self.floor_slice(face.second, face.level_second)] += rows[1]
        return w

    def penetration_vectors(self) -> list[tuple[ContactFace, outline.ContactPoint, np.ndarray]]:
        """Every contact point of a face in plan with its model-wide penetration weights: ``δ = w · q − gap``."""
        return [(f, p, self.scatter(f, p.weights)) for f in self.faces for p in f.points]

    @property
    def warnings(self) -> tuple[str, ...]:
        """The buildings' warnings (Rayleigh targets at coincident modes)."""
        return tuple(w for b in self.buildings for w in b.warnings)

    # ----------------------------------------------------------- display
    def overview(self) -> list[tuple[str, str]]:
        """The model in a few labelled lines: the model and its record, each building, the contacts, the links.

        The text of ``repr(model)`` and the rows of its notebook table (``_repr_html_``).
        """
        names = [b.name for b in self.buildings]
        if self.has_building_records:
            record = "a record per building: " + ", ".join(f"{n} {g.record} {g.describe_scale()}"
                                                          for n, g in zip(names, self.building_ground_motions))
        else:
            record = f"record {self.ground_motion.record} {self.ground_motion.describe_scale()}" + \
                (", wave passage" if self.ground_motion.wave_passage is not None else "")
        rows = [("model", f"'{self.name}': {len(self.buildings)} building{'s' if len(self.buildings) != 1 else ''}, "
                          f"{len(self.gaps)} contact{'s' if len(self.gaps) != 1 else ''}"
                          + (f", {len(self.links)} link{'s' if len(self.links) != 1 else ''}" if self.links else "")
                          + f"; {record}")]
        rows += [("building", b.describe()) for b in self.buildings]
        groups: dict[tuple[str, float], list[str]] = {}
        for g in self.gaps:   # contacts of one law and gap on one line
            law = g.law.name + (f"/{g.law.xi}" if getattr(g.law, "xi", None) else "")
            groups.setdefault((law, float(g.gap)), []).append(g.label(names))
        for (law, gap), labels in groups.items():
            shown = ", ".join(labels) if len(labels) <= 3 else f"{labels[0]} ... {labels[-1]} ({len(labels)})"
            rows.append(("contacts", f"{shown}: {law}, " + ("held open" if gap >= OPEN_GAP else f"gap {1000 * gap:.4g} mm")))
        for link in self.links:
            rows.append(("link", f"{names[link.left]}:{link.level_left}-{names[link.right]}:{link.level_right}: "
                                 f"{link.law.describe()}"))
        return rows

    def __repr__(self) -> str:
        rows = self.overview()
        return "\n".join([f"<Model {rows[0][1]}"] + [f"  {value}" if key == "building" else f"  {key}: {value}"
                                                      for key, value in rows[1:]]) + ">"

    def _repr_html_(self) -> str:
        """The overview as an HTML table, for notebooks."""
        from html import escape

        body = "".join(f"<tr><th style='text-align:left'>{escape(key)}</th><td style='text-align:left'>"
                       f"{escape(value)}</td></tr>" for key, value in self.overview())
        return f"<table><caption style='text-align:left'>pounding.Model</caption>{body}</table>"

    # ----------------------------------------------------------- helpers
    @property
    def periods(self) -> dict[str, np.ndarray]:
        """Building name → (n,) natural periods, s."""
        return {b.name: b.periods for b in self.buildings}

    @property
    def n_floors_total(self) -> int:
        """Floors of all buildings together."""
        return sum(b.n_floors for b in self.buildings)

    def building_index(self, building: int | str) -> int:
        """Index of a building given by index or name (ModelError with a suggestion)."""
        names = [b.name for b in self.buildings]
        if isinstance(building, str):
            if building not in names:
                raise ModelError(f"unknown building '{building}'{did_you_mean(building, names)}; "
                                 f"buildings are: {', '.join(names)}")
            return names.index(building)
        index = int(building)
        if not 0 <= index < len(names):
            raise ModelError(f"building index {index} is out of range (the model has {len(names)} buildings)")
        return index

    @property
    def has_building_records(self) -> bool:
        """True if every building has its own ``ground_motion`` (rather than one for the model)."""
        return bool(self.building_ground_motions)

    @property
    def is_multi_support(self) -> bool:
        """True if the buildings may see different ground motions (own records or a wave-passage lag)."""
        return self.has_building_records or self.ground_motion.wave_passage is not None

    def ground_motion_of(self, building: int | str) -> GroundMotionSpec:
        """The ground-motion section that moves *building* (its own, or the model's)."""
        index = self.building_index(building)
        return self.building_ground_motions[index] if self.building_ground_motions else self.ground_motion

    def refuse_building_records(self, what: str) -> None:
        """Raise a one-line ModelError if the model has per-building records: *what* needs one record."""
        if self.has_building_records:
            where = f"{self.path}: " if self.path else ""
            raise ModelError(f"{where}{what} needs one model-level ground_motion, but model '{self.name}' gives "
                             "each building its own record (buildings[i].ground_motion); edit the records in "
                             "the model file instead")

    def floor_offset(self, b: int | str) -> int:
        """Index of building *b*'s floor 1 in the concatenated floor vector (left to right)."""
        index = self.building_index(b)
        return sum(x.n_floors for x in self.buildings[:index])

    # ----------------------------------------------------------- derived models
    def _derived(self, **changes: Any) -> Model:
        return dataclasses.replace(self, **changes)

    def with_xi(self, name: str) -> Model:
        """The same model with every hertz-damp gap using xi formula *name*.

        Raises
        ------
        ModelError
            Unknown formula (with a suggestion), or no hertz-damp contact in the model.
        """
        try:
            key = xi_formulas.get(name).key
        except PoundingError as exc:
            raise ModelError(str(exc)) from None
        if not any(isinstance(g.law, HertzDamp) for g in self.gaps):
            raise ModelError(f"model '{self.name}' has no hertz-damp contacts; the xi formula applies only to "
                             "law hertz-damp")
        laws: dict[int, ContactLaw] = {}

        def renamed(law: ContactLaw) -> ContactLaw:
            if not isinstance(law, HertzDamp):
                return law
            if id(law) not in laws:
                laws[id(law)] = type(law)(**{**law.model_dump(), "xi": key})
            return laws[id(law)]

        return self._with_contacts(law=renamed)

    def with_laws(self, change: Any) -> Model:
        """The same model with every contact's law replaced by ``change(law)`` (points of a face follow it)."""
        return self._with_contacts(law=change)

    def _with_contacts(self, *, law: Any = None, gap: float | None = None) -> Model:
        """The same model with every contact's law changed by *law* (a function) and/or its gap set to *gap* (m).

        In plan the faces change and their points (the gap elements) follow them.
        """
        def changed(item: Any) -> dict[str, Any]:
            return {} if law is None else {"law": law(item.law)}

        if not self.faces:
            return self._derived(gaps=tuple(dataclasses.replace(g, **changed(g), **({} if gap is None else {"gap": gap}))
                                            for g in self.gaps))
        faces = tuple(dataclasses.replace(f, **changed(f), **({} if gap is None else
                                                              {"face": dataclasses.replace(f.face, gap=gap)}))
                      for f in self.faces)
        return self._derived(faces=faces, gaps=face_elements(faces))

    def with_contacts_open(self) -> Model:
        """The same model with every contact held open (gap :data:`OPEN_GAP`): the run without pounding.

        Labels, laws and everything else are kept, so the results line up with the model's own run.

        Raises
        ------
        ModelError
            The model has no contacts (holding them open would change nothing).
        """
        if not self.gaps:
            where = f"{self.path}: " if self.path else ""
            raise ModelError(f"{where}model '{self.name}' has no contacts; there is no pounding to leave out")
        return self._with_contacts(gap=OPEN_GAP)

    @property
    def contacts_held_open(self) -> bool:
        """True if the model has contacts and every one is held open (gap >= :data:`OPEN_GAP`)."""
        return bool(self.gaps) and all(g.gap >= OPEN_GAP for g in self.gaps)

    def with_ground_motion(self, **changes: Any) -> Model:
        """The same model with ground-motion fields changed (record, scale, duration, dt, units, base_dir).

        With a record per building only ``duration`` may change (it applies to all).

        Raises
        ------
        ModelError
            The model gives each building its own record (one line).
        """
        _check_keys("ground_motion", changes, GroundMotionSpec)
        if isinstance(changes.get("scale"), Mapping):
            # A target given as a mapping ({"pga": "0.4g"}) becomes the Scaling a model file's would.
            from pounding.records.processing import SpecProblem, parse_scale

            try:
                changes["scale"] = parse_scale(changes["scale"], [b.name for b in self.buildings])
            except SpecProblem as failed:
                raise ModelError(failed.message("ground_motion.scale", None)) from None
        if self.has_building_records and set(changes) == {"duration"}:
            # The simulated time applies to every building's record alike.
            own = tuple(dataclasses.replace(g, **changes) for g in self.building_ground_motions)
            return self._derived(building_ground_motions=own, ground_motion=own[0])
        self.refuse_building_records("changing the ground motion (record or scale)")
        return self._derived(ground_motion=dataclasses.replace(self.ground_motion, **changes))

    def collapse_drift_ratios(self) -> tuple[float | None, ...]:
        """Each building's collapse drift ratio, left to right: its own ``collapse: {drift_ratio}``, else
        ``solver.stop_drift_ratio``; None: no drift limit (an IMK storey at zero strength, or a storey
        losing its resistance to P-Delta, still ends the run: docs/models.md "Collapse")."""
        return tuple(b.collapse_drift_ratio if b.collapse_drift_ratio is not None else self.solver.stop_drift_ratio
                     for b in self.buildings)

    def with_collapse_drift(self, drift_ratio: float) -> Model:
        """The same model with every building's collapse drift ratio set to *drift_ratio* (what
        ``pounding ida --collapse-drift`` does for its study: it overrides both the buildings' own
        ``collapse`` and ``solver.stop_drift_ratio``)."""
        return self._derived(buildings=tuple(dataclasses.replace(b, collapse_drift_ratio=float(drift_ratio))
                                             for b in self.buildings))

    def with_solver(self, **changes: Any) -> Model:
        """The same model with solver settings changed (rtol, atol, atol_velocity, output_dt, …)."""
        _check_keys("solver", changes, SolverSettings)
        return self._derived(solver=dataclasses.replace(self.solver, **changes))

    # ----------------------------------------------------------- output
    def summary_lines(self) -> list[str]:
        """Human-readable summary: one line per building, then one per contact entry."""
        lines = []
        for b in self.buildings:
            periods = ", ".join(f"{t:.3f}" for t in b.periods[:3])
            lines.append(f"{b.name}: {b.n_floors} floors, {b.elevation[-1]:g} m, "
                         f"T1..{min(3, b.n_floors)} = {periods} s, {b.damping.describe()}")
            if b.is_inelastic or b.p_delta:
                laws = [p.hysteresis for _, _, p in b.planes()]
                kinds = sorted({law.describe() for law in laws if law is not None})
                yielding = sum(law is not None for law in laws)
                what = "planes" if b.in_plan else "storeys"
                lines.append(f"  {yielding} of {len(laws)} {what} yield: {'; '.join(kinds) or 'none'}"
                             + ("; P-Delta on" if b.p_delta else ""))
        for contact in sorted({g.contact for g in self.gaps}):
            gaps = [g for g in self.gaps if g.contact == contact]
            pairs = ", ".join(f"{schema.side_text(self.buildings, g.left, g.level_left, g.at_left)}-"
                              f"{schema.side_text(self.buildings, g.right, g.level_right, g.at_right)}" for g in gaps)
            lines.append(f"contact {contact}: {pairs}; gap {gaps[0].gap:g} m, {gaps[0].law.describe()}")
        for index in sorted({link.entry for link in self.links}):
            mine = [link for link in self.links if link.entry == index]
            left, right = self.buildings[mine[0].left].name, self.buildings[mine[0].right].name
            pairs = ", ".join(f"{left}{k.level_left}-{right}{k.level_right}" for k in mine)
            lines.append(f"link {index}: {pairs}; {mine[0].law.describe()}")

        def describe(gm: GroundMotionSpec) -> str:
            return (f"{gm.record} {gm.describe_scale()}"
                    + (f", processing {gm.processing.to_document()}" if gm.processing is not None else "")
                    + (f", first {gm.duration:g} s" if gm.duration is not None else ""))

        if self.building_ground_motions:
            for b, gm in zip(self.buildings, self.building_ground_motions):
                lines.append(f"ground motion under {b.name}: {describe(gm)}")
            return lines
        gm = self.ground_motion
        lines.append(f"ground motion: {describe(gm)}")
        if gm.wave_passage is not None:
            lags = ", ".join(f"{b.name} {gm.lag(b.name):.3g} s" for b in self.buildings)
            lines.append(f"wave passage at {gm.wave_passage.apparent_velocity:g} m/s: lags {lags}")
        return lines

    def to_document(self) -> str:
        """YAML text of the effective model, for archives (same as :meth:`to_yaml`).

        Always regenerated from the objects, so it rebuilds this exact model
        with :func:`model_from_text` even if ``source`` was set by hand.
        """
        return self.to_yaml()

    def plain_document(self) -> dict[str, Any]:
        """The model as plain data (what :meth:`to_yaml` writes): storeys one by one, explicit level pairs."""
        contacts = _face_documents(self) if self.faces else []
        for contact in sorted({g.contact for g in self.gaps}) if not self.faces else ():
            gaps = [g for g in self.gaps if g.contact == contact]
            first = gaps[0]
            names = [b.name for b in self.buildings]
            between = [schema.WALL_NAME if b == WALL else names[b] for b in (first.left, first.right)]
            if first.left == WALL:
                levels: list = [g.level_document("right") for g in gaps]
            elif first.right == WALL:
                levels = [g.level_document("left") for g in gaps]
            else:
                levels = [[g.level_document("left"), g.level_document("right")] for g in gaps]
            entry: dict[str, Any] = {"between": between, "levels": levels, "gap": float(first.gap)}
            entry.update(first.law.model_dump(mode="json"))
            contacts.append(entry)
        links = []
        for index in sorted({link.entry for link in self.links}):
            mine = [link for link in self.links if link.entry == index]
            first = mine[0]
            entry = {"between": [self.buildings[first.left].name, self.buildings[first.right].name],
                     "levels": [[link.level_left, link.level_right] for link in mine]}
            entry.update(first.law.model_dump(mode="json"))
            links.append(entry)
        buildings = [_plan_building_document(b) if b.in_plan else _building_document(b) for b in self.buildings]
        document: dict[str, Any] = {"name": self.name, "buildings": buildings, "contacts": contacts}
        if links:
            document["links"] = links
        if self.building_ground_motions:
            for building, spec in zip(buildings, self.building_ground_motions):
                building["ground_motion"] = spec.to_document()
        else:
            document["ground_motion"] = self.ground_motion.to_document()
        document["solver"] = {k: v for k, v in dataclasses.asdict(self.solver).items() if v is not None}
        return document

    def to_yaml(self) -> str:
        """A YAML document that :func:`model_from_text` turns back into this model.

        Storeys are written out one by one and contact levels as explicit
        pairs; floats are written with ``repr`` so they round-trip exactly.
        Written once per model (a model does not change; every ``with_*`` makes a new one): a run's
        archive holds it (``run_spec``), 2–7 ms of a run of the shipped models.
        """
        return self._yaml_text

    @cached_property
    def _yaml_text(self) -> str:
        """:meth:`to_yaml`'s text, written the first time it is asked for."""
        header = (f"# Model '{self.name}' regenerated by pounding"
                  + (f" from {self.path}" if self.path else "") + " (comments are not kept).\n")
        return header + dump_document(self.plain_document())


def face_elements(faces: tuple[ContactFace, ...]) -> tuple[GapElement, ...]:
    """The gap elements of *faces*: each face's points in order, face after face."""
    return tuple(g for index, face in enumerate(faces) for g in face.point_elements(index))


def _building_extras(b: Building, document: dict[str, Any]) -> dict[str, Any]:
    """*document* with the building's optional keys (``p_delta``, ``design``, ``collapse``) added."""
    if b.p_delta:
        document["p_delta"] = True
    if b.design is not None:
        document["design"] = schema.design_document(b.design)
    if b.collapse_drift_ratio is not None:
        document["collapse"] = {"drift_ratio": b.collapse_drift_ratio}
    if b.foundation is not None:
        document["foundation"] = b.foundation.to_document()
    return document


def _building_document(b: Building) -> dict[str, Any]:
    storeys = [schema.storey_document(m, k, h, law)
               for m, k, h, law in zip(b.mass, b.stiffness, b.height, b.hysteresis)]
    return _building_extras(b, {"name": b.name, "storeys": storeys, "damping": b.damping.to_document()})


def _plane_document(plane: floors.Plane) -> dict[str, Any]:
    out = {"direction": plane.direction, "at": float(plane.at), "stiffness": float(plane.stiffness)}
    if plane.hysteresis is not None:
        out["hysteresis"] = plane.hysteresis.model_dump(mode="json", exclude_none=True)
    return out


def _plan_building_document(b: Building) -> dict[str, Any]:
    (x0, y0), (x1, y1) = b.outline
    storeys = [{"mass": float(s.mass), "height": float(s.height), "centre_of_mass": [float(v) for v in s.centre],
                "radius_of_gyration": float(s.radius_of_gyration),
                "planes": [_plane_document(p) for p in s.planes]} for s in b.storeys]
    return _building_extras(b, {"name": b.name, "plan": {"outline": [[x0, y0], [x1, y1]]}, "storeys": storeys,
                                "damping": b.damping.to_document()})


def _face_documents(model: Model) -> list[dict[str, Any]]:
    """The contacts of a model in plan as plain data: one entry per YAML entry, its faces as level pairs."""
    names = [b.name for b in model.buildings]
    entries = []
    for contact in sorted({f.contact for f in model.faces}):
        faces = [f for f in model.faces if f.contact == contact]
        first = faces[0]
        wall = first.second == WALL
        def side(level: int, at: float | None) -> Any:
            return int(level) if at is None else {"storey": int(level), "at": float(at)}

        entry: dict[str, Any] = {"between": [names[first.first], schema.WALL_NAME if wall else names[first.second]],
                                 "levels": [side(f.level_first, f.at_first) for f in faces] if wall else
                                 [[side(f.level_first, f.at_first), side(f.level_second, f.at_second)]
                                  for f in faces]}
        if wall:
            entry["face"] = outline.wall_side(first.face)
        if wall or first.gap >= OPEN_GAP:
            entry["gap"] = float(first.gap)
        if first.friction is not None:
            entry["friction"] = float(first.friction)
        entry.update(first.law.model_dump(mode="json"))
        entries.append(entry)
    return entries


def _check_keys(section: str, changes: dict[str, Any], cls: type) -> None:
    allowed = [f.name for f in dataclasses.fields(cls)]
    for key in changes:
        if key not in allowed:
            raise ModelError(f"{section}: unknown setting '{key}'{did_you_mean(key, allowed)}; "
                             f"allowed: {', '.join(allowed)}")


# --------------------------------------------------------------------------- #
# Loading
# --------------------------------------------------------------------------- #


def _build(entry: schema.ModelEntry, *, name: str, text: str, path: str | None, base_dir: str | None) -> Model:
    """The domain objects of a validated model (no second check)."""
    buildings = tuple(_trusted_building(b, planar_storeys(*(b.column(key) for key in ("mass", "stiffness", "height",
                                                                                      "hysteresis"))))
                      for b in entry.buildings)
    gaps = tuple(GapElement(index, c.sides[0], c.sides[1], a, r, c.gap, c.parameters, at_a, at_r)
                 for index, c in enumerate(entry.contacts) for (a, r), (at_a, at_r) in zip(c.pairs, c.points))
    links = tuple(Link(index, e.sides[0], e.sides[1], a, r, e.parameters)
                  for index, e in enumerate(entry.links) for a, r in e.pairs)

    def spec(gm: schema.GroundMotionEntry) -> GroundMotionSpec:
        return _trusted(GroundMotionSpec, record=gm.record, scale=gm.scale, duration=gm.duration, dt=gm.dt,
                        units=gm.units, base_dir=base_dir, processing=gm.processing, wave_passage=gm.wave_passage)

    own = tuple(spec(b.ground_motion) for b in entry.buildings) if entry.ground_motion is None else ()
    ground_motion = own[0] if own else spec(entry.ground_motion)
    solver = _trusted(SolverSettings, **entry.solver.model_dump())
    return _trusted(Model, name=entry.name or name, buildings=buildings, gaps=gaps,
                    ground_motion=ground_motion, solver=solver, source=text, path=path,
                    building_ground_motions=own, links=links, faces=())


def _trusted_building(entry: Any, storeys: tuple[floors.Storey, ...], outline: Any = None) -> Building:
    """The :class:`Building` of a validated building entry (planar or in plan) with its *storeys*."""
    d = entry.damping
    damping = (_trusted(Damping, kind="modal", ratio=None, modes=None, modal_ratios=tuple(d.modal))
               if isinstance(d, schema.ModalEntry) else
               _trusted(Damping, kind="rayleigh", ratio=d.ratio, modes=tuple(d.modes), modal_ratios=None))
    building = _trusted(Building, name=entry.name, storeys=storeys, damping=damping, p_delta=entry.p_delta,
                        design=getattr(entry, "design", None),
                        collapse_drift_ratio=None if entry.collapse is None else entry.collapse.drift_ratio,
                        outline=outline)
    found = getattr(entry, "foundation", None)
    return building if found is None else dataclasses.replace(building, foundation=_foundation(found, building))


def _foundation(entry: Any, building: Building) -> Foundation:
    """The :class:`Foundation` of a validated ``foundation`` entry under the fixed-base *building*: its springs
    as given, or from the soil and the footing at the building's flexible-base frequency."""
    if entry.soil is None:
        return Foundation(float(entry.mass), float(entry.rotary_inertia), float(entry.sway.stiffness),
                          float(entry.sway.damping), float(entry.rocking.stiffness), float(entry.rocking.damping))
    soil = Soil(entry.soil.shear_wave_velocity, entry.soil.poisson, entry.soil.density)
    footing = Footing(entry.footing.length, entry.footing.width, entry.footing.embedment)
    omega, phi = building.modes
    return on_soil(entry.mass, entry.rotary_inertia, soil, footing, building.dof_mass, phi[:, 0], building.elevation,
                   float(omega[0]))


def _build_plan(entry: Any, *, name: str, text: str, path: str | None, base_dir: str | None) -> Model:
    """The domain objects of a validated plan model (:class:`pounding.model.plan_schema.PlanModelEntry`)."""
    buildings = tuple(_trusted_building(b, tuple(b.plan_storeys()), b.plan.outline) for b in entry.buildings)
    faces = []
    for index, c in enumerate(entry.contacts):
        first, second = c.sides
        for (level_first, level_second), (at_first, at_second) in zip(c.pairs, c.points):
            centre_first = buildings[first].centres[level_first - 1]
            centre_second = None if second == WALL else buildings[second].centres[level_second - 1]
            points = outline.face_points(c.plan_face, centre_first, centre_second)
            faces.append(ContactFace(index, first, second, level_first, level_second, c.plan_face, points,
                                     c.parameters, c.friction, at_first, at_second))
    links = tuple(_plan_link(index, e, pair) for index, e in enumerate(entry.links) for pair in e.pairs)
    own = tuple(_pair_spec(b.ground_motion, base_dir) for b in entry.buildings) if entry.ground_motion is None else ()
    ground_motion = own[0] if own else _pair_spec(entry.ground_motion, base_dir)
    solver = _trusted(SolverSettings, **entry.solver.model_dump())
    return _trusted(Model, name=entry.name or name, buildings=buildings, gaps=face_elements(tuple(faces)),
                    ground_motion=ground_motion, solver=solver, source=text, path=path,
                    building_ground_motions=own, links=links, faces=tuple(faces))


def _pair_spec(gm: Any, base_dir: str | None) -> GroundMotionSpec:
    """The :class:`GroundMotionSpec` of a validated two-component ground-motion entry."""
    x, y = ((None if c is None else Component(c.record, float(c.scale))) for c in (gm.x, gm.y))
    return _trusted(GroundMotionSpec, record=gm.record, scale=gm.scale, duration=gm.duration, dt=gm.dt,
                    units=gm.units, base_dir=base_dir, processing=gm.processing, wave_passage=gm.wave_passage,
                    angle=float(gm.angle), x=x, y=y)


def _plan_link(index: int, entry: Any, pair: tuple[int, int]) -> Link:
    """The link of a plan entry's level pair: at the middle of the facing edges' overlap, along the normal."""
    face = entry.plan_face
    first, second = entry.sides
    middle = 0.5 * (face.span[0] + face.span[1])
    point = (face.face_low, middle) if face.normal == "x" else (middle, face.face_low)
    (low, level_low), (high, level_high) = ((first, pair[0]), (second, pair[1])) if face.first_low else \
        ((second, pair[1]), (first, pair[0]))
    return Link(index, low, high, level_low, level_high, entry.parameters, face.normal, (float(point[0]),
                                                                                          float(point[1])))


def model_from_text(text: str, *, name: str = "model", path: str | None = None,
                    base_dir: str | None = None) -> Model:
    """Build a model from YAML text (e.g. the ``source`` stored in a results archive).

    Parameters
    ----------
    text : str
        The YAML document.
    name : str
        Model name if the document has no ``name`` key.
    path : str, optional
        File name for messages and ``Model.path``; messages use ``<name>`` without it.
    base_dir : str, optional
        Directory against which a relative record path is resolved.

    Raises
    ------
    ModelError
        ``<path>:<line>: <location> <problem>``.
    """
    label = path if path is not None else f"<{name}>"
    doc = parse_document(text, label)
    if is_plan_document(doc.data):
        from pounding.model import plan_schema  # loaded for plan models only (~50 ms of pydantic classes)

        return _build_plan(plan_schema.validate_plan(doc, base_dir), name=name, text=text, path=path,
                           base_dir=base_dir)
    entry = schema.validate(schema.ModelEntry, doc.data, doc, context={"base_dir": base_dir})
    return _build(entry, name=name, text=text, path=path, base_dir=base_dir)


def model_from_data(data: dict[str, Any], *, name: str = "model", source: str = "",
                    base_dir: str | None = None) -> Model:
    """Build a model from plain data (a parsed model document), validated by the same schema.

    Used by sweeps, which change a validated document and validate it again
    without writing and reading YAML text.

    Raises
    ------
    ModelError
        ``<location> <problem>`` (no file, no line).
    """
    if is_plan_document(data):
        from pounding.model import plan_schema

        return _build_plan(schema.checked(plan_schema.PlanModelEntry, data), name=name, text=source, path=None,
                           base_dir=base_dir)
    entry = schema.checked(schema.ModelEntry, data)
    return _build(entry, name=name, text=source, path=None, base_dir=base_dir)


def read_yaml_text(path: str | os.PathLike, *, kind: str) -> str:
    """Read a YAML file (a *kind* file: model, sweep) as UTF-8 text.

    Raises
    ------
    ModelError
        One line naming the file: not found (with a similar file suggested),
        a directory, not UTF-8, or unreadable.
    """
    label = os.fspath(path)
    file = Path(label)
    try:
        return file.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ModelError(f"file not found{_similar_file(file)}", file=label) from None
    except IsADirectoryError:
        raise ModelError(f"is a directory, not a {kind} file", file=label) from None
    except UnicodeDecodeError as exc:
        raise ModelError(f"is not UTF-8 text (byte {exc.start})", file=label) from None
    except OSError as exc:
        raise ModelError(f"cannot read the file: {exc.strerror}", file=label) from None


def load_model(path: str | os.PathLike) -> Model:
    """Read and validate a model file.

    The model name defaults to the file stem; relative record paths are
    resolved against the file's directory.

    Raises
    ------
    ModelError
        Unreadable file, or any problem in it, as one line
        ``<path as given>:<line>: <location> <problem>``.
    """
    label = os.fspath(path)
    file = Path(label)
    text = read_yaml_text(label, kind="model")
    return model_from_text(text, name=file.stem, path=label,
                           base_dir=os.path.dirname(os.path.abspath(label)))


def _similar_file(file: Path) -> str:
    """`` (did you mean 'models/pair.yaml'?)`` for a near-miss in the same directory."""
    parent = file.parent
    try:
        names = [n for n in os.listdir(parent) if n.endswith((".yaml", ".yml"))]
    except OSError:
        return ""
    candidates = [str(parent / n) if str(parent) != "." or str(file).startswith(".") else n for n in names]
    return did_you_mean(str(file), candidates)


def is_plan_file(path: str | os.PathLike) -> bool:
    """True if the model file at *path* is a plan model (a building with ``plan:``); parse errors raise one line.

    Here rather than in :mod:`pounding.model.plan_model` so that asking costs a planar run no plan module."""
    label = os.fspath(path)
    return is_plan_document(parse_document(read_yaml_text(label, kind="model"), label).data)
