"""numba start-up and on-disk cache handling for the compiled solver.

The solver is compiled once per machine (``cache=True``) and loaded from
numba's cache by every later process.  Three things make that load fast and
safe:

* :func:`load_registries_without_scipy` — numba's registries are imported
  without the ``scipy.linalg`` import numba makes only to probe for BLAS
  (0.2–0.4 s of every process);
* :func:`load_from_cache_without_refresh` — a cached overload is loaded
  without first installing every typing and lowering registry (~0.2 s),
  which only compiling needs;
* :func:`stamp_caches_with_sources` — a cached kernel is keyed on *every*
  source file compiled into it, not only its own: numba keys a cache entry
  on the function's file alone, so editing ``contact/laws.py`` or ``solver/kernels.py`` (a new contact
  law, a changed force) would otherwise leave the solver running the old
  contact kernels it inlined.

It also holds :data:`NO_REFCOUNT`, the options that compile the solver's
kernels without numba's reference counting (a third of the solver's time).

The first two change how numba loads code, through numba internals; they
are applied only on the numba versions they were tested on
(:data:`TESTED_NUMBA`, the same range as the ``numba`` pin in
``pyproject.toml``).  On any other version, or if an internal is not found,
numba is left to behave as it does by itself — slower to start, never wrong.
The third only ever discards a cache index that numba would have kept, so
it is applied whenever numba's cache file has the stamp it replaces.
"""

from __future__ import annotations

import os
import sys
from typing import Iterable

__all__ = ["TESTED_NUMBA", "NO_REFCOUNT", "INLINED", "CALLED", "shortcuts_supported", "load_registries_without_scipy",
           "load_from_cache_without_refresh",
           "stamp_caches_with_sources", "source_stamp", "EXTRA_SOURCES", "solver_sources",
           "stamp_solver_kernels"]

#: numba releases (major, minor) the start-up shortcuts were tested on; keep in step with
#: the ``numba`` pin in pyproject.toml, and widen both only after tests/test_jit.py passes.
TESTED_NUMBA = ((0, 67), (0, 68))


def shortcuts_supported() -> bool:
    """True if the installed numba is one of :data:`TESTED_NUMBA` (read at each call)."""
    import numba

    parts = str(getattr(numba, "__version__", "")).split(".")
    try:
        release = (int(parts[0]), int(parts[1]))
    except (IndexError, ValueError):
        return False
    return release in TESTED_NUMBA


#: numba options of a kernel that neither allocates an array nor returns one: compiled without
#: numba's reference counting (its ``_nrt`` option).  Such a kernel only reads and writes arrays
#: its caller owns for the whole call, so counting them buys nothing; with counting, every call
#: increments and decrements each array argument's count with an atomic instruction, which was
#: a third of the solver's time (the right-hand side alone takes ~30 arrays, six times a step).
#: numba refuses to compile an allocation in such a kernel, so the option cannot free an array in
#: use.  Applied on the numba releases of :data:`TESTED_NUMBA` only, like the start-up shortcuts.
NO_REFCOUNT: dict = {"_nrt": False} if shortcuts_supported() else {}

#: numba options of a kernel the driver calls on every step or output sample: inlined into its
#: caller by LLVM (numba's ``forceinline``: the LLVM ``alwaysinline`` attribute; the kernel is
#: still compiled, typed and cached once, as its own function).  numba passes every member of a
#: record argument as separate words on the stack (an array as 7), so a call taking ``work``,
#: ``structure``, ``contacts``, ``cstate`` and ``storey`` copies ~300 words: on the small models
#: these copies were most of the driver's own time (``perf``: 72 % of its samples on ``push``
#: instructions), and the solver-only time of isolated_moat.yaml 1.6x that of 20c2fbe (issue 24).
#: Inlined, the records are the caller's values and nothing is copied.  Results are bit-identical
#: (inlining changes no floating-point operation: no fast-math).
INLINED: dict = {"forceinline": True}

#: numba options of every other solver kernel: ``forceinline`` set (to False) explicitly.  numba
#: copies an unset ``forceinline`` from the compilation that triggers it, so a kernel first
#: compiled while numba compiles an :data:`INLINED` caller would otherwise be forced inline
#: everywhere (growing the compile time), depending on which model compiled it first.
CALLED: dict = {"forceinline": False}


