"""YAML text → plain data, with the line of every value: the reading half of model validation.

:class:`Document` composes the text once with a hardened, safe loader and
keeps a map from every location (``('buildings', 1, 'storeys', 3, 'mass')``)
to its YAML node, hence to its line and to the value exactly as written.
Checking the data is the job of :mod:`pounding.model.schema`; this module only
reads, and words located messages (:meth:`Document.error`, :meth:`Document.must`).

The reader
----------
* YAML 1.2 core-schema scalars: ``1:30`` is text (not 90, the YAML 1.1
  sexagesimal), ``1_000`` is text, ``yes/no/on/off`` are text (only
  ``true/false`` are booleans), ``0x1F`` and ``0o17`` are integers, ``2.5e5``
  is a float; dates stay text.
* Only plain data: an unknown tag (``!!python/object``) is refused.
* Duplicate keys are refused; ``<<`` merges are followed at most
  :data:`MAX_MERGE_DEPTH` deep.
* Bounded: nesting deeper than :data:`MAX_DEPTH` levels, and alias expansion
  beyond :data:`EXPANSION_FACTOR` times the written nodes (a "billion laughs"
  file), stop with one line instead of exhausting memory or the stack.
* Control characters (NUL...) anywhere, and a second document in the file,
  are one-line errors.
"""

from __future__ import annotations

import pickle
import re
from typing import Any

import yaml

from pounding.errors import ModelError
from pounding.units import NUMBER_TEXT

__all__ = ["Document", "Location", "format_location", "parse_document", "dump_document", "plain_copy", "MAX_DEPTH",
           "EXPANSION_FACTOR", "MAX_MERGE_DEPTH", "plural", "is_plan_document"]

Location = tuple[str | int, ...]

#: Deepest nesting of mappings and lists accepted in a YAML file.
MAX_DEPTH = 64
#: Alias expansion may produce at most this many times the nodes written in the file (plus 10 000).
EXPANSION_FACTOR = 10
#: Longest chain of ``<<`` merges followed.
MAX_MERGE_DEPTH = 20

_MERGE_TAG = "tag:yaml.org,2002:merge"
_STR_TAG = "tag:yaml.org,2002:str"


def format_location(loc: Location) -> str:
    """``('buildings', 1, 'storeys', 3, 'mass')`` → ``'buildings[1].storeys[3].mass'``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def plural(count: int, word: str) -> str:
    """``1 storey``, ``2 storeys``."""
    return f"{count} {word}" if count == 1 else f"{count} {word}s"


# --------------------------------------------------------------------------- #
# The hardened YAML 1.2 loader
# --------------------------------------------------------------------------- #

_INT_12 = re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$")
_FLOAT_12 = re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                       r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$")
_BOOL_12 = re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$")
_NULL_12 = re.compile(r"^(?:~|null|Null|NULL|)$")


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 core-schema scalars and a nesting bound."""

    yaml_implicit_resolvers: dict = {}

    def __init__(self, stream: str):
        super().__init__(stream)
        self.depth = 0

    def compose_node(self, parent: Any, index: Any) -> yaml.Node:
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise yaml.composer.ComposerError(None, None, f"nesting deeper than {MAX_DEPTH} levels", mark)
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1

    def construct_yaml_int(self, node: yaml.ScalarNode) -> int:
        text = node.value
        if text.startswith("0o"):
            return int(text[2:], 8)
        if text.startswith("0x"):
            return int(text[2:], 16)
        return int(text)

    def construct_yaml_bool(self, node: yaml.ScalarNode) -> bool:
        return node.value.lower() == "true"

    def construct_yaml_float(self, node: yaml.ScalarNode) -> float:
        return float(node.value.lower().replace(".inf", "inf").replace(".nan", "nan"))


_Loader.add_constructor("tag:yaml.org,2002:int", _Loader.construct_yaml_int)
_Loader.add_constructor("tag:yaml.org,2002:bool", _Loader.construct_yaml_bool)
_Loader.add_constructor("tag:yaml.org,2002:float", _Loader.construct_yaml_float)
for _tag, _pattern, _first in (
        ("tag:yaml.org,2002:bool", _BOOL_12, "tTfF"),
        ("tag:yaml.org,2002:int", _INT_12, "-+0123456789"),
        ("tag:yaml.org,2002:float", _FLOAT_12, "-+0123456789."),
        ("tag:yaml.org,2002:null", _NULL_12, ["~", "n", "N", ""]),
        (_MERGE_TAG, re.compile(r"^<<$"), "<")):
    _Loader.add_implicit_resolver(_tag, _pattern, list(_first))

