"""Memory a computation may plan to use, checked before it allocates.

Every layer that allocates in proportion to its input (a building's dense
modal matrices, a wave-passage lag, an archive read from disk, a run's
histories) asks :func:`check_memory` first, so that a request beyond
:data:`MEMORY_FRACTION` of what this process can use is one line naming the
number and the fix instead of a MemoryError (or the machine swapping).
"""

from __future__ import annotations

import os

from pounding.errors import PoundingError

__all__ = ["MEMORY_FRACTION", "available_memory", "check_memory", "format_bytes"]

#: A computation may plan to use at most this fraction of the memory available to it.
MEMORY_FRACTION = 0.5


def available_memory() -> int:
    """Bytes this process can still use: the smaller of physical RAM and the address-space limit left."""
    try:
        ram = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        ram = 2 ** 40
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            used = 0
            with open("/proc/self/status") as handle:
                for line in handle:
                    if line.startswith("VmSize:"):
                        used = int(line.split()[1]) * 1024
            ram = min(ram, max(0, soft - used))
    except (ImportError, OSError, ValueError):
        pass
    return int(ram)


def format_bytes(n: float) -> str:
    """``2.4 GB``, ``745 MB``, ``12 kB`` (decimal units)."""
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n / 1e3:.3g} kB"


def check_memory(needed: float, *, what: str, fix: str) -> None:
    """Refuse, with the numbers and the fix, to start something that needs more than
    :data:`MEMORY_FRACTION` of :func:`available_memory`.

    Raises
    ------
    PoundingError
        ``WHAT would need about N of memory, more than 50% of the M available; FIX``.
    """
    limit = MEMORY_FRACTION * available_memory()
    if not needed <= limit:   # also a NaN or infinite need
        shown = format_bytes(needed) if needed < 1e30 else "an unbounded amount"
        raise PoundingError(f"{what} would need about {shown} of memory, more than "
                            f"{MEMORY_FRACTION:.0%} of the {format_bytes(limit / MEMORY_FRACTION)} available; {fix}")
