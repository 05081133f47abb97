"""Plausibility checks of a run: the unit mistakes that give results without an error.

Each check returns warnings, never raises: a value outside the usual range
may be meant (a 4 g near-fault pulse, a gap of a seismic joint wider than a
storey), so the run goes on and the user reads one line.  The rules (docs/cli.md,
"Warnings"):

* ``pga``: the scaled record's PGA above :data:`PGA_LIMIT_G` (3 g) — not in an
  IDA, whose top stripes go there on purpose;
* ``units``: a record declared in g whose own PGA exceeds :data:`G_RECORD_LIMIT_G`
  (2.5 g: likely m/s² or cm/s² read as g), or a record in m/s² or cm/s² whose PGA is
  below :data:`SI_RECORD_FLOOR` (0.1 m/s²: likely values in g read as m/s²);
* ``gap``: a contact's gap wider than a storey of either building it joins
  (likely millimetres written as metres);
* ``drift``: an elastic building (no storey hysteresis) whose peak storey drift
  ratio exceeds :data:`ELASTIC_DRIFT_LIMIT` (10 %: far past any elastic range);
* ``axis``: a numeric sweep axis whose sorted values jump by a factor of
  :data:`AXIS_JUMP` (100) or more between neighbours (likely a value in other units).

A run reports each kind at most once (:func:`run_warnings`); a study (compare,
gap, sweep) gathers its runs' warnings and reports each kind once, with how
many runs it hit (:func:`study_warnings`).  The command line prints them as
``pounding: warning: ...`` on stderr.
"""

from __future__ import annotations

import json
import math
from typing import Any, Iterable, Sequence

from pounding.model.model import OPEN_GAP, WALL
from pounding.units import STANDARD_GRAVITY

__all__ = ["PGA_LIMIT_G", "G_RECORD_LIMIT_G", "SI_RECORD_FLOOR", "ELASTIC_DRIFT_LIMIT", "AXIS_JUMP",
           "record_warnings", "gap_warnings", "drift_warnings", "run_warnings", "study_warnings", "axis_warning",
           "model_warnings", "print_warnings"]

#: Scaled PGA (g) above which a run outside an IDA is flagged.
PGA_LIMIT_G = 3.0
#: Own PGA (g) above which a record declared in g is flagged.
G_RECORD_LIMIT_G = 2.5
#: Own PGA (m/s²) below which a record declared in m/s² or cm/s² is flagged.
SI_RECORD_FLOOR = 0.1
#: Peak storey drift ratio above which an elastic building is flagged.
ELASTIC_DRIFT_LIMIT = 0.10
#: Ratio between neighbouring sorted values of a numeric sweep axis that is flagged.
AXIS_JUMP = 100.0


def record_warnings(name: str, units: str | None, pga: float, scaled_pga: float, *,
                    ida: bool = False) -> dict[str, str]:
    """The ``units`` and ``pga`` warnings of one record.

    Parameters
    ----------
    name : str
        The record, as the message names it.
    units : str or None
        The units the record was read in (``g``, ``m/s2``, ``cm/s2``); None: unknown.
    pga, scaled_pga : float
        Its own PGA and the PGA as run, m/s².
    ida : bool
        An IDA's run: no ``pga`` warning.
    """
    found = {}
    if units == "g" and pga > G_RECORD_LIMIT_G * STANDARD_GRAVITY:
        found["units"] = (f"record {name} is declared in g but its PGA is {pga / STANDARD_GRAVITY:.3g} g (more than "
                          f"{G_RECORD_LIMIT_G:g} g): are its values in m/s2 or cm/s2?")
    elif units in ("m/s2", "cm/s2") and pga < SI_RECORD_FLOOR:
        found["units"] = (f"record {name} is declared in {units} but its PGA is {pga:.3g} m/s2 (less than "
                          f"{SI_RECORD_FLOOR:g} m/s2): are its values in g?")
    if not ida and scaled_pga > PGA_LIMIT_G * STANDARD_GRAVITY:
        found["pga"] = (f"record {name} is scaled to a PGA of {scaled_pga / STANDARD_GRAVITY:.3g} g (more than "
                        f"{PGA_LIMIT_G:g} g): check the scale factor or target")
    return found


def gap_warnings(contacts: Sequence[str], gaps: Sequence[float], storey_heights: Sequence[float]) -> dict[str, str]:
    """The ``gap`` warning: a contact whose gap (m) exceeds the lowest of *storey_heights* (m, per contact: of the
    buildings it joins); a contact held open (:data:`pounding.model.model.OPEN_GAP`) passes."""
    for label, gap, height in zip(contacts, gaps, storey_heights):
        if height < gap < OPEN_GAP:
            return {"gap": f"contact {label} has a gap of {gap:g} m, more than a storey height ({height:g} m): "
                           "is it in mm or cm instead of m?"}
    return {}


