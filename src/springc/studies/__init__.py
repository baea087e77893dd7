"""Studies: CompiledModel + StudyOptions -> Study, many runs in parallel, as Parquet.

Modules, each importing only those before it: ``params`` (parameter specifications,
grids, Monte Carlo and Latin hypercube samples), ``job`` (a batch of runs in a worker),
``engines`` (local processes or Dask), ``progress``, ``store`` (the Parquet layouts,
shards for resuming), ``study`` (:func:`run_study`, :func:`to_dataset`), ``fan``
(the plot of one variable across the runs), ``table`` (a user's CSV of runs) and
``ensemble`` (:func:`run_ensemble`: chunks of runs in an ensemble engine of
``ensemble_engines`` (the batched C kernel, numba, or the GPU), written by
``ensemble_outputs`` (trajectories read back by :func:`read_trajectories`),
one summary row per run, streamed into Parquet).

(The package is not named ``sweep``: ``springc.sweep`` is the API function.)
"""

from .engines import Executor, default_workers
from .ensemble import EnsembleOptions, EnsembleSummary, run_ensemble
from .ensemble_outputs import read_trajectories
from .fan import fan_figure, plot_variable, render_fan
from .job import RunJob, RunRecord, StudyOptions, run_batch
from .params import (
    DISTRIBUTIONS,
    METHODS,
    Distribution,
    ParameterSpec,
    grid,
    parse_parameter,
    parse_values,
    sample,
    unit_points,
)
from .store import FIXED_COLUMNS, check_outputs, partial_folder, summary_path
from .study import Study, parameter_table, run_study, to_dataset
from .table import read_table

__all__ = ["DISTRIBUTIONS", "FIXED_COLUMNS", "METHODS", "Distribution", "EnsembleOptions",
           "EnsembleSummary", "Executor",
           "ParameterSpec", "RunJob", "RunRecord", "Study", "StudyOptions", "check_outputs",
           "default_workers", "fan_figure", "grid", "parameter_table", "parse_parameter",
           "parse_values", "partial_folder", "plot_variable", "read_table",
           "read_trajectories", "render_fan", "run_batch", "run_ensemble", "run_study", "sample",
           "summary_path", "to_dataset", "unit_points"]
