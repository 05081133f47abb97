"""Incremental dynamic analysis (IDA) and fragility, with and without pounding: ``pounding ida``.

Every record of a set is scaled to a series of intensities and the model is
run at each (Vamvatsikos & Cornell 2002, "Incremental dynamic analysis",
EESD 31 491–514).  With ``--without-contacts`` every run is repeated with
the contacts held open (:func:`pounding.studies.gap.open_contacts`), so the
effect of pounding is measured on identical records and intensities.  See
``docs/physics.md`` §8 and ``docs/ida.md``.

Intensity measure (IM)
    ``sa-t1``: the 5 %-damped pseudo-spectral acceleration at the first
    (elastic) period of one building; ``pga``: the peak ground acceleration.
    Both are computed on the record as the model uses it (read, then
    processed as ``ground_motion.processing`` says), over its whole length.

Scaling to a level (:class:`IdaPlan`)
    ``record``: each record on its own, factor = level / IM_i, so its IM
    equals the level.  ``fema-p695`` (the default when every record is a FEMA
    P695 record): the FEMA P695 (2009, §A.8) procedure — each record is first
    multiplied by its normalisation factor NM_i, then the whole normalised set
    by one factor so that the *median* IM of the set equals the level:
    factor_i = NM_i · level / median_j(NM_j · IM_j).  A record's own IM is then
    ``intensity`` (record, level), and the level is the set's median.  Either
    way the factor is relative to the record as stored in the catalogue (or
    file), after processing.

Levels
    Fixed stripes (``--levels``): every record at every level.  Or
    hunt-and-fill (``--hunt``, :func:`next_hunt_level`): per record, levels
    rise with a growing step until the first collapse, the bracket between
    the highest non-collapsing and the lowest collapsing level is bisected
    down to a tolerance, and leftover runs fill the largest gaps below it
    (Vamvatsikos & Cornell 2004, "Applied incremental dynamic analysis",
    Earthquake Spectra 20 523–553).

Outcome of a run
    ``completed`` or ``collapsed`` from the run's ``status`` attribute
    (``collapsed`` only when the solver stopped the run at its collapse
    criterion), ``failed`` when the run raised.  A building is taken as
    **collapsed** in a run when the run's status is ``collapsed`` (every
    building: the run stopped, so the later response of its neighbours is
    unknown) or when its largest peak storey drift ratio reaches the collapse
    drift (``collapse_drift``, by default the largest drift limit).  A
    collapsed building counts as exceeding every drift limit.

Fragility (:mod:`pounding.studies.fragility`)
    Stripes: lognormal θ, β by maximum likelihood on the counts of records
    exceeding each limit at each level (Baker 2015), failed runs left out.
    Hunt: from each record's intensity at the limit (Baker 2015 eqs. 3–4):
    for collapse, the middle of the final bracket; for a drift limit, the IM
    where the record's IDA curve (max drift ratio against IM, runs in IM
    order) first reaches the limit, by linear interpolation between the two
    runs either side (the middle of them when the upper one collapsed).
    With ``mce``: the collapse margin ratio CMR = Ŝ_CT / S_MT, Ŝ_CT = θ of
    collapse (FEMA P695 §7.2).
"""

from __future__ import annotations

import copy
import math
import os
import sys
import threading
import time
from collections import OrderedDict
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np
import yaml

from pounding.errors import PoundingError
from pounding.model.document import dump_document
from pounding.units import STANDARD_GRAVITY

__all__ = ["IDA_PART", "VARIANTS", "DEFAULT_LIMITS", "IM_NAMES", "SCALINGS", "IntensityMeasure", "Hunt",
           "IdaPlan", "parse_levels", "parse_limits", "build_ida_plan", "run_ida_scenario", "next_hunt_level",
           "run_hunt", "ida_study", "assemble_ida_dataset", "ida_fragility", "ida_summary", "ida_table",
           "plot_ida", "run_outcome", "parse_intensity", "limit_label"]

#: Version of this study's part layout (stored in each part, checked when parts are reused).
IDA_PART = "ida-1"
#: The two variants of every scenario: the model as given, and with its contacts held open.
VARIANTS = ("with_contacts", "without_contacts")
#: Peak storey drift ratio limits of the fragility functions by default (0.5 %, 1.5 %, 2.5 %).
DEFAULT_LIMITS = (0.005, 0.015, 0.025)
IM_NAMES = ("sa-t1", "pga")
SCALINGS = ("auto", "record", "fema-p695")
#: Most levels of a --levels range (a typo such as 0.1:300:0.1 would ask for 3000 stripes).
MAX_LEVELS = 500
#: Largest dispersion reported; a larger one means the data do not define a fragility.
MAX_BETA = 5.0
#: Damping ratio of Sa(T1).
SA_DAMPING = 0.05


# --------------------------------------------------------------------------- #
# Inputs: intensity measure, levels, limits, hunt settings
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class IntensityMeasure:
    """What a level measures.

    Attributes
    ----------
    name : str
        ``sa-t1`` or ``pga``.
    building : str
        The building whose first period is T1 (``sa-t1``); also the building
        whose collapse a hunt brackets.
    period : float
        T1, s (NaN for ``pga``).
    """

    name: str
    building: str
    period: float = float("nan")

    def of(self, record) -> float:
        """The IM of a :class:`pounding.records.record.Record`, m/s²."""
        if self.name == "pga":
            return float(record.pga)
        from pounding.records.spectra import spectral_acceleration

        return spectral_acceleration(record, period=self.period, damping=SA_DAMPING)

    def describe(self) -> str:
        if self.name == "pga":
            return "PGA"
        return f"Sa(T1 = {self.period:.3f} s of building {self.building}, 5 %)"


