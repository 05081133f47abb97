"""The OpenSees domain of a model: nodes of its floors and supports, zeroLength elements of its springs.

One builder (:func:`build_domain`) reads the description (:class:`pounding.model.model.Model`) and
gives every part its nodes and elements; only where a part sits on a floor does the floor's
number of degrees of freedom matter, through the node numbering:

* **floors of one DOF** (:class:`AxisNodes`): one node per floor on one axis (``model basic -ndm 1
  -ndf 1``) and one fixed ground node per building, building by building (ground, then floors);
  every point of a floor is its node;
* **floors in plan** (:class:`DiaphragmNodes`): a ``rigidDiaphragm`` per floor (``-ndm 3 -ndf
  6``, every node at z = 0: the storeys are zero-length springs, elevations do not enter), its
  master at the centre of mass carrying ``m, m, I = m r²``, its slaves the points where planes,
  contacts, links, the P-Delta spring and the outline's corners attach; fixed nodes by location
  (the ground under storey 1, walls).  OpenSees' diaphragm is our small-rotation map
  (``u_x − θ (y − y_c)``, ``u_y + θ (x − x_c)``).  The masters are numbered after every other
  node: in OpenSees 3.7 (``IncrementalIntegrator::setupModal``) a diaphragm slave's DOF group
  copies its own node's eigenvector rows (never filled for a constrained node) over its master's
  equations, and the last group written wins, so modal damping needs the masters last.

Then, the same for every model:

* each plane (a planar storey is one plane along x) a ``zeroLength`` along its direction between
  its line's point on the floor below (the ground under storey 1) and on its floor, with the
  storey's material (:func:`pounding.export.opensees_materials.storey_material` at the plane's
  stiffness and its storey's height): its deformation is the plane's drift ``a · q``;
* ``p_delta: true``: per storey a ``zeroLength`` at the weight's centroid c̄ carrying the leaning
  column's geometric terms (:func:`pounding.model.floors.geometric_terms`): ``Elastic(−P/h)``
  along x (and y), ``Elastic(−P r̄²/h)`` about z in plan, without damping;
* each contact point (``Model.gaps``) a ``zeroLength`` along its ``normal`` from the low side's
  node at its ``point`` to the high side's (a wall: the fixed node there, which moves with the
  ground as the wall does), with the contact's material;
* each link (``Model.links``) a ``zeroLength`` along its ``normal`` between the two floors' nodes
  at its ``point``, with its law's materials: a contact point without a gap;
* the outline's corners of every floor in plan, as diaphragm slaves (their peaks).

The damping elements (a dashpot network, OpenSees' ``modalDamping``, Rayleigh regions) are
:mod:`pounding.export.opensees_damping`'s.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

from pounding.export.opensees_damping import (ModalDamping, dashpot_network, mass_proportional_dashpots,
                                              modal_damping, rayleigh_row, writes_damping_matrix)
from pounding.export.opensees_materials import contact_material, link_materials, storey_material
from pounding.model.floors import geometric_terms
from pounding.model.model import WALL

__all__ = ["AxisNodes", "DiaphragmNodes", "Spring", "PDelta", "Contact", "LinkElement", "Domain", "build_domain",
           "plane_point", "foundation_row", "CORNERS",
           "DIRECTION_DOF"]

#: The outline's corners, in this order (the archive's ``corner`` coordinate): (name, x index, y index)
#: into ((x0, y0), (x1, y1)).
CORNERS = (("south-west", 0, 0), ("south-east", 1, 0), ("north-east", 1, 1), ("north-west", 0, 1))

#: OpenSees DOF of a direction in plan (``-dir``): u_x 1, u_y 2, θ_z 6.
DIRECTION_DOF = {"x": 1, "y": 2, "rz": 6}


class AxisNodes:
    """Nodes of floors with one DOF: per building its fixed ground node, (on a foundation) its base mat, its floors.

    With a founded building the domain is the plane (x, z) with rotations (``ndf`` 3,
    :func:`pounding.export.opensees_text.axis_script`): every node stands at its elevation, a base mat's
    node sways and rocks on its ground node, and its floors' rotations are its rocking.
    """

    form = "axis"

    def __init__(self, model) -> None:
        self.grounds: list[int] = []
        self.floors: list[tuple[int, str, float]] = []          # (node, floor label, mass kg)
        self.bases: dict[int, int] = {}                          # building -> its base mat's node
        self.elevation: dict[int, float] = {}                    # node -> z, m
        self._floor: dict[tuple[int, int], int] = {}
        self._building: list[list[int]] = []
        self.ndf = 3 if any(b.foundation is not None for b in model.buildings) else 1
        node = 0
        for b_index, b in enumerate(model.buildings):
            node += 1
            self.grounds.append(node)
            nodes = [node]
            if b.foundation is not None:
                node += 1
                self.bases[b_index] = node
            for level, z in enumerate(b.elevation, start=1):
                node += 1
                self._floor[(b_index, level)] = node
                self.elevation[node] = float(z)
                self.floors.append((node, f"{b.name}:{level}", float(b.mass[level - 1])))
                nodes.append(node)
            self._building.append(nodes)

    def floor(self, building: int, level: int, point=None) -> int:
        """The node of floor *level* of *building* (0: the ground, or its base mat on a foundation)."""
        if level == 0:
            return self.bases.get(building, self.grounds[building])
        return self._floor[(building, level)]

    def fixed(self, building: int, point=None) -> int:
        """A fixed node beside *building* (a wall): its ground node, which moves with the ground as a wall does."""
        return self.grounds[building]

    def building_nodes(self, building: int) -> list[int]:
        """The nodes of *building*'s Rayleigh region: its ground node and its floors."""
        return self._building[building]

    def number(self) -> None:
        """Nothing to renumber: the nodes are numbered as they are made."""


