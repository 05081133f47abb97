"""The documentation cannot lie: its commands parse, its names import, its snippets and fast commands run.

Read from README.md, models/README.md and every docs/**/*.md (docs/testing.md, "Docs that run", states the
conventions):

* every shell command that starts with ``pounding`` (or ``python3 -m pounding``) in a fenced block,
  and every inline code span that does (except usage synopses, which hold ``[``, ``|``, ``…`` or
  ``(``), is parsed by the CLI's own parser (:func:`pounding.cli.build_parser`), without running;
* every dotted name ``pounding.x.y`` is imported (module, then attributes);
* every ```python block runs, the blocks of one file in order in one namespace, in a scratch folder
  that holds the shipped ``models/``, ``ground_motions/`` and ``sweeps/``;
* every fenced command runs, in order, in that folder, ``pounding run`` shortened to
  :data:`SHORT_DURATION` s unless it gives ``--duration``;
* a block whose first line is a comment starting ``# example`` is an example: parsed (commands) but not
  run (full record sets, benchmarks; ``.ci/run`` and the benchmarks run those);
* in the tutorial and the how-to guides (:data:`WALKTHROUGHS`) transcripts run in sequence with the
  other blocks, full length, so that a later block can read what they wrote, and their output is compared
  there (the other pages' transcripts each run and are compared on their own);
* an output block that follows ``$ pounding run MODEL`` is the summary of that run, line by line
  (``...`` skips lines; timings and ``wrote`` lines are not compared), and the counts the docs quote
  (records in the catalogue, scenarios of a sweep) are those of the code.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import io
import os
import re
import shlex
from pathlib import Path

import pytest

from pounding.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", ROOT / "models" / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
#: The tutorial and the how-to guides: their transcripts run in sequence with the other blocks (a later
#: block reads what they wrote), full length, as the site's build runs them (docs/hooks.py).
WALKTHROUGHS = re.compile(r"^docs/(tutorial\.md|howto/[\w-]+\.md)$")

#: Simulated time of a ``pounding run`` of the docs that gives no ``--duration``, s.
SHORT_DURATION = "2"

#: A fenced block: its language, its text and the line it starts on.
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)
COMMAND = re.compile(r"^(?:\$ )?(?:python3? -m )?pounding\s")
EXAMPLE = re.compile(r"^\s*#\s*example\b", re.I)
DOTTED = re.compile(r"(?<![\w/.-])pounding(?:\.[A-Za-z_]\w*)+")
#: A file or folder of the package named by its path (``pounding/solver/jit.py``, ``pounding/results/``).
PACKAGE_PATH = re.compile(r"(?<![\w/.<>-])pounding/[\w/.-]*[\w/]")
SYNOPSIS = re.compile(r"[\[|…(]")


def _blocks(path: Path) -> list[tuple[str, str, int]]:
    text = path.read_text(encoding="utf-8")
    return [(m.group(1), m.group(2), text[:m.start()].count("\n") + 2) for m in FENCE.finditer(text)]


def _strip_comment(line: str) -> str:
    """The command without its trailing ``# comment`` (a ``#`` after whitespace, outside quotes)."""
    try:
        return shlex.join(shlex.split(line, comments=True))
    except ValueError:
        return line


def _commands(body: str) -> list[str]:
    """The ``pounding`` commands of a block: continuation lines joined, ``$ ``, ``python3 -m`` and ``&&`` chains split."""
    joined = re.sub(r"\\\n\s*", " ", body)
    found = []
    for line in joined.splitlines():
        for part in line.split("&&"):
            part = part.strip()
            if COMMAND.match(part):
                part = re.sub(r"^(?:\$ )?(?:python3? -m )?", "", part)
                found.append(_strip_comment(part))
    return found


def _inline_commands(path: Path) -> list[tuple[str, int]]:
    text = FENCE.sub(lambda m: "\n" * m.group(0).count("\n"), path.read_text(encoding="utf-8"))
    found = []
    for m in re.finditer(r"`([^`\n]+)`", text):
        span = m.group(1).strip()
        if COMMAND.match(span) and not SYNOPSIS.search(span):
            found.append((re.sub(r"^(?:python3? -m )?", "", span), text[:m.start()].count("\n") + 1))
    return found


