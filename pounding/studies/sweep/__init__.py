"""Parameter sweeps on Dask: ``pounding sweep SWEEP.yaml -o SWEEP.nc``.

``spec``       the sweep file: axes, paths into the model, scenarios
``scenario``   one scenario, run on a worker
``store``      the resumable parts store (one JSON file per finished scenario)
``execution``  the Dask cluster, batching, retries and progress
``dataset``    the results NetCDF layout
"""

from pounding.studies.sweep.dataset import build_dataset
from pounding.studies.sweep.execution import default_workers, run_chunk, run_sweep, start_client
from pounding.studies.sweep.scenario import run_scenario
from pounding.studies.sweep.spec import (FEMA_SETS, PARTS_FORMAT, PathError, RESERVED_NAMES, RESULT_VARIABLES, Axis, Dimension, Scenario,
                                         Sweep, apply_path, expand_records, load_sweep, parse_path, scenario_key,
                                         sweep_from_text)
from pounding.studies.sweep.store import PARTS_SUFFIX, history_name, load_parts, parts_dir, save_part

__all__ = ["Axis", "Dimension", "Scenario", "Sweep", "load_sweep", "sweep_from_text", "expand_records",
           "parse_path", "apply_path", "PathError", "scenario_key", "run_scenario", "run_sweep", "run_chunk", "start_client",
           "default_workers", "build_dataset", "parts_dir", "save_part", "load_parts", "history_name",
           "PARTS_SUFFIX", "PARTS_FORMAT", "FEMA_SETS", "RESERVED_NAMES", "RESULT_VARIABLES"]
