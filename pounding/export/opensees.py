"""Export a model to a standalone OpenSeesPy script (the peer simulator).

``pounding export opensees MODEL.yaml [--record SPEC] [--dt 1e-4] [--xi NAME] [--duration T] -o model.py``
writes a Python script that builds the same structure in OpenSeesPy, runs it under the same
ground motion and prints the peaks under the run archive's names.  One builder reads the
description (:class:`pounding.model.model.Model`) for every model; what differs is in the data:

* **floors** (:mod:`pounding.export.opensees_elements`): a floor with one DOF is one node on an
  axis (``-ndm 1 -ndf 1``), a floor in plan a rigid diaphragm with its master at the centre of
  mass (``-ndm 3 -ndf 6``); every plane (a planar storey is one plane along x) is a ``zeroLength``
  on its line's drift with the storey's material (:mod:`pounding.export.opensees_materials`:
  ``Elastic``, ``Steel01``, ``BoucWen``, ``IMKBilin`` / ``IMKPeakOriented`` / ``IMKPinching``);
  P-Delta a leaning column's negative springs at the weight's centroid, undamped;
* **founded buildings** (:mod:`pounding.export.opensees_elements`, docs/foundations.md): the domain
  is the plane (x, z) with rotations (``-ndm 2 -ndf 3``); a base mat node on a ``zeroLength`` to
  its ground node with ``Elastic(K, c)`` sway and rocking, the floors at their elevations turning
  with it (``equalDOF``), storeys and dashpots as ``twoNodeLink`` shear springs (deformation
  ``x_j − x_i − (z_j − z_i) θ_b``), Rayleigh's a0·M as dashpots a0·m_i on the floors' deformations:
  the damping is ``Tᵀ C_fixed T + diag(c_x, c_θ)`` exactly;
* **contact points and links** (``Model.gaps``, ``Model.links``): a ``zeroLength`` along the
  ``normal`` between the two floors' nodes at the ``point`` (a wall: a fixed node), with
  ``Hertzdamp`` / ``ElasticPPGap`` / ``ImpactMaterial`` for contacts and ``Viscous`` /
  ``Parallel`` / ``ViscousDamper`` for links;
* **damping** (:mod:`pounding.export.opensees_damping`): Rayleigh regions on the initial tangent;
  modal damping as a dashpot network (floors with one DOF) or OpenSees' ``modalDamping`` (in plan);
* **ground** (``ground_motion``): the record along x, or the two components along x and y with
  the angle applied, as ``timeSeries Path`` + ``pattern UniformExcitation`` (linear between
  samples and zero after the end, as in :func:`pounding.simulate`);
* Newmark average acceleration (γ = 1/2, β = 1/4) and Newton at a fixed step ``dt``, with an
  unbalanced-force test at 1e-12 of the stiffest spring's force at 1 m (a failed step is retaken
  in ten sub-steps with line search); the peaks are read at the committed steps.

Refused in one line, each for a reason (:func:`export_refusal` and the material functions):

* multi-support excitation (a record per building, a wave passage): it needs OpenSees'
  ``MultipleSupport`` pattern with each support's ground displacement, and the export writes one
  ``UniformExcitation`` that moves every support alike;
* friction on a face: OpenSees' frictional contact elements take their normal force from their
  own penalty spring, not from the Hertz material beside them;
* a contact at a column point: it moves as a weighted mean of two floors, and a shear model has
  no column element to put that node on;
* contact laws without an OpenSees material (stereo-mechanical, kelvin, jankowski, bumper; the
  reasons in :data:`pounding.export.opensees_materials.CONTACT_LAWS_WITHOUT_MATERIAL`);
* modal damping in plan where two modes share a frequency with different ratios (OpenSees'
  ``modalDamping`` sets one ratio per mode in its eigen solver's order, and the eigenvectors of a
  repeated frequency are that solver's choice).

What remains different by construction is written as notes at the script's top: OpenSees'
``Hertzdamp`` fixes ξ from the strain rate at the end of the first step inside the gap (not at
the located closure) and never clamps the pull (compare with ``tension: allow``,
:func:`allow_tension`); ``ImpactMaterial`` starts the force of a closing step from the whole
strain increment; ``BoucWen`` integrates z by backward Euler (first order in dt); an impact
shorter than one step can be missed; the script runs to the end where our run stops at a
collapse.  :func:`run_opensees` runs a script in a child process and returns its peaks.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from pounding.errors import PoundingError
from pounding.export.opensees_damping import EIGEN_TAG_OFFSET, REPEATED_FREQUENCY, repeated_frequency
from pounding.export.opensees_elements import build_domain
from pounding.export.opensees_materials import storey_material
from pounding.export.opensees_text import ScriptGround, axis_script, diaphragm_script, inert

__all__ = ["opensees_script", "opensees_script_and_notes", "run_opensees", "run_script", "export_refusal",
           "allow_tension", "tension_allowed", "script_ground", "inert", "storey_material", "DEFAULT_DT"]

#: Default OpenSees time step, s.
DEFAULT_DT = 1.0e-4


def allow_tension(model):
    """The same model with ``tension: allow`` on every hertz-damp (and kelvin) contact.

    OpenSees' ``Hertzdamp`` material does not clamp the pull that the damping term produces just before
    separation; a model compared with it must not either.  The contacts that shared one law share one copy.
    """
    cache: dict[int, object] = {}
    return model.with_laws(lambda law: tension_allowed(law, cache))


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


def export_refusal(model) -> str | None:
    """Why *model* cannot be exported to OpenSees (one line naming the reason), or None.

    The contact, link and storey laws are checked as their materials are written
    (:mod:`pounding.export.opensees_materials`).
    """
    names = [b.name for b in model.buildings]
    if len({b.dofs_per_floor for b in model.buildings}) > 1:
        return ("the OpenSees export writes floors with one DOF or floors in plan, not both in one domain (a floor "
                "with one DOF has no u_y or rotation for a diaphragm's contact to act on)")
    if model.is_multi_support:
        return ("the OpenSees export does not write multi-support excitation (a record per building or a wave "
                "passage): it needs OpenSees' MultipleSupport pattern with each support's ground displacement, "
                "and the export writes one UniformExcitation that moves every support alike; export the model "
                "with one model-level ground_motion without wave_passage")
    friction = next((f for f in model.faces if f.friction), None)
    if friction is not None:
        return (f"contact {friction.label(names)}: the OpenSees export does not write friction (OpenSees' frictional "
                "contact elements take their normal force from their own penalty spring, not from the Hertz "
                "material beside them); export the model without friction")
    column = next((g for g in model.gaps if g.has_column_point), None)
    if column is not None:
        return (f"contact {column.label(names)} strikes a column between floors: a column point moves as a weighted "
                "mean of two floors, and OpenSees joins nodes (the shear model has no column element to put a node "
                "on); export a model with floor-to-floor and wall contacts only")
    return repeated_frequency(model)


def _end_samples(size: int, end_time: float, step: float) -> int:
    """The samples (of *size*) that reach *end_time* (s) at *step* (s)."""
    return min(size, int(math.ceil(end_time / step - 1e-9)) + 1)


def script_ground(model, record=None, *, where: str = "yaml") -> ScriptGround:
    """The ground motion of *model*'s script: its record along x, or its two components along x and y.

    *record*: a loaded :class:`~pounding.records.record.Record` instead of the model's (one component only).

    Raises
    ------
    PoundingError
        A loaded record for a model with two components, or a duration that is not > 0 (one line).
    """
    from pounding.records.record import Record
    from pounding.simulation import record_for, support_motions

    gm = model.ground_motion
    if gm.two_components:
        supports = support_motions(model, record, where=where)
        step, end = supports.time_step, supports.end_time
        rows = [supports.rows[supports.building_row[0]], supports.rows[supports.building_row_y[0]]]
        n = _end_samples(rows[0].size, end, step)
        name = gm.record if gm.record is not None else " + ".join(
            f"{c.record} along {axis}" for axis, c in (("x", gm.x), ("y", gm.y)) if c is not None)
        ground = ScriptGround((rows[0][:n], rows[1][:n]), float(step), float(end), str(name), angle=float(gm.angle))
    else:
        motion = record if isinstance(record, Record) else record_for(model, where=where)
        end = float(gm.duration or motion.duration)
        n = _end_samples(motion.acceleration.size, end, motion.time_step)
        ground = ScriptGround((motion.acceleration[:n],), float(motion.time_step), end, str(motion.name),
                              float(motion.scale))
    if ground.end_time <= 0.0:
        raise PoundingError(f"record {ground.name}: duration must be > 0 (got {ground.end_time} s)")
    return ground


def _collapse_note(model) -> list[str]:
    """The note that the script runs to the end, for a model whose run can stop at a collapse."""
    from pounding.hysteresis import ImkStorey

    planes = [p for b in model.buildings for s in b.storeys for p in s.planes]
    own = next(((b.name, b.collapse_drift_ratio) for b in model.buildings if b.collapse_drift_ratio), None)
    if model.solver.stop_drift_ratio:
        cause = f"solver.stop_drift_ratio {model.solver.stop_drift_ratio:g}"
    elif own is not None:
        cause = f"building {own[0]}'s collapse drift ratio {own[1]:g}"
    elif any(isinstance(p.hysteresis, ImkStorey) for p in planes):
        cause = "IMK storeys (a collapse at zero strength)"
    elif any(b.p_delta for b in model.buildings) and any(p.hysteresis is not None for p in planes):
        cause = "P-Delta on yielding storeys (a storey that loses its lateral resistance)"
    else:
        return []
    return [f"{cause}: the OpenSees script does not stop at a collapse, it runs to the end (compare completed "
            "runs only)"]


def opensees_script(model, record=None, *, dt: float = DEFAULT_DT, xi: str | None = None,
                    duration: float | None = None) -> str:
    """Text of a standalone OpenSeesPy script of *model* under *record*.

    Parameters
    ----------
    model : Model
    record : Record or str, optional
        Default: the model's own ground motion.  A string replaces the model's record (a catalogue pair for
        a model with two components), as ``pounding run --record`` does.
    dt : float
        OpenSees time step, s.
    xi : str, optional
        ξ formula for every hertz-damp contact (overrides the model).
    duration : float, optional
        Simulated time, s (default: the model's, else the record's duration).

    Returns
    -------
    str
        Python source.  Run it (``python model.py [--dt DT] [-o peaks.json]``) or import it and call
        ``analyse()``, which returns the peaks as a dict.
    """
    return opensees_script_and_notes(model, record, dt=dt, xi=xi, duration=duration)[0]


def opensees_script_and_notes(model, record=None, *, dt: float = DEFAULT_DT, xi: str | None = None,
                              duration: float | None = None, where: str = "api") -> tuple[str, list[str]]:
    """(script text, notes on what the script cannot reproduce exactly); parameters as :func:`opensees_script`.

    *where* (``api`` or ``cli``) words a bad record's message for its caller.

    Raises
    ------
    PoundingError
        One line: a refusal (:func:`export_refusal`), a law without an OpenSees material, a bad ``dt``,
        record or duration.
    """
    from pounding.simulation import with_overrides

    if not (dt > 0.0 and math.isfinite(dt)):
        raise PoundingError(f"--dt must be > 0 (got {dt!r})")
    refusal = export_refusal(model)
    if refusal is not None:
        raise PoundingError(f"{model.path or model.name}: {refusal}")
    model = with_overrides(model, record if isinstance(record, str) else None, xi=xi, duration=duration,
                           where=where)
    ground = script_ground(model, None if isinstance(record, str) else record,
                           where=where if isinstance(record, str) else "yaml")
    domain = build_domain(model)
    notes = domain.notes + _collapse_note(model)
    if domain.nodes.form == "axis":
        return axis_script(model, domain, ground, dt, notes), notes
    return diaphragm_script(model, domain, ground, dt, notes, eigen_offset=EIGEN_TAG_OFFSET,
                            repeated=REPEATED_FREQUENCY), notes


def run_opensees(model, record=None, *, dt: float = DEFAULT_DT, xi: str | None = None,
                 duration: float | None = None) -> dict:
    """Export *model* and run the script in a child Python process; return its peaks.

    The child keeps OpenSees' global state (and the "Process 0 Terminating" line OpenSees prints at
    interpreter exit) out of the calling process.

    Returns
    -------
    dict
        Under the run archive's names: ``floor``/``peak_displacement`` (m; in plan per floor its x and y),
        ``storey``/``peak_drift_ratio``, ``contact``/``peak_contact_force`` (N)/``impact_count``,
        ``link``/``peak_link_force`` (N); in plan also ``peak_rotation`` (rad), ``plane``/``peak_plane_drift``
        (m) and ``corner``/``peak_corner_displacement`` (m); plus ``wall_time`` (s, the ``analyze`` calls
        only), ``converged``, ``cut_steps`` and ``dt``.

    Raises
    ------
    PoundingError
        If OpenSeesPy is not installed, the model cannot be exported or the script fails.
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
