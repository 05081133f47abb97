"""Run a model under a record: assemble flat arrays, integrate, label the result.

This is the one place that joins the stages of the data flow:
:mod:`pounding.model` (YAML → buildings and gap elements) →
:mod:`pounding.records` (record) → :mod:`pounding.solver` (compiled
integration) → :mod:`pounding.results` (xarray Dataset).  :func:`rerun`
repeats what an archive recorded.
"""

from __future__ import annotations

import json
import math
import os
import time as _time
import dataclasses
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from pounding import hysteresis
from pounding.contact import laws as contact_laws
from pounding.errors import PoundingError
from pounding.errors import RecordError
from pounding.memory import MEMORY_FRACTION, available_memory, check_memory
from pounding.records.catalogue import is_catalogue_name
from pounding.records.readers import FIXES, declared_in_header
from pounding.records.record import Record
from pounding.records.load import CATALOGUE_REFERENCE, load_record
from pounding.model.model import WALL, Model, column_weights, model_from_text
from pounding.model.scales import check_work
from pounding.results.archive import check_archive, open_run
from pounding.results.dataset import run_peaks, to_dataset
from pounding.solver.integrator import STATUS_COLLAPSED, STATUS_MESSAGES, STATUS_OK, System, integrate

__all__ = ["assemble", "contact_side_terms", "simulate", "simulate_peaks", "record_for", "processed_record_for",
           "support_motions", "SupportMotions", "rerun", "record_path", "ENERGY_CLOSURE_LIMIT", "MEMORY_FRACTION",
           "estimate_memory", "available_memory", "check_memory", "model_inputs"]

#: Energy closure error above which a run is flagged (attribute ``status``, summary
#: line): converged runs of the shipped models close to ~1e-6, so 1e-3 is a
#: thousand-fold margin and marks a run whose energies (and likely peaks) are wrong.
ENERGY_CLOSURE_LIMIT = 1e-3



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


