"""Static pushover of each building alone (``pounding pushover``), and FEMA P695's pushover quantities.

Each building is a chain of storeys under a lateral load pattern p (floor
forces λ·p_i, Σp = 1, so λ is the base shear, N): storey i carries the shear
V_i = λ·S_i, S_i = Σ_(j≥i) p_j, and with P-Delta its resistance is
G_i(Δ) = F_i(Δ) − (P_i/h_i)Δ (the leaning column's negative stiffness,
docs/physics.md §7).  Contacts are left open (each building alone).

Displacement control on the *control storey*, the one whose monotonic
capacity max G_i / S_i is the least (the first to reach its peak): its drift
grows in equal steps to zero strength (G ≤ 0), its ultimate drift or the
drift limit; λ follows from it, and every other storey's drift solves
G_i(Δ_i) = λ·S_i from where it is (loading while λ grows, unloading along its
own hysteresis while λ falls: the softening localises in the control storey,
as in a shear building it does).  The storeys' shears are their drift-driven
models (:class:`pounding.studies.cyclic.StoreySpring`).

FEMA P695 (2009) §6.3: V_max; the effective yield roof drift
δ_y,eff = C₀ (V_max/W) (g/4π²) T² (eq. 6-7, T = max(T, T₁) there: here T₁,
the model's first period, or ``--period``), C₀ = φ_r Σm φ / Σm φ² (eq. 6-8,
first mode); the ultimate roof drift δ_u at 20 % loss of strength after the
peak (0.8 V_max on the descending branch, not the storey's ultimate drift);
the period-based ductility μ_T = δ_u / δ_y,eff (eq. 6-6); the overstrength
Ω = V_max / V (eq. 6-5) when the design base shear V = C_s·W is given.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from pounding import __version__
from pounding.errors import PoundingError
from pounding.studies.cyclic import StoreySpring
from pounding.units import STANDARD_GRAVITY

__all__ = ["PATTERNS", "load_pattern", "pushover_building", "pushover", "pushover_table", "pushover_tables",
           "plot_pushover"]

PATTERNS = ("first-mode", "triangular", "uniform")

#: Drift-limit ratio of the control storey when the model sets no ``solver.stop_drift_ratio``.
DEFAULT_DRIFT_LIMIT = 0.1

#: Most equal drift steps of a pushover: 50 times the default, about a minute and a half for a 20-storey
#: building (each step solves every storey's spring in Python, measured 0.2 ms a storey-step); the curves
#: hold a few MB at that bound.
MAX_STEPS = 20_000
#: Fewest equal drift steps of a pushover: with fewer the curve misses its peak (1 step lands on the drift
#: limit past the strength loss and reports V_max = 0; at 10 steps δ_u is within 8 % of 400 steps').
MIN_STEPS = 10


def load_pattern(building, pattern: str) -> np.ndarray:
    """Floor load fractions p (Σp = 1) of *pattern*: m_i, m_i·z_i (z the floor elevation) or m_i·φ_i,1."""
    m = np.asarray(building.mass, dtype=float)
    if pattern == "uniform":
        p = m.copy()
    elif pattern == "triangular":
        p = m * np.asarray(building.elevation, dtype=float)
    elif pattern == "first-mode":
        p = m * building.modes[1][:, 0]
    else:
        raise PoundingError(f"unknown load pattern '{pattern}'; choose one of: {', '.join(PATTERNS)}")
    return p / p.sum()


def _solve_drift(spring: StoreySpring, kpd: float, target: float, start: float, guess: float) -> float:
    """The drift Δ (m) where spring.trial(Δ) + kpd·Δ = *target* (N), by secant from *start* (piecewise-linear
    trial shears: a few iterations)."""
    x0, g0 = start, spring.trial(start) + kpd * start - target
    x1 = guess
    for _ in range(60):
        g1 = spring.trial(x1) + kpd * x1 - target
        if abs(g1) <= 1e-9 * (abs(target) + 1.0) or g1 == g0:
            return x1
        x0, g0, x1 = x1, g1, x1 - g1 * (x1 - x0) / (g1 - g0)
    return x1


def pushover_building(building, pattern: str = "first-mode", *, steps: int = 400,
                      drift_limit_ratio: float = DEFAULT_DRIFT_LIMIT) -> dict:
    """The capacity curve of *building*: base shear (N) and roof displacement (m) per step, and per storey.

    Returns a dict of arrays (``base_shear``, ``roof_displacement``, ``storey_drift`` (n, steps+1),
    ``storey_shear``), the ``control_storey`` (1-based), the ``end`` reason and the pattern's ``S``.
    """
    n = building.n_floors
    k, h = np.asarray(building.stiffness, float), np.asarray(building.height, float)
    kpd = np.asarray(building.p_delta_stiffness, float)
    p = load_pattern(building, pattern)
    share = np.cumsum(p[::-1])[::-1]          # S_i: storey shear over base shear
    limits = []
    for i, law in enumerate(building.hysteresis):
        limit = drift_limit_ratio * h[i]
        if law is not None and hasattr(law, "backbone"):
            limit = min(limit, law.backbone(k[i], h[i])["positive"]["uu"])
        limits.append(limit)
    # The control storey: the least monotonic capacity relative to its share of the base shear.
    capacity = []
    for i, law in enumerate(building.hysteresis):
        probe = StoreySpring(law, k[i], h[i])
        drifts = np.linspace(0.0, limits[i], 2001)[1:]
        capacity.append(max(probe.step(u) + kpd[i] * u for u in drifts) / share[i])
    c = int(np.argmin(capacity))
    springs = [StoreySpring(law, k[i], h[i]) for i, law in enumerate(building.hysteresis)]
    drift = np.zeros(n)
    rows_drift, rows_shear, base = [drift.copy()], [np.zeros(n)], [0.0]
    end = "drift limit"
    du = limits[c] / steps
    for step in range(1, steps + 1):
        u_c = step * du
        force_c = springs[c].step(u_c)
        base_shear = (force_c + kpd[c] * u_c) / share[c]
        if springs[c].failed or base_shear <= 0.0:
            end = "zero strength"
            base_shear = max(base_shear, 0.0) if not springs[c].failed else 0.0
        drift[c] = u_c
        for i in range(n):
            if i == c:
                continue
            target = base_shear * share[i]
            guess = drift[i] + (target - (springs[i].trial(drift[i]) + kpd[i] * drift[i])) / (k[i] + kpd[i])
            drift[i] = _solve_drift(springs[i], kpd[i], target, drift[i], guess)
            springs[i].step(drift[i])
        rows_drift.append(drift.copy())
        rows_shear.append(base_shear * share)
        base.append(base_shear)
        if end == "zero strength":
            break
    storey_drift = np.array(rows_drift).T
    return {"base_shear": np.array(base), "roof_displacement": storey_drift.sum(axis=0), "storey_drift": storey_drift,
            "storey_shear": np.array(rows_shear).T, "control_storey": c + 1, "end": end, "share": share}


def fema_p695_quantities(building, curve: dict, *, period: float | None = None,
                         design_cs: float | None = None) -> dict:
    """V_max (N), W (N), T (s), C₀, δ_y,eff and δ_u (m), μ_T and Ω of a capacity curve (FEMA P695 §6.3)."""
    m = np.asarray(building.mass, float)
    phi = building.modes[1][:, 0]
    c0 = phi[-1] * np.sum(m * phi) / np.sum(m * phi * phi)
    weight = STANDARD_GRAVITY * m.sum()
    t1 = float(building.periods[0])
    t = max(float(period), t1) if period else t1
    v, roof = curve["base_shear"], curve["roof_displacement"]
    peak = int(np.argmax(v))
    v_max = float(v[peak])
    yield_roof = c0 * v_max / weight * STANDARD_GRAVITY / (4.0 * math.pi ** 2) * t * t
    ultimate = float("nan")
    below = np.flatnonzero(v[peak:] <= 0.8 * v_max)
    if below.size:
        j = peak + int(below[0])
        v0, v1, r0, r1 = v[j - 1], v[j], roof[j - 1], roof[j]
        ultimate = float(r0 + (0.8 * v_max - v0) * (r1 - r0) / (v1 - v0)) if v1 != v0 else float(r1)
    return {"v_max": v_max, "roof_at_v_max": float(roof[peak]), "weight": weight, "period": t, "period_t1": t1,
            "c0": float(c0), "yield_roof": float(yield_roof), "ultimate_roof": ultimate,
            "ductility": ultimate / yield_roof, "overstrength": v_max / (design_cs * weight) if design_cs else
            float("nan")}


def pushover(model, *, pattern: str = "first-mode", building: str | None = None, steps: int = 400,
             period: float | None = None, design_cs: float | None = None) -> xr.Dataset:
    """The pushover of every building of *model* (a path or a loaded model), or of *building*: a dataset
    with ``kind = "pushover"`` (capacity curves on ``step``, padded with NaN; FEMA P695 quantities per building;
    the model pushed as YAML text in ``base_model``)."""
    from pounding.model.model import load_model
    from pounding.studies.common import base_model_text

    if steps < MIN_STEPS:
        raise PoundingError(f"--steps must be at least {MIN_STEPS} (got {steps}): fewer equal steps to the drift "
                            "limit miss the capacity curve's peak")
    if steps > MAX_STEPS:
        raise PoundingError(f"--steps must be at most {MAX_STEPS} (got {steps}): each step solves every storey in "
                            "Python (about 0.2 ms a storey-step), and the default 400 already resolves the curve")
    for key, value in (("--period", period), ("--design-cs", design_cs)):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise PoundingError(f"{key} must be a number > 0 (got {value:g})")
    loaded = load_model(model) if isinstance(model, (str, Path)) else model
    names = [b.name for b in loaded.buildings]
    if building is not None and building not in names:
        raise PoundingError(f"no building '{building}' in the model (buildings: {', '.join(names)})")
    chosen = [b for b in loaded.buildings if building is None or b.name == building]
    plan = next((b for b in chosen if b.in_plan), None)
    if plan is not None:
        raise PoundingError(f"building {plan.name} is in plan: its storeys resist through planes and its floors "
                            "move along x, y and a rotation, while pounding pushover pushes one storey spring per "
                            "storey along one direction; pounding p695 pushes it along x and along y as torsion-free "
                            "shear chains (its mu_T per axis)")
    # Each building to its own collapse drift ratio (collapse: {drift_ratio}, else solver.stop_drift_ratio).
    limits = dict(zip(names, loaded.collapse_drift_ratios()))
    curves = [pushover_building(b, pattern, steps=steps, drift_limit_ratio=float(limits[b.name] or DEFAULT_DRIFT_LIMIT))
              for b in chosen]
    results = [fema_p695_quantities(b, c, period=period, design_cs=design_cs) for b, c in zip(chosen, curves)]
    width = max(c["base_shear"].size for c in curves)
    storeys = max(b.n_floors for b in chosen)

    def padded(values, shape):
        out = np.full(shape, np.nan)
        out[tuple(slice(0, s) for s in values.shape)] = values
        return out

    def per_building(key):
        return np.array([r[key] for r in results])

    height = np.array([float(np.sum(b.height)) for b in chosen])
    roof = np.array([padded(c["roof_displacement"], (width,)) for c in curves])
    data = {
        "base_shear": (("building", "step"), np.array([padded(c["base_shear"], (width,)) for c in curves]),
                       {"units": "N", "long_name": "base shear (the lateral load's resultant)"}),
        "roof_displacement": (("building", "step"), roof, {"units": "m", "long_name": "roof displacement"}),
        "roof_drift_ratio": (("building", "step"), roof / height[:, None],
                             {"units": "1", "long_name": "roof displacement over the building's height"}),
        "storey_drift": (("building", "storey", "step"),
                         np.array([padded(c["storey_drift"], (storeys, width)) for c in curves]),
                         {"units": "m", "long_name": "storey drift"}),
        "storey_shear": (("building", "storey", "step"),
                         np.array([padded(c["storey_shear"], (storeys, width)) for c in curves]),
                         {"units": "N", "long_name": "storey shear (lateral load above the storey)"}),
        "v_max": (("building",), per_building("v_max"), {"units": "N", "long_name": "largest base shear V_max"}),
        "weight": (("building",), per_building("weight"), {"units": "N", "long_name": "seismic weight W = g·Σm"}),
        "period": (("building",), per_building("period"), {"units": "s", "long_name": "period T of eq. 6-7"}),
        "c0": (("building",), per_building("c0"), {"units": "1", "long_name": "C0 = φ_r Σmφ / Σmφ² (eq. 6-8)"}),
        "effective_yield_roof_displacement": (("building",), per_building("yield_roof"),
                                              {"units": "m", "long_name": "δ_y,eff (FEMA P695 eq. 6-7)"}),
        "ultimate_roof_displacement": (("building",), per_building("ultimate_roof"),
                                       {"units": "m", "long_name": "δ_u: roof displacement at 20 % strength loss"}),
        "period_based_ductility": (("building",), per_building("ductility"),
                                   {"units": "1", "long_name": "μ_T = δ_u / δ_y,eff (eq. 6-6)"}),
        "overstrength": (("building",), per_building("overstrength"),
                         {"units": "1", "long_name": "Ω = V_max / (C_s W) (eq. 6-5; NaN without --design-cs)"}),
        "control_storey": (("building",), np.array([c["control_storey"] for c in curves]),
                           {"long_name": "storey whose drift controls the pushover (1-based)"}),
        "end": (("building",), np.array([c["end"] for c in curves]), {"long_name": "why the pushover ended"}),
    }
    return xr.Dataset(data, coords={"building": [b.name for b in chosen], "step": np.arange(width),
                                    "storey": np.arange(1, storeys + 1)},
                      attrs={"kind": "pushover", "source": f"pounding {__version__}",
                             "title": f"pushover ({pattern} pattern)",
                             "history": f"pounding pushover {model if isinstance(model, (str, Path)) else '(a loaded model)'} "
                                        f"--pattern {pattern}" + (f" --building {building}" if building else ""),
                             "pattern": pattern, "steps": steps,
                             "model_file": str(model) if isinstance(model, (str, Path)) else "",
                             "base_model": base_model_text(loaded)})


def pushover_table(ds: xr.Dataset) -> str:
    """One row per building: V_max, V_max/W, δ_y,eff, δ_u, μ_T, Ω, the control storey and the end."""
    lines = [f"{'building':<10} {'V_max kN':>10} {'V_max/W':>8} {'T s':>6} {'δy,eff m':>9} {'δu m':>8} "
             f"{'μT':>6} {'Ω':>6} {'storey':>6}  end"]
    for i, name in enumerate(ds.building.values):
        row = ds.isel(building=i)
        lines.append(f"{str(name):<10} {float(row.v_max) / 1e3:>10.1f} {float(row.v_max / row.weight):>8.3f} "
                     f"{float(row.period):>6.3f} {float(row.effective_yield_roof_displacement):>9.4f} "
                     f"{float(row.ultimate_roof_displacement):>8.4f} {float(row.period_based_ductility):>6.2f} "
                     f"{float(row.overstrength):>6.2f} {int(row.control_storey):>6}  {str(row.end.values)}")
    return "\n".join(lines)


#: The per-building quantities of a pushover archive, in the order of :func:`pushover_table`.
BUILDING_QUANTITIES = ["v_max", "weight", "period", "c0", "effective_yield_roof_displacement",
                       "ultimate_roof_displacement", "period_based_ductility", "overstrength", "control_storey", "end"]


def pushover_tables(ds: xr.Dataset) -> dict:
    """The tables of a pushover archive for ``pounding table``: ``buildings`` (V_max, W, T, C₀, δ_y,eff, δ_u,
    μ_T, Ω, control storey, end), ``curves`` (base shear and roof displacement per step) and ``storeys``
    (drift and shear per storey and step); the NaN padding past a building's last step is left out."""
    from pounding.results.tables import long_table

    def steps_taken(frame, value: str):
        return frame[frame[value].notna()].reset_index(drop=True)

    curves = long_table(ds, ["base_shear", "roof_displacement", "roof_drift_ratio"])
    storeys = long_table(ds, ["storey_drift", "storey_shear"])
    return {"buildings": long_table(ds, [n for n in BUILDING_QUANTITIES if n in ds.variables]),
            "curves": steps_taken(curves, curves.columns[-3]),
            "storeys": steps_taken(storeys, storeys.columns[-2])}


def plot_pushover(ds: xr.Dataset, folder: str | Path) -> list[Path]:
    """``pushover.png`` in *folder*: base shear (kN) against roof drift ratio (%), one curve per building."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for i, name in enumerate(ds.building.values):
        row = ds.isel(building=i)
        line, = ax.plot(100 * row.roof_drift_ratio, row.base_shear / 1e3, label=str(name))
        height = float(row.roof_displacement.max() / row.roof_drift_ratio.max())
        for value, style in ((row.effective_yield_roof_displacement, ":"), (row.ultimate_roof_displacement, "--")):
            if np.isfinite(float(value)):
                ax.axvline(100 * float(value) / height, color=line.get_color(), ls=style, lw=0.8)
    ax.set_xlabel("roof drift ratio (%)")
    ax.set_ylabel("base shear (kN)")
    ax.set_title(f"pushover ({ds.attrs['pattern']}); dotted δ_y,eff, dashed δ_u", fontsize=9)
    ax.legend()
    fig.tight_layout()
    out = folder / "pushover.png"
    fig.savefig(out, dpi=130)
    plt.close(fig)
    return [out]
