"""User-facing errors.

Every problem with a user's input is raised as a :class:`PoundingError` whose
message is one line naming the file, the place in it and the fix, e.g.::

    models/pair.yaml:14: buildings[1].storeys[3].mass must be > 0 (got -2.5e5)

The command-line interface prints that line on stderr and exits with status 2;
it never shows a traceback unless ``--debug`` is given.
"""

from __future__ import annotations


class PoundingError(Exception):
    """A problem the user can fix (bad model, bad record, bad option)."""

    def __init__(self, message: str, *, file: str | None = None, line: int | None = None):
        prefix = ""
        if file is not None:
            prefix = f"{file}:{line}: " if line is not None else f"{file}: "
        super().__init__(prefix + " ".join(str(message).split()))
        self.file = file
        self.line = line


class ModelError(PoundingError):
    """The building-model YAML is invalid."""


class RecordError(PoundingError):
    """A ground-motion record cannot be read or is invalid."""


class ArchiveError(PoundingError):
    """A results archive cannot be written or read."""


def did_you_mean(name: str, choices: list[str] | tuple[str, ...]) -> str:
    """Return ``' (did you mean 'x'?)'`` for the closest of *choices*, or ``''``."""
    import difflib

    folded = {str(c).lower(): str(c) for c in reversed(list(choices))}   # case-blind; the first spelling wins
    close = difflib.get_close_matches(str(name).lower(), list(folded), n=1, cutoff=0.5)
    return f" (did you mean '{folded[close[0]]}'?)" if close else ""
