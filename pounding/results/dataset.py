"""Label the integrator's arrays as one self-describing ``xarray.Dataset``.

Dimensions
----------
``time``
    Output samples every ``solver.output_dt`` seconds.
``floor``
    Every floor of every building, left to right (coords ``building``,
    ``level`` 1…n from the ground up, ``elevation`` m).
``storey``
    Every storey (coords ``storey_building``, ``storey_level`` — storey i
    lies between floors i−1 and i — and ``height`` m).  xarray coordinate
    names are unique within a dataset, hence the ``storey_`` prefix; storey i
    of a building lies directly under floor i of that building.
``contact``
    Every gap element (coords ``building_left``, ``building_right``,
    ``level_left``, ``level_right``, ``gap`` m, ``law``, ``xi``).
``impact``
    One row per impact (gap closure), in time order (coords ``impact_time``
    s, ``impact_contact_label`` e.g. ``A:3-B:3``).
``ground``
    The ground under each building (coordinate ``ground``: the building's
    name; a dimension of its own because ``building`` already labels floors):
    record identity, scale, wave-passage lag and the ground motion histories.
``trace``
    Full-resolution samples (every solver step, on its interpolant) of every
    closed contact: what force–penetration loops are drawn from (coords
    ``trace_time`` s, ``trace_contact_label``).

``impact`` and ``trace`` are ragged: their lengths differ from run to run,
so two runs are combined with :func:`drop_ragged` first.

Every variable carries ``units`` and ``long_name``.  Peaks and impact data
are tracked by the solver at full resolution, not read off the decimated
histories.
"""

from __future__ import annotations

import json
from datetime import datetime, timezone
from typing import Any

import numpy as np
import xarray as xr

from pounding import __version__
from pounding.contact import links as contact_links
from pounding.records.record import Record
from pounding.results.describe import run_title
from pounding.model.floors import DOF_PER_FLOOR
from pounding.model.model import Model, column_weights
from pounding.model.schema import WALL_NAME
from pounding.results.corners import CORNERS, corner_displacements, floor_corners, hermite_at
from pounding.results.lazy_dask import defer_dask_import
from pounding.results.run_arrays import Deferred, RunArrays
from pounding.solver.assembly import Assembly, storey_stop_ratios
from pounding.solver.integrator import RawSolution, System
from pounding.solver.kinematics import penetration as combined_penetration
from pounding.solver.storeys import restoring_force
from pounding.solver.status import STATUS_ENERGY_INCONSISTENT, STATUS_MESSAGES, STATUS_NAMES, STATUS_OK
from pounding.solver import kinematics
from pounding.solver.storeys import recoverable_energy
from pounding.units import STANDARD_GRAVITY

defer_dask_import()   # xarray's variables without importing dask.array (lazy_dask)

__all__ = ["to_dataset", "run_arrays", "plane_arrays", "run_peaks", "energy_closure", "drop_ragged", "record_pga", "PGA_LONG_NAME", "REFERENCES",
           "RAGGED_DIMS", "loaded_record_pga"]

#: Dimensions whose length depends on the run (impacts, full-resolution contact samples).
RAGGED_DIMS = ("impact", "trace")


#: long_name of a study's ``intensity`` variable when it is the PGA of :func:`record_pga` (compare, sweep, gap).
PGA_LONG_NAME = "peak ground acceleration (PGA) of the scaled record: the record's own PGA times scale_factor"


def record_pga(ds: xr.Dataset) -> tuple[float, float]:
    """Peak ground acceleration of a run's record, m/s²: as recorded (unscaled) and as run (scaled).

    The unscaled PGA is the record file's own (``pga_g`` of ``record_metadata``, before processing and
    truncation), the scaled one that times ``record_scale``.  A record given as samples without that
    metadata falls back on the stored ``ground_acceleration`` (sampled at ``output_dt``).
    """
    pga_g = json.loads(ds.attrs.get("record_metadata", "{}")).get("pga_g")
    return _pga_pair(pga_g, float(ds.attrs.get("record_scale", 1.0)),
                     lambda: float(np.max(np.abs(ds.ground_acceleration.values))) if "ground_acceleration" in ds
                     else np.nan)


def _pga_pair(pga_g: float | None, scale: float, peak_as_run) -> tuple[float, float]:
    """``(as recorded, as run)`` PGA, m/s², from the file's own ``pga_g`` and the factor, else from
    ``peak_as_run()`` (the scaled samples' peak) over the factor."""
    if pga_g is None:
        scaled = peak_as_run()
        return (scaled / scale if scale else scaled), scaled
    unscaled = float(pga_g) * STANDARD_GRAVITY
    return unscaled, unscaled * scale


def drop_ragged(ds: xr.Dataset) -> xr.Dataset:
    """*ds* without the ``impact`` and ``trace`` dimensions and everything on them.

    Runs of one model differ in the number of impacts and trace samples, so
    ``xr.concat([a, b], dim="xi")`` needs them dropped first::

        runs = [pounding.drop_ragged(pounding.simulate(model, xi=x)) for x in ("ye", "exact")]
        both = xr.concat(runs, dim="xi", combine_attrs="drop_conflicts").assign_coords(xi=["ye", "exact"])

    Peaks (``peak_*``) and ``impact_count`` stay.
    """
    return ds.drop_dims([d for d in RAGGED_DIMS if d in ds.dims])

REFERENCES = (
    "Muthukumar, S. & DesRoches, R. (2006) EESD 35, 811-828; "
    "Ye, K., Li, L. & Zhu, H. (2009) EESD 38, 1135-1142; "
    "Dormand, J.R. & Prince, P.J. (1980) J. Comput. Appl. Math. 6, 19-26; "
    "FEMA P695 (2009) Quantification of Building Seismic Performance Factors."
)


def _var(dims, data, units: str, long_name: str, **extra) -> tuple:
    attrs = {"units": units, "long_name": long_name}
    attrs.update(extra)
    return (dims, data, attrs)


def _labels(model: Model) -> dict[str, np.ndarray]:
    building, level, elevation, height = [], [], [], []
    for b in model.buildings:
        n = b.n_floors
        building += [b.name] * n
        level += list(range(1, n + 1))
        elevation += list(b.elevation)
        height += list(b.height)
    return {"building": np.array(building, dtype=object), "level": np.array(level, dtype=np.int32),
            "elevation": np.array(elevation, dtype=float), "height": np.array(height, dtype=float)}


def _storey_drift(u: np.ndarray, below: np.ndarray) -> np.ndarray:
    """(nt, N) storey drifts ``u_j − u_below(j)`` (``u_j`` over the ground).

    A building's floors are consecutive (``below[j] = j − 1``), so most of the
    work is whole column slices; any other floor is gathered.
    """
    n = below.size
    drift = np.array(u, dtype=float, order="C")
    chain = (below >= 0) & (below == np.arange(n) - 1)
    edges = np.flatnonzero(np.diff(np.r_[0, chain.astype(np.int8), 0]))
    for start, stop in zip(edges[::2], edges[1::2]):
        drift[:, start:stop] -= u[:, start - 1:stop - 1]
    other = np.flatnonzero((below >= 0) & ~chain)
    if other.size:
        drift[:, other] -= np.take(u, below[other], axis=1)
    return drift


def _link_results(system: System, raw: RawSolution, ng: int,
                  ground_displacement: np.ndarray | None = None, *, weighted: bool = False) -> dict[str, np.ndarray]:
    """Per link (the elements after the *ng* contacts): deformation, work and stored energy histories.

    Stored energy (docs/physics.md §9): ½kδ² in a Kelvin spring, q²/(2k) in a Maxwell spring, none
    in a dashpot (the solver's ``kernels.potential`` of the same elements, vectorised here).  *weighted*:
    the deformation is the links' weighted sums of terms (points of floors in plan), not a floor difference.
    """
    n = system.n_floors
    lay = system.layout
    u = raw.state[:, :n]
    left, right = system.contact_left[ng:], system.contact_right[ng:]
    if weighted:
        deformation = combined_penetration(u, system.contact_floors[ng:], system.contact_weights[ng:],
                                           np.zeros(left.size), np.zeros((u.shape[0], left.size)))
    else:
        deformation = np.take(u, left, axis=1) - np.take(u, right, axis=1)
    if ground_displacement is not None:
        # Total displacements: the differential ground displacement of the link's two ends (docs/physics.md §10).
        deformation = deformation + (np.take(ground_displacement, system.contact_ground_left[ng:], axis=1)
                                     - np.take(ground_displacement, system.contact_ground_right[ng:], axis=1))
    work = raw.state[:, lay.work + ng:lay.internal]
    internal = raw.state[:, lay.internal + ng:lay.input_energy]
    law = system.contact_law[ng:]
    stiffness = system.contact_parameters[ng:, 0]
    stored = np.zeros_like(deformation)
    kelvin = law == contact_links.LINK_KELVIN
    maxwell = law == contact_links.LINK_MAXWELL
    stored[:, kelvin] = 0.5 * stiffness[kelvin] * deformation[:, kelvin] ** 2
    stored[:, maxwell] = 0.5 * internal[:, maxwell] ** 2 / stiffness[maxwell]
    return {"deformation": deformation, "work": work, "stored": stored}


