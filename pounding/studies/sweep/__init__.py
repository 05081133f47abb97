"""Parameter sweeps: ``pounding sweep SWEEP.yaml -o SWEEP.nc``.

``spec``       the sweep file: axes, paths into the model, scenarios
``scenario``   one scenario, run on a worker, and what a study keeps of its run (peaks, intensity)
``execution``  the sweep on the study engine (:mod:`pounding.studies.engine`: parts store, Dask, resume)
``dataset``    the results NetCDF layout
"""

from pounding.studies.engine.execution import default_workers, run_chunk, start_client
from pounding.studies.engine.keys import PARTS_FORMAT, scenario_key
from pounding.studies.engine.store import PARTS_SUFFIX, history_name, load_parts, parts_dir, save_part
from pounding.studies.engine.tasks import Scenario
from pounding.studies.sweep.dataset import build_dataset
from pounding.studies.sweep.execution import run_sweep
from pounding.studies.sweep.scenario import run_scenario
from pounding.studies.sweep.spec import (FEMA_SETS, RESERVED_NAMES, RESULT_VARIABLES, Axis, Dimension, PathError,
                                         Sweep, apply_path, expand_pairs, expand_records, load_sweep, parse_path,
                                         sweep_from_text)

__all__ = ["Axis", "Dimension", "Scenario", "Sweep", "load_sweep", "sweep_from_text", "expand_records", "expand_pairs",
           "parse_path", "apply_path", "PathError", "scenario_key", "run_scenario", "run_sweep", "run_chunk", "start_client",
           "default_workers", "build_dataset", "parts_dir", "save_part", "load_parts", "history_name",
           "PARTS_SUFFIX", "PARTS_FORMAT", "FEMA_SETS", "RESERVED_NAMES", "RESULT_VARIABLES"]
