"""Simplify: ``ir.flat`` -> ``ir.dae`` -> ``ir.ode`` (aliases, index reduction,
causalization), plus the balance check, the initial problem and state choice."""

from ..errors import describe_failure
from .balance import check_balance
from .initialize import RedundantInitialWarning, conditions, initial_state
from .ode_eval import OdeEvaluator, parameter_values
from .passes import simplify
from .state_choice import (
    StateChoice,
    conditioning,
    needs_switch,
    select_states,
    state_vector,
    switch,
)
from .static_choice import CHECK_DETAIL, CHECK_MESSAGE, THRESHOLD, pivot_checks

__all__ = [
    "CHECK_DETAIL",
    "CHECK_MESSAGE",
    "THRESHOLD",
    "OdeEvaluator",
    "RedundantInitialWarning",
    "StateChoice",
    "check_balance",
    "conditioning",
    "conditions",
    "describe_failure",
    "initial_state",
    "needs_switch",
    "parameter_values",
    "pivot_checks",
    "select_states",
    "simplify",
    "state_vector",
    "switch",
]
