"""Record files: PEER NGA ``.AT2`` and plain text (one column with dt, or time and acceleration).

Every problem is a :class:`~pounding.errors.RecordError` with a one-line
message ``file:line: what is wrong and the fix``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from pounding.errors import RecordError
from pounding.records.record import DT_RTOL, Record, check_time_step, normalise_units, positive_value
from pounding.units import FORTRAN_NUMBER, STANDARD_GRAVITY, UNITS, canonical_unit

__all__ = ["read_at2", "read_text", "check_agrees", "text_header", "declared_in_header", "header_declares_units",
           "FIXES"]

#: How to give a text record's units and time step, by where the record was named:
#: in a model YAML (``yaml``), on the command line (``cli``) or to the Python API (``api``).
FIXES = {
    "yaml": {"units": "a text record needs its units; add 'units: g' (or m/s2, cm/s2, gal) to the YAML "
                      "ground_motion section",
             "dt": "a one-column record needs its time step; add 'dt: <seconds>' to the YAML ground_motion "
                   "section (or add a time column)",
             "dt_given": "ground_motion.dt",
             "remove": "remove {what} from the YAML ground_motion section"},
    "cli": {"units": "a text record needs its units; give them on the command line, e.g. --units g --dt 0.005 "
                     "(units g, m/s2, cm/s2 or gal), or start the file with '# units: g; dt = 0.005 s'",
            "dt": "a one-column record needs its time step; give it on the command line, e.g. --dt 0.005, or "
                  "start the file with '# dt = 0.005 s' (or add a time column)",
            "dt_given": "--dt",
            "remove": "leave out --{what}"},
    "api": {"units": "a text record needs its units; pass record_units='g' (or 'm/s2', 'cm/s2', 'gal'), or "
                     "start the file with '# units: g; dt = 0.005 s'",
            "dt": "a one-column record needs its time step; pass record_dt=<seconds>, or start the file with "
                  "'# dt = 0.005 s' (or add a time column)",
            "dt_given": "record_dt",
            "remove": "leave out record_{what}"},
}
_HEADER_LINE = re.compile(r"#\s*(units|dt)\s*[:=]", re.IGNORECASE)
_HEADER_FIELD = re.compile(r"\b(units|dt)\s*[:=]\s*([^;,]+)", re.IGNORECASE)

# A real number as written in record files; D exponents (Fortran) included.
_NUMBER = FORTRAN_NUMBER
# A number must be followed by a separator, a sign (glued values such as
# 1.234E-02-5.678E-03) or the end of the line; "1.2.3" is not two numbers.
_NUMBER_TOKEN = re.compile(_NUMBER + r"(?=[\s,+-]|$)")
_DATA_LINE = re.compile(r"[\s,]*(?:" + _NUMBER + r"(?=[\s,+-]|$)[\s,]*)*")
_NON_FINITE = re.compile(r"[-+]?(?:nan|inf(?:inity)?)", re.IGNORECASE)

_NPTS_NEW = re.compile(r"NPTS\s*=\s*(\d+)\s*[,;]?\s*DT\s*=\s*(" + _NUMBER + r")", re.IGNORECASE)
_NPTS_NEW_REVERSED = re.compile(r"DT\s*=\s*(" + _NUMBER + r")\s*(?:SEC)?\s*[,;]?\s*NPTS\s*=\s*(\d+)",
                                re.IGNORECASE)
_NPTS_OLD = re.compile(r"^\s*(\d+)\s*[,;]?\s+(" + _NUMBER + r")\s*[,;]?\s*NPTS\s*[,;]?\s*DT\b", re.IGNORECASE)
_NPTS_EXPECTED = "expected 'NPTS= 3930, DT= .00500 SEC' or '3930 0.00500 NPTS, DT'"
_AT2_UNITS = re.compile(r"UNITS\s+(?:OF|ARE|IN)\s*[:=]?\s*\(?\s*([A-Za-z][A-Za-z0-9/^*]*)", re.IGNORECASE)
_DATE = re.compile(r"\b(\d{1,2}/\d{1,2}/\d{2,4})\b")


def check_agrees(record: Record, path: Path, *, dt: float | None, units: str | None) -> None:
    """dt / units given in the YAML must agree with what an AT2 header says."""
    if units is not None:
        wanted = normalise_units(units)
        if wanted != record.metadata["original_units"]:
            raise RecordError(f"the header gives units of {record.metadata['original_units']} but "
                              f"ground_motion.units is {units}; remove units from the YAML ground_motion section",
                              file=str(path), line=3)
    if dt is not None:
        given = positive_value("dt", dt, str(path))
        if abs(given - record.time_step) > DT_RTOL * record.time_step:
            raise RecordError(f"the header gives DT={record.time_step:g} s but ground_motion.dt is {given:g} s; "
                              "remove dt from the YAML ground_motion section", file=str(path), line=4)


# --------------------------------------------------------------------------- #
# File helpers
# --------------------------------------------------------------------------- #


def _read_lines(path: Path, what: str) -> list[str]:
    if not path.exists():
        raise RecordError("file not found; check ground_motion.record (relative paths are resolved against "
                          "the YAML file's folder)", file=str(path))
    if path.is_dir():
        raise RecordError(f"is a folder, not a {what} file; give the file in ground_motion.record", file=str(path))
    try:
        text = path.read_bytes().decode("latin-1")
    except OSError as error:
        raise RecordError(f"cannot read the file ({error.strerror}); check its permissions", file=str(path)) from None
    return text.splitlines()


def _bad_token(line: str) -> str:
    """The first token of *line* that is not a number (for error messages)."""
    pos = 0
    while pos < len(line):
        if line[pos] in " \t\r\f\v,":
            pos += 1
            continue
        match = _NUMBER_TOKEN.match(line, pos)
        if match:
            pos = match.end()
            continue
        end = pos
        while end < len(line) and line[end] not in " \t\r\f\v,":
            end += 1
        return line[pos:end]
    return line.strip()


_STRICT_NUMBER = re.compile(_NUMBER)


def _to_float(token: str) -> float:
    """A number token as float: D exponents accepted, nan/inf passed through (checked by callers)."""
    if not (_STRICT_NUMBER.fullmatch(token) or _NON_FINITE.fullmatch(token)):
        raise ValueError(token)
    return float(token.replace("D", "E").replace("d", "e"))


def _not_finite_error(path: Path, lineno: int, token: str) -> RecordError:
    return RecordError(f"non-finite value '{token}' in the data; the record is corrupt: replace it with a number "
                       "or re-download the record", file=str(path), line=lineno)


def _number_error(path: Path, lineno: int, token: str) -> RecordError:
    if _NON_FINITE.fullmatch(token):
        return _not_finite_error(path, lineno, token)
    return RecordError(f"cannot read '{token}' as a number; fix or delete this line", file=str(path), line=lineno)


# --------------------------------------------------------------------------- #
# PEER NGA .AT2
# --------------------------------------------------------------------------- #


def read_at2(path: str | Path) -> Record:
    """Read a PEER NGA ``.AT2`` acceleration record.

    The four header lines are a title, an event/date/station/component line, a
    units line (``ACCELERATION TIME SERIES IN UNITS OF G``) and the point count
    and step in either layout: ``NPTS=  3930, DT=   .00500 SEC`` (NGA-West2)
    or ``3930    0.00500    NPTS, DT`` (older NGA files). The values follow in
    free-format rows; values glued by a minus sign, trailing commas, a short
    last row and Fortran ``D`` exponents are accepted.
    """
    path = Path(path)
    lines = _read_lines(path, "PEER .AT2")
    if not any(line.strip() for line in lines):
        raise RecordError("empty file; expected a PEER NGA .AT2 record (4 header lines, then the values)",
                          file=str(path), line=1)
    if len(lines) < 4:
        raise RecordError(f"the file ends after {len(lines)} line(s); a PEER .AT2 file has 4 header lines "
                          "(title, event, units, NPTS/DT) before the values", file=str(path), line=len(lines))
    kind = lines[2].strip().upper()
    for other in ("VELOCITY", "DISPLACEMENT"):
        if kind.startswith(other):
            raise RecordError(f"this is a {other.lower()} time series; only acceleration records (.AT2) are "
                              "accepted", file=str(path), line=3)
    unit_match = _AT2_UNITS.search(lines[2])
    units = canonical_unit(unit_match[1]) if unit_match else None
    if units is None:
        found = f"'{unit_match[1]}'" if unit_match else "none"
        raise RecordError(f"cannot tell the units (found {found}); expected 'ACCELERATION TIME SERIES IN UNITS OF G' "
                          "(or CM/S/S, M/S/S)", file=str(path), line=3)

    header = lines[3]
    if (m := _NPTS_NEW.search(header)) is not None:
        npts_text, dt_text, variant = m[1], m[2], "NPTS=, DT="
    elif (m := _NPTS_NEW_REVERSED.search(header)) is not None:
        npts_text, dt_text, variant = m[2], m[1], "NPTS=, DT="
    elif (m := _NPTS_OLD.search(header)) is not None:
        npts_text, dt_text, variant = m[1], m[2], "NPTS, DT"
    else:
        raise RecordError(f"no NPTS/DT found; {_NPTS_EXPECTED}", file=str(path), line=4)
    npts, step = int(npts_text), _to_float(dt_text)
    if not math.isfinite(step) or step <= 0:
        raise RecordError(f"DT must be > 0 (got {dt_text}); fix the time step in the header", file=str(path), line=4)
    step = check_time_step(step, str(path), line=4)
    if npts < 2:
        raise RecordError(f"NPTS must be at least 2 (got {npts}); fix the header", file=str(path), line=4)

    values: list[float] = []
    for lineno, line in enumerate(lines[4:], start=5):
        if not line.strip():
            continue
        if not _DATA_LINE.fullmatch(line):
            raise _number_error(path, lineno, _bad_token(line))
        row = [_to_float(token) for token in _NUMBER_TOKEN.findall(line)]
        if not all(math.isfinite(v) for v in row):
            raise _not_finite_error(path, lineno, next(t for t in _NUMBER_TOKEN.findall(line)
                                                        if not math.isfinite(_to_float(t))))
        values.extend(row)
    if len(values) != npts:
        raise RecordError(f"NPTS={npts} but {len(values)} values found; the file is truncated or NPTS is wrong",
                          file=str(path), line=4)

    acc = np.asarray(values, dtype=np.float64)
    metadata: dict[str, Any] = {
        "format": "PEER NGA AT2",
        "header_variant": variant,
        **_at2_event(lines[1]),
        "header_line_1": lines[0].strip(),
        "header_line_2": lines[1].strip(),
        "header_line_3": lines[2].strip(),
        "header_line_4": header.strip(),
        "original_units": units,
        "original_npts": npts,
        "original_dt": step,
        "pga_g": float(np.max(np.abs(acc))) * UNITS[units] / STANDARD_GRAVITY,
    }
    return Record(name=path.stem, source=str(path), time_step=step, acceleration=acc * UNITS[units],
                  metadata=metadata)


def _at2_event(line: str) -> dict[str, str]:
    """Event, date, station and component from the second AT2 header line, as far as they parse.

    NGA-West2: ``Northridge-01, 1/17/1994, Arleta - Nordhoff Fire Sta, 360``;
    older files: ``NORTHRIDGE 01/17/94 1231, ARLETA, 360``.
    """
    parts = [p.strip() for p in line.split(",")]
    parts = [p for p in parts if p]
    out: dict[str, str] = {}
    if not parts:
        return out
    if len(parts) >= 4 and _DATE.fullmatch(parts[1]):
        out["event"], out["date"] = parts[0], parts[1]
        out["station"] = ", ".join(parts[2:-1])
        out["component"] = parts[-1]
        return out
    first = parts[0]
    date = _DATE.search(first)
    if date:
        out["event"] = first[: date.start()].strip()
        out["date"] = date[1]
    else:
        out["event"] = first
    if len(parts) >= 3:
        out["station"] = ", ".join(parts[1:-1])
        out["component"] = parts[-1].split()[0]
    elif len(parts) == 2:
        out["station"] = parts[1]
    return {k: v for k, v in out.items() if v}


# --------------------------------------------------------------------------- #
# Plain text
# --------------------------------------------------------------------------- #


def text_header(lines: list[str], path: Path) -> dict[str, Any]:
    """``units`` and ``dt`` declared in the leading comment lines of a text record.

    A line such as ``# units: g; dt = 0.005 s`` (the shipped synthetic
    records have one) declares them; fields are separated by ``;`` or ``,``
    and a trailing ``s`` after dt is allowed.  Returns ``{"units": ..., "dt":
    ..., "line": ...}`` with the fields found (none: an empty dict).
    """
    found: dict[str, Any] = {}
    for lineno, raw in enumerate(lines, start=1):
        stripped = raw.strip()
        if not stripped:
            continue
        if not stripped.startswith("#"):
            break
        if not _HEADER_LINE.match(stripped):   # other comments may mention dt= in passing
            continue
        for match in _HEADER_FIELD.finditer(stripped[1:]):
            key, value = match[1].lower(), match[2].strip()
            if key == "units":
                try:
                    found["units"] = normalise_units(value)
                except RecordError:
                    raise RecordError(f"the header declares unknown units '{value}'; write '# units: g' (or m/s2, "
                                      "cm/s2, gal)", file=str(path), line=lineno) from None
            else:
                number = re.sub(r"\s*(s|sec|seconds)\s*$", "", value, flags=re.IGNORECASE)
                try:
                    found["dt"] = float(number)
                except ValueError:
                    raise RecordError(f"the header declares dt = '{value}'; write '# dt = 0.005 s'",
                                      file=str(path), line=lineno) from None
                if not (math.isfinite(found["dt"]) and found["dt"] > 0):
                    raise RecordError(f"the header declares dt = {value}; dt must be > 0", file=str(path),
                                      line=lineno)
            found.setdefault("line", lineno)
    return found


def declared_in_header(path: str | Path) -> dict[str, Any]:
    """``units`` / ``dt`` declared by the header of a text record file; ``{}`` if none or unreadable.

    Errors in the file are left for :func:`read_text` to report.
    """
    try:
        return {k: v for k, v in text_header(_first_lines(path), Path(path)).items() if k != "line"}
    except (OSError, RecordError):
        return {}


def header_declares_units(path: str | Path) -> bool | None:
    """Whether a text record file declares its units in a ``# units: g`` header line.

    ``True`` if it does, ``False`` if the file has no such line or cannot be
    read, ``None`` if the header is malformed (unknown units, bad dt): that
    error is for :func:`read_text` to report, with its line.
    """
    try:
        return "units" in text_header(_first_lines(path), Path(path))
    except OSError:
        return False
    except RecordError:
        return None


def _first_lines(path: str | Path, count: int = 50) -> list[str]:
    """The first *count* lines of a file (a header is short; the samples after it need not be read)."""
    lines = []
    with open(path, "rb") as handle:
        for raw in handle:
            lines.append(raw.decode("latin-1").rstrip("\r\n"))
            if len(lines) >= count:
                break
    return lines


def read_text(path: str | Path, *, dt: float | None = None, units: str | None = None,
              where: str = "yaml") -> Record:
    """Read a plain-text record: one column (acceleration) or two (time, acceleration).

    Columns are separated by whitespace or commas; ``#`` starts a comment and
    one non-numeric first line (a CSV header) is skipped. One column needs
    *dt*; with two columns the step is taken from the (strictly increasing,
    uniform within 1e-6 relative) time column. *units* is required unless the
    file declares them in a leading comment, ``# units: g; dt = 0.005 s``
    (see :func:`text_header`); a *units* or *dt* given as well must agree
    with the header.  *where* (``yaml``, ``cli`` or ``api``) picks how the
    error messages say to give missing units or dt (:data:`FIXES`).
    """
    path = Path(path)
    fixes = FIXES.get(where, FIXES["yaml"])
    lines = _read_lines(path, "text record")
    header = text_header(lines, path)
    if units is None and "units" in header:
        units = header["units"]
    elif units is not None and "units" in header:
        try:
            given = normalise_units(units)
        except RecordError as error:
            raise RecordError(str(error), file=str(path)) from None
        if given != header["units"]:
            raise RecordError(f"the header declares units of {header['units']} but {units} was given; "
                              + fixes["remove"].format(what="units"), file=str(path), line=header["line"])
    if dt is None and "dt" in header:
        dt = header["dt"]
    elif dt is not None and "dt" in header:
        given_dt = positive_value("dt", dt, str(path))
        if abs(given_dt - header["dt"]) > DT_RTOL * header["dt"]:
            raise RecordError(f"the header declares dt = {header['dt']:g} s but {given_dt:g} s was given; "
                              + fixes["remove"].format(what="dt"), file=str(path), line=header["line"])
    if units is None:
        raise RecordError(fixes["units"], file=str(path))
    try:
        unit = normalise_units(units)
    except RecordError as error:
        raise RecordError(str(error), file=str(path)) from None

    rows: list[tuple[int, list[float]]] = []
    header_seen = False
    columns = 0
    for lineno, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        tokens = [t for t in re.split(r"[\s,;]+", line) if t]
        try:
            row = [_to_float(t) for t in tokens]
        except ValueError:
            if not rows and not header_seen:
                header_seen = True  # a CSV header such as "time,acc"
                continue
            bad = next(t for t in tokens if not _is_number(t))
            raise _number_error(path, lineno, bad) from None
        for token, value in zip(tokens, row):
            if not math.isfinite(value):
                raise _not_finite_error(path, lineno, token)
        if not columns:
            columns = len(row)
            first_line = lineno
            if columns > 2:
                raise RecordError(f"{columns} columns found; expected one column (acceleration) or two "
                                  "(time, acceleration)", file=str(path), line=lineno)
        elif len(row) != columns:
            raise RecordError(f"{len(row)} column(s) here but {columns} at line {first_line}; every row needs the "
                              "same columns", file=str(path), line=lineno)
        rows.append((lineno, row))
    if not rows:
        raise RecordError("empty file; expected one column of accelerations or two columns time, acceleration",
                          file=str(path), line=max(1, len(lines)))
    if len(rows) < 2:
        raise RecordError("only 1 sample; a record needs at least 2", file=str(path), line=rows[0][0])

    data = np.asarray([r for _, r in rows], dtype=np.float64)
    metadata: dict[str, Any] = {"format": f"text, {columns} column(s)"}
    if columns == 1:
        if dt is None:
            raise RecordError(fixes["dt"], file=str(path))
        step = check_time_step(positive_value("dt", dt, str(path)), str(path))
        acc = data[:, 0]
    else:
        time, acc = data[:, 0], data[:, 1]
        steps = np.diff(time)
        first = steps[0]
        for i, s in enumerate(steps):
            if s <= 0:
                lineno = rows[i + 1][0]
                raise RecordError(f"time does not increase at line {lineno} ({time[i + 1]:g} s after "
                                  f"{time[i]:g} s); times must be strictly increasing", file=str(path), line=lineno)
            if abs(s - first) > DT_RTOL * first:
                lineno = rows[i + 1][0]
                raise RecordError(f"non-uniform time step at line {lineno}: {s:g} s vs {first:g} s; resample the "
                                  "record to a constant step", file=str(path), line=lineno)
        step = float((time[-1] - time[0]) / (len(time) - 1))
        if dt is not None:
            given = positive_value("dt", dt, str(path))
            if abs(given - step) > DT_RTOL * step:
                raise RecordError(f"{fixes['dt_given']} is {given:g} s but the time column has a step of {step:g} s; "
                                  + fixes["remove"].format(what="dt"), file=str(path))
        metadata["original_start_time"] = float(time[0])
    metadata.update({
        "original_units": unit,
        "original_npts": int(acc.size),
        "original_dt": step,
        "pga_g": float(np.max(np.abs(acc))) * UNITS[unit] / STANDARD_GRAVITY,
    })
    return Record(name=path.stem, source=str(path), time_step=step, acceleration=acc * UNITS[unit],
                  metadata=metadata)


def _is_number(token: str) -> bool:
    try:
        _to_float(token)
    except ValueError:
        return False
    return True