def _all_commands() -> list[tuple[str, str]]:
    """(where, command) of every command of a fenced block."""
    out = []
    for path in DOCS:
        rel = path.relative_to(ROOT)
        for _, body, line in _blocks(path):
            out += [(f"{rel}:{line}", c) for c in _commands(body)]
    return out


def _all_fragments() -> list[tuple[str, str]]:
    """(where, command) of every inline ``pounding ...`` code span that is not a usage synopsis."""
    return [(f"{path.relative_to(ROOT)}:{line}", c) for path in DOCS for c, line in _inline_commands(path)]


def _check_fragment(command: str) -> None:
    """An inline span may leave out required arguments (`pounding run --plot DIR`), but its subcommand
    and every option it names must exist."""
    words = shlex.split(command)[1:]
    parser = build_parser(None)
    while words:
        groups = [a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction"]
        if not groups or words[0].startswith("-"):
            break
        if words[0] not in groups[0].choices:
            assert words[0].isupper(), f"no command {words[0]!r} (commands: {', '.join(groups[0].choices)})"
            return   # a placeholder such as COMMAND
        parser = groups[0].choices[words.pop(0)]
    known = set(parser._option_string_actions)
    unknown = [w for w in words if w.startswith("-") and w.split("=")[0] not in known]
    assert not unknown, f"{parser.prog} has no option {', '.join(unknown)}"


def _parse(command: str) -> None:
    """Parse *command* (without ``pounding``) with the CLI's parser; AssertionError with argparse's message."""
    words = shlex.split(command)[1:]
    parser = build_parser(None)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            args, extra = parser.parse_known_args(words)
        except SystemExit as exc:
            if exc.code == 0:   # --help, --version
                return
            raise AssertionError(" ".join(err.getvalue().split())) from None
    assert not extra, f"unrecognized arguments: {' '.join(extra)}"


def test_the_docs_hold_commands_to_check():
    commands = _all_commands()
    assert len(commands) > 40
    assert any(c.startswith("pounding run models/pair.yaml -o pair.nc") for _, c in commands)


@pytest.mark.parametrize("where, command", _all_commands(), ids=lambda x: x if ":" in str(x) else None)
def test_every_documented_command_parses(where, command):
    try:
        _parse(command)
    except AssertionError as exc:
        pytest.fail(f"{where}: `{command}`: {exc}")


@pytest.mark.parametrize("where, command", _all_fragments())
def test_every_inline_command_names_a_command_and_options_that_exist(where, command):
    try:
        _check_fragment(command)
    except AssertionError as exc:
        pytest.fail(f"{where}: `{command}`: {exc}")


def _mentions(pattern: re.Pattern) -> dict[str, str]:
    """Every distinct text *pattern* finds in the docs, with where it first appears."""
    found: dict[str, str] = {}
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in pattern.finditer(text):
            found.setdefault(m.group(0), f"{path.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}")
    return found


def _resolve(dotted: str) -> None:
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError as exc:
            if exc.name is not None and not ".".join(parts[:cut]).startswith(exc.name):
                raise
            continue
        for attribute in parts[cut:]:
            obj = getattr(obj, attribute)
        return
    raise ModuleNotFoundError(dotted)


@pytest.mark.parametrize("name, where", sorted(_mentions(DOTTED).items()))
def test_every_dotted_name_in_the_docs_exists(name, where):
    try:
        _resolve(name)
    except (ImportError, AttributeError) as exc:
        pytest.fail(f"{where}: {name} does not exist ({type(exc).__name__}: {exc})")


@pytest.mark.parametrize("name, where", sorted(_mentions(PACKAGE_PATH).items()))
def test_every_package_path_in_the_docs_exists(name, where):
    assert (ROOT / name).exists(), f"{where}: {name} does not exist"



# --------------------------------------------------------------------------- #
# Running the docs: python blocks, fast commands, transcripts, counts
# --------------------------------------------------------------------------- #

#: Output lines a transcript does not compare: files written and wall times.
VOLATILE_LINE = re.compile(r"^(wrote |wall time |ran \d+ )")


def _normalise(line: str) -> str:
    """A line as compared: runs of spaces as one (a doc may narrow a table), solver wall time blanked."""
    return re.sub(r"solver wall time [\d.]+ s", "solver wall time <t> s", " ".join(line.split()))


def _is_example(body: str) -> bool:
    first = next((line for line in body.splitlines() if line.strip()), "")
    return bool(EXAMPLE.match(first))


def _is_transcript(lang: str, body: str) -> bool:
    return lang == "" and body.lstrip().startswith("$ ")


@pytest.fixture(scope="module", autouse=True)
def one_ball_drop_per_setting():
    """The ball drop of ``pounding verify`` computed once per setting for the module's doc runs.

    The docs run ``pounding verify`` with its default settings six times (plain, ``--json``, ``--plot``, ``-o``,
    in docs/verification.md, docs/tour.md and their transcripts), ~5.5 s each: the same deterministic
    computation (:func:`pounding.studies.verify.run_verification`, tested by tests/test_verify.py) of the same
    arguments.  Each command still runs through the CLI, prints, writes and plots what it documents from a
    deep copy of the dataset its arguments give; another setting (``--gravity 0``, ``--models``) is computed.
    """
    from pounding.studies import verify

    real, computed = verify.run_verification, {}

    def run_verification(e_pre=verify.DEFAULT_E_PRE, models=None, **settings):
        key = (tuple(float(e) for e in e_pre), None if models is None else tuple(models),
               tuple(sorted(settings.items())))
        if key not in computed:
            computed[key] = real(e_pre, models, **settings)
        return computed[key].copy(deep=True)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(verify, "run_verification", run_verification)
        yield


def _scratch(folder: Path) -> Path:
    """A folder holding links to the shipped models, records, sweeps and examples (as the checkout does)."""
    for name in ("models", "ground_motions", "sweeps", "examples"):
        (folder / name).symlink_to(ROOT / "pounding" / "data" / name, target_is_directory=True)
    (folder / "docs").mkdir()
    return folder


def _run(command: str, *, shorten: bool) -> tuple[int, str]:
    """Run a documented ``pounding ...`` command in this process; its status and standard output."""
    words = shlex.split(command)[1:]
    if shorten and words[:1] == ["run"] and not any(w.startswith("--duration") for w in words):
        words += ["--duration", SHORT_DURATION]
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()) as err:
        status = main(words)
    return status, out.getvalue() + (err.getvalue() if status else "")


