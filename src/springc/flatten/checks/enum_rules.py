"""Enumeration values are not numbers (Modelica 3.6, section 4.9.5): an Integer or Real
is not bound to ``E.a``, a variable of type ``E`` not to ``2`` or to a literal of
another enumeration, and ``E.a == 1`` compares values of different types.

Input: a binding or the operands of a relation, with the scope they are written in.
Output: nothing, or a :class:`FlattenError` naming the rule. A type that cannot be told
from the expression (a function call, an element of a record) is never an error.
"""

from __future__ import annotations

from typing import Any

from ...errors import FlattenError
from ...ir import expr as x
from ...ir import syntax as s
from ..scopes import Enumeration, EnumLiteral, ExpressionEvaluator, Scope
from .rules import rule_error
from .type_rules import declared

#: The kind of a value for these rules: an enumeration, NUMBER for any other value
#: (Integer, Real, Boolean, String), or None when it cannot be told.
NUMBER = "number"
Kind = Enumeration | str | None

_RULE = ("enumeration values are neither Integers nor Reals: convert with Integer(e), "
         "and compare only values of the same enumeration type")
_RELATIONS = frozenset({"<", "<=", ">", ">=", "==", "<>"})
_NUMBERS = frozenset({"Integer", "String", "size", "ndims", "integer", "floor", "ceil",
                      "abs", "sum", "product", "sqrt", "sin", "cos", "exp", "log"})


def static_kind(e: s.Expr, scope: Scope, ev: ExpressionEvaluator) -> Kind:
    """The kind of ``e``: its enumeration type, NUMBER, or None if unknown."""
    if isinstance(e, (s.Number, s.Bool, s.String, s.Range)):
        return NUMBER
    if isinstance(e, (s.Binary, s.Unary)):
        return NUMBER  # arithmetic, relations and logic never give an enumeration
    if isinstance(e, s.Ref):
        return _ref_kind(e, scope, ev)
    if isinstance(e, s.IfExpr):
        return _common([static_kind(v, scope, ev) for _, v in e.branches]
                       + [static_kind(e.otherwise, scope, ev)])
    if isinstance(e, s.ArrayLit):
        return _common([static_kind(item, scope, ev) for item in e.items])
    if isinstance(e, s.Call) and e.func.dotted in _NUMBERS:
        return NUMBER
    return None


def _common(kinds: list[Kind]) -> Kind:
    return kinds[0] if kinds and all(k == kinds[0] for k in kinds) else None


def _ref_kind(e: s.Ref, scope: Scope, ev: ExpressionEvaluator) -> Kind:
    bare = s.Ref(tuple(s.RefPart(p.name, (), p.span) for p in e.parts), e.span,
                 e.is_global)
    prim = declared(bare, scope)
    if prim is not None:
        return prim.enumeration if prim.enumeration is not None else NUMBER
    try:
        value = ev.value(e, scope)
    except FlattenError:  # reported where the reference is evaluated
        return None
    return value_kind(value)


def value_kind(value: Any) -> Kind:
    """The kind of an evaluated value: known for constants only."""
    if isinstance(value, x.Const):
        v = value.value
        return v.enumeration if isinstance(v, EnumLiteral) else NUMBER
    return None


def _name(kind: Kind) -> str:
    return f"a value of enumeration type '{kind.name}'" if isinstance(kind, Enumeration) \
        else "a number"


def check_enum_binding(name: str, type_name: str, enumeration: Enumeration | None,
                       e: s.Expr | None, scope: Scope | None, ev: ExpressionEvaluator
                       ) -> None:
    """A variable of type ``E`` is bound to a value of ``E``; any other variable is not
    bound to an enumeration value."""
    if e is None or scope is None:
        return
    kind = static_kind(e, scope, ev)
    if kind is None or kind == (enumeration or NUMBER):
        return
    if isinstance(kind, str) and enumeration is None:
        return
    declared_as = f"of enumeration type '{enumeration.name}'" if enumeration is not None \
        else f"a {type_name}" if type_name != "Integer" else "an Integer"
    raise rule_error(f"'{name}' is {declared_as}, but it is given {_name(kind)}",
                     e.span, _RULE, "4.9.5")


def check_enum_relation(e: s.Binary, left: Any, right: Any, scope: Scope,
                        ev: ExpressionEvaluator) -> None:
    """``E.a == 1``, ``E.a < F.b``: a relation on an enumeration value compares it with
    a value of the same enumeration."""
    if e.op not in _RELATIONS:
        return
    kinds = [value_kind(v) for v in (left, right)]
    for k, side in enumerate((e.left, e.right)):
        if kinds[k] is None and isinstance(side, s.Ref):
            kinds[k] = static_kind(side, scope, ev)
    if None in kinds or kinds[0] == kinds[1] or not any(
            isinstance(k, Enumeration) for k in kinds):
        return
    raise rule_error(f"'{e.op}' compares {_name(kinds[0])} with {_name(kinds[1])}",
                     e.span, _RULE, "4.9.5")
