"""A building: floors with their degrees of freedom, storeys whose planes resist their drift, damping.

One class describes every building (docs/architecture.md).  Its floors are rigid bodies
with one degree of freedom (u_x: a planar shear building) or three (u_x, u_y, θ: a rigid
diaphragm in plan, when the building has an ``outline``); each storey resists through its
planes, springs on the drift of a line (:mod:`pounding.model.floors`).  A planar building
is a building whose floors have one degree of freedom and whose storeys have one plane
along x: its mass matrix is ``diag(m)`` and its stiffness the tridiagonal shear-building K,
built by the same virtual work as a plan building's.

Shear building (docs/physics.md §1): floor i (1 = first above ground) carries mass
m_i; storey i, between floor i−1 and floor i (floor 0 = ground), has lateral
stiffness k_i and height h_i.  M is diagonal, K tridiagonal::

    K[i, i] = k_i + k_{i+1},   K[i, i+1] = K[i+1, i] = −k_{i+1}   (k_{n+1} = 0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from pounding.errors import ModelError
from pounding.memory import check_memory
from pounding.recently_used import RecentlyUsed
from pounding.model import floors, schema
from pounding.model.foundation import BASE_DOFS, Foundation, effective_damping, founded_mass, founded_matrix, \
    founded_weights
from pounding.model.floors import PLAN_DOFS, PLANAR_DOFS, Outline, Plane, Storey

__all__ = ["Damping", "Building", "planar_storeys", "modes_key", "forget_modes", "MODES_KEPT"]

#: How many buildings' modes a process keeps (:func:`modes_key`): a study's worker meets the same few
#: buildings in every scenario; a study of many different buildings recomputes what it has dropped.
MODES_KEPT = 64
#: Modes by :func:`modes_key` (read-only arrays, shared by equal buildings).
_MODES: RecentlyUsed[tuple[np.ndarray, np.ndarray]] = RecentlyUsed(MODES_KEPT)


def forget_modes() -> None:
    """Drop every kept mode (:func:`modes_key`): the next building computes its own again."""
    _MODES.clear()


def modes_key(storeys: tuple[Storey, ...], dofs: int) -> tuple:
    """What a building's undamped modes are computed from, exactly: the key of the modes a process keeps.

    :meth:`Building.modes` solves ``K φ = ω² M φ`` with M from each floor's mass and radius of gyration
    and K from each storey plane's direction, line and initial stiffness and the floors' centres
    (:func:`pounding.model.floors.mass_matrix`, :func:`~pounding.model.floors.stiffness_matrix`), per floor
    *dofs* degrees of freedom.  The key holds those values as the hexadecimal text of their floats (so
    ``-0.0`` and ``0.0``, which compare equal, are two keys): two buildings share modes only when every
    number their matrices are made of is the same to the bit; a scenario of a sweep that changes a gap
    or a contact law meets the modes of the buildings it did not change.
    """
    def bits(value: float) -> str:
        return float(value).hex()

    return (dofs, tuple((bits(s.mass), bits(s.radius_of_gyration), tuple(bits(c) for c in s.centre),
                         tuple((p.direction, bits(p.at), bits(p.initial_stiffness)) for p in s.planes))
                        for s in storeys))


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
            entry = schema.checked(schema.RayleighEntry, {"ratio": self.ratio,
                                                          "modes": (1, 2) if modes is None else modes}, ("damping",))
            object.__setattr__(self, "ratio", entry.ratio)
            object.__setattr__(self, "modes", tuple(entry.modes))
        elif self.kind == "modal":
            ratios = self.modal_ratios
            entry = schema.checked(schema.ModalEntry,
                                   {"modal": list(ratios) if isinstance(ratios, (tuple, list)) else ratios},
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


def planar_storeys(mass: Any, stiffness: Any, height: Any, hysteresis: Any = ()) -> tuple[Storey, ...]:
    """A shear building's storeys: floors of one DOF at the plan origin, one plane along x per storey."""
    mass, stiffness, height = (np.asarray(v, dtype=float).reshape(-1) for v in (mass, stiffness, height))
    laws = tuple(hysteresis) or (None,) * mass.size
    return tuple(Storey(float(m), float(h), (0.0, 0.0), 0.0, (Plane("x", 0.0, float(k), law),))
                 for m, k, h, law in zip(mass, stiffness, height, laws))


