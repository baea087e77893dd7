"""Command-line interface: click options -> checked values and frozen options objects ->
library calls -> text on stdout. One module per command group: ``app`` (the group,
errors to exit codes), ``options`` (shared options and checks), ``model_commands``
(check, flatten, compile), ``simulate_command``, ``tradeoff_command``, ``sweep_command``,
``ensemble_command``, ``fmu_command``.

Exit codes: 0 success, 1 model errors (diagnostics on stderr), 2 usage errors (a bad
option value, an output file springc refuses to write), 3 internal errors (traceback
only with ``--debug``); 130 after Ctrl-C, 143 after SIGTERM, 141 when stdout is a pipe
closed early (``springc simulate m.mdl | head -1``), quietly. Unfinished output files
are removed in every case (:mod:`springc.fileio`).
"""

from .app import main
from .ensemble_command import ensemble
from .fmu_command import fmu
from .model_commands import check, compile_, flatten
from .simulate_command import simulate
from .sweep_command import sweep
from .tradeoff_command import tradeoff

__all__ = ["check", "compile_", "ensemble", "flatten", "fmu", "main", "simulate", "sweep",
           "tradeoff"]
