"""The text of an exported OpenSeesPy script: its tables and the two forms of its domain.

:func:`axis_script` writes a domain whose floors have one degree of freedom (``model basic
-ndm 1 -ndf 1``: FLOORS, GROUNDS, STOREYS, P_DELTA, RAYLEIGH, DASHPOTS, CONTACTS, LINKS);
:func:`diaphragm_script` one whose floors are rigid diaphragms in plan (``-ndm 3 -ndf 6``:
MASTERS, SLAVES, FIXED, PLANES, P_DELTA, RAYLEIGH, CONTACTS, LINKS, CORNERS and the modal
damping).  Both share the rest of the script (:data:`SCRIPT_PARTS`): its imports, the
recorders and peaks of the contacts and links, Newmark average acceleration + Newton at a fixed
step (a failed step retaken in ten sub-steps with line search), and the command line.  Running
either prints the peaks under the run archive's names as JSON.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pounding import __version__

__all__ = ["ScriptGround", "axis_script", "diaphragm_script", "inert", "SCRIPT_PARTS"]


@dataclass(frozen=True)
class ScriptGround:
    """The ground motion a script applies: its components' samples (m/s²) along x (and y), on one step.

    Attributes
    ----------
    components : tuple of ndarray
        The samples along x, and along y for two components (the angle applied).
    time_step : float
        s.
    end_time : float
        The simulated time, s.
    name : str
        The record's name (one component) or the pair's.
    scale : float
        The record's scale factor (one component).
    angle : float or None
        Two components: the angle of incidence of component a (x), degrees from +x.
    """

    components: tuple
    time_step: float
    end_time: float
    name: str
    scale: float = 1.0
    angle: float | None = None


def fmt(x: float) -> str:
    """*x* as the script writes a float (its repr: it reads back exactly)."""
    return repr(float(x))


def _samples(values: np.ndarray) -> str:
    return "\n".join("    " + ", ".join(fmt(a) for a in values[start:start + 6]) + ","
                     for start in range(0, values.size, 6))


def _rows(items) -> str:
    return "\n".join(f"    {tuple(item)!r}," for item in items)


def inert(text: object) -> str:
    """*text* made safe inside a docstring or a comment of the generated script.

    Names come from the user's YAML; written raw, a name holding a triple
    quote or a line break would end the docstring or comment and the rest of
    it would run as code.  Backslashes, quotes, line breaks and every
    non-printable or non-ASCII character are written as escapes (so the text
    reads the same inside the docstring and cannot leave it); values used as
    Python data are written with ``repr`` instead.
    """
    out = []
    for char in str(text):
        if char == "\\":
            out.append("\\\\")
        elif char in "\"'":
            out.append("\\" + char)
        elif char.isascii() and char.isprintable():
            out.append(char)
        else:
            out.append(char.encode("unicode_escape").decode("ascii") if ord(char) > 0x7f or char in "\n\r\t"
                       else f"\\x{ord(char):02x}")
    return "".join(out)


#: Parts of the generated script shared by both domain forms (inserted by ``str.format``).
SCRIPT_READ_ROWS = '''def _read_rows(path, width):
    """Rows of an OpenSees ``-binary`` recorder: *width* native doubles, then a newline byte."""
    with open(path, "rb") as handle:
        raw = handle.read()
    size = 8 * width + 1
    for start in range(0, len(raw) - size + 1, size):
        row = array("d")
        row.frombytes(raw[start:start + 8 * width])
        yield row'''

SCRIPT_IMPORTS = '''import json
import os
import shutil
import sys
import tempfile
import time
from array import array

import openseespy.opensees as ops
'''

SCRIPT_STEPPING = '''        n_steps = int(round(duration / dt))
        started = time.perf_counter()
        status = ops.analyze(n_steps, dt)
        cut_steps = 0
        while status != 0 and ops.getTime() < n_steps * dt - 0.5 * dt:
            # Newton failed: retake that step in 10 sub-steps with line search, then go on.
            cut_steps += 1
            ops.algorithm("NewtonLineSearch")
            status = ops.analyze(10, dt / 10.0)
            ops.algorithm("Newton")
            if status != 0:
                break
            status = ops.analyze(int(round((n_steps * dt - ops.getTime()) / dt)), dt)
        wall = time.perf_counter() - started'''

SCRIPT_MAIN = '''def main(argv=None):
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dt", type=float, default=DT, help="time step, s (default %(default)g)")
    parser.add_argument("--duration", type=float, default=DURATION, help="simulated time, s")
    parser.add_argument("-o", "--output", help="also write the peaks to this JSON file")
    args = parser.parse_args(argv)
    peaks = analyse(args.dt, args.duration)
    text = json.dumps(peaks, indent=1)
    print(text)
    if args.output:
        with open(args.output, "w") as handle:
            handle.write(text + "\\n")
    return 0 if peaks["converged"] else 1


if __name__ == "__main__":
    sys.exit(main())'''

SCRIPT_CONTACT_RECORDERS = '''        if contact_elements:
            ops.recorder("Element", "-binary", force, "-ele", *contact_elements, "basicForce")
        link_elements = [row[0] for row in LINKS]
        link_force = os.path.join(workdir, "link_force.bin")
        if link_elements:
            ops.recorder("Element", "-binary", link_force, "-ele", *link_elements, "basicForce")'''

SCRIPT_CONTACT_PEAKS = '''        nc = len(contact_elements)
        peak_force = [0.0] * nc
        impacts = [0] * nc
        if nc:
            closed = [False] * nc
            for row in _read_rows(force, nc):
                for c in range(nc):
                    f = -row[c]  # compression is negative in OpenSees
                    if f != 0.0 and not closed[c]:
                        impacts[c] += 1
                    closed[c] = f != 0.0
                    if f > peak_force[c]:
                        peak_force[c] = f
        peak_link = [0.0] * len(link_elements)
        if link_elements:
            for row in _read_rows(link_force, len(link_elements)):
                for c in range(len(link_elements)):
                    peak_link[c] = max(peak_link[c], abs(row[c]))'''

SCRIPT_SOLUTION = '''        # Unbalanced force below 1e-12 of the stiffest storey's force at 1 m: round-off level,
        # and a linear step converges in one Newton iteration.
        ops.test("NormUnbalance", UNBALANCE_TOLERANCE, 25)
        ops.algorithm("Newton")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")'''

SCRIPT_ANALYSE_HEAD = '''    """Run the analysis; return the peaks and the solver wall time.

    Peaks are read at every committed step; an impact is a step on which a
    gap element carries force after a step on which it carried none.
    """
    own = workdir is None
    workdir = tempfile.mkdtemp(prefix="pounding-opensees-") if own else workdir
    try:
        build(os.path.join(workdir, "opensees.log"))'''

SCRIPT_RUN_FACTS = '''            "dt": dt,
            "duration": duration,
            "end_time": end,
            "converged": status == 0,
            "cut_steps": cut_steps,
            "wall_time": wall,'''

SCRIPT_RESULTS_TAIL = '''            "contact": [row[4] for row in CONTACTS],
            "peak_contact_force": peak_force,
            "impact_count": impacts,
            "link": [row[4] for row in LINKS],
            "peak_link_force": peak_link,
        }
    finally:
        if own:
            shutil.rmtree(workdir, ignore_errors=True)'''

#: The notes, imports and constants at the top of both forms (formatted with the header's fields).
SCRIPT_CONSTANTS = '''{notes}
{imports}
MODEL_NAME = {name_literal}
UNBALANCE_TOLERANCE = {unbalance}  # N
DT = {dt}
DURATION = {duration}
RECORD_NAME = {record_name_literal}
RECORD_DT = {record_dt}'''

#: The shared parts by their template field names.
SCRIPT_PARTS = {"imports": SCRIPT_IMPORTS, "read_rows": SCRIPT_READ_ROWS, "stepping": SCRIPT_STEPPING,
                "main": SCRIPT_MAIN, "contact_recorders": SCRIPT_CONTACT_RECORDERS, "contact_peaks": SCRIPT_CONTACT_PEAKS,
                "solution": SCRIPT_SOLUTION, "analyse_head": SCRIPT_ANALYSE_HEAD, "run_facts": SCRIPT_RUN_FACTS,
                "results_tail": SCRIPT_RESULTS_TAIL}


AXIS_TEMPLATE = '''#!/usr/bin/env python3
"""OpenSeesPy model '{name}' exported by pounding {version}.

