"""The modified Ibarra–Medina–Krawinkler storey driven by a drift history (the material alone).

:class:`ImkMaterial` takes one storey drift after another (m) and returns the
storey shear (N), the way a uniaxial material of OpenSees is driven by
``setStrain``.  The rules are those of Ibarra, Medina & Krawinkler (2005) as
modified by Lignos & Krawinkler (2011), branch by branch as OpenSees'
``IMKBilin`` (Nov 2022), ``IMKPeakOriented`` and ``IMKPinching`` (Sep 2023,
A. Elkady and H. Eljisr) state them; docs/hysteresis.md lists the rules and
the two places where this implementation follows the paper instead.

Each direction's backbone is kept in its own coordinates (u' = σu, F' = σF
with σ = +1 positive, −1 negative), so one routine serves both directions:
:class:`Backbone`.  Branches (``branch``) of the peak-oriented and pinching
variants: elastic, unloading, then toward the pinching point, the last local
peak, the global peak, the capping point (hardening), along the post-capping
branch, residual; ``side`` is the direction of the reloading and backbone
branches.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pounding.hysteresis import ImkStorey
from pounding.solver.imk import beta

__all__ = ["ImkMaterial", "Backbone", "ELASTIC", "UNLOAD", "PINCH", "LOCAL", "GLOBAL", "HARDENING",
           "POST_CAPPING", "RESIDUAL"]

ELASTIC, UNLOAD, PINCH, LOCAL, GLOBAL, HARDENING, POST_CAPPING, RESIDUAL = range(8)


@dataclass
class Backbone:
    """One direction's current (deteriorated) backbone and peaks, in that direction's coordinates.

    Forces in N, drifts in m, stiffnesses in N/m; ``kpc`` < 0 (post-capping
    slope); ``fy0`` and ``kpc0`` the initial yield force and post-capping slope.
    """

    fy: float
    uy: float
    kp: float
    kpc: float
    ucap: float
    fcap: float
    fres: float
    ures: float
    uu: float
    rate: float
    fy0: float
    kpc0: float
    u_local: float
    f_local: float
    u_global: float
    f_global: float
    #: The last excursion's (1 − β D) reached zero: the strength is spent (the storey fails).
    exhausted: bool = False

    @classmethod
    def initial(cls, ke: float, fy: float, up: float, upc: float, uu: float, fcap_ratio: float,
                fres_ratio: float, d: float) -> Backbone:
        """The undeteriorated backbone: yield (F_y/k_e, F_y), capping (u_y + u_p, F_c), slope −F_c/u_pc."""
        uy = fy / ke
        fcap = fcap_ratio * fy
        kp = (fcap - fy) / up
        kpc = -fcap / upc
        fres = fres_ratio * fy
        ucap = uy + up
        return cls(fy=fy, uy=uy, kp=kp, kpc=kpc, ucap=ucap, fcap=fcap, fres=fres,
                   ures=(fres - fcap) / kpc + ucap, uu=uu, rate=d, fy0=fy, kpc0=kpc,
                   u_local=uy, f_local=fy, u_global=uy, f_global=fy)

    def deteriorate(self, ke: float, beta_s: float, beta_c: float, beta_a: float) -> float:
        """Basic strength (β_s), post-capping strength (β_c) and target drift (β_a) at a new excursion.

        The yield force and hardening slope scale by (1 − β_s D), the
        post-capping line's intercept at zero drift by (1 − β_c D), the
        global peak's drift by (1 + β_a D) (Ibarra et al. 2005 eq. 5-7;
        Lignos & Krawinkler 2011 Fig. 3).  Returns that intercept (N): the
        capping point is then :meth:`place_capping_point`'s.
        """
        intercept_pc = self.fcap - self.kpc * self.ucap
        strength, capping = 1.0 - beta_s * self.rate, 1.0 - beta_c * self.rate
        # D > 1 and β near 1 would turn the strength negative (a storey giving energy back): the capacity is
        # exhausted, as where β > 1 (Ibarra et al. 2005); the caller fails the storey.
        self.exhausted = strength <= 0.0 or capping <= 0.0
        self.fy *= max(strength, 0.0)
        self.kp *= max(strength, 0.0)
        self.u_global *= 1.0 + beta_a * self.rate
        self.uy = self.fy / ke
        return intercept_pc * max(capping, 0.0)

    def place_capping_point(self, intercept_pc: float) -> None:
        """Capping point where the hardening line meets the post-capping line of intercept *intercept_pc* (N)."""
        intercept_p = self.fy - self.kp * self.uy
        self.ucap = 0.0 if self.kp <= self.kpc else (intercept_pc - intercept_p) / (self.kp - self.kpc)
        self.fcap = intercept_p + self.kp * self.ucap

    def force_at(self, ke: float, u: float) -> float:
        """The backbone's force at drift *u* (this direction's coordinates), not below the residual."""
        if u < self.uy:
            f = ke * u
        elif u < self.ucap:
            f = self.fy + self.kp * (u - self.uy)
        else:
            f = self.fcap + self.kpc * (u - self.ucap)
        return max(f, self.fres)


def _slope(df: float, du: float, fallback: float) -> float:
    """df/du (N/m), or *fallback* where the two points coincide (the branch is left at once then)."""
    return df / du if du != 0.0 else fallback


class ImkMaterial:
    """An IMK storey's shear (N) as a function of its drift history (m): call :meth:`step` per drift.

    Parameters
    ----------
    law : ImkStorey
        The storey's validated IMK parameters.
    stiffness : float
        Elastic storey stiffness k_e, N/m.
    height : float
        Storey height h, m (drift ratios × h are drifts; E_t = Λ F_y h).
    """

    def __init__(self, law: ImkStorey, stiffness: float, height: float):
        p = law.backbone(stiffness, height)
        self.variant = law.variant
        self.ke = float(stiffness)
        self.sides = {+1: Backbone.initial(self.ke, **p["positive"]), -1: Backbone.initial(self.ke, **p["negative"])}
        self.e_s, self.e_c, self.e_a, self.e_k = p["e_s"], p["e_c"], p["e_a"], p["e_k"]
        self.c_s, self.c_c, self.c_a, self.c_k = p["c_s"], p["c_c"], p["c_a"], p["c_k"]
        self.kappa_f, self.kappa_d = p["kappa_f"], p["kappa_d"]
        self.u = 0.0
        self.f = 0.0
        self.k_unload = self.ke
        self.k_reload = self.ke
        self.energy = 0.0           #: work done on the storey, J (∫F dΔ, trapezoidal)
        self.energy_last = 0.0      #: the work at the start of the current excursion, J
        self.branch = ELASTIC
        self.side = 1
        self.u_pinch = 0.0          #: pinching point (absolute coordinates), m and N
        self.f_pinch = 0.0
        self.failed = False
        self.on_backbone = False    # imk-bilinear
        self.yielded = False        # imk-bilinear: deterioration starts at the first yield
        self.residual = False       # imk-bilinear: the residual branch has been reached
        self.lost = {+1: False, -1: False}  # imk-bilinear: a direction whose strength is lost

    # ------------------------------------------------------------------ #

    def step(self, u: float) -> float:
        """Move to drift *u* (m) from the last one; returns the storey shear, N."""
        u_prev, f_prev = self.u, self.f
        du = u - u_prev
        self.u = u
        if self.failed:
            self.f = 0.0
            return 0.0
        if du == 0.0:
            return f_prev
        if self.variant == "bilinear":
            f = self._bilinear(u, u_prev, f_prev, du)
        else:
            f = self._oriented(u, u_prev, f_prev, du)
        self.energy += 0.5 * (f + f_prev) * du
        self.f = f
        return f

    def run(self, drifts) -> list[float]:
        """Shear (N) after each drift of *drifts* (m), starting from the current state."""
        return [self.step(float(u)) for u in drifts]

    # ------------------------------------------------------------------ #

    def _unloading_deterioration(self, f_prev: float) -> bool:
        """Unloading stiffness at a reversal: k_u ← k_u(1 − β_k), the elastic energy of the unloading
        excluded from both E_i and ΣE (OpenSees); returns whether the capacity is exhausted."""
        elastic = 0.5 * f_prev * f_prev / self.k_unload
        beta_k, fail = beta(self.energy - self.energy_last - elastic, self.e_k, self.energy - elastic, self.c_k)
        self.k_unload *= 1.0 - beta_k
        return fail

    def _excursion_betas(self) -> tuple[float, float, float, bool]:
        """β_s, β_c, β_a of a new excursion (E_i: the work since the last one) and whether any fails."""
        spent = self.energy
        e_i = max(0.0, spent - self.energy_last)
        beta_s, fail_s = beta(e_i, self.e_s, spent, self.c_s)
        beta_c, fail_c = beta(e_i, self.e_c, spent, self.c_c)
        beta_a, fail_a = beta(e_i, self.e_a, spent, self.c_a)
        self.energy_last = spent
        return beta_s, beta_c, beta_a, fail_s or fail_c or fail_a

    # ------------------------------------------------------------------ #
    # Peak-oriented and pinching
    # ------------------------------------------------------------------ #

    def _oriented(self, u: float, u_prev: float, f_prev: float, du: float) -> float:
        fail = False
        if self.branch > UNLOAD and (f_prev * du < 0.0 or (f_prev == 0.0 and u_prev * du <= 0.0)):
            # Reversal: the last point is the direction's local peak (and its global peak if farther).
            self.branch = UNLOAD
            sigma = 1 if f_prev > 0.0 else -1
            b = self.sides[sigma]
            b.u_local, b.f_local = sigma * u_prev, sigma * f_prev
            if sigma * u_prev > b.u_global:
                b.u_global, b.f_global = b.u_local, b.f_local
            fail = self._unloading_deterioration(f_prev)
        if self.branch == UNLOAD and f_prev * (f_prev + self.k_unload * du) <= 0.0:
            fail = self._new_excursion(1 if du > 0.0 else -1, u_prev, f_prev) or fail
        self._shift(u, f_prev)
        f = self._branch_force(u, f_prev, du)
        pos, neg = self.sides[1], self.sides[-1]
        sigma = self.side
        if (fail or pos.f_global == 0.0 or neg.f_global == 0.0
                or (du > 0.0 and u >= pos.uu) or (du < 0.0 and -u >= neg.uu)
                or (self.branch == RESIDUAL and sigma * f <= 0.0)):
            self.failed = True
            f = 0.0
        return f

    def _new_excursion(self, sigma: int, u_prev: float, f_prev: float) -> bool:
        """The force crosses zero on unloading: deteriorate the backbone ahead, choose the reloading target."""
        beta_s, beta_c, beta_a, fail = self._excursion_betas()
        b = self.sides[sigma]
        b.place_capping_point(b.deteriorate(self.ke, beta_s, beta_c, beta_a))
        fail = fail or b.exhausted
        b.f_global = b.force_at(self.ke, b.u_global)
        b.ures = (b.fres - b.fcap + b.kpc * b.ucap) / b.kpc
        u0 = sigma * (u_prev - f_prev / self.k_unload)  # zero-force drift, this direction's coordinates
        k_global = b.f_global / (b.u_global - u0)
        k_local = _slope(b.f_local, b.u_local - u0, -math.inf)  # 0/0 in OpenSees: NaN, never chosen
        self.side = sigma
        if self.variant == "pinching":
            u_plastic = b.u_global - b.f_global / self.k_unload
            u_pinch = (1.0 - self.kappa_d) * u_plastic
            f_pinch = self.kappa_f * b.f_global * (u_pinch - u0) / (b.u_global - u0)
            self.u_pinch, self.f_pinch = sigma * u_pinch, sigma * f_pinch
            if u0 < u_pinch:
                self.branch, self.k_reload = PINCH, f_pinch / (u_pinch - u0)
                return fail
        if u0 < b.u_local and b.f_local < b.f_global and k_local > k_global:
            self.branch, self.k_reload = LOCAL, k_local
        else:
            self.branch, self.k_reload = GLOBAL, k_global
        return fail

    def _shift(self, u: float, f_prev: float) -> None:
        """Branch changes reached at drift *u*: yield, back to reloading, then along the reloading path."""
        if self.branch == ELASTIC:
            for sigma in (1, -1):
                if sigma * u > self.sides[sigma].uy:
                    self.branch, self.side = HARDENING, sigma
                    break
        elif self.branch == UNLOAD and f_prev != 0.0:
            sigma = 1 if f_prev > 0.0 else -1
            b = self.sides[sigma]
            if sigma * u > b.u_local:  # reloading again before the force changed sign
                self.side = sigma
                self.branch, self.k_reload = GLOBAL, _slope(b.f_global - b.f_local, b.u_global - b.u_local, self.ke)
                if self.variant == "pinching":
                    up, fp = sigma * self.u_pinch, sigma * self.f_pinch
                    k_pinch = _slope(fp - b.f_local, up - b.u_local, self.ke)
                    if (b.u_local < up and b.f_local < fp and up < b.u_global and fp < b.f_global
                            and k_pinch < self.k_reload):
                        self.branch, self.k_reload = PINCH, k_pinch
        if self.branch <= UNLOAD:
            return
        sigma = self.side
        b = self.sides[sigma]
        x = sigma * u
        if self.branch == PINCH and x > sigma * self.u_pinch:
            up, fp = sigma * self.u_pinch, sigma * self.f_pinch
            k_global = _slope(b.f_global - fp, b.u_global - up, self.ke)
            k_local = _slope(b.f_local - fp, b.u_local - up, self.ke)
            if up < b.u_local and fp < b.f_local and b.f_local < b.f_global and k_local > k_global:
                self.branch, self.k_reload = LOCAL, k_local
            else:
                self.branch, self.k_reload = GLOBAL, k_global
        if self.branch == LOCAL and x > b.u_local:
            self.branch, self.k_reload = GLOBAL, _slope(b.f_global - b.f_local, b.u_global - b.u_local, self.ke)
        if self.branch == GLOBAL and x > b.u_global:
            self.branch = HARDENING
        if self.branch == HARDENING and x > b.ucap:
            self.branch = POST_CAPPING
        if self.branch == POST_CAPPING and x > b.ures:
            self.branch = RESIDUAL

    def _branch_force(self, u: float, f_prev: float, du: float) -> float:
        """The force of the current branch at drift *u*, N."""
        if self.branch == ELASTIC:
            return self.ke * u
        if self.branch == UNLOAD:
            return f_prev + self.k_unload * du
        sigma = self.side
        b = self.sides[sigma]
        x = sigma * u
        if self.branch == PINCH:
            f = sigma * self.f_pinch + self.k_reload * (x - sigma * self.u_pinch)
        elif self.branch == LOCAL:
            f = b.f_local + self.k_reload * (x - b.u_local)
        elif self.branch == GLOBAL:
            f = b.f_global + self.k_reload * (x - b.u_global)
        elif self.branch == HARDENING:
            f = b.fcap + b.kp * (x - b.ucap)
        elif self.branch == POST_CAPPING:
            f = b.fcap + b.kpc * (x - b.ucap)
        else:
            f = b.fres
        return sigma * f

    # ------------------------------------------------------------------ #
    # Bilinear
    # ------------------------------------------------------------------ #

    def _bilinear(self, u: float, u_prev: float, f_prev: float, du: float) -> float:
        """IMKBilin: elastic (deteriorating) unloading and reloading, bounded by the deteriorated backbone."""
        fail = False
        if self.on_backbone and (f_prev * du < 0.0 or (f_prev == 0.0 and u_prev * du <= 0.0)):
            self.on_backbone = False
            fail = self._unloading_deterioration(f_prev)
            if self.residual or self.lost[1] or self.lost[-1]:
                # OpenSees IMKBilin: once a residual branch has been reached, unloading is at k_e / 2.
                self.k_unload = 0.5 * self.ke
        f = f_prev + self.k_unload * du
        sigma = 1 if du > 0.0 else -1
        b = self.sides[sigma]
        if not self.on_backbone and f_prev * f <= 0.0 and self.yielded:
            beta_s, beta_c, _, fail_e = self._excursion_betas()
            intercept_pc = b.deteriorate(self.ke, beta_s, beta_c, 0.0)
            fail = fail or fail_e or b.exhausted
            # The post-capping slope shrinks with the yield force's excess over the residual (IMKBilin).
            b.kpc = 0.0 if b.fy < b.fres else b.kpc0 * (b.fy - b.fres) / (b.fy0 - b.fres)
            b.place_capping_point(intercept_pc)
            # Hardening no steeper than the line from the unloading's zero-residual point to the cap.
            x_prev, g_prev = sigma * u_prev, sigma * f_prev
            candidate = (b.fcap - b.fres) / (b.ucap - x_prev - (b.fres - g_prev) / self.k_unload)
            if b.fcap < b.fres:
                b.fy = b.fcap = b.fres
                b.kp = b.kpc = 0.0
                b.uy = b.fy / self.ke
                b.ucap = 0.0
            elif 0.0 < candidate < b.kp:
                b.kp = candidate
            if b.kpc != 0.0:  # kept current for readers; the residual tests below compute it themselves
                b.ures = (b.fres - b.fcap + b.kpc * b.ucap) / b.kpc
        x = sigma * u
        slope = b.kp if x < b.ucap else b.kpc
        bound = b.fcap + (x - b.ucap) * slope
        if bound < b.fres or self.lost[-sigma]:
            bound = b.fres
        if self.lost[sigma]:
            bound = 0.0
        if sigma * f > bound:
            f = sigma * bound
            self.on_backbone = True
        pos, neg = self.sides[1], self.sides[-1]
        residual_pos = f == pos.fres if pos.kpc == 0.0 else u >= (pos.fres - pos.fcap + pos.kpc * pos.ucap) / pos.kpc
        residual_neg = -f == neg.fres if neg.kpc == 0.0 else -u >= (neg.fres - neg.fcap + neg.kpc * neg.ucap) / neg.kpc
        ahead = self.sides[sigma]
        lost_here = sigma * u >= ahead.uu or (self.on_backbone and sigma * f <= 0.0)
        if fail:
            self.failed = True
            f = 0.0
        elif lost_here:
            f = 0.0
            self.lost[sigma] = True
            self.failed = self.lost[-sigma]
        elif residual_pos or residual_neg:
            self.residual = True
        if self.on_backbone or self.residual or self.lost[sigma]:
            self.yielded = True
        return f
