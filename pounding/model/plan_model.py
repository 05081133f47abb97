"""Plan models as objects: plan buildings with their matrices, contacts with their points, the ground-motion pair.

A plan model file (any building with ``plan:``) is read and checked by
:mod:`pounding.model.plan_schema`; this module turns it into a
:class:`PlanModel` (the Python API: :func:`load_plan_model`,
:func:`plan_model_from_text`).  The solver does not integrate plan models yet:
:func:`pounding.model.model.load_model` refuses them in one line after checking them.

DOF numbering of a model: building after building (in ``buildings`` order),
floor after floor from the ground up, (u_x, u_y, θ) per floor.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from pounding.model import plan, plan_contacts
from pounding.model.document import parse_document
from pounding.model.ground_pair import ground_components
from pounding.model.model import WALL, Damping, SolverSettings, is_plan_file, read_yaml_text
from pounding.model.plan_schema import PlanGroundMotionEntry, PlanModelEntry, validate_plan
from pounding.model.schema import ModalEntry

__all__ = ["PlanBuilding", "PlanContact", "PlanGroundMotion", "PlanModel", "plan_model_from_text", "load_plan_model",
           "is_plan_file"]


@dataclass(frozen=True, eq=False)
class PlanBuilding:
    """A building of rigid floors with three DOF each (docs/plan-models.md).

    Attributes
    ----------
    name : str
    outline : ((x0, y0), (x1, y1))
        m, in the global plan frame.
    storeys : tuple of PlanStorey
        From the ground up.
    damping : Damping
    p_delta : bool
    collapse_drift_ratio : float or None
        Its own ``collapse: {drift_ratio}``: the run ends when one of its planes' |drift ratio| exceeds it
        (None: ``solver.stop_drift_ratio``, :meth:`PlanModel.collapse_drift_ratios`).
    """

    name: str
    outline: plan.Outline
    storeys: tuple[plan.PlanStorey, ...]
    damping: Damping
    p_delta: bool = False
    collapse_drift_ratio: float | None = None

    @property
    def n_floors(self) -> int:
        """Number of floors (= storeys)."""
        return len(self.storeys)

    @property
    def n_dof(self) -> int:
        """Degrees of freedom: 3 per floor."""
        return plan.DOF_PER_FLOOR * self.n_floors

    @property
    def elevation(self) -> np.ndarray:
        """(n,) floor elevations above ground, m."""
        return np.cumsum([s.height for s in self.storeys])

    @property
    def centres(self) -> list[tuple[float, float]]:
        """Every floor's centre of mass, m, floor 1 first."""
        return [s.centre for s in self.storeys]

    def mass_matrix(self) -> np.ndarray:
        """(3n, 3n) diagonal mass matrix diag(m, m, m r²)."""
        return plan.plan_mass_matrix(list(self.storeys))

    def stiffness_matrix(self, *, initial: bool = True) -> np.ndarray:
        """(3n, 3n) stiffness matrix by virtual work (initial tangents by default)."""
        return plan.plan_stiffness_matrix(list(self.storeys), initial=initial)

    def geometric_stiffness(self) -> np.ndarray:
        """(3n, 3n) P-Delta geometric stiffness K_G (zeros without ``p_delta``)."""
        if not self.p_delta:
            return np.zeros((self.n_dof, self.n_dof))
        return plan.plan_geometric_stiffness(list(self.storeys))

    def plane_weights(self) -> list[tuple[int, int, np.ndarray]]:
        """``(storey, plane index, a)`` for every plane: its drift is ``a · q`` (m)."""
        return [(i + 1, j, plan.plane_weights(list(self.storeys), i + 1, p))
                for i, s in enumerate(self.storeys) for j, p in enumerate(s.planes)]

    def drift_ratio_weights(self) -> list[tuple[int, int, np.ndarray]]:
        """``(storey, plane index, a / h)``: a plane's drift ratio, for ``stop_drift_ratio`` (any plane)."""
        return plan.plane_drift_ratio_weights(list(self.storeys))

    @cached_property
    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Undamped 3-D modes of the initial stiffness: ``(omega ascending, mass-normalised phi)``."""
        return plan.plan_modes(self.stiffness_matrix(), self.mass_matrix())

    @property
    def periods(self) -> np.ndarray:
        """(3n,) natural periods, s, longest first."""
        return 2.0 * math.pi / self.modes[0]

    @property
    def rayleigh_coefficients(self) -> tuple[float, float] | None:
        """Rayleigh ``(a0, a1)`` at the building's own targeted 3-D modes; None for modal damping."""
        if self.damping.kind != "rayleigh":
            return None
        omega = self.modes[0]
        i, j = self.damping.modes
        return plan.rayleigh_coefficients(float(omega[i - 1]), float(omega[j - 1]), self.damping.ratio)

    def damping_matrix(self) -> np.ndarray:
        """(3n, 3n) damping matrix: Rayleigh on the initial stiffness, or modal ``MΦ diag(2ζω) ΦᵀM``."""
        if self.damping.kind == "rayleigh":
            a0, a1 = self.rayleigh_coefficients
            return a0 * self.mass_matrix() + a1 * self.stiffness_matrix()
        omega, phi = self.modes
        mphi = self.mass_matrix() @ phi
        return (mphi * (2.0 * self.damping.ratios(self.n_dof) * omega)) @ mphi.T

    @property
    def warnings(self) -> tuple[str, ...]:
        """Warnings about the building (Rayleigh targets at coincident modes)."""
        if self.damping.kind != "rayleigh":
            return ()
        found = plan.coincident_modes(self.modes[0], self.damping.modes)
        return () if found is None else (f"building {self.name}: {found}",)


