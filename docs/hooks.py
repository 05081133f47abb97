"""MkDocs hooks (``hooks:`` in mkdocs.yml): what the site adds to the Markdown of ``docs/`` when it is built.

* The reference pages, generated from the code (``docs/gen_reference.py``).
* The README as the home page, and ``models/README.md`` (the model-file guide) as a page.
* The examples of the tutorial and the how-to guides run (``pounding`` commands, ``$ pounding``
  transcripts and python blocks, in order, in a scratch folder holding the shipped models, records
  and sweeps), and every figure they write is published beside the page, so the site's figures are
  the build's own.  ``tests/test_docs.py`` checks their printed output against the pages.
* Links between the pages are written as they work in the repository (``docs/gap.md`` from the
  README, ``../models/README.md`` from a page of docs/); each is rewritten to the page's place in
  the site, and a link to a file that is not a page (a model, a test) becomes its path in code.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import os
import posixpath
import re
import shlex
import tempfile
from pathlib import Path

from mkdocs.structure.files import File

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent

#: Repository file -> its page in the site, for the Markdown files that live outside docs/.
OUTSIDE_PAGES = {"README.md": "index.md", "models/README.md": "models/README.md", "CHANGELOG.md": "changelog.md"}

#: Committed figures that a page's run makes again at build time: site path -> (page, figure it writes).
#: The README's figure (docs/figures/, shown in the repository) is the tutorial's, so the site's is the build's.
REMADE = {"figures/pair_fifth_floors.png": ("tutorial.md", "tutorial_floor5.png")}

#: Pages whose examples run at build time (and whose figures are the build's).
RUN_PAGES = re.compile(r"^(tutorial\.md|howto/[\w-]+\.md)$")

FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)
COMMAND = re.compile(r"^(?:\$ )?(?:python3? -m )?pounding\s")
EXAMPLE = re.compile(r"^\s*#\s*example\b", re.I)
LINK = re.compile(r"(!?\[[^\]]*\])\(([^)\s]+)\)")


def _reference_module():
    spec = importlib.util.spec_from_file_location("gen_reference", DOCS / "gen_reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _add(files, config, src_uri: str, content: str | bytes) -> None:
    """Add a generated file, replacing a file of docs/ at the same place."""
    old = files.get_file_from_path(src_uri)
    if old is not None:
        files.remove(old)
    files.append(File.generated(config, src_uri, content=content))


def on_files(files, config):
    for src_uri, make in _reference_module().PAGES.items():
        _add(files, config, src_uri, make())
    for repo_path, src_uri in OUTSIDE_PAGES.items():
        _add(files, config, src_uri, (ROOT / repo_path).read_text(encoding="utf-8"))
    for page in [f for f in files.documentation_pages() if RUN_PAGES.match(f.src_uri)]:
        made = run_examples(Path(page.abs_src_path).read_text(encoding="utf-8"), page.src_uri)
        for rel, data in made.items():
            _add(files, config, posixpath.join(posixpath.dirname(page.src_uri), rel), data)
        for target, (source, figure) in REMADE.items():
            if source == page.src_uri:
                _add(files, config, target, made[figure])
    return files


# --------------------------------------------------------------------------- #
# The examples, run
# --------------------------------------------------------------------------- #


def _run_command(line: str, where: str) -> None:
    from pounding.cli import main

    words = shlex.split(re.sub(r"^(?:\$ )?(?:python3? -m )?", "", line), comments=True)[1:]
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        status = main(words)
    if status != 0:
        raise RuntimeError(f"{where}: `pounding {' '.join(words)}` ended with status {status}:\n{out.getvalue()}")


def run_examples(text: str, where: str) -> dict[str, bytes]:
    """Run a page's blocks in order in a scratch folder; the figures (PNG) they wrote, by relative path."""
    namespace: dict = {"__name__": "__docs__"}
    here = os.getcwd()
    with tempfile.TemporaryDirectory() as scratch:
        for name in ("models", "ground_motions", "sweeps", "examples"):
            (Path(scratch) / name).symlink_to(ROOT / "pounding" / "data" / name, target_is_directory=True)
        os.chdir(scratch)
        try:
            for m in FENCE.finditer(text):
                lang, body = m.group(1), m.group(2)
                line = f"{where}:{text[:m.start()].count(chr(10)) + 2}"
                if EXAMPLE.match(next((x for x in body.splitlines() if x.strip()), "")):
                    continue
                if lang == "python":
                    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                        exec(compile(body, line, "exec"), namespace)
                    continue
                transcript = body.lstrip().startswith("$ ")   # only its `$ ` lines are commands
                for x in re.sub(r"\\\n\s*", " ", body).splitlines():
                    if transcript and not x.startswith("$ "):
                        continue
                    for part in (p.strip() for p in x.split("&&")):
                        if COMMAND.match(part):
                            _run_command(part, line)
            return {p.relative_to(scratch).as_posix(): p.read_bytes()
                    for p in sorted(Path(scratch).rglob("*.png")) if not p.is_symlink()}
        finally:
            os.chdir(here)
            import matplotlib.pyplot as plt

            plt.close("all")


# --------------------------------------------------------------------------- #
# Links
# --------------------------------------------------------------------------- #


def _repo_path(src_uri: str) -> str:
    """Where a page of the site lives in the repository."""
    return {page: repo for repo, page in OUTSIDE_PAGES.items()}.get(src_uri, f"docs/{src_uri}")


def site_link(target: str, src_uri: str) -> str | None:
    """A link *target* written on the page *src_uri* as it works in the repository, as it works in the
    site; ``None`` where the target is a repository file that is not in the site."""
    if re.match(r"^([a-z]+:|#|/)", target):
        return target
    path, _, anchor = target.partition("#")
    repo = posixpath.normpath(posixpath.join(posixpath.dirname(_repo_path(src_uri)), path))
    if repo in OUTSIDE_PAGES:
        site = OUTSIDE_PAGES[repo]
    elif repo.startswith("docs/"):
        site = repo[len("docs/"):]
    else:
        return None
    rel = posixpath.relpath(site, posixpath.dirname(src_uri) or ".")
    return rel + (f"#{anchor}" if anchor else "")


def on_page_markdown(markdown, page, config, files):
    def rewrite(m: re.Match) -> str:
        text, target = m.group(1), m.group(2)
        new = site_link(target, page.file.src_uri)
        if new is not None:
            return f"{text}({new})"
        label = text.strip("![]")
        return f"{label} (`{target}`)" if label.strip("`") != target else f"`{target}`"

    # Links outside the fenced blocks only (code may hold `a[i](x)`).
    parts, last = [], 0
    for m in FENCE.finditer(markdown):
        parts += [LINK.sub(rewrite, markdown[last:m.start()]), m.group(0)]
        last = m.end()
    return "".join(parts) + LINK.sub(rewrite, markdown[last:])
