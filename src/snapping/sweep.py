"""Sweeps: a grid of runs over (chi, N, any run option), in parallel, resumable.

Each run is saved to its own netCDF file as soon as it finishes, written
atomically (to a temporary file in the same directory, then renamed), so a
killed sweep never leaves a corrupt file. Long runs checkpoint into the same
file while they run. Rerunning the same sweep skips every run whose file is
already there and complete, resumes every checkpointed or interrupted one, and
starts the others afresh. The finished runs combine into one
Dataset with ``chi`` and ``N`` dimensions (:func:`combine`).

Runs go to local worker processes by default; give a Dask scheduler address (or
a ``dask.distributed.Client``) to run the same sweep on an existing cluster.

Example
-------
>>> from snapping.sweep import Grid
>>> grid = Grid(chi=[0.25, 0.5], N=[50])       # run()'s defaults: method fast, chords exact
>>> [p.name for p in grid.paths("out")]         # (options, when given, add their hash to the names)
['run_chi0.25_N50.nc', 'run_chi0.5_N50.nc']
"""

from __future__ import annotations

# One idea a module (a pure split of the former sweep.py; every name is importable from here as before):
#   sweep_grid      Grid (chi x N with the same options), grid_key
#   sweep_run       run_sweep: workers, ensembles, Dask, resuming; _run_one, _run_task
#   sweep_files     atomic_to_netcdf, is_complete_run, combine, check_combined, COMBINE_SAME_INPUTS
#   sweep_failures  RunFailure, SweepFailed, failure_table (the failed runs' table)
from . import _workers  # noqa: F401 (snapping.sweep._workers, as before)
from .sweep_failures import RunFailure, SweepFailed, _existing, _failure_of, _one_line, failure_table  # noqa: F401
from .sweep_files import (_RUN_DIMS, _SUMMARY_ATTRS, COMBINE_SAME_INPUTS, _problem_key, _run_piece,  # noqa: F401
                          _same, atomic_to_netcdf, check_combined, combine, is_complete_run)
from .sweep_grid import Grid, _body_description, _check_values, _run_kwargs, grid_key  # noqa: F401
from .sweep_run import (ENSEMBLE_OPTIONS, _check_ensemble, _check_out_dir, _check_room, _client_for,  # noqa: F401
                        _groups, _label, _run_one, _run_sweep, _run_task, run_sweep)

__all__ = ["Grid", "run_sweep", "combine", "atomic_to_netcdf", "is_complete_run", "SweepFailed", "RunFailure",
           "failure_table"]
