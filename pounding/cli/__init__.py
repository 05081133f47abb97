"""Command-line interface: the ``pounding`` parser, one-line errors and the console entry point.

Every user error is printed as one line on stderr (``pounding: error: …``)
with exit status 2; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import argparse
import errno
import gc
import importlib
import os
import sys
from typing import Callable, NoReturn, Sequence

from pounding import __version__
from pounding.errors import PoundingError

__all__ = ["main", "console_main", "exit_at_once", "build_parser", "SUBCOMMAND_MODULES"]

#: Modules that add their own subcommand through ``register_cli(subparsers)``, by
#: subcommand name; their heavy imports happen inside the handlers, not at registration.
SUBCOMMAND_MODULES = {"verify": "pounding.cli.verify", "sweep": "pounding.cli.sweep",
                      "compare": "pounding.cli.compare", "records": "pounding.cli.records",
                      "export": "pounding.cli.export", "gap": "pounding.cli.gap", "ida": "pounding.cli.ida",
                      "init": "pounding.cli.init", "spectrum": "pounding.cli.spectrum",
                      "table": "pounding.cli.table", "hysteresis": "pounding.cli.hysteresis",
                      "pushover": "pounding.cli.pushover", "p695": "pounding.cli.p695",
                      "risk": "pounding.cli.risk", "report": "pounding.cli.report", "animate": "pounding.cli.animate"}


# --------------------------------------------------------------------------- #
# Parser
# --------------------------------------------------------------------------- #


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (after the usage of the subcommand concerned)."""

    def error(self, message: str):  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {' '.join(str(message).split())}\n")


