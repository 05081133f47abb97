"""A run's results as plain arrays: what its archive holds, before it is made an ``xarray.Dataset``.

:func:`pounding.results.dataset.run_arrays` labels the solver's arrays as
variables, coordinates and attributes (``(dims, values, attrs)`` tuples, as
the ``xarray.Dataset`` constructor takes them); :meth:`RunArrays.to_dataset`
makes the archive of them.  A study's worker that keeps only some values of
each run (a sweep's peaks, a gap study's separations) reads them from the
:class:`RunArrays` directly: building the dataset (~25 ms a run) is the
largest part of such a run outside the compiled solver.

:class:`RunArrays` answers the few reads those workers make of an archive,
as a dataset would: ``name in run``, ``run[name].values``,
``run.name.values``, ``run.variables[name].values``, ``run.dims``,
``run.coords`` and ``run.attrs``.  The arrays are the ones the dataset
would hold (``numpy.asarray`` of the same values), so every value read is
the archive's, bit for bit.

A value may be left :class:`Deferred` (a history no worker of a study reads, e.g. the floors'
absolute accelerations): it is computed, by the same code, the first time it is read, and
:meth:`RunArrays.to_dataset` computes every one that is left.  A worker then pays only for the
values it reads.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from collections.abc import Mapping
from typing import Any, Callable, Iterator

import numpy as np

__all__ = ["RunArrays", "LabelledArray", "Deferred"]


class Deferred:
    """A value of a :class:`RunArrays` computed when first read: ``Deferred(compute)``, *compute* taking no
    argument.  Calling it computes the value once and returns it every time after."""

    __slots__ = ("_compute", "_value")

    def __init__(self, compute: Callable[[], Any]) -> None:
        self._compute: Callable[[], Any] | None = compute
        self._value: Any = None

    def __call__(self) -> Any:
        if self._compute is not None:
            self._value, self._compute = self._compute(), None
        return self._value


def _resolved(entries: dict[str, tuple], name: str) -> tuple:
    """*entries[name]* with a :class:`Deferred` value computed, stored back in *entries*."""
    entry = entries[name]
    if isinstance(entry[1], Deferred):
        entry = (entry[0], entry[1](), *entry[2:])
        entries[name] = entry
    return entry


@dataclass(frozen=True)
class LabelledArray:
    """One variable or coordinate of a :class:`RunArrays`: its dimensions and values."""

    dims: tuple[str, ...]
    values: np.ndarray

    @property
    def size(self) -> int:
        return int(self.values.size)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.values.shape)


@dataclass
class RunArrays:
    """A run's variables and coordinates (name → ``(dims, values, attrs)``) and its attributes.

    Attributes
    ----------
    data_vars, coordinates : dict
        As the ``xarray.Dataset`` constructor takes them.
    attrs : dict
        The archive's attributes (changed in place, as a dataset's are).
    """

    data_vars: dict[str, tuple]
    coordinates: dict[str, tuple]
    attrs: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._arrays: dict[str, LabelledArray] = {}

    def _entries(self, name: str) -> dict[str, tuple] | None:
        """The mapping (variables or coordinates) that holds *name*, None if neither does."""
        if name in self.data_vars:
            return self.data_vars
        return self.coordinates if name in self.coordinates else None

    def _array(self, name: str) -> LabelledArray:
        """Variable or coordinate *name* (computed first if :class:`Deferred`); KeyError if there is none."""
        found = self.__dict__["_arrays"].get(name)
        if found is None:
            entries = self._entries(name)
            if entries is None:
                raise KeyError(name)
            entry = _resolved(entries, name)
            dims = (entry[0],) if isinstance(entry[0], str) else tuple(entry[0])
            found = self._arrays[name] = LabelledArray(dims, np.asarray(entry[1]))
        return found

    def __contains__(self, name: object) -> bool:
        return name in self.data_vars or name in self.coordinates

    def __getitem__(self, name: str) -> LabelledArray:
        return self._array(name)

    def __getattr__(self, name: str) -> LabelledArray:
        if name.startswith("_") or "data_vars" not in self.__dict__:
            raise AttributeError(name)
        try:
            return self._array(name)
        except KeyError:
            raise AttributeError(name) from None

    @property
    def variables(self) -> Mapping[str, LabelledArray]:
        """Every variable and coordinate by name (as ``Dataset.variables``; a deferred one computed when read)."""
        return _Named(self, (*self.data_vars, *self.coordinates))

    @property
    def coords(self) -> Mapping[str, LabelledArray]:
        """The coordinates by name."""
        return _Named(self, tuple(self.coordinates))

    @property
    def dims(self) -> dict[str, int]:
        """Each dimension's length (from the values computed; a deferred one only if no other has its dimension).

        Found once: the values of a run do not change after it is made (its attributes may)."""
        if "_dims" not in self.__dict__:
            self.__dict__["_dims"] = self._found_dims()
        return self.__dict__["_dims"]

    def _found_dims(self) -> dict[str, int]:
        found: dict[str, int] = {}
        deferred = []
        for name, entry in (*self.data_vars.items(), *self.coordinates.items()):
            if isinstance(entry[1], Deferred) and name not in self._arrays:
                deferred.append(name)
                continue
            array = self._array(name)
            found.update(zip(array.dims, array.values.shape))
        for name in deferred:
            dims = self.data_vars[name][0] if name in self.data_vars else self.coordinates[name][0]
            if any(d not in found for d in ((dims,) if isinstance(dims, str) else dims)):
                array = self._array(name)
                found.update(zip(array.dims, array.values.shape))
        return found

    def to_dataset(self):
        """The run's archive: an ``xarray.Dataset`` of these variables, coordinates and attributes."""
        import xarray as xr

        for entries in (self.data_vars, self.coordinates):
            for name in list(entries):
                _resolved(entries, name)
        coords = xr.Coordinates({name: _coordinate(name, entry) for name, entry in self.coordinates.items()})
        data_vars = {name: xr.Variable(*entry) for name, entry in self.data_vars.items()}
        return xr.Dataset(data_vars, coords=coords, attrs=self.attrs)


def _coordinate(name: str, entry: tuple):
    """Coordinate *name* of ``(dims, values, attrs)`` *entry* as an ``xarray.Variable``.

    A dimension's own labels of strings (``floor``, ``contact``, ...) are given as the ``pandas.Index`` of
    object dtype xarray would make of them (its default index of an object array), so that xarray does not
    first pass them through a ``pandas.Series`` (~0.2 ms an array, where pandas infers a string dtype to
    turn back into the same objects).  Every other coordinate as given.
    """
    import pandas as pd
    import xarray as xr

    dims, values = entry[0], entry[1]
    if (dims == name or tuple(dims) == (name,)) and isinstance(values, np.ndarray) and values.dtype == object \
            and values.ndim == 1:
        return xr.IndexVariable(name, pd.Index(values, dtype=object, copy=False, name=name), *entry[2:])
    return xr.Variable(*entry)


class _Named(Mapping):
    """Some of a :class:`RunArrays`' values by name, each read (and computed, if deferred) when asked for."""

    def __init__(self, run: RunArrays, names: tuple[str, ...]) -> None:
        self._run, self._names = run, names

    def __getitem__(self, name: str) -> LabelledArray:
        if name not in self._names:
            raise KeyError(name)
        return self._run[name]

    def __contains__(self, name: object) -> bool:
        return name in self._names

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)
