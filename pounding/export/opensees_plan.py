"""Export a plan model (floors that twist, docs/plan-models.md) to a standalone OpenSeesPy script.

``pounding export opensees corner.yaml [--dt 1e-4] [--xi NAME] [--duration T] -o model.py``
writes, for a model whose buildings take ``plan:``:

* a 3-D domain (``model basic -ndm 3 -ndf 6``) with every node at z = 0: the
  storeys are zero-length springs, so elevations do not enter (a shear model);
* every floor a ``rigidDiaphragm`` (perpendicular direction 3) whose master node
  at the floor's centre of mass carries ``m, m, I = m r²`` on u_x, u_y, θ_z (its
  u_z, θ_x, θ_y fixed), and whose slaves are the points where planes, contacts,
  the P-Delta load and the outline's corners attach (their u_z, θ_x, θ_y
  fixed); ``constraints Transformation`` imposes the diaphragms exactly, and
  OpenSees' diaphragm is the same small-rotation map as ours
  (``u_x − θ (y − y_c)``, ``u_y + θ (x − x_c)``), so the equations are the same;
* every plane a ``zeroLength`` with ``Elastic(k)`` along its direction
  (``-dir 1`` for x, ``2`` for y) between the plane's point on the floor below (a
  fixed ground node under storey 1) and on its floor: its deformation is the
  plane's drift ``a · q``, its stiffness ``k a aᵀ``;
* each building's Rayleigh damping ``a0 M + a1 K_init`` as two regions: its
  master nodes with ``-rayleigh a0 0 0 0`` and its plane elements with
  ``-rayleigh 0 0 a1 0`` (modal damping is refused in one line: its dense
  matrix couples u and θ of every floor and has no element here);
* with ``p_delta: true``, per storey one ``zeroLength`` at the weight's centroid
  c̄ with ``Elastic(−P/h)`` along x and y and ``Elastic(−P r̄²/h)`` about z
  (:func:`pounding.model.plan.plan_geometric_terms`), no damping;
* every contact point a ``zeroLength`` along the face normal from the low side's
  point to the high side's (a fixed node for a wall), both at the point's rest
  location, with the material of the planar export
  (:func:`pounding.export.opensees.contact_material`: ``Hertzdamp Kh xiNorm −gap``
  for hertz-damp), ``-doRayleigh 0``;
* the two ground components ``a_gx, a_gy`` (the angle applied,
  :func:`pounding.simulation.plan_ground`) as two ``timeSeries Path`` and two
  ``pattern UniformExcitation`` (directions 1 and 2);
* Newmark average acceleration + Newton at a fixed ``dt``, as the planar export.

Refused in one line: friction (``friction:`` on a contact), hysteretic planes,
modal damping.  The differences from our solver that remain are the planar
export's (module :mod:`pounding.export.opensees`): Hertzdamp reads its ξ one
step after closure and never clamps the pull before separation (compare with
``tension: allow``, :func:`allow_plan_tension`), peaks are read at the steps.

The script prints (and :func:`run_opensees_plan` returns) the peaks labelled
as in a plan archive: ``peak_displacement`` ((floor, direction) m),
``peak_rotation`` (rad), ``peak_plane_drift`` (m, archive plane order),
``peak_contact_force`` (N) and ``impact_count`` (archive point order), and
``peak_corner_displacement`` ((corner, direction) m, corners of
:func:`outline_corners`, which :func:`peak_corner_displacement` reads from our
archive).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pounding import __version__
from pounding.errors import PoundingError
from pounding.export.opensees import DEFAULT_DT, contact_material, inert, run_script, SCRIPT_PARTS, tension_allowed
from pounding.model.model import WALL
from pounding.model.floors import DOF_PER_FLOOR, geometric_terms as plan_geometric_terms
from pounding.model.model import Model as PlanModel

__all__ = ["plan_opensees_script", "plan_export_refusal", "allow_plan_tension", "plan_with_xi", "outline_corners",
           "peak_corner_displacement", "run_opensees_plan"]

#: The outline's corners, in this order: (name, x index, y index) into ((x0, y0), (x1, y1)).
CORNERS = (("SW", 0, 0), ("SE", 1, 0), ("NE", 1, 1), ("NW", 0, 1))


def plan_export_refusal(model: PlanModel) -> str | None:
    """Why *model* cannot be exported to OpenSees (one line), or None."""
    if any(c.friction for c in model.faces):
        return "the OpenSees export does not write friction (Coulomb friction on a face has no exact element here)"
    for b in model.buildings:
        if b.damping.kind != "rayleigh":
            return (f"building {b.name}: the OpenSees export of a plan model writes Rayleigh damping only "
                    "(a modal damping matrix couples every floor's u and θ)")
        for i, s in enumerate(b.storeys):
            if any(p.hysteresis is not None for p in s.planes):
                return f"building {b.name} storey {i + 1}: the OpenSees export of a plan model writes elastic planes only"
    return None


def _with_laws(model: PlanModel, change) -> PlanModel:
    return model.with_laws(change)


def allow_plan_tension(model: PlanModel) -> PlanModel:
    """The same plan model with ``tension: allow`` on every hertz-damp (and kelvin) contact (as OpenSees' Hertzdamp)."""
    cache: dict[int, object] = {}
    return _with_laws(model, lambda law: tension_allowed(law, cache))


def plan_with_xi(model: PlanModel, name: str) -> PlanModel:
    """The same plan model with every hertz-damp contact using the ξ formula *name*."""
    from pounding.contact.laws import HertzDamp
    from pounding.contact.xi import registry as xi_formulas

    key = xi_formulas.get(name).key
    if not any(isinstance(c.law, HertzDamp) for c in model.faces):
        raise PoundingError(f"model '{model.name}' has no hertz-damp contacts; the xi formula applies only to "
                            "law hertz-damp")
    return _with_laws(model, lambda law: type(law)(**{**law.model_dump(), "xi": key})
                      if isinstance(law, HertzDamp) else law)


def outline_corners(model: PlanModel) -> list[tuple[str, int, int, tuple[float, float]]]:
    """``(label, building, level, (x, y))`` for the four outline corners of every floor (``A:6:NE``), floor by floor."""
    out = []
    for b_index, b in enumerate(model.buildings):
        for level in range(1, b.n_floors + 1):
            for name, ix, iy in CORNERS:
                out.append((f"{b.name}:{level}:{name}", b_index, level,
                            (float(b.outline[ix][0]), float(b.outline[iy][1]))))
    return out


def peak_corner_displacement(model: PlanModel, ds) -> np.ndarray:
    """(corner, 2) peak |u_x|, |u_y| (m) of :func:`outline_corners` from a plan archive's sampled histories.

    Read at the archive's ``output_dt`` (small rotations: ``u_x − θ (y − y_c)``, ``u_y + θ (x − x_c)``).
    """
    u = ds.displacement.values
    theta = ds.rotation.values
    first = np.cumsum([0] + [b.n_floors for b in model.buildings])
    peaks = []
    for _label, b, level, (x, y) in outline_corners(model):
        floor = first[b] + level - 1
        xc, yc = model.buildings[b].storeys[level - 1].centre
        peaks.append((np.abs(u[:, floor, 0] - theta[:, floor] * (y - yc)).max(),
                      np.abs(u[:, floor, 1] + theta[:, floor] * (x - xc)).max()))
    return np.array(peaks, dtype=float).reshape(-1, 2)


def _fmt(x: float) -> str:
    return repr(float(x))


class _Nodes:
    """Node numbering: masters, their slaves by rest location, fixed ground nodes by location."""

    def __init__(self) -> None:
        self.count = 0
        self.masters: list[tuple] = []      # (node, label, x, y, m, I)
        self.slaves: dict[tuple, int] = {}  # (floor key, x, y) -> node
        self.slave_rows: list[tuple] = []   # (node, master, x, y)
        self.fixed: dict[tuple, int] = {}   # (x, y) -> node
        self.master_of: dict[tuple[int, int], int] = {}

    def master(self, key: tuple[int, int], label: str, centre, mass: float, inertia: float) -> int:
        self.count += 1
        self.master_of[key] = self.count
        self.masters.append((self.count, label, float(centre[0]), float(centre[1]), float(mass), float(inertia)))
        return self.count

    def at(self, key: tuple[int, int] | None, point) -> int:
        """The node of floor *key* (building, level; level 0 or None: the fixed ground) at *point*."""
        x, y = float(point[0]), float(point[1])
        if key is None or key[1] == 0:
            if (x, y) not in self.fixed:
                self.count += 1
                self.fixed[(x, y)] = self.count
            return self.fixed[(x, y)]
        if (key, x, y) not in self.slaves:
            self.count += 1
            self.slaves[(key, x, y)] = self.count
            self.slave_rows.append((self.count, self.master_of[key], x, y))
        return self.slaves[(key, x, y)]


def plan_opensees_script(model: PlanModel, *, dt: float = DEFAULT_DT, xi: str | None = None,
                         duration: float | None = None) -> tuple[str, list[str]]:
    """(text of a standalone OpenSeesPy script of the plan *model*, notes on what it cannot reproduce exactly).

    Parameters
    ----------
    model : PlanModel
    dt : float
        OpenSees time step, s.
    xi : str, optional
        ξ formula for every hertz-damp contact.
    duration : float, optional
        Simulated time, s (default: the model's, else the longer component's).
    """
    from pounding.simulation import plan_ground

    if not (dt > 0.0 and math.isfinite(dt)):
        raise PoundingError(f"--dt must be > 0 (got {dt!r})")
    refusal = plan_export_refusal(model)
    if refusal is not None:
        raise PoundingError(f"{model.path or model.name}: {refusal}")
    if xi is not None:
        model = plan_with_xi(model, xi)
    rows, step, end = plan_ground(model, duration)
    notes: list[str] = []
    nodes = _Nodes()
    for b_index, b in enumerate(model.buildings):
        for level, s in enumerate(b.storeys, start=1):
            nodes.master((b_index, level), f"{b.name}:{level}", s.centre, s.mass, s.mass * s.radius_of_gyration ** 2)

    element = 0
    planes, p_delta, rayleigh = [], [], []
    for b_index, b in enumerate(model.buildings):
        elements = []
        for storey, j, _a in b.plane_weights():
            plane = b.storeys[storey - 1].planes[j]
            point = (0.0, plane.at) if plane.direction == "x" else (plane.at, 0.0)
            element += 1
            planes.append((element, nodes.at((b_index, storey - 1), point), nodes.at((b_index, storey), point),
                           1 + "xy".index(plane.direction), float(plane.stiffness),
                           f"{b.name}:{storey}:{plane.direction}@{plane.at:g}"))
            elements.append(element)
        if b.p_delta:
            terms = plan_geometric_terms(list(b.storeys))
            for i in range(b.n_floors):
                (_, kx, ax), (_, ky, _), (_, kt, _) = terms[DOF_PER_FLOOR * i:DOF_PER_FLOOR * (i + 1)]
                # a_x, a_y are the drift weights of the weight's centroid c̄ = (x̄, ȳ): on the floor above
                # their θ weights are −(ȳ − y_c) and x̄ − x_c
                (_, ay) = terms[DOF_PER_FLOOR * i + 1][1:]
                xc, yc = b.storeys[i].centre
                theta = DOF_PER_FLOOR * i + 2
                centroid = (xc + ay[theta], yc - ax[theta])
                element += 1
                p_delta.append((element, nodes.at((b_index, i), centroid), nodes.at((b_index, i + 1), centroid),
                                [float(kx), float(ky), float(kt)]))
        a0, a1 = b.rayleigh_coefficients
        masters = [nodes.master_of[(b_index, level)] for level in range(1, b.n_floors + 1)]
        rayleigh.append((b.name, float(a0), float(a1), elements, masters))

    names = [b.name for b in model.buildings]
    contacts = []
    for c in model.faces:
        first = (c.first, c.level_first)
        second = None if c.second == WALL else (c.second, c.level_second)
        label = f"{names[c.first]}:{c.level_first}-" + ("wall" if second is None else f"{names[c.second]}:{c.level_second}")
        material, warnings = contact_material(c.law, c.gap)
        notes += [w for w in warnings if w not in notes]
        for point in c.points:
            one, two = nodes.at(first, point.location), nodes.at(second, point.location)
            low, high = (one, two) if c.face.first_low else (two, one)
            element += 1
            contacts.append((element, low, high, 1 + "xy".index(c.face.normal), material, label))

    corners = [(nodes.at((b, level), point), label) for label, b, level, point in outline_corners(model)]
    n_samples = int(math.ceil(end / step - 1e-9)) + 1
    unbalance = 1e-12 * max(row[4] for row in planes)
    summary = "\n".join(f"#   {inert(b.name)}: {b.n_floors} floors, outline {b.outline}" for b in model.buildings)
    text = _TEMPLATE.format(
        version=__version__, name=inert(model.name), name_literal=repr(str(model.name)), summary=summary,
        notes="\n".join("# NOTE: " + inert(n) for n in notes), angle=_fmt(model.ground_motion.angle),
        record_dt=_fmt(step), duration=_fmt(end), dt=_fmt(dt), unbalance=_fmt(unbalance), n_samples=n_samples,
        record_x=_samples(rows[0, :n_samples]), record_y=_samples(rows[1, :n_samples]),
        masters=_rows(nodes.masters), slaves=_rows(nodes.slave_rows), fixed=_rows((tag, x, y) for (x, y), tag in sorted(nodes.fixed.items(), key=lambda kv: kv[1])),
        planes=_rows(planes), p_delta=_rows(p_delta), rayleigh=_rows(rayleigh), contacts=_rows(contacts),
        corners=_rows(corners), **SCRIPT_PARTS)
    return text, notes


def _samples(values: np.ndarray) -> str:
    return "\n".join("    " + ", ".join(_fmt(a) for a in values[start:start + 6]) + ","
                     for start in range(0, values.size, 6))


def _rows(items) -> str:
    return "\n".join(f"    {tuple(item)!r}," for item in items)


def run_opensees_plan(model: PlanModel, *, dt: float = DEFAULT_DT, xi: str | None = None,
                      duration: float | None = None) -> dict:
    """Export the plan *model* and run the script in a child Python process; return its peaks (module docstring).

    Raises
    ------
    PoundingError
        If OpenSeesPy is not installed, the model cannot be exported or the script fails.
    """
    source, _notes = plan_opensees_script(model, dt=dt, xi=xi, duration=duration)
    return run_script(source, model.name)


_TEMPLATE = '''#!/usr/bin/env python3
"""OpenSeesPy plan model '{name}' exported by pounding {version} (rigid diaphragms, 3 DOF per floor).

Run:   python THIS.py [--dt DT] [-o peaks.json]
Import: analyse(dt=..., duration=...) -> dict of peaks (plan-archive names).

Units SI (kg, N/m, m, s).  Model:
{summary}
Ground: two components a_gx, a_gy (angle {angle} deg applied), {n_samples} samples at {record_dt} s (m/s^2),
simulated for {duration} s.
"""
{notes}
{imports}
MODEL_NAME = {name_literal}
UNBALANCE_TOLERANCE = {unbalance}  # N
DT = {dt}
DURATION = {duration}
RECORD_DT = {record_dt}
RECORD_X = [  # ground acceleration along x, m/s^2, linear between samples, 0 after the last
{record_x}
]
RECORD_Y = [  # along y
{record_y}
]
# floor masters at the centre of mass: (node, floor label, x m, y m, mass kg, I kg m^2)
MASTERS = [
{masters}
]
# diaphragm slaves: (node, master node, x m, y m)
SLAVES = [
{slaves}
]
# fixed nodes (the ground under storey 1, walls): (node, x m, y m)
FIXED = [
{fixed}
]
# planes: (element, node below, node, direction 1=x 2=y, stiffness N/m, plane label)
PLANES = [
{planes}
]
# P-Delta (leaning column at the weight's centroid): (element, node below, node, [k_x, k_y N/m, k_theta N m])
P_DELTA = [
{p_delta}
]
# Rayleigh damping per building: (name, a0 1/s on the masters, a1 s on the planes' initial stiffness, planes, masters)
RAYLEIGH = [
{rayleigh}
]
# contact points: (element, low-side node, high-side node, normal direction, material args, contact label)
CONTACTS = [
{contacts}
]
# outline corners (diaphragm slaves): (node, corner label)
CORNERS = [
{corners}
]


def build(log_file=None):
    """Create the OpenSees domain (wipes any previous one)."""
    ops.wipe()
    if log_file is not None:
        ops.logFile(log_file, "-noEcho")  # Hertzdamp prints one line per impact
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for tag, x, y in FIXED:
        ops.node(tag, x, y, 0.0)
        ops.fix(tag, 1, 1, 1, 1, 1, 1)
    for tag, _label, x, y, mass, inertia in MASTERS:
        ops.node(tag, x, y, 0.0)
        ops.mass(tag, mass, mass, 0.0, 0.0, 0.0, inertia)
        ops.fix(tag, 0, 0, 1, 1, 1, 0)
    slaves = {{}}
    for tag, master, x, y in SLAVES:
        ops.node(tag, x, y, 0.0)
        ops.fix(tag, 0, 0, 1, 1, 1, 0)
        slaves.setdefault(master, []).append(tag)
    for master, tags in slaves.items():
        ops.rigidDiaphragm(3, master, *tags)
    for ele, i, j, direction, k, _label in PLANES:
        ops.uniaxialMaterial("Elastic", ele, k)
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", direction, "-doRayleigh", 1)
    for ele, i, j, ks in P_DELTA:
        tags = [3 * ele + m for m in range(3)]
        for tag, k in zip(tags, ks):
            ops.uniaxialMaterial("Elastic", tag + 10_000_000, k)
        ops.element("zeroLength", ele, i, j, "-mat", *[t + 10_000_000 for t in tags], "-dir", 1, 2, 6,
                    "-doRayleigh", 0)
    for ele, i, j, direction, material, _label in CONTACTS:
        ops.uniaxialMaterial(material[0], ele, *material[1:])
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", direction, "-doRayleigh", 0)
    for index, (_name, a0, a1, elements, masters) in enumerate(RAYLEIGH):
        # a0 on the masters' masses (m, m, I), a1 on the planes' initial stiffness
        ops.region(2 * index + 1, "-nodeOnly", *masters, "-rayleigh", a0, 0.0, 0.0, 0.0)
        ops.region(2 * index + 2, "-eleOnly", *elements, "-rayleigh", 0.0, 0.0, a1, 0.0)
    ops.timeSeries("Path", 1, "-dt", RECORD_DT, "-values", *RECORD_X, "-factor", 1.0)
    ops.timeSeries("Path", 2, "-dt", RECORD_DT, "-values", *RECORD_Y, "-factor", 1.0)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.pattern("UniformExcitation", 2, 2, "-accel", 2)


{read_rows}


def _envelope(path):
    with open(path) as handle:
        return [[float(x) for x in line.split()] for line in handle if line.strip()][2]


def analyse(dt=DT, duration=DURATION, workdir=None):
    """Run the analysis; return the peaks and the solver wall time (an impact: a step with force after one without)."""
    own = workdir is None
    workdir = tempfile.mkdtemp(prefix="pounding-opensees-") if own else workdir
    try:
        build(os.path.join(workdir, "opensees.log"))
        masters = [row[0] for row in MASTERS]
        corner_nodes = [row[0] for row in CORNERS]
        plane_elements = [row[0] for row in PLANES]
        contact_elements = [row[0] for row in CONTACTS]
        files = {{name: os.path.join(workdir, name) for name in ("u.env", "corner.env", "drift.env", "force.bin")}}
        ops.recorder("EnvelopeNode", "-file", files["u.env"], "-precision", 16, "-node", *masters, "-dof", 1, 2, 6,
                     "disp")
        ops.recorder("EnvelopeNode", "-file", files["corner.env"], "-precision", 16, "-node", *corner_nodes,
                     "-dof", 1, 2, "disp")
        ops.recorder("EnvelopeElement", "-file", files["drift.env"], "-precision", 16, "-ele", *plane_elements,
                     "deformation")
        if contact_elements:
            ops.recorder("Element", "-binary", files["force.bin"], "-ele", *contact_elements, "basicForce")
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormUnbalance", UNBALANCE_TOLERANCE, 25)
        ops.algorithm("Newton")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")

{stepping}
        end = ops.getTime()
        ops.wipe()  # flushes and closes the recorders

        u = _envelope(files["u.env"])
        corner = _envelope(files["corner.env"])
        drift = _envelope(files["drift.env"])
        nc = len(contact_elements)
        peak_force, impacts = [0.0] * nc, [0] * nc
        if nc:
            closed = [False] * nc
            for row in _read_rows(files["force.bin"], nc):
                for c in range(nc):
                    f = -row[c]  # compression is negative in OpenSees
                    if f != 0.0 and not closed[c]:
                        impacts[c] += 1
                    closed[c] = f != 0.0
                    peak_force[c] = max(peak_force[c], f)
        return {{
            "model": MODEL_NAME,
            "simulator": "OpenSeesPy Newmark(1/2, 1/4) + Newton, rigid diaphragms",
            "dt": dt,
            "duration": duration,
            "end_time": end,
            "converged": status == 0,
            "cut_steps": cut_steps,
            "wall_time": wall,
            "floor": [row[1] for row in MASTERS],
            "peak_displacement": [u[3 * i:3 * i + 2] for i in range(len(masters))],
            "peak_rotation": [u[3 * i + 2] for i in range(len(masters))],
            "corner": [row[1] for row in CORNERS],
            "peak_corner_displacement": [corner[2 * i:2 * i + 2] for i in range(len(corner_nodes))],
            "plane": [row[5] for row in PLANES],
            "peak_plane_drift": drift,
            "point": [row[5] for row in CONTACTS],
            "peak_contact_force": peak_force,
            "impact_count": impacts,
        }}
    finally:
        if own:
            shutil.rmtree(workdir, ignore_errors=True)


{main}
'''
