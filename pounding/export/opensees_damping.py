"""Damping of a model's OpenSees domain: Rayleigh regions, a dashpot network, OpenSees' modalDamping.

Our solver damps every building with ``C = a0·M + a1·K_init`` (Rayleigh, K on each spring's
*initial* tangent, a Bouc–Wen spring's (α + (1 − α)A)·k) or with its modal matrix
``MΦ diag(2ζω) ΦᵀM`` over the modes of that K_init.  OpenSees writes them as follows:

* **Rayleigh** (:func:`rayleigh_row`): a ``region`` per building with ``-rayleigh a0 0 a1 0``
  (``betaKinit``: a1 on each material's initial tangent, so a yielding spring keeps its elastic
  damping, as ours): the nodes that carry the building's mass take a0·M, its springs a1·K_init.
  Floors of one DOF: one region of the storeys and their nodes; floors in plan: the masters
  (``-nodeOnly``) and the planes (``-eleOnly``), since no element touches a master.
* **Modal damping of floors with one DOF** (:func:`dashpot_network`): the dense matrix C as linear
  dashpots (``zeroLength`` + ``Elastic(0, c)``, ``-doRayleigh 0``): ``−C_ij`` between floors i and j
  and the row sum ``Σ_j C_ij`` from floor i to the ground, which assembles to C exactly.  A
  ``zeroLength`` dashpot couples like DOFs of two nodes, so this writes C only where each floor
  has one DOF.
* **Modal damping of floors in plan** (:func:`modal_damping`): OpenSees' ``modalDamping``, which adds
  ``Σ 2ζω (Mφ)(Mφ)ᵀ`` over the domain's mass-normalised modes to the force and the tangent.  The
  script finds them with ``eigen -fullGenLapack N`` (all N = 3 × floors modes; ARPACK gives at
  most N − 1) on Elastic stand-ins of the planes' initial tangents (no P-Delta, no contact: the
  stiffness our modes are of), gives each mode its building's ratio in OpenSees' ascending order
  (every building's modes merged, 0 for a Rayleigh-damped building's), then removes the
  stand-ins; the buildings are uncoupled at rest, so this is each building's modal matrix.
  Refused in one line (:func:`repeated_frequency`): two modes at one frequency with different
  ratios, since the order and eigenvectors of modes at one frequency are OpenSees' eigen
  solver's choice.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["ModalDamping", "rayleigh_row", "mass_proportional_dashpots", "writes_damping_matrix", "dashpot_network", "domain_modes",
           "modal_damping", "repeated_frequency", "REPEATED_FREQUENCY", "EIGEN_TAG_OFFSET"]

#: Two modes whose ω² differ by at most this fraction share a frequency (OpenSees' eigenvectors of it are its own).
REPEATED_FREQUENCY = 1.0e-6

#: Tags of the planes' elastic stand-ins (elements and materials) during the eigen analysis: this offset + element.
EIGEN_TAG_OFFSET = 20_000_000


@dataclass(frozen=True)
class ModalDamping:
    """OpenSees' modalDamping of a domain: each mode's ratio in OpenSees' order and its ω² (1/s²); empty: none."""

    ratios: list[float] = field(default_factory=list)
    omega2: list[float] = field(default_factory=list)


def rayleigh_row(building, elements: list[int], nodes: list[int], *, with_mass: bool = True) -> tuple:
    """``(name, a0 1/s, a1 s, spring elements, nodes carrying the mass)`` of a Rayleigh-damped *building*.

    *with_mass* False: a0 written as 0 (its part is :func:`mass_proportional_dashpots` instead).
    """
    a0, a1 = building.rayleigh_coefficients
    return (building.name, float(a0) if with_mass else 0.0, float(a1), elements, nodes)