def assemble(model: Model, building_ground: Any = None) -> System:
    """Flatten a model into the arrays the compiled integrator works on.

    Floors of all buildings are concatenated left to right.  Rayleigh damping
    stays tridiagonal (``a0·M + a1·K`` acts storey by storey); modal damping
    is stored as one dense block per building.  *building_ground* gives, per
    building, its row of the ground-acceleration array (default: one common
    ground, row 0); each gap element's two sides take the rows of their
    buildings (``System.contact_ground_left/right``): the place where a new
    kind of contact (a wall, a link) says which ground moves each of its ends.
    """
    rows = [0] * len(model.buildings) if building_ground is None else [int(r) for r in building_ground]
    masses, stiffness, below, a0, a1 = [], [], [], [], []
    dense_start, dense_size, dense_offset, dense_values = [], [], [], []
    offset = 0
    dense_used = 0
    for building in model.buildings:
        n = building.n_floors
        masses.append(building.mass)
        stiffness.append(building.stiffness)
        below.append(np.r_[-1, np.arange(offset, offset + n - 1)])
        if building.damping.kind == "rayleigh":
            c_mass, c_stiff = building.rayleigh_coefficients
            a0.append(np.full(n, c_mass))
            a1.append(np.full(n, c_stiff))
            dense_start.append(offset)
            dense_size.append(0)
            dense_offset.append(dense_used)
        else:
            a0.append(np.zeros(n))
            a1.append(np.zeros(n))
            block = np.asarray(building.damping_matrix(), dtype=float)
            dense_start.append(offset)
            dense_size.append(n)
            dense_offset.append(dense_used)
            dense_values.append(block.ravel())
            dense_used += n * n
        offset += n

    models, parameters, heights, p_delta = [], [], [], []
    for building in model.buildings:
        for law, k, h in zip(building.hysteresis, building.stiffness, building.height):
            models.append(hysteresis.MODEL_ELASTIC if law is None else law.model_id)
            parameters.append(np.zeros(hysteresis.N_HYSTERESIS_PARAMETERS) if law is None
                              else law.kernel_parameters(k, h))
        heights.append(building.height)
        p_delta.append(building.p_delta_stiffness)
    yielding = np.asarray(models, dtype=np.int64) != hysteresis.MODEL_ELASTIC
    storey_state = np.where(yielding, np.cumsum(yielding) - 1, -1).astype(np.int64)

    left, right, gaps, laws, params, floors, weights, ground_left, ground_right = [], [], [], [], [], [], [], [], []
    mass_all = np.concatenate(masses)
    for gap in model.gaps:
        terms_left = contact_side_terms(model, gap.left, gap.level_left, gap.at_left)
        terms_right = contact_side_terms(model, gap.right, gap.level_right, gap.at_right)
        left.append(terms_left[-1][0] if terms_left[-1][1] != 0.0 else terms_left[0][0])
        right.append(terms_right[-1][0] if terms_right[-1][1] != 0.0 else terms_right[0][0])
        floors.append([f for f, _ in terms_left] + [f for f, _ in terms_right])
        weights.append([w for _, w in terms_left] + [-w for _, w in terms_right])
        # Each side moves with its building's ground (a column point too); a wall moves with the ground of the
        # building it faces (docs/physics.md §11), so a wall contact sees no differential ground motion.
        ground_left.append(rows[gap.right if gap.left == WALL else gap.left])
        ground_right.append(rows[gap.left if gap.right == WALL else gap.right])
        gaps.append(gap.gap)
        laws.append(gap.law.law_id)
        params.append(gap.law.kernel_parameters(_side_mass(terms_left, mass_all), _side_mass(terms_right, mass_all)))
    # Links follow the contacts in the same arrays: elements engaged from the start, gap 0, never open.
    for link in model.links:
        lf = model.floor_offset(link.left) + link.level_left - 1
        rf = model.floor_offset(link.right) + link.level_right - 1
        left.append(lf)
        right.append(rf)
        floors.append([lf, -1, rf, -1])
        weights.append([1.0, 0.0, -1.0, 0.0])
        ground_left.append(rows[link.left])     # a link's ends move with their own buildings' grounds
        ground_right.append(rows[link.right])
        gaps.append(0.0)
        laws.append(link.law.law_id)
        params.append(link.law.kernel_parameters())

    return System(
        mass=np.ascontiguousarray(mass_all, dtype=float),
        storey_stiffness=np.ascontiguousarray(np.concatenate(stiffness), dtype=float),
        below=np.ascontiguousarray(np.concatenate(below), dtype=np.int64),
        rayleigh_mass=np.ascontiguousarray(np.concatenate(a0), dtype=float),
        rayleigh_stiffness=np.ascontiguousarray(np.concatenate(a1), dtype=float),
        dense_start=np.asarray(dense_start, dtype=np.int64),
        dense_size=np.asarray(dense_size, dtype=np.int64),
        dense_offset=np.asarray(dense_offset, dtype=np.int64),
        dense_values=np.ascontiguousarray(np.concatenate(dense_values) if dense_values else np.zeros(0)),
        contact_left=np.asarray(left, dtype=np.int64),
        contact_right=np.asarray(right, dtype=np.int64),
        contact_gap=np.asarray(gaps, dtype=float),
        contact_law=np.asarray(laws, dtype=np.int64),
        contact_parameters=np.ascontiguousarray(
            np.array(params, dtype=float).reshape(len(params), contact_laws.N_PARAMETERS)),
        storey_model=np.asarray(models, dtype=np.int64),
        storey_parameters=np.ascontiguousarray(np.array(parameters, dtype=float)),
        storey_state=storey_state,
        p_delta_stiffness=np.ascontiguousarray(np.concatenate(p_delta), dtype=float),
        storey_height=np.ascontiguousarray(np.concatenate(heights), dtype=float),
        stop_drift_ratio=float(model.solver.stop_drift_ratio or 0.0),
        floor_ground=np.repeat(np.asarray(rows, dtype=np.int64), [b.n_floors for b in model.buildings]),
        contact_ground_left=np.asarray(ground_left, dtype=np.int64),
        contact_ground_right=np.asarray(ground_right, dtype=np.int64),
        contact_floors=np.ascontiguousarray(np.array(floors, dtype=np.int64).reshape(len(floors), 4)),
        contact_weights=np.ascontiguousarray(np.array(weights, dtype=float).reshape(len(weights), 4)),
    )


def contact_side_terms(model: Model, building: int, level: int, at: float | None) -> list[tuple[int, float]]:
    """The two ``(floor index, weight)`` terms of one contact side (floor index −1: ground or wall, weight 0).

    A floor is ``[(floor, 1), (−1, 0)]``; a wall ``[(−1, 0), (−1, 0)]``; a point
    at fraction *at* of storey *level*'s column ``[(floor below, N1), (floor
    above, N2)]`` with the Hermite shape functions of
    :func:`pounding.model.model.column_weights` (the floor below of storey 1
    is the ground: its term has floor −1).
    """
    if building == WALL:
        return [(-1, 0.0), (-1, 0.0)]
    offset = model.floor_offset(building)
    if at is None:
        return [(offset + level - 1, 1.0), (-1, 0.0)]
    n1, n2 = column_weights(at)
    below = offset + level - 2 if level > 1 else -1
    return [(below, n1 if below >= 0 else 0.0), (offset + level - 1, n2)]


