"""Tradeoff: accuracy versus cost of every solver and tolerance on one model.

Modules, each importing only those before it: ``model`` (options, runs, constants),
``setup`` (grid, scales, errors), ``reference``, ``report``, ``energy``, ``plot``,
``runs`` (one timed run, warm-up, contenders), ``chains`` (a solver's settings, the
cost limit), ``baselines`` (scipy's calls, the rk45 probe), and ``study``
(:func:`run_tradeoff`), ``outputs`` (:func:`save_study`).
"""

from .model import DEFAULT_TARGETS, DEFAULT_TOLERANCES, Tradeoff, TradeoffError, TradeoffOptions
from .outputs import save_study
from .plot import write_work_precision
from .reference import write_reference
from .report import recommendations, summary, write_table_csv
from .study import SPREAD_ABOVE, available_solvers, compare_states, run_tradeoff

__all__ = ["DEFAULT_TARGETS", "DEFAULT_TOLERANCES", "SPREAD_ABOVE", "Tradeoff", "TradeoffError",
           "TradeoffOptions", "available_solvers", "compare_states", "recommendations",
           "run_tradeoff", "save_study", "summary", "write_reference", "write_table_csv",
           "write_work_precision"]
