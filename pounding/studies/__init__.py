"""Studies built on many runs: parameter sweeps, ξ-formula comparison and the ball-drop verification.

``sweep``    sweep files, scenarios, the parts store, Dask execution, the results dataset
``compare``  ξ formulas compared on storey drifts (a sweep over ``xi``)
``verify``   the ball-drop test of Ye, Li & Zhu (2009, Table I)
"""