def drift_warnings(buildings: Sequence[str], peak_drift: Sequence[float], elastic: Iterable[str]) -> dict[str, str]:
    """The ``drift`` warning: an elastic building whose largest peak storey drift ratio exceeds
    :data:`ELASTIC_DRIFT_LIMIT` (*peak_drift* per storey, *buildings* its building)."""
    elastic = set(elastic)
    worst: dict[str, float] = {}
    for building, drift in zip(buildings, peak_drift):
        if building in elastic and math.isfinite(drift):
            worst[building] = max(worst.get(building, 0.0), float(drift))
    for building, drift in worst.items():
        if drift > ELASTIC_DRIFT_LIMIT:
            return {"drift": f"elastic building {building} reaches a peak storey drift ratio of {100 * drift:.3g} % "
                             f"(more than {100 * ELASTIC_DRIFT_LIMIT:g} %, far past any elastic range): check "
                             "the record's units and scale, the masses and the stiffnesses"}
    return {}


def run_warnings(ds, *, gaps: Sequence[float] | None = None, ida: bool = False) -> dict[str, str]:
    """Every warning of a run's results dataset, by kind (``units``, ``pga``, ``gap``, ``drift``).

    *gaps* (m, per contact) replaces the archived gaps: a run with its contacts held open checks the model's own.
    """
    from pounding.results.dataset import record_pga

    meta = json.loads(ds.attrs.get("record_metadata", "{}"))
    pga, scaled = record_pga(ds)
    found = record_warnings(str(ds.attrs.get("record_name", "")), meta.get("original_units"), pga, scaled, ida=ida)
    heights = {}
    for building, height in zip(ds.storey_building.values, ds.height.values):
        heights[str(building)] = min(heights.get(str(building), math.inf), float(height))
    lowest = [min(heights.get(str(a), math.inf), heights.get(str(b), math.inf))
              for a, b in zip(ds.building_left.values, ds.building_right.values)]
    found.update(gap_warnings([str(c) for c in ds.contact.values],
                              [float(g) for g in (ds.gap.values if gaps is None else gaps)], lowest))
    inelastic = json.loads(ds.attrs.get("hysteresis", "{}"))
    found.update(drift_warnings([str(b) for b in ds.storey_building.values], ds.peak_drift_ratio.values,
                                [name for name in heights if name not in inelastic]))
    return found


def model_warnings(model) -> dict[str, str]:
    """The ``gap`` warning of a :class:`~pounding.model.model.Model` before any run (what ``pounding ida`` checks
    once: its runs are not checked one by one)."""
    names = [b.name for b in model.buildings]
    lowest = [min(float(min(model.buildings[i].height)) for i in (g.left, g.right) if i != WALL) for g in model.gaps]
    return gap_warnings([g.label(names) for g in model.gaps], [g.gap for g in model.gaps], lowest)


def study_warnings(per_run: Iterable[dict[str, str] | None]) -> list[str]:
    """One line per kind over a study's runs: the first run's message and how many runs the kind hit."""
    first: dict[str, str] = {}
    count: dict[str, int] = {}
    total = 0
    for found in per_run:
        total += 1
        for kind, message in (found or {}).items():
            first.setdefault(kind, message)
            count[kind] = count.get(kind, 0) + 1
    return [f"{message} ({count[kind]} of {total} runs)" if total > 1 else message
            for kind, message in first.items()]


def axis_warning(name: str, values: Sequence[Any], units: str | None = None) -> str | None:
    """The ``axis`` warning of one sweep axis: neighbouring sorted values a factor :data:`AXIS_JUMP` or more apart."""
    numbers = sorted(float(v) for v in values if isinstance(v, (int, float)) and not isinstance(v, bool)
                     and math.isfinite(v) and v > 0)
    for low, high in zip(numbers, numbers[1:]):
        if high >= AXIS_JUMP * low:
            unit = f" {units}" if units and units != "1" else ""
            return (f"axis {name} jumps from {low:g} to {high:g}{unit} (a factor {high / low:.3g}): is one value "
                    "in other units?")
    return None


def print_warnings(messages: Iterable[str], stream: Any = None) -> None:
    """Each message as one line ``pounding: warning: <message>`` on *stream* (default: stderr)."""
    import sys

    for message in messages:
        print(f"pounding: warning: {message}", file=stream or sys.stderr)