def _matches(expected: list[str], actual: list[str]) -> bool:
    """Whether *actual* lines match *expected* ones, ``...`` standing for any number of lines."""
    pattern = "".join(r"(?:[^\n]*\n)*?" if line.strip() == "..." else re.escape(line) + r"\n" for line in expected)
    return re.fullmatch(pattern, "".join(line + "\n" for line in actual)) is not None


def _compare_output(where: str, expected_text: str, printed: str) -> None:
    expected = [_normalise(x) for x in expected_text.splitlines() if not VOLATILE_LINE.match(x)]
    actual = [_normalise(x) for x in printed.splitlines() if not VOLATILE_LINE.match(x)]
    assert _matches(expected, actual), (f"{where}: the documented output is not what the command prints now:\n"
                                        + "\n".join(actual))


def _runnable_docs() -> list[Path]:
    return [p for p in DOCS if any(not _is_example(body) and (lang == "python" or _commands(body))
                                   for lang, body, _ in _blocks(p))]


@pytest.mark.parametrize("path", _runnable_docs(), ids=lambda p: str(p.relative_to(ROOT)))
def test_the_python_blocks_and_fast_commands_of_a_doc_run(path, tmp_path, monkeypatch, studies_in_process):
    """In reading order, in a scratch folder: python blocks share one namespace; a python block directly
    followed by an unlabelled block prints that block; commands run (``run`` shortened); transcripts are
    :func:`test_every_transcript_is_what_the_command_prints`'s."""
    monkeypatch.chdir(_scratch(tmp_path))
    text = path.read_text(encoding="utf-8")
    matches = list(FENCE.finditer(text))
    namespace: dict = {"__name__": "__docs__"}
    rel = path.relative_to(ROOT)
    for i, m in enumerate(matches):
        lang, body = m.group(1), m.group(2)
        where = f"{rel}:{text[:m.start()].count(chr(10)) + 2}"
        if _is_example(body):
            continue
        if _is_transcript(lang, body):
            if WALKTHROUGHS.match(rel.as_posix()):
                # Run here, in sequence, and compared here (not again in the transcript test): what it prints
                # is the lines below it, as test_every_transcript_is_what_the_command_prints compares elsewhere.
                for k, segment in enumerate(re.split(r"^\$ ", body, flags=re.M)[1:]):
                    line, _, expected = segment.partition("\n")
                    command = re.sub(r"^(?:python3? -m )?", "", line.strip())
                    status, printed = _run(command, shorten=False)
                    assert status == 0, f"{where}: `{command}` ended with status {status}:\n{printed}"
                    if expected.strip():
                        _compare_output(f"{where} ${k + 1}", expected, printed)
            continue
        if lang == "python":
            printed = io.StringIO()
            with contextlib.redirect_stdout(printed):
                try:
                    exec(compile(body, where, "exec"), namespace)
                except Exception as exc:   # noqa: BLE001 - report the block that failed
                    pytest.fail(f"{where}: the python block raises {type(exc).__name__}: {exc}")
            following = matches[i + 1] if i + 1 < len(matches) else None
            if following is not None and following.group(1) == "" and \
                    not text[m.end():following.start()].strip() and not _is_transcript("", following.group(2)):
                _compare_output(where, following.group(2), printed.getvalue())
            continue
        for line in re.sub(r"\\\n\s*", " ", body).splitlines():
            for part in (p.strip() for p in line.split("&&")):
                if part.startswith("cd "):
                    os.chdir(shlex.split(part)[1])
                elif COMMAND.match(part):
                    command = _strip_comment(re.sub(r"^(?:\$ )?(?:python3? -m )?", "", part))
                    status, printed = _run(command, shorten=True)
                    assert status == 0, f"{where}: `{command}` ended with status {status}:\n{printed}"


