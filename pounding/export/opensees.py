"""Export a model to a standalone OpenSeesPy script (the peer simulator).

``pounding export opensees MODEL.yaml [--record SPEC] [--dt 1e-4] [--xi NAME] -o model.py``
writes a Python script that builds the same row of shear buildings in
OpenSeesPy and runs it under the same record:

* one node per floor (its mass) and one fixed ground node per building, all
  on one axis (``model basic -ndm 1 -ndf 1``);
* each storey a ``zeroLength`` element with ``-doRayleigh 1`` and the
  storey's material: ``Elastic`` (``k_i``) for an elastic storey,
  ``Steel01(F_y, k_i, α, 0, 1, 0, 1)`` (kinematic hardening, no isotropic
  hardening) for a ``bilinear`` one, ``BoucWen(α, k_i, n, γ/u_yⁿ, β/u_yⁿ, A,
  0, 0, 0)`` for a ``bouc-wen`` one (OpenSees' z is in length units, z_o =
  u_y·z, and in its code ``gamma`` is the constant term and ``beta``
  multiplies sgn(Δε·z): our γ goes to its ``gamma``, our β to its ``beta``;
  its internal Newton tolerance on z_o is set to 1e-12·u_y); ``IMKBilin``,
  ``IMKPeakOriented`` or ``IMKPinching`` for an IMK storey (drift ratios × h,
  OpenSees' Λ = Λ·h; :func:`imk_material`);
* each Rayleigh-damped building gets its own ``a0, a1`` through a ``region``
  holding its storey elements and their nodes, with ``a1`` on the *initial*
  stiffness (``-rayleigh a0 0 a1 0``: the nodes carry ``a0·M``, the storeys
  ``a1·K_init``), as our solver damps on the elastic stiffness; a Bouc–Wen
  storey with A ≠ 1 (initial tangent (α + (1 − α)A)·k, not k) gets a
  parallel dashpot ``a1·(1 − α)(1 − A)·k`` that makes up the difference;
* with ``p_delta: true`` each storey gets a parallel ``zeroLength`` with an
  ``Elastic(−P_i/h_i)`` material (the leaning column's negative geometric
  stiffness, P_i = g Σ_(j≥i) m_j) and ``-doRayleigh 0``, outside the
  Rayleigh region: it adds no damping;
* a building with modal damping gets its dense damping matrix ``C`` as a
  network of linear dashpots (``zeroLength`` + ``Elastic`` with ``E = 0``,
  ``eta = c``, ``-doRayleigh 0``): ``−C_ij`` between floors i and j and the
  row sum ``Σ_j C_ij`` from floor i to the ground, which assembles to ``C``
  exactly;
* each gap element a ``zeroLength`` from the left floor to the right floor
  with ``uniaxialMaterial Hertzdamp Kh xiNorm −gap`` (``xiNorm = p(e)`` of the
  chosen ξ formula) and ``-doRayleigh 0`` (``hertz`` exports as ``xiNorm = 0``,
  ``linear`` as ``ElasticPPGap``, ``bilinear`` as ``ImpactMaterial K1 K2 −δy −gap``,
  the same parallelogram loop; other laws are refused by name in one line);
* each link (``links:``, a permanent damper between two floors) a
  ``zeroLength`` from the left floor to the right floor with ``-doRayleigh 0``
  and the material of its law: ``Viscous(c, 1)`` (linear viscous),
  ``Parallel`` of ``Elastic(k)`` and ``Viscous(c, 1)`` (Kelvin), and
  ``ViscousDamper(k, c, 1)`` (Maxwell: a spring in series with a linear
  dashpot, integrated inside the material by an adaptive Dormand-Prince
  scheme); the peak |force| of each link is recorded as ``peak_link_force``;
* the record as ``timeSeries Path`` + ``pattern UniformExcitation`` (linear
  between samples and zero after the end, as in :func:`pounding.simulate`);
* ``Newmark`` average acceleration (γ = 1/2, β = 1/4), ``Newton`` with an
  unbalanced-force test at 1e-12 of the stiffest storey's force at 1 m, at a
  fixed step ``dt`` (a failed step is retaken in ten sub-steps with line
  search);
* recorders for our results schema's peaks: ``peak_displacement`` (floor),
  ``peak_drift_ratio`` (storey), ``peak_contact_force`` and ``impact_count``
  (contact), labelled as in the results dataset (``A:3``, ``A:1-B:1``),
  printed as JSON and optionally written to a file.

Differences from our solver that remain by construction (with them the
peer converges slowly once impacts start):

* OpenSees' ``Hertzdamp`` fixes ξ from the strain rate at the end of the
  first step inside the gap, not at the located instant of closure, so its
  ξ is slightly too large (the floors have already slowed down);
* it has no ``min_impact_velocity`` floor on v0;
* it never clamps tension: a model with ``tension: clamp`` exports with a
  warning; compare against ``tension: allow`` (:func:`allow_tension`);
* ``ImpactMaterial`` (``bilinear``) updates its force from the last
  committed strain: in the step in which the gap closes the force starts
  from K1 times the whole strain increment, the open part of the step
  included (then capped by the loop's upper line), where our solver starts
  it at the located closure — an overshoot of at most K1 times the open part
  of one step, which vanishes with dt;
* peaks are read at the committed steps and an impact shorter than one step
  can be missed;
* the script always runs to the end: it does not stop at
  ``solver.stop_drift_ratio`` (compare completed runs only).

:func:`run_opensees` runs the generated script in-process and returns the
peaks (the cross-check tests and the benchmarks use it).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

from pounding import __version__
from pounding.errors import PoundingError
from pounding.model.schema import WALL

__all__ = ["opensees_script", "opensees_script_and_notes", "run_opensees", "run_script", "allow_tension",
           "tension_allowed", "inert", "SCRIPT_PARTS", "contact_material", "link_materials", "storey_material",
           "initial_tangent", "imk_material", "IMK_MATERIALS", "LAMBDA_OFF", "BILINEAR_NOTE", "DEFAULT_DT"]

#: Default OpenSees time step, s.
DEFAULT_DT = 1.0e-4


def allow_tension(model):
    """The same model with ``tension: allow`` on every hertz-damp (and kelvin) gap element.

    OpenSees' ``Hertzdamp`` material does not clamp the pull that the damping
    term produces just before separation; a model compared with it must not
    either.
    """
    laws: dict[int, object] = {}
    gaps = tuple(dataclasses.replace(g, law=tension_allowed(g.law, laws)) for g in model.gaps)
    return dataclasses.replace(model, gaps=gaps)


def tension_allowed(law, cache: dict[int, object]):
    """*law* with ``tension: allow`` if it is a hertz-damp or kelvin law that clamps, else *law* itself.

    *cache* (id of a law -> its switched copy) keeps contacts that shared one law sharing one copy.
    """
    from pounding.contact.laws import HertzDamp, Kelvin

    if not isinstance(law, (HertzDamp, Kelvin)) or law.tension == "allow":
        return law
    if id(law) not in cache:
        cache[id(law)] = type(law)(**{**law.model_dump(), "tension": "allow"})
    return cache[id(law)]


def _prepare(model, record=None, xi=None, duration=None):
    """Apply the overrides as :func:`pounding.simulate` does; return (model, record, end_time).

    A record given as a string replaces the model's ``ground_motion.record``
    (processed and scaled as the model says, by :func:`pounding.simulation.record_for`);
    a :class:`~pounding.ground_motion.Record` is used as it is.
    """
    from pounding.records.record import Record
    from pounding.simulation import record_for

    if model.is_multi_support:
        where = f"{model.path}: " if model.path else ""
        raise PoundingError(f"{where}the OpenSees export does not support multi-support excitation (a ground motion "
                            "per building or wave_passage); export the model with one model-level ground_motion "
                            "without wave_passage")
    if xi is not None:
        model = model.with_xi(xi)
    changes = {}
    if isinstance(record, str):
        changes["record"] = record
    if duration is not None:
        changes["duration"] = duration
    if changes:
        model = model.with_ground_motion(**changes)
    motion = record if isinstance(record, Record) else record_for(model)
    end_time = model.ground_motion.duration or motion.duration
    if end_time <= 0.0:
        raise PoundingError(f"record {motion.name}: duration must be > 0 (got {end_time} s)")
    return model, motion, float(end_time)


def contact_material(law, gap: float) -> tuple[list, list[str]]:
    """OpenSees material arguments (after the tag) for one gap element, and warnings."""
    from pounding.contact.laws import Bilinear, Hertz, HertzDamp, Linear

    if isinstance(law, HertzDamp):
        notes = []
        if law.tension == "clamp":
            notes.append("hertz-damp with tension: clamp — OpenSees' Hertzdamp does not clamp the pull "
                         "before separation (it behaves as tension: allow)")
        return ["Hertzdamp", float(law.kh), float(law.p), -float(gap)], notes
    if isinstance(law, Hertz):
        return ["Hertzdamp", float(law.kh), 0.0, -float(gap)], []
    if isinstance(law, Linear):
        # Compression-only elastic gap: ElasticPPGap E Fy gap with a yield force it never reaches.
        return ["ElasticPPGap", float(law.k), -1.0e30, -float(gap)], []
    if isinstance(law, Bilinear):
        # Muthukumar's element is OpenSees' ImpactMaterial K1 K2 δy gap, compression negative: our K2 > 0
        # check (kernel_parameters) first, so a loop that cannot be built is refused as in a run.
        k1, k2, dy = (float(x) for x in law.kernel_parameters(1.0, 1.0)[:3])
        return ["ImpactMaterial", k1, k2, -dy, -float(gap)], [BILINEAR_NOTE]
    raise PoundingError(f"contact law '{law.name}' has no OpenSees counterpart in this exporter "
                        "(supported: hertz-damp, hertz, linear, bilinear)")


#: What an exported ``law: bilinear`` contact does differently (OpenSees' ImpactMaterial::setTrialStrain).
BILINEAR_NOTE = ("bilinear (ImpactMaterial): in the step in which a gap closes, OpenSees starts the force from "
                 "K1 times the whole strain increment of that step, the part still open included (capped by the "
                 "loop's upper line); our solver starts it at the located closure")


#: Material tags of the parts of a Parallel link material: this offset plus 2·element (+1).
_PART_TAG_OFFSET = 1_000_000


def link_materials(law, element: int) -> list[list]:
    """OpenSees materials of one link: ``[tag, type, args...]`` rows, the last one the element's (tag *element*)."""
    from pounding.contact.links import KelvinLink, MaxwellLink, ViscousLink

    if isinstance(law, ViscousLink):
        return [[element, "Viscous", float(law.damping), 1.0]]
    if isinstance(law, KelvinLink):
        spring, dashpot = _PART_TAG_OFFSET + 2 * element, _PART_TAG_OFFSET + 2 * element + 1
        return [[spring, "Elastic", float(law.stiffness)], [dashpot, "Viscous", float(law.damping), 1.0],
                [element, "Parallel", spring, dashpot]]
    if isinstance(law, MaxwellLink):
        # ViscousDamper K Cd alpha: the Maxwell model of a fluid damper (Akcelyan, Lignos & Hikino 2018).
        return [[element, "ViscousDamper", float(law.stiffness), float(law.damping), 1.0]]
    raise PoundingError(f"link law '{law.name}' has no OpenSees counterpart in this exporter "
                        "(supported: viscous, kelvin, maxwell)")


