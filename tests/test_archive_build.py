"""The archive a run builds: the same dataset as xarray's own constructor makes of the same arrays.

:meth:`RunArrays.to_dataset` builds the dataset from ``xarray.Variable``s and one ``xarray.Coordinates``
(a dimension's string labels given as their object ``pandas.Index``); these tests hold it to the dataset
``xarray.Dataset(data_vars, coords=..., attrs=...)`` makes of the very same arrays: every variable,
coordinate, index, attribute, dtype and value.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import pounding
from pounding.model.model import model_from_text
from pounding.results.run_arrays import RunArrays

MODELS = Path(__file__).resolve().parents[1] / "models"


def _plain(run: RunArrays) -> xr.Dataset:
    """The dataset xarray's constructor makes of *run*'s (resolved) arrays."""
    run.to_dataset()   # resolves every Deferred value in place
    return xr.Dataset(run.data_vars, coords=run.coordinates, attrs=run.attrs)


def _same(a: xr.Dataset, b: xr.Dataset) -> None:
    assert a.identical(b)
    assert list(a.variables) == list(b.variables) and list(a.coords) == list(b.coords)
    assert set(a.xindexes) == set(b.xindexes)
    for name in a.xindexes:
        assert a.xindexes[name].to_pandas_index().dtype == b.xindexes[name].to_pandas_index().dtype
    for name, v in a.variables.items():
        w = b.variables[name]
        assert (type(v), v.dims, v.dtype, v.attrs, v.encoding) == (type(w), w.dims, w.dtype, w.attrs, w.encoding)
        assert v.values.flags.writeable == w.values.flags.writeable
        if v.dtype == object:
            assert [type(x) for x in v.values.ravel()] == [type(x) for x in w.values.ravel()]
        else:
            assert v.values.tobytes() == w.values.tobytes()   # bit for bit, signed zeros and NaNs included


@pytest.mark.parametrize("name", ["pair", "corner_pair"])
def test_archive_is_the_dataset_xarray_makes_of_the_arrays(name, monkeypatch):
    import pounding.results.dataset as dataset
    import pounding.simulation as simulation

    runs = []
    inner = dataset.run_arrays

    def kept(*args, **kwargs):
        runs.append(inner(*args, **kwargs))
        return runs[-1]

    monkeypatch.setattr(dataset, "run_arrays", kept)
    ds = simulation.simulate(pounding.load_model(MODELS / f"{name}.yaml"))
    plain = _plain(runs[0])
    plain.attrs["energy_status"] = ds.attrs["energy_status"]   # set on the dataset after it is made
    _same(ds, plain)
    assert ds.floor.dtype == object and isinstance(ds.floor.values[0], str)


def test_a_string_index_of_one_label_and_an_empty_one():
    run = RunArrays({"x": (("a", "b"), np.zeros((1, 0)), {"units": "m"})},
                    {"a": ("a", np.array(["only"], dtype=object), {"long_name": "a"}),
                     "b": ("b", np.zeros(0, dtype=object), {}),
                     "c": ("a", np.array(["-0"], dtype=object), {})}, {"title": "t"})
    _same(run.to_dataset(), _plain(run))


def test_a_model_writes_its_yaml_once_and_a_derived_model_its_own():
    model = pounding.load_model(MODELS / "pair.yaml")
    text = model.to_yaml()
    assert model.to_yaml() is text
    derived = model.with_xi("exact")
    assert derived.to_yaml() != text and "xi: exact" in derived.to_yaml()
    assert model_from_text(text, name="pair").to_yaml().split("\n", 1)[1] == text.split("\n", 1)[1]
