"""Formulas for the damping constant ξ of the Hertz-damp contact law.

The Hertz-damp law (Hunt–Crossley form) is ``F = kh·δ^1.5 + ξ·δ^1.5·δ̇``.
Every published formula for ξ has the form

    ξ = p(e) · kh / v0

with ``e`` the coefficient of restitution, ``kh`` the Hertz stiffness
(N/m^1.5) and ``v0`` the approach velocity at the instant the gap closes
(m/s).  A formula is therefore one dimensionless function ``p(e)``; this module
keeps them in a registry keyed by name, in the style of
``scipy.integrate._ivp``: adding a formula is one function and one
:func:`register` line with its citation.

>>> from pounding.contact import xi
>>> round(xi.p("ye", 0.65), 6)
0.861538
>>> round(xi.damping_constant("lankarani-nikravesh", restitution=0.65, kh=1e10, v0=0.5))
8662500000
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from pounding.errors import PoundingError, did_you_mean
from pounding.registry import add_unique, lookup

__all__ = [
    "XiFormula",
    "FORMULAS",
    "ALIASES",
    "register",
    "get",
    "p",
    "damping_constant",
    "names",
    "catalogue",
]


@dataclass(frozen=True)
class XiFormula:
    """One published formula for the Hertz-damp damping constant.

    Attributes
    ----------
    key : str
        Registry name, e.g. ``"ye"``.
    function : callable
        ``p(e)``, dimensionless, for 0 < e ≤ 1; ``ξ = p(e)·kh/v0``.
    expression : str
        ``p(e)`` written out, for listings.
    reference : str
        The paper the formula comes from.
    status : str
        ``confirmed`` (checked against the paper), ``secondary`` (taken from a
        review that cites it) or ``unconfirmed`` (forms differ between sources).
    bounded : bool
        True if ``p(e)`` stays of order one as e → 0 (at most 3·exp(2)/4 ≈
        5.5, zhiying-qishao's limit); such a formula cannot produce low restitution
        in a free impact.  ``carvalho-martins`` tends to 16.5 and ``exact``
        and the 1/e-type formulas diverge: they are not bounded in this sense.
    """

    key: str
    function: Callable[[float], float]
    expression: str
    reference: str
    status: str
    bounded: bool

    def __call__(self, restitution: float) -> float:
        return float(self.function(float(restitution)))


FORMULAS: dict[str, XiFormula] = {}
ALIASES: dict[str, str] = {}


def register(key: str, expression: str, reference: str, status: str, *, bounded: bool,
             aliases: tuple[str, ...] = ()) -> Callable[[Callable[[float], float]], Callable[[float], float]]:
    """Decorator: register ``p(e)`` under *key* with its citation."""

    def wrap(function: Callable[[float], float]) -> Callable[[float], float]:
        add_unique(FORMULAS, key, XiFormula(key, function, expression, reference, status, bounded), "xi formula")
        for alias in aliases:
            add_unique(ALIASES, alias, key, "xi formula alias")
        return function

    return wrap


# --------------------------------------------------------------------------- #
# The catalogue (docs/physics.md §3).  Each entry: one function, one register line.
# --------------------------------------------------------------------------- #


@register("hunt-crossley", "3(1-e)/2",
          "Hunt, K.H. & Crossley, F.R.E. (1975). Coefficient of restitution interpreted as "
          "damping in vibroimpact. J. Appl. Mech. 42(2), 440-445.",
          "confirmed", bounded=True)
def hunt_crossley(e: float) -> float:
    """Hunt & Crossley (1975): first-order expansion for e → 1."""
    return 1.5 * (1.0 - e)


@register("herbert-mcwhannell", "6(1-e)/((2e-1)^2+3)",
          "Herbert, R.G. & McWhannell, D.C. (1977). Shape and frequency composition of pulses "
          "from an impact pair. J. Eng. Ind. 99(3), 513-518. Form as in ladisk/DyS (Skrinjar, after "
          "Machado et al. 2012).",
          "secondary", bounded=True)
def herbert_mcwhannell(e: float) -> float:
    """Herbert & McWhannell (1977), as quoted in later reviews.

    Catalogue check: the original paper was not reachable.  The same form,
    ``6(1−e)/((2e−1)²+3)``, is what L. Skrinjar (Ladisk, Ljubljana, the group
    of the review Skrinjar, Slavič & Boltežar 2018, Int. J. Mech. Sci. 145,
    171-187) implements in GitHub ladisk/DyS,
    ``MBD_system/contact_model/contact_model.py``, which states it follows
    Machado et al. (2012), Mech. Mach. Theory 53, 99-121.  Secondary.
    """
    return 6.0 * (1.0 - e) / ((2.0 * e - 1.0) ** 2 + 3.0)


@register("lee-wang", "3(1-e)/4",
          "Lee, T.W. & Wang, A.C. (1983). On the dynamics of intermittent-motion mechanisms. "
          "Part 1. J. Mech. Transm. Autom. Des. 105(3), 534-540. Form as in ladisk/DyS (Skrinjar, after "
          "Machado et al. 2012).",
          "secondary", bounded=True)
def lee_wang(e: float) -> float:
    """Lee & Wang (1983).

    Catalogue check: the original paper was not reachable.  ``3(1−e)/4``
    matches ladisk/DyS ``MBD_system/contact_model/contact_model.py`` (Skrinjar,
    after Machado et al. 2012); one stored version of that file multiplies by
    ``K/v0`` twice, an evident slip, the other has the plain form.  Secondary.
    """
    return 0.75 * (1.0 - e)


@register("lankarani-nikravesh", "3(1-e^2)/4",
          "Lankarani, H.M. & Nikravesh, P.E. (1990). A contact force model with hysteresis "
          "damping for impact analysis of multibody systems. J. Mech. Des. 112(3), 369-376. "
          "Used for pounding by Muthukumar, S. & DesRoches, R. (2006), EESD 35, 811-828.",
          "confirmed", bounded=True, aliases=("muthukumar-desroches", "ln"))
def lankarani_nikravesh(e: float) -> float:
    """Lankarani & Nikravesh (1990); the formula of Muthukumar & DesRoches (2006).

    Derived assuming e close to 1; it cannot represent low restitution
    (Ye, Li & Zhu 2009 call it the "initial formula").
    """
    return 0.75 * (1.0 - e * e)


@register("gonthier", "(1-e^2)/e",
          "Gonthier, Y., McPhee, J., Lange, C. & Piedboeuf, J.-C. (2004). A regularized contact "
          "model with asymmetric damping and dwell-time dependent friction. Multibody Syst. Dyn. "
          "11, 209-233.",
          "confirmed", bounded=False)
def gonthier(e: float) -> float:
    """Gonthier et al. (2004)."""
    return (1.0 - e * e) / e


@register("zhiying-qishao", "3(1-e^2)exp(2(1-e))/4",
          "Zhiying, Q. & Qishao, L. (2006). Analysis of impact process based on restitution "
          "coefficient. J. Dyn. Control 4, 294-298. Form as in ladisk/DyS (Skrinjar, after Machado et "
          "al. 2012).",
          "secondary", bounded=True)
def zhiying_qishao(e: float) -> float:
    """Zhiying & Qishao (2006).

    Catalogue check: the original (in Chinese) was not reachable.
    ``3(1−e²)·exp(2(1−e))/4`` matches ladisk/DyS
    ``MBD_system/contact_model/contact_model.py`` (Skrinjar, after Machado et
    al. 2012).  Secondary.
    """
    return 0.75 * (1.0 - e * e) * math.exp(2.0 * (1.0 - e))


@register("ye", "8(1-e)/(5e)",
          "Ye, K., Li, L. & Zhu, H. (2009). A note on the Hertz contact model with nonlinear "
          "damping for pounding simulation. Earthquake Eng. Struct. Dyn. 38, 1135-1142. "
          "Identical to Flores, P. et al. (2011), Multibody Syst. Dyn. 25, 357-375.",
          "confirmed", bounded=False, aliases=("flores", "ye-li-zhu", "corrected"))
def ye(e: float) -> float:
    """Ye, Li & Zhu (2009) "corrected formula" (= Flores et al. 2011)."""
    return 1.6 * (1.0 - e) / e


@register("gharib-hurmuzlu", "(1-e)/e",
          "Gharib, M. & Hurmuzlu, Y. (2012). A new contact force model for low coefficient of "
          "restitution impact. J. Appl. Mech. 79(6), 064506. Form not confirmed in any source found.",
          "unconfirmed", bounded=False)
def gharib_hurmuzlu(e: float) -> float:
    """Gharib & Hurmuzlu (2012).

    Catalogue check: not confirmable with the sources searched (the paper,
    the reviews of Machado et al. 2012 and Skrinjar et al. 2018 were not
    readable; no code implementing it with a formula was found, only plot
    labels).  ``(1−e)/e`` is kept as the brief gives it; unconfirmed.
    """
    return (1.0 - e) / e


@register("hu-guo", "3(1-e)/(2e)",
          "Hu, S. & Guo, X. (2015). A dissipative contact force model for impact analysis in "
          "multibody dynamics. Multibody Syst. Dyn. 35, 131-151. Form not confirmed: ladisk/DyS "
          "(Skrinjar) uses 3(1-e)/(4e).",
          "unconfirmed", bounded=False)
def hu_guo(e: float) -> float:
    """Hu & Guo (2015); a 3(1-e)/(4e) variant also circulates.

    Catalogue check: the two forms remain in conflict.  ladisk/DyS
    ``MBD_system/contact_model/contact_model.py`` (Skrinjar, author of the
    2018 review) implements Hu-Guo as ``(3/2)(1−e)/(2e)`` = ``3(1−e)/(4e)``,
    the variant, not the ``3(1−e)/(2e)`` used here; no readable copy of the
    paper or of a review quoting its formula was found.  Unconfirmed: check
    the paper before relying on this key.
    """
    return 1.5 * (1.0 - e) / e


@register("carvalho-martins", "3(1-e)(11-e)/(2(1+9e))",
          "Carvalho, A.S. & Martins, J.M. (2019). Exact restitution and generalizations for the "
          "Hunt-Crossley contact model. Mech. Mach. Theory 139, 174-194 (rational approximation).",
          "secondary", bounded=False)
def carvalho_martins(e: float) -> float:
    """Carvalho & Martins (2019), rational approximation of the exact relation.

    Catalogue check: not found in the sources searched (no review or code
    quoting it).  Numerically it is a good fit of :func:`exact` for e ≳ 0.5
    (the ball drop of :mod:`pounding.studies.verify` gives e_post within 2e-4 of
    e_pre there) and drifts high below (0.303 at e = 0.3, 0.128 at 0.1).
    """
    return 1.5 * (1.0 - e) * (11.0 - e) / (1.0 + 9.0 * e)


def _relation_over_p2(p_value: float, e: float) -> float:
    """``g(p)/p²`` with ``g(p) = ln(1+p) − ln(1−e·p) − (1+e)·p``.

    Dividing by p² removes the trivial root p = 0 (both sides of the relation
    agree to second order there).  For small p the series
    ``Σ_{k≥2} p^(k−2)·(e^k − (−1)^k)/k`` is summed instead, which has no
    cancellation.
    """
    if p_value < 0.05 and e * p_value < 0.05:
        log_e = math.log1p(-(1.0 - e))  # 1 − e is exact for e ≥ 0.5: no cancellation in e^k − 1
        total, term_p, k = 0.0, 1.0, 2
        while True:
            coefficient = math.expm1(k * log_e) if k % 2 == 0 else e**k + 1.0
            term = term_p * coefficient / k
            total += term
            if abs(term) <= 1e-18 * abs(total) or k > 60:
                return total
            term_p *= p_value
            k += 1
    if e * p_value >= 1.0:
        return math.inf
    g = math.log1p(p_value) - math.log1p(-e * p_value) - (1.0 + e) * p_value
    return g / (p_value * p_value)


@register("exact", "root of ln((1+p)/(1-e p)) = (1+e) p",
          "Exact restitution of the Hunt-Crossley law for two free bodies (docs/physics.md §3); the "
          "exact-restitution idea of Carvalho, A.S. & Martins, J.M. (2019), Mech. Mach. Theory "
          "139, 174-194.",
          "derived", bounded=False, aliases=("exact-restitution",))
def exact(e: float) -> float:
    """Root p in (0, 1/e) of ``ln((1+p)/(1−e·p)) = (1+e)·p``.

    Integrating ``m_eff·v·dv/(1 + (ξ/kh)·v) = −kh·δ^n·dδ`` over a whole free
    contact gives this relation, independent of n, kh and the masses; it is
    the only formula for which a free impact rebounds with exactly ``e``.
    Solved by Brent's method on ``g(p)/p²``, which is negative near 0
    (value (e²−1)/2) and tends to +∞ as p → 1/e.  As e → 1, p ≈ 1.5(1−e);
    as e → 0, p → 1/e (for e ≲ 2e-3, 1−e·p underflows and p = 1/e to double
    precision).
    """
    from scipy.optimize import brentq

    if e >= 1.0:
        return 0.0
    upper = 1.0 / e
    # Walk the upper bracket towards 1/e until the function is positive there.
    high = upper * (1.0 - 1e-3)
    while _relation_over_p2(high, e) <= 0.0:
        gap = upper - high
        if gap <= 4.0 * math.ulp(upper):
            return upper
        high = upper - gap * 1e-3
    low = min(1.5 * (1.0 - e) * 0.5, high * 0.5)
    while _relation_over_p2(low, e) >= 0.0:
        low *= 0.5
    return brentq(_relation_over_p2, low, high, args=(e,), xtol=1e-300, rtol=4.0 * 2.0**-52,
                  maxiter=500)


# --------------------------------------------------------------------------- #
# Look-up
# --------------------------------------------------------------------------- #


def names() -> list[str]:
    """Registry keys, in catalogue order."""
    return list(FORMULAS)


def get(name: str) -> XiFormula:
    """Return the formula registered as *name* (or an alias of it; case is ignored, :func:`pounding.registry.lookup`).

    Raises
    ------
    PoundingError
        For an unknown name, with a "did you mean" suggestion.
    """
    key = lookup(FORMULAS, name, ALIASES)
    if key is None:
        choices = list(FORMULAS) + list(ALIASES)
        raise PoundingError(f"unknown xi formula '{name}'{did_you_mean(str(name), choices)}; "
                            f"choose one of: {', '.join(FORMULAS)}")
    return FORMULAS[key]


def p(name: str, restitution: float) -> float:
    """Dimensionless ``p(e) = ξ·v0/kh`` of formula *name*."""
    check_restitution(restitution)
    return get(name)(restitution)


def check_restitution(restitution: float) -> None:
    """Raise unless 0 < e ≤ 1."""
    if not (0.0 < restitution <= 1.0):
        raise PoundingError(f"coefficient of restitution must be in (0, 1] (got {restitution})")


def damping_constant(name: str, restitution: float, kh: float, v0: float) -> float:
    """ξ = p(e)·kh/v0 in N·s/m^2.5.

    Parameters
    ----------
    name : str
        Formula key.
    restitution : float
        Coefficient of restitution e, 0 < e ≤ 1.
    kh : float
        Hertz stiffness, N/m^1.5.
    v0 : float
        Approach velocity at gap closure, m/s (> 0).
    """
    return p(name, restitution) * kh / v0


def catalogue() -> list[dict[str, str]]:
    """The catalogue as rows ``{key, p(e), reference, status, aliases}``."""
    rows = []
    for key, formula in FORMULAS.items():
        aliases = sorted(a for a, k in ALIASES.items() if k == key)
        rows.append({"key": key, "p(e)": formula.expression, "reference": formula.reference,
                     "status": formula.status, "aliases": ", ".join(aliases)})
    return rows
