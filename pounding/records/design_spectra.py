"""Design response spectra of the codes: ASCE 7-22, Eurocode 8 Part 1, and a user's table.

Every spectrum here is a pseudo-spectral acceleration ``Sa(T)`` in units of
g (standard gravity, :data:`pounding.units.STANDARD_GRAVITY`), at 5 % damping
unless stated.  The formulas are small pure functions of the periods and the
code's parameters, each citing its clause; :class:`DesignSpectrum` bundles one
with its name, clause and damping for the command line and the studies.

ASCE/SEI 7-22
-------------
Two-period design response spectrum (§11.4.5.2 of ASCE 7-22, the form of
§11.4.6 of ASCE 7-16, Figure 11.4-1), with ``T0 = 0.2 S_D1/S_DS`` and
``Ts = S_D1/S_DS``::

    T < T0:        Sa = S_DS (0.4 + 0.6 T/T0)
    T0 ≤ T ≤ Ts:   Sa = S_DS
    Ts < T ≤ T_L:  Sa = S_D1 / T
    T > T_L:       Sa = S_D1 T_L / T²

The MCE_R response spectrum is 1.5 times the design spectrum (ASCE 7-22
§11.4.6 and §21.3; the design parameters are 2/3 of the MCE_R ones,
§11.4.5).  The **multi-period** spectrum of ASCE 7-22 §11.4.5.1 is tabulated
per site by the USGS Seismic Design Geodatabase; those data are not shipped
here, so a multi-period spectrum is given as a user table
(:func:`read_user_spectrum`, ``pounding spectrum user FILE``).

Eurocode 8 (EN 1998-1:2004)
---------------------------
Elastic horizontal spectrum, §3.2.2.2 expressions (3.2)-(3.5), with the soil
factor S and the corner periods T_B, T_C, T_D of Table 3.2 (type 1) or
Table 3.3 (type 2, the recommended values) and the damping correction
``η = √(10/(5 + ξ)) ≥ 0.55`` (ξ in per cent), expression (3.6)::

    0 ≤ T ≤ T_B:   Se = a_g S [1 + T/T_B (2.5 η − 1)]
    T_B ≤ T ≤ T_C: Se = a_g S 2.5 η
    T_C ≤ T ≤ T_D: Se = a_g S 2.5 η T_C/T
    T_D ≤ T:       Se = a_g S 2.5 η T_C T_D/T²

(the code defines the spectrum up to 4 s and points to its Annex A beyond;
the last branch is continued here).  Design spectrum for elastic analysis,
§3.2.2.5 expressions (3.13)-(3.16), with the behaviour factor q and the lower
bound β a_g (β = 0.2 recommended)::

    0 ≤ T ≤ T_B:   Sd = a_g S [2/3 + T/T_B (2.5/q − 2/3)]
    T_B ≤ T ≤ T_C: Sd = a_g S 2.5/q
    T_C ≤ T ≤ T_D: Sd = max(a_g S 2.5/q T_C/T, β a_g)
    T_D ≤ T:       Sd = max(a_g S 2.5/q T_C T_D/T², β a_g)

a_g is the design ground acceleration on type A ground (γ_I a_gR), in g.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from pounding.errors import PoundingError, did_you_mean

__all__ = ["DesignSpectrum", "asce7_22_two_period", "asce7_22_spectrum", "EC8_GROUND_TYPES", "ec8_ground_parameters",
           "ec8_damping_correction", "ec8_elastic", "ec8_design", "ec8_spectrum", "tabulated_spectrum",
           "read_user_spectrum", "spectrum_periods", "MCE_R_FACTOR", "EC8_BETA"]

#: MCE_R / design spectral ratio of ASCE 7-22 (S_DS = 2/3 S_MS, §11.4.5; §11.4.6).
MCE_R_FACTOR = 1.5
#: Recommended lower-bound factor β of the Eurocode 8 design spectrum (§3.2.2.5(4)P, Note).
EC8_BETA = 0.2

#: Eurocode 8 Tables 3.2 (type 1) and 3.3 (type 2): ground type → (S, T_B s, T_C s, T_D s).
EC8_GROUND_TYPES: dict[int, dict[str, tuple[float, float, float, float]]] = {
    1: {"A": (1.0, 0.15, 0.4, 2.0), "B": (1.2, 0.15, 0.5, 2.0), "C": (1.15, 0.20, 0.6, 2.0),
        "D": (1.35, 0.20, 0.8, 2.0), "E": (1.4, 0.15, 0.5, 2.0)},
    2: {"A": (1.0, 0.05, 0.25, 1.2), "B": (1.35, 0.05, 0.25, 1.2), "C": (1.5, 0.10, 0.25, 1.2),
        "D": (1.8, 0.10, 0.30, 1.2), "E": (1.6, 0.05, 0.25, 1.2)},
}


@dataclass(frozen=True)
class DesignSpectrum:
    """A design spectrum: a name, the clause it comes from, and Sa(T) in g.

    Attributes
    ----------
    name : str
        Short description, e.g. ``ASCE 7-22 design (S_DS 1 g, S_D1 0.6 g, T_L 8 s)``.
    clause : str
        The code and clause of the formula.
    function : callable
        ``function(periods) -> Sa`` for an array of periods (s, ≥ 0), Sa in g.
    damping : float
        Damping ratio the spectrum is for.
    corners : tuple of float
        Corner periods, s (always tabulated by :func:`spectrum_periods`).
    max_period : float
        Longest period the spectrum is defined for, s (inf: no bound).
    min_period : float
        Shortest period the spectrum is defined for, s (0 but for a table starting later).
    """

    name: str
    clause: str
    function: Callable[[np.ndarray], np.ndarray]
    damping: float = 0.05
    corners: tuple[float, ...] = ()
    max_period: float = math.inf
    min_period: float = 0.0

    def sa(self, periods: Any) -> np.ndarray:
        """Sa (g) at *periods* (s); a period outside the spectrum is refused in one line."""
        t = np.atleast_1d(np.asarray(periods, dtype=float))
        bad = t[~np.isfinite(t) | (t < self.min_period) | (t > self.max_period)]
        if bad.size:
            raise PoundingError(f"{self.name}: period {bad[0]:g} s is outside the spectrum "
                                f"({self.min_period:g} to {self.max_period:g} s)")
        return np.asarray(self.function(t), dtype=float)


def _positive(name: str, value: float) -> float:
    number = float(value)
    if not math.isfinite(number) or number <= 0:
        raise PoundingError(f"{name} must be a finite number > 0 (got {value!r})")
    return number


# --------------------------------------------------------------------------- #
# ASCE 7-22
# --------------------------------------------------------------------------- #


def asce7_22_two_period(periods: Any, sds: float, sd1: float, tl: float) -> np.ndarray:
    """ASCE 7-22 §11.4.5.2 two-period design response spectrum Sa(T), g.

    Parameters
    ----------
    periods : array
        Periods T, s (≥ 0).
    sds, sd1 : float
        Design spectral accelerations at short periods and at 1 s, g (§11.4.5).
    tl : float
        Long-period transition period T_L, s (Chapter 22 maps).

    Returns
    -------
    ndarray
        Sa, g: ``S_DS (0.4 + 0.6 T/T0)`` below T0 = 0.2 S_D1/S_DS, S_DS up to
        Ts = S_D1/S_DS, S_D1/T up to T_L, S_D1 T_L/T² beyond.
    """
    t = np.asarray(periods, dtype=float)
    t0, ts = 0.2 * sd1 / sds, sd1 / sds
    with np.errstate(divide="ignore"):
        return np.where(t < t0, sds * (0.4 + 0.6 * t / t0),
                        np.where(t <= ts, sds, np.where(t <= tl, sd1 / t, sd1 * tl / t ** 2)))


def asce7_22_spectrum(sds: float, sd1: float, tl: float, *, mce: bool = False) -> DesignSpectrum:
    """The ASCE 7-22 two-period design spectrum, or the MCE_R spectrum (1.5 × design, §11.4.6) with *mce*.

    Raises
    ------
    PoundingError
        A parameter that is not > 0 (one line).
    """
    sds, sd1, tl = _positive("S_DS", sds), _positive("S_D1", sd1), _positive("T_L", tl)
    factor = MCE_R_FACTOR if mce else 1.0
    kind = "MCE_R" if mce else "design"
    clause = ("ASCE 7-22 §11.4.6 (MCE_R = 1.5 x the §11.4.5.2 two-period design spectrum)" if mce
              else "ASCE 7-22 §11.4.5.2 (two-period design response spectrum)")
    return DesignSpectrum(
        name=f"ASCE 7-22 {kind} (S_DS {sds:g} g, S_D1 {sd1:g} g, T_L {tl:g} s)", clause=clause,
        function=lambda t: factor * asce7_22_two_period(t, sds, sd1, tl),
        corners=(0.2 * sd1 / sds, sd1 / sds, tl))


# --------------------------------------------------------------------------- #
# Eurocode 8
# --------------------------------------------------------------------------- #


def ec8_ground_parameters(spectrum_type: int, ground: str) -> tuple[float, float, float, float]:
    """(S, T_B, T_C, T_D) of EN 1998-1 Table 3.2 (type 1) or Table 3.3 (type 2) for ground type A-E.

    Raises
    ------
    PoundingError
        Unknown type or ground type (one line).
    """
    if spectrum_type not in EC8_GROUND_TYPES:
        raise PoundingError(f"the Eurocode 8 spectrum type must be 1 or 2 (got {spectrum_type!r})")
    table = EC8_GROUND_TYPES[spectrum_type]
    key = str(ground).strip().upper()
    if key not in table:
        raise PoundingError(f"unknown Eurocode 8 ground type {ground!r}{did_you_mean(key, list(table))}; "
                            f"choose one of {', '.join(table)} (EN 1998-1 Table 3.1; S1 and S2 need special studies)")
    return table[key]


def ec8_damping_correction(damping: float) -> float:
    """η = √(10/(5 + ξ)) ≥ 0.55 with ξ the viscous damping ratio in per cent (EN 1998-1 §3.2.2.2(3), (3.6))."""
    return max(math.sqrt(10.0 / (5.0 + 100.0 * float(damping))), 0.55)


def ec8_elastic(periods: Any, ag: float, soil: float, tb: float, tc: float, td: float,
                eta: float = 1.0) -> np.ndarray:
    """EN 1998-1 §3.2.2.2 elastic horizontal response spectrum Se(T), expressions (3.2)-(3.5), in the units of *ag*.

    Parameters
    ----------
    periods : array
        Periods, s (≥ 0).
    ag : float
        Design ground acceleration on type A ground, g.
    soil, tb, tc, td : float
        Soil factor S and corner periods T_B, T_C, T_D (s), Table 3.2 or 3.3.
    eta : float
        Damping correction factor η (1 at 5 %).
    """
    t = np.asarray(periods, dtype=float)
    plateau = ag * soil * 2.5 * eta
    with np.errstate(divide="ignore"):
        return np.where(t <= tb, ag * soil * (1.0 + t / tb * (2.5 * eta - 1.0)),
                        np.where(t <= tc, plateau, np.where(t <= td, plateau * tc / t, plateau * tc * td / t ** 2)))


def ec8_design(periods: Any, ag: float, soil: float, tb: float, tc: float, td: float, q: float,
               beta: float = EC8_BETA) -> np.ndarray:
    """EN 1998-1 §3.2.2.5 design spectrum for elastic analysis Sd(T), expressions (3.13)-(3.16), units of *ag*.

    Parameters
    ----------
    periods : array
        Periods, s (≥ 0).
    ag, soil, tb, tc, td : float
        As :func:`ec8_elastic`.
    q : float
        Behaviour factor.
    beta : float
        Lower-bound factor of the horizontal design spectrum (0.2 recommended).
    """
    t = np.asarray(periods, dtype=float)
    plateau = ag * soil * 2.5 / q
    floor = beta * ag
    with np.errstate(divide="ignore"):
        return np.where(t <= tb, ag * soil * (2.0 / 3.0 + t / tb * (2.5 / q - 2.0 / 3.0)),
                        np.where(t <= tc, plateau,
                                 np.where(t <= td, np.maximum(plateau * tc / t, floor),
                                          np.maximum(plateau * tc * td / t ** 2, floor))))


def ec8_spectrum(spectrum_type: int, ground: str, ag: float, *, q: float | None = None, damping: float = 0.05,
                 beta: float = EC8_BETA) -> DesignSpectrum:
    """The Eurocode 8 elastic spectrum (§3.2.2.2; *q* None) or design spectrum (§3.2.2.5, behaviour factor *q*).

    The design spectrum has no damping correction: §3.2.2.5 puts the
    behaviour factor in its place (*damping* is then refused unless 5 %).

    Raises
    ------
    PoundingError
        A bad parameter (one line).
    """
    soil, tb, tc, td = ec8_ground_parameters(spectrum_type, ground)
    ag = _positive("a_g", ag)
    zeta = float(damping)
    if not (math.isfinite(zeta) and 0.0 <= zeta < 1.0):
        raise PoundingError(f"the damping ratio must be in [0, 1) (got {damping!r})")
    label = f"type {spectrum_type}, ground {str(ground).strip().upper()}, a_g {ag:g} g"
    corners = (tb, tc, td)
    if q is None:
        eta = ec8_damping_correction(zeta)
        return DesignSpectrum(
            name=f"Eurocode 8 elastic ({label}, {100 * zeta:g} % damping, eta {eta:.3f})",
            clause="EN 1998-1 §3.2.2.2 (elastic horizontal spectrum, (3.2)-(3.6))",
            function=lambda t: ec8_elastic(t, ag, soil, tb, tc, td, eta), damping=zeta, corners=corners)
    q = _positive("the behaviour factor q", q)
    if q < 1.0:
        raise PoundingError(f"the behaviour factor q must be >= 1 (got {q:g}): EN 1998-1 §3.2.2.5's design spectrum "
                            "divides the elastic one by q, and q = 1 is elastic; a q below 1 would raise the forces")
    if abs(zeta - 0.05) > 1e-12:
        raise PoundingError("the Eurocode 8 design spectrum (§3.2.2.5) has no damping correction; give --damping "
                            "only for the elastic spectrum (without --q)")
    beta = float(beta)
    if not (math.isfinite(beta) and beta >= 0):
        raise PoundingError(f"beta must be >= 0 (got {beta!r})")
    return DesignSpectrum(
        name=f"Eurocode 8 design ({label}, q {q:g}, beta {beta:g})",
        clause="EN 1998-1 §3.2.2.5 (design spectrum for elastic analysis, (3.13)-(3.16))",
        function=lambda t: ec8_design(t, ag, soil, tb, tc, td, q, beta), corners=corners)


# --------------------------------------------------------------------------- #
# A user's table
# --------------------------------------------------------------------------- #


def tabulated_spectrum(periods: Any, sa: Any, *, name: str = "user spectrum", damping: float = 0.05,
                       clause: str = "a table given by the user") -> DesignSpectrum:
    """A spectrum from a table of (period s, Sa g), linear in T between the rows; outside the table refused.

    Raises
    ------
    PoundingError
        Fewer than two rows, periods not increasing, negative or non-finite values (one line).
    """
    t = np.asarray(periods, dtype=float).reshape(-1)
    a = np.asarray(sa, dtype=float).reshape(-1)
    if t.size != a.size:
        raise PoundingError(f"{name}: {t.size} periods but {a.size} spectral values")
    if t.size < 2:
        raise PoundingError(f"{name}: give at least two rows (period s, Sa g)")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a))):
        raise PoundingError(f"{name}: every period and Sa must be a finite number")
    if t[0] < 0 or np.any(np.diff(t) <= 0):
        raise PoundingError(f"{name}: periods must be >= 0 s and strictly increasing")
    if np.any(a < 0):
        raise PoundingError(f"{name}: Sa must be >= 0 g (got {a[a < 0][0]:g})")
    t.setflags(write=False)
    a.setflags(write=False)

    return DesignSpectrum(name=name, clause=clause, function=lambda x: np.interp(x, t, a), damping=damping,
                          max_period=float(t[-1]), min_period=float(t[0]))


def read_user_spectrum(path: str | os.PathLike, *, damping: float = 0.05) -> DesignSpectrum:
    """A user spectrum from a text file of two columns, period (s) and Sa (g).

    Blank lines and lines starting with ``#`` are skipped; columns are
    separated by spaces, tabs or a comma.  An ASCE 7-22 multi-period spectrum
    (§11.4.5.1, from the USGS Seismic Design Geodatabase) is given this way.

    Raises
    ------
    PoundingError
        ``FILE:LINE: ...`` for an unreadable file or a bad line (one line).
    """
    label = os.fspath(path)
    try:
        with open(label, encoding="utf-8") as stream:
            lines = stream.read().splitlines()
    except FileNotFoundError:
        raise PoundingError("file not found", file=label) from None
    except IsADirectoryError:
        raise PoundingError("is a directory, not a spectrum file", file=label) from None
    except UnicodeDecodeError as exc:
        raise PoundingError(f"is not UTF-8 text (byte {exc.start})", file=label) from None
    except OSError as exc:
        raise PoundingError(f"cannot read the file: {exc.strerror}", file=label) from None
    rows: list[tuple[float, float]] = []
    previous = -math.inf
    for number, text in enumerate(lines, start=1):
        stripped = text.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = stripped.replace(",", " ").split()
        if len(fields) != 2:
            raise PoundingError(f"expected two columns, period (s) and Sa (g) (got {len(fields)}: {stripped!r})",
                                file=label, line=number)
        try:
            period, sa = float(fields[0]), float(fields[1])
        except ValueError:
            raise PoundingError(f"not a number in {stripped!r}", file=label, line=number) from None
        if not (math.isfinite(period) and math.isfinite(sa)) or period < 0 or sa < 0:
            raise PoundingError(f"period and Sa must be finite and >= 0 (got {stripped!r})", file=label, line=number)
        if period <= previous:
            raise PoundingError(f"periods must increase (got {period:g} s after {previous:g} s)", file=label,
                                line=number)
        previous = period
        rows.append((period, sa))
    if len(rows) < 2:
        raise PoundingError(f"needs at least two rows of period (s) and Sa (g) (got {len(rows)})", file=label)
    table = np.array(rows)
    return tabulated_spectrum(table[:, 0], table[:, 1], name=f"user spectrum {label}", damping=damping,
                              clause=f"the table in {label}")


def spectrum_periods(spectrum: DesignSpectrum, longest: float = 4.0, step: float = 0.1) -> np.ndarray:
    """Periods for a printed table: 0 to *longest* s every *step* (within the spectrum), with its corners added."""
    low, top = spectrum.min_period, min(longest, spectrum.max_period)
    grid = np.round(np.arange(0.0, top + 0.5 * step, step), 10)
    corners = [c for c in spectrum.corners if low <= c <= top]
    return np.unique(np.concatenate([grid[(grid >= low) & (grid <= top)], corners, [low, top]]))
