"""An IDA's inputs and schedule: intensity measure, levels, limits, hunt settings; every record's IM and factor.

The schedule (:class:`IdaPlan`) resolves, before any run, the IM of every
record as the model uses it and the factor that takes it to a level
(``record`` or ``fema-p695`` scaling, see :mod:`pounding.studies.ida`), and
makes the scenario of any (variant, record, level).

A model shaken by two components (floors in plan) runs record *pairs*, each in
both orientations, as FEMA P695 runs its pairs in three-dimensional analyses:

``ab``  component a along the model's ``angle``, b 90° further;
``ba``  the components swapped: b along ``angle``, a 90° further.

Each orientation is a record of the IDA (``PAIR ab`` / ``PAIR ba``; its own
chain of a hunt); both components are scaled by one factor, so the pair keeps
its shape.  A pair's IM is the geometric mean of its components' IMs
(:meth:`IntensityMeasure.of_records`: for Sa(T1) the pair's geometric-mean
spectrum at T1, as FEMA P695 §A.8 normalises and scales record pairs; it does
not depend on the orientation); its FEMA P695 normalisation factor NM is the
pair's (Table A-4C: one per pair, both components carry it).
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import yaml

from pounding.errors import PoundingError
from pounding.model.document import dump_document
from pounding.units import STANDARD_GRAVITY

__all__ = ["VARIANTS", "DEFAULT_LIMITS", "IM_NAMES", "SCALINGS", "MAX_LEVELS", "SA_DAMPING", "LEVEL_DECIMALS",
           "LEVEL_RESOLUTION", "MAX_IDA_RUNS", "IntensityMeasure",
           "Hunt", "IdaPlan", "parse_levels", "parse_limits", "limit_label", "build_ida_plan", "parse_intensity",
           "collapse_drifts", "with_collapse_drift", "check_ida_inputs", "resolve_scaling", "check_run_count",
           "ida_measure", "finish_ida_plan", "ORIENTATIONS", "oriented_document", "ground_records", "normalisation_of"]

#: The two variants of every scenario: the model as given, and with its contacts held open.
VARIANTS = ("with_contacts", "without_contacts")
#: Peak storey drift ratio limits of the fragility functions by default (0.5 %, 1.5 %, 2.5 %).
DEFAULT_LIMITS = (0.005, 0.015, 0.025)
IM_NAMES = ("sa-t1", "pga")
SCALINGS = ("auto", "record", "fema-p695")
#: Most levels of a --levels range (a typo such as 0.1:300:0.1 would ask for 3000 stripes).
MAX_LEVELS = 500
#: Damping ratio of Sa(T1).
SA_DAMPING = 0.05
#: Levels of a hunt are rounded to this many decimals of g (a run's key hashes its level).
LEVEL_DECIMALS = 6
#: The smallest step between two hunt levels, g: a smaller step, increment or tolerance rounds to
#: the same level again and the hunt would repeat it forever.
LEVEL_RESOLUTION = 10.0 ** -LEVEL_DECIMALS
#: Most runs an IDA may plan (records x variants x runs per record); ~0.1-1 s each on one core,
#: 1e5 runs is a day of a small cluster.
MAX_IDA_RUNS = 100_000
#: The two orientations of a record pair: which component acts along the model's ``angle`` (ground_motion x).
ORIENTATIONS = ("ab", "ba")


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
    pair : bool
        True for record pairs (a model shaken by two components): a pair's IM is the geometric mean of its two
        components' IMs (:meth:`of_records`).
    """

    name: str
    building: str
    period: float = float("nan")
    pair: bool = False

    def of(self, record) -> float:
        """The IM of a :class:`pounding.records.record.Record`, m/s²."""
        if self.name == "pga":
            return float(record.pga)
        from pounding.records.spectra import spectral_acceleration

        return spectral_acceleration(record, period=self.period, damping=SA_DAMPING)

    def of_records(self, records) -> float:
        """The IM of a ground motion, m/s²: of one record, its own (:meth:`of`); of a record pair, the geometric
        mean √(IM_a · IM_b) of its two components' (for ``sa-t1`` the pair's geometric-mean spectrum at T1, as
        FEMA P695 §A.8 normalises pairs)."""
        if len(records) == 1:
            return self.of(records[0])
        return math.sqrt(self.of(records[0]) * self.of(records[1]))

    def describe(self) -> str:
        mean = ", geometric mean of the pair" if self.pair else ""
        if self.name == "pga":
            return f"PGA{mean}"
        return f"Sa(T1 = {self.period:.3f} s of building {self.building}, 5 %{mean})"


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
        for flag, value, least in (("--hunt-step", self.step, LEVEL_RESOLUTION),
                                   ("--tolerance", self.tolerance, 2 * LEVEL_RESOLUTION)):
            if value < least:
                raise PoundingError(f"{flag} {value:g} g is below the resolution of the levels ({least:g} g; "
                                    f"levels are rounded to {LEVEL_DECIMALS} decimals): give at least {least:g}")
        if 0 < self.increment < LEVEL_RESOLUTION:
            raise PoundingError(f"--hunt-increment {self.increment:g} g is below the resolution of the levels "
                                f"({LEVEL_RESOLUTION:g} g): give 0 or at least {LEVEL_RESOLUTION:g}")
        per_record = self.max_runs()
        if per_record > MAX_IDA_RUNS:
            raise PoundingError(f"--hunt would make up to {per_record:.3g} runs per record (from {self.start:g} to "
                                f"--hunt-ceiling {self.ceiling:g} g by --hunt-step {self.step:g} g, "
                                f"--hunt-increment {self.increment:g} g); at most {MAX_IDA_RUNS} allowed: lower "
                                "the ceiling or raise the step or increment")

    def climb_runs(self) -> float:
        """Runs of the climb from ``start`` to ``ceiling`` with no collapse (both ends included).

        After j steps the level is ``start + j·step + increment·j(j−1)/2``.
        """
        span = self.ceiling - self.start
        if span <= 0:
            return 1.0
        if self.increment > 0:   # smallest j with j·step + inc·j(j−1)/2 >= span
            b = self.step - 0.5 * self.increment
            j = (-b + math.sqrt(b * b + 2.0 * self.increment * span)) / self.increment
        else:
            j = span / self.step
        return float(math.ceil(j - 1e-9) + 1)

    def max_runs(self) -> float:
        """Most runs of one record's hunt-and-fill: the climb, then the bisections of the widest bracket
        (the last step of the climb, or [0, start]) down to ``tolerance``, or ``runs`` if more (the fill)."""
        climb = self.climb_runs()
        widest = max(self.start, self.step + max(climb - 2, 0) * self.increment)   # [0, start] if it collapses
        bisections = max(0, math.ceil(math.log2(max(widest / self.tolerance, 1.0))))
        return float(max(climb + bisections, self.runs))


