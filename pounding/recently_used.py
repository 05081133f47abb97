"""What a process keeps of what it computed: the last few values by key, safe across threads.

A study's worker meets the same few things in every run (a building's modes, a record read and
processed, a validated model, a model's gap side vectors): each is computed once per process and
kept by a key that says exactly what it was computed from.  :class:`RecentlyUsed` is that cache,
one class for all of them: get-or-compute by key, the ``kept`` most recently used values kept,
the least recently used dropped first.
"""
from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

__all__ = ["RecentlyUsed"]

V = TypeVar("V")


class RecentlyUsed(Generic[V]):
    """The last ``kept`` values by key, least recently used dropped first; thread-safe.

    Parameters
    ----------
    kept : int
        How many values are kept (at least 1).  ``kept`` may be changed later; the next value kept
        drops what no longer fits.

    Notes
    -----
    The lock is held only to read and write the table, never while a value is computed: two
    threads that miss the same key both compute it, and the later one's value is kept.  Values
    should be immutable (read-only arrays, frozen records): every caller shares the one kept.
    """

    def __init__(self, kept: int) -> None:
        if kept < 1:
            raise ValueError(f"RecentlyUsed keeps at least one value, not {kept}")
        self.kept = kept
        self._values: OrderedDict[Hashable, V] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: Hashable, compute: Callable[[], V]) -> V:
        """The value kept for *key*, or ``compute()`` kept for it: either way now the most recently used."""
        value = self.find(key)
        if value is None:
            value = compute()
            self.put(key, value)
        return value

    def find(self, key: Hashable) -> V | None:
        """The value kept for *key*, now the most recently used, or None (nothing computed, nothing kept)."""
        with self._lock:
            if key not in self._values:
                return None
            self._values.move_to_end(key)
            return self._values[key]

    def put(self, key: Hashable, value: V) -> None:
        """Keep *value* for *key* as the most recently used, dropping the least recently used beyond ``kept``."""
        with self._lock:
            self._values[key] = value
            self._values.move_to_end(key)
            while len(self._values) > max(1, self.kept):
                self._values.popitem(last=False)

    def clear(self) -> None:
        """Drop every kept value: the next :meth:`get` of any key computes it again."""
        with self._lock:
            self._values.clear()

    def __contains__(self, key: Hashable) -> bool:
        with self._lock:
            return key in self._values

    def __len__(self) -> int:
        with self._lock:
            return len(self._values)