def _leaves(parser: argparse.ArgumentParser):
    """Every parser below *parser* that has no subcommands of its own (``run``, ``xi list`` …)."""
    groups = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not groups:
        yield parser
        return
    for group in groups:
        for child in dict.fromkeys(group.choices.values()):
            yield from _leaves(child)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``pounding`` argument parser.

    Parameters
    ----------
    command : str, optional
        The subcommand about to be parsed.  A subcommand of this module
        (``run``, ``info`` …) needs none of the modules in
        :data:`SUBCOMMAND_MODULES`, and one of theirs needs only its own, so
        the others are not imported (0.05 s of a run's start-up).  ``None``
        (help, or an unknown command) registers every subcommand.
    """
    parser = Parser(prog="pounding", description="Structural pounding of adjacent buildings.",
                    epilog="`pounding COMMAND --help` describes each command.")
    parser.add_argument("--version", action="version", version=f"pounding {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks instead of one-line errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    from pounding.cli import run as run_commands  # light: its handlers import what they need

    run_commands.register_cli(sub)

    if command in sub.choices:  # one of the run subcommands: no other module needed
        needed = {}
    elif command in SUBCOMMAND_MODULES:  # only the module that defines it
        needed = {command: SUBCOMMAND_MODULES[command]}
    else:  # help or an unknown word: all, so that usage lists every choice
        needed = SUBCOMMAND_MODULES
    for module_name in needed.values():
        importlib.import_module(module_name).register_cli(sub)
    for leaf in _leaves(parser):
        if leaf is parser:
            continue
        # --debug also after the subcommand; SUPPRESS keeps the top-level value when absent here
        leaf.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                          help="show tracebacks instead of one-line errors")
        leaf.set_defaults(usage_parser=leaf)
    return parser


def _subcommand(argv: Sequence[str]) -> str | None:
    """The first word of *argv* that is not an option (the subcommand), if any."""
    return next((a for a in argv if not a.startswith("-")), None)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pounding`` console script."""
    argv = sys.argv[1:] if argv is None else list(argv)
    _tolerant_streams()
    parser = build_parser(_subcommand(argv))
    args, extra = parser.parse_known_args(argv)
    if extra:  # reported with the usage of the subcommand concerned, not the top-level one
        getattr(args, "usage_parser", parser).error(f"unrecognized arguments: {' '.join(extra)}")
    func: Callable[[argparse.Namespace], int] = args.func
    from pounding.provenance import running

    try:
        with running(argv):   # every archive written meanwhile records this command (`pounding report`)
            status = func(args)
        if sys.stdout is not None:
            sys.stdout.flush()  # a full or failing stdout shows here, not as a traceback at exit
        return status
    except PoundingError as exc:
        if args.debug:
            raise
        print(f"pounding: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("pounding: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader went away (`pounding records list | head`): stop quietly, as Unix tools do.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error when Python flushes stdout
        return 141  # 128 + SIGPIPE
    except OSError as exc:
        if args.debug or exc.errno not in _STREAM_ERRNOS:
            raise
        _silence_stdout()
        print(f"pounding: error: cannot write the output ({exc.strerror or exc}); is standard output a full "
              "disk or a closed file?", file=sys.stderr)
        return 2


#: errno of a failing standard output (full disk, I/O error, closed descriptor).
_STREAM_ERRNOS = frozenset({errno.ENOSPC, errno.EIO, errno.EBADF, errno.EDQUOT, errno.EFBIG})


def _tolerant_streams() -> None:
    """Print names the locale cannot encode (non-UTF-8 locale, non-ASCII names) as escapes, not a traceback."""
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None and hasattr(stream, "reconfigure") and \
                    str(getattr(stream, "encoding", "")).lower().replace("-", "") != "utf8":
                stream.reconfigure(errors="backslashreplace")
        except (OSError, ValueError):
            pass


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that Python's final flush does not fail a second time."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


#: Subcommands that never use dask in their own process (everything but sweep/compare).
LEAN_COMMANDS = frozenset({"run", "rerun", "info", "plot", "xi", "verify", "records", "export", "table", "report"})

#: Subcommands of one run (or one archive read) whose process is set up for a short life
#: (:func:`console_main`): no cyclic garbage collector, and OpenBLAS on one thread.
SHORT_COMMANDS = frozenset({"run", "rerun", "info"})


def console_main(*, exit_when_done: bool = True) -> int:
    """Entry point of the ``pounding`` console script and ``python -m pounding``.

    For the subcommands that never use dask, dask is marked absent before
    anything imports it: xarray imports dask (and, when writing NetCDF,
    dask.distributed) merely to ask whether arrays are dask arrays, which
    costs about 0.5 s of a 2 s ``pounding run``.  Only this process-level
    entry point does it; :func:`main` called from Python leaves imports alone.

    The commands of :data:`SHORT_COMMANDS` (one run, or one archive read)
    also get a process made for a short life, worth 0.25 s of a 1 s warm
    ``pounding run models/pair.yaml`` on a 2-core machine:

    * the cyclic garbage collector is off and, at the end, every object is
      frozen (:func:`gc.freeze`): a whole run leaves only ~2,300 objects of
      cyclic garbage, while the collector would traverse the ~130,000 objects
      the imports create some 350 times (0.07 s) and again at shutdown
      (0.1 s); reference counting still frees everything not in a cycle;
    * pydantic loads no plugins unless ``PYDANTIC_DISABLE_PLUGINS`` says
      otherwise: looking for them reads the entry points of every installed
      distribution (0.03 s with ~180 of them), for plugins that only observe
      validation, which a run's model needs none of;
    * OpenBLAS runs on one thread unless ``OPENBLAS_NUM_THREADS`` says
      otherwise: its worker threads, started when numpy loads, cost 0.05 s of
      start-up and spin for nothing, since a run's matrices (modal analysis)
      are far below OpenBLAS's threading threshold (every fingerprint is the
      same either way);
    * with *exit_when_done* (the console script, ``python -m pounding``), the
      process ends as soon as the command has returned: the exit handlers
      run and the standard streams are flushed, the interpreter's teardown
      of every module and object (~25 ms; every file the command wrote is
      closed by then) is skipped (:func:`exit_at_once`).
    """
    argv = sys.argv[1:]
    command = _subcommand(argv)
    if command in LEAN_COMMANDS:
        for name in ("dask", "distributed"):
            sys.modules.setdefault(name, None)  # type: ignore[arg-type]
    if command not in SHORT_COMMANDS:
        return main(argv)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")   # read when numpy loads OpenBLAS, later
    os.environ.setdefault("PYDANTIC_DISABLE_PLUGINS", "__all__")   # read at the first model class, later
    gc.disable()
    try:
        status = main(argv)
    finally:
        gc.freeze()   # the shutdown's collections then skip every object the command made
    if exit_when_done:
        exit_at_once(status)
    return status


def exit_at_once(status: int) -> NoReturn:
    """End the process with *status* now: exit handlers run, standard streams flushed, no teardown."""
    import atexit

    atexit._run_exitfuncs()   # CPython's own exit step (logging, tempfile and multiprocessing handlers)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    os._exit(status)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(console_main())
