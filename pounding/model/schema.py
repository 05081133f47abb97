"""Schema of the building-model YAML: raw text → validated plain data.

This module reads the YAML text, checks every key and value, and turns each
problem into one :class:`~pounding.errors.ModelError` line of the form::

    models/pair.yaml:14: buildings[1].storeys[3].mass must be > 0 (got -2.5e5)

i.e. ``<file as given>:<line>: <location> <what is wrong>``.  Locations are
written like Python subscripts with **0-based** list indices
(``buildings[1]`` is the second building); floor and mode numbers *inside*
messages are 1-based, as in the YAML.  The ``got`` value is the scalar exactly
as written in the file (``-2.5e5``, not ``-250000.0``).

How it works
------------
1. :func:`parse_document` composes the text with PyYAML's *safe* composer
   (``yaml.SafeLoader``; nothing but plain data can be constructed), builds
   the Python data itself — rejecting duplicate keys — and keeps a map from
   every location to its YAML node, hence to its line and original text.
2. Small pydantic models (``extra="forbid"``) check each mapping; their first
   error (in document order) is translated by :meth:`Document.from_pydantic`.
   Contact-law parameters are checked by the law classes of
   :mod:`pounding.contact` themselves and translated the same way.
3. Cross-field rules (adjacency, floor numbers, modes that exist, elevation
   matching) are checked by hand in :func:`parse`.

The result, :class:`ParsedModel`, holds plain Python values only; the
mechanics (matrices, modes) live in :mod:`pounding.model`.

YAML 1.1 quirk: PyYAML reads ``2.5e5`` (no dot) as a *string*.  Number fields
accept such numeric strings and convert them.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import PurePath
from typing import Annotated, Any, Callable, ClassVar

import numpy as np
import yaml
from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, ValidationError
from pydantic_core import PydanticCustomError

from pounding.contact.laws import LAWS, ContactLaw
from pounding.errors import ModelError, did_you_mean

__all__ = [
    "Document",
    "ParsedModel",
    "ParsedBuilding",
    "ParsedContact",
    "parse",
    "parse_document",
    "format_location",
    "match_levels",
    "normalise_units",
    "is_catalogue_reference",
    "UNITS",
    "DEFAULT_TOLERANCE",
    "MIN_RTOL",
]

Location = tuple[str | int, ...]

#: Default elevation tolerance of ``levels: matching`` (m).
DEFAULT_TOLERANCE = 0.01
#: Smallest accepted solver ``rtol``; tighter is below double-precision round-off.
MIN_RTOL = 1e-12
#: Accepted ``ground_motion.units`` spellings (lower case) → normalised name.
UNITS = {"g": "g", "m/s2": "m/s2", "m/s^2": "m/s2", "cm/s2": "cm/s2", "cm/s^2": "cm/s2", "gal": "cm/s2"}

_NUMBER_TEXT = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
_CATALOGUE_REFERENCE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]+:[^/\\]")
_MERGE_TAG = "tag:yaml.org,2002:merge"


# --------------------------------------------------------------------------- #
# Small pure helpers
# --------------------------------------------------------------------------- #


def format_location(loc: Location) -> str:
    """``('buildings', 1, 'storeys', 3, 'mass')`` → ``'buildings[1].storeys[3].mass'``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def is_catalogue_reference(record: str) -> bool:
    """True for a catalogue reference such as ``fema-p695:farfield/1a``.

    A reference is ``<catalogue>:<record>`` with a catalogue name of two or more
    characters (so a Windows drive letter ``C:\\...`` is a path, not a reference).
    """
    return bool(_CATALOGUE_REFERENCE.match(record))


def normalise_units(units: str) -> str | None:
    """Normalised units name (``g``, ``m/s2``, ``cm/s2``) or None if unknown."""
    return UNITS.get(units.strip().lower()) if isinstance(units, str) else None


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


def _plural(count: int, word: str) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {word}s"


# --------------------------------------------------------------------------- #
# Value checks shared by the pydantic types and the hand-written rules
# --------------------------------------------------------------------------- #


class _Problem(Exception):
    """A value failed a check; ``predicate`` reads "must be ..."."""

    def __init__(self, predicate: str, hint: str = ""):
        super().__init__(predicate)
        self.predicate = predicate
        self.hint = hint


def as_number(value: Any) -> float:
    """A finite float from an int, float or numeric string (``'2.5e5'``).

    Raises
    ------
    _Problem
        For booleans, non-numeric text, empty values and non-finite numbers.
    """
    if isinstance(value, bool) or value is None:
        raise _Problem("must be a number")
    if isinstance(value, str):
        text = value.strip()
        if not _NUMBER_TEXT.match(text):
            raise _Problem("must be a number")
        value = float(text)
    if not isinstance(value, (int, float)):
        raise _Problem("must be a number")
    number = float(value)
    if not math.isfinite(number):
        raise _Problem("must be a finite number")
    return number


