"""Simplify: ``ir.flat`` -> ``ir.dae`` -> ``ir.ode`` (aliases, index reduction,
causalization), plus the balance check, the initial problem and state choice."""

from .balance import check_balance
from .initialize import conditions, initial_state
from .passes import simplify
from .state_choice import simulate_switching

__all__ = ["check_balance", "conditions", "initial_state", "simplify", "simulate_switching"]