def _transcripts() -> list[tuple[str, str, str]]:
    """(where, command, expected output) of every ``$ pounding ...`` line of an unlabelled block, but those of
    the walkthroughs (:data:`WALKTHROUGHS`), which their doc run runs in sequence and compares."""
    found = []
    for path in DOCS:
        if WALKTHROUGHS.match(path.relative_to(ROOT).as_posix()):
            continue
        for lang, body, line in _blocks(path):
            if not _is_transcript(lang, body) or _is_example(body):
                continue
            for k, segment in enumerate(re.split(r"^\$ ", body, flags=re.M)[1:]):
                command, _, output = segment.partition("\n")
                found.append((f"{path.relative_to(ROOT)}:{line} ${k + 1}",
                              re.sub(r"^(?:python3? -m )?", "", command.strip()), output))
    return found


@pytest.mark.parametrize("where, command, expected", _transcripts(), ids=[t[0] for t in _transcripts()])
def test_every_transcript_is_what_the_command_prints(where, command, expected, tmp_path, monkeypatch,
                                                    studies_in_process):
    """A ``$ pounding ...`` line and the lines below it are the command's output, in full (not shortened)."""
    monkeypatch.chdir(_scratch(tmp_path))
    status, printed = _run(command, shorten=False)
    assert status == 0, f"{where}: `{command}` ended with status {status}:\n{printed}"
    if expected.strip():   # a command without output lines below it is only run
        _compare_output(where, expected, printed)


def _catalogue_counts() -> tuple[int, ...]:
    from pounding.records.catalogue import load_catalogue

    entries = load_catalogue()
    sets = [e.set for e in entries.values()]
    return len(entries), sets.count("farfield"), sets.count("nearfield")


def _sweep(name: str):
    from pounding.studies.sweep.spec import load_sweep

    return load_sweep(ROOT / "sweeps" / name)


def _sweep_size(name: str) -> int:
    return _sweep(name).size


@functools.lru_cache(maxsize=None)
def _impacts(model: str) -> dict[str, int]:
    """Impacts per contact of a shipped model's own run, and ``all``."""
    import pounding

    ds = pounding.simulate(pounding.load_model(ROOT / "models" / model))
    counts = {str(c): int(n) for c, n in zip(ds.contact.values, ds.impact_count.values)}
    return {**counts, "all": sum(counts.values())}


