"""numba start-up and on-disk cache handling for the compiled solver.

The solver is compiled once per machine (``cache=True``) and loaded from
numba's cache by every later process.  Three things make that load fast and
safe:

* :func:`load_registries_without_scipy` — numba's registries are imported
  without the ``scipy.linalg`` import numba makes only to probe for BLAS
  (0.2–0.4 s of every process);
* :func:`load_from_cache_without_refresh` — a cached overload is loaded
  without first installing every typing and lowering registry (~0.2 s),
  which only compiling needs, and from the kernels compiled when the
  package was built (:data:`PREBUILT`) when numba's own cache has none, so
  that an installed pounding's first run does not compile (issue 24 §4);
* :func:`stamp_caches_with_sources` — a cached kernel is keyed on *every*
  source file compiled into it, not only its own, and on their contents
  (a hash), not their times: numba keys a cache entry on the function's file alone, so editing ``contact/laws.py`` or ``solver/kernels.py`` (a new contact
  law, a changed force) would otherwise leave the solver running the old
  contact kernels it inlined.

It also holds :data:`NO_REFCOUNT`, the options that compile the solver's
kernels without numba's reference counting (a third of the solver's time).

The first two change how numba loads code, through numba internals; they
are applied only on the numba versions they were tested on
(:data:`TESTED_NUMBA`, the same range as the ``numba`` pin in
``pyproject.toml``).  On any other version, or if an internal is not found,
numba is left to behave as it does by itself — slower to start, never wrong.
The third discards a cache index whenever any of the files changes (numba
alone: only its own), and keeps it while their contents stay the same, so
it is applied whenever numba's cache file has the stamp it replaces.
"""

from __future__ import annotations

import hashlib
import os
import sys
from typing import Iterable

__all__ = ["TESTED_NUMBA", "PYTHON_ONLY", "NO_REFCOUNT", "INLINED", "CALLED", "shortcuts_supported", "load_registries_without_scipy",
           "load_from_cache_without_refresh",
           "stamp_caches_with_sources", "source_stamp", "EXTRA_SOURCES", "solver_sources",
           "stamp_solver_kernels", "PREBUILT", "load_prebuilt", "prebuilt_status", "prebuilt_switched_off",
           "cache_folders"]

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
    """Let *dispatcher* load its cached machine code without a registry refresh, from numba's cache
    or else from the kernels built with the package (:data:`PREBUILT`).

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
            found = load(signature, target_context)
            return found if found is not None else load_prebuilt(cache, signature, target_context)
        return None  # the guard swallowed a spurious I/O error: compile instead

    cache.load_overload = load_overload


#: Folder of the kernels compiled when the package was built (``python -m pounding.prebuild``, run by
#: ``setup.py``'s build step): numba cache files (an index and its data files per kernel), keyed on a
#: hash of the solver's sources (:func:`source_stamp`) and on the machine they were compiled for.
#: Absent in a plain checkout; read, never written, by a run; ignored if the environment variable
#: ``POUNDING_PREBUILT`` is ``0`` (every kernel then comes from numba's cache or is compiled;
#: :func:`prebuilt_switched_off`); ``python -m pounding.prebuild --status`` says whether they are used.
PREBUILT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "prebuilt")


def load_prebuilt(cache, signature, target_context):
    """The overload of *signature* from :data:`PREBUILT`, or None (no folder, no such kernel, other
    sources, another numba or another CPU: numba's own checks on the index key and stamp).

    *cache* is the dispatcher's numba cache; the prebuilt index is read with its file name and its
    source stamp, so a kernel built from other sources than those installed is never loaded.
    """
    if prebuilt_switched_off() or not os.path.isdir(PREBUILT):
        return None
    from numba.core.caching import IndexDataCacheFile

    own = cache._cache_file
    prebuilt = IndexDataCacheFile(cache_path=PREBUILT, filename_base=own._index_name[:-len(".nbi")],
                                  source_stamp=own._source_stamp)
    try:
        data = prebuilt.load(cache._index_key(signature, target_context.codegen()))
        return None if data is None else cache._impl.rebuild(target_context, data)
    except Exception:  # a damaged or foreign file is a cache miss: numba compiles instead
        return None


def prebuilt_status() -> tuple[bool, str]:
    """Whether the kernels of :data:`PREBUILT` are used here, and one line saying why: absent,
    switched off (``POUNDING_PREBUILT``), or how many kernel files and whether they were built for
    the installed sources, numba and machine (else they are ignored).  Call after importing
    ``pounding.solver.kernels`` (which adds the law modules it compiles to :data:`EXTRA_SOURCES`), as
    ``python -m pounding.prebuild --status`` does."""
    import pickle

    import numba

    indexes = sorted(name for name in os.listdir(PREBUILT) if name.endswith(".nbi")) if os.path.isdir(PREBUILT) else []
    if not indexes:
        return False, f"no prebuilt kernels in {PREBUILT}: compiled on first use"
    files = len([name for name in os.listdir(PREBUILT) if name.endswith((".nbi", ".nbc"))])
    if prebuilt_switched_off():
        return False, f"{files} prebuilt kernel files ignored: POUNDING_PREBUILT={os.environ['POUNDING_PREBUILT']}"
    with open(os.path.join(PREBUILT, indexes[0]), "rb") as index:
        version = pickle.load(index)
        stamp, overloads = pickle.loads(index.read())
    if version != numba.__version__:
        return False, f"{files} prebuilt kernel files built with numba {version}, not {numba.__version__}: ignored"
    if stamp != source_stamp(solver_sources()):
        return False, f"{files} prebuilt kernel files built from other solver sources: ignored"
    from numba.core.registry import cpu_target

    machine = cpu_target.target_context.codegen().magic_tuple()
    if all(key[1] != machine for key in overloads):
        return False, f"{files} prebuilt kernel files built for another machine ({next(iter(overloads))[1][1]}): ignored"
    return True, f"{files} prebuilt kernel files for these sources, numba {version} and this machine in {PREBUILT}"


def prebuilt_switched_off() -> bool:
    """True if the environment variable ``POUNDING_PREBUILT`` turns :data:`PREBUILT` off (``0``, ``no``,
    ``false``, ``off``: the words setup.py accepts for ``POUNDING_PREBUILD``, which cannot import this)."""
    return os.environ.get("POUNDING_PREBUILT", "").strip().lower() in ("0", "no", "false", "off")


def cache_folders() -> list[str]:
    """The folders numba caches the solver's kernels in (those stamped so far; ``pounding.prebuild``
    copies them)."""
    return sorted(_CACHE_FOLDERS)


_CACHE_FOLDERS: set[str] = set()


#: Source files compiled into every solver kernel besides the ones each stamp names: the modules of
#: contact laws written in files of their own (pounding.solver.kernels adds them; those of the
#: package are in :func:`solver_sources` already, a law of another package is not), so that
#: editing one discards the cached solver as editing contact/laws.py does.
EXTRA_SOURCES: list[str] = []


def source_stamp(files: Iterable[str | os.PathLike]) -> tuple[str, str]:
    """``("sha256", digest)`` of the names and contents of *files* and :data:`EXTRA_SOURCES`: the
    stamp numba keeps with a cache index.  A hash of the contents, not numba's (mtime, size), so
    that kernels compiled from the same sources elsewhere (:data:`PREBUILT`) are recognised, and a
    file saved again unchanged does not discard the cache."""
    digest = hashlib.sha256()
    for name in dict.fromkeys([*map(str, files), *EXTRA_SOURCES]):
        digest.update(os.path.basename(name).encode())
        digest.update(_file_digest(name))
    return "sha256", digest.hexdigest()


def _file_digest(name: str) -> bytes:
    """SHA-256 of the file *name*, remembered per (path, mtime, size) for the process's 13 stamps."""
    status = os.stat(name)
    key = (os.path.abspath(name), status.st_mtime_ns, status.st_size)
    if key not in _DIGESTS:
        with open(name, "rb") as source:
            _DIGESTS[key] = hashlib.sha256(source.read()).digest()
    return _DIGESTS[key]


