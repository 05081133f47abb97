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
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["RunArrays", "LabelledArray"]


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
        for name, entry in (*self.data_vars.items(), *self.coordinates.items()):
            dims = (entry[0],) if isinstance(entry[0], str) else tuple(entry[0])
            self._arrays[name] = LabelledArray(dims, np.asarray(entry[1]))

    def __contains__(self, name: object) -> bool:
        return name in self._arrays

    def __getitem__(self, name: str) -> LabelledArray:
        return self._arrays[name]

    def __getattr__(self, name: str) -> LabelledArray:
        arrays = self.__dict__.get("_arrays", {})
        if name in arrays:
            return arrays[name]
        raise AttributeError(name)

    @property
    def variables(self) -> dict[str, LabelledArray]:
        """Every variable and coordinate by name (as ``Dataset.variables``)."""
        return self._arrays

    @property
    def coords(self) -> dict[str, LabelledArray]:
        """The coordinates by name."""
        return {name: self._arrays[name] for name in self.coordinates}

    @property
    def dims(self) -> dict[str, int]:
        """Each dimension's length."""
        found: dict[str, int] = {}
        for array in self._arrays.values():
            found.update(zip(array.dims, array.values.shape))
        return found

    def to_dataset(self):
        """The run's archive: an ``xarray.Dataset`` of these variables, coordinates and attributes."""
        import xarray as xr

        return xr.Dataset(self.data_vars, coords=self.coordinates, attrs=self.attrs)
