"""The sides of a before / after benchmark: another tree of this repository, and a process that runs in it.

``scaling.py`` and ``worker_share.py`` compare this checkout with another tree (``--before REF``): a
commit extracted once with ``git archive`` into ``<out>/trees/<commit>``, or another checkout's folder.
Each side is a long-lived process of a worker script of *this* checkout's ``benchmarks/``, started
with ``PYTHONPATH`` set to its tree (so the ``pounding`` it imports is that tree's), answering one
JSON request a line (:class:`WorkerProcess`).  :func:`time_solver_thread` notes the compiled solver's
thread CPU time in such a process.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[1]


def git(*args: str) -> str:
    """The output of ``git -C <this checkout> *args*`` (stripped; '' on an error)."""
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True).stdout.strip()


def this_tree_label() -> str:
    """``<branch>@<commit>``, with ``+changes`` if tracked files differ from it."""
    branch, commit = git("rev-parse", "--abbrev-ref", "HEAD"), git("rev-parse", "--short", "HEAD")
    changed = git("status", "--porcelain", "--untracked-files=no")
    return f"{branch}@{commit}{'+changes' if changed else ''}" if commit else str(ROOT)


def tree_of(ref: str, out: Path, script: str) -> tuple[Path, str]:
    """The folder and label of ``--before REF``: a pounding checkout's folder, or a commit extracted once
    into ``<out>/trees/<commit>`` (kept; its first run compiles the solver).  *script* names the benchmark
    in its one-line errors."""
    folder = Path(ref).expanduser()
    if (folder / "pounding" / "__init__.py").is_file():
        return folder.resolve(), str(folder)
    commit = git("rev-parse", "--verify", "--quiet", f"{ref}^{{commit}}")
    if not commit:
        raise SystemExit(f"{script}: --before {ref}: neither a commit of {ROOT} nor a folder holding "
                         "pounding/__init__.py; give a commit (e.g. main, 66b6f41) or another checkout")
    tree = out / "trees" / commit[:12]
    if not (tree / ".extracted").is_file():
        print(f"extracting {ref} ({commit[:12]}) into {tree} (kept; its first run compiles the solver)")
        tree.mkdir(parents=True, exist_ok=True)
        archive = subprocess.Popen(["git", "-C", str(ROOT), "archive", "--format=tar", commit], stdout=subprocess.PIPE)
        subprocess.run(["tar", "-x", "-C", str(tree)], stdin=archive.stdout, check=True)
        if archive.wait() != 0:
            raise SystemExit(f"{script}: --before {ref}: git archive failed (exit {archive.returncode})")
        (tree / ".extracted").write_text(commit + "\n")
    return tree, ref


class WorkerProcess:
    """A worker script of this checkout run in *tree* (``PYTHONPATH=tree``, started in it), one JSON a line.

    *name* and *script* (the benchmark) only name the process in the one-line error of a dead worker.
    """

    def __init__(self, worker: Path, tree: Path, args: list[str], *, name: str, script: str) -> None:
        self.tree, self.name, self.script = tree, name, script
        env = dict(os.environ, PYTHONPATH=str(tree))
        self.process = subprocess.Popen([sys.executable, str(worker), *args], cwd=tree, env=env, text=True,
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE)

    def ask(self, request: dict) -> dict:
        """The worker's answer to *request*; stops the benchmark in one line if the worker has ended."""
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        line = self.process.stdout.readline()
        if not line:
            raise SystemExit(f"{self.script}: the {self.name} side's process ({self.tree}) ended "
                             f"(exit {self.process.wait()}); its error is printed above")
        return json.loads(line)

    def close(self) -> None:
        if self.process.poll() is None:
            self.process.stdin.close()
            self.process.wait()


def time_solver_thread(spent: list[float]) -> bool:
    """Wrap ``pounding.simulation.integrate`` (the compiled solver's entry) so that each call appends its
    thread's CPU time (s, ``time.thread_time``) to *spent*; False if this tree has no such function."""
    import pounding.simulation as simulation

    solve = getattr(simulation, "integrate", None)
    if solve is None:
        return False

    def timed(*args, **kwargs):
        started = time.thread_time()
        try:
            return solve(*args, **kwargs)
        finally:
            spent.append(time.thread_time() - started)

    simulation.integrate = timed
    return True


def serve(answer: Callable[[dict], dict]) -> None:
    """A worker script's loop: each JSON request line on stdin answered by *answer* in one line on stdout.

    The library's own prints go to stderr meanwhile, so that they never mix with the answers.
    """
    replies, sys.stdout = sys.stdout, sys.stderr
    for line in sys.stdin:
        replies.write(json.dumps(answer(json.loads(line))) + "\n")
        replies.flush()


def checked(sides: list, check: Callable[[Any], None]) -> list:
    """*sides* (each with ``close()``), each passed to *check* (its first requests, timed by the caller);
    every side's process is closed if a check fails."""
    try:
        for side in sides:
            check(side)
    except BaseException:
        for side in sides:
            side.close()
        raise
    return sides
