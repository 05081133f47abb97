"""One world in OpenSees too: a planar model and its twin in plan export to scripts whose peaks agree.

tests/one_world.py writes a planar model as a model in plan (each storey one plane along x through
the centre of mass and two along y at the ends, each face's two contact points with half of kh,
the record along x).  The export writes the planar model on an axis (a node per floor, a
``zeroLength`` per storey and contact) and its twin with rigid diaphragms (masters at the centres
of mass, a ``zeroLength`` per plane and contact point between diaphragm slaves).  Both integrate
the same equations: the twin's y and θ degrees of freedom are never loaded (the x plane passes
through the centre of mass, the ground moves along x, the two points of a face close together),
and two Hertzdamp points with kh/2 push as one with kh (force and damping constant are linear in
kh).  What can differ is round-off: another equation system (3-D, ``Transformation``
constraints), the Newton test at 1e-12 of the stiffest spring's force at 1 m, carried through
the impacts.

``models/pair.yaml`` over its first 5 s at dt 1e-3 s (its first impact is at 3.45 s, so over
3 s neither script pounds and the impact counts would be 0 = 0).  The two scripts are compared
with each other, not with our solver, so the step only has to be the same in both: OpenSees'
discretisation error (Newmark's, Hertzdamp's onset) is the same in the two scripts, and what
remains is round-off.  Measured at dt 1e-3 s: the floor peaks agree to 3.5e-15, the drift ratios
to 6.7e-15, the contact forces (the twin's two points summed) to 7.6e-15, the impact counts are
identical on every point (2, 2, 4 on the top three levels, as at dt 1e-4 s), and the twin's peak
u_y and θ are exactly 0 (at dt 1e-4 s: 4.6e-15, 2.7e-14 and 2e-14).  The tolerance, 1e-10 (the issue's bound for our own solver's
twins), leaves four orders of magnitude for round-off carried through contacts, while any
difference of model moves the peaks at first order (a point with kh instead of kh/2 doubles its
force; a plane off the centre of mass twists the floors).

Runtime: the twin's 75 diaphragm slaves cost OpenSees 1 – 6 ms a step (the Transformation
handler), 5 – 30 s for the 5 000 steps (the more, the more loaded the machine); at dt 1e-4 s it
was 50 – 190 s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from one_world import as_plan_document, planar_document
from opensees_peer import relative, skip_without_openseespy

skip_without_openseespy()

from pounding.errors import PoundingError  # noqa: E402
from pounding.export.opensees import opensees_script, run_opensees  # noqa: E402
from pounding.model.model import load_model, model_from_data  # noqa: E402

MODELS = Path(__file__).resolve().parents[1] / "models"
TOLERANCE = 1.0e-10


def twin_of(name: str):
    """The planar shipped model *name* and its twin in plan (tests/one_world.py)."""
    path = MODELS / f"{name}.yaml"
    twin = model_from_data(as_plan_document(planar_document(path.read_text())), name=f"{name}_plan",
                           base_dir=str(MODELS))
    return load_model(path), twin


@pytest.fixture(scope="module")
def pair_peaks():
    """(planar script's peaks, twin's peaks) of models/pair.yaml over 5 s at dt 1e-3 s (the same in both)."""
    planar, twin = twin_of("pair")
    return run_opensees(planar, dt=1e-3, duration=5.0), run_opensees(twin, dt=1e-3, duration=5.0)


def test_twin_writes_the_diaphragm_form_of_the_same_model():
    planar, twin = twin_of("pair")
    flat, plan = opensees_script(planar, duration=0.01), opensees_script(twin, duration=0.01)
    # a planar model without foundations: one dimension, one DOF a node (a founded one writes NDF = 3, in 2-D)
    assert "\nNDF = 1\n" in flat and 'ops.model("basic", "-ndm", min(NDF, 2), "-ndf", NDF)' in flat
    assert "rigidDiaphragm" not in flat
    assert 'ops.model("basic", "-ndm", 3, "-ndf", 6)' in plan and "rigidDiaphragm" in plan
    # The same record along x, and nothing along y.
    record = flat[flat.index("RECORD = ["):flat.index("]", flat.index("RECORD = ["))].split("[", 1)[1]
    along_x = plan[plan.index("RECORD_X = ["):plan.index("]", plan.index("RECORD_X = ["))].split("[", 1)[1]
    assert record.split("\n", 1)[1] == along_x.split("\n", 1)[1]


def test_planar_model_and_its_twin_agree_in_opensees(pair_peaks):
    flat, plan = pair_peaks
    assert flat["converged"] and plan["converged"] and flat["cut_steps"] == plan["cut_steps"] == 0
    assert plan["floor"] == flat["floor"] and plan["storey"] == flat["storey"]
    u = np.asarray(plan["peak_displacement"])
    assert relative(u[:, 0], flat["peak_displacement"]).max() < TOLERANCE
    assert relative(plan["peak_drift_ratio"], flat["peak_drift_ratio"]).max() < TOLERANCE
    assert np.abs(u[:, 1]).max() < TOLERANCE * u.max() and max(plan["peak_rotation"]) < TOLERANCE * u.max() / 20.0
    # Each face's two points: the planar contact's impacts each, half its force each.
    assert sum(flat["impact_count"]) >= 8
    assert plan["impact_count"] == [n for n in flat["impact_count"] for _ in range(2)]
    forces = np.asarray(plan["peak_contact_force"]).reshape(-1, 2)
    struck = np.asarray(flat["peak_contact_force"]) > 0
    assert relative(forces.sum(axis=1)[struck], np.asarray(flat["peak_contact_force"])[struck]).max() < TOLERANCE
    assert [label.split("@")[0] for label in plan["contact"][::2]] == flat["contact"]


@pytest.mark.parametrize("name, message", [
    ("pair_wave_passage", "does not write multi-support excitation.*MultipleSupport pattern"),
    ("pair_bumper", "contact law 'bumper' has no OpenSees counterpart: its hard face"),
    ("pair_column", "strikes a column between floors: a column point moves as a weighted mean of two floors"),
])
def test_a_model_and_its_twin_are_refused_alike(name, message):
    # The refusals read the description (a ground motion per support, a contact's law, a column point), not the
    # model kind.
    for model in twin_of(name):
        with pytest.raises(PoundingError, match=message) as info:
            opensees_script(model, duration=1.0)
        assert "\n" not in str(info.value)


def test_column_points_are_refused_with_their_reason():
    with pytest.raises(PoundingError, match=r"contact A:1-B:s2@0.25 strikes a column between floors: a column "
                                            r"point moves as a weighted mean of two floors") as info:
        opensees_script(load_model(MODELS / "pair_column.yaml"))
    assert "\n" not in str(info.value)