@dataclass(frozen=True)
class Hunt:
    """Hunt-and-fill settings, all levels in g.

    The hunt runs ``start``, then adds ``step + k·increment`` after the k-th
    run (k = 0, 1, ...) until the first collapse or ``ceiling``; the bracket
    is then bisected until it is at most ``tolerance`` wide; then, until the
    record has ``runs`` runs, the largest gap between 0 and the non-collapsing
    levels is split in two (if wider than ``tolerance``).
    """

    start: float = 0.1
    step: float = 0.1
    increment: float = 0.05
    tolerance: float = 0.05
    runs: int = 12
    ceiling: float = 5.0

    def check(self) -> None:
        for name in ("start", "step", "tolerance", "ceiling"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise PoundingError(f"--hunt: {name} must be > 0 (got {value:g})")
        if not (math.isfinite(self.increment) and self.increment >= 0):
            raise PoundingError(f"--hunt: increment must be >= 0 (got {self.increment:g})")
        if self.ceiling < self.start:
            raise PoundingError(f"--hunt-ceiling {self.ceiling:g} g is below the first level {self.start:g} g")
        if self.runs < 1:
            raise PoundingError(f"--runs-per-record must be >= 1 (got {self.runs})")


def _number(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise PoundingError(f"{what}: '{text}' is not a number") from None
    if not math.isfinite(value):
        raise PoundingError(f"{what}: '{text}' is not a finite number")
    return value


def parse_levels(text: str) -> np.ndarray:
    """``--levels``: ``START:STOP:STEP`` (both ends included) or a comma-separated list, in g; sorted, > 0."""
    raw = str(text).strip()
    what = f"--levels {raw!r}"
    if ":" in raw:
        pieces = raw.split(":")
        if len(pieces) != 3:
            raise PoundingError(f"{what}: write START:STOP:STEP in g, e.g. 0.1:3.0:0.1, or a list 0.2,0.4,0.8")
        start, stop, step = (_number(p, what) for p in pieces)
        if not step > 0:
            raise PoundingError(f"{what}: STEP must be > 0")
        if stop < start:
            raise PoundingError(f"{what}: STOP must be >= START")
        count = int(math.floor((stop - start) / step + 1e-9)) + 1
        if count > MAX_LEVELS:
            raise PoundingError(f"{what} gives {count} levels; at most {MAX_LEVELS}: use a larger STEP")
        levels = np.round(start + step * np.arange(count), 10)
    else:
        items = [p for p in raw.split(",") if p.strip()]
        if not items:
            raise PoundingError(f"{what}: write START:STOP:STEP in g, e.g. 0.1:3.0:0.1, or a list 0.2,0.4,0.8")
        levels = np.array(sorted({_number(p.strip(), what) for p in items}))
        if levels.size > MAX_LEVELS:
            raise PoundingError(f"{what} gives {levels.size} levels; at most {MAX_LEVELS}")
    if not np.all(levels > 0):
        raise PoundingError(f"{what}: every level must be > 0 (in g)")
    return levels


def parse_limits(text: str | None) -> tuple[float, ...]:
    """``--limits``: comma-separated peak storey drift ratios (0.015 = 1.5 %), each in (0, 1)."""
    if text is None:
        return DEFAULT_LIMITS
    values = []
    for item in str(text).split(","):
        if not item.strip():
            continue
        value = _number(item.strip(), f"--limits {text!r}")
        if not 0 < value < 1:
            raise PoundingError(f"--limits {text!r}: a drift ratio must be in (0, 1), e.g. 0.015 for 1.5 % "
                                f"(got {value:g})")
        values.append(value)
    if not values:
        raise PoundingError("--limits needs drift ratios, e.g. 0.005,0.015,0.025")
    return tuple(sorted(set(values)))


def limit_label(value: float) -> str:
    """A drift limit as the JSON and the archive write it: ``0.015``."""
    return f"{value:g}"


# --------------------------------------------------------------------------- #
# The plan: records, their IM and factors, the scenarios
# --------------------------------------------------------------------------- #

#: A scale no model uses, written into a document's one dump per variant and record and then
#: replaced by each run's factor (IdaPlan._scaled_document).
_SCALE_PLACEHOLDER = 1.2345678901234567e+299


def _yaml_scalar(value: float) -> str:
    """*value* as :func:`~pounding.model.document.dump_document` writes it inside a document (``0.5``, ``1.0e-05``, ``.inf``)."""
    return yaml.representer.SafeRepresenter().represent_float(value).value


@dataclass
class IdaPlan:
    """Everything an IDA runs: the record sweep, the IM, the factor of every record at a level.

    ``unit_factor[r]`` is the factor that takes record r to level 1 m/s²; a
    level L (m/s²) uses ``L · unit_factor[r]``, and record r's own IM is then
    ``L · unit_factor[r] · im_stored[r]``.
    """

    sweep: Any                     # the record sweep (pounding.studies.sweep.spec.Sweep), one scenario per record
    records: list[str]
    documents: list[dict]          # the model document of each record (plain data, scale 1)
    im: IntensityMeasure
    im_stored: np.ndarray          # IM of each record as stored (after processing), m/s²
    normalisation: np.ndarray      # FEMA P695 NM_i, or 1
    unit_factor: np.ndarray
    scaling: str                   # record | fema-p695
    buildings: list[str]
    variants: tuple[str, ...]
    limits: tuple[float, ...]
    collapse_drift: float
    levels: np.ndarray | None = None   # g (stripes)
    hunt: Hunt | None = None
    mce: float | None = None           # m/s²
    model_path: str = ""
    model_name: str = ""
    errors: list[str | None] = field(default_factory=list)   # per record: why it cannot run (or None)
    _cache: dict = field(default_factory=dict, repr=False)

    def factor(self, record: int, level_g: float) -> float:
        """The factor on record *record* (as stored) at level *level_g* (g)."""
        return float(level_g * STANDARD_GRAVITY * self.unit_factor[record])

    def intensity(self, record: int, level_g: float) -> float:
        """Record *record*'s own IM at level *level_g*, m/s²."""
        return float(self.factor(record, level_g) * self.im_stored[record])

    def scenario(self, variant: str, record: int, level_g: float):
        """The :class:`~pounding.studies.sweep.spec.Scenario` of one run (cached)."""
        from pounding.studies.sweep.spec import Scenario, code_fingerprint, content_key, record_fingerprint, \
            scenario_key

        cache_key = (variant, record, float(level_g))
        if cache_key in self._cache:
            return self._cache[cache_key]
        coords = {"variant": variant, "record": self.records[record], "level": f"{level_g:g}g"}
        error = self.errors[record]
        if error is None:
            document, text = self._scaled_document(variant, record, self.factor(record, level_g))
        else:
            document = copy.deepcopy(self.documents[record])
            text = dump_document(document)
        base_dir = self.sweep.base_dir
        identity = scenario_key(text if error is None else f"{text}\n# invalid: {error}", base_dir)
        fingerprint = self._cache.get(("record", record))
        if fingerprint is None:  # hashes the record file, or asks the package version: once per record
            fingerprint = self._cache[("record", record)] = record_fingerprint(self.records[record], base_dir)
        key = content_key(identity, fingerprint, code_fingerprint())
        scenario = Scenario((VARIANTS.index(variant), record), coords, text, base_dir, key, error, document, identity)
        self._cache[cache_key] = scenario
        return scenario

    def _scaled_document(self, variant: str, record: int, factor: float) -> tuple[dict, str]:
        """Record *record*'s model document in *variant* with the record scaled by *factor*: (data, YAML text).

        The text is exactly :func:`~pounding.model.document.dump_document` of the data (the
        scenario key hashes it), but built from one dump per variant and record with the factor
        written in: a dump takes milliseconds, which over the thousands of runs of an IDA was
        seconds of serial work on the client before the first run.  The documents share everything but their
        ``ground_motion`` mapping; nothing changes a scenario's data after it is made.
        """
        from pounding.studies.gap import OPEN_GAP

        template = self._cache.get(("template", variant, record))
        if template is None:
            base = copy.deepcopy(self.documents[record])
            if variant == "without_contacts":
                for contact in base.get("contacts") or []:
                    contact["gap"] = OPEN_GAP
            base["ground_motion"]["scale"] = _SCALE_PLACEHOLDER
            pieces = dump_document(base).split(_yaml_scalar(_SCALE_PLACEHOLDER))
            template = (base, pieces)
            self._cache[("template", variant, record)] = template
        base, pieces = template
        document = dict(base)
        document["ground_motion"] = dict(base["ground_motion"], scale=factor)
        if len(pieces) != 2:  # the placeholder is not one scalar of the text: dump the whole document
            return document, dump_document(document)
        return document, _yaml_scalar(factor).join(pieces)

    def stripe_scenarios(self) -> list:
        """Every (variant, record, level) of the fixed stripes, variant slowest."""
        return [self.scenario(v, r, float(level)) for v in self.variants for r in range(len(self.records))
                for level in self.levels]


def _record_setting(records: str | list[str] | None, base) -> list[str]:
    from pounding.studies.compare import record_list

    listed = record_list(records)
    if listed is not None:
        return [os.path.abspath(r) if os.path.exists(r) else r for r in listed]
    return [base.ground_motion.record if base.ground_motion.is_catalogue else str(base.ground_motion.record_path)]


def build_ida_plan(model: str | os.PathLike, records: str | list[str] | None = None, *, im: str = "sa-t1",
                   building: str | None = None, levels: Any = None, hunt: Hunt | None = None,
                   without_contacts: bool = False, limits: Any = None, collapse_drift: float | None = None,
                   mce: float | None = None, scaling: str = "auto", duration: float | None = None) -> IdaPlan:
    """Check the inputs of an IDA and resolve every record's IM and factor (before any run).

    Parameters
    ----------
    model : path-like
        YAML model.
    records : str or list of str, optional
        A set (``fema-p695:farfield``) or a comma-separated list; default: the model's record.
    im : str
        ``sa-t1`` or ``pga``.
    building : str, optional
        The building of Sa(T1) and of the hunt's collapse (default: the first).
    levels : str or array, optional
        Stripes in g (``0.1:3.0:0.1``, a list, or an array); exclusive with *hunt*.
    hunt : Hunt, optional
        Hunt-and-fill instead of stripes.
    without_contacts : bool
        Also run every scenario with the contacts held open.
    limits : str or sequence, optional
        Drift-ratio limits (default :data:`DEFAULT_LIMITS`).
    collapse_drift : float, optional
        Peak storey drift ratio taken as collapse (default: the largest limit).
    mce : float, optional
        S_MT, m/s², for the collapse margin ratio.
    scaling : str
        ``auto``, ``record`` or ``fema-p695`` (see the module docstring).
    duration : float, optional
        Simulated time of every run, s.
    """
    import yaml

    from pounding.model.model import load_model, model_from_data
    from pounding.simulation import record_for
    from pounding.studies.sweep.spec import sweep_from_text

    if im not in IM_NAMES:
        raise PoundingError(f"--im {im!r}: choose one of {', '.join(IM_NAMES)}")
    if scaling not in SCALINGS:
        raise PoundingError(f"--scaling {scaling!r}: choose one of {', '.join(SCALINGS)}")
    if (levels is None) == (hunt is None):
        raise PoundingError("give either --levels START:STOP:STEP (fixed stripes) or --hunt (hunt-and-fill)")
    if levels is not None and not isinstance(levels, np.ndarray):
        levels = parse_levels(levels) if isinstance(levels, str) else np.array(sorted(float(x) for x in levels))
    if hunt is not None:
        hunt.check()
    drift_limits = limits if isinstance(limits, tuple) else parse_limits(
        None if limits is None else (",".join(map(str, limits)) if not isinstance(limits, str) else limits))
    if collapse_drift is None:
        collapse_drift = max(drift_limits)
    if not (math.isfinite(collapse_drift) and collapse_drift > 0):
        raise PoundingError(f"--collapse-drift must be > 0 (got {collapse_drift:g})")
    if mce is not None and not (math.isfinite(mce) and mce > 0):
        raise PoundingError(f"--mce must be > 0 (got {mce:g})")
    if duration is not None and not duration > 0:
        raise PoundingError(f"--duration must be > 0 (got {duration:g})")

    base = load_model(model)   # the model's own errors, with its file name
    base.refuse_building_records("pounding ida (it scales one record)")
    names = [b.name for b in base.buildings]
    if building is None:
        building = names[0]
    elif building not in names:
        raise PoundingError(f"--building {building!r}: the model has buildings {', '.join(names)}")
    period = float(base.buildings[names.index(building)].periods[0]) if im == "sa-t1" else float("nan")
    measure = IntensityMeasure(im, building, period)
    if without_contacts and not base.gaps:
        raise PoundingError(f"{os.fspath(model)}: --without-contacts needs a model with contacts")

    path = os.path.abspath(os.fspath(model))
    settings: dict[str, Any] = {"name": f"{base.name} (IDA)", "ground_motion.scale": 1.0}
    if duration is not None:
        settings["ground_motion.duration"] = float(duration)
    listed = _record_setting(records, base)
    document = {"name": f"ida-{Path(path).stem}", "model": path, "set": settings, "axes": {"records": listed}}
    sweep = sweep_from_text(yaml.safe_dump(document, sort_keys=False), label=f"<ida {os.fspath(model)}>",
                            base_dir=os.getcwd())
    invalid = sweep.invalid_values()
    if invalid:
        raise PoundingError(invalid[0].split(": ", 1)[-1])
    scenarios = sweep.scenarios()
    if not scenarios:
        raise PoundingError("--records: the record set is empty")
    recs = [str(s.coords["record"]) for s in scenarios]
    documents, stored, norm, errors = [], [], [], []
    for s in scenarios:
        documents.append(s.data)
        try:
            if s.error is not None:
                raise PoundingError(s.error)
            one = model_from_data(s.data, name=base.name, source=s.document, base_dir=s.base_dir)
            rec = record_for(one)
            value = measure.of(rec)
            if not value > 0:
                raise PoundingError(f"record {s.coords['record']}: its {measure.describe()} is 0; it cannot be "
                                    "scaled")
            stored.append(value)
            nm = rec.metadata.get("normalization_factor")
            norm.append(float(nm) if isinstance(nm, (int, float)) and nm > 0 else float("nan"))
            errors.append(None)
        except PoundingError as exc:
            stored.append(float("nan"))
            norm.append(float("nan"))
            errors.append(f"{sweep.label}: record {s.coords['record']}: {' '.join(str(exc).split())}")
    if all(e is not None for e in errors):
        raise PoundingError(f"no record can be read: {errors[0]}")
    im_stored, normalisation = np.array(stored), np.array(norm)
    readable = np.array([e is None for e in errors])
    fema = bool(np.all(np.isfinite(normalisation[readable])))
    if scaling == "auto":
        scaling = "fema-p695" if fema else "record"
    if scaling == "fema-p695":
        if not fema:
            raise PoundingError("--scaling fema-p695 needs FEMA P695 records (fema-p695:farfield, "
                                "fema-p695:nearfield); use --scaling record")
        median = float(np.median(normalisation[readable] * im_stored[readable]))
        unit = normalisation / median
    else:
        normalisation = np.ones_like(im_stored)
        unit = 1.0 / im_stored
    variants = VARIANTS if without_contacts else VARIANTS[:1]
    return IdaPlan(sweep=sweep, records=recs, documents=documents, im=measure, im_stored=im_stored,
                   normalisation=normalisation, unit_factor=unit, scaling=scaling, buildings=names,
                   variants=variants, limits=drift_limits, collapse_drift=float(collapse_drift), levels=levels,
                   hunt=hunt, mce=mce, model_path=path, model_name=base.name, errors=errors)


# --------------------------------------------------------------------------- #
# One run (on a worker)
# --------------------------------------------------------------------------- #


def _plain(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


#: This worker process's validated models and processed (unscaled) records of the last few IDA
#: templates (a variant and a record).  The runs of one template differ only in their
#: ``ground_motion.scale``, a plain factor; validating the model and reading and processing the
#: record took ~3 ms of every ~30 ms run, and is now done once per worker and template.
_TEMPLATES: OrderedDict = OrderedDict()
_TEMPLATES_KEPT = 8
_TEMPLATES_LOCK = threading.Lock()


def _model_and_record(task: dict[str, Any]) -> tuple[Any, Any]:
    """The run's model and its scaled record (None: the model loads its own), reusing its template's.

    A run is keyed by its document data with the scale left out (``repr`` of plain data: exact
    for floats), its base folder and name; a scaled record is
    ``scale_record(processed, factor)``, exactly what :func:`~pounding.simulation.record_for`
    makes of ``scale: factor``.  The first run of a template validates its own document, so a
    model or record error is that run's error, raised again by every run of it (nothing is kept).
    """
    from pounding.model.model import model_from_data
    from pounding.records.processing import scale_record
    from pounding.simulation import processed_record_for

    data = task["data"]
    ground_motion = data.get("ground_motion") if isinstance(data, dict) else None
    scale = ground_motion.get("scale") if isinstance(ground_motion, dict) else None
    name = task.get("name", "model")
    if not isinstance(scale, (int, float)) or isinstance(scale, bool):
        return model_from_data(data, name=name, source=task["document"], base_dir=task.get("base_dir")), None
    key = repr((dict(data, ground_motion=dict(ground_motion, scale=None)), task.get("base_dir"), name))
    with _TEMPLATES_LOCK:
        template = _TEMPLATES.get(key)
        if template is not None:
            _TEMPLATES.move_to_end(key)
    if template is None:
        model = model_from_data(data, name=name, source=task["document"], base_dir=task.get("base_dir"))
        if model.has_building_records:
            return model, None
        template = (model, processed_record_for(model, where="yaml"))
        with _TEMPLATES_LOCK:
            _TEMPLATES[key] = template
            while len(_TEMPLATES) > _TEMPLATES_KEPT:
                _TEMPLATES.popitem(last=False)
    model, processed = template
    return model, scale_record(processed, float(scale))


def run_ida_scenario(task: dict[str, Any]) -> dict[str, Any]:
    """One run of an IDA, on a worker: simulate the scaled model and keep its peaks (plain data).

    Never raises for a problem of the scenario: the result then has
    ``status = "error"`` and the message (the run ``failed``).  NaN values
    are stored as None (JSON has no NaN).
    """
    from pounding.simulation import simulate_peaks
    from pounding.studies.sweep.scenario import one_line
    from pounding.studies.sweep.spec import PARTS_FORMAT

    started = time.perf_counter()
    result: dict[str, Any] = {"key": task["key"], "status": "error", "error": "", "study": IDA_PART,
                              "format": PARTS_FORMAT}
    try:
        model, record = _model_and_record(task)
        peaks = simulate_peaks(model, record)   # the peaks of simulate(model), without histories or dataset
        result.update({
            "status": "ok",
            "outcome": peaks["status"],
            "run_status": peaks["status"],
            "collapse_time": _plain(peaks["collapse_time"]),
            "collapse_storey": peaks["collapse_storey"],
            "storeys": {
                "storey": list(peaks["storey"]),
                "building": list(peaks["storey_building"]),
                "peak_drift_ratio": [float(x) for x in peaks["peak_drift_ratio"]],
                "residual_drift_ratio": [_plain(float(x)) for x in peaks["residual_drift_ratio"]],
            },
            "contacts": {
                "contact": list(peaks["contact"]),
                "impact_count": [int(x) for x in peaks["impact_count"]],
                "peak_contact_force": [float(x) for x in peaks["peak_contact_force"]],
            },
            "scale_factor": peaks["record_scale"],
            "solver_wall_time": peaks["wall_time"],
        })
    except Exception as exc:  # noqa: BLE001 - a failing run is a result, not a crash
        result["error"] = f"{task.get('where', 'scenario')}: {one_line(exc)}"
    result["wall_time"] = time.perf_counter() - started
    return result


def run_outcome(part: dict[str, Any] | None) -> str:
    """``completed``, ``collapsed`` or ``failed`` (no result, or an error) of one run's part."""
    if not part or part.get("status") != "ok" or part.get("study") != IDA_PART:
        return "failed"
    return "collapsed" if part.get("outcome") == "collapsed" else "completed"


def _building_drifts(part: dict[str, Any], buildings: list[str]) -> np.ndarray:
    storeys = part["storeys"]
    drift = np.array(storeys["peak_drift_ratio"], dtype=float)
    owner = np.array(storeys["building"], dtype=object)
    return np.array([float(np.max(np.abs(drift[owner == b]))) if np.any(owner == b) else np.nan
                     for b in buildings])


def _collapsed(part: dict[str, Any] | None, plan: IdaPlan, building: str) -> bool | None:
    """Whether *building* collapsed in a run (None if the run failed)."""
    outcome = run_outcome(part)
    if outcome == "failed":
        return None
    if outcome == "collapsed":
        return True
    drift = _building_drifts(part, [building])[0]
    return bool(drift >= plan.collapse_drift)


# --------------------------------------------------------------------------- #
# Hunt-and-fill (sequential per record; records in parallel on dask futures)
# --------------------------------------------------------------------------- #


def next_hunt_level(hunt: Hunt, runs: list[tuple[float, bool]]) -> float | None:
    """The next level (g) of one record's hunt-and-fill, or None when it is done.

    Parameters
    ----------
    hunt : Hunt
    runs : list of (level in g, collapsed)
        The record's runs so far, in the order they ran.

    The answer depends on *runs* alone, so a resumed study replays the same
    sequence and finds the finished runs in its parts store.
    """
    if not runs:
        return round(hunt.start, 6)
    collapses = [s for s, c in runs if c]
    if not collapses:                                    # hunt up
        last = runs[-1][0]
        if last >= hunt.ceiling:
            return None
        k = len(runs) - 1
        return round(min(last + hunt.step + k * hunt.increment, hunt.ceiling), 6)
    high = min(collapses)
    low = max([s for s, c in runs if not c and s < high], default=0.0)
    if high - low > hunt.tolerance * (1 + 1e-9):         # bracket
        middle = round(0.5 * (low + high), 6)
        return middle if low < middle < high else None
    if len(runs) >= hunt.runs:                           # fill
        return None
    points = sorted({0.0} | {s for s, c in runs if not c and s < high})
    gaps = np.diff(points)
    if gaps.size == 0 or gaps.max() <= hunt.tolerance:
        return None
    i = int(np.argmax(gaps))
    return round(0.5 * (points[i] + points[i + 1]), 6)


def run_hunt(plan: IdaPlan, output: str | os.PathLike | None = None, *, workers: int | None = None,
             scheduler: str | None = None, client: Any = None, overwrite: bool = False, keep_parts: bool = False,
             progress: bool = True, retries: int = 2, log: Callable[[str], None] | None = None):
    """Hunt-and-fill on Dask futures: each (variant, record) is a chain of runs, the chains run side by side.

    One future per run: when a run finishes, its part is stored (as in
    :func:`pounding.studies.sweep.execution.run_sweep`: ``OUTPUT.parts/``,
    one atomic JSON file per run) and the chain's next level is submitted at
    once, so a worker is never idle while any chain has work.  A resumed
    study replays every chain through :func:`next_hunt_level` and finds the
    runs already done in the store; only the missing ones run.
    """
    from pounding.results.archive import check_writable, save_run
    from pounding.studies.sweep.execution import check_scheduler_address, sweep_inputs
    from pounding.studies.sweep.store import load_parts, parts_dir, prepare_store, sweep_lock

    say = log or (lambda line: print(line, file=sys.stderr))
    if scheduler and client is None:
        check_scheduler_address(scheduler)
    target = check_writable(output, overwrite=overwrite, inputs=sweep_inputs(plan.sweep)) \
        if output is not None else None
    if target is None:
        return _hunt_locked(plan, None, None, {}, say, workers=workers, scheduler=scheduler, client=client,
                            progress=progress, retries=retries)
    with sweep_lock(target):
        store = prepare_store(parts_dir(target))
        bad: list[str] = []
        done = load_parts(store, bad=bad)
        for message in bad[:5]:
            say(f"pounding: warning: invalid part {message}; its run runs again")
        ds = _hunt_locked(plan, target, store, done, say, workers=workers, scheduler=scheduler, client=client,
                          progress=progress, retries=retries)
        save_run(ds, target, overwrite=overwrite)
        if not keep_parts and not ds.attrs.get("n_lost", 0):
            import shutil

            shutil.rmtree(store, ignore_errors=True)
    return ds


def _hunt_locked(plan: IdaPlan, target, store, done, say, *, workers, scheduler, client, progress, retries):
    import uuid

    from pounding.studies.sweep.execution import Chunk, run_chunk, start_client
    from pounding.studies.sweep.scenario import one_line
    from pounding.studies.sweep.spec import PARTS_FORMAT
    from pounding.studies.sweep.store import save_part

    hunt = plan.hunt
    chains = [(v, r) for v in plan.variants for r in range(len(plan.records))]
    runs: dict[tuple[str, int], list[tuple[float, Any]]] = {c: [] for c in chains}   # (level, scenario)
    results: dict[str, dict[str, Any]] = {}
    lost: set[str] = set()
    reused = 0

    def history(chain) -> list[tuple[float, bool]] | None:
        out = []
        for level, scenario in runs[chain]:
            collapsed = _collapsed(results.get(scenario.key), plan, plan.im.building)
            if collapsed is None:
                return None          # a failed run ends its chain
            out.append((level, collapsed))
        return out

    def advance(chain):
        """The chain's next scenario to run, after replaying the finished ones; None when the chain is done."""
        nonlocal reused
        while True:
            past = history(chain)
            if past is None:
                return None
            level = next_hunt_level(hunt, past)
            if level is None:
                return None
            scenario = plan.scenario(chain[0], chain[1], level)
            runs[chain].append((level, scenario))
            if scenario.error is not None:
                results[scenario.key] = {"key": scenario.key, "status": "error", "error": scenario.error,
                                         "format": PARTS_FORMAT, "study": IDA_PART, "wall_time": 0.0}
                return None
            if scenario.key in done:
                results[scenario.key] = done[scenario.key]
                reused += 1
                continue
            return scenario

    started = time.perf_counter()
    first = [(c, advance(c)) for c in chains]
    first = [(c, s) for c, s in first if s is not None]
    if reused:
        say(f"{reused} runs already done (in {store}); the hunt goes on from there")
    ran = 0
    if first:
        from dask.distributed import as_completed
        from tqdm import tqdm

        own = client is None
        cluster = None
        if own:
            client, cluster = start_client(workers=workers, scheduler=scheduler)
        flying: dict[str, tuple[tuple[str, int], Any]] = {}
        completed = as_completed(loop=client.loop)

        def submit(chain, scenario):
            task = scenario.task(sweep_label=plan.sweep.label, name=plan.model_name)
            key = f"pounding-ida-{scenario.key[:16]}-{uuid.uuid4().hex[:8]}"
            # one run as a Chunk, as the stripes send theirs: Dask does not walk its model document
            future = client.submit(run_chunk, run_ida_scenario, Chunk([task]), key=key, retries=retries, pure=False)
            flying[future.key] = (chain, scenario)
            completed.add(future)

        estimate = len(chains) * hunt.runs
        bar = tqdm(total=estimate, initial=reused, unit="run", desc=plan.sweep.name, file=sys.stderr,
                   disable=not progress, dynamic_ncols=True, smoothing=0.1)
        try:
            for chain, scenario in first:
                submit(chain, scenario)
            for future in completed:
                chain, scenario = flying.pop(future.key)
                try:
                    result = future.result()[0]
                except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after the retries
                    result = {"key": scenario.key, "status": "error", "format": PARTS_FORMAT, "study": IDA_PART,
                              "wall_time": float("nan"),
                              "error": f"{plan.sweep.label}: scenario {scenario.label}: {one_line(exc)}"}
                    lost.add(scenario.key)
                finally:
                    future.release()
                if store is not None and scenario.key not in lost:
                    result["identity"] = scenario.identity
                    save_part(store, result)
                results[scenario.key] = result
                ran += 1
                if bar.n + 1 > bar.total:
                    bar.total = bar.n + 1 + len(flying)
                bar.update(1)
                nxt = advance(chain)
                if nxt is not None:
                    submit(chain, nxt)
        except BaseException:
            for future in list(completed.futures):
                future.cancel()
            raise
        finally:
            bar.close()
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    elapsed = time.perf_counter() - started
    entries = [(chain[0], chain[1], level, scenario.key) for chain in chains for level, scenario in runs[chain]]
    ds = assemble_ida_dataset(plan, results, entries, elapsed=elapsed, ran=ran)
    ds.attrs["n_lost"] = len(lost)
    if lost:
        say(f"{len(lost)} runs could not run (their workers died); the others are kept in {store}: rerun the "
            "same command with --overwrite to retry just those")
    return ds


# --------------------------------------------------------------------------- #
# The study and its dataset
# --------------------------------------------------------------------------- #


def ida_study(plan: IdaPlan, output: str | os.PathLike | None = None, **run_options):
    """Run the IDA of *plan* (stripes on the sweep engine, hunt on futures); returns its dataset.

    *run_options* go to :func:`pounding.studies.sweep.execution.run_sweep`
    or :func:`run_hunt` (workers, scheduler, client, progress, overwrite...).
    """
    from pounding.studies.sweep.execution import run_sweep

    if plan.hunt is not None:
        return run_hunt(plan, output, **run_options)
    scenarios = plan.stripe_scenarios()
    sweep = replace(plan.sweep, _scenarios=scenarios)
    entries = [(v, r, float(level), plan.scenario(v, r, float(level)).key) for v in plan.variants
               for r in range(len(plan.records)) for level in plan.levels]

    def assemble(_sweep, results, *, elapsed=float("nan"), ran=0):
        return assemble_ida_dataset(plan, results, entries, elapsed=elapsed, ran=ran)

    return run_sweep(sweep, output, runner=run_ida_scenario, assemble=assemble, **run_options)


def assemble_ida_dataset(plan: IdaPlan, results: dict[str, dict[str, Any]],
                         entries: list[tuple[str, int, float, str]], *, elapsed: float = float("nan"),
                         ran: int = 0):
    """The IDA's NetCDF layout from per-run results.

    *entries* lists every run as (variant, record index, level in g, key).
    With stripes the ``level`` dimension is the stripes; with a hunt it is
    each record's runs sorted by level (padded with NaN), and ``intensity``,
    ``scale_factor`` and ``level_value`` gain the ``variant`` dimension.
    """
    import xarray as xr

    from pounding import __version__

    variants = list(plan.variants)
    nv, nr, nb = len(variants), len(plan.records), len(plan.buildings)
    stripes = plan.hunt is None
    if stripes:
        slots = {(v, r, float(level)): j for v in variants for r in range(nr) for j, level in enumerate(plan.levels)}
        nl = len(plan.levels)
        run_order = None
    else:
        per_chain: dict[tuple[str, int], list[float]] = {}
        order: dict[tuple[str, int, float], int] = {}
        for v, r, level, _ in entries:
            order[(v, r, level)] = len(per_chain.setdefault((v, r), []))
            per_chain[(v, r)].append(level)
        slots = {}
        for (v, r), levels in per_chain.items():
            for j, level in enumerate(sorted(levels)):
                slots[(v, r, level)] = j
        nl = max((len(x) for x in per_chain.values()), default=0)
        run_order = np.full((nv, nr, nl), -1, np.int32)
    parts = {key: results.get(key) for *_, key in entries}
    first = next((p for p in parts.values() if run_outcome(p) != "failed"), None)
    storeys = first["storeys"]["storey"] if first else []
    storey_building = first["storeys"]["building"] if first else []
    contacts = first["contacts"]["contact"] if first else []
    ns, nc = len(storeys), len(contacts)

    level_value = np.full((nv, nr, nl), np.nan)
    intensity = np.full((nv, nr, nl), np.nan)
    scale_factor = np.full((nv, nr, nl), np.nan)
    max_drift = np.full((nv, nr, nl, nb), np.nan)
    collapsed = np.zeros((nv, nr, nl, nb), np.int8)
    peak_drift = np.full((nv, nr, nl, ns), np.nan)
    residual = np.full((nv, nr, nl, ns), np.nan)
    impacts = np.full((nv, nr, nl, nc), -1, np.int32)
    force = np.full((nv, nr, nl, nc), np.nan)
    status = np.full((nv, nr, nl), "", dtype=object)
    error = np.full((nv, nr, nl), "", dtype=object)
    collapse_time = np.full((nv, nr, nl), np.nan)
    collapse_storey = np.full((nv, nr, nl), "", dtype=object)
    wall = np.full((nv, nr, nl), np.nan)
    for v, r, level, key in entries:
        i, j = variants.index(v), slots[(v, r, level)]
        part = parts[key]
        level_value[i, r, j] = level * STANDARD_GRAVITY
        factor = plan.factor(r, level) if plan.errors[r] is None else float("nan")
        intensity[i, r, j] = plan.intensity(r, level) if plan.errors[r] is None else float("nan")
        scale_factor[i, r, j] = factor
        if run_order is not None:
            run_order[i, r, j] = order[(v, r, level)]
        outcome = run_outcome(part)
        status[i, r, j] = outcome
        if outcome == "failed":
            error[i, r, j] = (part or {}).get("error") or "no result (the worker running it was lost)"
            continue
        wall[i, r, j] = part.get("solver_wall_time", np.nan)
        scale_factor[i, r, j] = part.get("scale_factor", factor)
        max_drift[i, r, j] = _building_drifts(part, plan.buildings)
        collapsed[i, r, j] = [1 if (outcome == "collapsed" or d >= plan.collapse_drift) else 0
                              for d in max_drift[i, r, j]]
        peak_drift[i, r, j] = part["storeys"]["peak_drift_ratio"]
        residual[i, r, j] = [np.nan if x is None else x for x in part["storeys"]["residual_drift_ratio"]]
        impacts[i, r, j] = part["contacts"]["impact_count"]
        force[i, r, j] = part["contacts"]["peak_contact_force"]
        collapse_time[i, r, j] = np.nan if part.get("collapse_time") is None else part["collapse_time"]
        collapse_storey[i, r, j] = part.get("collapse_storey", "")
    status[status == ""] = "not run"

    def var(dims, data, units, long_name, **extra):
        return (dims, data, {"units": units, "long_name": long_name, **extra})

    run = ("variant", "record", "level")
    if stripes:   # the same for both variants: (record, level)
        im_dims, level_values = ("record", "level"), plan.levels * STANDARD_GRAVITY
        intensity_data, factor_data = intensity[0], scale_factor[0]
    else:
        im_dims, level_values = run, np.arange(nl)
        intensity_data, factor_data = intensity, scale_factor
    data_vars = {
        "intensity": var(im_dims, intensity_data, "m s-2",
                         f"{plan.im.describe()} of the scaled record (the IM value reached)"),
        "scale_factor": var(im_dims, factor_data, "1",
                            "factor applied to the record as stored (catalogue or file), after processing"),
        "max_drift_ratio": var(run + ("building",), max_drift, "1",
                               "largest peak storey drift ratio of the building"),
        "peak_drift_ratio": var(run + ("storey",), peak_drift, "1", "peak absolute storey drift ratio"),
        "residual_drift_ratio": var(run + ("storey",), residual, "1",
                                    "residual storey drift ratio at the end of the run (signed; NaN if the run "
                                    "does not report it)"),
        "impact_count": var(run + ("contact",), impacts, "1", "number of impacts (-1: run failed)"),
        "peak_contact_force": var(run + ("contact",), force, "N", "peak contact force"),
        "collapsed": var(run + ("building",), collapsed, "1",
                         "1 if the building collapsed in the run: run status collapsed, or max drift ratio >= "
                         "collapse_drift"),
        "status": (run, status, {"long_name": "completed, collapsed, failed (or not run)"}),
        "error": (run, error, {"long_name": "error message of a failed run"}),
        "collapse_time": var(run, collapse_time, "s", "time at which the solver stopped the run at collapse"),
        "collapse_storey": (run, collapse_storey, {"long_name": "storey that collapsed ('' if none)"}),
        "solver_wall_time": var(run, wall, "s", "solver wall time of the run"),
        "im_stored": var(("record",), plan.im_stored, "m s-2",
                         f"{plan.im.describe()} of the record as stored, after processing"),
        "normalisation_factor": var(("record",), plan.normalisation, "1",
                                    "FEMA P695 normalisation factor NM (1 with per-record scaling)"),
    }
    if not stripes:
        data_vars["level_value"] = var(run, level_value, "m s-2", "the level of each run (the record's own "
                                       "IM with per-record scaling; the set's median with FEMA P695 scaling)")
        data_vars["run_order"] = var(run, run_order, "1", "position of the run in the record's hunt-and-fill "
                                     "sequence (-1: no run)")
    coords = {
        "variant": ("variant", np.array(variants, dtype=object), {"long_name": "with the model's contacts, or "
                                                                  "with the contacts held open"}),
        "record": ("record", np.array(plan.records, dtype=object), {"long_name": "record specification"}),
        "level": ("level", level_values,
                  {"units": "m s-2", "long_name": "intensity level (the set's median IM with FEMA P695 "
                   "scaling, each record's IM otherwise)"} if stripes else
                  {"units": "1", "long_name": "run of a record, in order of level"}),
        "building": ("building", np.array(plan.buildings, dtype=object), {"long_name": "building name"}),
        "storey": ("storey", np.array(storeys, dtype=object), {"long_name": "storey label BUILDING:LEVEL"}),
        "storey_building": ("storey", np.array(storey_building, dtype=object),
                            {"long_name": "building of the storey"}),
        "contact": ("contact", np.array(contacts, dtype=object), {"long_name": "gap element label"}),
        "limit": ("limit", np.array(plan.limits, dtype=float), {"units": "1",
                                                                "long_name": "peak storey drift ratio limit"}),
    }
    ds = xr.Dataset(data_vars, coords=coords, attrs={
        "title": f"pounding IDA: {plan.model_name}",
        "source": f"pounding {__version__}",
        "study": "ida",
        "history": f"{time.strftime('%Y-%m-%d %H:%M:%S')} pounding ida ({'stripes' if stripes else 'hunt-and-fill'}, "
                   f"{nr} records, {len(entries)} runs)",
        "model_path": plan.model_path,
        "im": plan.im.name,
        "im_building": plan.im.building,
        "im_period": plan.im.period,
        "im_damping": SA_DAMPING,
        "im_description": plan.im.describe(),
        "scaling": plan.scaling,
        "method": "stripes" if stripes else "hunt-and-fill",
        "hunt": "" if stripes else (f"start {plan.hunt.start:g} g, step {plan.hunt.step:g} g + k x "
                                    f"{plan.hunt.increment:g} g, tolerance {plan.hunt.tolerance:g} g, "
                                    f"{plan.hunt.runs} runs per record, ceiling {plan.hunt.ceiling:g} g"),
        "collapse_drift": plan.collapse_drift,
        "mce": float("nan") if plan.mce is None else plan.mce,
        "n_runs": len(entries),
        "n_failed": int(sum(run_outcome(p) == "failed" for p in parts.values())),
        "n_run": ran,
        "elapsed_time": elapsed,
        "Conventions": "CF-1.8",
    })
    fragility = ida_fragility(ds)
    names = ["theta", "beta"]
    limits = [limit_label(x) for x in plan.limits] + ["collapse"]
    arrays = {n: np.full((nv, nb, len(limits)), np.nan) for n in names}
    notes = np.full((nv, nb, len(limits)), "", dtype=object)
    for i, v in enumerate(variants):
        for b, name in enumerate(plan.buildings):
            for k, label in enumerate(limits):
                entry = fragility[v][name][label]
                arrays["theta"][i, b, k] = np.nan if entry["theta"] is None else entry["theta"] * STANDARD_GRAVITY
                arrays["beta"][i, b, k] = np.nan if entry["beta"] is None else entry["beta"]
                notes[i, b, k] = entry.get("note", "")
    ds = ds.assign_coords(fragility_limit=("fragility_limit", np.array(limits, dtype=object),
                                           {"long_name": "drift ratio limit as written, or collapse"}))
    ds["fragility_theta"] = (("variant", "building", "fragility_limit"), arrays["theta"],
                             {"units": "m s-2", "long_name": "lognormal fragility median (theta)"})
    ds["fragility_beta"] = (("variant", "building", "fragility_limit"), arrays["beta"],
                            {"units": "1", "long_name": "lognormal fragility dispersion (beta)"})
    ds["fragility_note"] = (("variant", "building", "fragility_limit"), notes,
                            {"long_name": "why a fragility could not be fitted, or how"})
    return ds


# --------------------------------------------------------------------------- #
# Fragility from the dataset
# --------------------------------------------------------------------------- #


def _exceeds(ds, limit: float | None) -> np.ndarray:
    """(variant, record, level, building): 1 exceed, 0 not, NaN failed/not run; limit None = collapse."""
    ok = np.isin(ds.status.values, ("completed", "collapsed"))[..., None]
    collapsed = ds.collapsed.values.astype(bool)
    hit = collapsed if limit is None else (collapsed | (ds.max_drift_ratio.values >= limit))
    return np.where(ok, hit.astype(float), np.nan)


def _crossing(levels: np.ndarray, drift: np.ndarray, hit: np.ndarray, limit: float | None) -> float:
    """The level (g) at which one record's IDA curve first reaches the limit (NaN if never)."""
    good = np.isfinite(hit)
    levels, drift, hit = levels[good], drift[good], hit[good]
    order = np.argsort(levels)
    levels, drift, hit = levels[order], drift[order], hit[order]
    above = np.flatnonzero(hit > 0)
    if above.size == 0:
        return float("nan")
    j = int(above[0])
    low_level = levels[j - 1] if j > 0 else 0.0
    low_drift = drift[j - 1] if j > 0 else 0.0
    if limit is None or not (np.isfinite(drift[j]) and drift[j] >= limit) or drift[j] <= low_drift:
        return float(0.5 * (low_level + levels[j]))
    return float(low_level + (levels[j] - low_level) * (limit - low_drift) / (drift[j] - low_drift))


def ida_fragility(ds) -> dict[str, dict[str, dict[str, dict[str, Any]]]]:
    """Fragility per variant, building and limit (drift limits as written, and ``collapse``); θ in g.

    Each entry: ``theta`` (g), ``beta``, ``method`` and, when no fit was
    possible or records were left out, ``note``.  Stripes: MLE on the
    counts; hunt: from the per-record intensities (see the module docstring).
    """
    from pounding.studies.fragility import fit_intensities, fit_stripes

    stripes = ds.attrs["method"] == "stripes"
    limits = [float(x) for x in ds.limit.values]
    out: dict[str, dict[str, dict[str, dict[str, Any]]]] = {}
    for i, variant in enumerate(ds.variant.values):
        out[str(variant)] = {}
        for b, building in enumerate(ds.building.values):
            entries: dict[str, dict[str, Any]] = {}
            for limit in limits + [None]:
                label = "collapse" if limit is None else limit_label(limit)
                hit = _exceeds(ds, limit)[i, :, :, b]
                entry: dict[str, Any] = {"theta": None, "beta": None}
                try:
                    if stripes:
                        n = np.sum(np.isfinite(hit), axis=0)
                        z = np.nansum(hit, axis=0)
                        fit = fit_stripes(ds.level.values / STANDARD_GRAVITY, n, z)
                        if not (0 < fit.theta < math.inf and fit.beta < MAX_BETA):
                            raise PoundingError(f"the fraction exceeding hardly changes over the stripes (beta "
                                                f"{fit.beta:.3g}): widen the range of levels")
                        entry.update(theta=fit.theta, beta=fit.beta, method="mle-stripes")
                    else:
                        levels = ds.level_value.values[i] / STANDARD_GRAVITY
                        drift = ds.max_drift_ratio.values[i, :, :, b]
                        values = np.array([_crossing(levels[r], drift[r], hit[r], limit)
                                           for r in range(ds.record.size)])
                        finite = values[np.isfinite(values)]
                        if finite.size < values.size:
                            entry["note"] = (f"{values.size - finite.size} of {values.size} records never reached "
                                             "it (or failed) and are left out")
                        fit = fit_intensities(finite)
                        entry.update(theta=fit.theta, beta=fit.beta, method="intensities")
                except PoundingError as exc:
                    entry["note"] = str(exc).replace("fragility fit: ", "")
                entries[label] = entry
            out[str(variant)][str(building)] = entries
    return out


def _finite(value: Any) -> float | None:
    if value is None:
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def ida_summary(ds) -> dict[str, Any]:
    """The study as one JSON-ready document: ``{"im", "fragility", "cmr"}`` (θ and IMs in g)."""
    fragility = {}
    for i, variant in enumerate(ds.variant.values):
        fragility[str(variant)] = {}
        for b, building in enumerate(ds.building.values):
            fragility[str(variant)][str(building)] = {
                str(label): {"theta": _finite(ds.fragility_theta.values[i, b, k] / STANDARD_GRAVITY),
                             "beta": _finite(ds.fragility_beta.values[i, b, k])}
                for k, label in enumerate(ds.fragility_limit.values)}
    im = {"name": ds.attrs["im"], "units": "g", "scaling": ds.attrs["scaling"], "method": ds.attrs["method"]}
    if ds.attrs["im"] == "sa-t1":
        im.update(building=ds.attrs["im_building"], period=float(ds.attrs["im_period"]), damping=SA_DAMPING)
    out: dict[str, Any] = {"im": im, "fragility": fragility}
    mce = float(ds.attrs.get("mce", float("nan")))
    if math.isfinite(mce):
        from pounding.studies.fragility import collapse_margin_ratio

        collapse = list(ds.fragility_limit.values).index("collapse")
        out["cmr"] = {str(v): {str(b): _finite(collapse_margin_ratio(ds.fragility_theta.values[i, k, collapse], mce))
                               for k, b in enumerate(ds.building.values)}
                      for i, v in enumerate(ds.variant.values)}
        out["mce"] = mce / STANDARD_GRAVITY
    failed = {}
    for index in np.ndindex(ds.status.shape):
        if ds.status.values[index] == "failed":
            v, r, j = index
            failed.setdefault(str(ds.error.values[index]), []).append(
                f"{ds.variant.values[v]}, {ds.record.values[r]}, level {j}")
    if failed:
        out["failed"] = failed
    return out


def _g(value: float | None, digits: int = 3) -> str:
    return "-" if value is None or not math.isfinite(value) else f"{value:.{digits}f}"


def ida_table(ds) -> str:
    """The printed summary: θ (g) and β per building, limit and variant, and the change of θ due to pounding."""
    summary = ida_summary(ds)
    status = ds.status.values
    counts = {s: int((status == s).sum()) for s in ("completed", "collapsed", "failed")}
    variants = [str(v) for v in ds.variant.values]
    lines = [f"IDA of {ds.attrs['title'].split(': ', 1)[-1]}: {ds.record.size} records, "
             f"{ds.attrs['method']}, {status.size if ds.attrs['method'] == 'stripes' else ds.attrs['n_runs']} runs "
             f"({counts['completed']} completed, {counts['collapsed']} collapsed, {counts['failed']} failed)",
             f"IM: {ds.attrs['im_description']}, in g; scaling: "
             + ("FEMA P695 (records normalised, the set's median IM at the level)"
                if ds.attrs["scaling"] == "fema-p695" else "each record to the level"),
             f"collapse: run status collapsed, or max storey drift ratio >= {ds.attrs['collapse_drift']:g}",
             "fragility P(exceed | IM) = Phi(ln(IM/theta)/beta), "
             + ("maximum likelihood on the stripe counts" if ds.attrs["method"] == "stripes"
                else "from each record's intensity at the limit")]
    head = f"{'building':<9} {'limit':<9}" + "".join(f" {v + ' theta':>22} {'beta':>6}" for v in variants)
    if len(variants) == 2:
        head += f" {'pounding: theta change':>23}"
    lines.append(head)
    notes = []
    for building in ds.building.values:
        for label in ds.fragility_limit.values:
            row = f"{str(building):<9} {str(label):<9}"
            thetas = []
            for v in variants:
                entry = summary["fragility"][v][str(building)][str(label)]
                thetas.append(entry["theta"])
                row += f" {_g(entry['theta']):>22} {_g(entry['beta'], 2):>6}"
                note = ds.fragility_note.sel(variant=v, building=building, fragility_limit=label).item()
                if note:
                    notes.append(f"  {v}, {building}, {label}: {note}")
            if len(variants) == 2:
                a, b = thetas
                change = "-" if a is None or b is None else f"{100 * (a / b - 1):+.1f} %"
                row += f" {change:>23}"
            lines.append(row)
    if len(variants) == 2:
        lines.append("pounding: theta change = theta with contacts / theta without - 1 (negative: pounding makes "
                     "the limit easier to reach)")
    if "cmr" in summary:
        lines.append(f"collapse margin ratio CMR = theta(collapse) / S_MT, S_MT = {summary['mce']:.3f} g: "
                     + "; ".join(f"{v}: " + ", ".join(f"{b} {_g(x, 2)}" for b, x in summary["cmr"][v].items())
                                 for v in variants))
    if notes:
        lines.append("not fitted or partly fitted:")
        lines += notes
    return "\n".join(lines)


# --------------------------------------------------------------------------- #
# Plots
# --------------------------------------------------------------------------- #


def _curve(ds, i: int, r: int, b: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One record's IDA curve: levels (g, sorted), max drift, collapsed flags (runs that ran)."""
    if ds.attrs["method"] == "stripes":
        levels = ds.level.values / STANDARD_GRAVITY
    else:
        levels = ds.level_value.values[i, r] / STANDARD_GRAVITY
    ok = np.isin(ds.status.values[i, r], ("completed", "collapsed")) & np.isfinite(levels)
    drift = ds.max_drift_ratio.values[i, r, :, b]
    collapsed = ds.collapsed.values[i, r, :, b].astype(bool)
    order = np.argsort(levels[ok])
    return levels[ok][order], drift[ok][order], collapsed[ok][order]


def _im_label(ds) -> str:
    return "PGA" if ds.attrs["im"] == "pga" else f"Sa(T1 of {ds.attrs['im_building']})"


def plot_ida(ds, directory: str | os.PathLike) -> list[Path]:
    """``ida_curves.png`` (IM against max drift ratio per record, median and 16/84 % stripes, per variant) and
    ``fragility.png`` (fitted curves with the stripe fractions as points), per building."""
    from scipy.special import ndtr

    from pounding.results.plots import pyplot

    plt = pyplot()
    out = Path(directory)
    if out.exists() and not out.is_dir():
        raise PoundingError(f"{out} is a file; --plot needs a directory")
    out.mkdir(parents=True, exist_ok=True)
    variants = [str(v) for v in ds.variant.values]
    buildings = [str(b) for b in ds.building.values]
    stripes = ds.attrs["method"] == "stripes"
    collapse_drift = float(ds.attrs["collapse_drift"])
    titles = {"with_contacts": "with contacts (pounding)", "without_contacts": "contacts held open"}
    paths = []

    # IDA curves: one row per building, one column per variant
    fig, axes = plt.subplots(len(buildings), len(variants), figsize=(5.4 * len(variants), 4.2 * len(buildings)),
                             squeeze=False, sharey=True)
    largest = float(np.nanmax(ds.max_drift_ratio.values, initial=0.0))
    top = 115 * collapse_drift if largest >= 0.5 * collapse_drift else 120 * max(largest, 1e-6)
    for b, building in enumerate(buildings):
        for i, variant in enumerate(variants):
            ax = axes[b, i]
            for r in range(ds.record.size):
                levels, drift, collapsed = _curve(ds, i, r, b)
                if levels.size == 0:
                    continue
                shown = np.where(collapsed, top, 100 * np.minimum(drift, top / 100))
                ax.plot(shown, levels, color="0.65", lw=0.8, marker=".", ms=3,
                        label="one record" if r == 0 else None)
                if collapsed.any():
                    ax.plot(shown[collapsed][:1], levels[collapsed][:1], "x", color="C3", ms=6,
                            label="collapse" if r == 0 else None)
            if stripes:
                drift = np.where(ds.collapsed.values[i, :, :, b].astype(bool), np.inf,
                                 ds.max_drift_ratio.values[i, :, :, b])
                ok = np.isin(ds.status.values[i], ("completed", "collapsed"))
                levels = ds.level.values / STANDARD_GRAVITY
                for q, style, name in ((50, "-", "median"), (16, "--", "16 % and 84 %"), (84, "--", None)):
                    values = []
                    for j in range(levels.size):
                        column = drift[ok[:, j], j]
                        values.append(np.percentile(column, q, method="inverted_cdf") if column.size else np.nan)
                    values = np.array(values)
                    keep = np.isfinite(values)
                    ax.plot(100 * values[keep], levels[keep], style, color="k", lw=1.8 if q == 50 else 1.1,
                            label=name)
            ax.axvline(100 * collapse_drift, color="C3", lw=0.8, ls=":", label="collapse drift")
            ax.set_xlim(0, top * 1.02)
            ax.set_ylim(bottom=0)
            ax.set_xlabel(f"max storey drift ratio of {building} (%)")
            ax.set_ylabel(f"{_im_label(ds)} level (g)")
            ax.set_title(f"building {building}, {titles.get(variant, variant)}", fontsize=10)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="lower right")
    fig.suptitle(f"IDA curves, {ds.record.size} records; IM = {ds.attrs['im_description']}", fontsize=10)
    fig.tight_layout()
    path = out / "ida_curves.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    paths.append(path)

    # Fragility curves: one panel per building, a colour per limit, solid with contacts, dashed without
    summary = ida_summary(ds)
    fig, axes = plt.subplots(1, len(buildings), figsize=(5.8 * len(buildings), 5.6), squeeze=False)
    labels = [str(x) for x in ds.fragility_limit.values]
    limits = [float(x) for x in ds.limit.values] + [None]
    if stripes:
        grid_top = float(ds.level.values.max() / STANDARD_GRAVITY) * 1.1
    else:
        grid_top = float(np.nanmax(ds.level_value.values) / STANDARD_GRAVITY) * 1.1
    x = np.linspace(grid_top / 400, grid_top, 400)
    for b, building in enumerate(buildings):
        ax = axes[0, b]
        for k, (label, limit) in enumerate(zip(labels, limits)):
            color = f"C{k}" if limit is not None else "k"
            name = f"{100 * limit:g} %" if limit is not None else "collapse"
            for i, variant in enumerate(variants):
                entry = summary["fragility"][variant][building][label]
                style = "-" if variant == "with_contacts" else "--"
                if entry["theta"] is not None:
                    ax.plot(x, ndtr(np.log(x / entry["theta"]) / entry["beta"]), style, color=color, lw=1.5,
                            label=f"{name}, {'contacts' if variant == 'with_contacts' else 'open'}: "
                                  f"\u03b8 {entry['theta']:.2f} g, \u03b2 {entry['beta']:.2f}")
                if stripes:
                    hit = _exceeds(ds, limit)[i, :, :, b]
                    n = np.sum(np.isfinite(hit), axis=0)
                    with np.errstate(invalid="ignore", divide="ignore"):
                        fraction = np.nansum(hit, axis=0) / n
                    ax.plot(ds.level.values / STANDARD_GRAVITY, fraction, "o", color=color, ms=4,
                            mfc=color if variant == "with_contacts" else "white")
        ax.set_xlim(0, grid_top)
        ax.set_ylim(-0.02, 1.02)
        ax.set_xlabel(f"{_im_label(ds)} (g)")
        ax.set_ylabel("P(exceed | IM)")
        ax.set_title(f"building {building}: max storey drift ratio > limit, or collapse"
                     + ("\npoints: fraction of records at each stripe (filled: with contacts, open: without)"
                        if stripes else "\nsolid: with contacts; dashed: contacts held open"), fontsize=9)
        ax.grid(alpha=0.3)
        handles, names = ax.get_legend_handles_labels()
        if handles:   # below the axes
            ax.legend(handles, names, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
                      frameon=False)
    fig.suptitle(f"fragility, {ds.record.size} records ({ds.attrs['method']})", fontsize=10)
    fig.tight_layout()
    path = out / "fragility.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    paths.append(path)
    return paths


def parse_intensity(text: Any, what: str) -> float:
    """An IM value on the command line, m/s²: a number is in g (``0.9``); or with units (``0.9g``, ``8.8 m/s2``)."""
    from pounding.records.processing import SpecProblem, parse_acceleration

    raw = str(text).strip()
    try:
        value = float(raw) * STANDARD_GRAVITY
    except ValueError:
        try:
            value = parse_acceleration(raw)[0]
        except SpecProblem:
            raise PoundingError(f"{what} {raw!r}: give an intensity in g (0.9) or with units (0.9g, 8.8 m/s2)") \
                from None
    if not (math.isfinite(value) and value > 0):
        raise PoundingError(f"{what} {raw!r}: must be > 0")
    return value
