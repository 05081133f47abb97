"""Incremental dynamic analysis (IDA) and fragility, with and without pounding: ``pounding ida``.

Every record of a set is scaled to a series of intensities and the model is
run at each (Vamvatsikos & Cornell 2002, "Incremental dynamic analysis",
EESD 31 491–514).  With ``--without-contacts`` every run is repeated with
the contacts held open (:meth:`pounding.model.model.Model.with_contacts_open`), so the
effect of pounding is measured on identical records and intensities.  See
``docs/physics.md`` §8 and ``docs/ida.md``.

Intensity measure (IM)
    ``sa-t1``: the 5 %-damped pseudo-spectral acceleration at the first
    (elastic) period of one building; ``pga``: the peak ground acceleration.
    Both are computed on the record as the model uses it (read, then
    processed as ``ground_motion.processing`` says), over its whole length.

Scaling to a level (:class:`IdaPlan`)
    ``record``: each record on its own, factor = level / IM_i, so its IM
    equals the level.  ``fema-p695`` (the default when every record is a FEMA
    P695 record): the FEMA P695 (2009, §A.8) procedure — each record is first
    multiplied by its normalisation factor NM_i, then the whole normalised set
    by one factor so that the *median* IM of the set equals the level:
    factor_i = NM_i · level / median_j(NM_j · IM_j).  A record's own IM is then
    ``intensity`` (record, level), and the level is the set's median.  Either
    way the factor is relative to the record as stored in the catalogue (or
    file), after processing.

Levels
    Fixed stripes (``--levels``): every record at every level.  Or
    hunt-and-fill (``--hunt``, :func:`next_hunt_level`): per record, levels
    rise with a growing step until the first collapse (each building in turn,
    below the level where another's collapse censors it), the bracket between
    the highest non-collapsing and the lowest collapsing level is bisected
    down to a tolerance, and leftover runs fill the largest gaps below it
    (Vamvatsikos & Cornell 2004, "Applied incremental dynamic analysis",
    Earthquake Spectra 20 523–553).

Outcome of a run
    ``completed`` or ``collapsed`` from the run's ``status`` attribute
    (``collapsed`` only when the solver stopped the run at its collapse
    criterion, or where a storey lost its lateral resistance to P-Delta,
    status ``unstable``: a sidesway collapse), ``failed`` when the run raised
    or its status is ``energy_inconsistent`` (its contacts dissipated more
    energy than it received: tighter tolerances give an answer).  A building is
    **collapsed** in a run when its collapse ended the run (the run records
    which building) or when its largest peak storey drift ratio reaches its
    collapse drift ratio in the study (``--collapse-drift``, else its own
    ``collapse: {drift_ratio}``, else ``solver.stop_drift_ratio``, else the
    largest drift limit); every other building of a run that a collapse ended
    is **censored** there (its later response is unknown).  A collapsed
    building counts as exceeding every drift limit.

Fragility (:mod:`pounding.studies.fragility`)
    Stripes: lognormal θ, β by maximum likelihood on the counts of records
    exceeding each limit at each level (Baker 2015), failed and censored runs
    left out.  Hunt: from each record's intensity at the limit (Baker 2015
    eqs. 3–4; with right-censored records, the censored likelihood):
    for collapse, the middle of the final bracket; for a drift limit, the IM
    where the record's IDA curve (max drift ratio against IM, runs in IM
    order) first reaches the limit, by linear interpolation between the two
    runs either side (the middle of them when the upper one collapsed).
    With ``mce``: the collapse margin ratio CMR = Ŝ_CT / S_MT, Ŝ_CT = θ of
    collapse (FEMA P695 §7.2).  A fit whose median is not inside the data is
    "not determinable": no θ, β or CMR (docs/ida.md).

Record pairs
    A model shaken by two components (floors in plan) runs record pairs,
    each in both orientations (FEMA P695's three-dimensional analyses; a
    pair's IM the geometric mean of its components'): see
    :mod:`pounding.studies.ida.schedule`.  Its storeys' drift ratios are their
    planes' largest; the archive adds each plane's (``plane``) and the pair's
    ``pair``, ``orientation`` and components.

Modules
    ``schedule`` inputs (IM, levels, limits, hunt settings) and the schedule of every run
    ``runs``     one run on a worker, and its outcome
    ``hunt``     hunt-and-fill: the next level of a record, the hunt on the study engine
    ``dataset``  the NetCDF layout and the fragility fitted on it
    ``report``   the JSON summary, the printed table, the plots
"""

from __future__ import annotations

import os

from pounding.studies.ida.dataset import MAX_BETA, assemble_ida_dataset, exceeds, ida_fragility
from pounding.studies.ida.hunt import HuntTasks, next_hunt_level, run_hunt
from pounding.studies.ida.schedule import (DEFAULT_LIMITS, IM_NAMES, MAX_LEVELS, ORIENTATIONS, SA_DAMPING, SCALINGS,
                                           VARIANTS, Hunt, IdaPlan, IntensityMeasure, build_ida_plan, limit_label,
                                           parse_intensity, parse_levels, parse_limits)
from pounding.studies.ida.report import ida_summary, ida_table, ida_tables, plot_ida
from pounding.studies.ida.runs import IDA_PART, building_drifts, collapsed_in, run_ida_scenario, run_outcome

__all__ = ["IDA_PART", "VARIANTS", "DEFAULT_LIMITS", "IM_NAMES", "SCALINGS", "MAX_LEVELS", "MAX_BETA", "SA_DAMPING",
           "IntensityMeasure", "Hunt", "IdaPlan", "parse_levels", "parse_limits", "build_ida_plan",
           "run_ida_scenario", "next_hunt_level", "HuntTasks", "run_hunt", "ida_study", "assemble_ida_dataset", "ida_fragility",
           "ida_summary", "ida_table", "ida_tables", "plot_ida", "run_outcome", "parse_intensity", "limit_label", "exceeds",
           "building_drifts", "collapsed_in", "ORIENTATIONS"]


def ida_study(plan: IdaPlan, output: str | os.PathLike | None = None, **run_options):
    """Run the IDA of *plan* on the study engine (stripes: a static list; hunt: :class:`HuntTasks`).

    *run_options* go to :func:`pounding.studies.engine.execution.run_study`
    (workers, scheduler, client, progress, overwrite...).
    """
    from pounding.studies.engine.execution import run_study
    from pounding.studies.sweep.execution import sweep_tasks

    if plan.hunt is not None:
        return run_hunt(plan, output, **run_options)
    scenarios = plan.stripe_scenarios()
    entries = [(v, r, float(level), plan.scenario(v, r, float(level)).key) for v in plan.variants
               for r in range(len(plan.records)) for level in plan.levels]

    def assemble(_sweep, results, *, elapsed=float("nan"), ran=0):
        return assemble_ida_dataset(plan, results, entries, elapsed=elapsed, ran=ran)

    tasks = sweep_tasks(plan.sweep, runner=run_ida_scenario, assemble=assemble, scenarios=scenarios)
    return run_study(tasks, output, **run_options)