def mass_proportional_dashpots(building, nodes, b_index: int, element: int) -> list[tuple]:
    """``(element, base node, floor node, a0·m_i N s/m)``: the a0·M part of *building*'s Rayleigh damping as dashpots.

    In the plane (x, z) (a domain with a founded building) each is a ``twoNodeLink`` from the building's
    base (its base mat, or its ground node) to floor i, whose deformation is the floor's deformation
    ``d_i = x_i − u_b − z_i θ_b``: together they assemble ``a0 Tᵀ M T``, the mass-proportional damping
    of the fixed-base building acting on its deformations (a Rayleigh region would damp ``x_i``, and
    the base mat's mass and rotary inertia, instead).  Tags after *element*.
    """
    a0, _a1 = building.rayleigh_coefficients
    rows = []
    for level, mass in enumerate(building.mass, start=1):
        element += 1
        rows.append((element, nodes.floor(b_index, 0), nodes.floor(b_index, level), float(a0 * mass)))
    return rows


def writes_damping_matrix(building) -> bool:
    """True if *building*'s modal damping is written as a dashpot network (its floors have one DOF)."""
    return building.damping.kind == "modal" and building.dofs_per_floor == 1


def dashpot_network(building, nodes, b_index: int, element: int) -> list[tuple]:
    """``(element, node i, node j, c N s/m)`` dashpots assembling to *building*'s damping matrix, tags after *element*.

    Parameters
    ----------
    building : Building
        Floors with one DOF.
    nodes : AxisNodes
        The domain's nodes (``floor(b, level)``, level 0 the ground).
    b_index : int
        The building's index in the model.
    element : int
        The last element tag used.
    """
    c = np.asarray(building.damping_matrix(), dtype=float)
    rows = []
    for i in range(building.n_floors):
        element += 1
        rows.append((element, nodes.floor(b_index, 0), nodes.floor(b_index, i + 1), float(c[i].sum())))
        for j in range(i + 1, building.n_floors):
            if c[i, j] != 0.0:
                element += 1
                rows.append((element, nodes.floor(b_index, i + 1), nodes.floor(b_index, j + 1), float(-c[i, j])))
    return rows


def domain_modes(model) -> list[tuple[float, float, str, int]]:
    """Every building's modes as OpenSees' ``eigen`` orders the domain's: ``(ω² 1/s², ratio, building, mode)``.

    Ascending ω² over all buildings (uncoupled at rest: the domain's modes are theirs); the ratio is the
    building's modal ratio of that mode (``damping.ratios``), 0 for a Rayleigh-damped building (damped by
    its regions instead).
    """
    rows = []
    for b in model.buildings:
        omega = np.asarray(b.modes[0], dtype=float)
        ratios = b.damping.ratios(omega.size) if b.damping.kind == "modal" else np.zeros(omega.size)
        rows += [(float(w * w), float(r), b.name, k) for k, (w, r) in enumerate(zip(omega, ratios), start=1)]
    return sorted(rows, key=lambda row: row[0])


def _uses_modal_damping(model) -> bool:
    return any(b.damping.kind == "modal" and not writes_damping_matrix(b) for b in model.buildings)


def modal_damping(model) -> ModalDamping:
    """The ratios and ω² of OpenSees' modalDamping for *model* (empty if no building needs it)."""
    if not _uses_modal_damping(model):
        return ModalDamping()
    modes = domain_modes(model)
    return ModalDamping([row[1] for row in modes], [row[0] for row in modes])


def repeated_frequency(model) -> str | None:
    """Why OpenSees' modalDamping cannot write *model*'s modal damping (one frequency, two ratios), or None."""
    if not _uses_modal_damping(model):
        return None
    rows = domain_modes(model)
    for (w1, r1, b1, m1), (w2, r2, b2, m2) in zip(rows, rows[1:]):
        if w2 - w1 <= REPEATED_FREQUENCY * w2 and r1 != r2:
            return (f"modal damping: mode {m1} of {b1} and mode {m2} of {b2} share a frequency "
                    f"({math.sqrt(w2) / (2.0 * math.pi):.6g} Hz, ω² within {REPEATED_FREQUENCY:g}) but take damping "
                    f"ratios {r1:g} and {r2:g} (0 for a Rayleigh-damped building): OpenSees' modalDamping gives one "
                    "ratio per mode of the whole domain in its eigen solver's order, and the order and eigenvectors "
                    "of modes at one frequency are that solver's choice, so it cannot write this damping matrix")
    return None