#: OpenSees' Λ (m) written for a mode switched off (Λ = 0 here): OpenSees has no off switch, and with
#: E_t = 1e20·F_y its β = (E_i / (E_t − ΣE))^c is ~1e-20 (Λ = 0 there gives β ≤ 0, clipped to 0 for c = 1
#: but NaN for another c).
LAMBDA_OFF = 1.0e20

#: OpenSees material of each IMK variant (pounding.hysteresis.ImkStorey.variant).
IMK_MATERIALS = {"bilinear": "IMKBilin", "peak-oriented": "IMKPeakOriented", "pinching": "IMKPinching"}


def imk_material(law, stiffness: float, height: float) -> list:
    """``IMKBilin | IMKPeakOriented | IMKPinching`` arguments (after the tag) of an IMK storey.

    ``Ke, then per direction (positive, then negative, magnitudes) Up Upc Uu Fy FcapFy FresFy``
    (m, m, m, N, -, -), then ``Λ_s Λ_c [Λ_a] Λ_k c_s c_c [c_a] c_k D+ D−`` with OpenSees' Λ = E_t / F_y+
    = Λ·h (m; :data:`LAMBDA_OFF` for a mode switched off), then ``κ_f κ_d`` for IMKPinching
    (the argument order of OpenSees' ``OPS_IMKBilin`` / ``OPS_IMKPeakOriented`` / ``OPS_IMKPinching``).
    """
    k = float(stiffness)
    p = law.backbone(k, height)
    fy = p["positive"]["fy"]

    def lam(energy: float) -> float:
        return energy / fy if energy > 0.0 else LAMBDA_OFF

    sides = []
    for sign in ("positive", "negative"):
        d = p[sign]
        sides += [d["up"], d["upc"], d["uu"], d["fy"], d["fcap_ratio"], d["fres_ratio"]]
    rates = [p["positive"]["d"], p["negative"]["d"]]
    if law.variant == "bilinear":
        tail = [lam(p["e_s"]), lam(p["e_c"]), lam(p["e_k"]), p["c_s"], p["c_c"], p["c_k"]] + rates
    else:
        tail = [lam(p["e_s"]), lam(p["e_c"]), lam(p["e_a"]), lam(p["e_k"]), p["c_s"], p["c_c"], p["c_a"],
                p["c_k"]] + rates
        if law.variant == "pinching":
            tail += [p["kappa_f"], p["kappa_d"]]
    return [IMK_MATERIALS[law.variant], k] + [float(x) for x in sides + tail]


