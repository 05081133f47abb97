"""The gap study on plan models (docs/plan-models.md "Studies"), until it joins :mod:`pounding.studies.gap`.

``gap``      the separation per face and contact point under two-component records, and the rules' estimates

Sweeps and compares of every model are :mod:`pounding.studies.sweep` and :mod:`pounding.studies.compare`.
"""
