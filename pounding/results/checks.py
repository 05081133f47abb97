"""Plausibility checks of a run: the unit mistakes that give results without an error.

Each check returns warnings, never raises: a value outside the usual range
may be meant (a 4 g near-fault pulse, a gap of a seismic joint wider than a
storey), so the run goes on and the user reads one line.  The rules (docs/cli.md,
"Warnings"):

* ``pga``: the scaled record's PGA above :data:`PGA_LIMIT_G` (3 g) — not in an
  IDA, whose top stripes go there on purpose;
* ``units``: a record declared in g whose own PGA exceeds :data:`G_RECORD_STRONG_G`
  (1.5 g: likely m/s² read as g; above :data:`G_RECORD_LIMIT_G`, 2.5 g, m/s² or cm/s²),
  or a record in m/s² or cm/s² whose PGA is below :data:`SI_RECORD_FLOOR_G` (0.05 g:
  likely values in g read as m/s²) — the record's own PGA in its declared units, before
  any scaling (an IDA's records too);
* ``spectrum``: a design spectrum's S_DS, S_D1, S_MS, S_M1 or a_g above
  :data:`SPECTRAL_LIMIT_G` (3 g: likely m/s² or % of g given as g);
* ``period``: a building of more than one storey whose fundamental period is below
  :data:`SHORT_PERIOD` (0.05 s: likely floor masses in tonnes), or any building's above
  :data:`LONG_PERIOD` (10 s: likely storey stiffnesses in kN/m);
* ``gap``: a contact's gap wider than a storey of either building it joins
  (likely millimetres written as metres);
* ``drift``: an elastic building (no storey hysteresis) whose peak storey drift
  ratio exceeds :data:`ELASTIC_DRIFT_LIMIT` (10 %: far past any elastic range);
* ``axis``: a numeric sweep axis whose sorted values jump by a factor of
  :data:`AXIS_JUMP` (100) or more between neighbours (likely a value in other units).

A run reports each kind at most once (:func:`run_warnings`); a study (compare,
gap, sweep) gathers its runs' warnings and reports each kind once, with how
many runs it hit (:func:`study_warnings`).  A study that does not check its runs one
by one (ida, p695, gap --code) checks the model (:func:`model_warnings`), its records
as read (:func:`ground_motion_warnings`) and its spectrum (:func:`spectrum_warnings`)
once.  The command line prints them as
``pounding: warning: ...`` on stderr.
"""

from __future__ import annotations

import json
import math
from typing import Any, Iterable, Sequence

from pounding.model.model import OPEN_GAP, WALL
from pounding.units import STANDARD_GRAVITY

__all__ = ["PGA_LIMIT_G", "G_RECORD_LIMIT_G", "G_RECORD_STRONG_G", "SI_RECORD_FLOOR_G", "SPECTRAL_LIMIT_G",
           "SHORT_PERIOD", "LONG_PERIOD", "ELASTIC_DRIFT_LIMIT", "AXIS_JUMP",
           "record_warnings", "ground_motion_warnings", "spectrum_warnings", "period_warnings", "gap_warnings",
           "drift_warnings", "run_warnings", "study_warnings", "axis_warning", "model_warnings", "print_warnings"]

#: Scaled PGA (g) above which a run outside an IDA is flagged.
PGA_LIMIT_G = 3.0
#: Own PGA (g) above which a record declared in g is flagged as m/s² or cm/s² values (a cm/s² record read as g
#: lands far above it).
G_RECORD_LIMIT_G = 2.5
#: Own PGA (g) above which a record declared in g is flagged as m/s² values: a record of 0.15-0.25 g in m/s² read
#: as g runs at 1.5-2.5 g.  Few records ever reached 1.5 g; the strongest of the shipped catalogue and the FEMA
#: P695 sets is 1.43 g (Cape Mendocino 1992, CPM 350), so none of them is flagged.
G_RECORD_STRONG_G = 1.5
#: Own PGA (g) below which a record declared in m/s² or cm/s² is flagged: a record of 0.1-0.49 g in g read as m/s²
#: has 0.01-0.05 g, weaker than the motions a pounding study is run for.
SI_RECORD_FLOOR_G = 0.05
#: A design spectrum's parameter (S_DS, S_D1, S_MS, S_M1, a_g; g) above which it is flagged: twice the S_MS of
#: FEMA P695's highest design category (Dmax, 1.5 g; FEMA P695 2009, Table 5-1A); the value in m/s² is 9.81 times,
#: in % of g 100 times the value in g, so most such mistakes land above it.
SPECTRAL_LIMIT_G = 3.0
#: Fundamental period (s) below which a building of more than one storey is flagged: floor masses in tonnes read as
#: kg divide the periods by 31.6 (sqrt 1000); a single storey may be that stiff (a one-storey wall building).
SHORT_PERIOD = 0.05
#: Fundamental period (s) above which a building is flagged: storey stiffnesses in kN/m read as N/m multiply the
#: periods by 31.6.
LONG_PERIOD = 10.0
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
    in_g = pga / STANDARD_GRAVITY
    if units == "g" and in_g > G_RECORD_STRONG_G:
        limit, which = (G_RECORD_LIMIT_G, "m/s2 or cm/s2") if in_g > G_RECORD_LIMIT_G else (G_RECORD_STRONG_G, "m/s2")
        found["units"] = (f"record {name} is declared in g but its PGA is {in_g:.3g} g (more than {limit:g} g): "
                          f"are its values in {which}?")
    elif units in ("m/s2", "cm/s2") and in_g < SI_RECORD_FLOOR_G:
        found["units"] = (f"record {name} is declared in {units} but its PGA is {pga:.3g} m/s2 ({in_g:.3g} g, less "
                          f"than {SI_RECORD_FLOOR_G:g} g): are its values in g?")
    if not ida and scaled_pga > PGA_LIMIT_G * STANDARD_GRAVITY:
        found["pga"] = (f"record {name} is scaled to a PGA of {scaled_pga / STANDARD_GRAVITY:.3g} g (more than "
                        f"{PGA_LIMIT_G:g} g): check the scale factor or target")
    return found


