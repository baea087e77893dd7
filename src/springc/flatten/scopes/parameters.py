"""Numeric values of parameters and constants, evaluated from their bindings on demand,
and the check of the parameters' bindings once the model is flat.

Input: the flat binding of each parameter and constant (an ``ir.expr`` expression, or
None). Output: numbers (or numpy arrays), cached, with cycles and missing values raised
as ``KeyError`` naming the parameter; located errors for bindings that use variables,
divide by zero or overflow.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

from ...errors import FlattenError, Span
from ...ir import expr as x
from ...ir import flat

__all__ = ["MAX_INTEGER_EXPONENT", "ParameterValues", "binding_errors", "check_powers"]

VARIABILITY_HINT = ("a parameter's binding may only use parameters and constants (Modelica "
                    "3.6, section 3.8): bind it to a parameter expression, or remove the "
                    "`parameter` prefix to make it a variable with a binding equation")
VALUE_HINT = "change the binding (or the parameters it uses) so that it has a finite value"


class ParameterValues(Mapping[str, Any]):
    """Numeric values of parameters and constants, evaluated from bindings on demand."""

    def __init__(self) -> None:
        self.bindings: dict[str, x.Expr | None] = {}
        self.cache: dict[str, Any] = {}
        self.active: set[str] = set()
        self.reads = 0  # how often a value was asked for (see equation_templates.reusable)

    def __getitem__(self, name: str) -> Any:
        self.reads += 1
        if name in self.cache:
            return self.cache[name]
        if name not in self.bindings:
            raise KeyError(f"the variable '{name}'")
        binding = self.bindings[name]
        if binding is None or name in self.active:
            raise KeyError(f"the parameter '{name}', which has no value")
        self.active.add(name)
        try:
            check_powers(binding, self)
            value = x.evaluate(binding, self, initial=True)  # computed in initialization
        finally:
            self.active.discard(name)
        self.cache[name] = value
        return value

    def __iter__(self) -> Iterator[str]:
        return iter(self.bindings)

    def __len__(self) -> int:
        return len(self.bindings)


#: Integer powers beyond this exponent are refused: Python computes ``10 ^ 10^9`` exactly,
#: a number of a billion digits, which takes hours (Modelica's ``^`` is a Real power).
MAX_INTEGER_EXPONENT = 4096


def check_powers(e: x.Expr, values: Mapping[str, Any]) -> None:
    """Raise OverflowError for an integer power in ``e`` whose exact value would be huge;
    inner powers are checked before the operands that contain them are evaluated. A
    node shared by several parents is visited once (the values a function's loop
    builds share their sub-expressions: walking them as trees took 160 s for
    ``Blocks.Examples.Filter``)."""
    _check_powers(e, values, set())


def _check_powers(node: x.Expr, values: Mapping[str, Any], seen: set[int]) -> None:
    # A function of the module, not a recursive closure: that would be a reference
    # cycle (closure -> its cell -> closure) left to the collector, paused while a
    # model compiles (springc.collector).
    if id(node) in seen:
        return
    seen.add(id(node))
    for child in x.children(node):
        _check_powers(child, values, seen)
    if isinstance(node, x.BinOp) and node.op == "^":
        base, exponent = x.evaluate(node.left, values), x.evaluate(node.right, values)
        if isinstance(base, int) and isinstance(exponent, int) and abs(base) > 1 \
                and abs(exponent) > MAX_INTEGER_EXPONENT:
            raise OverflowError(f"{base} ^ {exponent} is too large")


def binding_errors(variables: Iterable[flat.Variable], values: ParameterValues
                   ) -> list[FlattenError]:
    """The parameters whose binding uses something other than parameters and constants
    (a variable, ``time``, a derivative), or whose value cannot be computed or is not
    finite (division by zero, overflow); one error per declaration. A binding that
    depends on a parameter without a value is left alone."""
    errors: list[FlattenError] = []
    reported: set[Span] = set()
    for v in variables:
        if v.variability != "parameter" or v.binding is None or v.span in reported:
            continue
        error = _binding_error(v, v.binding, values)
        if error is not None:
            reported.add(v.span)
            errors.append(error)
    return errors


def _binding_error(v: flat.Variable, binding: x.Expr, values: ParameterValues
                   ) -> FlattenError | None:
    outside = [n for n in x.variables(binding) if n not in values.bindings]
    if outside or any(isinstance(n, (x.Der, x.Time)) for n in x.walk(binding)):
        what = f"the variable '{outside[0]}'" if outside else "time or a derivative"
        return FlattenError(f"parameter '{v.name}' is bound to an expression that uses "
                            f"{what}, which is not a parameter or constant", v.span,
                            hint=VARIABILITY_HINT)
    try:
        value = values[v.name]
    except KeyError:  # a parameter without a value: it is given one at simulation
        return None
    except (ArithmeticError, ValueError, TypeError) as err:
        reason = "division by zero" if isinstance(err, ZeroDivisionError) else str(err)
        return FlattenError(f"cannot evaluate the binding of parameter '{v.name}': {reason}",
                            v.span, hint=VALUE_HINT)
    if isinstance(value, (int, float)) and not math.isfinite(value):
        return FlattenError(f"the binding of parameter '{v.name}' evaluates to {value} (an "
                            "operation overflows or is undefined)", v.span, hint=VALUE_HINT)
    return None
