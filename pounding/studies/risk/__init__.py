"""The risk of pounding and of collapse at a site: ``pounding risk``.

A multi-stripe analysis of a model (the IDA's stripes, with and without contacts) is integrated over the
site's hazard curve: the annual frequency and 50-year probability of pounding at every separation of each
contact, the separation that meets a target, and each building's collapse risk with and without pounding.
See ``docs/risk.md``.

Modules
    ``hazard``     the hazard curve: a file (g, 1/yr) or a power law
    ``integrals``  λ = ∫ P(E | IM) |dλ_IM| for a lognormal fragility or per-stripe demands
    ``measures``   the intensity measures (pga, sa-t1, sa:T, sa-avg:T1,T2)
    ``study``      the plan, the runs on the study engine
    ``report``     the archive, the printed table, CSV tables and the figure
"""

from __future__ import annotations

from pounding.studies.risk.hazard import HazardCurve, power_law, read_hazard
from pounding.studies.risk.report import plot_risk, risk_table, risk_tables
from pounding.studies.risk.study import RiskPlan, build_risk_plan, default_levels, risk_study

__all__ = ["HazardCurve", "power_law", "read_hazard", "RiskPlan", "build_risk_plan", "default_levels", "risk_study",
           "risk_table", "risk_tables", "plot_risk"]