def as_positive_integer(value: Any) -> int:
    """A positive int; floats such as ``2.0`` are refused (say what you mean)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise _Problem("must be a positive integer")
    return int(value)


def as_name(value: Any) -> str:
    """A building name: non-empty text (an integer is taken as its digits)."""
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise _Problem("must be text")
    text = str(value).strip()
    if not text:
        raise _Problem("must be a non-empty name")
    return text


def _pydantic(check: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """Wrap a check so that its :class:`_Problem` becomes a pydantic error."""

    def run(value: Any) -> Any:
        try:
            return check(value)
        except _Problem as problem:
            raise PydanticCustomError("pounding", problem.predicate, {"hint": problem.hint}) from None

    return run


def _bound(test: Callable[[float], bool], predicate: str) -> Callable[[float], float]:
    def check(value: float) -> float:
        if not test(value):
            raise _Problem(predicate)
        return value

    return check


def _optional(check: Callable[[Any], Any]) -> Callable[[Any], Any]:
    return lambda value: None if value is None else check(value)


def _units(value: Any) -> str:
    name = normalise_units(value) if isinstance(value, str) else None
    if name is None:
        hint = did_you_mean(str(value).strip().lower(), list(UNITS)).strip() if isinstance(value, str) else ""
        raise _Problem("must be one of g, m/s2, cm/s2, gal", hint)
    return name


def _modes(value: Any) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2:
        raise _Problem("must be two mode numbers, e.g. [1, 2]")
    return value  # items are checked by the item type


def _record(value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        raise _Problem("must be a record reference (e.g. fema-p695:farfield/1a) or a file path")
    return value.strip()


PositiveNumber = Annotated[float, BeforeValidator(_pydantic(as_number)),
                           AfterValidator(_pydantic(_bound(lambda v: v > 0, "must be > 0")))]
NonNegativeNumber = Annotated[float, BeforeValidator(_pydantic(as_number)),
                              AfterValidator(_pydantic(_bound(lambda v: v >= 0, "must be >= 0")))]
OptionalPositiveNumber = Annotated[
    float | None, BeforeValidator(_pydantic(_optional(as_number))),
    AfterValidator(_pydantic(_optional(_bound(lambda v: v > 0, "must be > 0"))))]
DampingRatio = Annotated[float, BeforeValidator(_pydantic(as_number)),
                         AfterValidator(_pydantic(_bound(lambda v: 0 <= v < 1, "must be in [0, 1)")))]
PositiveInteger = Annotated[int, BeforeValidator(_pydantic(as_positive_integer))]
Name = Annotated[str, BeforeValidator(_pydantic(as_name))]
Rtol = Annotated[float, BeforeValidator(_pydantic(as_number)),
                 AfterValidator(_pydantic(_bound(lambda v: v >= MIN_RTOL, f"must be >= {MIN_RTOL:g}")))]


# --------------------------------------------------------------------------- #
# Pydantic models, one per YAML mapping
# --------------------------------------------------------------------------- #


class _Schema(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class TopLevel(_Schema):
    """The document: ``name``, ``buildings``, ``contacts``, ``ground_motion``, ``solver``."""

    name: Annotated[str | None, BeforeValidator(_pydantic(_optional(as_name)))] = Field(
        None, description="model name; defaults to the file stem")
    buildings: Any = Field(description="list of buildings, left to right")
    contacts: Any = Field(None, description="list of contact entries")
    ground_motion: Any = Field(description="e.g. {record: fema-p695:farfield/1a}")
    solver: Any = Field(None, description="integration settings")


class BuildingEntry(_Schema):
    """One building: ``name``, ``storeys``, ``damping``."""

    name: Name = Field(description="unique building name")
    storeys: Any = Field(description="a list of {mass, stiffness, height} from the ground up, "
                                     "or {count, mass, stiffness, height}")
    damping: Any = Field(description="e.g. {ratio: 0.05, modes: [1, 2]} or {modal: [0.05, 0.05]}")


class StoreyEntry(_Schema):
    """One storey: the floor mass on top, the storey stiffness and height."""

    mass: PositiveNumber = Field(description="floor mass, kg")
    stiffness: PositiveNumber = Field(description="storey lateral stiffness, N/m")
    height: PositiveNumber = Field(description="storey height, m")


class StoreyShorthand(StoreyEntry):
    """``count`` identical storeys."""

    count: PositiveInteger = Field(description="number of identical storeys")


class RayleighEntry(_Schema):
    """Rayleigh damping with ``ratio`` at two of the building's own modes."""

    ratio: DampingRatio = Field(description="damping ratio at the two modes, e.g. 0.05")
    modes: Annotated[tuple[Annotated[int, BeforeValidator(_pydantic(as_positive_integer))], ...],
                     BeforeValidator(_pydantic(_modes))] = Field(
        (1, 2), description="two different mode numbers, 1-based")


