"""Studies built on many runs, all on one engine: parameter sweeps, ξ formulas compared, gap, IDA; the ball drop.

``engine``     the study engine: scenarios, task sources (static, adaptive), part keys, parts store, Dask
``common``     what the record studies share: the ``--records`` option, the record sweep, option checks
``sweep``      sweep files, scenarios, the results dataset (a static task source)
``compare``    ξ formulas compared on storey drifts (a sweep over ``xi``)
``gap``        the separation that avoids pounding, by simulation and by the code rules (every model)
``ida``        incremental dynamic analysis (records or record pairs): schedule, runs, hunt-and-fill (an adaptive
               source), dataset, report
``p695``       the FEMA P695 collapse evaluation (planar or plan buildings)
``fragility``  lognormal fragility fits and the collapse margin ratio
``plan``       sweep and compare on plan models (buildings with ``plan:``)
``verify``     the ball-drop test of Ye, Li & Zhu (2009, Table I)
"""
