"""What the report says of each archive kind: the excitation ("under what") and the run status.

One :class:`Kind` per archive kind :func:`pounding.cli.run.open_archive`
recognises, in :data:`KINDS`.  A new archive kind (a new study) adds its
entry with :func:`register`; what every kind shares — the model, the
summary ``pounding info`` prints, the tables of ``pounding table``, the
figures of ``pounding plot``, the warnings and the command — is read in
:mod:`pounding.cli.report.sections` without an entry here.
"""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass
from typing import Callable

import numpy as np

from pounding.errors import ArchiveError

__all__ = ["Kind", "KINDS", "register", "kind_of", "attribute_rows", "study_errors"]

Rows = list[tuple[str, str]]


@dataclass(frozen=True)
class Kind:
    """An archive kind: *what* it is in words, its *excitation* rows and *status* rows (label, text)."""
    name: str
    what: str
    excitation: Callable[[object], Rows]
    status: Callable[[object], Rows]


#: Every archive kind the report knows, by the name ``open_archive`` gives it.
KINDS: dict[str, Kind] = {}


def register(name: str, what: str, excitation: Callable[[object], Rows], status: Callable[[object], Rows]) -> Kind:
    """Add (or replace) the archive kind *name* in :data:`KINDS`; returns it."""
    KINDS[name] = Kind(name, what, excitation, status)
    return KINDS[name]


def kind_of(name: str, source: str) -> Kind:
    """The :class:`Kind` called *name*; one line naming the archive *source* if the report does not know it.

    Raises
    ------
    ArchiveError
    """
    if name not in KINDS:
        raise ArchiveError(f"{source}: `pounding report` does not know {name} archives (it reports "
                           f"{', '.join(sorted(KINDS))}); use `pounding info` and `pounding table` on it")
    return KINDS[name]


def attribute_rows(ds, labels: dict[str, str]) -> Rows:
    """(label, value) of each attribute of *labels* (attribute → label) the archive has and is not empty."""
    rows = []
    for name, label in labels.items():
        value = ds.attrs.get(name)
        if value is None or (isinstance(value, str) and not value.strip()):
            continue
        if isinstance(value, (float, np.floating)) and np.isnan(value):
            continue
        rows.append((label, f"{value:.6g}" if isinstance(value, (float, np.floating)) else str(value)))
    return rows


# --------------------------------------------------------------------------- #
# One run
# --------------------------------------------------------------------------- #


def _run_excitation(ds) -> Rows:
    from pounding.results.describe import record_event, scale_text

    attrs = ds.attrs
    rows: Rows = []
    if attrs.get("multi_support") == "per-building records" and "ground_record" in ds:
        rows += [(f"record of {g}", f"{rec}, scale factor {float(s):.6g}") for g, rec, s in
                 zip(ds.ground.values, ds.ground_record.values, ds.ground_scale.values)]
    else:
        event = record_event(ds)
        rows.append(("record", f"{attrs.get('record_name', '')}{f' ({event})' if event else ''}"))
        rows.append(("intensity", scale_text(float(attrs.get("record_scale", 1.0)),
                                             str(attrs.get("record_scale_method", "factor")),
                                             str(attrs.get("record_scale_description", "")))))
    if attrs.get("multi_support"):
        rows.append(("ground", str(attrs["multi_support"])))
    if "angle" in attrs:
        rows.append(("angle of the record pair", f"{float(attrs['angle']):g}°"))
    rows += attribute_rows(ds, {"record_sha256": "record samples (SHA-256)", "contacts": "contacts"})
    rows.append(("duration", f"{float(attrs.get('duration', np.nan)):g} s"))
    return rows


def _run_status(ds) -> Rows:
    attrs = ds.attrs
    rows: Rows = [("status", str(attrs.get("status", "")))]
    closure = attrs.get("energy_closure_error")
    if closure is not None:
        rows.append(("energy closure error", f"{float(closure):.3g} ({attrs.get('energy_status', 'not judged')})"))
    if attrs.get("collapse_building"):
        rows.append(("collapse", f"building {attrs['collapse_building']}, storey {attrs.get('collapse_storey', '')} at "
                                 f"{float(attrs.get('collapse_time', np.nan)):.3f} s ({attrs.get('collapse_cause', '')})"))
    rows.append(("solver", f"{attrs.get('solver_steps', '?')} steps ({attrs.get('solver_rejected_steps', '?')} rejected), "
                           f"rtol {attrs.get('solver_rtol', '?')}, {float(attrs.get('wall_time', np.nan)):.3g} s"))
    return rows


# --------------------------------------------------------------------------- #
# Studies of many runs
# --------------------------------------------------------------------------- #

_STUDY_ATTRIBUTES = {"records_spec": "records", "im_description": "intensity measure", "scaling": "scaling",
                     "method": "method", "hunt": "hunt", "hazard": "hazard curve", "sdc": "seismic design category",
                     "s_ms": "S_MS (g)", "s_m1": "S_M1 (g)", "spectrum_source": "spectrum",
                     "analysis": "analysis", "collapse_drift": "collapse drift ratio", "mce": "MCE intensity"}


def _values(ds, name: str) -> np.ndarray:
    return np.asarray(ds[name].values).ravel()


