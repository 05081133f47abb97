"""Quasi-static cyclic test of one storey: a drift history in, the storey shear out (``pounding hysteresis``).

The storey is driven alone, without mass, damping or P-Delta: its hysteresis
model (or its elastic stiffness) turns each drift into a shear.  This is how a
storey is calibrated against a test, and how the models are checked against
OpenSees' uniaxial materials driven by the same history (docs/hysteresis.md).

* elastic: F = kΔ;
* ``bilinear``: the plastic drift by return mapping, exact for any history
  (the yield surface is ``|Δ − Δ_p| = u_y``);
* ``bouc-wen``: ż integrated along each drift increment (Δ linear in a
  pseudo-time) by classical Runge–Kutta in sub-steps of at most u_y/100;
* IMK: :class:`pounding.studies.imk.ImkMaterial`.

The force formulas are the solver's own kernels (:mod:`pounding.solver.storeys`).

Protocols (drift amplitudes, each cycle +a, −a, back to 0; legs sampled in
:data:`POINTS_PER_LEG` equal steps):

* ``fema461``: FEMA 461 (2007), the quasi-static cyclic protocol: two cycles
  per amplitude, each amplitude 1.4 times the previous, ten increases (the
  protocol's minimum) from the first amplitude to the target
  (``--amplitude``), so a_0 = a_m / 1.4¹⁰;
* ``atc24``: ATC-24 (1992): at least six cycles below the yield drift δ_y (here
  two each at 0.25, 0.5, 0.75 δ_y), three cycles each at δ_y, 2δ_y, 3δ_y, then two
  cycles each at 4δ_y, 5δ_y, … up to the target amplitude; δ_y is the storey's
  (positive) yield drift.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import xarray as xr

from pounding import __version__
from pounding.errors import ModelError, PoundingError
from pounding.hysteresis import MODEL_BILINEAR, MODEL_BOUC_WEN, ImkStorey, StoreyHysteresis
from pounding.solver import storeys
from pounding.studies.imk import ImkMaterial

__all__ = ["PROTOCOLS", "POINTS_PER_LEG", "named_protocol", "read_protocol", "amplitudes", "storey_response",
           "StoreySpring", "hysteresis_summary", "hysteresis_tables",
           "hysteresis_test", "write_csv", "plot_hysteresis"]

PROTOCOLS = ("fema461", "atc24")

#: Equal steps of each leg (0 → +a, +a → 0, 0 → −a, −a → 0) of a named protocol.
POINTS_PER_LEG = 25

#: Bouc–Wen sub-step: at most this fraction of u_y per Runge–Kutta step.
BOUC_WEN_SUBSTEP = 0.01

#: Largest |storey drift| / storey height a cyclic test accepts: a drift as large as the storey is tall is
#: past any storey's collapse, and larger ones only cost time (Bouc–Wen sub-steps, ATC-24 cycles).
MAX_DRIFT_RATIO = 1.0


def amplitudes(name: str, amplitude: float, yield_drift: float | None = None) -> list[float]:
    """The cycle amplitudes (m) of protocol *name* up to *amplitude* (m), one entry per cycle.

    Raises
    ------
    PoundingError
        Unknown protocol; ``atc24`` without a yield drift (an elastic storey).
    """
    if not (amplitude > 0.0 and np.isfinite(amplitude)):
        raise PoundingError(f"the protocol's amplitude must be a finite number > 0 (got {amplitude:g} m)")
    if name == "fema461":
        return [a for i in range(11) for a in 2 * [amplitude * 1.4 ** (i - 10)]]
    if name == "atc24":
        if yield_drift is None:
            raise PoundingError("the atc24 protocol is in multiples of the yield drift: the storey has no "
                                "hysteresis (use fema461 or a FILE)")
        levels = [(0.25, 2), (0.5, 2), (0.75, 2), (1.0, 3), (2.0, 3), (3.0, 3)]
        multiple = 4.0
        while multiple * yield_drift <= amplitude * (1.0 + 1e-12):
            levels.append((multiple, 2))
            multiple += 1.0
        return [m * yield_drift for m, n in levels if m * yield_drift <= amplitude * (1.0 + 1e-12)
                for _ in range(n)]
    raise PoundingError(f"unknown protocol '{name}'; choose one of: {', '.join(PROTOCOLS)}, or a file")


def named_protocol(name: str, amplitude: float, yield_drift: float | None = None) -> np.ndarray:
    """Drift history (m) of protocol *name* to *amplitude* (m): starts and ends at 0, every cycle sampled."""
    legs = [np.zeros(1)]
    ramp = np.arange(1, POINTS_PER_LEG + 1) / POINTS_PER_LEG
    for a in amplitudes(name, amplitude, yield_drift):
        legs += [a * ramp, a * ramp[::-1][1:], [0.0], -a * ramp, -a * ramp[::-1][1:], [0.0]]
    return np.concatenate(legs)


def read_protocol(path: str | Path) -> np.ndarray:
    """Drift history (m) from a text file: one storey drift in metres per line (``#`` comments, blank lines).

    Raises
    ------
    PoundingError
        Unreadable file, a line that is not one finite number, or no drift at all.
    """
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise PoundingError(f"cannot read the drift history {path}: {getattr(exc, 'strerror', None) or exc}") from None
    out = []
    for number, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not np.isfinite(value):
            raise PoundingError(f"{path}:{number}: expected one storey drift in metres per line (got {text!r})")
        out.append(value)
    if not out:
        raise PoundingError(f"{path}: no drift in the file (one storey drift in metres per line)")
    return np.asarray(out, dtype=float)


class StoreySpring:
    """One storey's shear as its drift moves, from rest: :meth:`step` moves it, :meth:`trial` only asks.

    Parameters
    ----------
    law : StoreyHysteresis or None
        The storey's hysteresis model (None: elastic).
    stiffness, height : float
        Elastic storey stiffness (N/m) and storey height (m).
    """

    def __init__(self, law: StoreyHysteresis | None, stiffness: float, height: float):
        self.law, self.k = law, float(stiffness)
        self.material = ImkMaterial(law, self.k, height) if isinstance(law, ImkStorey) else None
        self.table = None if law is None or self.material is not None else law.kernel_parameters(self.k, height)[None, :]
        if self.table is not None and law.model_id not in (MODEL_BILINEAR, MODEL_BOUC_WEN):
            raise ModelError(f"storey hysteresis '{law.name}' has no quasi-static driver")
        self.r, self.u = 0.0, 0.0

    @property
    def failed(self) -> bool:
        """An IMK storey that has lost its strength (in either direction)."""
        m = self.material
        return m is not None and (m.failed or any(m.lost.values()))

    def step(self, u: float) -> float:
        """Move to drift *u* (m); the shear, N."""
        if self.table is None:
            self.u = u
            return self.material.step(u) if self.material is not None else self.k * u
        table, uy = self.table, self.table[0, 0]
        if self.law.model_id == MODEL_BILINEAR:
            elastic = u - self.r
            if elastic > uy:
                self.r = u - uy
            elif elastic < -uy:
                self.r = u + uy
        else:
            self.r = _bouc_wen_increment(self.law.model_id, table, self.r, u - self.u, uy)
        self.u = u
        return storeys.restoring_force(self.law.model_id, table, 0, self.k, u, self.r)

    def trial(self, u: float) -> float:
        """The shear (N) at drift *u* (m) from here, the spring left as it is."""
        return copy.deepcopy(self).step(u)


def storey_response(law: StoreyHysteresis | None, stiffness: float, height: float,
                    drifts: np.ndarray) -> np.ndarray:
    """Storey shear (N) after each drift of *drifts* (m), from rest at zero drift (:class:`StoreySpring`)."""
    spring = StoreySpring(law, stiffness, height)
    return np.array([spring.step(float(u)) for u in np.asarray(drifts, dtype=float)])


def _bouc_wen_increment(model: int, table: np.ndarray, z: float, du: float, uy: float) -> float:
    """z after a drift increment *du* (m): dz/ds = ż(Δ̇ = du) over s ∈ [0, 1], classical Runge–Kutta."""
    if du == 0.0:
        return z
    steps = max(1, int(np.ceil(abs(du) / (BOUC_WEN_SUBSTEP * uy))))
    h = 1.0 / steps
    mode = storeys.ELASTIC
    for _ in range(steps):
        k1 = storeys.state_rate(model, table, 0, mode, du, z)
        k2 = storeys.state_rate(model, table, 0, mode, du, z + 0.5 * h * k1)
        k3 = storeys.state_rate(model, table, 0, mode, du, z + 0.5 * h * k2)
        k4 = storeys.state_rate(model, table, 0, mode, du, z + h * k3)
        z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return z


def hysteresis_test(model, storey: str, protocol: str, amplitude: float | None = None) -> xr.Dataset:
    """The cyclic test of storey *storey* (``A:1``) of *model* (a path or a loaded model).

    Parameters
    ----------
    protocol : str
        ``fema461``, ``atc24`` or a file of drifts (m, one per line).
    amplitude : float, optional
        The named protocol's target drift ratio (× the storey height); required for them.

    Returns
    -------
    xarray.Dataset
        ``storey_drift`` (m) and ``storey_shear`` (N) on the ``step`` dimension; attributes
        ``kind = "hysteresis"``, the storey, its model (``model_file``, and the model itself as YAML text:
        ``base_model``), stiffness and height, the protocol.
    """
    from pounding.model.model import load_model
    from pounding.studies.common import base_model_text

    loaded = load_model(model) if isinstance(model, (str, Path)) else model
    building, level = _storey(loaded, storey)
    if building.in_plan:
        raise PoundingError(f"storey {storey} is in plan: it resists through "
                            f"{len(building.storeys[level - 1].planes)} planes, each a spring with its own stiffness "
                            "and law, and pounding hysteresis drives one storey spring; test a plane's law as the "
                            "storey of a planar building (the plane's stiffness, the storey height, its hysteresis)")
    k, h = float(building.stiffness[level - 1]), float(building.height[level - 1])
    law = building.hysteresis[level - 1]
    if protocol in PROTOCOLS:
        if amplitude is None:
            raise PoundingError(f"the {protocol} protocol needs --amplitude (the target drift ratio, e.g. 0.05)")
        if float(amplitude) > MAX_DRIFT_RATIO:
            raise PoundingError(f"--amplitude is a drift ratio (drift / storey height): {float(amplitude):g} is a "
                                f"drift larger than the {h:g} m storey; give at most {MAX_DRIFT_RATIO:g}, e.g. 0.05")
        yield_drift = None if law is None else law.yield_force_for(k, h) / k
        drifts = named_protocol(protocol, float(amplitude) * h, yield_drift)
    else:
        if amplitude is not None:
            raise PoundingError("--amplitude scales the named protocols only; a FILE gives drifts in metres")
        drifts = read_protocol(protocol)
        peak = int(np.argmax(np.abs(drifts)))
        if abs(drifts[peak]) > MAX_DRIFT_RATIO * h:
            raise PoundingError(f"{protocol}: drift {peak + 1} of the file, {drifts[peak]:g} m, is larger than "
                                f"storey {storey}'s height ({h:g} m); the file gives storey drifts in metres")
    shear = storey_response(law, k, h, drifts)
    return xr.Dataset(
        {"storey_drift": ("step", drifts, {"units": "m", "long_name": f"storey drift of {storey}"}),
         "storey_shear": ("step", shear, {"units": "N", "long_name": f"storey shear of {storey}"})},
        coords={"step": ("step", np.arange(drifts.size), {"long_name": "step of the drift history"})},
        attrs={"kind": "hysteresis", "source": f"pounding {__version__}",
               "title": f"cyclic test of storey {storey} ({protocol})",
               "history": f"pounding hysteresis {model if isinstance(model, (str, Path)) else '(a loaded model)'} "
                          f"--storey {storey} --protocol {protocol}"
                          + ("" if amplitude is None else f" --amplitude {float(amplitude):g}"),
               "storey": storey, "hysteresis": "elastic" if law is None else law.describe(),
               "stiffness": k, "height": h, "protocol": str(protocol),
               "amplitude_drift_ratio": float("nan") if amplitude is None else float(amplitude),
               "model_file": str(model) if isinstance(model, (str, Path)) else "",
               "base_model": base_model_text(loaded)})


def _storey(model, storey: str):
    """The building and storey level (1-based) of ``NAME:LEVEL``."""
    name, _, level_text = storey.rpartition(":")
    names = [b.name for b in model.buildings]
    if not name or not level_text.isdigit():
        raise PoundingError(f"--storey must be BUILDING:LEVEL, e.g. {names[0]}:1 (got {storey!r})")
    if name not in names:
        raise PoundingError(f"no building '{name}' in the model (buildings: {', '.join(names)})")
    building = model.buildings[names.index(name)]
    level = int(level_text)
    if not 1 <= level <= building.n_floors:
        raise PoundingError(f"building {name} has storeys 1..{building.n_floors} (got {level})")
    return building, level


def write_csv(ds: xr.Dataset, path: str | Path) -> Path:
    """``storey_drift_m,storey_shear_N``, one row per step."""
    from pounding.results.archive import atomic_path

    path = Path(path)
    rows = np.column_stack([ds.storey_drift.values, ds.storey_shear.values])
    if str(path.parent):
        path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as temporary:   # a full disk keeps the old file
        np.savetxt(temporary, rows, delimiter=",", header="storey_drift_m,storey_shear_N", comments="", fmt="%.17g")
    return path


def hysteresis_tables(ds: xr.Dataset) -> dict:
    """The table of a hysteresis archive for ``pounding table``: ``steps``, the storey drift (m) and shear (N)
    per step (the columns of ``--csv``, with the step number)."""
    from pounding.results.tables import long_table

    return {"steps": long_table(ds, ["storey_drift", "storey_shear"])}


def plot_hysteresis(ds: xr.Dataset, folder: str | Path) -> list[Path]:
    """``hysteresis.png`` in *folder*: storey shear (kN) against drift ratio (%); its path in a list."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(100.0 * ds.storey_drift.values / ds.attrs["height"], ds.storey_shear.values / 1e3, lw=0.9)
    ax.axhline(0.0, color="0.7", lw=0.5)
    ax.axvline(0.0, color="0.7", lw=0.5)
    ax.set_xlabel(f"storey drift ratio of {ds.attrs['storey']} (%)")
    ax.set_ylabel("storey shear (kN)")
    ax.set_title(f"{ds.attrs['hysteresis'][:70]}\nprotocol {Path(ds.attrs['protocol']).name}", fontsize=8)
    fig.tight_layout()
    out = folder / "hysteresis.png"
    fig.savefig(out, dpi=130)
    plt.close(fig)
    return [out]


def hysteresis_summary(ds: xr.Dataset) -> str:
    """One line for ``pounding info``: the storey, its model, the steps and the peaks."""
    return (f"  storey {ds.attrs['storey']}: {ds.attrs['hysteresis']}\n  {ds.sizes['step']} steps; peak |drift| "
            f"{float(abs(ds.storey_drift).max()):.6g} m, peak |shear| {float(abs(ds.storey_shear).max()):.6g} N")
