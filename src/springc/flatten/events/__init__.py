"""Events and when-rules: when-equations and variable if-equations (``when``), when
statements, the when-target rule, the event built-ins (``event_calls``), ``delay`` and
algorithm sections (``algorithms``, ``section_starts``, ``loop_break``)."""

from __future__ import annotations

from .algorithms import Section, algorithm_section, apply_starts
from .delay import NAME as DELAY
from .delay import delay_call
from .event_calls import (
    EVENT_CALLS,
    EVENT_EQUATIONS,
    check_arithmetic_operands,
    check_unary_operand,
    event_call,
    event_dependent,
)
from .when import check_events, flatten_when, variable_if_equation

__all__ = [
    "DELAY",
    "EVENT_CALLS",
    "EVENT_EQUATIONS",
    "Section",
    "algorithm_section",
    "apply_starts",
    "check_arithmetic_operands",
    "check_events",
    "check_unary_operand",
    "delay_call",
    "event_call",
    "event_dependent",
    "flatten_when",
    "variable_if_equation",
]