def _inelastic_summary(system: System, raw: RawSolution, heights: np.ndarray,
                       rows: Assembly | None = None) -> dict[str, np.ndarray]:
    """Per storey: residual drift ratio, yield drift, peak ductility and dissipated energy at the end.

    *rows*: the assembly of a planar model whose storeys are weighted rows (a building on a foundation);
    None: a chain, each storey ``u_j − u_below``.
    """
    n = system.n_floors
    final = raw.final_state
    displacement = final[:n]
    if rows is None:
        below = system.below
        drift = displacement - np.where(below >= 0, displacement[np.maximum(below, 0)], 0.0)
        peak, stiffness = raw.peak_drift, system.storey_stiffness
    else:
        drift, peak, stiffness = rows.plane_weights @ displacement, raw.peak_plane_drift, rows.plane_stiffness
    if rows is not None and system.storey_floors is None:   # weighted rows without a yielding one: no storey rows
        nan = np.full(drift.size, np.nan)
        return {"residual": drift / heights, "yield_drift": nan, "ductility": nan, "dissipated": np.zeros(drift.size)}
    yielding = system.storey_state >= 0
    yield_drift = np.where(yielding, system.storey_parameters[:, 0], np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        ductility = peak / yield_drift
    dissipated = np.zeros(drift.size)
    if yielding.any():
        lay = system.layout
        index = system.storey_state[yielding]
        state = final[lay.hysteretic + index]
        work = final[lay.storey_work + index]
        table = np.ascontiguousarray(system.storey_parameters, dtype=np.float64)
        recoverable = np.array([_recoverable(int(system.storey_model[j]), table, int(j),
                                             float(stiffness[j]), float(drift[j]), float(r))
                                for j, r in zip(np.flatnonzero(yielding), state)])
        dissipated[yielding] = work - recoverable
    return {"residual": drift / heights, "yield_drift": yield_drift, "ductility": ductility,
            "dissipated": dissipated}


def _recoverable(model: int, table: np.ndarray, row: int, stiffness: float, drift: float, state: float) -> float:
    """Recoverable energy of storey *row* (J), by the solver's own kernel (*table*: every storey's kernel vector)."""
    return float(recoverable_energy(model, table, row, stiffness, drift, state))


def _impact_law_values(gaps, raw: RawSolution) -> tuple[np.ndarray, np.ndarray]:
    """Per impact ``(ξ, restitution)``: the damping constant the law fixed at the onset (N s m⁻²·⁵; NaN for a
    law without one) and the separation over the approach velocity (NaN at zero approach velocity: floors
    touching at rest, gap 0), for the contacts (planar) or contact points (in plan) *gaps*."""
    with np.errstate(invalid="ignore", divide="ignore"):
        restitution = np.where(raw.impact_velocity > 0.0, raw.impact_separation_velocity / raw.impact_velocity,
                               np.nan)
    has_xi = np.array([type(g.law).onset_xi for g in gaps], dtype=bool)  # the law's class says (ContactLaw)
    impact_xi = np.where(has_xi[raw.impact_contact] if len(gaps) else np.zeros(0, bool), raw.impact_constant,
                         np.nan)
    return impact_xi, restitution


def _penetration(u: np.ndarray, system: System, ground_displacement: np.ndarray) -> np.ndarray:
    """(nt, nc) penetration ``Σ_k w_k·u[floor_k] + u_g,L − u_g,R − gap`` of every contact, by the solver's
    kinematics (:func:`pounding.solver.kinematics.penetration`).

    Walls and the ground contribute no floor term; *ground_displacement* (nt, G)
    holds each ground row's displacement (a wall's row is the one of the
    building it faces, so a wall contact's ground difference is 0).
    """
    differential = (np.take(ground_displacement, system.contact_ground_left, axis=1)
                    - np.take(ground_displacement, system.contact_ground_right, axis=1))
    return kinematics.penetration(u, system.contact_floors, system.contact_weights, system.contact_gap, differential)


def contact_coords(model: Model) -> dict[str, tuple]:
    """Coordinates of the ``contact`` dimension: every gap element's label, its two sides (building and floor;
    the low side along the normal on the left), gap at rest, law, ξ formula and parameters."""
    gaps = model.gaps
    side_names = [b.name for b in model.buildings] + [WALL_NAME]  # index WALL (−1) is the wall
    return {
        "contact": ("contact", np.array([g.label(side_names[:-1]) for g in gaps], dtype=object),
                    {"long_name": "gap element label"}),
        "building_left": ("contact", np.array([side_names[g.left] for g in gaps], dtype=object),
                          {"long_name": "left building of the gap element"}),
        "building_right": ("contact", np.array([side_names[g.right] for g in gaps], dtype=object),
                           {"long_name": "right building of the gap element"}),
        "level_left": ("contact", np.array([g.level_left for g in gaps], dtype=np.int32),
                       {"units": "1", "long_name": "floor number in the left building"}),
        "level_right": ("contact", np.array([g.level_right for g in gaps], dtype=np.int32),
                        {"units": "1", "long_name": "floor number in the right building"}),
        "gap": ("contact", np.array([g.gap for g in gaps], dtype=float),
                {"units": "m", "long_name": "gap at rest"}),
        "law": ("contact", np.array([g.law.name for g in gaps], dtype=object), {"long_name": "contact law"}),
        "xi_formula": ("contact", np.array([getattr(g.law, "xi", "") for g in gaps], dtype=object),
                       {"long_name": "formula for the Hertz-damp damping constant"}),
        "law_parameters": ("contact", np.array([g.law.describe() for g in gaps], dtype=object),
                           {"long_name": "contact law and its parameters"}),
    }


def _column_point_coords(gaps) -> dict:
    """``at_left`` / ``at_right``: the column point's fraction of the storey height (NaN for a floor or a wall)."""
    def column(side: str) -> np.ndarray:
        return np.array([np.nan if getattr(g, f"at_{side}") is None else getattr(g, f"at_{side}") for g in gaps])
    return {f"at_{side}": ("contact", column(side),
                           {"units": "1", "long_name": f"column point on the {side}: fraction of the height of "
                                                       f"storey level_{side} (NaN: a floor or a wall)"})
            for side in ("left", "right")}


def column_shear_demand(shear: np.ndarray, force: np.ndarray, at: float, side: str) -> np.ndarray:
    """Largest column shear (N) of a storey struck at fraction *at* of its height.

    The fixed-fixed column carries the storey's restoring shear ``V`` (end
    displacements) plus the point force: with ``Q`` the force on the column in
    +x (``−F`` on a left side, ``+F`` on a right side, F ≥ 0 the contact force)
    the segment below the point carries ``V + N1·Q``, the one above
    ``V − N2·Q`` (``N1``, ``N2``: :func:`pounding.model.model.column_weights`);
    the demand is the larger magnitude (docs/physics.md §12).
    """
    n1, n2 = column_weights(at)
    q = -force if side == "left" else force
    return np.maximum(np.abs(shear + n1 * q), np.abs(shear - n2 * q))


def _column_shear_variables(system: System, raw: RawSolution, gaps) -> dict:
    """``column_shear`` (time, contact) and ``peak_column_shear`` (contact); NaN for a contact without a column point.

    The peak is the larger of the maximum over the output samples and over the
    contact's full-resolution trace samples, where the trace's force is exact
    and the storey shear is interpolated linearly between output samples.
    """
    nt = raw.time.size
    nc = len(gaps)
    demand = np.full((nt, nc), np.nan)
    peak = np.full(nc, np.nan)
    for c, g in enumerate(gaps):
        side = "left" if g.at_left is not None else ("right" if g.at_right is not None else None)
        if side is None:
            continue
        at = g.at_left if side == "left" else g.at_right
        # the storey of the column point is the storey under the side's upper floor term
        storey = int(system.contact_floors[c, 1 if side == "left" else system.contact_floors.shape[1] // 2 + 1])
        shear = raw.storey_shear[:, storey]
        demand[:, c] = column_shear_demand(shear, raw.contact_force[:, c], at, side)
        best = float(np.max(demand[:, c])) if nt else 0.0
        rows = raw.trace_contact == c
        if rows.any() and nt > 1:
            at_trace = np.interp(raw.trace_time[rows], raw.time, shear)
            best = max(best, float(np.max(column_shear_demand(at_trace, raw.trace_force[rows], at, side))))
        peak[c] = best
    return {
        "column_shear": _var(("time", "contact"), demand, "N",
                             "largest column shear of the struck storey (storey shear plus the impact force's "
                             "share), NaN for a contact without a column point"),
        "peak_column_shear": _var(("contact",), peak, "N",
                                  "peak column shear demand at the impact point's storey (output and full-resolution "
                                  "trace samples), NaN for a contact without a column point"),
    }


def energy_closure(ds: xr.Dataset) -> float:
    """``max |E_in + W_g − Σ parts| / max |E_in + W_g|`` of a results dataset (dimensionless).

    ``W_g`` (``energy_ground_work``) is the work of the contact forces on the
    differential ground motion, an input when buildings stand on different
    grounds (0 otherwise).  Summed on the plain arrays, in the order written
    (xarray's arithmetic on the same time axis gives the same numbers, at ten
    times the cost of a run's whole energy audit).
    """
    energy = _energies(ds)
    inputs = energy("energy_input") + energy("energy_ground_work") if "energy_ground_work" in ds \
        else energy("energy_input")
    parts = (energy("energy_kinetic") + energy("energy_strain") + energy("energy_damping")
             + energy("energy_contact_dissipated") + energy("energy_contact_strain"))
    for name in ("energy_link_dissipated", "energy_link_strain", "energy_hysteretic"):
        if name in ds:
            parts = parts + energy(name)
    scale = float(np.abs(inputs).max())
    if scale == 0.0:
        return 0.0
    return float(np.abs(inputs - parts).max()) / scale


def _energies(ds: xr.Dataset):
    """``energy(name, default)``: the history *name* of *ds* as a plain array (J), *default* if absent."""
    def energy(name: str, default: float | None = None):
        return ds[name].values if default is None or name in ds else default
    return energy


#: Energy closure error above which a run is flagged (attribute ``energy_status``, summary
#: line): converged runs of the shipped models close to ~1e-6, so 1e-3 is a
#: thousand-fold margin and marks a run whose energies (and likely peaks) are wrong.
ENERGY_CLOSURE_LIMIT = 1e-3


def contact_energy_budget(system: System, raw: RawSolution, n_gaps: int) -> tuple[float, float]:
    """``(absorbed, received)``, J, at the end of the run: what the gap elements absorbed, what the run received.

    *absorbed* is the gap elements' work ∫F·δ̇ dt (dissipated, plus what a closed
    contact still stores); *received* the initial energy (kinetic, storey and
    contact strain at the first sample), the input work E_in, the work W_g of
    the differential ground motion and gravity's work under P-Delta, at most
    ``½·Σ (P/h)·Δ²`` (the storeys' P-Delta potential, negative, is all that can
    make their recoverable energy negative).  Every other term of the balance
    ``E_0 + E_in + W_g = KE + U_s + damping + hysteretic + contacts + links`` is
    ≥ 0, so in a solution that conserves energy ``absorbed ≤ received`` at every
    instant.  Read from the solver's final state, so a run and its IDA twin
    (:func:`simulate_peaks <pounding.simulation.simulate_peaks>`, same steps) agree.
    """
    lay = system.layout
    n = lay.n_floors
    first, last = raw.state[0], raw.final_state
    v0 = first[n:2 * n]
    initial = 0.5 * float(v0 @ (v0 * system.mass)) + float(raw.storey_energy[0, 0]) + float(raw.contact_potential[0])
    drift = _storey_drift(last[None, :n], system.below)[0]
    gravity = -0.5 * float(drift @ (drift * system.p_delta_stiffness))
    received = initial + float(last[lay.input_energy]) + float(last[lay.ground_work]) + gravity
    absorbed = float(last[lay.work:lay.work + n_gaps].sum())
    return absorbed, received


def energy_inconsistent(absorbed: float, received: float) -> bool:
    """True if the contacts absorbed more energy than the run received, beyond integration error.

    The margin is :data:`ENERGY_CLOSURE_LIMIT` of the larger of the two: the excess
    is a lower bound of the run's energy-closure error (every other term of the
    balance is ≥ 0), so a run that passes the energy audit's limit is never
    flagged here; converged runs close to ~1e-6, and a contact sequence the
    solver did not resolve (a chattering contact at loose tolerances) exceeds it
    many times over (tests/test_stability.py: 45x at atol 1e-4 m unscaled).
    """
    return absorbed - received > ENERGY_CLOSURE_LIMIT * max(abs(received), absorbed)


def collapse_reason(raw: RawSolution, system: System) -> str:
    """Why the storey that ended the run did (words after its label): past its collapse drift ratio, at
    zero strength, or "" (a loss of stability says its own; nothing collapsed)."""
    if raw.collapse_cause == "drift_ratio":
        return f"passed its collapse drift ratio {system.storey_stop_ratio[raw.collapse_storey]:g}"
    if raw.collapse_cause == "zero_strength":
        return "reached its ultimate drift (IMK storey at zero strength)"
    return ""


def run_status(system: System, raw: RawSolution, n_gaps: int, storey: str, building: str = "") -> tuple[str, str]:
    """``(status, one-line message)`` of a run that ended (``completed``, ``collapsed``, ``unstable`` or
    ``energy_inconsistent``; message ``""`` when completed).  *storey*: the label of the storey that
    collapsed or lost stability (``""`` if none), *building* its building."""
    absorbed, received = contact_energy_budget(system, raw, n_gaps)
    code = STATUS_ENERGY_INCONSISTENT if energy_inconsistent(absorbed, received) else raw.status
    if code == STATUS_OK:
        return STATUS_NAMES[code], ""
    return STATUS_NAMES[code], STATUS_MESSAGES[code].format(t=raw.final_time, storey=storey, dissipated=absorbed,
                                                            available=received, building=building,
                                                            cause=collapse_reason(raw, system))


def floor_dofs(model: Model) -> np.ndarray:
    """(floors,) the index of every floor's first degree of freedom in the model's vector (a founded building's
    base mat DOF, after its floors, are left out)."""
    return np.concatenate([offset + b.dofs_per_floor * np.arange(b.n_floors)
                           for b, offset in zip(model.buildings, model.dof_offsets)]).astype(np.int64) \
        if model.buildings else np.zeros(0, dtype=np.int64)


def _founded(model: Model) -> list[tuple[int, Any, int]]:
    """``(building index, building, index of its base mat's sway)`` of every building on a foundation (its
    rocking follows the sway)."""
    return [(i, b, offset + b.n_dof) for i, (b, offset) in enumerate(zip(model.buildings, model.dof_offsets))
            if b.foundation is not None]


def _row_strain(model: Model, assembly: Assembly, raw: RawSolution, drift: np.ndarray) -> np.ndarray:
    """(nt,) recoverable energy of a planar model with weighted storey rows, J: the storeys' (yielding ones by
    their hysteresis), the P-Delta potential and the foundations' springs ``½ K_x u_b² + ½ K_θ θ_b²``."""
    energies = _plane_energies(assembly, raw, drift)
    return energies["energy_plane_strain"] + energies["energy_p_delta"] + _foundation_energies(model, raw)[0]


def _foundation_energies(model: Model, raw: RawSolution) -> tuple[np.ndarray, np.ndarray]:
    """(nt,) the foundations' spring energy (J) and the energy their dashpots dissipated (J, the trapezoidal
    rule on the stored samples of ``c_x u̇_b² + c_θ θ̇_b²``: it is part of the damping energy the solver
    integrates at every step, which the energy audit uses)."""
    n = raw.peak_displacement.size
    strain = np.zeros(raw.time.size)
    power = np.zeros(raw.time.size)
    for _, b, sway in _founded(model):
        q = raw.state[:, sway:sway + 2]
        rate = raw.state[:, n + sway:n + sway + 2]
        strain += 0.5 * (q * q) @ b.foundation.stiffness
        power += (rate * rate) @ b.foundation.damping
    dissipated = np.r_[0.0, np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(raw.time))] if raw.time.size else power
    return strain, dissipated


def foundation_variables(model: Model, raw: RawSolution, floor: np.ndarray) -> dict[str, Any]:
    """The founded buildings' base mat histories and peaks, their floors' deformation (relative to the base mat),
    the foundations' energies, and under ``coords`` the ``foundation`` dimension (module docstring)."""
    n = raw.peak_displacement.size
    found = _founded(model)
    sway = np.array([s for *_, s in found], dtype=np.int64)
    q = raw.state[:, :n]
    deformation = q[:, floor].copy()
    for _, b, s in found:   # d_i = x_i − u_b − z_i θ_b (pounding.model.foundation)
        own = np.flatnonzero(floor == s - b.n_dof) + np.arange(b.n_floors)
        deformation[:, own] -= q[:, [s]] + q[:, [s + 1]] * b.elevation[None, :]
    strain, dissipated = _foundation_energies(model, raw)
    return {
        "coords": {"foundation": ("foundation", np.array([b.name for _, b, _ in found], dtype=object),
                                  {"long_name": "building on a foundation"})},
        "base_sway": _var(("time", "foundation"), q[:, sway], "m", "base mat sway relative to the free field"),
        "base_rocking": _var(("time", "foundation"), q[:, sway + 1], "rad", "base mat rocking, counter-clockwise"),
        "base_sway_rate": _var(("time", "foundation"), raw.state[:, n + sway], "m s-1", "base mat sway velocity"),
        "base_rocking_rate": _var(("time", "foundation"), raw.state[:, n + sway + 1], "rad s-1",
                                  "base mat rocking rate"),
        "peak_base_sway": _var(("foundation",), raw.peak_displacement[sway], "m",
                               "peak |sway| of the base mat (full resolution)"),
        "peak_base_rocking": _var(("foundation",), raw.peak_displacement[sway + 1], "rad",
                                  "peak |rocking| of the base mat (full resolution)"),
        "floor_deformation": _var(("time", "floor"), deformation, "m",
                                  "floor displacement relative to its base mat (without sway and rocking; a fixed "
                                  "base: the displacement)"),
        "peak_floor_deformation": _var(("floor",), np.abs(deformation).max(axis=0, initial=0.0), "m",
                                       "peak |floor_deformation| (stored samples)"),
        "energy_foundation_strain": _var(("time",), strain, "J",
                                         "elastic energy of the foundation springs (part of energy_strain)"),
        "energy_foundation_damping": _var(("time",), dissipated, "J",
                                          "energy dissipated by the foundation dashpots (stored samples, trapezoidal "
                                          "rule; part of energy_damping)"),
    }


def run_peaks(model: Model, assembly: Assembly, raw: RawSolution) -> dict[str, Any]:
    """The peaks and end-of-run state of one simulation, as plain arrays (what studies keep of a run).

    The same values :func:`to_dataset` stores under the same names: storey and
    contact labels, ``peak_drift_ratio`` and ``residual_drift_ratio`` (storey,
    1), ``impact_count`` and ``peak_contact_force`` (contact, N), ``status``
    (``completed``, ``collapsed``, ``unstable`` or ``energy_inconsistent``: :func:`run_status`) and
    ``status_message`` (its one line, ``""`` when completed), ``collapse_time`` (s, NaN if none),
    ``collapse_storey`` (label, ``""`` if none; also for ``unstable``: the storey that lost its
    resistance), ``collapse_building`` (its building, ``""`` if none) and ``collapse_cause``
    (:data:`pounding.solver.status.COLLAPSE_CAUSES`, ``""`` if none): the first building to collapse
    ends the run, so at most one building collapses in a run.  They do not depend on the output sampling: the solver tracks peaks at every step.
    Planes in plan: :func:`plane_peaks`.
    """
    if not assembly.chain and model.in_plan:
        return plane_peaks(model, assembly, raw)
    system = assembly.system
    rows = None if assembly.chain else assembly   # planar storeys as weighted rows: a building on a foundation
    labels = _labels(model)
    heights = labels["height"]
    ng = len(model.gaps)   # the gap elements; the links follow them in the solver's arrays
    floor_names = [f"{b}:{lv}" for b, lv in zip(labels["building"], labels["level"])]
    building_names = [b.name for b in model.buildings]
    collapsed = raw.collapse_storey >= 0
    building = str(labels["building"][raw.collapse_storey]) if collapsed else ""
    status, message = run_status(system, raw, ng, floor_names[raw.collapse_storey] if collapsed else "", building)
    return {
        "storey": floor_names,
        "storey_building": [str(b) for b in labels["building"]],
        "contact": [g.label(building_names) for g in model.gaps],
        "peak_drift_ratio": (raw.peak_drift if rows is None else raw.peak_plane_drift) / heights,
        "residual_drift_ratio": _inelastic_summary(system, raw, heights, rows)["residual"],
        "impact_count": (np.bincount(raw.impact_contact, minlength=ng).astype(np.int32) if ng
                         else np.zeros(0, np.int32)),
        "peak_contact_force": raw.peak_contact_force[:ng],
        "status": status,
        "status_message": message,
        "collapse_time": float(raw.final_time) if collapsed else float("nan"),
        "collapse_storey": floor_names[raw.collapse_storey] if collapsed else "",
        "collapse_building": building,
        "collapse_cause": raw.collapse_cause if collapsed else "",
    }


def _ragged_coords(variables: dict[str, Any], coords: dict[str, Any], raw: RawSolution, what: str) -> dict:
    """*coords* with the ragged dimensions' times and contact labels, taken out of *variables* (both changed).

    ``impact_time``, ``trace_time`` and each impact's and trace sample's contact label (*what*: the kind of
    contact) are coordinates, so that ``ds.trace_force.plot(x="trace_time")`` and
    ``groupby("trace_contact_label")`` work; given to the dataset's constructor (not set afterwards: each
    change of a dataset copies it, ~8 ms of every run).
    """
    labels = np.asarray(coords["contact"][1], dtype=object)
    for name in ("impact_time", "trace_time"):
        coords[name] = variables.pop(name)
    coords["impact_contact_label"] = ("impact", labels[raw.impact_contact] if labels.size else np.zeros(0, object),
                                      {"long_name": f"{what} of the impact (label of impact_contact)"})
    coords["trace_contact_label"] = ("trace", labels[raw.trace_contact] if labels.size else np.zeros(0, object),
                                     {"long_name": f"{what} of the sample (label of trace_contact)"})
    return coords


def to_dataset(model: Model, record: Record, assembly: Assembly, raw: RawSolution, *,
               end_time: float, wall_time: float, supports=None) -> xr.Dataset:
    """Build the results dataset of one simulation (:func:`run_arrays`, made an ``xarray.Dataset``).

    *supports* (:class:`pounding.records.supports.SupportMotions`, rows as given to
    the solver) describes the ground under each building; without it every
    building stands on *record* (row 0 of the solution's ground).  Planes as weighted rows (floors
    in plan): :func:`plane_dataset`.
    """
    return run_arrays(model, record, assembly, raw, end_time=end_time, wall_time=wall_time,
                      supports=supports).to_dataset()


def run_arrays(model: Model, record: Record, assembly: Assembly, raw: RawSolution, *, end_time: float,
               wall_time: float, supports=None, archive: bool = True) -> RunArrays:
    """The variables, coordinates and attributes of one simulation's results dataset, as plain arrays
    (:class:`~pounding.results.run_arrays.RunArrays`; arguments as :func:`to_dataset`).

    *archive*: also the attribute ``run_spec`` (what a rerun needs: the effective model as YAML, ~7 ms a
    run); a study's worker that keeps only the run's peaks leaves it out.
    """
    if not assembly.chain and model.in_plan:
        return plane_arrays(model, record, assembly, raw, end_time=end_time, wall_time=wall_time,
                            supports=supports, archive=archive)
    system = assembly.system
    n = system.n_floors
    rows = None if assembly.chain else assembly   # planar storeys as weighted rows: a building on a foundation
    floor = floor_dofs(model)
    labels = _labels(model)
    # The histories no study's worker reads are Deferred: computed when read (RunArrays), every one for an archive.
    u = Deferred(lambda: raw.state[:, floor])
    lay = system.layout
    work = raw.state[:, lay.work:lay.internal]
    e_input = raw.state[:, lay.input_energy]
    e_damping = raw.state[:, lay.damping_energy]

    drift = Deferred(lambda: _storey_drift(u(), system.below) if rows is None
                     else raw.state[:, :n] @ assembly.plane_weights.T)
    heights = labels["height"]
    ground = _grounds(model, record, system, raw, supports)
    ground_velocity = Deferred(lambda: ground["motion"]()[0])
    ground_displacement = Deferred(lambda: ground["motion"]()[1])
    # Contacts first, then links (pounding.solver.assembly.assemble puts the links after the gap elements).
    ng = len(model.gaps)
    # Total displacements: the differential ground displacement of each gap element's two sides joins
    # (0 on one common ground, and for a wall, which moves with the ground of the building it faces).
    penetration = Deferred(lambda: _penetration(raw.state[:, :n], system, ground_displacement())[:, :ng])
    # Without links their (time, 0) arrays need no ground: the same empty histories, the same sums.
    links = _link_results(system, raw, ng, ground_displacement() if system.contact_left.size > ng else None)

    kinetic = 0.5 * np.einsum("ij,ij,j->i", raw.state[:, n:2 * n], raw.state[:, n:2 * n], system.mass)
    # Recoverable storey energy (with the P-Delta potential), summed by the solver at each output time;
    # a yielding storey's dissipated energy is its work ∫F dΔ minus its recoverable part.
    strain = raw.storey_energy[:, 0] if rows is None else _row_strain(model, assembly, raw, drift())
    storey_work = raw.state[:, lay.storey_work:lay.ground_work]
    hysteretic = storey_work.sum(axis=1) - raw.storey_energy[:, 1]
    inelastic = _inelastic_summary(system, raw, heights, rows)
    peaks = run_peaks(model, assembly, raw)
    # Summed over contacts and links by the solver at each output time; the links' share is taken out.
    contact_strain = raw.contact_potential - links["stored"].sum(axis=1)
    contact_work = work[:, :ng].sum(axis=1)

    floor_names = peaks["storey"]
    building_names = [b.name for b in model.buildings]
    gaps = model.gaps
    impact_count = peaks["impact_count"]
    impact_xi, restitution = _impact_law_values(gaps, raw)

    coords = {
        "time": ("time", raw.time, {"units": "s", "long_name": "time", "standard_name": "time"}),
        "ground": ("ground", np.array(building_names, dtype=object),
                   {"long_name": "building standing on the ground"}),
        "floor": ("floor", np.array(floor_names, dtype=object), {"long_name": "floor label building:level"}),
        "building": ("floor", labels["building"], {"long_name": "building of the floor"}),
        "level": ("floor", labels["level"], {"units": "1", "long_name": "floor number above ground"}),
        "elevation": ("floor", labels["elevation"], {"units": "m", "long_name": "floor elevation above ground"}),
        "storey": ("storey", np.array(floor_names, dtype=object),
                   {"long_name": "storey label building:level (storey i between floors i-1 and i)"}),
        "storey_building": ("storey", labels["building"], {"long_name": "building of the storey"}),
        "storey_level": ("storey", labels["level"], {"units": "1", "long_name": "storey number above ground"}),
        "height": ("storey", heights, {"units": "m", "long_name": "storey height"}),
        **contact_coords(model),
        "link": ("link", np.array([f"{building_names[k.left]}:{k.level_left}-{building_names[k.right]}:"
                                   f"{k.level_right}" for k in model.links], dtype=object),
                 {"long_name": "link label left:level-right:level"}),
        "link_law": ("link", np.array([k.law.describe() for k in model.links], dtype=object),
                     {"long_name": "link element and its parameters"}),
    }
    variables = {
        "displacement": _var(("time", "floor"), u, "m", "floor displacement relative to the ground (on a foundation: "
                             "to the free field, the base mat's sway and rocking included)"),
        "velocity": _var(("time", "floor"), Deferred(lambda: raw.state[:, n:2 * n][:, floor]), "m s-1",
                         "floor velocity relative to the ground"),
        "absolute_acceleration": _var(("time", "floor"), Deferred(
                                      lambda: raw.acceleration[:, floor]
                                      + np.take(ground["acceleration"], system.floor_ground[floor], axis=1)),
                                      "m s-2", "absolute floor acceleration (over the building's own ground)"),
        "storey_drift": _var(("time", "storey"), drift, "m", "storey drift u_i - u_(i-1) (on a foundation: the "
                             "storey's deformation, without the base mat's rocking)"),
        "drift_ratio": _var(("time", "storey"), Deferred(lambda: drift() / heights), "1",
                            "storey drift ratio (drift / height)"),
        "contact_force": _var(("time", "contact"), raw.contact_force[:, :ng], "N", "contact force (>= 0 pushes apart)"),
        "penetration": _var(("time", "contact"), penetration, "m",
                            "penetration u_left - u_right + u_ground_left - u_ground_right - gap "
                            "(positive = overlap, negative = open gap)"),
        "ground_acceleration": _var(("time",), raw.ground_acceleration, "m s-2",
                                    "ground acceleration (under the first building when they differ)"),
        "ground_record": _var(("ground",), ground["record"], "", "record under the building"),
        "ground_record_source": _var(("ground",), ground["source"], "", "record specification under the building"),
        "ground_scale": _var(("ground",), ground["scale"], "1", "scale factor applied to the building's record"),
        "ground_lag": _var(("ground",), ground["lag"], "s",
                           "wave-passage time lag applied (rounded to the record step)"),
        "ground_lag_requested": _var(("ground",), ground["lag_requested"], "s",
                                     "wave-passage time lag (position - first position) / apparent velocity"),
        "building_ground_acceleration": _var(("time", "ground"),
                                             Deferred(lambda: ground["acceleration"][:, ground["row"]]),
                                             "m s-2", "ground acceleration under the building"),
        "building_ground_velocity": _var(("time", "ground"), Deferred(lambda: ground_velocity()[:, ground["row"]]),
                                         "m s-1", "ground velocity under the building (exact integral from rest)"),
        "building_ground_displacement": _var(("time", "ground"),
                                             Deferred(lambda: ground_displacement()[:, ground["row"]]), "m",
                                             "ground displacement under the building (exact integral from rest)"),
        "peak_displacement": _var(("floor",), raw.peak_displacement[floor], "m",
                                  "peak absolute floor displacement relative to the ground"),
        "peak_storey_drift": _var(("storey",), raw.peak_drift if rows is None else raw.peak_plane_drift, "m",
                                  "peak absolute storey drift"),
        "peak_drift_ratio": _var(("storey",), peaks["peak_drift_ratio"], "1", "peak absolute storey drift ratio"),
        "collapse_drift_ratio": _var(("storey",), Deferred(lambda: np.where(storey_stop_ratios(model) > 0,
                                                                            storey_stop_ratios(model), np.nan)), "1",
                                     "collapse drift ratio of the storey's building (the run ends when the storey's "
                                     "|drift ratio| first exceeds it; NaN: no drift limit)"),
        "peak_contact_force": _var(("contact",), peaks["peak_contact_force"], "N", "peak contact force"),
        "impact_count": _var(("contact",), impact_count, "1", "number of impacts (gap closures)"),
        "impact_time": _var(("impact",), raw.impact_time, "s", "time of gap closure (located event)"),
        "impact_contact": _var(("impact",), raw.impact_contact.astype(np.int32), "1",
                               "index of the gap element along the contact dimension"),
        "impact_velocity": _var(("impact",), raw.impact_velocity, "m s-1", "approach velocity at gap closure"),
        "impact_xi": _var(("impact",), impact_xi, "N s m-2.5",
                          "Hertz-damp damping constant fixed at gap closure (nan for other laws)"),
        "impact_peak_force": _var(("impact",), raw.impact_peak_force, "N", "peak contact force of the impact"),
        "impact_duration": _var(("impact",), raw.impact_end_time - raw.impact_time, "s",
                                "contact duration (nan if still in contact at the end)"),
        "impact_impulse": _var(("impact",), raw.impact_impulse, "N s", "impulse of the contact force"),
        "impact_dissipated_energy": _var(("impact",), raw.impact_work, "J",
                                         "energy dissipated by the contact during the impact "
                                         "(work of the contact force; partial if still in contact at the end)"),
        "impact_restitution": _var(("impact",), restitution, "1",
                                   "separation velocity / approach velocity (can exceed 1 between floors of buildings; "
                                   "nan at zero approach velocity)"),
        "trace_time": _var(("trace",), raw.trace_time, "s",
                           "time of a full-resolution sample of a closed contact"),
        "trace_contact": _var(("trace",), raw.trace_contact.astype(np.int32), "1",
                              "index of the gap element along the contact dimension"),
        "trace_penetration": _var(("trace",), raw.trace_penetration, "m",
                                  "penetration at the full-resolution sample"),
        "trace_force": _var(("trace",), raw.trace_force, "N", "contact force at the full-resolution sample"),
        "energy_input": _var(("time",), e_input, "J",
                             "input energy -integral sum_b a_g,b 1_b'M du/dt dt (each building from its own ground)"),
        "energy_ground_work": _var(("time",), raw.state[:, -1], "J",
                                   "work of the contact forces on the differential ground motion "
                                   "integral F (du_g,left/dt - du_g,right/dt) dt (an input; 0 on one common ground)"),
        "energy_kinetic": _var(("time",), kinetic, "J", "kinetic energy (relative motion)"),
        "energy_strain": _var(("time",), strain, "J",
                              "recoverable strain energy of the storeys (with the P-Delta gravity potential)"),
        "energy_damping": _var(("time",), e_damping, "J", "energy dissipated by structural damping"),
        "energy_contact_dissipated": _var(("time",), contact_work - contact_strain, "J",
                                          "energy dissipated by the contacts"),
        "energy_contact_strain": _var(("time",), contact_strain, "J", "elastic energy stored in the contacts"),
        "energy_hysteretic": _var(("time",), hysteretic, "J", "energy dissipated by yielding storeys"),
        "energy_link_dissipated": _var(("time",), links["work"].sum(axis=1) - links["stored"].sum(axis=1), "J",
                                       "energy dissipated by the links"),
        "energy_link_strain": _var(("time",), links["stored"].sum(axis=1), "J", "elastic energy stored in the links"),
        "link_force": _var(("time", "link"), raw.contact_force[:, ng:], "N",
                           "link force (> 0 pushes the floors apart, < 0 pulls them together)"),
        "link_deformation": _var(("time", "link"), links["deformation"], "m",
                                 "relative displacement u_left - u_right across the link"),
        "peak_link_force": _var(("link",), raw.peak_contact_force[ng:], "N",
                                "peak absolute link force, tracked on every step"),
        "link_dissipated_energy": _var(("link",), links["work"][-1] - links["stored"][-1], "J",
                                       "energy dissipated by the link over the run"),
        "storey_shear": _var(("time", "storey"), raw.storey_shear if rows is None else
                             Deferred(lambda: _plane_shear(assembly, raw, drift())), "N",
                             "storey restoring (column) shear, without P-Delta and damping"),
        "residual_drift_ratio": _var(("storey",), peaks["residual_drift_ratio"], "1",
                                     "signed storey drift ratio at the end of the run"),
        "peak_ductility": _var(("storey",), inelastic["ductility"], "1",
                               "peak absolute storey drift over yield drift (NaN for an elastic storey)"),
        "yield_drift": _var(("storey",), inelastic["yield_drift"], "m",
                            "storey yield drift u_y = F_y / k (NaN for an elastic storey)"),
        "yield_force": _var(("storey",), inelastic["yield_drift"] * (system.storey_stiffness if rows is None
                                                                     else assembly.plane_stiffness), "N",
                            "storey yield force F_y (NaN for an elastic storey)"),
        "storey_hysteretic_energy": _var(("storey",), inelastic["dissipated"], "J",
                                         "energy dissipated by the storey's hysteresis over the run"),
    }
    if rows is not None and any(b.foundation is not None for b in model.buildings):
        found = foundation_variables(model, raw, floor)
        coords.update(found.pop("coords"))
        variables.update(found)
    if any(g.has_column_point for g in gaps):
        coords.update(_column_point_coords(gaps))
        variables.update(_column_shear_variables(system, raw, gaps))
    if not model.links:
        # A model without links has no link dimension and no link variables (archives as before links).
        for name in ("link", "link_law"):
            del coords[name]
        for name in ("energy_link_dissipated", "energy_link_strain", "link_force", "link_deformation",
                     "peak_link_force", "link_dissipated_energy"):
            del variables[name]
    ds = RunArrays(variables, _ragged_coords(variables, coords, raw, "gap element"))
    closure = energy_closure(ds)
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    ds.attrs = {
        "Conventions": "CF-1.10",
        "title": "",   # below: run_title reads the other attributes
        "source": f"pounding {__version__}",
        "history": f"{now} simulated with pounding {__version__}",
        "references": REFERENCES,
        **_model_attrs(model),
        "run_spec": json.dumps(run_spec(model, record, end_time, ground)) if archive else "",
        "record_name": record.name,
        "record_source": record.source,
        "record_scale": float(record.scale),
        "record_time_step": float(record.time_step),
        "record_metadata": json.dumps(record.metadata, default=str),
        "record_key": str(record.metadata.get("catalogue_key", "")),
        "record_scale_method": str(record.metadata.get("scale_method", "factor")),
        "record_scale_description": str(record.metadata.get("scale_description", f"factor {record.scale:g}")),
        "record_processing": str(record.metadata.get("processing", "[]")),
        "record_sha256": str(record.metadata.get("sha256", "")),
        "duration": float(end_time),
        **_solver_attrs(model, raw),
        "wall_time": float(wall_time),
        "energy_closure_error": closure,
        "status": peaks["status"],
        "collapse_time": peaks["collapse_time"],
        "collapse_storey": peaks["collapse_storey"],
        "collapse_building": peaks["collapse_building"],
        "collapse_cause": peaks["collapse_cause"],
        "hysteresis": json.dumps({b.name: [None if law is None else law.describe() for law in b.hysteresis]
                                  for b in model.buildings if b.is_inelastic}),
    }
    if "foundation" in ds.coords:   # per founded building: periods, damping, springs (from soil: at which ω)
        ds.attrs["foundations"] = json.dumps({b.name: {
            "fixed_base_periods": [float(x) for x in b.periods], "flexible_base_periods":
            [float(x) for x in b.flexible_periods], "effective_damping": float(b.effective_damping),
            "fixed_base_damping": float(b.modal_damping_ratios[0]), "springs": b.foundation.springs()}
            for _, b, _ in _founded(model)})
    if peaks["status_message"]:   # not completed: why (a completed run's archive is as before)
        ds.attrs["status_message"] = peaks["status_message"]
    if model.has_building_records:   # each building's own record: its PGA as recorded and as run, m/s²
        ds.attrs["ground_pga"] = json.dumps({b.name: {"record": str(ground["record"][i]), "scale": float(ground["scale"][i]),
                                                      "pga_recorded": ground["pga"][i][0], "pga": ground["pga"][i][1]}
                                             for i, b in enumerate(model.buildings)})
    if model.contacts_held_open:   # the run without pounding (pounding run --no-contacts)
        ds.attrs["contacts"] = (f"held open: every gap {model.gaps[0].gap:g} m, so no contact closes "
                                "(the run without pounding)")
    ds.attrs["title"] = f"pounding simulation of {run_title(ds)}"
    if not archive:
        del ds.attrs["run_spec"]
    return ds


def loaded_record_pga(record: Record) -> tuple[float, float]:
    """A record's PGA, m/s²: as recorded (the file's own ``pga_g``, else the samples over the factor) and as run."""
    return _pga_pair(record.metadata.get("pga_g"), float(record.scale),
                     lambda: float(np.max(np.abs(record.acceleration))) if record.acceleration.size else 0.0)


def _grounds(model: Model, record: Record, system: System, raw: RawSolution, supports) -> dict:
    """Per building (the ``ground`` dimension): record identity, lag, and the ground histories per row."""
    names = [b.name for b in model.buildings]
    if supports is None:
        rows, step = np.atleast_2d(raw.ground_acceleration), None
        records, lags, requested, row = [record] * len(names), [0.0] * len(names), [0.0] * len(names), [0] * len(names)
    else:
        rows, step = supports.rows, supports.time_step
        records, lags, requested = supports.records, supports.lag, supports.lag_requested
        row = list(supports.building_row)
    # Accelerations as the solver evaluated them; velocity and displacement by the same closed forms.
    acc = raw.support_acceleration if raw.support_acceleration is not None else raw.ground_acceleration[:, None]
    # (velocity, displacement), computed when first read (a worker that reads neither does not pay for them)
    motion = Deferred(lambda: (np.zeros_like(acc),) * 2 if step is None
                      else kinematics.ground_state_at(rows, step, raw.time)[1:])
    return {"record": np.array([r.name for r in records], dtype=object),
            "pga": [loaded_record_pga(r) for r in records],
            "source": np.array([r.source for r in records], dtype=object),
            "scale": np.array([float(r.scale) for r in records]),
            "sha256": [str(r.metadata.get("sha256", "")) for r in records],
            "lag": np.array(lags, dtype=float), "lag_requested": np.array(requested, dtype=float),
            "row": np.asarray(row, dtype=np.int64), "acceleration": acc, "motion": motion}


def _model_attrs(model: Model) -> dict[str, Any]:
    """A run archive's attributes that describe its model, the same for planar models and models in plan: its
    name, file and text, how its ground moves, P-Delta, the ξ formulas of its contacts, each building's
    periods (s) and the drift ratio that stops the run (0: none)."""
    return {"model_name": model.name, "model_path": str(model.path or ""), "model_yaml": model.source,
            "multi_support": ("per-building records" if model.has_building_records else
                              "wave passage" if model.ground_motion.wave_passage is not None else ""),
            "p_delta": ", ".join(b.name for b in model.buildings if b.p_delta),
            "xi_formulas": ", ".join(sorted({getattr(g.law, "xi", "") for g in model.gaps} - {""})),
            "periods": json.dumps({b.name: [float(x) for x in b.periods] for b in model.buildings}),
            "stop_drift_ratio": float(model.solver.stop_drift_ratio or 0.0)}


def _solver_attrs(model: Model, raw: RawSolution) -> dict[str, Any]:
    """A run archive's attributes that describe its integration, the same for both kinds of model: the
    method, the tolerances (``solver_atol`` m, ``solver_atol_velocity`` m/s), the output step (s), how linear
    phases ran, and the counts of accepted, exact and rejected steps."""
    solver = model.solver
    return {"solver": "Dormand-Prince 5(4), event-located contacts (pounding.solver)",
            "solver_rtol": float(solver.rtol), "solver_atol": float(solver.atol),
            "solver_atol_velocity": float(solver.atol_velocity), "solver_output_dt": float(solver.output_dt),
            "solver_linear_phases": str(solver.linear_phases), "solver_steps": int(raw.n_steps),
            "solver_exact_steps": int(raw.exact_steps), "solver_rejected_steps": int(raw.n_rejected)}


def run_spec(model: Model, record: Record, end_time: float, ground: dict | None = None) -> dict:
    """Everything :func:`pounding.archive.rerun` needs besides the model YAML.

    ``scale`` is the resolved factor actually applied (whatever the method),
    ``scale_method`` / ``scale_description`` how it was obtained,
    ``processing`` the processing steps (JSON list) and ``record_sha256`` the
    hash of the samples used, which a rerun must reproduce.
    """
    meta = record.metadata
    return {
        "model": model.to_document(),
        "base_dir": model.ground_motion.base_dir,
        "record": record.source,
        "record_key": meta.get("catalogue_key", ""),
        "scale": float(record.scale),
        "scale_method": meta.get("scale_method", "factor"),
        "scale_description": meta.get("scale_description", f"factor {record.scale:g}"),
        "processing": json.loads(meta["processing"]) if isinstance(meta.get("processing"), str) else [],
        "duration": float(end_time),
        "record_sha256": meta.get("sha256", ""),
        "grounds": [] if ground is None or not model.has_building_records else [
            {"building": b.name, "record": str(ground["source"][i]), "scale": float(ground["scale"][i]),
             "record_sha256": ground["sha256"][i]} for i, b in enumerate(model.buildings)],
    }


# --------------------------------------------------------------------------- #
# Floors in plan: directions and rotations, corners, plane rows, contact points, faces
# --------------------------------------------------------------------------- #


def _plan_floor_labels(model: Model) -> dict[str, Any]:
    buildings = [b.name for b in model.buildings for _ in range(b.n_floors)]
    levels = [i + 1 for b in model.buildings for i in range(b.n_floors)]
    centres = np.array([c for b in model.buildings for c in b.centres], dtype=float).reshape(-1, 2)
    corners = floor_corners(model)
    return {"building": (("floor",), np.array(buildings, dtype=object), {"long_name": "building of the floor"}),
            "level": (("floor",), np.array(levels, dtype=np.int64),
                            {"units": "1", "long_name": "floor number from the ground up"}),
            "floor_centre_x": (("floor",), centres[:, 0], {"units": "m", "long_name": "x of the floor's centre of mass"}),
            "floor_centre_y": (("floor",), centres[:, 1], {"units": "m", "long_name": "y of the floor's centre of mass"}),
            "corner": (("corner",), np.array(CORNERS, dtype=object), {"long_name": "corner of the floor's outline"}),
            "corner_x": (("floor", "corner"), corners[:, :, 0], {"units": "m", "long_name": "x of the corner at rest"}),
            "corner_y": (("floor", "corner"), corners[:, :, 1], {"units": "m", "long_name": "y of the corner at rest"})}


def _plane_labels(model: Model) -> dict[str, Any]:
    rows = [(b.name, storey, b.storeys[storey - 1].planes[j])
            for b in model.buildings for storey, j, _ in b.plane_weights()]
    return {"plane_building": (("plane",), np.array([r[0] for r in rows], dtype=object),
                               {"long_name": "building of the plane"}),
            "plane_storey": (("plane",), np.array([r[1] for r in rows], dtype=np.int64),
                             {"units": "1", "long_name": "storey of the plane"}),
            "plane_direction": (("plane",), np.array([r[2].direction for r in rows], dtype=object),
                                {"long_name": "direction the plane resists"}),
            "plane_at": (("plane",), np.array([r[2].at for r in rows], dtype=float),
                         {"units": "m", "long_name": "the plane's line (y along x, x along y)"})}


def _point_labels(model: Model) -> dict[str, Any]:
    names = [b.name for b in model.buildings]
    faces = [model.faces[g.face] for g in model.gaps]
    between = [f.label(names) for f in faces]
    point_face = np.array([g.face for g in model.gaps], dtype=np.int64)
    location = np.array([g.point for g in model.gaps], dtype=float).reshape(len(model.gaps), 2)
    return {"point_between": (("contact",), np.array(between, dtype=object),
                              {"long_name": "the two floors of the contact point (building:floor)"}),
            "point_face": (("contact",), point_face, {"units": "1", "long_name": "index of the point's face"}),
            "point_normal": (("contact",), np.array([c.face.normal for c in faces], dtype=object),
                             {"long_name": "normal direction of the point's face"}),
            "point_x": (("contact",), location[:, 0], {"units": "m", "long_name": "x of the point at rest"}),
            "point_y": (("contact",), location[:, 1], {"units": "m", "long_name": "y of the point at rest"})}


def _impact_slip(model: Model, assembly: Assembly, raw: RawSolution) -> np.ndarray:
    """(impacts,) the face's tangential slip (low side minus high side along +tangent, m) at each impact's onset.

    The state at the onset is the cubic Hermite interpolant of the stored samples
    (displacements with their velocities; :func:`hermite_at`).
    """
    n = assembly.system.n_floors
    if raw.impact_contact.size == 0:
        return np.zeros(0)
    slip = np.array([model.scatter(c, p.slip) for c in model.faces for p in c.points]).reshape(-1, n)
    q = hermite_at(raw.time, raw.state[:, :n], raw.state[:, n:2 * n], raw.impact_time)
    return np.einsum("ij,ij->i", q, slip[raw.impact_contact])


def _plane_energies(assembly: Assembly, raw: RawSolution, drift: np.ndarray) -> dict[str, np.ndarray]:
    """Energy histories (J): input, kinetic, damping, plane strain, P-Delta, contacts; initial energy first.

    The planes' strain energy is ``Σ ½ k Δ²`` of the elastic ones at the stored states (*drift*: (nt, plane),
    m) plus the yielding ones' recoverable energy, the P-Delta potential ``Σ ½ k_G (a · q)²``.
    """
    system = assembly.system
    lay = system.layout
    n, npt = lay.n_floors, assembly.n_points
    state = raw.state
    v = state[:, n:2 * n]
    work = state[:, lay.work:lay.work + lay.n_contacts]
    elastic = np.ones(assembly.plane_stiffness.size, dtype=bool)
    elastic[_yielding_planes(assembly)] = False  # a yielding plane's energy: recoverable here, the rest dissipated
    strain = 0.5 * (drift[:, elastic] ** 2) @ assembly.plane_stiffness[elastic]
    geometric = 0.5 * ((state[:, :n] @ assembly.p_delta_weights.T) ** 2) @ assembly.p_delta_stiffness
    hysteretic = state[:, lay.storey_work:lay.ground_work].sum(axis=1) - raw.storey_energy[:, 1]
    return {"energy_input": state[:, lay.input_energy],
            "energy_ground_work": state[:, lay.ground_work],
            "energy_kinetic": 0.5 * (v * v) @ system.mass,
            "energy_damping": state[:, lay.damping_energy],
            "energy_plane_strain": strain + raw.storey_energy[:, 1],
            "energy_p_delta": geometric,
            "energy_contact": work[:, :npt].sum(axis=1),
            "energy_hysteretic": hysteretic}


def _friction_variables(assembly: Assembly, raw: RawSolution) -> dict[str, tuple]:
    """The friction faces' histories (module docstring), {} without friction."""
    system = assembly.system
    if raw.friction_history is None:
        return {}
    nf, lay = system.n_faces, system.layout
    history = raw.friction_history
    slip = combined_penetration(raw.state[:, :system.n_floors], system.friction_floors, system.friction_weights,
                       np.zeros(nf), np.zeros((raw.time.size, nf)))
    dissipated = raw.state[:, lay.friction_work:lay.friction_work + nf].sum(axis=1)
    return {"friction_normal": _var(("time", "face"), history[:, :nf], "N", "normal force on the friction face"),
            "friction_force": _var(("time", "face"), -history[:, nf:2 * nf], "N",
                                   "friction on the face's low side along +tangent (the high side: the opposite)"),
            "friction_state": _var(("time", "face"), history[:, 2 * nf:].astype(np.int64), "1",
                                   "face: 0 open, +1/-1 slipping along +/-tangent, 2 sticking"),
            "face_slip": _var(("time", "face"), slip, "m",
                              "tangential slip of the low side's face relative to the high side's, along +tangent"),
            "energy_friction": _var(("time",), dissipated, "J", "energy: friction (dissipated)")}


def _face_labels(model: Model, assembly: Assembly) -> dict[str, Any]:
    """Coordinates of the friction faces (``face`` dimension), {} without friction."""
    if assembly.system.n_faces == 0:
        return {}
    names = [b.name for b in model.buildings]
    faces = [(i, c) for i, c in enumerate(model.faces) if c.friction]
    between = [c.label(names) for _, c in faces]
    return {"face_index": (("face",), np.array([i for i, _ in faces], dtype=np.int64),
                           {"units": "1", "long_name": "index of the face (as point_face)"}),
            "face_between": (("face",), np.array(between, dtype=object), {"long_name": "the two floors of the face"}),
            "face_tangent": (("face",), np.array([c.face.tangent for _, c in faces], dtype=object),
                             {"long_name": "tangential direction of the face"}),
            "face_friction_coefficient": (("face",), np.array([float(c.friction) for _, c in faces]),
                                          {"units": "1", "long_name": "Coulomb friction coefficient"})}


def _yielding_planes(assembly: Assembly) -> np.ndarray:
    """Indices of the yielding planes, in the order of their hysteretic states (none without storey rows)."""
    system = assembly.system
    if system.storey_floors is None:
        return np.zeros(0, dtype=np.int64)
    planes = np.flatnonzero(system.storey_state >= 0)
    return planes[np.argsort(system.storey_state[planes])]


def _plane_shear(assembly: Assembly, raw: RawSolution, drift: np.ndarray) -> np.ndarray:
    """(nt, plane) shear of every plane, N: kΔ, a yielding plane's by its hysteresis at its state."""
    system = assembly.system
    shear = drift * assembly.plane_stiffness
    first = system.layout.hysteretic
    for index, p in enumerate(_yielding_planes(assembly)):
        shear[:, p] = restoring_force.py_func(int(system.storey_model[p]), system.storey_parameters, int(p),
                                              float(assembly.plane_stiffness[p]), drift[:, p], raw.state[:, first + index])
    return shear


def plane_energy_closure(ds: xr.Dataset) -> float:
    """``max |E_0 + E_in − Σ parts| / max (E_0 + |E_in|)`` of an archive with plane rows (dimensionless)."""
    energy = _energies(ds)   # plain arrays, summed in the order written (see energy_closure)
    parts = (energy("energy_kinetic") + energy("energy_damping") + energy("energy_plane_strain")
             + energy("energy_p_delta") + energy("energy_contact") + energy("energy_hysteretic", 0.0)
             + energy("energy_friction", 0.0) + energy("energy_link_dissipated", 0.0)
             + energy("energy_link_strain", 0.0))
    initial = float(parts[0])
    supplied = initial + energy("energy_input") + energy("energy_ground_work", 0.0)
    scale = float(np.abs(supplied).max())
    return 0.0 if scale == 0.0 else float(np.abs(supplied - parts).max()) / scale


def _plane_rows(model: Model) -> list[tuple[str, int, Any, float]]:
    """``(building, storey, plane, storey height m)`` of every plane row, in the solver's order."""
    return [(b.name, storey, plane, b.storeys[storey - 1].height) for b in model.buildings
            for storey, _, plane in b.planes()]


def plane_labels(model: Model) -> list[str]:
    """Each plane's label ``A:1:x@10`` (building, storey, direction and line)."""
    return [f"{b}:{s}:{p.direction}@{float(p.at):g}" for b, s, p, _ in _plane_rows(model)]


def _storey_peaks(model: Model, peak_ratio: np.ndarray) -> dict[str, np.ndarray]:
    """Per storey (building:level) the largest peak |drift ratio| of its planes, and the storey's labels."""
    rows = _plane_rows(model)
    storeys = list(dict.fromkeys((b, s) for b, s, _, _ in rows))
    peak = np.zeros(len(storeys))
    for (b, s, _, _), value in zip(rows, peak_ratio):
        k = storeys.index((b, s))
        peak[k] = max(peak[k], float(value))
    height = {(b, s): h for b, s, _, h in rows}
    return {"storey": np.array([f"{b}:{s}" for b, s in storeys], dtype=object),
            "building": np.array([b for b, _ in storeys], dtype=object),
            "level": np.array([s for _, s in storeys], dtype=np.int32),
            "height": np.array([height[k] for k in storeys], dtype=float), "peak": peak}


def plane_status(model: Model, assembly: Assembly, raw: RawSolution) -> dict[str, Any]:
    """A run's ``status`` and, if a plane ended it, ``status_message``, ``collapse_time`` (s),
    ``collapse_building``, ``collapse_storey`` (``building:storey``), ``collapse_plane`` (its index in the
    archive's ``plane`` dimension) and ``collapse_cause`` (``drift_ratio`` or ``zero_strength``)."""
    if raw.status == STATUS_OK or raw.collapse_storey < 0:
        return {"status": "completed", "status_message": "", "collapse_time": float("nan"), "collapse_storey": "",
                "collapse_building": "", "collapse_cause": ""}
    p = int(raw.collapse_storey)
    building, storey, plane, _ = _plane_rows(model)[p]
    where = f"plane {p} ({plane.direction} at {plane.at:g} m)"
    cause = (f"{where} reached its ultimate drift (IMK plane at zero strength)" if raw.collapse_cause == "zero_strength"
             else f"{where} passed its collapse drift ratio {assembly.system.storey_stop_ratio[p]:g}")
    message = STATUS_MESSAGES[raw.status].format(t=raw.final_time, building=building, storey=f"{building}:{storey}",
                                                 cause=cause, dissipated=0.0, available=0.0)
    return {"status": STATUS_NAMES[raw.status], "status_message": message, "collapse_time": float(raw.final_time),
            "collapse_building": building, "collapse_storey": f"{building}:{storey}", "collapse_plane": p,
            "collapse_cause": raw.collapse_cause}


def plane_peaks(model: Model, assembly: Assembly, raw: RawSolution) -> dict[str, Any]:
    """The peaks of a run with plane rows as plain arrays (what studies keep of a run; :func:`run_peaks`).

    ``storey`` / ``storey_building`` / ``peak_drift_ratio``: per storey the largest peak |drift ratio| of its
    planes; ``plane`` / ``peak_plane_drift_ratio``: per plane; ``contact`` (each point ``A:1-B:1@(24,10)``),
    ``impact_count`` and ``peak_contact_force`` (N); the status and collapse as :func:`run_peaks`.
    """
    heights = np.array([h for *_, h in _plane_rows(model)], dtype=float)
    ratio = raw.peak_plane_drift / heights if heights.size else np.zeros(0)
    storeys = _storey_peaks(model, ratio)
    npt = assembly.n_points
    names = [b.name for b in model.buildings]
    status = plane_status(model, assembly, raw)
    return {
        "storey": [str(x) for x in storeys["storey"]],
        "storey_building": [str(x) for x in storeys["building"]],
        "plane": plane_labels(model),
        "contact": [g.label(names) for g in model.gaps],
        "peak_drift_ratio": storeys["peak"],
        "peak_plane_drift_ratio": ratio,
        "residual_drift_ratio": np.full(storeys["peak"].size, np.nan),
        "impact_count": (np.bincount(raw.impact_contact, minlength=npt)[:npt].astype(np.int32) if npt
                         else np.zeros(0, np.int32)),
        "peak_contact_force": raw.peak_contact_force[:npt],
        **{k: status[k] for k in ("status", "status_message", "collapse_time", "collapse_storey",
                                  "collapse_building", "collapse_cause")},
    }


def _ground_xy(supports, ground_state: Deferred) -> np.ndarray | None:
    """(nt, 2) the first building's ground acceleration along x and y at the output times, m/s² (*ground_state*:
    :func:`_plan_ground_state`)."""
    if supports is None or not supports.building_row_y:
        return None
    acceleration, _, _ = ground_state()
    return acceleration[:, [supports.building_row[0], supports.building_row_y[0]]]


def _plane_variables(model: Model, assembly: Assembly, raw: RawSolution, drift: np.ndarray) -> dict[str, tuple]:
    """The plane rows' histories and peaks: drift (m and ratio), shear, stiffness; per storey its largest ratio."""
    heights = np.array([h for *_, h in _plane_rows(model)], dtype=float)
    ratio = raw.peak_plane_drift / heights if heights.size else np.zeros(0)
    storeys = _storey_peaks(model, ratio)
    return {
        "plane_drift": _var(("time", "plane"), drift, "m", "drift of the plane's line"),
        "plane_drift_ratio": _var(("time", "plane"), Deferred(lambda: drift / heights), "1",
                                  "drift ratio of the plane (drift / storey height)"),
        "peak_plane_drift": _var(("plane",), raw.peak_plane_drift, "m", "peak |drift| of the plane (full resolution)"),
        "peak_plane_drift_ratio": _var(("plane",), ratio, "1", "peak |drift ratio| of the plane (full resolution)"),
        "plane_stiffness": _var(("plane",), assembly.plane_stiffness, "N/m", "elastic stiffness of the plane"),
        "plane_shear": _var(("time", "plane"), Deferred(lambda: _plane_shear(assembly, raw, drift)), "N",
                            "shear of the plane (restoring force, without P-Delta)"),
        "peak_drift_ratio": _var(("storey",), storeys["peak"], "1",
                                 "peak |drift ratio| of the storey: the largest of its planes' (full resolution)"),
    }


def _plane_coords(model: Model) -> dict[str, tuple]:
    """Coordinates of the plane rows (with their labels and heights) and of the storeys they make up."""
    rows = _plane_rows(model)
    storeys = _storey_peaks(model, np.zeros(len(rows)))
    return {"plane": ("plane", np.array(plane_labels(model), dtype=object),
                      {"long_name": "plane label building:storey:direction@line"}),
            "plane_height": ("plane", np.array([h for *_, h in rows], dtype=float),
                             {"units": "m", "long_name": "height of the plane's storey"}),
            "storey": ("storey", storeys["storey"], {"long_name": "storey label building:level"}),
            "storey_building": ("storey", storeys["building"], {"long_name": "building of the storey"}),
            "storey_level": ("storey", storeys["level"], {"units": "1", "long_name": "storey number above ground"}),
            "height": ("storey", storeys["height"], {"units": "m", "long_name": "storey height"})}


def _floor_coords(model: Model) -> dict[str, tuple]:
    """Each floor's label ``A:1`` and elevation (besides its building, 1-based level and centre of mass)."""
    return {"floor": ("floor", np.array([f"{b.name}:{i + 1}" for b in model.buildings for i in range(b.n_floors)],
                                        dtype=object), {"long_name": "floor label building:level"}),
            "elevation": ("floor", np.array([e for b in model.buildings for e in b.elevation], dtype=float),
                          {"units": "m", "long_name": "floor elevation above ground"})}


def _plan_run_attrs(model: Model, record: Record, raw: RawSolution, supports, *, end_time: float,
                    wall_time: float, status: dict[str, Any], archive: bool = True) -> dict[str, Any]:
    """A run's attributes with floors in plan: the model, the record pair and its factor, the solver, the status
    (*archive*: with ``run_spec``, :func:`run_arrays`)."""
    from pounding import __version__

    now = datetime.now(timezone.utc)
    components = [] if supports is None else [r for pair in zip(supports.records, supports.records_y) for r in pair]
    meta = record.metadata
    spec = {"model": model.to_document() if archive else "", "base_dir": model.ground_motion.base_dir,
            "record": str(model.ground_motion.record or record.source), "scale": float(meta.get(
        "scale_factor", record.scale)), "duration": float(end_time),
            "component_sha256": [None if r is None else str(r.metadata.get("sha256", "")) for r in components[:2]]}
    attrs = {"Conventions": "CF-1.10", "title": f"pounding plan run: {model.name}", "model": model.name,
             "kind": "plan_run", "source": f"pounding {__version__}", "references": REFERENCES,
             "history": f"{now.strftime('%Y-%m-%dT%H:%M:%SZ')} simulated with pounding {__version__}",
             "created": now.isoformat(), **_model_attrs(model), "run_spec": json.dumps(spec),
             "record_name": str(model.ground_motion.record or record.name), "record_source": record.source,
             "record_scale": float(meta.get("scale_factor", record.scale)),
             "record_scale_method": str(meta.get("scale_method", "factor")),
             "record_scale_description": str(meta.get("scale_description", f"factor {record.scale:g}")),
             "record_metadata": json.dumps(meta, default=str), "record_step": float(record.time_step),
             "angle": float(supports.angle if supports is not None and supports.angle is not None else 0.0),
             "end_time": float(end_time), "duration": float(end_time), "wall_time": float(wall_time),
             **_solver_attrs(model, raw),
             "hysteresis": json.dumps({b.name: [None if p.hysteresis is None else p.hysteresis.describe()
                                                for _, _, p in b.planes()] for b in model.buildings if b.is_inelastic})}
    attrs.update({k: v for k, v in status.items() if v != "" and not (isinstance(v, float) and np.isnan(v))})
    if model.contacts_held_open:
        attrs["contacts"] = (f"held open: every gap {model.gaps[0].gap:g} m, so no contact closes "
                             "(the run without pounding)")
    if not archive:
        del attrs["run_spec"]
    return attrs


def _plane_link_variables(model: Model, assembly: Assembly, raw: RawSolution, supports,
                          ground_state: Deferred) -> dict[str, tuple]:
    """The links' histories, peaks and energies of a run with floors in plan ({} without links; *ground_state*:
    :func:`_plan_ground_state`)."""
    if not model.links:
        return {}
    npt = assembly.n_points
    grounds = None
    if supports is not None and supports.rows.shape[0] > 1:
        grounds = ground_state()[2]
    links = _link_results(assembly.system, raw, npt, grounds, weighted=True)
    return {
        "link_force": _var(("time", "link"), raw.contact_force[:, npt:], "N",
                           "link force (> 0 pushes the floors apart, < 0 pulls them together)"),
        "link_deformation": _var(("time", "link"), links["deformation"], "m",
                                 "relative displacement of the link's two points along its normal, low side minus high"),
        "peak_link_force": _var(("link",), raw.peak_contact_force[npt:], "N",
                                "peak absolute link force, tracked on every step"),
        "link_dissipated_energy": _var(("link",), links["work"][-1] - links["stored"][-1], "J",
                                       "energy dissipated by the link over the run"),
        "energy_link_dissipated": _var(("time",), links["work"].sum(axis=1) - links["stored"].sum(axis=1), "J",
                                       "energy dissipated by the links"),
        "energy_link_strain": _var(("time",), links["stored"].sum(axis=1), "J", "elastic energy stored in the links"),
    }


def _link_coords(model: Model) -> dict[str, tuple]:
    """The ``link`` dimension's labels and laws ({} without links)."""
    if not model.links:
        return {}
    names = [b.name for b in model.buildings]
    return {"link": ("link", np.array([k.label(names) for k in model.links], dtype=object),
                     {"long_name": "link label left:level-right:level"}),
            "link_law": ("link", np.array([k.law.describe() for k in model.links], dtype=object),
                         {"long_name": "link element and its parameters"})}


def plane_dataset(model: Model, record: Record, assembly: Assembly, raw: RawSolution, *, end_time: float,
                  wall_time: float, supports=None) -> xr.Dataset:
    """The archive of a run with plane rows (floors in plan): floors per direction with their rotation and
    corners, planes (drift, drift ratio, shear), each storey's largest plane drift ratio, contact points,
    friction faces, impacts and the energy audit (:func:`plane_arrays`, made an ``xarray.Dataset``)."""
    return plane_arrays(model, record, assembly, raw, end_time=end_time, wall_time=wall_time,
                        supports=supports).to_dataset()


def _plan_absolute_acceleration(system: System, raw: RawSolution, supports, ground_state: Deferred) -> dict:
    """``absolute_acceleration`` (time, floor, direction) of a model in plan, m/s²: each floor centre's relative
    acceleration plus its building's ground acceleration along x and y (as a planar archive's ü + a_g); nothing
    without support motions."""
    if supports is None:
        return {}
    n = system.n_floors

    def values() -> np.ndarray:
        ground = np.take(ground_state()[0], system.floor_ground[:n], axis=1)
        return (raw.acceleration[:, :n] + ground).reshape(raw.time.size, -1, DOF_PER_FLOOR)[:, :, :2]

    return {"absolute_acceleration": _var(("time", "floor", "direction"), Deferred(values), "m/s²",
                                          "absolute acceleration of the floor's centre of mass (over the "
                                          "building's own ground)")}


def _plan_building_grounds(model: Model, supports, ground_state: Deferred) -> tuple[dict[str, tuple], dict]:
    """The ground under each building of a model in plan, as a planar archive has it (variables, coordinates):
    its acceleration, velocity and displacement along x and y at the output times (time, ground, direction) and
    its wave-passage lag; nothing without support motions.  A floor's displacement is relative to its own
    building's ground, so these are what put two buildings in one frame
    (:func:`pounding.results.plots.ground_offsets`)."""
    if supports is None:
        return {}, {}
    x, y = list(supports.building_row), list(supports.building_row_y)

    def along_xy(k: int) -> Deferred:
        def values() -> np.ndarray:
            rows = ground_state()[k]
            return np.stack([rows[:, x], rows[:, y] if y else np.zeros((rows.shape[0], len(x)))], axis=-1)
        return Deferred(values)

    dims = ("time", "ground", "direction")
    data = {"building_ground_acceleration": _var(dims, along_xy(0), "m/s²", "ground acceleration under the building"),
            "building_ground_velocity": _var(dims, along_xy(1), "m/s",
                                             "ground velocity under the building (exact integral from rest)"),
            "building_ground_displacement": _var(dims, along_xy(2), "m",
                                                 "ground displacement under the building (exact integral from rest)"),
            "ground_lag": _var(("ground",), np.array(supports.lag, dtype=float), "s",
                               "wave-passage time lag applied (rounded to the record step)"),
            "ground_lag_requested": _var(("ground",), np.array(supports.lag_requested, dtype=float), "s",
                                         "wave-passage time lag (position - first position) / apparent velocity")}
    coords = {"ground": ("ground", np.array([b.name for b in model.buildings], dtype=object),
                         {"long_name": "building standing on the ground"})}
    return data, coords


def plane_arrays(model: Model, record: Record, assembly: Assembly, raw: RawSolution, *, end_time: float,
                 wall_time: float, supports=None, archive: bool = True) -> RunArrays:
    """:func:`plane_dataset`'s variables, coordinates and attributes as plain arrays; *archive* as in
    :func:`run_arrays`."""
    system = assembly.system
    n = system.n_floors
    nf = n // DOF_PER_FLOOR
    npt = assembly.n_points
    u = raw.state[:, :n].reshape(-1, nf, DOF_PER_FLOOR)
    v = raw.state[:, n:2 * n].reshape(-1, nf, DOF_PER_FLOOR)
    # The histories no study's worker reads are Deferred (as in run_arrays): computed when read, all for an archive.
    ground_state = _plan_ground_state(supports, raw)
    delta = Deferred(lambda: _penetration(raw.state[:, :n], system, (
        ground_state()[2] if supports is not None else np.zeros((raw.time.size, 1)))))
    drift = raw.state[:, :n] @ assembly.plane_weights.T
    peak_u = raw.peak_displacement.reshape(nf, DOF_PER_FLOOR)
    counts = np.bincount(raw.impact_contact, minlength=npt)[:npt] if raw.impact_contact.size else np.zeros(npt, int)
    corner = corner_displacements(model, u)
    magnitude = np.hypot(corner[..., 0], corner[..., 1])
    points = np.array([g.point for g in model.gaps], dtype=float).reshape(npt, 2)
    location = points[raw.impact_contact] if raw.impact_contact.size else np.zeros((0, 2))
    impact_xi, restitution = _impact_law_values(model.gaps[:npt], raw)
    data = {
        "displacement": _var(("time", "floor", "direction"), u[:, :, :2], "m",
                             "displacement of the floor's centre of mass relative to the ground"),
        "rotation": _var(("time", "floor"), u[:, :, 2], "rad", "rotation of the floor, counter-clockwise"),
        "velocity": _var(("time", "floor", "direction"), v[:, :, :2], "m/s",
                         "velocity of the floor's centre of mass relative to the ground"),
        **_plan_absolute_acceleration(system, raw, supports, ground_state),
        "rotation_rate": _var(("time", "floor"), v[:, :, 2], "rad/s", "rotation rate of the floor"),
        "peak_displacement": _var(("floor", "direction"), peak_u[:, :2], "m",
                                  "peak |displacement| of the centre of mass (full resolution)"),
        "peak_rotation": _var(("floor",), peak_u[:, 2], "rad", "peak |rotation| of the floor (full resolution)"),
        "corner_displacement": _var(("time", "floor", "corner", "direction"), corner, "m",
                                    "displacement of the outline's corner (small rotations)"),
        "corner_displacement_magnitude": _var(("time", "floor", "corner"), magnitude, "m",
                                              "magnitude of the corner's displacement"),
        "peak_corner_displacement": _var(("floor", "corner", "direction"), np.abs(corner).max(axis=0, initial=0.0),
                                         "m", "peak |displacement| of the corner (stored samples)"),
        "peak_corner_displacement_magnitude": _var(("floor", "corner"), magnitude.max(axis=0, initial=0.0), "m",
                                                   "peak magnitude of the corner's displacement (stored samples)"),
        **_plane_variables(model, assembly, raw, drift),
        "contact_force": _var(("time", "contact"), raw.contact_force[:, :npt], "N",
                              "normal contact force at the point (compression positive)"),
        "penetration": _var(("time", "contact"), Deferred(lambda: delta()[:, :npt]), "m",
                            "penetration at the point (overlap positive)"),
        "peak_contact_force": _var(("contact",), raw.peak_contact_force[:npt], "N",
                                   "peak normal contact force at the point (full resolution)"),
        "impact_count": _var(("contact",), counts, "1", "number of impacts at the point"),
        "impact_contact": _var(("impact",), raw.impact_contact, "1", "contact point of the impact (index along contact)"),
        "impact_time": _var(("impact",), raw.impact_time, "s", "time of contact onset"),
        "impact_x": _var(("impact",), location[:, 0], "m", "x of the impact's contact point at rest"),
        "impact_y": _var(("impact",), location[:, 1], "m", "y of the impact's contact point at rest"),
        "impact_slip": _var(("impact",), _impact_slip(model, assembly, raw), "m",
                            "tangential slip of the face at the onset (low side minus high side, along +tangent)"),
        "impact_velocity": _var(("impact",), raw.impact_velocity, "m/s", "approach velocity at the point at onset"),
        "impact_peak_force": _var(("impact",), raw.impact_peak_force, "N", "peak force of the impact"),
        "impact_impulse": _var(("impact",), raw.impact_impulse, "N s", "impulse of the impact"),
        "impact_duration": _var(("impact",), raw.impact_end_time - raw.impact_time, "s",
                                "contact duration (nan if still in contact at the end)"),
        "impact_dissipated_energy": _var(("impact",), raw.impact_work, "J",
                                         "energy dissipated by the contact during the impact "
                                         "(work of the contact force; partial if still in contact at the end)"),
        "impact_xi": _var(("impact",), impact_xi, "N s m-2.5",
                          "Hertz-damp damping constant fixed at the onset (nan for other laws)"),
        "impact_restitution": _var(("impact",), restitution, "1",
                                   "separation velocity / approach velocity at the point (nan at zero approach "
                                   "velocity)"),
        **_trace_variables(raw),
        **_plane_yielding(assembly, raw),
    }
    data.update(_friction_variables(assembly, raw))
    data.update(_plane_link_variables(model, assembly, raw, supports, ground_state))
    for name, values in _plane_energies(assembly, raw, drift).items():
        label = name.removeprefix("energy_").replace("_", " ")
        data[name] = _var(("time",), values, "J", f"energy: {label}")
    ground = _ground_xy(supports, ground_state)
    if ground is not None:
        data["ground_acceleration"] = _var(("time", "direction"), ground, "m/s²", "ground acceleration along x and y")
    grounds, ground_coords = _plan_building_grounds(model, supports, ground_state)
    data.update(grounds)
    coords = {"time": ("time", raw.time, {"units": "s", "long_name": "time"}), **ground_coords,
              "direction": ("direction", np.array(["x", "y"], dtype=object), {"long_name": "plan direction"}),
              **_floor_coords(model), **_plan_floor_labels(model), **_plane_labels(model), **_plane_coords(model),
              **contact_coords(model), **_point_labels(model), **_face_labels(model, assembly), **_link_coords(model)}
    status = plane_status(model, assembly, raw)
    ds = RunArrays(data, _ragged_coords(data, coords, raw, "contact point"),
                   _plan_run_attrs(model, record, raw, supports, end_time=end_time, wall_time=wall_time,
                                   status=status, archive=archive))
    ds.attrs["energy_closure"] = plane_energy_closure(ds)
    ds.attrs["energy_closure_error"] = ds.attrs["energy_closure"]
    ds.attrs["title"] = f"pounding simulation of {run_title(ds)}"
    return ds


def _plan_ground_state(supports, raw: RawSolution) -> Deferred:
    """The ground rows' (acceleration, velocity, displacement) at the output times
    (:func:`pounding.solver.kinematics.ground_state_at`), worked out once when first read: the points'
    penetrations, the links and the archive's ground acceleration share them."""
    return Deferred(lambda: kinematics.ground_state_at(supports.rows, supports.time_step, raw.time))


def _trace_variables(raw: RawSolution) -> dict[str, tuple]:
    """Full-resolution samples of every closed contact (every solver step, on its interpolant)."""
    return {"trace_time": _var(("trace",), raw.trace_time, "s", "time of a full-resolution sample of a closed contact"),
            "trace_contact": _var(("trace",), raw.trace_contact.astype(np.int32), "1",
                                  "index of the contact point along the contact dimension"),
            "trace_penetration": _var(("trace",), raw.trace_penetration, "m",
                                      "penetration at the full-resolution sample"),
            "trace_force": _var(("trace",), raw.trace_force, "N", "contact force at the full-resolution sample")}


def _plane_yielding(assembly: Assembly, raw: RawSolution) -> dict[str, tuple]:
    """Each plane's yield drift and force and its peak ductility (NaN for an elastic plane; {} without yielding
    planes)."""
    system = assembly.system
    if system.storey_floors is None or not np.any(system.storey_state >= 0):
        return {}
    yielding = system.storey_state >= 0
    yield_drift = np.where(yielding, system.storey_parameters[:, 0], np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        ductility = raw.peak_plane_drift / yield_drift
    return {"plane_yield_drift": _var(("plane",), yield_drift, "m", "yield drift of the plane (NaN: elastic)"),
            "plane_yield_force": _var(("plane",), yield_drift * assembly.plane_stiffness, "N",
                                      "yield force of the plane (NaN: elastic)"),
            "peak_plane_ductility": _var(("plane",), ductility, "1",
                                         "peak |drift| of the plane over its yield drift (NaN: elastic)")}