class ModalEntry(_Schema):
    """Per-mode damping ratios."""

    modal: Annotated[list[DampingRatio], Field(min_length=1)] = Field(
        description="damping ratio of modes 1, 2, ...; later modes take the last value")


class ContactGeometry(_Schema):
    """The keys of a contact entry that are not law parameters."""

    model_config = ConfigDict(extra="ignore", frozen=True)
    KEYS: ClassVar[tuple[str, ...]] = ("between", "levels", "gap", "tolerance", "law")

    between: Any = Field(description="two adjacent building names, left first, e.g. [A, B]")
    levels: Any = Field("matching", description="'matching' or [[level_left, level_right], ...]")
    gap: NonNegativeNumber = Field(description="separation at rest, m")
    tolerance: OptionalPositiveNumber = Field(None, description="elevation tolerance of levels: matching, m")
    law: Any = Field(description=f"contact law: {', '.join(LAWS)}")


class GroundMotionEntry(_Schema):
    """``ground_motion``: record reference or file, scale, duration, dt, units."""

    record: Annotated[str, BeforeValidator(_pydantic(_record))] = Field(
        description="e.g. fema-p695:farfield/1a or a file path relative to the YAML file")
    scale: Any = Field(1.0, description="a factor, or {pga: 0.4g}, {sa: 0.8g, period: 1.0 | building A}, "
                                        "{fema-p695: true}")
    processing: Any = Field(None, description="{trim: significant-duration, baseline: true}")
    duration: OptionalPositiveNumber = Field(None, description="truncate the record to this length, s")
    dt: OptionalPositiveNumber = Field(None, description="time step of a one-column text record, s")
    units: Annotated[str | None, BeforeValidator(_pydantic(_optional(_units)))] = Field(
        None, description="g, m/s2 or cm/s2 (gal)")


class SolverEntry(_Schema):
    """``solver``: tolerances and output sampling."""

    rtol: Rtol = 1.0e-6
    atol: PositiveNumber = 1.0e-8
    atol_velocity: PositiveNumber = 1.0e-7
    output_dt: PositiveNumber = 0.01


# --------------------------------------------------------------------------- #
# The composed document: data plus a location → node map
# --------------------------------------------------------------------------- #