class DiaphragmNodes:
    """Nodes of floors in plan: slaves by floor and rest location, fixed nodes by location, then the masters.

    The masters are numbered after every other node (:meth:`number`; module docstring).
    """

    form = "diaphragm"
    ndf = 6

    def __init__(self, model) -> None:
        self.count = 0
        self._masters: list[tuple] = []        # (floor key, label, x, y, m, I)
        self._slaves: dict[tuple, int] = {}    # (floor key, x, y) -> node
        self._slave_rows: list[tuple] = []     # (node, floor key, x, y)
        self._fixed: dict[tuple, int] = {}     # (x, y) -> node
        self.tags: dict[tuple[int, int], int] = {}
        self.masters: list[tuple] = []         # (node, floor label, x m, y m, mass kg, I kg m²), after number()
        self.slaves: list[tuple] = []          # (node, master node, x m, y m)
        self.fixed_rows: list[tuple] = []      # (node, x m, y m)
        for b_index, b in enumerate(model.buildings):
            for level, s in enumerate(b.storeys, start=1):
                self._masters.append(((b_index, level), f"{b.name}:{level}", float(s.centre[0]),
                                      float(s.centre[1]), float(s.mass), float(s.mass * s.radius_of_gyration ** 2)))

    def floor(self, building: int, level: int, point) -> int:
        """The node of floor *level* (0: the fixed ground) of *building* at *point* (m)."""
        if level == 0:
            return self.fixed(building, point)
        key = ((building, level), float(point[0]), float(point[1]))
        if key not in self._slaves:
            self.count += 1
            self._slaves[key] = self.count
            self._slave_rows.append((self.count, *key))
        return self._slaves[key]

    def fixed(self, building: int | None, point) -> int:
        """The fixed node at *point* (m): the ground, or a wall."""
        key = (float(point[0]), float(point[1]))
        if key not in self._fixed:
            self.count += 1
            self._fixed[key] = self.count
        return self._fixed[key]

    def number(self) -> None:
        """Number the masters after every other node and fill the tables (call once every node is made)."""
        self.tags = {row[0]: self.count + i for i, row in enumerate(self._masters, start=1)}
        self.masters = [(self.tags[key], *rest) for key, *rest in self._masters]
        self.slaves = [(node, self.tags[key], x, y) for node, key, x, y in self._slave_rows]
        self.fixed_rows = [(tag, x, y) for (x, y), tag in sorted(self._fixed.items(), key=lambda kv: kv[1])]

    def building_nodes(self, building: int) -> list[int]:
        """The nodes carrying *building*'s mass: its floors' masters (after :meth:`number`)."""
        return [tag for (b, _level), tag in self.tags.items() if b == building]