#: Tags of values a model file may hold.
_PLAIN_TAGS = frozenset({"tag:yaml.org,2002:int", "tag:yaml.org,2002:bool", "tag:yaml.org,2002:float",
                         "tag:yaml.org,2002:null", _STR_TAG, "tag:yaml.org,2002:seq", "tag:yaml.org,2002:map"})

_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f\x80-\x84\x86-\x9f\ufffe\uffff]")


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
        Plain Python data (keys as written).
    values, keys : dict
        Location → value node / key node.
    """

    def __init__(self, text: str, label: str):
        self.text = text
        self.label = label
        self.values: dict[Location, yaml.Node] = {}
        self.keys: dict[Location, yaml.Node] = {}
        self._check_characters()
        self._loader = _Loader(text)
        try:
            root = self._loader.get_single_node()
            self._budget = 10_000 + EXPANSION_FACTOR * self._count_nodes(root)
            self.data = None if root is None else self._convert(root, (), set())
        except yaml.MarkedYAMLError as exc:
            raise self._syntax_error(exc) from None
        except yaml.YAMLError as exc:
            raise ModelError(f"invalid YAML: {' '.join(str(exc).split())}", file=label) from None
        except RecursionError:
            raise ModelError(f"invalid YAML: nesting deeper than {MAX_DEPTH} levels", file=label) from None
        finally:
            self._loader.dispose()

    # ----------------------------------------------------------- reading
    def _check_characters(self) -> None:
        bad = _CONTROL.search(self.text)
        if bad is None:
            return
        line = self.text.count("\n", 0, bad.start()) + 1
        column = bad.start() - (self.text.rfind("\n", 0, bad.start()) + 1) + 1
        raise ModelError(f"invalid YAML: control character U+{ord(bad.group()):04X} in column {column}; a model "
                         "file is plain text: remove it (a NUL byte often means a binary or UTF-16 file)",
                         file=self.label, line=line)

    @staticmethod
    def _count_nodes(root: yaml.Node | None) -> int:
        """Distinct nodes written in the file (aliases counted once)."""
        seen: set[int] = set()
        stack = [root] if root is not None else []
        while stack:
            node = stack.pop()
            if id(node) in seen:
                continue
            seen.add(id(node))
            if isinstance(node, yaml.SequenceNode):
                stack.extend(node.value)
            elif isinstance(node, yaml.MappingNode):
                stack.extend(n for pair in node.value for n in pair)
        return len(seen)

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
        if "nesting deeper" in message:
            message += "; a model file is a few levels deep (buildings[0].storeys[0].mass)"
        return ModelError(message, file=self.label, line=None if mark is None else mark.line + 1)

    def _convert(self, node: yaml.Node, loc: Location, active: set[int]) -> Any:
        self.values[loc] = node
        self._budget -= 1
        if self._budget < 0:
            raise self.error(loc, "YAML aliases expand to too many values (more than "
                                  f"{EXPANSION_FACTOR} times what the file writes); write the values out, "
                                  "or use storeys: {count: ...} for repeated storeys")
        if node.tag not in _PLAIN_TAGS:
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
            if not isinstance(merged, yaml.MappingNode) or depth > MAX_MERGE_DEPTH:
                what = "'<<' must merge a mapping" if depth <= MAX_MERGE_DEPTH else \
                    f"'<<' merges are chained more than {MAX_MERGE_DEPTH} deep"
                raise ModelError(f"{format_location(loc) or 'top level'}: {what}",
                                 file=self.label, line=merged.start_mark.line + 1)
            self._budget -= len(merged.value)
            for key, pair in self._mapping_pairs(merged, loc, depth + 1).items():
                pairs.setdefault(key, pair)
        return pairs

    # ----------------------------------------------------------- look-ups
    def has(self, loc: Location) -> bool:
        """True if the document has a value at *loc*."""
        return loc in self.values

    def node(self, loc: Location) -> yaml.Node | None:
        """The value node at *loc*, or None if the location is absent."""
        return self.values.get(loc)

    def line(self, loc: Location) -> int | None:
        """1-based line of the value at *loc* (or of its closest present ancestor)."""
        while loc not in self.values and loc:
            loc = loc[:-1]
        node = self.values.get(loc)
        return 1 if node is None else node.start_mark.line + 1

    def key_line(self, loc: Location) -> int | None:
        """Line of the key that introduces *loc*, else of its value."""
        node = self.keys.get(loc)
        return node.start_mark.line + 1 if node is not None else self.line(loc)

    def got(self, loc: Location) -> str:
        """The value at *loc* as written in the file, for ``(got ...)``."""
        node = self.values.get(loc)
        if node is None:
            return "nothing"
        if isinstance(node, yaml.ScalarNode):
            value = self._loader.construct_object(node) if node.tag != _STR_TAG else node.value
            if node.value == "":
                return "nothing"
            if isinstance(value, str) and not NUMBER_TEXT.match(value):
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


class DataSource(Document):
    """Data given in Python (no file): the same messages, with ``repr`` values and no lines.

    Parameters
    ----------
    data : Any
        The plain data validated (for ``(got ...)``).
    root : Location
        Where *data* sits in a model (``('ground_motion',)`` for that section).
    prefix : str
        Replaces the location's root in messages (``'building x:'``); empty for none.
    """

    def __init__(self, data: Any, root: Location = (), prefix: str = ""):   # noqa: D107 - no YAML to read
        self.text = ""
        self.label = None       # type: ignore[assignment]
        self.data = data
        self.root = root
        self.prefix = prefix
        self.values = {}
        self.keys = {}

    def _value(self, loc: Location) -> tuple[bool, Any]:
        value = self.data
        for part in loc[len(self.root):]:
            try:
                value = value[part]
            except (KeyError, IndexError, TypeError):
                return False, None
        return True, value

    def has(self, loc: Location) -> bool:
        return self._value(loc)[0]

    def line(self, loc: Location) -> int | None:
        return None

    def key_line(self, loc: Location) -> int | None:
        return None

    def got(self, loc: Location) -> str:
        found, value = self._value(loc)
        if not found or value is None:
            return "nothing"
        if isinstance(value, tuple):
            value = list(value)
        return repr(value)

    def _where(self, loc: Location) -> str:
        where = format_location(loc)
        return f"{self.prefix} {where}".strip() if self.prefix else where

    def error(self, loc: Location, text: str, *, line: int | None = None, colon: bool = True) -> ModelError:
        where = self._where(loc)
        return ModelError((f"{where}: {text}" if colon else f"{where} {text}") if where else text)

    def must(self, loc: Location, predicate: str, hint: str = "", *, line: int | None = None) -> ModelError:
        message = f"{self._where(loc)} {predicate} (got {self.got(loc)})"
        if hint:
            message += f" {hint}" if hint.startswith("(") else f"; {hint}"
        return ModelError(message)


#: PyYAML's libyaml emitter where the wheel has it: the same text as the pure-Python one, ~5x sooner.
_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


def dump_document(data: Any) -> str:
    """Plain data (a model document) as the YAML text pounding writes and hashes.

    Block style for mappings, flow style for lists of scalars, lines up to
    100 characters, keys in their order; the text of ``yaml.safe_dump`` with
    those options, written by libyaml when PyYAML has it (a sweep or an IDA
    writes one document per run, and its scenario key hashes the text).
    """
    return yaml.dump(data, Dumper=_DUMPER, sort_keys=False, default_flow_style=None, width=100)


def plain_copy(data: Any) -> Any:
    """A deep copy of plain data (a model document: mappings, lists and scalars), equal to what
    ``copy.deepcopy`` makes (shared parts stay shared), about five times sooner: one pickle round trip
    instead of deepcopy's walk in Python.  A sweep copies its base document for every axis value it checks
    and every scenario it expands (53 µs → 11 µs for ``models/pair.yaml``'s)."""
    return pickle.loads(pickle.dumps(data, pickle.HIGHEST_PROTOCOL))


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


def is_plan_document(data: Any) -> bool:
    """True if *data* (a model document) has a building with a ``plan`` key (docs/plan-models.md)."""
    buildings = data.get("buildings") if isinstance(data, dict) else None
    return isinstance(buildings, list) and any(isinstance(b, dict) and "plan" in b for b in buildings)