@dataclass(frozen=True, eq=False)
class Building:
    """A building of floors (rigid bodies) on storeys whose planes resist their drift.

    Attributes
    ----------
    name : str
    storeys : tuple of Storey
        From the ground up: each the floor on top (mass, centre of mass, radius of gyration)
        and the planes below it.
    damping : Damping
    p_delta : bool
        Leaning-column P-Delta: storey i carries ``P_i = g·Σ_(j≥i) m_j`` (docs/physics.md §7).
    design : DesignEntry, optional
        The building's design factors per code (``design:`` in the YAML), for ``pounding gap --code``.
    collapse_drift_ratio : float or None
        Its own ``collapse: {drift_ratio}``: it collapses, and the run ends, when one of its
        storeys' (planes') |drift ratio| first exceeds this.  None: ``solver.stop_drift_ratio``.
    outline : ((x0, y0), (x1, y1)) or None
        m, in the global plan frame: its floors are rigid diaphragms with u_x, u_y and θ.  None:
        floors with one degree of freedom u_x (a planar shear building).
    foundation : Foundation or None
        A planar building's sway–rocking foundation (docs/foundations.md): its DOF are then the
        floors' displacements relative to the free field, then the base mat's sway and rocking
        (the ``model_*`` matrices); the fixed-base matrices (``mass_matrix``, ``stiffness_matrix``,
        ``modes``, ``damping_matrix``) stay those of the building on a fixed base.  None: a fixed base.

    Build a planar building with :meth:`shear`.  Equality is identity.
    """

    name: str
    storeys: tuple[Storey, ...]
    damping: Damping
    p_delta: bool = False
    design: Any = None
    collapse_drift_ratio: float | None = None
    outline: Outline | None = None
    foundation: Foundation | None = None

    @classmethod
    def shear(cls, name: str, mass: Any, stiffness: Any, height: Any, damping: Damping, hysteresis: Any = (),
              p_delta: bool = False, design: Any = None, collapse_drift_ratio: float | None = None) -> Building:
        """A planar shear building from per-storey arrays, checked by the model file's own rules.

        Parameters
        ----------
        mass, stiffness, height : (n,) array_like
            Floor masses (kg; floor 1 first), storey stiffnesses (N/m) and heights (m).
        hysteresis : sequence of StoreyHysteresis or None, optional
            Per storey; empty: every storey elastic.

        Raises
        ------
        ModelError
            One line naming the building and the problem.
        """
        arrays = [np.array(v, dtype=float).reshape(-1) for v in (mass, stiffness, height)]
        if not arrays[0].size == arrays[1].size == arrays[2].size:
            raise ModelError(f"building {name}: mass, stiffness and height must have the same length "
                             f"(got {arrays[0].size}, {arrays[1].size}, {arrays[2].size})")
        laws = tuple(hysteresis) or (None,) * arrays[0].size
        if len(laws) != arrays[0].size:
            raise ModelError(f"building {name}: hysteresis must have one entry (or None) per storey "
                             f"(got {len(laws)} for {arrays[0].size} storeys)")
        document: dict[str, Any] = {
            "name": name, "p_delta": p_delta,
            "storeys": [schema.storey_document(m, k, h, law) for m, k, h, law in zip(*arrays, laws)],
            "damping": damping.to_document() if isinstance(damping, Damping) else damping}
        if design is not None:
            document["design"] = schema.design_document(design)
        if collapse_drift_ratio is not None:
            document["collapse"] = {"drift_ratio": collapse_drift_ratio}
        entry = schema.checked(schema.BuildingEntry, document, prefix=f"building {name}:")
        return cls(name, planar_storeys(*arrays, entry.column("hysteresis")), damping, bool(p_delta), entry.design,
                   None if entry.collapse is None else entry.collapse.drift_ratio)

    # ----------------------------------------------------------- display
    def describe(self) -> str:
        """One line: ``A: 8 storeys, 25.6 m, periods 0.910 0.307 0.188 ... s, yielding, P-Delta``."""
        periods = self.periods
        shown = " ".join(f"{t:.3f}" for t in periods[:3]) + (" ..." if periods.size > 3 else "")
        return (f"{self.name}: {self.n_floors} storey{'s' if self.n_floors != 1 else ''}, "
                f"{float(self.height.sum()):.4g} m, periods {shown} s" + (", in plan" if self.in_plan else "")
                + (", yielding" if self.is_inelastic else "") + (", P-Delta" if self.p_delta else "")
                + ("" if self.foundation is None else
                   f", on a foundation: flexible-base period {self.flexible_periods[0]:.3f} s, effective damping "
                   f"{100 * self.effective_damping:.2f}%"))

    def __repr__(self) -> str:
        return f"<Building {self.describe()}>"

    # ----------------------------------------------------------- floors and degrees of freedom
    @property
    def in_plan(self) -> bool:
        """True if the floors are rigid diaphragms in plan (u_x, u_y, θ); False: one DOF u_x each."""
        return self.outline is not None

    @property
    def dofs_per_floor(self) -> int:
        """Degrees of freedom of each floor: 3 in plan, 1 for a planar building."""
        return PLAN_DOFS if self.in_plan else PLANAR_DOFS

    @property
    def dof_names(self) -> tuple[str, ...]:
        """Names of a floor's degrees of freedom: ``("x",)`` or ``("x", "y", "rz")``."""
        return floors.DOF_NAMES[self.dofs_per_floor]

    @property
    def n_floors(self) -> int:
        """Number of floors (= storeys)."""
        return len(self.storeys)

    @property
    def n_dof(self) -> int:
        """Degrees of freedom of the building."""
        return self.dofs_per_floor * self.n_floors

    @cached_property
    def mass(self) -> np.ndarray:
        """(n,) floor masses, kg (read-only)."""
        return _frozen([s.mass for s in self.storeys])

    @cached_property
    def height(self) -> np.ndarray:
        """(n,) storey heights, m (read-only)."""
        return _frozen([s.height for s in self.storeys])

    @cached_property
    def stiffness(self) -> np.ndarray:
        """(n,) each storey's elastic stiffness summed over its planes, N/m (a planar storey's k; read-only)."""
        return _frozen([sum(float(p.stiffness) for p in s.planes) for s in self.storeys])

    @property
    def elevation(self) -> np.ndarray:
        """(n,) floor elevations above ground, m (cumulative storey heights)."""
        return np.cumsum(self.height)

    @property
    def centres(self) -> list[tuple[float, float]]:
        """Every floor's centre of mass, m, floor 1 first."""
        return [s.centre for s in self.storeys]

    # ----------------------------------------------------------- planes, yielding and P-Delta
    def planes(self) -> list[tuple[int, int, Plane]]:
        """``(storey, plane index, plane)`` of every plane, storey by storey from the ground up."""
        return [(i + 1, j, p) for i, s in enumerate(self.storeys) for j, p in enumerate(s.planes)]

    def plane_weights(self) -> list[tuple[int, int, np.ndarray]]:
        """``(storey, plane index, a)`` for every plane: its drift is ``a · q`` (m) over the building's DOF."""
        return [(i, j, floors.plane_weights(list(self.storeys), i, p, self.dofs_per_floor))
                for i, j, p in self.planes()]

    def drift_ratio_weights(self) -> list[tuple[int, int, np.ndarray]]:
        """``(storey, plane index, a / h)``: a plane's drift ratio, for ``stop_drift_ratio`` (any plane)."""
        return floors.plane_drift_ratio_weights(list(self.storeys), self.dofs_per_floor)

    @property
    def hysteresis(self) -> tuple:
        """Per storey its yielding model or None, for buildings whose storeys have one plane each (planar)."""
        if any(len(s.planes) != 1 for s in self.storeys):
            raise ModelError(f"building {self.name}: its storeys have several planes; read each plane's hysteresis "
                             "(Building.planes())")
        return tuple(s.planes[0].hysteresis for s in self.storeys)

    @property
    def is_inelastic(self) -> bool:
        """True if any plane has a hysteresis model."""
        return any(p.hysteresis is not None for _, _, p in self.planes())

    @property
    def yield_force(self) -> np.ndarray:
        """(n,) storey yield forces F_y, N (NaN for an elastic storey; planar buildings)."""
        return np.array([np.nan if law is None else law.yield_force_for(k, h)
                         for law, k, h in zip(self.hysteresis, self.stiffness, self.height)])

    @property
    def yield_drift(self) -> np.ndarray:
        """(n,) storey yield drifts u_y = F_y / k, m (NaN for an elastic storey; planar buildings)."""
        return self.yield_force / self.stiffness

    @property
    def gravity_load(self) -> np.ndarray:
        """(n,) axial load P_i = g·Σ_(j≥i) m_j carried by each storey, N."""
        return floors.storey_gravity_load(self.mass)

    @property
    def p_delta_stiffness(self) -> np.ndarray:
        """(n,) geometric storey stiffness −P_i/h_i, N/m (zeros without ``p_delta``)."""
        if not self.p_delta:
            return np.zeros(self.n_floors)
        return -self.gravity_load / self.height

    # ----------------------------------------------------------- matrices
    def mass_matrix(self) -> np.ndarray:
        """Diagonal mass matrix: ``diag(m)`` (kg), or ``diag(m, m, m r²)`` per floor in plan."""
        return floors.mass_matrix(list(self.storeys), self.dofs_per_floor)

    @cached_property
    def dof_mass(self) -> np.ndarray:
        """(n_dof,) the mass matrix's diagonal: kg per translation, kg·m² per rotation (read-only)."""
        return _frozen(np.diag(self.mass_matrix()))

    def stiffness_matrix(self, *, initial: bool = True) -> np.ndarray:
        """Stiffness matrix by virtual work over the planes (initial tangents by default), N/m, N, N·m."""
        return floors.stiffness_matrix(list(self.storeys), self.dofs_per_floor, initial=initial)

    def geometric_stiffness(self) -> np.ndarray:
        """P-Delta geometric stiffness K_G (zeros without ``p_delta``)."""
        if not self.p_delta:
            return np.zeros((self.n_dof, self.n_dof))
        return floors.geometric_stiffness(list(self.storeys), self.dofs_per_floor)

    @cached_property
    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Undamped modes of the initial stiffness: ``(omega ascending rad/s, mass-normalised phi in columns)``.

        Each mode is signed so that the roof floor's largest component is positive (a planar building's roof
        along +x); computed once, after
        checking the dense matrices fit in memory (:meth:`check_modes_memory`).
        """
        self.check_modes_memory()
        return _MODES.get(modes_key(self.storeys, self.dofs_per_floor), self._computed_modes)

    def _computed_modes(self) -> tuple[np.ndarray, np.ndarray]:
        omega, phi = floors.natural_modes(self.stiffness_matrix(), self.mass_matrix(), self.dofs_per_floor)
        omega.setflags(write=False)
        phi.setflags(write=False)
        return omega, phi

    def check_modes_memory(self) -> None:
        """Refuse in one line, before allocating, modes whose dense matrices would not fit in memory.

        The eigensolver holds about 5 matrices of N² floats at its peak (measured 4.0 with
        tracemalloc at N = 1500); modal damping adds its dense damping matrix and the run's copy (8).
        """
        n = self.n_dof
        copies = 8 if self.damping.kind == "modal" else 5
        check_memory(8.0 * copies * n * n, what=f"building {self.name}: the modes of its {self.n_floors} storeys "
                                                f"(dense {n} x {n} matrices)",
                     fix="model the building with fewer storeys (lump several storeys into one) or run it on a "
                         "machine with more memory")

    @property
    def periods(self) -> np.ndarray:
        """Natural periods, s, longest first (one per degree of freedom)."""
        return 2.0 * math.pi / self.modes[0]

    @property
    def rayleigh_coefficients(self) -> tuple[float, float] | None:
        """Rayleigh ``(a0, a1)`` (1/s, s) for ``C = a0·M + a1·K`` at the targeted modes; None for modal damping.

        ``a0 = 2ζ·ωi·ωj/(ωi+ωj)``, ``a1 = 2ζ/(ωi+ωj)`` give ratio ζ exactly at modes i and j
        (docs/physics.md §1); in plan, the building's own 3-D modes sorted by frequency.
        """
        if self.damping.kind != "rayleigh":
            return None
        omega = self.modes[0]
        i, j = self.damping.modes
        return floors.rayleigh_coefficients(float(omega[i - 1]), float(omega[j - 1]), self.damping.ratio)

    @property
    def modal_damping_ratios(self) -> np.ndarray:
        """Damping ratio of every mode (Rayleigh: ``(a0/ω + a1·ω)/2``)."""
        omega = self.modes[0]
        if self.damping.kind == "modal":
            return self.damping.ratios(self.n_dof)
        a0, a1 = self.rayleigh_coefficients
        return 0.5 * (a0 / omega + a1 * omega)

    def damping_matrix(self) -> np.ndarray:
        """Damping matrix C: Rayleigh ``a0·M + a1·K`` (initial stiffness), or modal ``M·Φ·diag(2ζ_k·ω_k)·Φᵀ·M``."""
        if self.damping.kind == "rayleigh":
            a0, a1 = self.rayleigh_coefficients
            return a0 * self.mass_matrix() + a1 * self.stiffness_matrix()
        omega, phi = self.modes
        mphi = self.dof_mass[:, None] * phi
        return (mphi * (2.0 * self.damping.ratios(self.n_dof) * omega)) @ mphi.T

    # ----------------------------------------------------------- on a foundation: the model's DOF
    @property
    def n_base_dof(self) -> int:
        """Degrees of freedom of the base mat: 2 (sway, rocking) on a foundation, else 0."""
        return 0 if self.foundation is None else BASE_DOFS

    @property
    def n_model_dof(self) -> int:
        """Degrees of freedom of the building in the model's vector: its floors', then its base mat's."""
        return self.n_dof + self.n_base_dof

    @cached_property
    def model_mass(self) -> np.ndarray:
        """(n_model_dof,) masses of the model's DOF: :attr:`dof_mass`, then m_b (kg) and I_b (kg·m²)."""
        return self.dof_mass if self.foundation is None else _frozen(founded_mass(self.dof_mass, self.foundation))

    def model_stiffness_matrix(self, *, initial: bool = True) -> np.ndarray:
        """Stiffness on the model's DOF: ``Tᵀ K T + diag(0 … 0, K_x, K_θ)`` on a foundation (module
        :mod:`pounding.model.foundation`), else :meth:`stiffness_matrix`; N/m, N, N·m/rad."""
        k = self.stiffness_matrix(initial=initial)
        return k if self.foundation is None else founded_matrix(k, self.elevation, self.foundation.stiffness)

    def model_damping_matrix(self) -> np.ndarray:
        """Damping on the model's DOF: the fixed-base building's C on its deformations, ``Tᵀ C T``, plus the
        foundation's dashpots on sway and rocking; N·s/m, N·m·s/rad."""
        c = self.damping_matrix()
        return c if self.foundation is None else founded_matrix(c, self.elevation, self.foundation.damping)

    def model_plane_weights(self) -> list[tuple[int, int, np.ndarray]]:
        """``(storey, plane index, a)`` over the model's DOF: each plane's deformation is ``a · q``, m."""
        found = self.plane_weights()
        if self.foundation is None:
            return found
        return [(i, j, founded_weights(a, self.elevation)) for i, j, a in found]

    @cached_property
    def flexible_modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Undamped modes on the model's DOF (on a foundation: the flexible-base building), as :attr:`modes`."""
        if self.foundation is None:
            return self.modes
        self.check_modes_memory()
        return floors.natural_modes(self.model_stiffness_matrix(), np.diag(self.model_mass), PLANAR_DOFS)

    @property
    def flexible_periods(self) -> np.ndarray:
        """Undamped natural periods on the model's DOF, s, longest first (fixed base: :attr:`periods`)."""
        return 2.0 * math.pi / self.flexible_modes[0]

    @property
    def effective_damping(self) -> float:
        """Damping ratio of the fundamental mode of the damped system on the model's DOF (complex modes;
        on a foundation: the building's damping and the foundation's dashpots together)."""
        return effective_damping(self.model_mass, self.model_damping_matrix(), self.model_stiffness_matrix())[1]

    @property
    def warnings(self) -> tuple[str, ...]:
        """Warnings about the building (Rayleigh targets at coincident modes, in plan)."""
        if self.damping.kind != "rayleigh" or not self.in_plan:
            return ()
        found = floors.coincident_modes(self.modes[0], self.damping.modes)
        return () if found is None else (f"building {self.name}: {found}",)


def _frozen(values: Any) -> np.ndarray:
    array = np.array(values, dtype=float)
    array.setflags(write=False)
    return array