def _side_mass(terms: list[tuple[int, float]], mass: np.ndarray) -> float:
    """Generalised mass of a contact side, kg: ``1/Σ w²/m`` (a floor: its mass; a wall: inf)."""
    compliance = sum(w * w / mass[f] for f, w in terms if f >= 0 and w != 0.0)
    return 1.0 / compliance if compliance > 0.0 else float("inf")


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
    record = load_record(spec.record, base_dir=spec.base_dir, dt=spec.dt, units=spec.units, where=where)
    return process(record, spec.processing)


@dataclass(frozen=True)
class SupportMotions:
    """The ground motion under every building, on one time grid.

    Attributes
    ----------
    rows : (G, ns) ndarray
        Ground accelerations, m/s², one row per distinct ground (G = 1 when
        every building sees the same motion at the same time).
    time_step : float
        Their common sampling interval, s.
    building_row : tuple of int
        Row of each building, left to right.
    records : tuple of Record
        The record under each building (scaled and processed; before any lag or resampling).
    lag_requested, lag : tuple of float
        Per building: the wave-passage lag asked for, ``(d_b − min d)/c`` (s), and the
        one applied, rounded to the record step (0 without wave passage).
    end_time : float
        Default simulated time, s: the longest record plus its lag.
    """

    rows: np.ndarray
    time_step: float
    building_row: tuple
    records: tuple
    lag_requested: tuple
    lag: tuple
    end_time: float


def _common_step(records: list[Record], names: list[str]) -> float:
    """The finest time step of *records*; every other must be a whole multiple of it (else one line)."""
    finest = min(r.time_step for r in records)
    for record, name in zip(records, names):
        ratio = record.time_step / finest
        if abs(ratio - round(ratio)) > 1e-6 * ratio:
            raise PoundingError(f"the records under the buildings have time steps {finest:g} s and "
                                f"{record.time_step:g} s (building {name}), not whole multiples of one another; "
                                "resample one record to the other's step")
    return finest


def _on_step(record: Record, step: float) -> np.ndarray:
    """*record*'s acceleration sampled every *step* s (a whole fraction of its own): exact for piecewise-linear data."""
    ratio = int(round(record.time_step / step))
    if ratio == 1:
        return np.asarray(record.acceleration, dtype=float)
    fine = np.arange((record.acceleration.size - 1) * ratio + 1) * step
    return np.interp(fine, record.time, record.acceleration)


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
    if model.has_building_records:
        if record is None:
            records = [record_for(model, building=i, where=where) for i in range(len(names))]
        elif isinstance(record, (list, tuple)) and len(record) == len(names):
            records = list(record)
        else:
            raise PoundingError(f"model '{model.name}' gives each building its own record: pass one Record per "
                                f"building ({len(names)}), or none to use the model's")
        step = _common_step(records, names)
        series = [_on_step(r, step) for r in records]
        lag_requested = lags = [0.0] * len(names)
        ends = [(model.ground_motion_of(i).duration or r.duration) for i, r in enumerate(records)]
    else:
        motion = record if isinstance(record, Record) else record_for(model, where=where)
        step = motion.time_step
        spec = model.ground_motion
        lag_requested = [spec.lag(name) for name in names]
        _check_lags(model, lag_requested, step, motion.acceleration.size)
        shifts = [int(round(lag / step)) for lag in lag_requested]
        lags = [k * step for k in shifts]
        base = np.asarray(motion.acceleration, dtype=float)
        series = [np.concatenate([np.zeros(k), base]) if k else base for k in shifts]
        records = [motion] * len(names)
        ends = [(spec.duration or motion.duration + max(lags))] * len(names)
    distinct: list[np.ndarray] = []
    building_row = []
    for values in series:
        for row, known in enumerate(distinct):
            if known.size == values.size and np.array_equal(known, values):
                building_row.append(row)
                break
        else:
            building_row.append(len(distinct))
            distinct.append(values)
    size = max(v.size for v in distinct)
    rows = np.zeros((len(distinct), size))
    for row, values in enumerate(distinct):
        rows[row, :values.size] = values
    return SupportMotions(rows, float(step), tuple(building_row), tuple(records), tuple(lag_requested),
                          tuple(lags), float(max(ends)))


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
             record_dt: float | None = None, where: str = "api") -> xr.Dataset:
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
    where : str
        ``api`` or ``cli``: how an error about a record given here says to
        fix it (``record_units=`` or ``--units``).

    Returns
    -------
    xarray.Dataset
        The results schema documented in the README (``pounding.results``).
    """
    _check_modes_memory(model)
    if xi is not None:
        model = model.with_xi(xi)
    changes = {k: v for k, v in dict(rtol=rtol, atol=atol, atol_velocity=atol_velocity,
                                     output_dt=output_dt).items() if v is not None}
    if changes:
        model = model.with_solver(**changes)
    gm_changes: dict[str, Any] = {}
    if isinstance(record, str):
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
        gm_changes.update(record=spec, units=record_units, dt=record_dt)
    elif record_units is not None or record_dt is not None:
        raise PoundingError("record_units and record_dt apply only to a record file given as record=")
    if scale is not None:
        gm_changes["scale"] = scale
    if duration is not None:
        gm_changes["duration"] = duration
    if gm_changes:
        model = model.with_ground_motion(**gm_changes)

    if isinstance(record, Record):
        model.refuse_building_records("a record given to simulate()")
        supports = support_motions(model, record if scale is None else record.scaled(scale / record.scale))
    elif isinstance(record, (list, tuple)):
        supports = support_motions(model, list(record))
    else:
        supports = support_motions(model, where=where if isinstance(record, str) else "yaml")
    motion = supports.records[0]
    end_time = supports.end_time
    if end_time <= 0.0:
        raise PoundingError(f"record {motion.name}: duration must be > 0 (got {end_time} s)")

    settings = model.solver
    if settings.output_dt > end_time:
        raise PoundingError(f"{_where(model)}solver.output_dt is {settings.output_dt:g} s, longer than the simulated "
                            f"{end_time:g} s: no history (and no energy balance) would be stored; use an output_dt "
                            f"well below the duration, e.g. {min(0.01, end_time / 100):g} s")
    step = supports.time_step
    check_memory(estimate_memory(model, end_time, step, settings.output_dt) * supports.rows.shape[0],
                 what=f"{_where(model)}this run", fix="shorten ground_motion.duration or raise solver.output_dt")
    system, raw, wall, rows = _solve(model, supports, end_time, settings.output_dt)
    ds = to_dataset(model, motion, system, raw, end_time=end_time, wall_time=wall,
                    supports=dataclasses.replace(supports, rows=rows))
    mark_energy_status(ds)
    return ds


def simulate_peaks(model: Model, record: Record | None = None) -> dict[str, Any]:
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
    histories and no dataset are made.
    """
    _check_modes_memory(model)
    supports = support_motions(model, record, where="yaml")
    motion = supports.records[0]
    end_time = supports.end_time
    if end_time <= 0.0:
        raise PoundingError(f"record {motion.name}: duration must be > 0 (got {end_time} s)")
    system, raw, wall, _ = _solve(model, supports, end_time, end_time)
    peaks = run_peaks(model, system, raw)
    peaks.update(record_scale=float(motion.scale), wall_time=wall)
    return peaks