def ground_motion_warnings(name: str, records: Sequence, factor: float = 1.0, *, ida: bool = False) -> dict[str, str]:
    """The ``units`` and ``pga`` warnings of a ground motion before it runs (:func:`record_warnings` of each record).

    Parameters
    ----------
    name : str
        The ground motion, as the message names it (a pair's components are named by their own names).
    records : sequence of pounding.records.record.Record
        Its record, or a pair's two components, as read (their own PGA: the file's ``pga_g``).
    factor : float
        The factor it runs at, on top of the records' own scale.
    ida : bool
        An IDA's records: no ``pga`` warning.
    """
    from pounding.results.dataset import loaded_record_pga

    found: dict[str, str] = {}
    for record in records:
        own, as_read = loaded_record_pga(record)
        label = name if len(records) == 1 else f"{name} ({record.name})"
        for kind, message in record_warnings(label, record.metadata.get("original_units"), own, as_read * factor,
                                             ida=ida).items():
            found.setdefault(kind, message)
    return found


def spectrum_warnings(parameters: dict[str, float | None]) -> dict[str, str]:
    """The ``spectrum`` warning: the design spectrum's *parameters* (name → value in g, None: not given) above
    :data:`SPECTRAL_LIMIT_G`, all named in one line."""
    high = [f"{name} = {value:g} g" for name, value in parameters.items()
            if value is not None and value > SPECTRAL_LIMIT_G]
    if not high:
        return {}
    one = len(high) == 1
    return {"spectrum": f"{' and '.join(high)} {'is' if one else 'are'} more than {SPECTRAL_LIMIT_G:g} g: "
                        f"{'is it' if one else 'are they'} given in m/s2 or in % of g?"}


def period_warnings(periods: dict[str, float], storeys: dict[str, int]) -> dict[str, str]:
    """The ``period`` warning: the first building (name → fundamental period, s; name → storeys) of more than one
    storey whose period is below :data:`SHORT_PERIOD`, or whose period is above :data:`LONG_PERIOD`."""
    for name, period in periods.items():
        count = storeys.get(name, 1)
        if count > 1 and period < SHORT_PERIOD:
            return {"period": f"building {name} ({count} storeys) has a fundamental period of {period:.3g} s (less "
                              f"than {SHORT_PERIOD:g} s): are its floor masses in tonnes instead of kg?"}
        if period > LONG_PERIOD:
            return {"period": f"building {name} has a fundamental period of {period:.3g} s (more than "
                              f"{LONG_PERIOD:g} s): are its storey stiffnesses in kN/m instead of N/m?"}
    return {}


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
    """Every warning of a run's results dataset, by kind (``units``, ``pga``, ``period``, ``gap``, ``drift``).

    *gaps* (m, per contact) replaces the archived gaps: a run with its contacts held open checks the model's own.
    """
    from pounding.results.dataset import record_pga

    meta = json.loads(ds.attrs.get("record_metadata", "{}"))
    pga, scaled = record_pga(ds)
    found = record_warnings(str(ds.attrs.get("record_name", "")), meta.get("original_units"), pga, scaled, ida=ida)
    heights: dict[str, float] = {}
    storeys: dict[str, int] = {}
    for building, height in zip(ds.storey_building.values, ds.height.values):
        heights[str(building)] = min(heights.get(str(building), math.inf), float(height))
        storeys[str(building)] = storeys.get(str(building), 0) + 1
    periods = json.loads(ds.attrs.get("periods", "{}"))   # per building, longest first (s)
    found.update(period_warnings({name: max(values) for name, values in periods.items() if values}, storeys))
    lowest = [min(heights.get(str(a), math.inf), heights.get(str(b), math.inf))
              for a, b in zip(ds.building_left.values, ds.building_right.values)]
    found.update(gap_warnings([str(c) for c in ds.contact.values],
                              [float(g) for g in (ds.gap.values if gaps is None else gaps)], lowest))
    inelastic = json.loads(ds.attrs.get("hysteresis", "{}"))
    found.update(drift_warnings([str(b) for b in ds.storey_building.values], ds.peak_drift_ratio.values,
                                [name for name in heights if name not in inelastic]))
    return found


def model_warnings(model) -> dict[str, str]:
    """The ``period`` and ``gap`` warnings of a :class:`~pounding.model.model.Model` before any run (what ``ida``,
    ``p695`` and ``gap --code`` check once: their runs are not checked one by one)."""
    names = [b.name for b in model.buildings]
    lowest = [min(float(min(model.buildings[i].height)) for i in (g.left, g.right) if i != WALL) for g in model.gaps]
    found = period_warnings({name: float(max(periods)) for name, periods in model.periods.items()},
                            {b.name: b.n_floors for b in model.buildings})
    found.update(gap_warnings([g.label(names) for g in model.gaps], [g.gap for g in model.gaps], lowest))
    return found


def study_warnings(per_run: Iterable[dict[str, str] | None], what: str = "runs") -> list[str]:
    """One line per kind over a study's runs (or *what* the study counts: ``records``): the first run's message and
    how many runs the kind hit."""
    first: dict[str, str] = {}
    count: dict[str, int] = {}
    total = 0
    for found in per_run:
        total += 1
        for kind, message in (found or {}).items():
            first.setdefault(kind, message)
            count[kind] = count.get(kind, 0) + 1
    return [f"{message} ({count[kind]} of {total} {what})" if total > 1 else message
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