class Document:
    """YAML text composed safely, with the node of every location.

    Attributes
    ----------
    text : str
        The YAML source.
    label : str
        The file name used in messages (as given by the user).
    data : Any
        Plain Python data (safe-load semantics, keys as written).
    """

    def __init__(self, text: str, label: str):
        self.text = text
        self.label = label
        self.values: dict[Location, yaml.Node] = {}
        self.keys: dict[Location, yaml.Node] = {}
        self._loader = yaml.SafeLoader(text)
        try:
            root = self._loader.get_single_node()
            self.data = None if root is None else self._convert(root, (), set())
        except yaml.MarkedYAMLError as exc:
            raise self._syntax_error(exc) from None
        except yaml.YAMLError as exc:
            raise ModelError(f"invalid YAML: {exc}", file=label) from None
        finally:
            self._loader.dispose()

    # ----------------------------------------------------------- composing
    def _syntax_error(self, exc: yaml.MarkedYAMLError) -> ModelError:
        mark = exc.problem_mark or exc.context_mark
        message = f"invalid YAML: {exc.problem or exc.context}"
        if exc.problem and exc.context:
            message += f" ({exc.context}"
            if exc.context_mark is not None and exc.context_mark.line != getattr(mark, "line", None):
                message += f" on line {exc.context_mark.line + 1}"
            message += ")"
        if "'\\t'" in message:
            message += "; indent with spaces, not tabs"
        return ModelError(message, file=self.label, line=None if mark is None else mark.line + 1)

    def _convert(self, node: yaml.Node, loc: Location, active: set[int]) -> Any:
        self.values[loc] = node
        if node.tag not in yaml.SafeLoader.yaml_constructors:
            raise self.error(loc, f"unsupported YAML tag '{node.tag}'; model files hold plain data only")
        if isinstance(node, yaml.ScalarNode):
            return self._loader.construct_object(node)
        if id(node) in active:
            raise self.error(loc, "a YAML alias refers to itself (recursive structure)")
        active.add(id(node))
        try:
            if isinstance(node, yaml.SequenceNode):
                return [self._convert(item, loc + (i,), active) for i, item in enumerate(node.value)]
            result = {}
            for key, (key_node, value_node) in self._mapping_pairs(node, loc).items():
                self.keys[loc + (key,)] = key_node
                result[key] = self._convert(value_node, loc + (key,), active)
            return result
        finally:
            active.discard(id(node))

    def _mapping_pairs(self, node: yaml.MappingNode, loc: Location,
                       depth: int = 0) -> dict[str, tuple[yaml.Node, yaml.Node]]:
        """Key text → (key node, value node); explicit keys first, then ``<<`` merges."""
        pairs: dict[str, tuple[yaml.Node, yaml.Node]] = {}
        merges: list[yaml.Node] = []
        for key_node, value_node in node.value:
            if key_node.tag == _MERGE_TAG:
                merges.extend(value_node.value if isinstance(value_node, yaml.SequenceNode) else [value_node])
                continue
            if not isinstance(key_node, yaml.ScalarNode):
                raise ModelError(f"{format_location(loc) or 'top level'}: mapping keys must be plain names",
                                 file=self.label, line=key_node.start_mark.line + 1)
            key = key_node.value
            if key in pairs:
                first = pairs[key][0].start_mark.line + 1
                where = format_location(loc)
                raise ModelError(f"{where + ': ' if where else ''}duplicate key '{key}' (first given on line {first})",
                                 file=self.label, line=key_node.start_mark.line + 1)
            pairs[key] = (key_node, value_node)
        for merged in merges:
            if not isinstance(merged, yaml.MappingNode) or depth > 20:
                raise ModelError(f"{format_location(loc) or 'top level'}: '<<' must merge a mapping",
                                 file=self.label, line=merged.start_mark.line + 1)
            for key, pair in self._mapping_pairs(merged, loc, depth + 1).items():
                pairs.setdefault(key, pair)
        return pairs

    # ----------------------------------------------------------- look-ups
    def node(self, loc: Location) -> yaml.Node | None:
        """The value node at *loc*, or None if the location is absent."""
        return self.values.get(loc)

    def line(self, loc: Location) -> int:
        """1-based line of the value at *loc* (or of its closest present ancestor)."""
        while loc not in self.values and loc:
            loc = loc[:-1]
        node = self.values.get(loc)
        return 1 if node is None else node.start_mark.line + 1

    def key_line(self, loc: Location) -> int:
        """Line of the key that introduces *loc*, else of its value."""
        node = self.keys.get(loc)
        return node.start_mark.line + 1 if node is not None else self.line(loc)

    def got(self, loc: Location) -> str:
        """The value at *loc* as written in the file, for ``(got ...)``."""
        node = self.values.get(loc)
        if node is None:
            return "nothing"
        if isinstance(node, yaml.ScalarNode):
            value = self._loader.construct_object(node) if node.tag != "tag:yaml.org,2002:str" else node.value
            if node.value == "":
                return "nothing"
            if isinstance(value, str) and not _NUMBER_TEXT.match(value.strip()):
                return f"'{node.value}'"
            return node.value
        raw = self.text[node.start_mark.index:node.end_mark.index].strip()
        if raw and "\n" not in raw and len(raw) <= 60:
            return raw
        return "a list" if isinstance(node, yaml.SequenceNode) else "a mapping"

    # ----------------------------------------------------------- errors
    def error(self, loc: Location, text: str, *, line: int | None = None, colon: bool = True) -> ModelError:
        """``<file>:<line>: <loc>: <text>`` (``<loc> <text>`` if not *colon*; no location at top level)."""
        where = format_location(loc)
        message = (f"{where}: {text}" if colon else f"{where} {text}") if where else text
        return ModelError(message, file=self.label, line=self.line(loc) if line is None else line)

    def must(self, loc: Location, predicate: str, hint: str = "", *, line: int | None = None) -> ModelError:
        """``<file>:<line>: <loc> must be ... (got <as written>)[; hint]``."""
        message = f"{format_location(loc)} {predicate} (got {self.got(loc)})"
        if hint:
            message += f" {hint}" if hint.startswith("(") else f"; {hint}"
        return ModelError(message, file=self.label, line=self.line(loc) if line is None else line)

    def from_pydantic(self, exc: ValidationError, cls: type[BaseModel], loc: Location,
                      allowed: list[str] | None = None) -> ModelError:
        """Translate the first error of *exc* (in document order) to one line.

        Parameters
        ----------
        exc : ValidationError
            From ``cls.model_validate(data at loc)``.
        cls : type
            The model class (for field descriptions and bounds).
        loc : tuple
            Location of the validated mapping in the document.
        allowed : list of str, optional
            Keys to suggest for an unknown key (default: the model's fields).
        """
        def rank(error: dict) -> int:
            # an unknown key usually explains a "missing" one (a typo): report it first
            return {"extra_forbidden": 0, "missing": 2}.get(error["type"], 1)

        errors = exc.errors(include_url=False)
        translated = [(rank(e), self._translate(e, cls, loc, allowed)) for e in errors]
        rank_, first = min(translated, key=lambda item: (item[0], item[1].line or 0))
        first.rank = rank_   # lets callers merging several validations keep the same priority
        return first

    def _translate(self, error: dict, cls: type[BaseModel], loc: Location,
                   allowed: list[str] | None) -> ModelError:
        kind = error["type"]
        full = loc + tuple(error["loc"])
        if kind == "missing":
            key = error["loc"][-1]
            parent = full[:-1]
            info = cls.model_fields.get(key) if len(error["loc"]) == 1 else None
            text = f"missing required key '{key}'"
            if info is not None and info.description:
                text += f" ({info.description})"
            if issubclass(cls, ContactLaw):
                text += f" for law {cls.name}"
            return self.error(parent, text, line=self.key_line(parent))
        if kind == "extra_forbidden":
            key = str(error["loc"][-1])
            choices = allowed if allowed is not None else list(cls.model_fields)
            hint = did_you_mean(key, choices) or f"; allowed keys: {', '.join(choices)}"
            what = "unknown key" if full[:-1] else "unknown top-level key"
            return self.error(full[:-1], f"{what} '{key}'{hint}", line=self.key_line(full))
        if kind == "pounding":
            return self.must(full, error["msg"], error.get("ctx", {}).get("hint", ""))
        if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
            info = cls.model_fields.get(error["loc"][0]) if len(error["loc"]) == 1 else None
            return self.must(full, f"must be {_range_text(info.metadata if info else [], error)}")
        if kind == "literal_error":
            return self.must(full, f"must be {error['ctx']['expected']}")
        if kind == "value_error":
            message = str(error["msg"]).removeprefix("Value error, ")
            return self.error(full, message)
        if kind in ("string_type", "string_parsing"):
            return self.must(full, "must be text")
        if kind in ("float_type", "float_parsing", "int_type", "int_parsing"):
            return self.must(full, "must be a number")
        if kind == "too_short":
            return self.must(full, "must not be empty")
        if kind in ("list_type", "tuple_type"):
            return self.must(full, "must be a list")
        message = str(error["msg"])
        return self.must(full, "is invalid: " + message[:1].lower() + message[1:])


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


