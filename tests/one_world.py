"""A planar model written as a model in plan: the twin that proves the two are one world (tests/test_one_world.py).

Each building of the row becomes a rectangle in plan, ``WIDTH`` m along x and ``DEPTH`` m along
y, side by side along x with the gaps of the contacts between them; each storey's stiffness is
one plane along x through the floors' centres of mass (the centroid: no torsion is coupled in)
and two planes along y at the building's ends (stiffness ``Y_FACTOR`` times the storey's each:
the y and torsional modes exist but are never excited).  Every contact between two floors becomes
a face whose two contact points each take half the stiffness of the contact law (``kh`` and the
bumper's ``bumper_kh``: Hertz forces and their damping constants are linear in them, so the two
points together push as the planar contact does); a link acts at the middle of the face; a wall
stands beside the building's east or west face.  Rayleigh damping keeps its two targeted modes,
renumbered among the building's 3-D modes (the x modes are the planar modes); modal damping lists
the planar ratios at the x modes.  The record is the one component along x.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import yaml

from pounding.model.model import model_from_data

__all__ = ["WIDTH", "DEPTH", "as_plan_document", "planar_document", "storey_of_plane"]

#: Plan dimensions of every building, m (any: nothing twists).
WIDTH, DEPTH = 20.0, 12.0
#: Stiffness of each of a storey's two planes along y, as a multiple of its stiffness along x.
Y_FACTOR = 1.0
#: Keys of a contact law that are stiffnesses per contact: halved on each of a face's two points.
PER_POINT = ("kh", "bumper_kh")
#: A gap (m) between buildings joined by no contact (links only, or nothing).
SPACING = 1.0


def planar_document(text: str) -> dict[str, Any]:
    """A planar model file's data with each building's storeys written out one by one."""
    document = yaml.safe_load(text)
    for building in document["buildings"]:
        storeys = building["storeys"]
        if isinstance(storeys, dict):
            count = storeys.pop("count")
            building["storeys"] = [dict(storeys) for _ in range(count)]
    return document


def _row_gaps(document: dict[str, Any]) -> list[float]:
    """The gap between each pair of neighbours (their contacts' gap; every contact between them has the same)."""
    names = [b["name"] for b in document["buildings"]]
    gaps = [SPACING] * (len(names) - 1)
    for contact in document.get("contacts") or []:
        left, right = contact["between"]
        if "wall" in (left, right):
            continue
        gaps[min(names.index(left), names.index(right))] = float(contact["gap"])
    return gaps


def _plan_building(building: dict[str, Any], x0: float) -> dict[str, Any]:
    storeys = []
    for storey in building["storeys"]:
        k = float(storey["stiffness"])
        along_x = {"direction": "x", "at": DEPTH / 2, "stiffness": k}
        if storey.get("hysteresis") is not None:
            along_x["hysteresis"] = storey["hysteresis"]
        storeys.append({"mass": storey["mass"], "height": storey["height"],
                        "planes": [along_x, {"direction": "y", "at": x0, "stiffness": Y_FACTOR * k},
                                   {"direction": "y", "at": x0 + WIDTH, "stiffness": Y_FACTOR * k}]})
    out = {key: copy.deepcopy(value) for key, value in building.items() if key not in ("storeys", "ground_motion")}
    out["plan"] = {"outline": [[x0, 0.0], [x0 + WIDTH, DEPTH]]}
    out["storeys"] = storeys
    return out


def _plan_contact(contact: dict[str, Any], names: list[str]) -> dict[str, Any]:
    out = {key: value for key, value in contact.items() if key != "gap"}
    for key in PER_POINT:
        if key in out:
            out[key] = float(out[key]) / 2.0
    left, right = contact["between"]
    if "wall" in (left, right):
        out["between"] = [right, "wall"] if left == "wall" else [left, "wall"]
        out["face"] = "west" if left == "wall" else "east"
        out["gap"] = contact["gap"]
    return out


def _plan_ground(ground: dict[str, Any]) -> dict[str, Any]:
    out = {key: value for key, value in ground.items() if key != "record"}
    out["x"] = {"record": ground["record"]}
    out["angle"] = 0.0
    return out


def _x_modes(building: Any) -> list[int]:
    """1-based numbers, among a building's 3-D modes, of its modes along x (the planar modes, in order)."""
    phi = building.modes[1]
    along_x = np.abs(phi[0::3]).max(axis=0) > 1e-8 * np.abs(phi).max(axis=0)
    return [int(k) + 1 for k in np.flatnonzero(along_x)]


def _renumber_damping(plan: dict[str, Any], planar: dict[str, Any]) -> None:
    """Each building's damping at its x modes among its 3-D modes (in place)."""
    model = model_from_data(copy.deepcopy(plan))
    for entry, source, building in zip(plan["buildings"], planar["buildings"], model.buildings):
        damping = source.get("damping", {})
        modes = _x_modes(building)
        if "modal" in damping:
            ratios = list(damping["modal"])
            full = [ratios[-1]] * building.n_dof
            for k, mode in enumerate(modes):
                full[mode - 1] = ratios[min(k, len(ratios) - 1)]
            entry["damping"] = {"modal": full}
        else:
            i, j = damping.get("modes", [1, 2])
            entry["damping"] = {"ratio": damping.get("ratio", 0.05), "modes": [modes[i - 1], modes[j - 1]]}


def as_plan_document(planar: dict[str, Any]) -> dict[str, Any]:
    """The model-in-plan twin of a planar model's data (module docstring)."""
    names = [b["name"] for b in planar["buildings"]]
    x0, plan_buildings = 0.0, []
    for building, gap in zip(planar["buildings"], _row_gaps(planar) + [0.0]):
        plan_buildings.append(_plan_building(building, x0))
        x0 += WIDTH + gap
    plan = {key: copy.deepcopy(value) for key, value in planar.items()
            if key not in ("buildings", "contacts", "ground_motion")}
    plan["buildings"] = plan_buildings
    plan["contacts"] = [_plan_contact(c, names) for c in planar.get("contacts") or []]
    if planar.get("ground_motion") is not None:
        plan["ground_motion"] = _plan_ground(planar["ground_motion"])
    else:
        for entry, source in zip(plan["buildings"], planar["buildings"]):
            entry["ground_motion"] = _plan_ground(source["ground_motion"])
    _renumber_damping(plan, planar)
    return plan


def storey_of_plane(label: str) -> str:
    """``A:3:x@6`` → ``A:3``."""
    return ":".join(label.split(":")[:2])