@dataclass(frozen=True)
class PlanContact:
    """One face of a plan contact entry between floor ``level_first`` of ``first`` and ``level_second`` of ``second``.

    Attributes
    ----------
    contact : int
        Index of the YAML ``contacts`` entry.
    first, second : int
        Building indices (``second`` is :data:`WALL` for a wall).
    level_first, level_second : int
        1-based floors (0 for the wall).
    face : Face
        Normal, gap, the overlap's ends.
    points : tuple of ContactPoint
        The face's two contact points with their penetration and slip weights.
    law : ContactLaw
        Applied at each point.
    friction : float or None
        Coulomb μ on the face.
    """

    contact: int
    first: int
    second: int
    level_first: int
    level_second: int
    face: plan_contacts.Face
    points: tuple[plan_contacts.ContactPoint, ...]
    law: Any
    friction: float | None = None

    @property
    def gap(self) -> float:
        """Separation at rest, m."""
        return self.face.gap


@dataclass(frozen=True)
class PlanGroundMotion:
    """A plan model's ground motion: two components (a/x, b/y; either may be absent), the angle, shared keys."""

    components: tuple[Any, Any]
    angle: float = 0.0
    duration: float | None = None
    dt: float | None = None
    units: str | None = None
    base_dir: str | None = None

    def records(self) -> tuple[Any, Any]:
        """The two components loaded as :class:`pounding.records.record.Record` (None where absent)."""
        from pounding.records.load import load_record

        return tuple(None if c is None else load_record(c.record, base_dir=self.base_dir, dt=self.dt,
                                                        units=self.units, scale=c.scale, duration=self.duration)
                     for c in self.components)   # type: ignore[return-value]

    def on_grid(self, time: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The global ground accelerations ``(a_gx, a_gy)`` (m/s²) at *time* (s)."""
        zero = (np.zeros(2), 1.0)
        first, second = ((zero if r is None else (r.acceleration, r.time_step)) for r in self.records())
        return ground_components(time, first, second, self.angle)


@dataclass(frozen=True, eq=False)
class PlanModel:
    """Plan buildings, contacts from the plan, a two-component ground motion and solver settings."""

    name: str
    buildings: tuple[PlanBuilding, ...]
    contacts: tuple[PlanContact, ...]
    ground_motion: PlanGroundMotion
    solver: SolverSettings
    source: str = ""
    path: str | None = None

    @property
    def dof_offsets(self) -> list[int]:
        """Index of each building's first DOF in the model's DOF vector."""
        return [int(x) for x in np.cumsum([0] + [b.n_dof for b in self.buildings])[:-1]]

    @property
    def n_dof(self) -> int:
        """Degrees of freedom of the model."""
        return sum(b.n_dof for b in self.buildings)

    def floor_slice(self, building: int, level: int) -> slice:
        """The DOF of floor *level* (1-based) of *building* in the model's vector."""
        start = self.dof_offsets[building] + plan.DOF_PER_FLOOR * (level - 1)
        return slice(start, start + plan.DOF_PER_FLOOR)

    def scatter(self, contact: PlanContact, rows: np.ndarray) -> np.ndarray:
        """(N,) model-wide weights from a contact's (2, 3) rows (first side's floor, second's)."""
        w = np.zeros(self.n_dof)
        w[self.floor_slice(contact.first, contact.level_first)] += rows[0]
        if contact.second != WALL:
            w[self.floor_slice(contact.second, contact.level_second)] += rows[1]
        return w

    def penetration_vectors(self) -> list[tuple[PlanContact, plan_contacts.ContactPoint, np.ndarray]]:
        """Every contact point with its model-wide penetration weights: ``δ = w · q − gap``."""
        return [(c, p, self.scatter(c, p.weights)) for c in self.contacts for p in c.points]

    def collapse_drift_ratios(self) -> tuple[float | None, ...]:
        """Each building's collapse drift ratio: its own ``collapse: {drift_ratio}``, else
        ``solver.stop_drift_ratio`` (None: never)."""
        return tuple(b.collapse_drift_ratio if b.collapse_drift_ratio is not None else self.solver.stop_drift_ratio
                     for b in self.buildings)

    @property
    def warnings(self) -> tuple[str, ...]:
        """The buildings' warnings."""
        return tuple(w for b in self.buildings for w in b.warnings)


def _damping(entry: Any) -> Damping:
    if isinstance(entry, ModalEntry):
        return Damping("modal", modal_ratios=tuple(entry.modal))
    return Damping("rayleigh", ratio=entry.ratio, modes=tuple(entry.modes))


def _ground_motion(entry: PlanGroundMotionEntry, base_dir: str | None) -> PlanGroundMotion:
    return PlanGroundMotion(entry.components(), entry.angle, entry.duration, entry.dt, entry.units, base_dir)


def build_plan_model(entry: PlanModelEntry, *, name: str, text: str = "", path: str | None = None,
                     base_dir: str | None = None) -> PlanModel:
    """The objects of a checked plan model."""
    buildings = tuple(PlanBuilding(b.name, b.plan.outline, tuple(b.plan_storeys()), _damping(b.damping), b.p_delta,
                                   None if b.collapse is None else b.collapse.drift_ratio)
                      for b in entry.buildings)
    contacts = []
    for index, c in enumerate(entry.contacts):
        first, second = c.sides
        for level_first, level_second in c.pairs:
            centre_first = buildings[first].centres[level_first - 1]
            centre_second = None if second == WALL else buildings[second].centres[level_second - 1]
            points = plan_contacts.face_points(c.plan_face, centre_first, centre_second)
            contacts.append(PlanContact(index, first, second, level_first, level_second, c.plan_face, points,
                                        c.parameters, c.friction))
    return PlanModel(entry.name or name, buildings, tuple(contacts), _ground_motion(entry.ground_motion, base_dir),
                     SolverSettings(**entry.solver.model_dump()), text, path)


def plan_model_from_text(text: str, *, name: str = "model", path: str | None = None,
                         base_dir: str | None = None) -> PlanModel:
    """Read and check a plan model's YAML text (one located line per problem) and build it."""
    doc = parse_document(text, path if path is not None else f"<{name}>")
    return build_plan_model(validate_plan(doc, base_dir), name=name, text=text, path=path, base_dir=base_dir)


def load_plan_model(path: str | os.PathLike) -> PlanModel:
    """Read and check a plan model file; relative record paths are relative to its folder."""
    label = os.fspath(path)
    return plan_model_from_text(read_yaml_text(label, kind="model"), name=Path(label).stem, path=label,
                                base_dir=os.path.dirname(os.path.abspath(label)))
