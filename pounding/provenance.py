"""The command line being run, so that every archive it writes records how to write it again.

:func:`pounding.cli.main` holds the command (:func:`running`) while it runs;
:func:`pounding.results.archive.save_run` stamps :func:`command_attributes`
on every archive it writes then (``command``: the words as a shell would
take them, ``command_directory``: where they were typed, since file names in
them are relative to it).  An archive written from Python, outside the
command line, gets neither.  Light: the standard library only.
"""

from __future__ import annotations

import os
import shlex
from contextlib import contextmanager
from typing import Iterator, Sequence

__all__ = ["running", "command_attributes", "command_text"]

#: The command being run, ``("pounding", "run", ...)``, and its working directory; empty outside one.
_current: list[tuple[tuple[str, ...], str]] = []


@contextmanager
def running(argv: Sequence[str], program: str = "pounding") -> Iterator[None]:
    """Hold ``program argv...`` as the command being run until the block ends (nested calls stack)."""
    try:
        directory = os.getcwd()
    except OSError:   # the working directory was removed
        directory = ""
    _current.append(((program, *map(str, argv)), directory))
    try:
        yield
    finally:
        _current.pop()


def command_text(words: Sequence[str]) -> str:
    """*words* as one line a POSIX shell reads back as the same words (quoted where needed)."""
    return shlex.join(list(words))


def command_attributes() -> dict[str, str]:
    """``{"command": ..., "command_directory": ...}`` of the command being run; ``{}`` outside one."""
    if not _current:
        return {}
    words, directory = _current[-1]
    return {"command": command_text(words), "command_directory": directory}