def storey_material(law, stiffness: float, height: float) -> list:
    """OpenSees material arguments (after the tag) of a storey: Elastic, Steel01, BoucWen or an IMK material."""
    from pounding.hysteresis import BilinearStorey, BoucWenStorey, ImkStorey

    k = float(stiffness)
    if law is None:
        return ["Elastic", k]
    if isinstance(law, ImkStorey):
        return imk_material(law, k, height)
    fy = float(law.yield_force_for(k, height))
    alpha = float(law.post_yield_ratio)
    if isinstance(law, BilinearStorey):
        # Steel01 Fy E0 b a1 a2 a3 a4: a1 = a3 = 0 switch isotropic hardening off (kinematic only).
        return ["Steel01", fy, k, alpha, 0.0, 1.0, 0.0, 1.0]
    if isinstance(law, BoucWenStorey):
        # BoucWen alpha ko n gamma beta Ao deltaA deltaNu deltaEta tol maxIter.  OpenSees integrates
        # z_o = u_y z (m): dz_o/dε = Ao − |z_o|ⁿ (gamma + beta sgn(dε z_o)), so gamma = γ/u_yⁿ (the
        # constant term) and beta = β/u_yⁿ (the one multiplying the sign); no degradation.
        uy = fy / k
        scale = uy ** float(law.n)
        return ["BoucWen", alpha, k, float(law.n), float(law.gamma) / scale, float(law.beta) / scale,
                float(law.A), 0.0, 0.0, 0.0, 1.0e-12 * uy, 100]
    raise PoundingError(f"storey hysteresis '{law.name}' has no OpenSees counterpart in this exporter "
                        "(supported: bilinear, bouc-wen, imk-bilinear, imk-peak-oriented, imk-pinching)")