class Spring(NamedTuple):
    """A plane (a planar storey: its one plane) as a ``zeroLength``."""

    element: int
    below: int
    node: int
    direction: int          # OpenSees DOF: 1 (x) or 2 (y)
    stiffness: float        # N/m
    label: str              # the archive's plane label, A:3:x@0
    storey: str             # A:3
    height: float           # m
    material: list
    tangent: float          # the material's initial tangent, N/m


class PDelta(NamedTuple):
    """A storey's leaning column: its geometric terms as Elastic materials along x (y, θ) at the weight's centroid."""

    element: int
    below: int
    node: int
    directions: list[int]
    stiffness: list[float]  # N/m along x and y, N m about z
    storey: str


class Contact(NamedTuple):
    """A contact point as a ``zeroLength`` from the low side's node to the high side's, along *direction*."""

    element: int
    low: int
    high: int
    material: list
    label: str
    direction: int


class LinkElement(NamedTuple):
    """A link as a ``zeroLength`` from the low side's node to the high side's (a contact point without a gap)."""

    element: int
    left: int
    right: int
    materials: list
    label: str
    direction: int


@dataclass
class Domain:
    """Every node and element of a model's OpenSees domain (:func:`build_domain`)."""

    nodes: AxisNodes | DiaphragmNodes
    springs: list[Spring] = field(default_factory=list)
    p_delta: list[PDelta] = field(default_factory=list)
    dashpots: list[tuple] = field(default_factory=list)   # (element, node i, node j, c N s/m)
    rayleigh: list[tuple] = field(default_factory=list)   # (name, a0 1/s, a1 s, spring elements, mass nodes)
    contacts: list[Contact] = field(default_factory=list)
    links: list[LinkElement] = field(default_factory=list)
    corners: list[tuple] = field(default_factory=list)    # (node, corner label)
    foundations: list[tuple] = field(default_factory=list)  # foundation_row()
    modal: ModalDamping = field(default_factory=ModalDamping)
    notes: list[str] = field(default_factory=list)

    @property
    def elements(self) -> int:
        """The last element tag used."""
        return len(self.springs) + len(self.p_delta) + len(self.dashpots) + len(self.contacts) + len(self.links)


def plane_point(plane) -> tuple[float, float]:
    """A point of a plane's line, m: ``(0, at)`` along x, ``(at, 0)`` along y (any point of it drifts alike)."""
    return (0.0, float(plane.at)) if plane.direction == "x" else (float(plane.at), 0.0)


def _springs(domain: Domain, b_index: int, building) -> list[int]:
    """Add *building*'s planes, storey by storey; return their elements."""
    nodes, added = domain.nodes, []
    for level, s in enumerate(building.storeys, start=1):
        for plane in s.planes:
            point, k = plane_point(plane), float(plane.stiffness)
            element = domain.elements + 1
            domain.springs.append(Spring(
                element, nodes.floor(b_index, level - 1, point), nodes.floor(b_index, level, point),
                DIRECTION_DOF[plane.direction], k, f"{building.name}:{level}:{plane.direction}@{plane.at:g}",
                f"{building.name}:{level}", float(s.height), storey_material(plane.hysteresis, k, float(s.height)),
                float(plane.initial_stiffness)))
            added.append(element)
    return added


def _p_delta(domain: Domain, b_index: int, building) -> None:
    """Add *building*'s leaning-column springs, one per storey at its weight's centroid c̄."""
    per = building.dofs_per_floor
    terms = geometric_terms(list(building.storeys), per)
    for i, storey in enumerate(building.storeys):
        own = terms[per * i:per * (i + 1)]
        xc, yc = storey.centre
        # The x (and y) term's drift weights are those of c̄ = (x̄, ȳ): on the floor above, θ weighs −(ȳ − y_c)
        # along x and x̄ − x_c along y.
        centroid = (xc, yc) if per == 1 else (xc + own[1][2][per * i + 2], yc - own[0][2][per * i + 2])
        domain.p_delta.append(PDelta(domain.elements + 1, domain.nodes.floor(b_index, i, centroid),
                                     domain.nodes.floor(b_index, i + 1, centroid),
                                     [DIRECTION_DOF[d] for d in ("x", "y", "rz")[:per]],
                                     [float(k) for _, k, _ in own], f"{building.name}:{i + 1}"))