def parse_document(text: str, label: str) -> Document:
    """Compose *text* safely; raise :class:`ModelError` on syntax errors or an empty file."""
    doc = Document(text, label)
    if doc.data is None:
        raise ModelError("the file is empty; a model needs at least 'buildings' and 'ground_motion' "
                         "(see models/README.md)", file=label, line=1)
    if not isinstance(doc.data, dict):
        kind = "a list" if isinstance(doc.data, list) else f"'{doc.got(())}'" if isinstance(doc.data, str) \
            else doc.got(())
        raise ModelError(f"the top level must be a mapping with keys buildings, contacts, ground_motion, "
                         f"solver (got {kind})", file=label, line=doc.line(()))
    return doc


# --------------------------------------------------------------------------- #
# Parsed (validated) model: plain values only
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class ParsedBuilding:
    """A validated building: per-floor values from the ground up (SI units)."""

    name: str
    mass: tuple[float, ...]
    stiffness: tuple[float, ...]
    height: tuple[float, ...]
    damping_kind: str                      # "rayleigh" | "modal"
    ratio: float | None = None
    modes: tuple[int, int] | None = None
    modal_ratios: tuple[float, ...] | None = None


@dataclass(frozen=True)
class ParsedContact:
    """A validated contact entry, expanded to 1-based level pairs."""

    index: int
    left: int
    right: int
    pairs: tuple[tuple[int, int], ...]
    gap: float
    law: ContactLaw


@dataclass(frozen=True)
class ParsedModel:
    """Everything in a valid model file, as plain values."""

    name: str | None
    buildings: tuple[ParsedBuilding, ...]
    contacts: tuple[ParsedContact, ...]
    ground_motion: dict[str, Any]
    solver: dict[str, float]
    document: Document = field(repr=False, compare=False)


def _validate(doc: Document, cls: type[BaseModel], loc: Location, data: Any,
              allowed: list[str] | None = None, what: str = "a mapping") -> BaseModel:
    if not isinstance(data, dict):
        raise doc.must(loc, f"must be {what}", line=doc.key_line(loc))
    try:
        return cls.model_validate(data)
    except ValidationError as exc:
        raise doc.from_pydantic(exc, cls, loc, allowed) from None


def parse(text: str, label: str) -> ParsedModel:
    """Validate model text completely.

    Parameters
    ----------
    text : str
        The YAML source.
    label : str
        File name for messages, as the user gave it.

    Raises
    ------
    ModelError
        The first problem, in document order within each section, as one line
        ``<label>:<line>: <location> <problem>``.
    """
    doc = parse_document(text, label)
    top = _validate(doc, TopLevel, (), doc.data)
    buildings = _parse_buildings(doc, top.buildings)
    contacts = _parse_contacts(doc, top.contacts, buildings)
    ground_motion = _parse_ground_motion(doc, top.ground_motion, [b.name for b in buildings])
    solver = _validate(doc, SolverEntry, ("solver",), {} if top.solver is None else top.solver,
                       what="a mapping of solver settings, e.g. {rtol: 1.0e-6}")
    return ParsedModel(top.name, buildings, contacts, ground_motion, solver.model_dump(), doc)


