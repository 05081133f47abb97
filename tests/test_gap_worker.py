"""A gap study's worker: the modes and the separation search it shares within a run give each run's own values.

A gap run works out each building's mode of largest effective mass along a normal once
(:func:`pounding.studies.gap.normal_modes`) and finds the roots of the separation search's slopes in one
call (:func:`pounding.studies.gap.max_hermite`); each is checked against the work done one at a time, bit
for bit, and a changed building against its own.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from pounding.model.model import model_from_data

ROOT = Path(__file__).resolve().parents[1]
PAIR = ROOT / "models" / "pair.yaml"


def pair_model() -> object:
    """models/pair.yaml as a worker validates it."""
    return model_from_data(yaml.safe_load(PAIR.read_text()), name="pair", source=PAIR.read_text(),
                           base_dir=str(PAIR.parent))


def test_a_gap_run_works_out_each_mode_once_and_gives_normal_mode(monkeypatch):
    """:func:`normal_modes` equals :func:`normal_mode` for every building and normal, computing each once."""
    from pounding.studies import gap

    model = pair_model()
    calls = []
    real = gap.normal_mode
    monkeypatch.setattr(gap, "normal_mode", lambda b, n="x": calls.append((b.name, n)) or real(b, n))
    mode = gap.normal_modes(model)
    for _ in range(3):
        for b, building in enumerate(model.buildings):
            assert mode(b, "x") == real(building, "x")
    assert sorted(calls) == sorted((b.name, "x") for b in model.buildings)
    data = yaml.safe_load(PAIR.read_text())
    data["buildings"][0]["storeys"]["stiffness"] = 2 * float(data["buildings"][0]["storeys"]["stiffness"])
    stiffer = model_from_data(data, name="pair", source="", base_dir=str(PAIR.parent))
    assert gap.normal_modes(stiffer)(0, "x")[0] < mode(0, "x")[0]   # a stiffer building: its own shorter period


def reference_max_hermite(time: np.ndarray, value: np.ndarray, rate: np.ndarray) -> float:
    """:func:`pounding.studies.gap.max_hermite` as it was, one ``numpy.roots`` per interval (the reference)."""
    best = float(np.max(value))
    h = np.diff(time)
    y0, y1 = value[:-1], value[1:]
    m0, m1 = rate[:-1] * h, rate[1:] * h
    a = 6.0 * y0 + 3.0 * m0 - 6.0 * y1 + 3.0 * m1
    b = -6.0 * y0 - 4.0 * m0 + 6.0 * y1 - 2.0 * m1
    c = m0
    rise = np.maximum(y0, y1) + (4.0 / 27.0) * (np.abs(m0) + np.abs(m1))
    pad = 1e-12 * (abs(best) + float(np.max(np.abs(rise), initial=0.0)))
    for k in np.flatnonzero(((m0 > 0.0) | (m1 < 0.0)) & (rise >= best - pad)):
        roots = np.roots([a[k], b[k], c[k]]) if a[k] != 0.0 or b[k] != 0.0 else np.empty(0)
        for s in roots:
            if abs(s.imag) > 1e-12 or not 0.0 < s.real < 1.0:
                continue
            s = s.real
            s2, s3 = s * s, s * s * s
            y = ((2 * s3 - 3 * s2 + 1) * y0[k] + (s3 - 2 * s2 + s) * m0[k]
                 + (-2 * s3 + 3 * s2) * y1[k] + (s3 - s2) * m1[k])
            best = max(best, float(y))
    return best


def test_the_separation_search_gives_the_one_root_at_a_time_search_bit_for_bit(monkeypatch):
    """Random histories (smooth, noisy, with flat stretches whose slopes' quadratics lose a or c, and
    zero rates), each compared with the reference bit for bit: the roots come from the same LAPACK
    routine on the same companion matrices."""
    from pounding.studies.gap import max_hermite

    one_by_one = []   # the quadratics max_hermite leaves to numpy.roots (a = 0 or c = 0): they must occur
    roots = np.roots
    monkeypatch.setattr(np, "roots", lambda p: one_by_one.append(len(p)) or roots(p))
    rng = np.random.default_rng(11)
    for case in range(400):
        n = int(rng.integers(2, 300))
        time = np.cumsum(rng.uniform(0.001, 0.02, n))
        value = np.cumsum(rng.normal(0.0, 1e-3, n)) * (np.sin(time * rng.uniform(1.0, 30.0)) if case % 2 else 1.0)
        rate = np.gradient(value, time) + (rng.normal(0.0, 1e-2, n) if case % 3 else 0.0)
        if case % 5 == 0:   # flat stretches: equal samples and zero rates (quadratics with a = 0, c = 0 or both)
            flat = rng.random(n) < 0.3
            value[flat], rate[flat] = 0.0, 0.0
        for v, r in ((value, rate), (-value, -rate)):
            found = max_hermite(time, v, r)
            searched = len(one_by_one)
            expected = reference_max_hermite(time, v, r)
            del one_by_one[searched:]   # the reference's own calls
            assert found.hex() == expected.hex()
    assert one_by_one