def load_registries_without_scipy() -> None:
    """Import numba's implementation registries without importing ``scipy.linalg``.

    numba's first compilation or cache load in a process imports
    ``numba.np.arraymath``, which tries ``import scipy.linalg.cython_blas``
    only to decide how *np.correlate* and *np.convolve* take inner products.
    The solver uses no BLAS, so the probe is answered "absent" while that
    module is imported; the marker is removed at once, so ``import
    scipy.linalg`` works normally afterwards, and numba functions that need
    BLAS (``np.dot``, ``np.linalg``) still import it when they are compiled.
    Nothing is done if scipy.linalg or the registry module is already imported,
    or on a numba version outside :data:`TESTED_NUMBA`.
    """
    if not shortcuts_supported():
        return
    blas = "scipy.linalg.cython_blas"
    if "numba.np.arraymath" in sys.modules or blas in sys.modules:
        return
    sys.modules[blas] = None  # type: ignore[assignment]  # makes the import raise ImportError
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if sys.modules.get(blas, 0) is None:
            del sys.modules[blas]


def load_from_cache_without_refresh(dispatcher) -> None:
    """Let *dispatcher* load its cached machine code without a registry refresh.

    Before loading a cached overload, numba refreshes its target context: it
    installs every typing and lowering registry (thousands of
    implementations), which only *compiling* needs.  Running cached code
    needs the compiled library and numba's runtime (NRT) symbols, so this
    loader initialises the runtime and loads the library.  On a cache miss
    nothing changes: numba's compiler refreshes the context itself before it
    compiles (``CompilerBase.__init__``).  Nothing is done on a numba version
    outside :data:`TESTED_NUMBA`.
    """
    if not shortcuts_supported():
        return
    try:
        from numba.core.runtime import rtsys

        cache = dispatcher._cache
        load = cache._load_overload
        guard = cache._guard_against_spurious_io_errors
    except (ImportError, AttributeError):  # pragma: no cover - other numba internals
        return

    def load_overload(signature, target_context):
        rtsys.initialize(target_context)
        with guard():
            return load(signature, target_context)
        return None  # the guard swallowed a spurious I/O error: compile instead

    cache.load_overload = load_overload


#: Source files compiled into every solver kernel besides the ones each stamp names: the modules of
#: contact laws written in files of their own (pounding.solver.kernels adds them), so that editing
#: one discards the cached solver as editing contact/laws.py does.
EXTRA_SOURCES: list[str] = []


def source_stamp(files: Iterable[str | os.PathLike]) -> tuple[float, int]:
    """(newest modification time, total size) of *files* and :data:`EXTRA_SOURCES`: numba's source stamp."""
    stats = [os.stat(f) for f in dict.fromkeys([*map(str, files), *EXTRA_SOURCES])]
    return max(s.st_mtime for s in stats), sum(s.st_size for s in stats)


def stamp_caches_with_sources(dispatchers: Iterable, files: Iterable[str | os.PathLike]) -> None:
    """Key the on-disk cache of each of *dispatchers* on all of *files*.

    numba stores, with each cache index, the (mtime, size) of the function's
    own source file and discards the index when they change.  A kernel that
    inlines functions from other files must be discarded when *those* change
    too, so its stamp is replaced by :func:`source_stamp` over *files* (its
    own file included).  Must be called before the dispatcher's first call.
    """
    stamp = source_stamp(list(files))
    for dispatcher in dispatchers:
        cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
        if cache_file is not None and hasattr(cache_file, "_source_stamp"):
            cache_file._source_stamp = stamp


def solver_sources() -> list[str]:
    """Every source file compiled into the solver's kernels: the modules of ``pounding/solver``
    and the contact-law, link and hysteresis modules whose ids and sizes they inline."""
    solver = os.path.dirname(os.path.abspath(__file__))
    package = os.path.dirname(solver)
    own = sorted(os.path.join(solver, name) for name in os.listdir(solver) if name.endswith(".py"))
    return own + [os.path.join(package, "contact", "laws.py"), os.path.join(package, "contact", "links.py"),
                  os.path.join(package, "hysteresis.py")]


def stamp_solver_kernels(namespace: dict) -> None:
    """Key the cache of every compiled kernel in *namespace* (a solver module's ``globals()``) on
    :func:`solver_sources`: a kernel calls and inlines kernels of the other solver modules, so its
    cached code is stale when any of them changes.  Called at the end of each solver module."""
    from numba.core.dispatcher import Dispatcher

    stamp_caches_with_sources([f for f in namespace.values() if isinstance(f, Dispatcher)], solver_sources())
