"""Tradeoff: accuracy versus cost of every solver and tolerance on one model."""

from .plot import write_work_precision
from .reference import write_reference
from .report import summary, write_table_csv
from .study import (
    DEFAULT_TARGETS,
    DEFAULT_TOLERANCES,
    TradeoffOptions,
    available_solvers,
    compare_states,
    run_tradeoff,
)

__all__ = ["DEFAULT_TARGETS", "DEFAULT_TOLERANCES", "TradeoffOptions", "available_solvers",
           "compare_states", "run_tradeoff", "summary", "write_reference", "write_table_csv",
           "write_work_precision"]
