"""Results of a run: the labelled xarray dataset, its NetCDF archive and its plots.

``dataset``  solver output → ``xarray.Dataset`` with units and long names
``archive``  atomic NetCDF writing, reopening
``plots``    PNG figures of a run
``tables``   report tables of a run or sweep archive, and CSV writing (units in the headers)
``lazy_dask`` xarray without importing dask.array where no dask array is made
"""
