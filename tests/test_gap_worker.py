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


def test_the_slopes_roots_are_numpy_roots_bit_for_bit():
    """The separation search's roots (:func:`slope_roots`, all of a history's intervals in one call) are those of
    ``numpy.roots`` on each quadratic alone, real and imaginary parts bit for bit, so :func:`max_hermite` keeps
    the maximum it found one interval at a time: random quadratics over twelve decades, real and complex
    roots, and the degenerate ones (a = 0, c = 0, a = b = 0) that ``numpy.roots`` reduces."""
    from pounding.studies.gap import slope_roots

    rng = np.random.default_rng(11)
    for case in range(200):
        n = int(rng.integers(1, 200))
        a, b, c = (rng.normal(size=n) * 10.0 ** rng.uniform(-6, 6, n) for _ in range(3))
        for coefficient in (a, b, c) if case % 4 == 0 else ():
            coefficient[rng.random(n) < 0.3] = 0.0
        found = slope_roots(a, b, c)
        assert len(found) == n
        for k in range(n):
            expected = np.roots([a[k], b[k], c[k]]) if a[k] != 0.0 or b[k] != 0.0 else np.empty(0)
            assert found[k].size == expected.size
            assert np.real(found[k]).tobytes() == np.real(expected).tobytes(), (a[k], b[k], c[k])
            assert np.imag(found[k]).tobytes() == np.imag(expected).tobytes(), (a[k], b[k], c[k])


def test_the_separation_search_finds_the_interpolants_maximum():
    """:func:`max_hermite` against the interpolant sampled densely (its maximum lies between two dense samples,
    so the dense one is at most the found one and within the curvature's reach of it)."""
    from pounding.studies.gap import max_hermite

    rng = np.random.default_rng(5)
    for _ in range(50):
        n = int(rng.integers(3, 60))
        time = np.cumsum(rng.uniform(0.005, 0.02, n))
        value, rate = rng.normal(0.0, 1e-2, n), rng.normal(0.0, 1.0, n)
        found = max_hermite(time, value, rate)
        s = np.linspace(0.0, 1.0, 2001)[:, None]
        h = np.diff(time)
        dense = ((2 * s**3 - 3 * s**2 + 1) * value[:-1] + (s**3 - 2 * s**2 + s) * rate[:-1] * h
                 + (-2 * s**3 + 3 * s**2) * value[1:] + (s**3 - s**2) * rate[1:] * h).max()
        # 1e-12 m: round-off of values ~1e-2 m; 1e-7 m: a cubic of slopes ~1e-2 m per interval moves by at most
        # ~(1/2000)² × its second derivative (~0.1 m) between dense samples around its maximum
        assert dense <= found + 1e-12 and found - dense <= 1e-7
