"""The cache a worker process keeps its modes, records, templates and side vectors in (pounding.recently_used)."""
from __future__ import annotations

import threading

import pytest

from pounding.recently_used import RecentlyUsed


def counted(values: dict):
    """A compute function per key that counts its calls in *values* (key -> calls)."""
    def compute_for(key):
        def compute():
            values[key] = values.get(key, 0) + 1
            return ("value of", key)
        return compute
    return compute_for


def test_a_kept_value_is_not_computed_again_and_the_least_recently_used_goes_first():
    calls: dict = {}
    compute = counted(calls)
    kept = RecentlyUsed(2)
    assert kept.get("a", compute("a")) == ("value of", "a")
    assert kept.get("b", compute("b")) == ("value of", "b")
    assert kept.get("a", compute("a")) == ("value of", "a")   # a hit: "a" is now the most recently used
    assert calls == {"a": 1, "b": 1}
    kept.get("c", compute("c"))   # a third key: "b", the least recently used, is dropped
    assert "a" in kept and "c" in kept and "b" not in kept and len(kept) == 2
    kept.get("b", compute("b"))
    assert calls == {"a": 1, "b": 2, "c": 1}
    assert "a" not in kept   # "a" was the least recently used when "b" came back


def test_find_does_not_compute_and_put_keeps_as_the_most_recently_used():
    kept = RecentlyUsed(2)
    assert kept.find("a") is None and len(kept) == 0   # a miss keeps nothing
    kept.put("a", 1)
    kept.put("b", 2)
    assert kept.find("a") == 1   # "a" now the most recently used
    kept.put("c", 3)
    assert [kept.find(k) for k in "abc"] == [1, None, 3]


def test_a_smaller_bound_drops_the_oldest_at_the_next_value_and_clear_drops_all():
    kept = RecentlyUsed(4)
    for k in "abcd":
        kept.put(k, k)
    kept.kept = 2
    kept.put("e", "e")
    assert [k for k in "abcde" if k in kept] == ["d", "e"]
    kept.clear()
    assert len(kept) == 0 and kept.find("e") is None


def test_a_failed_compute_keeps_nothing():
    kept = RecentlyUsed(2)

    def fails():
        raise OSError("no such record")

    with pytest.raises(OSError):
        kept.get("a", fails)
    assert "a" not in kept
    assert kept.get("a", lambda: 1) == 1


def test_threads_sharing_one_cache_never_see_more_than_kept_nor_another_keys_value():
    kept = RecentlyUsed(3)
    wrong = []

    def worker(seed: int) -> None:
        for i in range(2000):
            key = (seed * 7 + i) % 5
            value = kept.get(key, lambda key=key: ("value of", key))
            if value != ("value of", key):
                wrong.append((key, value))
            if len(kept) > 3:
                wrong.append(("size", len(kept)))

    threads = [threading.Thread(target=worker, args=(s,)) for s in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert wrong == [] and len(kept) == 3


def test_at_least_one_value_is_kept():
    with pytest.raises(ValueError, match="at least one"):
        RecentlyUsed(0)