def _contacts(domain: Domain, model) -> None:
    """Add every contact point along its normal (walls: the fixed node at the point)."""
    names = [b.name for b in model.buildings]
    for g in model.gaps:
        material, warnings = contact_material(g.law, g.gap)
        domain.notes += [w for w in warnings if w not in domain.notes]
        point = g.point
        low = domain.nodes.fixed(g.right, point) if g.left == WALL else domain.nodes.floor(g.left, g.level_left, point)
        high = domain.nodes.fixed(g.left, point) if g.right == WALL else \
            domain.nodes.floor(g.right, g.level_right, point)
        domain.contacts.append(Contact(domain.elements + 1, low, high, material, g.label(names),
                                       DIRECTION_DOF[g.normal]))


def _links(domain: Domain, model) -> None:
    """Add every link along its normal between its floors' nodes at its point."""
    names = [b.name for b in model.buildings]
    for link in model.links:
        element = domain.elements + 1
        domain.links.append(LinkElement(element, domain.nodes.floor(link.left, link.level_left, link.point),
                                        domain.nodes.floor(link.right, link.level_right, link.point),
                                        link_materials(link.law, element), link.label(names),
                                        DIRECTION_DOF[link.normal]))


def _corners(domain: Domain, model) -> None:
    """Add the outline's four corners of every floor of a building in plan (``A:6:north-east``)."""
    for b_index, b in enumerate(model.buildings):
        if b.outline is None:
            continue
        for level in range(1, b.n_floors + 1):
            for name, ix, iy in CORNERS:
                point = (float(b.outline[ix][0]), float(b.outline[iy][1]))
                domain.corners.append((domain.nodes.floor(b_index, level, point), f"{b.name}:{level}:{name}"))


def foundation_row(nodes: AxisNodes, b_index: int, building) -> tuple:
    """A founded *building*'s base mat: ``(base node, ground node, building, m_b kg, I_b kg m², K_x N/m,
    c_x N s/m, K_θ N m/rad, c_θ N m s/rad, floor nodes)``."""
    f = building.foundation
    return (nodes.floor(b_index, 0), nodes.grounds[b_index], building.name, float(f.mass), float(f.rotary_inertia),
            float(f.sway_stiffness), float(f.sway_damping), float(f.rocking_stiffness), float(f.rocking_damping),
            [nodes.floor(b_index, level) for level in range(1, building.n_floors + 1)])


def build_domain(model) -> Domain:
    """Every node and element of *model*'s OpenSees domain (module docstring).

    Elements are numbered building by building (its planes, its P-Delta springs, its dashpots), then the
    contact points, then the links.

    *model* is one the export accepts (:func:`pounding.export.opensees.export_refusal`).

    Raises
    ------
    PoundingError
        One line: a contact or link law without an OpenSees material.
    """
    domain = Domain(DiaphragmNodes(model) if model.in_plan else AxisNodes(model))
    regions = []
    for b_index, b in enumerate(model.buildings):
        elements = _springs(domain, b_index, b)
        if b.p_delta:
            _p_delta(domain, b_index, b)
        if b.damping.kind == "rayleigh":
            regions.append((b_index, b, elements))
            if domain.nodes.ndf == 3:
                domain.dashpots += mass_proportional_dashpots(b, domain.nodes, b_index, domain.elements)
        elif writes_damping_matrix(b):
            domain.dashpots += dashpot_network(b, domain.nodes, b_index, domain.elements)
    _contacts(domain, model)
    _links(domain, model)
    _corners(domain, model)
    domain.nodes.number()
    plane = domain.nodes.ndf == 3
    domain.rayleigh = [rayleigh_row(b, elements, domain.nodes.building_nodes(b_index), with_mass=not plane)
                       for b_index, b, elements in regions]
    domain.foundations = [foundation_row(domain.nodes, b_index, b) for b_index, b in enumerate(model.buildings)
                          if plane and b.foundation is not None]
    domain.modal = modal_damping(model)
    return domain
