"""Rules on the types and variabilities of expressions (Modelica 3.6, sections 3.7.1,
3.7.4, 3.8, 4.4.4.1, 8.3.4 and 10.6): checked where flattening meets the expression.

Input: a declaration with its binding, a ``der`` or numeric argument, a condition value.
Output: nothing, or a :class:`FlattenError` naming the rule and its section.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from ...errors import Note, Span
from ...ir import expr as x
from ...ir import syntax as s
from ..scopes import ClassScope, Primitive, Scope, refs
from .rules import rule_error

#: Variabilities from the least to the most restrictive.
_ORDER = ("", "continuous", "discrete", "parameter", "constant")


def stronger(a: str, b: str) -> str:
    """The more restrictive of two variability prefixes: the prefix of a structured
    component applies to its elements that have a less restrictive one (4.4.4.1)."""
    return a if _ORDER.index(a) >= _ORDER.index(b) else b


def check_constant_binding(name: str, binding: Iterable[x.Expr | None],
                           parameters: Any, span: Span | None) -> None:
    """A constant is bound to a constant expression, never to a parameter (3.8.2)."""
    for value in binding:
        if value is None:
            continue
        for used in x.variables(value):
            if used in parameters:
                raise rule_error(
                    f"the value of constant '{name}' must be a constant expression, but it "
                    f"depends on the parameter '{used}'", span,
                    "a constant is bound only to literals, constants and functions of "
                    "them; make it a parameter, or the parameter a constant", "3.8.2")


def certainly_real(e: s.Expr) -> bool:
    """Whether ``e`` is of type Real whatever its references are: a Real literal, a
    division or a power (Real even on Integers), or arithmetic on one of these."""
    if isinstance(e, s.Number):
        return isinstance(e.value, float)
    if isinstance(e, s.Binary):
        if e.op in ("/", "./", "^", ".^"):
            return True
        if e.op in ("+", "-", "*", ".+", ".-", ".*"):
            return certainly_real(e.left) or certainly_real(e.right)
        return False
    if isinstance(e, s.Unary):
        return e.op in ("-", "+") and certainly_real(e.operand)
    if isinstance(e, s.IfExpr):
        return any(certainly_real(v) for _, v in e.branches) or certainly_real(e.otherwise)
    if isinstance(e, s.ArrayLit):
        return any(certainly_real(i) for i in e.items)
    return False


def check_integer_binding(name: str, type_name: str, value: s.Expr | None) -> None:
    """An Integer is not bound to a Real expression such as ``3 / 2`` (10.6.5, 10.6.7)."""
    if type_name != "Integer" or value is None or not certainly_real(value):
        return
    raise rule_error(
        f"'{name}' is an Integer, but its value is a Real expression", value.span,
        "`/` and `^` give a Real even on Integers (use div(a, b) for integer division, "
        "integer(...) to convert); a Real is not converted to Integer implicitly",
        "10.6.5")


def declared(ref: s.Ref, scope: Scope) -> Primitive | None:
    """The primitive declaration ``ref`` names (without subscripts), if any."""
    if any(part.subscripts for part in ref.parts):
        return None
    try:
        member: Any = scope.lookup(ref.parts[0].name, ref.span)
        for part in ref.parts[1:]:
            if not isinstance(member, ClassScope) or not member.has_member(part.name):
                return None
            member = member.member(part.name, part.span)
    except Exception:  # reported where the reference is evaluated
        return None
    return member if isinstance(member, Primitive) else None


def check_der_argument(call: s.Call, scope: Scope) -> None:
    """``der(v)``: ``v`` is a Real and not a discrete-time variable (3.7.4)."""
    if len(call.args) != 1 or not isinstance(call.args[0], s.Ref):
        return
    prim = declared(call.args[0], scope)
    if prim is None:
        return
    ref = call.args[0]
    if prim.type != "Real":
        raise rule_error(f"der needs a Real argument, but '{ref.dotted}' is of type "
                         f"{prim.type}", ref.span, "the argument of der must be of type "
                         "Real", "3.7.4", (Note("declared here", prim.decl.span),))
    if prim.variability == "discrete":
        raise rule_error(f"der of the discrete-time variable '{ref.dotted}'", ref.span,
                         "the argument of der must be continuous-time (a parameter or "
                         "constant gives zero)", "3.7.4",
                         (Note("declared here", prim.decl.span),))


def check_boolean_condition(value: object, span: Span, what: str) -> None:
    """The condition of an if-equation is Boolean, not a number (8.3.4)."""
    if isinstance(value, bool | np.bool_):
        return
    if isinstance(value, int | float | np.integer | np.floating):
        kind = "an Integer" if isinstance(value, int | np.integer) else "a Real"
        raise rule_error(f"{what} must be a Boolean, found {kind}", span,
                         "conditions are Boolean expressions; compare the number, "
                         "e.g. `i <> 0`", "8.3.4")


#: Built-in functions whose arguments are numbers (Integer or Real), never Boolean.
NUMERIC_FUNCTIONS = frozenset({
    "abs", "sign", "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh",
    "cosh", "tanh", "exp", "log", "log10", "floor", "ceil", "integer", "div", "mod", "rem"})


def check_numeric_arguments(name: str, call: s.Call, scope: Scope) -> None:
    """``abs(b)`` with a Boolean ``b`` is a type error (3.7.1)."""
    if name not in NUMERIC_FUNCTIONS:
        return
    for arg in call.args:
        prim = declared(arg, scope) if isinstance(arg, s.Ref) else None
        if isinstance(arg, s.Bool) or (prim is not None and prim.type == "Boolean"):
            what = f"'{arg.dotted}' is a Boolean" if isinstance(arg, s.Ref) else \
                "the argument is a Boolean"
            raise rule_error(f"{name} needs a number: {what}", arg.span,
                             f"the arguments of {name} are Integer or Real", "3.7.1")



#: Built-in calls whose value is discrete-time whatever their arguments (3.8.4): they
#: generate events or give sizes.
_DISCRETE_CALLS = frozenset({"integer", "floor", "ceil", "div", "mod", "rem", "pre", "edge",
                             "change", "sample", "initial", "terminal", "size", "ndims",
                             "cardinality"})
_RELATIONS = frozenset({"<", "<=", ">", ">=", "==", "<>"})


def continuous_part(e: s.Expr, scope: Scope) -> str | None:
    """A continuous-time part of ``e`` (``time``, a continuous Real variable, or
    ``noEvent`` of one), or None if ``e`` is a discrete-time expression (3.8.4);
    references that cannot be resolved count as discrete."""
    if isinstance(e, s.Ref):
        if e.parts[0].name == "time" and len(e.parts) == 1:
            prim_time = declared(e, scope)
            return "time" if prim_time is None else None
        prim = declared(e, scope)
        if prim is not None and prim.type == "Real" and prim.variability == "continuous":
            return f"the continuous-time variable '{e.dotted}'"
        return None
    if isinstance(e, s.Binary):
        if e.op in _RELATIONS:
            return None  # a relation generates events
        return continuous_part(e.left, scope) or continuous_part(e.right, scope)
    if isinstance(e, s.Unary):
        return continuous_part(e.operand, scope)
    if isinstance(e, s.IfExpr):
        for cond, value in e.branches:
            found = continuous_part(cond, scope) or continuous_part(value, scope)
            if found:
                return found
        return continuous_part(e.otherwise, scope)
    if isinstance(e, s.ArrayLit):
        for item in e.items:
            found = continuous_part(item, scope)
            if found:
                return found
        return None
    if isinstance(e, s.Call):
        name = e.func.dotted
        if name in _DISCRETE_CALLS:
            return None
        if name in ("noEvent", "smooth"):  # no events: relations inside are continuous
            return _any_continuous_variable(e, scope)
        for arg in (*e.args, *(n.value for n in e.named)):
            found = continuous_part(arg, scope)
            if found:
                return found
    return None


def _any_continuous_variable(e: s.Call, scope: Scope) -> str | None:
    for arg in e.args:
        for ref in refs(arg):
            found = continuous_part(ref, scope)
            if found:
                return found
    return None


def check_discrete_binding(name: str, type_name: str, variability: str,
                           value: s.Expr | None, scope: Scope | None) -> None:
    """An Integer, Boolean or discrete variable is bound to a discrete-time expression:
    ``Integer y = f(x)`` with a continuous ``x`` is an error (3.8.4)."""
    if value is None or scope is None or variability != "discrete":
        return
    found = continuous_part(value, scope)
    if found is not None:
        kind = "a discrete" if type_name == "Real" else f"an {type_name}" \
            if type_name == "Integer" else f"a {type_name}"
        raise rule_error(
            f"'{name}' is {kind} variable, but its value depends on {found}", value.span,
            "Integer, Boolean and discrete variables change only at events: their values "
            "are discrete-time expressions (relations, integer(), pre(), ... of "
            "continuous-time variables, not the variables themselves)", "3.8.4")