def _number(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise PoundingError(f"{what}: '{text}' is not a number") from None
    if not math.isfinite(value):
        raise PoundingError(f"{what}: '{text}' is not a finite number")
    return value


def _level(text: str, what: str) -> float:
    """One ``--levels`` value in g: a number (``0.4``) or an intensity with units as ``--mce`` takes it
    (``0.4g``, ``3.9 m/s2``, ``390 gal``; :func:`parse_intensity`)."""
    try:
        float(text)
    except ValueError:
        return parse_intensity(text, what) / STANDARD_GRAVITY
    return _number(text, what)


def parse_levels(text: str) -> np.ndarray:
    """``--levels``: ``START:STOP:STEP`` (both ends included) or a comma-separated list, in g (or each value with
    units, as ``--mce``: ``0.1g:1.5g:0.1g``, ``1,2,4 m/s2``); sorted, > 0."""
    raw = str(text).strip()
    what = f"--levels {raw!r}"
    if ":" in raw:
        pieces = raw.split(":")
        if len(pieces) != 3:
            raise PoundingError(f"{what}: write START:STOP:STEP in g, e.g. 0.1:3.0:0.1, or a list 0.2,0.4,0.8")
        start, stop, step = (_level(p.strip(), what) for p in pieces)
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
        levels = np.array(sorted({_level(p.strip(), what) for p in items}))
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
    collapse_drift: float              # --collapse-drift, else the largest drift limit (see collapse_drifts)
    levels: np.ndarray | None = None   # g (stripes)
    hunt: Hunt | None = None
    mce: float | None = None           # m/s²
    model_path: str = ""
    model_name: str = ""
    errors: list[str | None] = field(default_factory=list)   # per record: why it cannot run (or None)
    #: Per building: its collapse drift ratio in this study (:func:`collapse_drifts`) and where it comes from.
    collapse_drifts: tuple[float, ...] = ()
    collapse_sources: tuple[str, ...] = ()
    #: Record pairs only: per record (a pair in one orientation) its two components, the one along the model's
    #: ``angle`` first (ground_motion x) and the one 90° further (y); empty when each record is one component.
    pairs: tuple[tuple[str, str], ...] = ()
    #: The buildings whose collapse a hunt brackets, in model order (empty: every building); ``pounding p695``
    #: hunts only the building of each IDA.
    hunted: tuple[str, ...] = ()
    #: The records' plausibility warnings (``units``: their own PGA in their declared units), each kind once.
    warnings: tuple[str, ...] = ()
    _cache: dict = field(default_factory=dict, repr=False)

    def describe_levels(self) -> str:
        """The intensities in words: ``at 0.5, 1.5 g (...)``, ``at 15 stripes 0.1-1.5 g (...)``, ``hunted from ...``."""
        how = "the set's median, FEMA P695 scaling" if self.scaling == "fema-p695" else "each record scaled to it"
        if self.hunt is not None:
            return f"hunted from {self.hunt.start:g} g up to {self.hunt.ceiling:g} g ({how})"
        levels = [float(x) for x in self.levels]
        shown = ", ".join(f"{x:g}" for x in levels) if len(levels) <= 4 else \
            f"{len(levels)} stripes {min(levels):g}-{max(levels):g}"
        return f"at {shown} g ({how})"

    def __repr__(self) -> str:
        return (f"<IdaPlan of model '{self.model_name}': {len(self.records)} records x "
                + (f"{len(self.levels)} levels" if self.hunt is None else "hunt-and-fill")
                + f" x {len(self.variants)} variant{'s' if len(self.variants) != 1 else ''} = "
                f"{'up to ' if self.hunt is not None else ''}{self.planned_runs()} runs; "
                f"{self.im.describe()} {self.describe_levels()}>")

    def factor(self, record: int, level_g: float) -> float:
        """The factor on record *record* (as stored) at level *level_g* (g)."""
        return float(level_g * STANDARD_GRAVITY * self.unit_factor[record])

    def intensity(self, record: int, level_g: float) -> float:
        """Record *record*'s own IM at level *level_g*, m/s²."""
        return float(self.factor(record, level_g) * self.im_stored[record])

    def scenario(self, variant: str, record: int, level_g: float):
        """The :class:`~pounding.studies.engine.tasks.Scenario` of one run (cached)."""
        from pounding.studies.engine.keys import code_fingerprint, content_key, record_fingerprint, scenario_key
        from pounding.studies.engine.tasks import Scenario

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
            specs = self.pairs[record] if self.pairs else (self.records[record],)
            fingerprint = self._cache[("record", record)] = "|".join(record_fingerprint(spec, base_dir)
                                                                    for spec in specs)
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
        ``ground_motion`` mapping; nothing changes a scenario's data after it is made.  A record pair is
        written as components ``x`` and ``y``, each with the factor as its ``scale`` (:func:`_scaled_ground`).
        """
        from pounding.model.model import hold_contacts_open

        template = self._cache.get(("template", variant, record))
        if template is None:
            base = copy.deepcopy(self.documents[record])
            if variant == "without_contacts":
                hold_contacts_open(base)
            base["ground_motion"] = _scaled_ground(base["ground_motion"], _SCALE_PLACEHOLDER)
            pieces = dump_document(base).split(_yaml_scalar(_SCALE_PLACEHOLDER))
            template = (base, pieces)
            self._cache[("template", variant, record)] = template
        base, pieces = template
        document = dict(base)
        document["ground_motion"] = _scaled_ground(base["ground_motion"], factor)
        if len(pieces) != 1 + len(_scaled_parts(base["ground_motion"])):   # the placeholder is elsewhere: dump it all
            return document, dump_document(document)
        return document, _yaml_scalar(factor).join(pieces)

    def planned_runs(self) -> int:
        """The most runs this IDA will make (a hunt may stop a record's chain earlier)."""
        per_record = self.hunt.max_runs() if self.hunt is not None else len(self.levels)
        return int(len(self.records) * len(self.variants) * per_record)

    def stripe_scenarios(self) -> list:
        """Every (variant, record, level) of the fixed stripes, variant slowest."""
        return [self.scenario(v, r, float(level)) for v in self.variants for r in range(len(self.records))
                for level in self.levels]


def _scaled_parts(ground: dict) -> list[str]:
    """Where a ``ground_motion`` mapping's factor goes: its components ``x`` and ``y`` (a record pair given one
    by one: both scaled alike), else its ``scale``."""
    return [k for k in ("x", "y") if isinstance(ground.get(k), dict)] or ["scale"]


def _scaled_ground(ground: dict, factor: float) -> dict:
    """A copy of a ``ground_motion`` mapping with its record (or both components of its pair) scaled by *factor*."""
    parts = _scaled_parts(ground)
    if parts == ["scale"]:
        return dict(ground, scale=factor)
    return dict(ground, **{k: dict(ground[k], scale=factor) for k in parts})


def check_ida_inputs(im: str, scaling: str, levels: Any, hunt: Hunt | None, limits: Any,
                     collapse_drift: float | None, mce: float | None,
                     duration: float | None) -> tuple[np.ndarray | None, tuple[float, ...], float]:
    """Check an IDA's options (one line each; :func:`build_ida_plan` has them):
    ``(levels in g or None, drift limits, collapse drift ratio)``."""
    from pounding.studies.common import check_duration

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
    check_duration(duration)
    return levels, drift_limits, float(collapse_drift)


def resolve_scaling(scaling: str, im_stored: np.ndarray, normalisation: np.ndarray,
                    errors: list[str | None]) -> tuple[str, np.ndarray, np.ndarray]:
    """``(scaling, normalisation, unit factor)`` of every record (module docstring of :mod:`pounding.studies.ida`):
    *scaling* ``auto`` resolved, NM_i (1 with per-record scaling), the factor taking record i to level 1 m/s²."""
    if all(e is not None for e in errors):
        raise PoundingError(f"no record can be read: {errors[0]}")
    readable = np.array([e is None for e in errors])
    fema = bool(np.all(np.isfinite(normalisation[readable])))
    if scaling == "auto":
        scaling = "fema-p695" if fema else "record"
    if scaling == "fema-p695":
        if not fema:
            raise PoundingError("--scaling fema-p695 needs FEMA P695 records (fema-p695:farfield, "
                                "fema-p695:nearfield); use --scaling record")
        median = float(np.median(normalisation[readable] * im_stored[readable]))
        return scaling, normalisation, normalisation / median
    return scaling, np.ones_like(im_stored), 1.0 / im_stored


def check_run_count(records: int, variants: int, levels: np.ndarray | None, hunt: Hunt | None) -> None:
    """Refuse an IDA of more than :data:`MAX_IDA_RUNS` runs, with the count."""
    runs = records * variants * (hunt.max_runs() if hunt is not None else len(levels))
    if runs > MAX_IDA_RUNS:
        raise PoundingError(f"this IDA would make up to {runs:.3g} runs ({records} records x {variants} "
                            f"variant(s) x {runs / records / variants:.3g} per record); at most "
                            f"{MAX_IDA_RUNS} allowed: use fewer records, levels or --runs-per-record")


def ida_measure(model, im: str, building: str | None, *, pair: bool = False) -> IntensityMeasure:
    """The IDA's IM on *model* (planar or plan): T1 the first period of *building* (default: the first
    building; an unknown name is refused in one line)."""
    names = [b.name for b in model.buildings]
    if building is None:
        building = names[0]
    elif building not in names:
        raise PoundingError(f"--building {building!r}: the model has buildings {', '.join(names)}")
    period = float(model.buildings[names.index(building)].periods[0]) if im == "sa-t1" else float("nan")
    return IntensityMeasure(im, building, period, pair=pair)


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
        Every building's collapse drift ratio in this study: written into every run's model (so the run
        ends there) over the buildings' own ``collapse`` and ``solver.stop_drift_ratio``
        (:func:`collapse_drifts`).
    mce : float, optional
        S_MT, m/s², for the collapse margin ratio.
    scaling : str
        ``auto``, ``record`` or ``fema-p695`` (see the module docstring).
    duration : float, optional
        Simulated time of every run, s.
    """
    from pounding.model.model import load_model
    from pounding.results.checks import study_warnings
    from pounding.studies.common import record_sweep

    override = collapse_drift
    levels, drift_limits, collapse_drift = check_ida_inputs(im, scaling, levels, hunt, limits, collapse_drift, mce,
                                                            duration)

    base = load_model(model)   # the model's own errors, with its file name
    base.refuse_building_records("pounding ida (it scales one record)")
    pair = base.ground_motion.record_pairs
    measure = ida_measure(base, im, building, pair=pair)
    if without_contacts and not base.gaps:
        raise PoundingError(f"{os.fspath(model)}: --without-contacts needs a model with contacts")
    if pair and records is None and base.ground_motion.record is None:
        raise PoundingError(f"{os.fspath(model)}: its ground motion is given as components x and y; pounding ida "
                            "runs record pairs, each in both orientations: give --records fema-p695:farfield (or "
                            "pairs such as fema-p695:farfield/1,fema-p695:farfield/2)")

    settings: dict[str, Any] = {"name": f"{base.name} (IDA)", "ground_motion.scale": 1.0}
    if duration is not None:
        settings["ground_motion.duration"] = float(duration)
    sweep = record_sweep(model, base, "ida", settings, records, f"<ida {os.fspath(model)}>")
    scenarios = sweep.scenarios()
    if not scenarios:
        raise PoundingError("--records: the record set is empty")
    labels, documents, components, stored, norm, errors, checked = [], [], [], [], [], [], []
    for s in scenarios:
        record = str(s.coords["record"])
        value, nm, error = _record_measure(s, record, base.name, measure, sweep.label, checked)
        for orientation in (ORIENTATIONS if pair else (None,)):
            document = s.data if orientation is None else oriented_document(s.data, record, orientation)
            documents.append(document if override is None else with_collapse_drift(document, float(override)))
            labels.append(record if orientation is None else f"{record} {orientation}")
            if orientation is not None:
                components.append((document["ground_motion"]["x"]["record"], document["ground_motion"]["y"]["record"]))
            stored.append(value)
            norm.append(nm)
            errors.append(error)
    plan = finish_ida_plan(base, sweep, labels, documents, measure, stored, norm, errors, scaling=scaling,
                           without_contacts=without_contacts, limits=drift_limits, collapse_drift=collapse_drift,
                           override=override, levels=levels, hunt=hunt, mce=mce, path=os.path.abspath(os.fspath(model)),
                           pairs=tuple(components))
    plan.warnings = tuple(study_warnings(checked, "records"))   # the records' units, each kind once (pounding.results.checks)
    return plan


def oriented_document(document: dict, pair: str, orientation: str) -> dict:
    """A copy of a model *document* shaken by the record *pair* in *orientation*: components ``x`` (along the
    model's ``angle``) and ``y`` (90° further), each at scale 1 (the IDA writes its factor into both)."""
    from pounding.model.ground import pair_components

    out = copy.deepcopy(document)
    ground = out.setdefault("ground_motion", {})
    a, b = pair_components(pair)
    first, second = (a, b) if orientation == "ab" else (b, a)
    for key in ("record", "scale", "x", "y", "units", "dt"):
        ground.pop(key, None)
    ground["x"] = {"record": first, "scale": 1.0}
    ground["y"] = {"record": second, "scale": 1.0}
    return out


def ground_records(model) -> list:
    """The record(s) of *model*'s ground motion as it runs them: one record read and processed
    (:func:`pounding.simulation.record_for`), or a pair's two components (:func:`pounding.simulation.component_records`)."""
    from pounding.simulation import component_records, record_for

    if model.ground_motion.two_components:
        return [r for r in component_records(model) if r is not None]
    return [record_for(model)]


def normalisation_of(records: list) -> float:
    """The FEMA P695 normalisation factor NM of a ground motion: its record's, or its pair's (both components
    carry the pair's, FEMA P695 Table A-4C); NaN if there is none (not FEMA P695 records)."""
    values = [r.metadata.get("normalization_factor") for r in records]
    if all(isinstance(x, (int, float)) and x > 0 for x in values) and len(set(values)) == 1:
        return float(values[0])
    return float("nan")


def _record_measure(scenario, record: str, name: str, measure: IntensityMeasure,
                    label: str, checked: list) -> tuple[float, float, str | None]:
    """``(IM as stored m/s², NM, error)`` of one record (pair) of the IDA's sweep (an error: NaN, NaN, the line);
    its records' ``units`` warning (:func:`pounding.results.checks.ground_motion_warnings`) appended to *checked*."""
    from pounding.model.model import model_from_data, model_from_text
    from pounding.model.document import dump_document
    from pounding.results.checks import ground_motion_warnings

    what = "record pair" if measure.pair else "record"
    try:
        if scenario.error is not None:
            raise PoundingError(scenario.error)
        if measure.pair:   # the orientation does not change the pair's IM (a geometric mean) nor its NM
            one = model_from_text(dump_document(oriented_document(scenario.data, record, "ab")), name=name,
                                  base_dir=scenario.base_dir)
        else:
            one = model_from_data(scenario.data, name=name, source=scenario.document, base_dir=scenario.base_dir)
        records = ground_records(one)
        checked.append(ground_motion_warnings(record, records, ida=True))
        value = measure.of_records(records)
        if not value > 0:
            raise PoundingError(f"{what} {record}: its {measure.describe()} is 0; it cannot be scaled")
        return value, normalisation_of(records), None
    except PoundingError as exc:
        return float("nan"), float("nan"), f"{label}: {what} {record}: {' '.join(str(exc).split())}"


def finish_ida_plan(base, sweep, records: list[str], documents: list[dict], measure: IntensityMeasure,
                    stored: list[float], norm: list[float], errors: list[str | None], *, scaling: str,
                    without_contacts: bool, limits: tuple[float, ...], collapse_drift: float,
                    override: float | None, levels: np.ndarray | None, hunt: Hunt | None, mce: float | None,
                    path: str, pairs: tuple[tuple[str, str], ...] = ()) -> IdaPlan:
    """The :class:`IdaPlan` of checked inputs and every record's IM as stored (*stored*, m/s²), FEMA P695 NM
    (*norm*, NaN if none) and error: the scaling resolved (:func:`resolve_scaling`), the run count checked,
    each building's collapse drift ratio (*override*: ``--collapse-drift``)."""
    im_stored = np.array(stored)
    scaling, normalisation, unit = resolve_scaling(scaling, im_stored, np.array(norm), errors)
    variants = VARIANTS if without_contacts else VARIANTS[:1]
    check_run_count(len(records), len(variants), levels, hunt)
    return IdaPlan(sweep=sweep, records=records, documents=documents, im=measure, im_stored=im_stored,
                   normalisation=normalisation, unit_factor=unit, scaling=scaling, buildings=[b.name for b in
                                                                                               base.buildings],
                   variants=variants, limits=limits, collapse_drift=float(collapse_drift), levels=levels,
                   hunt=hunt, mce=mce, model_path=path, model_name=base.name, errors=errors, pairs=pairs,
                   **dict(zip(("collapse_drifts", "collapse_sources"), collapse_drifts(base, override, max(limits)))))


def with_collapse_drift(document: dict, drift_ratio: float) -> dict:
    """A copy of the model *document* (plain data) with every building's ``collapse: {drift_ratio}`` set."""
    out = copy.deepcopy(document)
    for building in out.get("buildings", []):
        if isinstance(building, dict):
            building["collapse"] = {"drift_ratio": drift_ratio}
    return out


def collapse_drifts(model, override: float | None, fallback: float) -> tuple[tuple[float, ...], tuple[str, ...]]:
    """Each building's collapse drift ratio in an IDA and its source, by precedence: ``--collapse-drift``
    (*override*; the runs end there), the building's ``collapse: {drift_ratio}``, ``solver.stop_drift_ratio``
    (both end the run there too), else *fallback*, the largest drift limit, applied to the peaks after
    the run (the run does not end there, so it censors no other building)."""
    if override is not None:
        return (float(override),) * len(model.buildings), ("--collapse-drift",) * len(model.buildings)
    values, sources = [], []
    for b, ratio in zip(model.buildings, model.collapse_drift_ratios()):
        values.append(float(fallback if ratio is None else ratio))
        sources.append("largest drift limit (peaks, after the run)" if ratio is None else
                       "building collapse.drift_ratio" if b.collapse_drift_ratio is not None else
                       "solver.stop_drift_ratio")
    return tuple(values), tuple(sources)


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