# ----------------------------------------------------------- buildings


def _parse_buildings(doc: Document, data: Any) -> tuple[ParsedBuilding, ...]:
    loc: Location = ("buildings",)
    if not isinstance(data, list):
        raise doc.must(loc, "must be a list of buildings, left to right", line=doc.key_line(loc))
    if not data:
        raise doc.error(loc, "list at least one building", line=doc.key_line(loc))
    buildings = []
    seen: dict[str, int] = {}
    for index, entry in enumerate(data):
        building = _parse_building(doc, loc + (index,), entry)
        if building.name in seen:
            first = seen[building.name]
            raise doc.must(loc + (index, "name"), "must be unique",
                           f"buildings[{first}] on line {doc.line(loc + (first, 'name'))} has the same name")
        seen[building.name] = index
        buildings.append(building)
    return tuple(buildings)


def _parse_building(doc: Document, loc: Location, data: Any) -> ParsedBuilding:
    entry = _validate(doc, BuildingEntry, loc, data, what="a mapping {name, storeys, damping}")
    mass, stiffness, height = _parse_storeys(doc, loc + ("storeys",), entry.storeys)
    damping = _parse_damping(doc, loc + ("damping",), entry.damping, entry.name, len(mass))
    return ParsedBuilding(entry.name, mass, stiffness, height, **damping)


def _parse_storeys(doc: Document, loc: Location, data: Any) -> tuple[tuple[float, ...], ...]:
    if isinstance(data, dict):
        short = _validate(doc, StoreyShorthand, loc, data)
        return ((short.mass,) * short.count, (short.stiffness,) * short.count, (short.height,) * short.count)
    if not isinstance(data, list):
        raise doc.must(loc, "must be a list of {mass, stiffness, height} from the ground up, "
                            "or {count, mass, stiffness, height}", line=doc.key_line(loc))
    if not data:
        raise doc.error(loc, "list at least one storey", line=doc.key_line(loc))
    rows = [_validate(doc, StoreyEntry, loc + (i,), item, what="a mapping {mass, stiffness, height}")
            for i, item in enumerate(data)]
    return (tuple(r.mass for r in rows), tuple(r.stiffness for r in rows), tuple(r.height for r in rows))


def _parse_damping(doc: Document, loc: Location, data: Any, name: str, n: int) -> dict[str, Any]:
    what = "a mapping, e.g. {ratio: 0.05, modes: [1, 2]} or {modal: [0.05, 0.05]}"
    if isinstance(data, dict) and "modal" in data:
        if "ratio" in data or "modes" in data:
            raise doc.error(loc, "give either ratio and modes (Rayleigh) or modal (per-mode ratios), not both",
                            line=doc.key_line(loc))
        modal = _validate(doc, ModalEntry, loc, data, what=what)
        if len(modal.modal) > n:
            raise doc.error(loc + ("modal",), f"lists {len(modal.modal)} ratios but building {name} has only "
                                              f"{_plural(n, 'mode')}", colon=False)
        return {"damping_kind": "modal", "modal_ratios": tuple(modal.modal)}
    rayleigh = _validate(doc, RayleighEntry, loc, data, allowed=["ratio", "modes", "modal"], what=what)
    i, j = rayleigh.modes
    for position, mode in enumerate(rayleigh.modes):
        if mode > n:
            hint = "; use damping: {modal: [ratio]} for a one-storey building" if n == 1 else ""
            raise doc.error(loc + ("modes", position),
                            f"mode {mode} does not exist: building {name} has {_plural(n, 'storey')}, "
                            f"so {_plural(n, 'mode')}{hint}")
    if i == j:
        raise doc.must(loc + ("modes",), "must name two different modes, e.g. [1, 2]")
    return {"damping_kind": "rayleigh", "ratio": rayleigh.ratio, "modes": (i, j)}


# ----------------------------------------------------------- contacts


def _parse_contacts(doc: Document, data: Any, buildings: tuple[ParsedBuilding, ...]) -> tuple[ParsedContact, ...]:
    loc: Location = ("contacts",)
    if data is None:
        return ()
    if not isinstance(data, list):
        raise doc.must(loc, "must be a list of contact entries", line=doc.key_line(loc))
    contacts: list[ParsedContact] = []
    joined: dict[tuple[int, int, int], int] = {}   # (left building, level_left, level_right) -> entry
    for index, entry in enumerate(data):
        contact = _parse_contact(doc, loc + (index,), index, entry, buildings)
        for position, (a, b) in enumerate(contact.pairs):
            key = (contact.left, a, b)
            if key in joined:
                left, right = buildings[contact.left].name, buildings[contact.right].name
                where = loc + (index, "levels") if doc.node(loc + (index, "levels", position)) is None \
                    else loc + (index, "levels", position)
                other = "this entry" if joined[key] == index else f"contacts[{joined[key]}]"
                raise doc.error(where, f"floors {left}{a} and {right}{b} are already joined by {other}")
            joined[key] = index
        contacts.append(contact)
    return tuple(contacts)