def initial_tangent(law, stiffness: float) -> float:
    """The initial tangent (N/m) OpenSees gives the material of :func:`storey_material` (what ``-rayleigh a0 0 a1 0``
    damps): ``(α + (1 − α)A)·k`` for Bouc–Wen, the elastic *stiffness* k (N/m) otherwise."""
    from pounding.hysteresis import BoucWenStorey

    if isinstance(law, BoucWenStorey):
        alpha = float(law.post_yield_ratio)
        return (alpha + (1.0 - alpha) * float(law.A)) * float(stiffness)
    return float(stiffness)


def _fmt(x: float) -> str:
    return repr(float(x))


def opensees_script(model, record=None, *, dt: float = DEFAULT_DT, xi: str | None = None,
                    duration: float | None = None) -> str:
    """Text of a standalone OpenSeesPy script of *model* under *record*.

    Parameters
    ----------
    model : Model
    record : Record or str, optional
        Default: the model's own ground motion.
    dt : float
        OpenSees time step, s.
    xi : str, optional
        ξ formula for every hertz-damp contact (overrides the model).
    duration : float, optional
        Simulated time, s (default: the model's, else the record's duration).

    Returns
    -------
    str
        Python source.  Run it (``python model.py [--dt DT] [-o peaks.json]``)
        or import it and call ``analyse()``, which returns the peaks as a dict.
    """
    return opensees_script_and_notes(model, record, dt=dt, xi=xi, duration=duration)[0]


