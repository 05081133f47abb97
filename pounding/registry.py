"""Registries keyed by name (contact laws, link laws, ξ formulas, storey hysteresis, separation rules).

Each registry is a plain ``dict``; :func:`add_unique` is how every one of them
takes a new entry, so a name is taken once everywhere.  :func:`lookup` is how
every one of them is read by name: exactly, by an alias, or ignoring case
(``Hertz-Damp``, ``YE``, ``--xi Exact``).  Registries whose
entries select a branch of the compiled solver number them with
:func:`add_numbered`: the id is the entry's place in the registry, so no id is
written by hand and none is taken twice.
"""

from __future__ import annotations

from typing import Any, Mapping, MutableMapping

__all__ = ["add_unique", "add_numbered", "lookup"]


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


def add_numbered(registry: MutableMapping[str, Any], cls: type, kind: str, id_attribute: str, first: int = 0) -> type:
    """Register class *cls* under ``cls.name`` and give it the id ``first + (its place in the registry)``.

    The id is set as the class attribute *id_attribute* (``law_id``,
    ``model_id``): the branch of the compiled kernels the class selects.
    Registration order is the id order, so ids are dense and never shared.

    Raises
    ------
    ValueError
        If ``cls.name`` is registered already (:func:`add_unique`).
    """
    number = first + len(registry)
    add_unique(registry, cls.name, cls, kind)
    setattr(cls, id_attribute, number)
    return cls


def lookup(registry: Mapping[str, Any], name: object, aliases: Mapping[str, str] | None = None) -> str | None:
    """The key of *registry* that *name* names, or None if it names none.

    *name* matches a key or an alias (alias → key) as written, else ignoring
    case and surrounding spaces, so ``Hertz-Damp``, ``YE`` and ``' exact '``
    name ``hertz-damp``, ``ye`` and ``exact``.  Callers word the unknown-name
    error with :func:`pounding.errors.did_you_mean` (also case-blind).
    """
    if not isinstance(name, str):
        return None
    aliases = aliases or {}
    key = aliases.get(name, name)
    if key in registry:
        return key
    folded = {k.lower(): aliases.get(k, k) for k in (*aliases, *registry)}
    return folded.get(name.strip().lower())
