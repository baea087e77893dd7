"""``String`` values while flattening (Modelica 3.6, sections 3.6.1, 3.7.1, 4.9.4, 10.6.2):
String variables, ``String(...)`` conversions, ``+`` concatenation and relations.

Strings are never simulated: a String parameter or constant is known while flattening,
and so is a String variable, whose value is given by one equation (or algorithm
assignment) with a String expression of literals, constants, parameters and loop
indices: ``s = "a" + String(n)``. Such variables are not part of the flat model nor of
the results (which hold numbers). A String variable assigned in a when-clause (a
discrete String) changes at events: its equations are checked, and reading its value
is not supported yet.

Input: the evaluated sides of equations and assignments, ``String(...)`` calls.
Output: the variables' values (:class:`StringVariable`), strings, Boolean constants.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import FlattenError, Note, Span
from ...ir import expr as x
from ...ir import syntax as s
from .. import arrays as a
from ..checks import declared
from ..scopes import (
    EnumLiteral,
    ExpressionEvaluator,
    FlattenContext,
    Mod,
    Primitive,
    ResolvedType,
    Scope,
    check_attribute_mods,
)

_HINT = "springc supports a subset of Modelica; see \"Not supported yet\" in docs/language.md"


@dataclass(eq=False)
class StringVariable:
    """One scalar String variable: its flat name and, once its equation is met, its
    value (or ``at_events``: it is assigned in a when-clause)."""

    name: str
    span: Span
    value: str | None = None
    defined: Span | None = None
    at_events: bool = False


def string_variables(names: list[str], dims: tuple[int, ...], span: Span) -> Any:
    """The values of a declared String variable (an array of them for an array)."""
    slots = [StringVariable(n, span) for n in names]
    return a.make_array(slots, dims) if dims else slots[0]


def read(value: Any) -> Any:
    """A String variable's value where it is known (itself, the target of an equation,
    where it is not)."""
    if isinstance(value, np.ndarray):
        if value.size and isinstance(value.flat[0], StringVariable):
            return a.make_array([read(v) for v in value.flat], value.shape)
        return value
    if isinstance(value, StringVariable) and value.value is not None:
        return value.value
    return value


def is_string(v: object) -> bool:
    """Whether ``v`` is a String value or variable (or an array of them)."""
    if isinstance(v, np.ndarray):
        return bool(v.size) and isinstance(v.flat[0], (str, StringVariable))
    return isinstance(v, (str, StringVariable))


def string_equation(lhs: Any, rhs: Any, span: Span, at_events: bool = False) -> bool:
    """``s = "text"``: give each String variable of one side the String of the other;
    True if the equation is about Strings (it then adds no flat equation)."""
    if not (is_string(lhs) or is_string(rhs)):
        return False
    left, right = _items(lhs), _items(rhs)
    if len(left) != len(right):
        raise FlattenError("the two sides of this equation differ in size", span)
    for target, value in zip(left, right):
        if isinstance(value, StringVariable) and not isinstance(target, StringVariable):
            target, value = value, target
        if not isinstance(target, StringVariable):
            raise FlattenError("both sides of this equation are Strings known already",
                               span, hint="a String variable is given its value by one "
                               "equation (or its binding)")
        if isinstance(value, StringVariable):
            raise FlattenError(f"an equation between the String variables '{target.name}' "
                               f"and '{value.name}' is not supported yet", span,
                               hint="give one of them its value first: s1 = \"...\"")
        if not isinstance(value, str):
            raise FlattenError(f"the String '{target.name}' is given a number", span,
                               hint="convert with String(...)")
        assign(target, value, span, at_events)
    return True


def assign(target: StringVariable, value: str, span: Span, at_events: bool) -> None:
    if at_events:
        target.at_events = True
        return
    if target.defined is not None:
        raise FlattenError(f"the String variable '{target.name}' is given a value twice",
                           span, [Note("first here", target.defined)],
                           "a String variable has one equation")
    target.value, target.defined = value, span


def _items(v: Any) -> list[Any]:
    return list(v.flat) if isinstance(v, np.ndarray) else [v]


def check_known(value: Any, span: Span) -> None:
    """A String variable read in an expression has a value already."""
    for item in _items(value):
        if isinstance(item, StringVariable):
            if item.at_events:
                raise FlattenError(f"reading the discrete String '{item.name}' (assigned in "
                                   "a when-clause) is not supported yet", span, hint=_HINT)
            raise FlattenError(f"the String variable '{item.name}' is read before the "
                               "equation that gives its value", span,
                               [Note("declared here", item.span)],
                               "springc evaluates Strings while flattening: write the "
                               "equation that gives its value before its uses")


_RELATIONS = {"==": "__eq__", "<>": "__ne__", "<": "__lt__", "<=": "__le__",
              ">": "__gt__", ">=": "__ge__"}


def string_binary(op: str, left: Any, right: Any, span: Span) -> a.Value | None:
    """``"a" + "b"`` and relations on Strings (sections 3.5, 3.6.1); None if neither
    operand is a String."""
    if not (is_string(left) or is_string(right)):
        return None
    check_known(left, span)
    check_known(right, span)
    if not (isinstance(left, str) and isinstance(right, str)):
        raise FlattenError(f"'{op}' needs two Strings here, found a String and a number "
                           "or an array", span, hint="convert a number with String(...)")
    if op == "+":
        return left + right
    method = _RELATIONS.get(op)
    if method is None:
        raise FlattenError(f"'{op}' is not defined on Strings", span,
                           hint="Strings have `+` (concatenation) and the relations")
    return x.Const(bool(getattr(left, method)(right)))


#: ``format`` of String(r, format = ...): flags, width, precision and the conversion of
#: a Real (e, f, g) or of an Integer (d, i, o, x, c) (section 3.7.1).
_REAL_FORMAT = re.compile(r"[-+ 0#]*\d*(\.\d+)?[eEfgG]")
_INTEGER_FORMAT = re.compile(r"[-+ 0#]*\d*[diuoxXc]")


def string_call(ev: ExpressionEvaluator, call: s.Call, scope: Scope) -> str:
    """``String(e, minimumLength = n, leftJustified = b, significantDigits = d)`` and
    ``String(r, format = "8.3f")`` of a value known while flattening (section 3.7.1)."""
    if len(call.args) != 1:
        raise FlattenError(f"'String' takes 1 positional argument, {len(call.args)} given",
                           call.span)
    options: dict[str, Any] = {}
    for named in call.named:
        if named.name not in ("minimumLength", "leftJustified", "significantDigits",
                              "format"):
            raise FlattenError(f"'String' has no argument '{named.name}'", named.span,
                               hint="its arguments are minimumLength, leftJustified, "
                               "significantDigits and format")
        options[named.name] = ev.constant(named.value, scope, f"'{named.name}'")
    _check_widths(ev, options, call)
    arg = read(ev.value(call.args[0], scope))
    check_known(arg, call.args[0].span)
    if isinstance(arg, str):
        return arg
    try:
        value = ev.fold(arg)
    except KeyError as missing:
        value = _bound(ev, call.args[0], scope)
        if value is not None:
            return _text(value, options, call)
        raise FlattenError(f"'String' of a value that changes during the simulation is not "
                           f"supported yet: it depends on {missing.args[0]}",
                           call.args[0].span, hint=_HINT) from None
    if isinstance(value, np.ndarray):
        raise FlattenError("'String' of an array is not defined", call.args[0].span)
    return _text(value, options, call)


def _check_widths(ev: ExpressionEvaluator, options: dict[str, Any], call: s.Call) -> None:
    """Refuse a width or a number of digits past the size cap before any text is made
    (``minimumLength = 10^9`` would make a String of a gigabyte)."""
    numbers: list[tuple[str, Any]] = [(key, options[key]) for key in (
        "minimumLength", "significantDigits") if key in options]
    spec = options.get("format")
    if isinstance(spec, str):
        numbers += [("format", float(n) if len(n) < 20 else math.inf)
                    for n in re.findall(r"\d+", spec)]
    for key, number in numbers:
        if isinstance(number, (int, float, np.integer, np.floating)):
            ev.flattener.limits.check_size(float(number), f"the '{key}' of String(...)",
                                           call.span, "characters")


def _bound(ev: ExpressionEvaluator, e: s.Expr, scope: Scope) -> Any:
    """The value of a variable whose binding equation is a parameter expression (``E e1
    = E.one``: e1 is E.one at all times), else None."""
    prim = declared(e, scope) if isinstance(e, s.Ref) else None
    if prim is None or prim.dims or prim.mod is None or prim.mod.value is None:
        return None
    try:
        return ev.fold(ev.flattener.mod_value(prim.mod.value))
    except (KeyError, ArithmeticError, ValueError, TypeError):
        return None


def _text(value: Any, options: dict[str, Any], call: s.Call) -> str:
    if isinstance(value, EnumLiteral):
        text = value.literal
    elif isinstance(value, (bool, np.bool_)):
        text = "true" if value else "false"
    elif "format" in options:
        spec = options["format"]
        integer = isinstance(value, (int, np.integer))
        pattern = _INTEGER_FORMAT if integer else _REAL_FORMAT
        if not isinstance(spec, str) or not pattern.fullmatch(spec):
            example = "\"5d\"" if integer else "\"8.3f\""
            raise FlattenError(f"the format of a{'n Integer' if integer else ' Real'} is "
                               f"written like {example}, found {spec!r}", call.span,
                               hint="flags, width, precision and a conversion: e, f or g "
                               "for a Real, d for an Integer (Modelica 3.6, section 3.7.1)")
        return f"{int(value) if integer else float(value):{spec.replace('u', 'd')}}"
    elif isinstance(value, (int, np.integer)):
        text = str(int(value))
    else:
        text = real_text(float(value), int(options.get("significantDigits", 6)))
    width = int(options.get("minimumLength", 0))
    return text.ljust(width) if options.get("leftJustified", True) else text.rjust(width)


def real_text(value: float, digits: int) -> str:
    """A Real as ``String`` shows it: ``digits`` significant digits, ``%g`` style."""
    if math.isnan(value):
        return "NaN"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return f"{value:.{max(1, digits)}g}"


def undefined_strings(value: Any) -> list[FlattenError]:
    """A String variable that no equation gives a value (nor a when-clause)."""
    return [FlattenError(f"the String variable '{item.name}' has no equation giving its "
                         "value", item.span, hint="bind it (String s = \"...\") or write "
                         "an equation s = \"...\"")
            for item in _items(value)
            if isinstance(item, StringVariable) and item.value is None and not item.at_events]


def string_component(ctx: FlattenContext, decl: s.Component, rtype: ResolvedType,
                     mod: Mod | None, dims: tuple[int, ...], name: str) -> Primitive:
    """A ``String`` component: its value or its :class:`StringVariable`s (it is not a
    variable of the flat model)."""
    variability = decl.variability or rtype.prefixes[0]
    check_attribute_mods(mod, "String", name)
    names = [name] if not dims else [
        f"{name}[{','.join(map(str, idx))}]"
        for idx in itertools.product(*(range(1, n + 1) for n in dims))]
    if mod is not None and mod.value is not None:
        value = ctx.mod_value(mod.value)
        if not is_string(value) or a.shape(value) != dims:
            raise FlattenError(
                f"'{name}' is a String array of size {a.describe_shape(dims)} and must "
                "be given Strings of that size" if dims else
                f"'{name}' is a String and must be given a string", mod.value.span)
        check_known(value, mod.value.span)
    elif variability in ("parameter", "constant"):
        value = a.make_array([""] * len(names), dims) if dims else ""
    else:  # given by an equation
        value = string_variables(names, dims, decl.span)
    return Primitive(a.make_array(names, dims) if dims else name, value, decl,
                     variability or "discrete", decl.causality, False, "String", mod, dims)
