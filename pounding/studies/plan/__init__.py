"""Studies on plan models (buildings with ``plan:``, docs/plan-models.md "Studies"): sweep, compare.

``sweep``    plan sweep files: axes over record pairs, angle of incidence, eccentricity, contact keys
``runs``     one plan scenario on a worker (its peaks), and the plan sweep's NetCDF layout
``compare``  ξ formulas (or with and without pounding) compared on plane drifts and corner displacements

The planar studies (:mod:`pounding.studies.sweep`, :mod:`~pounding.studies.compare`,
and :mod:`~pounding.studies.gap`, which serves every model) are untouched: the commands dispatch on :func:`is_plan_study_model`.
"""