def opensees_script_and_notes(model, record=None, *, dt: float = DEFAULT_DT, xi: str | None = None,
            duration: float | None = None) -> tuple[str, list[str]]:
    """(script text, notes on what the export cannot reproduce exactly)."""
    if not (dt > 0.0 and math.isfinite(dt)):
        raise PoundingError(f"--dt must be > 0 (got {dt!r})")
    model, motion, end_time = _prepare(model, record, xi, duration)
    notes: list[str] = []

    # ---- nodes and elements ---------------------------------------------------
    node = 0
    element = 0
    floors = []        # (node, label, mass)
    grounds = []       # node
    storeys = []       # (element, node below, node, k, label, height, material args)
    buildings = []     # (name, a0, a1, [storey elements], [nodes]) for Rayleigh buildings
    dashpots = []      # (element, node i, node j, c)
    p_delta = []       # (element, node below, node, -P/h, label)
    floor_node: dict[tuple[int, int], int] = {}
    for b_index, b in enumerate(model.buildings):
        node += 1
        ground = node
        grounds.append(ground)
        nodes = [ground]
        for level in range(1, b.n_floors + 1):
            node += 1
            floor_node[(b_index, level)] = node
            floors.append((node, f"{b.name}:{level}", float(b.mass[level - 1])))
            nodes.append(node)
        elements = []
        for level in range(1, b.n_floors + 1):
            element += 1
            below = ground if level == 1 else floor_node[(b_index, level - 1)]
            k, h, law = float(b.stiffness[level - 1]), float(b.height[level - 1]), b.hysteresis[level - 1]
            storeys.append((element, below, floor_node[(b_index, level)], k, f"{b.name}:{level}", h,
                            storey_material(law, k, h)))
            elements.append(element)
        if b.p_delta:
            for level, kg in enumerate(b.p_delta_stiffness, start=1):
                element += 1
                below = ground if level == 1 else floor_node[(b_index, level - 1)]
                p_delta.append((element, below, floor_node[(b_index, level)], float(kg), f"{b.name}:{level}"))
        if b.damping.kind == "rayleigh":
            a0, a1 = b.rayleigh_coefficients
            buildings.append((b.name, float(a0), float(a1), elements, nodes))
            for level in range(1, b.n_floors + 1):
                # Our solver damps a1·k; OpenSees damps a1·(initial tangent): make up any difference.
                k = float(b.stiffness[level - 1])
                missing = k - initial_tangent(b.hysteresis[level - 1], k)
                if missing != 0.0:
                    element += 1
                    below = ground if level == 1 else floor_node[(b_index, level - 1)]
                    dashpots.append((element, below, floor_node[(b_index, level)], float(a1) * missing))
        else:
            c = np.asarray(b.damping_matrix(), dtype=float)
            n = b.n_floors
            for i in range(n):
                element += 1
                dashpots.append((element, ground, floor_node[(b_index, i + 1)], float(c[i].sum())))
                for j in range(i + 1, n):
                    if c[i, j] != 0.0:
                        element += 1
                        dashpots.append((element, floor_node[(b_index, i + 1)], floor_node[(b_index, j + 1)],
                                         float(-c[i, j])))
    names = [b.name for b in model.buildings]
    contacts = []      # (element, node left, node right, material args, label)
    for g in model.gaps:
        if g.has_column_point:
            raise PoundingError(f"contact {g.label(names)} strikes a column between floors; the OpenSees export "
                                "joins floor nodes only (a column point needs a column element): export a model "
                                "with floor-to-floor and wall contacts only")
        element += 1
        material, warnings = contact_material(g.law, g.gap)
        for w in warnings:
            if w not in notes:
                notes.append(w)
        # A fixed wall is the building's fixed ground node: it moves with the ground, as the wall does.
        left = grounds[g.right] if g.left == WALL else floor_node[(g.left, g.level_left)]
        right = grounds[g.left] if g.right == WALL else floor_node[(g.right, g.level_right)]
        contacts.append((element, left, right, material, g.label(names)))

    links = []         # (element, node left, node right, [[tag, material, args...], ...], link label)
    for link in model.links:
        element += 1
        links.append((element, floor_node[(link.left, link.level_left)], floor_node[(link.right, link.level_right)],
                      link_materials(link.law, element),
                      f"{names[link.left]}:{link.level_left}-{names[link.right]}:{link.level_right}"))

    n_samples = min(motion.acceleration.size, int(math.ceil(end_time / motion.time_step - 1e-9)) + 1)
    samples = motion.acceleration[:n_samples]
    lines = []
    for start in range(0, samples.size, 6):
        lines.append("    " + ", ".join(_fmt(a) for a in samples[start:start + 6]) + ",")
    record_text = "\n".join(lines)

    def rows(items) -> str:
        return "\n".join(f"    {tuple(item)!r}," for item in items)

    if model.solver.stop_drift_ratio:
        notes.append(f"solver.stop_drift_ratio {model.solver.stop_drift_ratio:g}: the OpenSees script does not "
                     "stop at a collapse, it runs to the end (compare completed runs only)")

    summary = "\n".join("#   " + inert(line) for line in model.summary_lines())
    note_text = "\n".join("# NOTE: " + inert(n) for n in notes)
    return _TEMPLATE.format(
        version=__version__, name=inert(model.name), name_literal=repr(str(model.name)), summary=summary,
        notes=note_text, record_name=inert(motion.name), record_name_literal=repr(str(motion.name)), record_scale=_fmt(motion.scale), record_dt=_fmt(motion.time_step),
        duration=_fmt(end_time), dt=_fmt(dt), unbalance=_fmt(1e-12 * max(s[3] for s in storeys)), n_samples=samples.size, record=record_text,
        floors=rows(floors), grounds=repr(grounds), storeys=rows(storeys), buildings=rows(buildings),
        dashpots=rows(dashpots), contacts=rows(contacts), p_delta=rows(p_delta), links=rows(links), **SCRIPT_PARTS,
    ), notes


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


