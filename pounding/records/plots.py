"""Picture of one record: acceleration, velocity, displacement and its response spectrum."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from pounding.errors import PoundingError
from pounding.records.record import STANDARD_GRAVITY, event_text
from pounding.records.spectra import default_periods, response_spectrum

__all__ = ["plot_record", "trapezoid_integrals"]


def trapezoid_integrals(acc: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Velocity (m/s) and displacement (m) of an acceleration series (m/s²) by the trapezoidal rule, from rest."""
    velocity = np.concatenate([[0.0], np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt)])
    displacement = np.concatenate([[0.0], np.cumsum(0.5 * (velocity[1:] + velocity[:-1]) * dt)])
    return velocity, displacement


def plot_record(record, path: str | os.PathLike, damping: float = 0.05) -> Path:
    """PNG with acceleration, velocity, displacement (trapezoidal integration) and the response spectrum."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    target = Path(path)
    if target.parent and not target.parent.exists():   # created, as --plot creates its folder
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise PoundingError(f"{target}: cannot create the folder {target.parent} ({exc.strerror or exc})") from None
    acc = record.acceleration
    t = record.time
    velocity, displacement = trapezoid_integrals(acc, record.time_step)
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
        ax.tick_params(labelbottom=row == len(series) - 1)   # the time axis is the bottom panel's
    ax.set_xlabel("time (s)")
    ax_s = fig.add_subplot(grid[3])
    ax_s.semilogx(spectrum.periods, spectrum.psa / STANDARD_GRAVITY, color="C1")
    ax_s.set_xlabel("period T (s)")
    ax_s.set_ylabel(f"Sa (g), {100 * damping:g}% damping")
    ax_s.grid(alpha=0.3, which="both")
    event = event_text(record.metadata)
    fig.suptitle(f"{record.name}, scale factor {record.scale:.4g}" + (f"\n{event}" if event else ""), fontsize=10)
    fig.savefig(target, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return target