def _parse_contact(doc: Document, loc: Location, index: int, data: Any,
                   buildings: tuple[ParsedBuilding, ...]) -> ParsedContact:
    what = "a mapping {between, levels, gap, law, ...}"
    if not isinstance(data, dict):
        raise doc.must(loc, f"must be {what}")
    # law name first: it decides which other keys are allowed
    if "law" in data and not (isinstance(data["law"], str) and data["law"] in LAWS):
        law_name = data["law"]
        if isinstance(law_name, str):
            raise doc.error(loc + ("law",), f"unknown contact law '{law_name}'{did_you_mean(law_name, list(LAWS))}; "
                                            f"choose one of: {', '.join(LAWS)}")
        raise doc.must(loc + ("law",), f"must be one of {', '.join(LAWS)}")
    law_cls = LAWS.get(data.get("law"))
    candidates: list[ModelError] = []
    try:
        geometry = ContactGeometry.model_validate(data)
    except ValidationError as exc:
        candidates.append(doc.from_pydantic(exc, ContactGeometry, loc))
    law = None
    if law_cls is not None:
        params = {k: v for k, v in data.items() if k not in ContactGeometry.KEYS or k == "law"}
        allowed = list(ContactGeometry.KEYS) + [k for k in law_cls.model_fields if k != "law"]
        try:
            law = law_cls.model_validate(_coerce_law_numbers(doc, loc, law_cls, params))
        except ValidationError as exc:
            candidates.append(doc.from_pydantic(exc, law_cls, loc, allowed))
        except ModelError as exc:
            candidates.append(exc)
    if candidates:
        raise min(candidates, key=lambda err: (getattr(err, "rank", 1), err.line or 0))
    assert law is not None
    left, right = _parse_between(doc, loc + ("between",), geometry.between, buildings)
    pairs = _parse_levels(doc, loc, geometry, buildings[left], buildings[right])
    return ParsedContact(index, left, right, tuple(pairs), geometry.gap, law)


def _coerce_law_numbers(doc: Document, loc: Location, law_cls: type[ContactLaw],
                        params: dict[str, Any]) -> dict[str, Any]:
    """Law parameters with number fields converted by :func:`as_number`."""
    out = dict(params)
    for key, value in params.items():
        info = law_cls.model_fields.get(key)
        if info is not None and info.annotation is float:
            try:
                out[key] = as_number(value)
            except _Problem as problem:
                raise doc.must(loc + (key,), problem.predicate) from None
    return out


def _parse_between(doc: Document, loc: Location, value: Any,
                   buildings: tuple[ParsedBuilding, ...]) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2:
        raise doc.must(loc, "must be two building names, left first, e.g. [A, B]")
    names = [b.name for b in buildings]
    indices = []
    for position, item in enumerate(value):
        try:
            name = as_name(item)
        except _Problem as problem:
            raise doc.must(loc + (position,), problem.predicate) from None
        if name not in names:
            raise doc.error(loc + (position,), f"unknown building '{name}'{did_you_mean(name, names)}; "
                                               f"buildings are: {', '.join(names)}")
        indices.append(names.index(name))
    left, right = indices
    a, b = names[left], names[right]
    neighbours = ", ".join(f"{names[i]}-{names[i + 1]}" for i in range(len(names) - 1)) or "none"
    if left == right:
        raise doc.error(loc, f"joins building {a} to itself; contacts join neighbours in the row: {neighbours}")
    if left == right + 1:
        raise doc.error(loc, f"{b} stands left of {a} (buildings are listed left to right); "
                             f"write between: [{b}, {a}]")
    if abs(left - right) != 1:
        raise doc.error(loc, f"{a} and {b} are not adjacent; contacts join neighbours in the row: {neighbours}")
    return left, right


def _elevations(building: ParsedBuilding) -> np.ndarray:
    return np.cumsum(np.asarray(building.height, dtype=float))