_DIGESTS: dict[tuple[str, int, int], bytes] = {}


def stamp_caches_with_sources(dispatchers: Iterable, files: Iterable[str | os.PathLike]) -> None:
    """Key the on-disk cache of each of *dispatchers* on all of *files*.

    numba stores, with each cache index, the (mtime, size) of the function's
    own source file and discards the index when they change.  A kernel that
    inlines functions from other files must be discarded when *those* change
    too, so its stamp is replaced by :func:`source_stamp` over *files* (its
    own file included): a hash of their contents.  Must be called before the
    dispatcher's first call.
    """
    stamp = source_stamp(list(files))
    for dispatcher in dispatchers:
        cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
        if cache_file is not None and hasattr(cache_file, "_source_stamp"):
            cache_file._source_stamp = stamp


#: Solver modules no kernel is compiled from or reads (the model's lowering into arrays, the tolerance
#: factors): editing them keeps the compiled kernels.
PYTHON_ONLY = ("assembly.py", "tolerances.py")


def solver_sources() -> list[str]:
    """Every source file compiled into the solver's kernels: the modules of ``pounding/solver``
    (but :data:`PYTHON_ONLY`) and of ``pounding/contact`` (the contact laws, links and ξ formulas whose ids, sizes and
    forces they inline, a law in a file of its own included) and ``pounding/hysteresis.py``.
    The same list whichever module is imported first, so every kernel has the same stamp."""
    solver = os.path.dirname(os.path.abspath(__file__))
    package = os.path.dirname(solver)
    contact = os.path.join(package, "contact")
    own = sorted(os.path.join(solver, name) for name in os.listdir(solver)
                 if name.endswith(".py") and name not in PYTHON_ONLY)
    laws = sorted(os.path.join(contact, name) for name in os.listdir(contact) if name.endswith(".py"))
    return own + laws + [os.path.join(package, "hysteresis.py")]


def stamp_solver_kernels(namespace: dict) -> None:
    """Key the cache of every compiled kernel in *namespace* (a solver module's ``globals()``) on
    :func:`solver_sources`: a kernel calls and inlines kernels of the other solver modules, so its
    cached code is stale when any of them changes.  Called at the end of each solver module."""
    from numba.core.dispatcher import Dispatcher

    kernels = [f for f in namespace.values() if isinstance(f, Dispatcher)]
    stamp_caches_with_sources(kernels, solver_sources())
    for kernel in kernels:
        load_from_cache_without_refresh(kernel)
        folder = getattr(getattr(kernel, "_cache", None), "_cache_path", None)
        if folder is not None:
            _CACHE_FOLDERS.add(folder)