def _stripes(levels: str) -> int:
    from pounding.studies.ida import parse_levels

    return len(parse_levels(levels))


#: Counts the docs quote: (file, pattern whose groups are the numbers, the numbers now).
COUNTS = [
    ("docs/tour.md", r"the (\d+) far-field records \((\d+) in all\)", lambda: _catalogue_counts()[1::-1]),
    ("docs/tour.md", r"gap_restitution\.nc +# (\d+) scenarios", lambda: (_sweep_size("gap_restitution.yaml"),)),
    ("docs/ground_motions.md", r"names (\d+) records with readable keys", lambda: _catalogue_counts()[:1]),
    ("docs/ground_motions.md", r"all (\d+) components of the FEMA P695 far-field", lambda: _catalogue_counts()[1:2]),
    ("docs/ground_motions.md", r"all (\d+) components of the FEMA P695 near-field", lambda: _catalogue_counts()[2:]),
    ("docs/tour.md", r"the same pair pounds (\d+)\s+times", lambda: (_impacts("pair.yaml")["all"],)),
    ("docs/tour.md", r"`pounding run models/pair.yaml`: (\d+) impacts,\s+(\d+) at floor 1",
     lambda: (_impacts("pair.yaml")["all"], _impacts("pair.yaml")["A:1-B:1"])),
    ("docs/tour.md", r"the floor-1 contact pounds (\d+) times", lambda: (_impacts("pair_wave_passage.yaml")["A:1-B:1"],)),
    ("docs/tour.md", r"all (\d+) far-field\s+components at (\d+) stripes of Sa\(T₁ of A\) \((\d+) runs",
     lambda: (_catalogue_counts()[1], _stripes("0.1:1.5:0.1"), _catalogue_counts()[1] * _stripes("0.1:1.5:0.1") * 2)),
    ("docs/sweeps.md", r"gap_restitution.yaml: (\d+) gaps x (\d+) restitutions x (\d+) records = (\d+) scenarios",
     lambda: (*(d.size for d in _sweep("gap_restitution.yaml").dimensions), _sweep_size("gap_restitution.yaml"))),
]


@pytest.mark.parametrize("file, pattern, actual", COUNTS, ids=[f"{c[0]}:{c[1][:30]}" for c in COUNTS])
def test_the_counts_the_docs_quote_are_the_code_s(file, pattern, actual):
    m = re.search(pattern, (ROOT / file).read_text(encoding="utf-8"))
    assert m, f"{file}: no longer says {pattern!r}; update COUNTS in tests/test_docs.py with the text"
    assert tuple(int(x) for x in m.groups()) == tuple(actual()), f"{file}: {m.group(0)!r}"


def test_every_far_or_near_field_count_in_the_docs_is_the_catalogue_s():
    """``44 far-field records``, ``56 near-field components``, ``22 far-field pairs``... anywhere in the docs."""
    _, far, near = _catalogue_counts()
    wrong = []
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"\b(\d+)\s+(?:FEMA P695\s+)?(far|near)-field\b( pairs)?", text):
            components = {"far": far, "near": near}[m.group(2)]
            if int(m.group(1)) != (components // 2 if m.group(3) else components):  # a pair is two components
                wrong.append(f"{path.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}: {m.group(0)!r}")
    assert not wrong, f"the catalogue has {far} far-field and {near} near-field components: " + "; ".join(wrong)


def test_install_md_lists_every_file_pounding_init_copies():
    """docs/install.md's table of what ``pounding init`` writes names exactly the shipped files of each folder."""
    from pounding.data import STARTER_FOLDERS, data_path

    text = (ROOT / "docs" / "install.md").read_text(encoding="utf-8")
    for name in STARTER_FOLDERS:
        row = re.search(rf"^\| `{name}/` \|(.*)\|$", text, re.M)
        assert row, f"docs/install.md: no table row for `{name}/`"
        listed = set(re.findall(r"`([\w-]+\.\w+)`", row.group(1)))
        shipped = {p.name for p in data_path(name).iterdir() if p.is_file() and not p.name.startswith(("_", "."))}
        assert listed == shipped, (f"docs/install.md, `{name}/`: not listed {sorted(shipped - listed)}, "
                                   f"not shipped {sorted(listed - shipped)}")
