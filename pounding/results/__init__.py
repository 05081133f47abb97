"""Results of a run: the labelled xarray dataset, its NetCDF archive and its plots.

``dataset``  solver output → ``xarray.Dataset`` with units and long names
``archive``  atomic NetCDF writing, reopening
``plots``    PNG figures of a run
``tables``   report tables of a run or sweep archive, and CSV writing (units in the headers)
``lazy_dask`` xarray without importing dask.array where no dask array is made
"""

from pounding.results.lazy_dask import defer_dask_import

defer_dask_import()   # xarray's datasets without importing dask.array (0.3-1.2 s a process): lazy_dask