#: Parts of the generated scripts shared by the planar and the plan export (inserted by ``str.format``).
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

#: The shared parts by their template field names.
SCRIPT_PARTS = {"imports": SCRIPT_IMPORTS, "read_rows": SCRIPT_READ_ROWS, "stepping": SCRIPT_STEPPING, "main": SCRIPT_MAIN}


_TEMPLATE = '''#!/usr/bin/env python3
"""OpenSeesPy model '{name}' exported by pounding {version}.

Run:   python THIS.py [--dt DT] [-o peaks.json]
Import: analyse(dt=..., duration=...) -> dict of peaks (results-schema names).

Units SI (kg, N/m, m, s).  Model:
{summary}
Record: {record_name} x {record_scale}, {n_samples} samples at {record_dt} s (m/s^2),
simulated for {duration} s.
"""
{notes}
{imports}
MODEL_NAME = {name_literal}
UNBALANCE_TOLERANCE = {unbalance}  # N
DT = {dt}
DURATION = {duration}
RECORD_NAME = {record_name_literal}
RECORD_DT = {record_dt}
RECORD = [  # ground acceleration, m/s^2, linear between samples, 0 after the last
{record}
]

# (node, floor label, mass kg)
FLOORS = [
{floors}
]
# fixed ground node of each building
GROUNDS = {grounds}
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
# linear dashpots (a modal damping matrix; the Rayleigh part a storey's initial tangent misses):
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


def build(log_file=None):
    """Create the OpenSees domain (wipes any previous one)."""
    ops.wipe()
    if log_file is not None:
        ops.logFile(log_file, "-noEcho")  # Hertzdamp prints one line per impact
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    for tag in GROUNDS:
        ops.node(tag, 0.0)
        ops.fix(tag, 1)
    for tag, _label, mass in FLOORS:
        ops.node(tag, 0.0)
        ops.mass(tag, mass)
    for ele, i, j, _k, _label, _h, material in STOREYS:
        ops.uniaxialMaterial(material[0], ele, *material[1:])
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", 1)
    for ele, i, j, k, _label in P_DELTA:
        ops.uniaxialMaterial("Elastic", ele, k)
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", 0)
    for ele, i, j, c in DASHPOTS:
        ops.uniaxialMaterial("Elastic", ele, 0.0, c)
        ops.element("zeroLength", ele, i, j, "-mat", ele, "-dir", 1, "-doRayleigh", 0)
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
    """Run the analysis; return the peaks and the solver wall time.

    Peaks are read at every committed step; an impact is a step on which a
    gap element carries force after a step on which it carried none.
    """
    own = workdir is None
    workdir = tempfile.mkdtemp(prefix="pounding-opensees-") if own else workdir
    try:
        build(os.path.join(workdir, "opensees.log"))
        floor_nodes = [tag for tag, _l, _m in FLOORS]
        storey_elements = [row[0] for row in STOREYS]
        contact_elements = [row[0] for row in CONTACTS]
        disp = os.path.join(workdir, "disp.env")
        drift = os.path.join(workdir, "drift.env")
        force = os.path.join(workdir, "contact_force.bin")
        ops.recorder("EnvelopeNode", "-file", disp, "-precision", 16, "-node", *floor_nodes, "-dof", 1, "disp")
        ops.recorder("EnvelopeElement", "-file", drift, "-precision", 16, "-ele", *storey_elements,
                     "deformation")
        if contact_elements:
            ops.recorder("Element", "-binary", force, "-ele", *contact_elements, "basicForce")
        link_elements = [row[0] for row in LINKS]
        link_force = os.path.join(workdir, "link_force.bin")
        if link_elements:
            ops.recorder("Element", "-binary", link_force, "-ele", *link_elements, "basicForce")
        ops.constraints("Plain")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        # Unbalanced force below 1e-12 of the stiffest storey's force at 1 m: round-off level,
        # and a linear step converges in one Newton iteration.
        ops.test("NormUnbalance", UNBALANCE_TOLERANCE, 25)
        ops.algorithm("Newton")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")

{stepping}
        end = ops.getTime()
        ops.wipe()  # flushes and closes the recorders

        with open(disp) as handle:
            env = [[float(x) for x in line.split()] for line in handle if line.strip()]
        peak_u = env[2]
        with open(drift) as handle:
            env = [[float(x) for x in line.split()] for line in handle if line.strip()]
        peak_drift = env[2]
        nc = len(contact_elements)
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
                    peak_link[c] = max(peak_link[c], abs(row[c]))
        return {{
            "model": MODEL_NAME,
            "record": RECORD_NAME,
            "simulator": "OpenSeesPy Newmark(1/2, 1/4) + Newton",
            "dt": dt,
            "duration": duration,
            "end_time": end,
            "converged": status == 0,
            "cut_steps": cut_steps,
            "wall_time": wall,
            "floor": [row[1] for row in FLOORS],
            "peak_displacement": peak_u,
            "storey": [row[4] for row in STOREYS],
            "peak_drift_ratio": [d / row[5] for d, row in zip(peak_drift, STOREYS)],
            "contact": [row[4] for row in CONTACTS],
            "peak_contact_force": peak_force,
            "impact_count": impacts,
            "link": [row[4] for row in LINKS],
            "peak_link_force": peak_link,
        }}
    finally:
        if own:
            shutil.rmtree(workdir, ignore_errors=True)


{main}
'''


