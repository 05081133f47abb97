"""Tables of an archive for reports: printed by ``pounding table``, written by ``--csv``.

Every archive kind has one function that turns its dataset into named
tables (``{name: pandas.DataFrame}``); the first table is the main one.
Headers carry the units of the archive's variables, ``name [unit]``
(``peak_drift_ratio [-]``, ``peak_contact_force [N]``); text and label
columns have none.  This module holds the kinds of this layer and below
(a run, a sweep); the studies' own kinds (compare, gap, IDA, verify) build
on :func:`long_table` in their modules.

:func:`write_csv` writes the main table to the file named and each other
table beside it as ``STEM.NAME.csv``; :func:`format_tables` is the text form.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

__all__ = ["header", "long_table", "run_tables", "sweep_tables", "scenario_dims", "write_csv", "csv_paths",
           "format_tables"]


def header(ds, name: str) -> str:
    """Column header of variable or coordinate *name*: ``name [units]``, ``[-]`` for a ratio or count.

    A variable without units (labels, text) keeps its bare name.
    """
    units = ds[name].attrs.get("units") if name in ds.variables else None
    if units is None or units == "":
        return name
    return f"{name} [{'-' if units == '1' else units}]"


def long_table(ds, names: Sequence[str], *, extra: Sequence[str] = ()):
    """Variables *names* (all on the same dimensions) as one long table, one row per element.

    Columns: one per dimension (its coordinate's values, or the position if
    it has none), then each of *extra* (variables or coordinates on a subset
    of those dimensions, repeated along the others), then each of *names*.
    Rows run in the variables' own order (last dimension fastest).

    Returns
    -------
    pandas.DataFrame
        Headers from :func:`header` (units in brackets).
    """
    import pandas as pd

    dims = ds[names[0]].dims
    shape = tuple(ds.sizes[d] for d in dims)
    index = {d: i.ravel() for d, i in zip(dims, np.indices(shape))} if dims else {}
    columns: dict[str, np.ndarray] = {}
    for d in dims:
        labels = ds[d].values if d in ds.coords else np.arange(ds.sizes[d])
        columns[header(ds, d) if d in ds.coords else d] = np.asarray(labels)[index[d]]
    for name in (*extra, *names):
        var = ds[name]
        if not set(var.dims) <= set(dims):
            raise ValueError(f"{name} has dimensions {var.dims}, not within {dims}")
        values = var.values
        columns[header(ds, name)] = values[tuple(index[d] for d in var.dims)] if var.dims else \
            np.repeat(values, int(np.prod(shape)))
    return pd.DataFrame(columns)


def _present(ds, names: Sequence[str]) -> list[str]:
    return [n for n in names if n in ds.variables]


def run_tables(ds) -> dict:
    """Tables of a run archive, of any model, those its dimensions call for.

    ``storeys`` (the main table: peak drift ratio, and drift, residual drift, ductility and hysteretic energy
    where the archive has them), ``planes`` where storeys are made of planes (peak drift and drift ratio per
    plane), ``floors`` (peak displacement per floor; in plan per floor and direction), ``rotations`` and
    ``corners`` where floors move in plan (peak rotation per floor, peak corner displacement per floor, corner
    and direction),
    ``contacts`` (gap, law, impacts, peak force; a contact point's location and normal) and ``links``.
    Floors and storeys are labelled ``A:1`` with their building and 1-based level.
    """
    storey = _present(ds, ["peak_drift_ratio", "peak_storey_drift", "residual_drift_ratio", "peak_ductility",
                           "storey_hysteretic_energy"])
    if "peak_ductility" in ds and not bool(np.isfinite(ds.peak_ductility.values).any()):
        storey = [n for n in storey if n not in ("residual_drift_ratio", "peak_ductility",
                                                 "storey_hysteretic_energy")]
    tables = {"storeys": long_table(ds, storey, extra=_present(ds, ["storey_building", "storey_level", "height"]))}
    if ds.sizes.get("plane", 0):
        tables["planes"] = long_table(ds, ["peak_plane_drift_ratio", "peak_plane_drift"], extra=_present(
            ds, ["plane_building", "plane_storey", "plane_direction", "plane_at", "plane_height", "plane_stiffness"]))
    floor = _present(ds, ["building", "level"])
    in_plan = "direction" in ds.peak_displacement.dims
    # every run's floors: peak displacement (in plan per direction); a planar run's with its elevation
    tables["floors"] = long_table(ds, ["peak_displacement"], extra=floor + ([] if in_plan else _present(
        ds, ["elevation"])))
    if in_plan:
        tables["rotations"] = long_table(ds, ["peak_rotation"], extra=floor)
        tables["corners"] = long_table(ds, ["peak_corner_displacement"], extra=floor + _present(
            ds, ["corner_x", "corner_y", "peak_corner_displacement_magnitude"]))
    if ds.sizes.get("contact", 0):
        tables["contacts"] = long_table(ds, ["impact_count", "peak_contact_force"], extra=_present(
            ds, ["building_left", "level_left", "building_right", "level_right", "gap", "law", "xi_formula",
                 "point_x", "point_y", "point_normal"]))
    if ds.sizes.get("link", 0):
        tables["links"] = long_table(ds, ["peak_link_force", "link_dissipated_energy"],
                                     extra=_present(ds, ["link_law"]))
    return tables


def scenario_dims(ds) -> tuple[str, ...]:
    """The scenario dimensions of a sweep-like study archive (those of its ``status``)."""
    return tuple(ds.status.dims)


def sweep_tables(ds) -> dict:
    """Tables of a sweep (or compare) archive: ``storeys`` (peak drift ratio per scenario and storey),
    ``contacts`` (impacts and peak force per scenario and contact) and ``scenarios`` (status, energy
    closure error, error message).  A failed scenario's values are NaN.

    Where the archive has them (floors in plan): ``planes`` (peak drift ratio and drift per scenario and
    plane), ``floors`` (peak displacement per scenario, floor and direction, and peak rotation) and ``corners``
    (peak corner displacement per scenario, floor and corner)."""
    tables = {"storeys": long_table(ds, ["peak_drift_ratio"], extra=_present(ds, ["status", "storey_building",
                                                                                   "storey_level"]))}
    if ds.sizes.get("contact", 0):
        tables["contacts"] = long_table(ds, _present(ds, ["impact_count", "peak_contact_force"]),
                                        extra=_present(ds, ["status", "point_x", "point_y", "point_normal"]))
    if ds.sizes.get("plane", 0):
        tables["planes"] = long_table(ds, ["peak_plane_drift_ratio", "peak_plane_drift"], extra=_present(
            ds, ["status", "plane_building", "plane_storey", "plane_direction", "plane_at"]))
    if "direction" in ds.dims and "peak_displacement" in ds:
        tables["floors"] = long_table(ds, ["peak_displacement"], extra=_present(ds, ["status", "building", "level",
                                                                                     "peak_rotation"]))
    if "peak_corner_displacement_magnitude" in ds:
        tables["corners"] = long_table(ds, ["peak_corner_displacement_magnitude"],
                                       extra=_present(ds, ["status", "building", "level"]))
    tables["scenarios"] = long_table(ds, _present(ds, ["status", "scale_factor", "intensity", "energy_closure_error",
                                                       "error"]))
    return tables


def csv_paths(path: str | os.PathLike, names: Sequence[str]) -> dict[str, Path]:
    """Where :func:`write_csv` puts each table: the first at *path*, table NAME at ``STEM.NAME.csv`` beside it."""
    target = Path(path)
    stem = target.name[:-4] if target.name.lower().endswith(".csv") else target.name
    return {name: target if i == 0 else target.with_name(f"{stem}.{name}.csv") for i, name in enumerate(names)}


def write_csv(tables: dict, path: str | os.PathLike) -> list[Path]:
    """Write *tables* as CSV files (see :func:`csv_paths`), each atomically; the folder is created if needed.

    Floats are written with every digit (they read back exactly); NaN is an empty cell.

    Returns
    -------
    list of pathlib.Path
        The files written, the main table first.
    """
    from pounding.results.archive import atomic_path

    written = []
    for name, target in csv_paths(path, list(tables)).items():
        target.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(target) as temporary:
            tables[name].to_csv(temporary, index=False)
        written.append(target)
    return written


def format_tables(tables: dict, title: str = "") -> str:
    """The tables as text: *title*, then each table under its name, all rows and columns."""
    lines = [title] if title else []
    for name, frame in tables.items():
        lines += ["", f"{name}:", frame.to_string(index=False, max_rows=None, max_cols=None, float_format="{:.6g}".format)]
    return "\n".join(lines).lstrip("\n")