def _parse_levels(doc: Document, loc: Location, geometry: ContactGeometry,
                  left: ParsedBuilding, right: ParsedBuilding) -> list[tuple[int, int]]:
    levels = geometry.levels
    here = loc + ("levels",)
    if levels == "matching":
        tolerance = DEFAULT_TOLERANCE if geometry.tolerance is None else geometry.tolerance
        pairs = match_levels(_elevations(left), _elevations(right), tolerance)
        if not pairs:
            def show(b: ParsedBuilding) -> str:
                e = _elevations(b)
                return ", ".join(f"{x:g}" for x in e[:6]) + (", ..." if e.size > 6 else "")
            raise doc.error(here, f"'matching' joins no floors: no floor of {left.name} is within "
                                  f"{tolerance:g} m of a floor of {right.name} (elevations {left.name}: "
                                  f"{show(left)} m; {right.name}: {show(right)} m); give explicit pairs "
                                  f"[[level_left, level_right], ...] or a larger tolerance")
        return pairs
    if geometry.tolerance is not None:
        raise doc.error(loc + ("tolerance",), "applies only to 'levels: matching'; remove it or use "
                                              "'levels: matching'", line=doc.key_line(loc + ("tolerance",)),
                        colon=False)
    if not isinstance(levels, list):
        raise doc.must(here, "must be 'matching' or a list of pairs [[level_left, level_right], ...]")
    if not levels:
        raise doc.error(here, "list at least one pair [level_left, level_right]")
    pairs = []
    for position, pair in enumerate(levels):
        where = here + (position,)
        if not isinstance(pair, list) or len(pair) != 2:
            raise doc.must(where, "must be a pair [level_left, level_right] of 1-based floor numbers")
        checked = []
        for side, (level, building) in enumerate(zip(pair, (left, right))):
            at = where + (side,)
            n = len(building.mass)
            if isinstance(level, int) and not isinstance(level, bool) and level == 0:
                raise doc.error(at, f"level 0 is the ground; floors are numbered 1 to {n} from the ground up "
                                    f"in building {building.name}")
            try:
                level = as_positive_integer(level)
            except _Problem:
                raise doc.must(at, "must be a floor number (a positive integer)") from None
            if level > n:
                raise doc.error(at, f"level {level} does not exist: building {building.name} has "
                                    f"{_plural(n, 'floor')}")
            checked.append(level)
        pairs.append((checked[0], checked[1]))
    return pairs


# ----------------------------------------------------------- ground motion


def record_is_catalogued(record: str) -> bool:
    """True for a catalogue reference (``fema-p695:farfield/1a``) or a bare catalogue name."""
    from pounding.records.catalogue import is_catalogue_name

    return is_catalogue_reference(record) or is_catalogue_name(record)


def _spec_error(doc: Document, loc: Location, problem: Any) -> ModelError:
    """A :class:`pounding.processing.SpecProblem` at *loc* as a located one-line error."""
    where = loc + problem.where
    line = doc.key_line(loc + problem.at) if problem.at != problem.where else None
    if problem.kind == "must":
        return doc.must(where, problem.text, problem.hint, line=line)
    return doc.error(where, problem.text, line=line)


def _parse_ground_motion(doc: Document, data: Any, buildings: list[str] | None = None) -> dict[str, Any]:
    from pounding.records.processing import SpecProblem, Scaling, parse_processing, parse_scale

    loc: Location = ("ground_motion",)
    entry = _validate(doc, GroundMotionEntry, loc, data,
                      what="a mapping, e.g. {record: fema-p695:farfield/1a, scale: 1.0}")
    record = entry.record
    try:
        scale = parse_scale(entry.scale, buildings)
    except SpecProblem as problem:
        raise _spec_error(doc, loc + ("scale",), problem) from None
    try:
        processing = parse_processing(entry.processing)
    except SpecProblem as problem:
        raise _spec_error(doc, loc + ("processing",), problem) from None
    if record_is_catalogued(record):
        if not is_catalogue_reference(record):
            from pounding.records.catalogue import get_entry
            from pounding.errors import RecordError

            try:
                catalogued = get_entry(record)
            except RecordError as error:
                raise doc.error(loc + ("record",), str(error)) from None
            fema = catalogued.source.startswith("fema-p695:")
        else:
            fema = record.lower().startswith("fema-p695:")
        if isinstance(scale, Scaling) and scale.method == "fema-p695" and not fema:
            raise doc.error(loc + ("scale", "fema-p695"), f"the FEMA P695 normalisation factor exists only for "
                                                          f"FEMA P695 records; '{record}' is not one: scale it "
                                                          "with pga or sa instead",
                            line=doc.key_line(loc + ("scale", "fema-p695")))
    else:
        suffix = PurePath(record).suffix.lower()
        if isinstance(scale, Scaling) and scale.method == "fema-p695":
            raise doc.error(loc + ("scale", "fema-p695"), f"the FEMA P695 normalisation factor exists only for "
                                                          f"FEMA P695 records; '{record}' is a file: scale it "
                                                          "with pga or sa instead",
                            line=doc.key_line(loc + ("scale", "fema-p695")))
        if suffix == ".at2":
            if entry.units not in (None, "g"):
                raise doc.must(loc + ("units",), "must be g for a PEER .AT2 record (AT2 files are in g)")
        elif entry.units is None:
            raise doc.error(loc + ("record",), f"the plain-text record '{record}' needs ground_motion.units "
                                               "(g, m/s2, cm/s2 or gal)")
    out = entry.model_dump()
    out["scale"] = scale
    out["processing"] = processing
    return out
