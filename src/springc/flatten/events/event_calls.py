"""The event built-ins in expressions: syntax call -> ``ir.expr`` call.

``pre(v)``, ``edge(b)``, ``change(v)`` take a variable (element-wise over arrays);
``initial()`` and ``terminal()`` take nothing; ``sample(start, interval)`` takes
parameter expressions. They stay calls in the flat model (``pre(x)``,
``sample(0, 0.1)``); their meaning at events is given by simplify/events.py and the
generated event update. ``reinit`` and ``terminate`` are equations, not
expressions (flatten/events/when.py). :class:`EventUses` records what the checks at the
end of flattening need (``pre`` of continuous variables outside when-clauses,
non-Boolean when-conditions).
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import FlattenError, Span, describe_failure
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ...ir.builtins import BUILTINS, EQUATION, names
from .. import arrays as a
from ..scopes import EventUses, ExpressionEvaluator, Scope

EVENT_CALLS = names(lambda b: b.at_events)
"""Calls handled here (``reinit`` and ``terminate`` only to refuse them in expressions)."""
EVENT_EQUATIONS = names(lambda b: b.at_events and b.kind == EQUATION)
"""``reinit`` and ``terminate``: equations of when-clauses only."""


def event_call(ev: ExpressionEvaluator, uses: EventUses, e: s.Call, scope: Scope) -> a.Value:
    """The flat value of the event built-in ``e``."""
    name = e.func.dotted
    if name in EVENT_EQUATIONS:
        raise FlattenError(f"'{name}' is an equation, not an expression", e.func.span,
                           hint=f"write '{name}(...);' as an equation inside a "
                           "when-clause")
    if e.named:
        raise FlattenError(f"'{name}' takes no named arguments", e.named[0].span)
    count = BUILTINS[name].arity[0]
    if len(e.args) != count:
        raise FlattenError(f"'{name}' takes {count} argument{'s' if count != 1 else ''}, "
                           f"{len(e.args)} given", e.span)
    if name in ("initial", "terminal"):
        return x.Call(name, ())
    if name == "sample":
        args = []
        for arg, what in zip(e.args, ("start", "interval")):
            value = ev.scalar(arg, scope)
            if not ev.flattener.is_parameter_expression(value):
                raise FlattenError(f"the {what} of sample(start, interval) must be a "
                                   "parameter expression", arg.span)
            args.append(value)
        _check_sample(ev, args, e)
        return x.Call("sample", tuple(args))
    argument = ev.value(e.args[0], scope)

    def one(item: x.Expr) -> x.Expr:
        if not isinstance(item, x.Var):
            raise FlattenError(f"the argument of '{name}' must be a variable",
                               e.args[0].span,
                               hint=f"write {name}(v) with v a variable, not an expression")
        if not uses.in_when:
            uses.pre_uses.append((item.name, e.span))
        return x.Call(name, (item,))

    return a.elementwise(one, argument)


def _check_sample(ev: ExpressionEvaluator, args: list[x.Expr], e: s.Call) -> None:
    """sample's start must be finite and its interval positive (3.7.5), where their
    values are known (a parameter without a value is left to the run)."""
    for value, arg, what in zip(args, e.args, ("start", "interval")):
        try:
            number = float(ev.fold(value))
        except ArithmeticError as err:
            raise FlattenError(f"cannot evaluate the {what} of sample(start, interval): "
                               f"{describe_failure(err)}", arg.span) from None
        except (KeyError, TypeError, ValueError):
            continue  # known only at run time (a parameter without a value)
        if what == "start" and not math.isfinite(number):
            raise FlattenError(f"the start of sample(start, interval) must be a finite "
                               f"time, found {number:g}", arg.span)
        if what == "interval" and not number > 0:
            raise FlattenError(f"{POSITIVE_INTERVAL}, found {number:g}", arg.span,
                               hint="sample(start, interval) is true at start, "
                               "start + interval, start + 2*interval... (Modelica 3.6, "
                               "section 3.7.5)")
    interval = args[1]
    if not isinstance(interval, x.Const):  # a run's parameter values may make it 0
        positive = x.Call("noEvent", (x.BinOp(">", interval, x.Const(0.0)),))
        ev.flattener.assertions.append((flat.Assertion(
            positive, f"{POSITIVE_INTERVAL}: {x.to_text(interval)} <= 0", "error",
            e.args[1].span, flat.Origin("equation", "", "sample")), e.args[1].span))


POSITIVE_INTERVAL = "the interval of sample(start, interval) must be positive"


#: Event built-ins whose value is a Boolean (3.7.5): never operands of arithmetic.
BOOLEAN_CALLS = names(lambda b: b.boolean)


def check_arithmetic_operands(op: str, operands: tuple[object, ...], e: s.Binary) -> None:
    """``true + 1`` and ``2.0*terminal()`` are type errors: a Boolean (a literal, a
    relation, ``not``/``and``/``or``, a Boolean event built-in) is no number (Modelica
    3.6, section 3.4: arithmetic operates on numeric types)."""
    for value, side in zip(operands, (e.left, e.right)):
        if surely_boolean(value):
            assert isinstance(value, x.Expr)
            text = x.to_text(value)
            raise FlattenError(
                f"'{text}' is a Boolean and cannot be an operand of '{op}'",
                side.span, hint="arithmetic needs Integer or Real operands (Modelica 3.6, "
                f"section 3.4); choose a number with an if-expression ('if {text} then "
                "1.0 else 0.0')")


def check_unary_operand(op: str, value: object, span: Span) -> None:
    """``-true`` is a type error (section 3.4), and so is ``not 2`` (section 3.5: not
    takes a Boolean)."""
    if op == "not":
        if type(value) is x.Const and not isinstance(value.value, (bool, np.bool_)) \
                and isinstance(value.value, (int, float, np.integer, np.floating)):
            raise FlattenError(f"'not' needs a Boolean operand, found the number "
                               f"{x.to_text(value)}", span,
                               hint="compare the number, e.g. 'not (i <> 0)' (Modelica "
                               "3.6, section 3.5)")
    elif surely_boolean(value):
        assert isinstance(value, x.Expr)
        raise FlattenError(f"'{x.to_text(value)}' is a Boolean and cannot be an operand "
                           f"of unary '{op}'", span, hint="arithmetic needs Integer or "
                           "Real operands (Modelica 3.6, section 3.4)")


def surely_boolean(value: object) -> bool:
    """Whether ``value`` is a Boolean whatever the variables' types."""
    kind = type(value)
    if kind is x.Const:
        return isinstance(value.value, (bool, np.bool_))  # type: ignore[attr-defined]
    if kind is x.Call:
        return value.name in BOOLEAN_CALLS  # type: ignore[attr-defined]
    if kind is x.BinOp:
        return value.op in x.RELATIONS or value.op in ("and", "or")  # type: ignore[attr-defined]
    return kind is x.Not


def event_dependent(e: x.Expr) -> bool:
    """Whether ``e`` calls an event built-in (``initial()``, ``terminal()``, ``pre``,
    ...): its value changes during the simulation even without variables."""
    return any(type(n) is x.Call and n.name in EVENT_CALLS for n in x.walk(e))
