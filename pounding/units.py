"""Acceleration units and number text: the one table and the one pattern of the package.

Every place that reads an acceleration unit (``ground_motion.units``, a
target such as ``scale: {pga: 3.9 m/s/s}``, an AT2 header, the record
catalogue) goes through :func:`canonical_unit`, and every place that reads a
number written as text (YAML values, scale targets, record files) builds on
:data:`NUMBER`.

>>> canonical_unit("m/s/s"), canonical_unit("Gal"), canonical_unit("CM/SEC/SEC")
('m/s2', 'cm/s2', 'cm/s2')
>>> number_from_text(" 2.5e5 "), number_from_text("1:30")
(250000.0, None)
"""

from __future__ import annotations

import re

__all__ = ["STANDARD_GRAVITY", "UNITS", "UNIT_ALIASES", "UNIT_CHOICES", "canonical_unit", "NUMBER",
           "FORTRAN_NUMBER", "NUMBER_TEXT", "number_from_text"]

#: Standard gravity, m/s² (the "g" of PEER and FEMA P695 records).
STANDARD_GRAVITY = 9.80665

#: Factor from each canonical unit to m/s².
UNITS: dict[str, float] = {"g": STANDARD_GRAVITY, "m/s2": 1.0, "cm/s2": 0.01}


def _spellings(canonical: str, *lengths: str) -> dict[str, str]:
    """Every ``<length>/<time>²`` spelling of *canonical* (``/s2``, ``/s^2``, ``/s**2``, ``/s/s``, ``sec``)."""
    out = {}
    for length in lengths:
        for second in ("s", "sec"):
            for square in ("2", "^2", "**2", f"/{second}"):
                out[f"{length}/{second}{square}"] = canonical
    return out


#: Accepted spellings (lower case, no spaces) → canonical unit of :data:`UNITS`.
UNIT_ALIASES: dict[str, str] = {"g": "g", **_spellings("m/s2", "m"), **_spellings("cm/s2", "cm"), "gal": "cm/s2"}

#: The spellings named in messages.
UNIT_CHOICES = ("g", "m/s2", "cm/s2", "gal")


def canonical_unit(name: object) -> str | None:
    """Canonical unit (``g``, ``m/s2``, ``cm/s2``) of a spelling, or None if it is not one.

    Case and spaces are ignored: ``Gal``, ``m/s^2``, ``M/SEC/SEC`` and ``cm / s2`` are all accepted.
    """
    if not isinstance(name, str):
        return None
    return UNIT_ALIASES.get(name.strip().lower().replace(" ", ""))


#: A decimal number as written in text (no Fortran ``D`` exponent).
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
#: A number in record files: also Fortran ``D`` exponents (``1.5D-03``).
FORTRAN_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?"
#: A whole text that is one number (surrounding spaces allowed).
NUMBER_TEXT = re.compile(rf"^\s*{NUMBER}\s*$")


def number_from_text(text: object) -> float | None:
    """The float written in *text* (``'2.5e5'`` → 250000.0), or None if *text* is not one number."""
    if isinstance(text, str) and NUMBER_TEXT.match(text):
        return float(text)
    return None
