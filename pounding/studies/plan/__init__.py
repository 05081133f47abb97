"""Studies on plan models (buildings with ``plan:``, docs/plan-models.md "Studies"): sweep, compare, gap.

``sweep``    plan sweep files: axes over record pairs, angle of incidence, eccentricity, contact keys
``runs``     one plan scenario on a worker (its peaks), and the plan sweep's NetCDF layout
``compare``  ξ formulas (or with and without pounding) compared on plane drifts and corner displacements
``gap``      the separation per face and contact point under two-component records, and the rules' estimates

The planar studies (:mod:`pounding.studies.sweep`, :mod:`~pounding.studies.compare`,
:mod:`~pounding.studies.gap`) are untouched: the commands dispatch on :func:`is_plan_study_model`.
"""