Run:   python THIS.py [--dt DT] [-o peaks.json]
Import: analyse(dt=..., duration=...) -> dict of peaks (results-schema names).

Units SI (kg, N/m, m, s).  Model:
{summary}
Record: {record_name} x {record_scale}, {n_samples} samples at {record_dt} s (m/s^2),
simulated for {duration} s.
"""
{constants}
RECORD = [  # ground acceleration, m/s^2, linear between samples, 0 after the last
{record}
]

# (node, floor label, mass kg)
FLOORS = [
{floors}
]
# fixed ground node of each building
GROUNDS = {grounds}
# 1: every node one DOF along x (model basic -ndm 1 -ndf 1).  3: the plane (x, z) with rotations, since a
# base mat rocks: every node at its elevation (ELEVATION, m; 0 if absent), vertical DOF fixed; storeys and
# dashpots are twoNodeLink elements whose shear deformation is x_j - x_i - (z_j - z_i) theta of their end
# nodes, which rotate with their base mat (equalDOF) or not at all (a fixed base)
NDF = {ndf}
ELEVATION = {elevation}
# base mats on sway and rocking springs and dashpots (Elastic E, eta: linear), a zeroLength to the ground node:
# (base node, ground node, building, m_b kg, I_b kg m^2, K_x N/m, c_x N s/m, K_theta N m/rad,
# c_theta N m s/rad, floor nodes that rotate with the base)
FOUNDATIONS = [
{foundations}
]
FOUNDATION_TAG_OFFSET = 30_000_000  # tags of a base mat's zeroLength and materials
# (element, node below, node, storey stiffness N/m, storey label, storey height m, material args)
STOREYS = [
{storeys}
]
# P-Delta (leaning column): (element, node below, node, -P/h N/m, storey label), no Rayleigh damping
P_DELTA = [
{p_delta}
]
# Rayleigh-damped buildings: (name, a0 1/s, a1 s on the initial stiffness, storey elements, nodes)
RAYLEIGH = [
{buildings}
]
# linear dashpots (a modal damping matrix; the Rayleigh part a storey's initial tangent misses; with NDF 3, the
# a0 M part of Rayleigh damping, from the building's base to each floor: on the deformations only):
# (element, node i, node j, c N s/m)
DASHPOTS = [
{dashpots}
]
# gap elements: (element, left floor node, right floor node, material args, contact label)
CONTACTS = [
{contacts}
]
# links (permanent dampers, no gap): (element, left floor node, right floor node,
# materials [[tag, type, args...], ...] the last of which is the element's, link label)
LINKS = [
{links}
]


def _node(tag, fixed, rocks):
    """Node *tag* at its elevation: fixed, or free along x (and, if it *rocks*, in rotation)."""
    if NDF == 1:
        ops.node(tag, 0.0)
        if fixed:
            ops.fix(tag, 1)
        return
    ops.node(tag, 0.0, ELEVATION.get(tag, 0.0))
    ops.fix(tag, int(fixed), 1, int(not rocks))


def _storey_element(ele, i, j, damped):
    """A spring or dashpot on material *ele* between nodes *i* (below) and *j*, Rayleigh-damped if *damped*."""
    if NDF == 1:
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", int(damped))
    else:  # shear (local y) deformation: -(x_j - x_i - (z_j - z_i) theta), the sign OpenSees' local y gives
        ops.element("twoNodeLink", ele, i, j, "-mat", ele, "-dir", 2, *(["-doRayleigh"] if damped else []))


def build(log_file=None):
    """Create the OpenSees domain (wipes any previous one)."""
    ops.wipe()
    if log_file is not None:
        ops.logFile(log_file, "-noEcho")  # Hertzdamp prints one line per impact
    ops.model("basic", "-ndm", min(NDF, 2), "-ndf", NDF)
    rocking = {{node for row in FOUNDATIONS for node in [row[0], *row[9]]}}
    for tag in GROUNDS:
        _node(tag, True, False)
    for tag, _label, mass in FLOORS:
        _node(tag, False, tag in rocking)
        ops.mass(tag, mass, *[0.0] * (NDF - 1))
    for base, ground, _name, m_b, i_b, k_x, c_x, k_t, c_t, floors in FOUNDATIONS:
        _node(base, False, True)
        ops.mass(base, m_b, 0.0, i_b)
        tag = FOUNDATION_TAG_OFFSET + 2 * base  # the zeroLength and its sway material; the rocking material tag + 1
        ops.uniaxialMaterial("Elastic", tag, k_x, c_x)
        ops.uniaxialMaterial("Elastic", tag + 1, k_t, c_t)
        ops.element("zeroLength", tag, ground, base, "-mat", tag, tag + 1, "-dir", 1, 3,
                    "-doRayleigh", 0)
        for floor in floors:
            ops.equalDOF(base, floor, 3)
    for ele, i, j, _k, _label, _h, material in STOREYS:
        ops.uniaxialMaterial(material[0], ele, *material[1:])
        _storey_element(ele, i, j, True)
    for ele, i, j, k, _label in P_DELTA:
        ops.uniaxialMaterial("Elastic", ele, k)
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", 0)
    for ele, i, j, c in DASHPOTS:
        ops.uniaxialMaterial("Elastic", ele, 0.0, c)
        _storey_element(ele, i, j, False)
    for ele, i, j, material, _label in CONTACTS:
        ops.uniaxialMaterial(material[0], ele, *material[1:])
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", 0)
    for ele, i, j, materials, _label in LINKS:
        for tag, kind, *args in materials:
            ops.uniaxialMaterial(kind, tag, *args)
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", 0)
    for region, (_name, a0, a1, elements, nodes) in enumerate(RAYLEIGH, start=1):
        # Each building its own a0 (on its nodes' masses) and a1 (on its storeys' initial stiffness:
        # alphaM betaK betaKinit betaKcomm, so a yielding storey keeps its elastic damping).
        ops.region(region, "-ele", *elements, "-rayleigh", a0, 0.0, a1, 0.0)
    ops.timeSeries("Path", 1, "-dt", RECORD_DT, "-values", *RECORD, "-factor", 1.0)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)


{read_rows}


def analyse(dt=DT, duration=DURATION, workdir=None):
{analyse_head}
        floor_nodes = [tag for tag, _l, _m in FLOORS]
        storey_elements = [row[0] for row in STOREYS]
        contact_elements = [row[0] for row in CONTACTS]
        disp = os.path.join(workdir, "disp.env")
        drift = os.path.join(workdir, "drift.env")
        force = os.path.join(workdir, "contact_force.bin")
        ops.recorder("EnvelopeNode", "-file", disp, "-precision", 16, "-node", *floor_nodes, "-dof", 1, "disp")
        ops.recorder("EnvelopeElement", "-file", drift, "-precision", 16, "-ele", *storey_elements,
                     "deformation")
{contact_recorders}
        base_nodes = [row[0] for row in FOUNDATIONS]
        base = os.path.join(workdir, "base.env")
        if base_nodes:
            ops.recorder("EnvelopeNode", "-file", base, "-precision", 16, "-node", *base_nodes, "-dof", 1, 3, "disp")
        ops.constraints("Plain" if NDF == 1 else "Transformation")  # equalDOF: the floors rotate with their base
        ops.numberer("RCM")
        ops.system("BandGeneral")
{solution}

{stepping}
        end = ops.getTime()
        ops.wipe()  # flushes and closes the recorders

        with open(disp) as handle:
            env = [[float(x) for x in line.split()] for line in handle if line.strip()]
        peak_u = env[2]
        with open(drift) as handle:
            env = [[float(x) for x in line.split()] for line in handle if line.strip()]
        peak_drift = env[2]
        peak_base = [0.0] * (2 * len(base_nodes))
        if base_nodes:
            with open(base) as handle:
                peak_base = [[float(x) for x in line.split()] for line in handle if line.strip()][2]
{contact_peaks}
        return {{
            "model": MODEL_NAME,
            "record": RECORD_NAME,
            "simulator": "OpenSeesPy Newmark(1/2, 1/4) + Newton",
{run_facts}
            "floor": [row[1] for row in FLOORS],
            "peak_displacement": peak_u,
            "storey": [row[4] for row in STOREYS],
            "peak_drift_ratio": [d / row[5] for d, row in zip(peak_drift, STOREYS)],
            "foundation": [row[2] for row in FOUNDATIONS],
            "peak_base_sway": peak_base[0::2],
            "peak_base_rocking": peak_base[1::2],
{results_tail}


{main}
'''


DIAPHRAGM_TEMPLATE = '''#!/usr/bin/env python3
"""OpenSeesPy model '{name}' exported by pounding {version} (rigid diaphragms, 3 DOF per floor).

