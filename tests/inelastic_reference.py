"""An independent reference for rows of yielding shear buildings: scipy ``solve_ivp``.

Written from docs/physics.md alone, sharing nothing with ``pounding.solver``
but the model's parameters: dense M, C = a0·M + a1·K (Rayleigh on the elastic
K) and K per building; storey forces from the hysteresis laws written out
again here; P-Delta from the floor masses; Hertz-damp contacts with ξ fixed
at each located closure from the approach velocity.  DOP853 at a tight
tolerance integrates between the record's samples (never across a kink of
a_g), and every switch — gap closure and separation, a bilinear storey's
yield onset and unloading — is a terminal event after which the integration
restarts in the new mode.  Peaks are read off the dense output on a fine grid.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

GRAVITY = 9.80665


class Row:
    """Flat description of a model for the reference (from pounding's Model objects)."""

    def __init__(self, model):
        self.mass, self.k, self.h, self.below, self.kind, self.uy, self.alpha = [], [], [], [], [], [], []
        self.bw = []
        self.pdelta = []
        blocks = []
        offset = 0
        for b in model.buildings:
            n = b.n_floors
            for i in range(n):
                self.mass.append(b.mass[i])
                self.k.append(b.stiffness[i])
                self.h.append(b.height[i])
                self.below.append(offset + i - 1 if i > 0 else -1)
                law = b.hysteresis[i]
                name = None if law is None else law.name
                self.kind.append(name)
                fy = np.nan if law is None else law.yield_force_for(b.stiffness[i], b.height[i])
                self.uy.append(fy / b.stiffness[i])
                self.alpha.append(0.0 if law is None else law.post_yield_ratio)
                self.bw.append((law.n, law.beta, law.gamma, law.A) if name == "bouc-wen" else None)
                weight = GRAVITY * float(np.sum(b.mass[i:]))
                self.pdelta.append(-weight / b.height[i] if b.p_delta else 0.0)
            coefficients = b.rayleigh_coefficients
            if coefficients is None:   # modal damping: the model's own matrix
                blocks.append((offset, np.asarray(b.damping_matrix(), dtype=float)))
                offset += n
                continue
            a0, a1 = coefficients
            kmat = np.zeros((n, n))
            for i in range(n):
                kmat[i, i] += b.stiffness[i]
                if i > 0:
                    kmat[i, i - 1] -= b.stiffness[i]
                    kmat[i - 1, i] -= b.stiffness[i]
                    kmat[i - 1, i - 1] += b.stiffness[i]
            blocks.append((offset, a0 * np.diag(b.mass) + a1 * kmat))
            offset += n
        self.n = offset
        self.mass = np.array(self.mass)
        self.C = np.zeros((self.n, self.n))
        for start, block in blocks:
            m = block.shape[0]
            self.C[start:start + m, start:start + m] = block
        self.contacts = []
        floor0 = np.cumsum([0] + [b.n_floors for b in model.buildings])
        for g in model.gaps:
            law = g.law
            self.contacts.append((floor0[g.left] + g.level_left - 1, floor0[g.right] + g.level_right - 1, g.gap,
                                  law.kh, law.p, law.min_impact_velocity))


def _drift(row, y, j):
    b = row.below[j]
    n = row.n
    if b < 0:
        return y[j], y[n + j]
    return y[j] - y[b], y[n + j] - y[n + b]


def floor_forces(row, y, shear) -> np.ndarray:
    """Damping plus every storey's resisting force (``shear(j, drift)`` and P-Delta) on the floors, N."""
    n = row.n
    f = row.C @ y[n:2 * n]
    for j in range(n):
        d, _ = _drift(row, y, j)
        s = shear(j, d) + row.pdelta[j] * d
        f[j] += s
        if row.below[j] >= 0:
            f[row.below[j]] -= s
    return f


def reference_run(model, ag: np.ndarray, dt: float, duration: float, *, rtol: float = 1e-11,
                  sample: float = 2e-5) -> dict:
    """Integrate *model* under *ag* (m/s², step *dt*); peaks, impacts and the final state."""
    row = Row(model)
    n = row.n
    nc = len(row.contacts)
    mode = [0] * n                   # bilinear: 0 elastic, +1/-1 yielding
    closed = [False] * nc
    xi = [0.0] * nc
    y = np.zeros(3 * n)              # u, v, hysteretic state (plastic drift or z)
    impacts = 0
    peak_drift = np.zeros(n)
    peak_u = np.zeros(n)

    def rhs(t, y, a_g):
        f = row.C @ y[n:2 * n]
        rate = np.zeros(3 * n)
        for j in range(n):
            d, dv = _drift(row, y, j)
            r = y[2 * n + j]
            kind = row.kind[j]
            k = row.k[j]
            if kind is None:
                s = k * d
            elif kind == "bilinear":
                s = row.alpha[j] * k * d + (1 - row.alpha[j]) * k * (d - r)
                rate[2 * n + j] = dv if mode[j] else 0.0
            else:
                nn, beta, gamma, A = row.bw[j]
                uy = row.uy[j]
                s = row.alpha[j] * k * d + (1 - row.alpha[j]) * k * uy * r
                rate[2 * n + j] = dv / uy * (A - abs(r) ** nn * (beta * np.sign(dv * r) + gamma))
            s += row.pdelta[j] * d
            f[j] += s
            if row.below[j] >= 0:
                f[row.below[j]] -= s
        for c, (lf, rf, gap, kh, p, vmin) in enumerate(row.contacts):
            if closed[c]:
                delta = y[lf] - y[rf] - gap
                ddot = y[n + lf] - y[n + rf]
                force = max(0.0, max(delta, 0.0) ** 1.5 * (kh + xi[c] * ddot))
                f[lf] += force
                f[rf] -= force
        rate[:n] = y[n:2 * n]
        rate[n:2 * n] = -f / row.mass - a_g
        return rate

    def events_for():
        found = []
        for c, (lf, rf, gap, *_rest) in enumerate(row.contacts):
            def ev(t, y, *args, lf=lf, rf=rf, gap=gap):
                return y[lf] - y[rf] - gap
            ev.terminal = True
            ev.direction = -1 if closed[c] else 1
            found.append(("contact", c, ev))
        for j in range(n):
            if row.kind[j] != "bilinear":
                continue
            if mode[j] == 0:
                for sign in (1, -1):
                    def ev(t, y, *args, j=j, sign=sign):
                        d, _ = _drift(row, y, j)
                        return (d - y[2 * n + j]) - sign * row.uy[j]
                    ev.terminal = True
                    ev.direction = sign
                    found.append(("yield", (j, sign), ev))
            else:
                def ev(t, y, *args, j=j):
                    return _drift(row, y, j)[1]
                ev.terminal = True
                ev.direction = -mode[j]
                found.append(("unload", j, ev))
        return found

    def track(sol, a, b):
        nonlocal peak_drift, peak_u
        grid = np.linspace(a, b, max(2, int(np.ceil((b - a) / sample)) + 1))
        states = sol.sol(grid)
        u = states[:n]
        drift = u.copy()
        for j in range(n):
            if row.below[j] >= 0:
                drift[j] -= u[row.below[j]]
        peak_u = np.maximum(peak_u, np.abs(u).max(axis=1))
        peak_drift = np.maximum(peak_drift, np.abs(drift).max(axis=1))

    samples = np.arange(int(round(duration / dt)) + 1) * dt
    for i in range(samples.size - 1):
        t0, t1 = samples[i], samples[i + 1]
        g0, g1 = ag[i], ag[i + 1] if i + 1 < ag.size else ag[-1]
        t = t0
        while t < t1 - 1e-15:
            evs = events_for()
            sol = solve_ivp(lambda tt, yy: rhs(tt, yy, g0 + (g1 - g0) * (tt - t0) / dt), (t, t1), y,
                            method="DOP853", rtol=rtol, atol=rtol * 1e-3, dense_output=True,
                            events=[e for _, _, e in evs])
            hit = [(te[0], idx) for idx, te in enumerate(sol.t_events) if te.size]
            if not hit:
                track(sol, t, t1)
                y = sol.y[:, -1]
                t = t1
                break
            te, idx = min(hit)
            track(sol, t, te)
            y = sol.y_events[idx][0].copy()
            what, which, _ = evs[idx]
            if what == "contact":
                lf, rf, gap, kh, p, vmin = row.contacts[which]
                if not closed[which]:
                    v0 = y[n + lf] - y[n + rf]
                    closed[which] = True
                    xi[which] = p * kh / max(v0, vmin)
                    impacts += 1
                else:
                    closed[which] = False
            elif what == "yield":
                j, sign = which
                d, dv = _drift(row, y, j)
                y[2 * n + j] = d - sign * row.uy[j]
                mode[j] = sign if dv * sign > 0 else 0
            else:
                mode[which] = 0
            t = te
    final_drift = np.array([_drift(row, y, j)[0] for j in range(n)])
    return {"peak_drift": peak_drift, "peak_displacement": peak_u, "impacts": impacts,
            "final_drift": final_drift, "height": np.array(row.h)}
