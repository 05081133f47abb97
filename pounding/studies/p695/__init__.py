"""The FEMA P695 collapse evaluation (FEMA 2009, "Quantification of Building Seismic Performance Factors"):
``pounding p695``.  See ``docs/p695.md``.

Modules
    ``tables``   the methodology's tables (Tables 5-1A/B, 7-1a/b, 7-2a-d, 7-3; ASCE 7 Tables 12.8-1/2), read from
                 ``pounding/data/p695/tables.yaml``, with their interpolation
    ``verdict``  T, S_MT, beta_TOT, ACMR and the verdict, in g
    ``study``    the study: pushover, hunt-and-fill IDA per building (with and without contacts), the archive
    ``report``   the printed table, the JSON summary, the plot
"""

from __future__ import annotations

from pounding.studies.p695.report import VERDICT_WORDS, p695_summary, p695_table, plot_p695, pounding_effect
from pounding.studies.p695.study import (DEFAULT_RECORDS, OUTCOMES, P695Inputs, collapse_intensities, ida_folder,
                                         median_collapse, outcome_counts, p695_study, parse_systems)
from pounding.studies.p695.tables import SDCS, SYSTEMS
from pounding.studies.p695.verdict import (Quality, Spectrum, Verdict, design_period, group_verdict, mce_spectrum,
                                           parse_quality, total_uncertainty, verdict)

__all__ = ["SDCS", "SYSTEMS", "DEFAULT_RECORDS", "VERDICT_WORDS", "P695Inputs", "Quality", "Spectrum", "Verdict",
           "parse_quality", "parse_systems", "mce_spectrum", "design_period", "total_uncertainty", "verdict",
           "group_verdict", "OUTCOMES", "collapse_intensities", "outcome_counts", "median_collapse", "ida_folder",
           "p695_study", "p695_summary",
           "p695_table", "plot_p695", "pounding_effect"]