Run:   python THIS.py [--dt DT] [-o peaks.json]
Import: analyse(dt=..., duration=...) -> dict of peaks (results-schema names).

Units SI (kg, N/m, m, s).  Model:
{summary}
Ground: {record_name}, two components a_gx, a_gy (angle {angle} deg applied), {n_samples} samples at {record_dt} s
(m/s^2), simulated for {duration} s.
"""
{constants}
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
# planes: (element, node below, node, direction 1=x 2=y, stiffness N/m, plane label, storey label, storey height m,
# material args (those of a planar storey of the same hysteresis), initial tangent N/m)
PLANES = [
{planes}
]
# P-Delta (leaning column at the weight's centroid), no Rayleigh damping:
# (element, node below, node, directions, [k_x, k_y N/m, k_theta N m], storey label)
P_DELTA = [
{p_delta}
]
# Rayleigh damping per building: (name, a0 1/s on the masters, a1 s on the planes' initial stiffness, planes, masters)
RAYLEIGH = [
{rayleigh}
]
# contact points: (element, low-side node, high-side node, material args, contact label, normal direction)
CONTACTS = [
{contacts}
]
# links (permanent dampers, no gap): (element, low-side node, high-side node,
# materials [[tag, type, args...], ...] the last of which is the element's, link label, normal direction)
LINKS = [
{links}
]
# outline corners (diaphragm slaves): (node, corner label)
CORNERS = [
{corners}
]
# Modal damping (empty: none): one ratio per mode of the whole domain, in OpenSees' ascending order of omega^2
# (every building's 3n modes merged; 0 for the modes of a Rayleigh-damped building, damped by its regions),
# and the omega^2 (1/s^2) the exporter found for them, which OpenSees' eigen analysis must reproduce.
MODAL_RATIOS = {modal_ratios}
MODAL_OMEGA2 = {modal_omega2}
REPEATED_FREQUENCY = {repeated}  # the exporter refused modes closer than this (relative, in omega^2) with other ratios
EIGEN_TAG_OFFSET = {eigen_offset}  # tags of the planes' elastic stand-ins during the eigen analysis
P_DELTA_TAG_OFFSET = 10_000_000  # tags of the P-Delta springs' materials: this offset + 3 element + direction
# FullGeneral with modal damping: its matrix couples every floor of a building, and BandGeneral keeps only the
# band of the elements' graph
SYSTEM = {system}


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
    if MODAL_RATIOS:
        modal_damping()
    for ele, i, j, direction, _k, _label, _storey, _h, material, _k0 in PLANES:
        ops.uniaxialMaterial(material[0], ele, *material[1:])
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", direction, "-doRayleigh", 1)
    for ele, i, j, directions, ks, _label in P_DELTA:
        tags = [P_DELTA_TAG_OFFSET + 3 * ele + m for m in range(len(ks))]
        for tag, k in zip(tags, ks):
            ops.uniaxialMaterial("Elastic", tag, k)
        ops.element("zeroLength", ele, i, j, "-mat", *tags, "-dir", *directions, "-doRayleigh", 0)
    for ele, i, j, material, _label, direction in CONTACTS:
        ops.uniaxialMaterial(material[0], ele, *material[1:])
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", direction, "-doRayleigh", 0)
    for ele, i, j, materials, _label, direction in LINKS:
        for tag, kind, *args in materials:
            ops.uniaxialMaterial(kind, tag, *args)
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", direction, "-doRayleigh", 0)
    for index, (_name, a0, a1, elements, masters) in enumerate(RAYLEIGH):
        # a0 on the masters' masses (m, m, I), a1 on the planes' initial stiffness (betaKinit)
        ops.region(2 * index + 1, "-nodeOnly", *masters, "-rayleigh", a0, 0.0, 0.0, 0.0)
        ops.region(2 * index + 2, "-eleOnly", *elements, "-rayleigh", 0.0, 0.0, a1, 0.0)
    ops.timeSeries("Path", 1, "-dt", RECORD_DT, "-values", *RECORD_X, "-factor", 1.0)
    ops.timeSeries("Path", 2, "-dt", RECORD_DT, "-values", *RECORD_Y, "-factor", 1.0)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.pattern("UniformExcitation", 2, 2, "-accel", 2)


def modal_damping():
    """OpenSees' modalDamping with our modes and ratios: after the nodes and diaphragms, before any element.

    The eigen analysis sees the planes as Elastic stand-ins of their initial tangent only (the stiffness our
    modes are of: no P-Delta, no contact, and no hysteretic material's own idea of its tangent), all N modes of
    the domain (-fullGenLapack: ARPACK finds at most N - 1); then the stand-ins go.  OpenSees damps with
    sum 2 zeta omega (M phi)(M phi)^T over the domain's mass-normalised modes, in the force and the tangent.
    The masters have the highest node tags: OpenSees reads the modal vectors DOF group by DOF group in node
    order, and a diaphragm slave's group writes its node's unfilled rows over its master's equations.
    """
    stand_ins = []
    for ele, i, j, direction, _k, _label, _storey, _h, _material, k0 in PLANES:
        tag = EIGEN_TAG_OFFSET + ele
        ops.uniaxialMaterial("Elastic", tag, k0)
        ops.element("zeroLength", tag, i, j, "-mat", tag, "-dir", direction)
        stand_ins.append(tag)
    omega2 = ops.eigen("-fullGenLapack", len(MODAL_RATIOS))
    worst = max(abs(a - b) / b for a, b in zip(omega2, MODAL_OMEGA2))
    if len(omega2) != len(MODAL_OMEGA2) or worst > 0.1 * REPEATED_FREQUENCY:
        raise SystemExit(f"OpenSees' eigen analysis does not reproduce the modes the damping ratios were ordered by "
                         f"(largest relative difference of omega^2 {{worst:.3g}})")
    ops.modalDamping(*MODAL_RATIOS)
    for tag in stand_ins:
        ops.remove("ele", tag)


{read_rows}


def _envelope(path):
    """The peak |value| row (the third) of an Envelope recorder's file."""
    with open(path) as handle:
        return [[float(x) for x in line.split()] for line in handle if line.strip()][2]


def _storey_peaks(peak_drift):
    """(storey labels, each storey's peak |drift ratio| over its planes) from the planes' peak drifts (m)."""
    storeys, peaks = [], []
    for row, drift in zip(PLANES, peak_drift):
        if row[6] not in storeys:
            storeys.append(row[6])
            peaks.append(0.0)
        peaks[storeys.index(row[6])] = max(peaks[storeys.index(row[6])], drift / row[7])
    return storeys, peaks


def analyse(dt=DT, duration=DURATION, workdir=None):
{analyse_head}
        masters = [row[0] for row in MASTERS]
        corner_nodes = [row[0] for row in CORNERS]
        plane_elements = [row[0] for row in PLANES]
        contact_elements = [row[0] for row in CONTACTS]
        disp = os.path.join(workdir, "disp.env")
        corner = os.path.join(workdir, "corner.env")
        drift = os.path.join(workdir, "drift.env")
        force = os.path.join(workdir, "contact_force.bin")
        ops.recorder("EnvelopeNode", "-file", disp, "-precision", 16, "-node", *masters, "-dof", 1, 2, 6, "disp")
        ops.recorder("EnvelopeNode", "-file", corner, "-precision", 16, "-node", *corner_nodes, "-dof", 1, 2,
                     "disp")
        ops.recorder("EnvelopeElement", "-file", drift, "-precision", 16, "-ele", *plane_elements,
                     "deformation")
{contact_recorders}
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system(SYSTEM)
{solution}

{stepping}
        end = ops.getTime()
        ops.wipe()  # flushes and closes the recorders

        u = _envelope(disp)
        corner_u = _envelope(corner)
        peak_drift = _envelope(drift)
        storeys, peak_ratio = _storey_peaks(peak_drift)
{contact_peaks}
        return {{
            "model": MODEL_NAME,
            "record": RECORD_NAME,
            "simulator": "OpenSeesPy Newmark(1/2, 1/4) + Newton, rigid diaphragms",
{run_facts}
            "floor": [row[1] for row in MASTERS],
            "peak_displacement": [u[3 * i:3 * i + 2] for i in range(len(masters))],
            "peak_rotation": [u[3 * i + 2] for i in range(len(masters))],
            "corner": [row[1] for row in CORNERS],
            "peak_corner_displacement": [corner_u[2 * i:2 * i + 2] for i in range(len(corner_nodes))],
            "plane": [row[5] for row in PLANES],
            "peak_plane_drift": peak_drift,
            "storey": storeys,
            "peak_drift_ratio": peak_ratio,
{results_tail}


{main}
'''


def _header(model, domain, ground: ScriptGround, dt: float, notes: list[str]) -> dict:
    """The template fields both forms share: names, notes, summary, time steps, the tolerance."""
    fields = dict(version=__version__, name=inert(model.name), name_literal=repr(str(model.name)),
                  summary="\n".join("#   " + inert(line) for line in model.summary_lines()),
                  notes="\n".join("# NOTE: " + inert(n) for n in notes), record_name=inert(ground.name),
                  record_name_literal=repr(str(ground.name)), record_dt=fmt(ground.time_step),
                  duration=fmt(ground.end_time), dt=fmt(dt), n_samples=ground.components[0].size,
                  unbalance=fmt(1e-12 * max(s.stiffness for s in domain.springs)), **SCRIPT_PARTS)
    return {**fields, "constants": SCRIPT_CONSTANTS.format(**fields)}


def axis_script(model, domain, ground: ScriptGround, dt: float, notes: list[str]) -> str:
    """The script of a domain whose floors have one DOF (module docstring); *ground* along x.

    Parameters
    ----------
    model : Model
    domain : Domain
        Its nodes and elements (:func:`pounding.export.opensees_elements.build_domain`).
    ground : ScriptGround
    dt : float
        OpenSees time step, s.
    notes : list of str
        What the script cannot reproduce exactly, written at its top.
    """
    nodes = domain.nodes
    return AXIS_TEMPLATE.format(
        **_header(model, domain, ground, dt, notes), record_scale=fmt(ground.scale),
        record=_samples(ground.components[0]), floors=_rows(nodes.floors), grounds=repr(nodes.grounds),
        storeys=_rows((s.element, s.below, s.node, s.stiffness, s.storey, s.height, s.material)
                      for s in domain.springs),
        p_delta=_rows((p.element, p.below, p.node, p.stiffness[0], p.storey) for p in domain.p_delta),
        buildings=_rows(domain.rayleigh), dashpots=_rows(domain.dashpots), ndf=nodes.ndf,
        elevation=repr(nodes.elevation if nodes.ndf == 3 else {}), foundations=_rows(domain.foundations),
        contacts=_rows(c[:5] for c in domain.contacts), links=_rows(k[:5] for k in domain.links))


def diaphragm_script(model, domain, ground: ScriptGround, dt: float, notes: list[str], *, eigen_offset: int,
                     repeated: float) -> str:
    """The script of a domain whose floors are rigid diaphragms in plan (module docstring).

    Parameters as :func:`axis_script`; *ground* has its components along x and y; *eigen_offset* is the tag
    offset of the planes' stand-ins in the eigen analysis and *repeated* the relative ω² within which modes
    share a frequency (:mod:`pounding.export.opensees_damping`).
    """
    nodes = domain.nodes
    return DIAPHRAGM_TEMPLATE.format(
        **_header(model, domain, ground, dt, notes), angle=fmt(ground.angle or 0.0),
        record_x=_samples(ground.components[0]),
        record_y=_samples(ground.components[1] if len(ground.components) > 1 else 0.0 * ground.components[0]),
        masters=_rows(nodes.masters), slaves=_rows(nodes.slaves), fixed=_rows(nodes.fixed_rows),
        planes=_rows(domain.springs), p_delta=_rows(domain.p_delta), rayleigh=_rows(domain.rayleigh),
        contacts=_rows(domain.contacts), links=_rows(domain.links), corners=_rows(domain.corners),
        modal_ratios=repr(domain.modal.ratios), modal_omega2=repr(domain.modal.omega2),
        system=repr("FullGeneral" if domain.modal.ratios else "BandGeneral"), eigen_offset=eigen_offset,
        repeated=fmt(repeated))