def _labelled(ds, name: str) -> list[tuple[str, object]]:
    """Each element of variable *name* with its label: its coordinates joined by ``/`` (``with_contacts/A``)."""
    var = ds[name]
    labels = [ds[d].values if d in ds.coords else np.arange(ds.sizes[d]) for d in var.dims]
    return [("/".join(str(labels[k][i]) for k, i in enumerate(index)) or name, var.values[index])
            for index in np.ndindex(var.shape)]


def _study_excitation(ds) -> Rows:
    rows: Rows = []
    attributes = dict(_STUDY_ATTRIBUTES)
    if "record" in ds.coords:
        records = [str(r) for r in _values(ds, "record")]
        rows.append((f"records ({len(records)})", ", ".join(records)))
        attributes.pop("records_spec")
    rows += attribute_rows(ds, attributes)
    for name, label in (("scale_factor", "scale factors"), ("intensity", "intensities")):
        if name in ds.variables:
            values = _values(ds, name).astype(float)
            values = values[np.isfinite(values)]
            if values.size:
                units = ds[name].attrs.get("units", "")
                rows.append((label, f"{values.min():.4g} to {values.max():.4g}{f' {units}' if units not in ('', '1') else ''}"
                                    f" ({np.unique(values).size} distinct)"))
    if "axes" in ds.attrs:
        rows.append(("axes", ", ".join(f"{k}: {v}" for k, v in json.loads(ds.attrs["axes"]).items())))
    return rows


def _study_status(ds) -> Rows:
    rows: Rows = []
    if "status" in ds.variables:
        counts = Counter(str(s) for s in _values(ds, "status"))
        rows.append(("runs", ", ".join(f"{n} {s}" for s, n in counts.most_common())))
    if "collapsed" in ds.variables:
        collapsed = _values(ds, "collapsed")
        rows.append(("collapsed", f"{int(np.sum(collapsed == True))} of {collapsed.size} building-runs"))  # noqa: E712
    if "energy_closure_error" in ds.variables:
        closure = _values(ds, "energy_closure_error").astype(float)
        closure = closure[np.isfinite(closure)]
        if closure.size:
            rows.append(("energy closure error", f"largest {closure.max():.3g} over {closure.size} runs"))
    if "passes" in ds.variables:
        rows.append(("passes", ", ".join(f"{label}: {'yes' if p else 'no'}" for label, p in _labelled(ds, "passes"))))
    rows += attribute_rows(ds, {"n_run": "runs made by this invocation", "elapsed_time": "elapsed time (s)"})
    return rows


def study_errors(ds) -> list[str]:
    """Each distinct error message of the study's failed runs, with how many runs it ended."""
    if "error" not in ds.variables:
        return []
    counts = Counter(str(e) for e in _values(ds, "error") if str(e).strip() and str(e) != "nan")
    return [f"{message} ({n} run{'s' if n != 1 else ''})" for message, n in counts.most_common()]


# --------------------------------------------------------------------------- #
# Tests of one building or storey, and the verification
# --------------------------------------------------------------------------- #


def _pushover_excitation(ds) -> Rows:
    return attribute_rows(ds, {"pattern": "load pattern", "steps": "steps"})


def _hysteresis_excitation(ds) -> Rows:
    return attribute_rows(ds, {"storey": "storey", "hysteresis": "hysteresis", "stiffness": "stiffness (N/m)",
                               "height": "height (m)", "protocol": "protocol",
                               "amplitude_drift_ratio": "amplitude (drift ratio)"})


def _end_status(ds) -> Rows:
    if "end" in ds.variables:
        return [("end", ", ".join(f"{label}: {e}" for label, e in _labelled(ds, "end")))]
    return [("steps", str(ds.sizes.get("step", "")))]


def _verify_excitation(ds) -> Rows:
    return attribute_rows(ds, {"settings": "settings"})


def _code_check_excitation(ds) -> Rows:
    rows = attribute_rows(ds, {"code": "code", "rule": "rule", "statistic": "statistic of the records",
                               "spectrum_options": "design spectrum", "verdict_intensity": "verdict at"})
    if "records" in ds.attrs:
        records = json.loads(ds.attrs["records"])
        rows.append(("records", f"{len(records)}: {', '.join(map(str, records[:6]))}{' ...' if len(records) > 6 else ''}"))
    return rows


def _code_check_status(ds) -> Rows:
    """The check's answer per pair of buildings, in its own words."""
    return [("answer", line) for line in str(ds.attrs.get("answers", "")).splitlines() if line.strip()]


register("run", "one run", _run_excitation, _run_status)
register("gap-code", "a check of the gap against a code and the records", _code_check_excitation,
         _code_check_status)
for _name, _what in (("sweep", "a sweep"), ("compare", "a comparison"), ("gap", "a separation study"),
                     ("ida", "an incremental dynamic analysis"), ("risk", "a site risk study"),
                     ("p695", "a FEMA P695 evaluation")):
    register(_name, _what, _study_excitation, _study_status)
register("pushover", "a pushover", _pushover_excitation, _end_status)
register("hysteresis", "a cyclic storey test", _hysteresis_excitation, _end_status)
register("verify", "the contact-law verification", _verify_excitation, lambda ds: [])
