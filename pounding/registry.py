"""Registries keyed by name (contact laws, ξ formulas, storey hysteresis, separation rules).

Each registry is a plain ``dict``; :func:`add_unique` is how every one of them
takes a new entry, so a name is taken once everywhere.
"""

from __future__ import annotations

from typing import Any, MutableMapping

__all__ = ["add_unique"]


def add_unique(registry: MutableMapping[str, Any], key: str, value: Any, kind: str) -> None:
    """Put *value* under *key*; a key already present is refused.

    Raises
    ------
    ValueError
        ``<kind> '<key>' is registered twice``.
    """
    if key in registry:
        raise ValueError(f"{kind} '{key}' is registered twice")
    registry[key] = value
