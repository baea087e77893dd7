"""Calls: user-defined functions executed symbolically (``functions``, with ``while``/
``break``/``return`` in ``control``), the built-ins (``builtins``), ``assert`` and
``String`` values."""

from __future__ import annotations

from .assertions import assertion, check_conditions, guard_assertions, unique
from .builtins import CONSTANTS, Builtins, switches, without_events
from .control import Jumped, branch_jumps, check_jumps, folded, run_loop_body, run_while, stray
from .functions import (
    argument_value,
    call_for_effect,
    call_function,
    condition_value,
    function_of,
    multiple_outputs,
)
from .short_functions import short_defaults
from .strings import (
    is_string,
    read,
    string_binary,
    string_component,
    string_equation,
    undefined_strings,
)

__all__ = [
    "CONSTANTS",
    "Builtins",
    "Jumped",
    "argument_value",
    "assertion",
    "branch_jumps",
    "call_for_effect",
    "call_function",
    "check_conditions",
    "check_jumps",
    "condition_value",
    "folded",
    "function_of",
    "guard_assertions",
    "is_string",
    "multiple_outputs",
    "read",
    "run_loop_body",
    "run_while",
    "short_defaults",
    "stray",
    "string_binary",
    "string_component",
    "string_equation",
    "switches",
    "undefined_strings",
    "unique",
    "without_events",
]
