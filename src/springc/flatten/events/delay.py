"""``delay(expr, delayTime)`` and ``delay(expr, delayTime, delayMax)`` while flattening
(Modelica 3.6, section 3.7.4.1).

The value is ``expr`` at ``time - delayTime`` (at the start time while ``time -
delayTime`` lies before it). Without ``delayMax`` the delay time is a parameter
expression; with it, ``delayMax`` is one and bounds a delay time that may vary:
``0 <= delayTime <= delayMax``. The call stays ``delay(...)`` in the flat model; the
simulation keeps the history of ``expr`` (codegen/delays.py, simulation/delays.py).
"""

from __future__ import annotations

from typing import Any

from ...errors import FlattenError
from ...ir import expr as x
from ...ir import syntax as s
from ..scopes import ExpressionEvaluator, Scope

NAME = "delay"
_SECTION = "(Modelica 3.6, section 3.7.4.1)"


def delay_call(ev: ExpressionEvaluator, e: s.Call, scope: Scope) -> x.Expr:
    """The flat ``delay(...)`` of ``e``, its arguments checked."""
    if e.named or len(e.args) not in (2, 3):
        raise FlattenError("delay takes 2 or 3 arguments: delay(expr, delayTime) or "
                           "delay(expr, delayTime, delayMax)", e.span)
    args = [ev.scalar(arg, scope) for arg in e.args]
    parameter = ev.flattener.is_parameter_expression
    if len(args) == 2 and not parameter(args[1]):
        raise FlattenError("the delay time of delay(expr, delayTime) must be a parameter "
                           "expression", e.args[1].span,
                           hint="give a bound for a delay time that varies: "
                           f"delay(expr, delayTime, delayMax) {_SECTION}")
    if len(args) == 3 and not parameter(args[2]):
        raise FlattenError("delayMax of delay(expr, delayTime, delayMax) must be a "
                           "parameter expression", e.args[2].span,
                           hint=f"bound the delay time by a parameter or constant {_SECTION}")
    delay_time = _value(ev, args[1]) if parameter(args[1]) else None
    if delay_time is not None and delay_time < 0:
        raise FlattenError(f"the delay time of delay(...) must not be negative, found "
                           f"{delay_time:g}", e.args[1].span, hint=f"delay by 0 or more {_SECTION}")
    if len(args) == 3:
        delay_max = _value(ev, args[2])
        if delay_time is not None and delay_max is not None and delay_time > delay_max:
            raise FlattenError(f"the delay time ({delay_time:g}) exceeds delayMax "
                               f"({delay_max:g})", e.span, hint="delayTime must lie "
                               f"between 0 and delayMax {_SECTION}")
    return x.Call(NAME, tuple(args))


def _value(ev: ExpressionEvaluator, e: x.Expr) -> float | None:
    try:
        value: Any = ev.fold(e)
        return float(value)
    except (KeyError, TypeError, ValueError, ArithmeticError):
        return None  # known only at run time (a parameter without value)