def run_opensees(model, record=None, *, dt: float = DEFAULT_DT, xi: str | None = None,
                 duration: float | None = None) -> dict:
    """Export *model* and run the script in a child Python process; return its peaks.

    The child keeps OpenSees' global state (and the "Process 0 Terminating"
    line OpenSees prints at interpreter exit) out of the calling process.

    Returns
    -------
    dict
        ``floor``/``peak_displacement`` (m), ``storey``/``peak_drift_ratio``,
        ``contact``/``peak_contact_force`` (N)/``impact_count``, ``link``/``peak_link_force`` (N), labelled as
        in the results dataset, plus ``wall_time`` (s, the ``analyze`` calls
        only), ``converged`` and ``dt``.

    Raises
    ------
    PoundingError
        If OpenSeesPy is not installed, the model cannot be exported or the
        script fails.
    """
    source, _notes = opensees_script_and_notes(model, record, dt=dt, xi=xi, duration=duration)
    return run_script(source, model.name)


def run_script(source: str, name: str) -> dict:
    """Run an exported OpenSeesPy script (*source*) in a child Python process; return the peaks it writes.

    *name* (the model's) labels a failure.
    """
    import importlib.util
    import json
    import subprocess
    import tempfile

    if importlib.util.find_spec("openseespy") is None:  # pragma: no cover - depends on the environment
        raise PoundingError("OpenSeesPy is not available; pip install openseespy")
    with tempfile.TemporaryDirectory(prefix="pounding-opensees-") as folder:
        script = Path(folder) / "model_opensees.py"  # not the model's name: it may hold '/' or '..'
        peaks_file = Path(folder) / "peaks.json"
        script.write_text(source, encoding="utf-8")
        done = subprocess.run([sys.executable, str(script), "-o", str(peaks_file)], capture_output=True,
                              text=True, cwd=folder)
        if not peaks_file.exists():
            # OpenSees prints "Process 0 Terminating" as the interpreter exits: the script's own last word is before
            last = ([line for line in done.stderr.splitlines() if line.strip() and "Process 0 Terminating" not in line]
                    or ["no output"])[-1]
            raise PoundingError(f"the OpenSees script for {name} failed (exit {done.returncode}): {last}")
        return json.loads(peaks_file.read_text(encoding="utf-8"))