def _solve(model: Model, supports: SupportMotions, end_time: float, output_dt: float):
    """Integrate *model* on its *supports* up to *end_time*: ``(system, raw solution, wall time in s,
    the ground rows as given to the solver (G, ns))``."""
    settings = model.solver
    check_work(model, end_time, where=_where(model))   # a stiff element would take hours, silently
    step = supports.time_step
    samples_needed = int(np.ceil(end_time / step - 1e-9)) + 1
    ground = np.zeros((supports.rows.shape[0], max(samples_needed, supports.rows.shape[1])))
    ground[:, : supports.rows.shape[1]] = supports.rows
    rows = ground
    if ground.shape[0] == 1:
        ground = ground[0]

    system = assemble(model, supports.building_row)
    started = _time.perf_counter()
    raw = integrate(system, ground, step, end_time, rtol=settings.rtol,
                    atol=settings.atol, atol_velocity=settings.atol_velocity,
                    output_dt=output_dt)
    wall = _time.perf_counter() - started
    if raw.status not in (STATUS_OK, STATUS_COLLAPSED):
        # STATUS_STEP_TOO_SMALL, STATUS_EVENT_LIMIT, STATUS_TABLE_LIMIT: one line each (pounding.solver).
        raise PoundingError(f"{_where(model)}" + STATUS_MESSAGES[raw.status].format(t=raw.final_time))
    return system, raw, wall, rows


def mark_energy_status(ds: xr.Dataset) -> str:
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
    n = sum(b.n_floors for b in model.buildings)
    nc = len(model.gaps)
    n_out = end_time / output_dt + 2 if output_dt > 0 else float("inf")
    n_ground = end_time / record_dt + 2 if record_dt > 0 else float("inf")
    per_sample = (2 * n + 3 * nc + 2) + n + nc + 3          # solver output buffers
    per_sample += 5 * n + 2 * nc + 8                        # dataset histories and energies
    total = 8.0 * (2 * per_sample * n_out + n_ground)
    return int(min(total, 2 ** 62))


def model_inputs(model: Model) -> list[str]:
    """Files a model run reads: the model file and, if they are files, the records (one per building or one)."""
    found = [str(model.path)] if getattr(model, "path", None) else []
    for spec in getattr(model, "building_ground_motions", ()) or (model.ground_motion,):
        record = getattr(spec, "record", None)
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
    model = model_from_text(spec["model"], name=ds.attrs.get("model_name", "model"),
                            path=ds.attrs.get("model_path") or None, base_dir=spec.get("base_dir"))
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
