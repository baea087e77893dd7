"""``cardinality(c)`` (Modelica 3.6, section 3.7.4.4; deprecated but valid).

``cardinality(c)`` is the number of ``connect`` equations that name the connector
``c``, from inside or from outside. It is known only once every connect equation of
the model is flat, but the expression that uses it may be flattened earlier (a
binding inside the component whose connector the enclosing model connects). So
:func:`cardinality_call` gives the placeholder call ``cardinality(<connector name>)``
and :func:`apply_cardinalities`, run after all equations are flat, replaces each by
its Integer count. A placeholder is a :class:`~springc.ir.expr.Var` of the
connector's flat name, so that equation templates rename it with their prefix.
"""

from __future__ import annotations

import dataclasses
from collections import Counter

from ...errors import FlattenError
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ..scopes import ClassScope, ExpressionEvaluator, FlatResults, Leaf, Scope

NAME = "cardinality"


def cardinality_call(ev: ExpressionEvaluator, e: s.Call, scope: Scope) -> x.Expr:
    """The placeholder of ``cardinality(c)`` (its argument checked)."""
    if len(e.args) != 1 or e.named:
        raise FlattenError("cardinality takes one argument: cardinality(c) with c a "
                           "connector", e.span)
    arg = e.args[0]
    target = ev.reference(arg, scope) if isinstance(arg, s.Ref) else None
    if isinstance(target, ClassScope) and target.kind == "connector":
        return x.Call(NAME, (x.Var(target.prefix),))
    if isinstance(target, Leaf):
        return x.Call(NAME, (x.Var(target.name),))
    raise FlattenError("the argument of cardinality must be a connector",
                       arg.span, hint="cardinality(c) counts the connect equations "
                       "that name the connector c, a scalar connector "
                       "(Modelica 3.6, section 3.7.4.4)")


def _replace(e: x.Expr, counts: Counter[str], memo: dict[int, tuple[x.Expr, x.Expr]]
             ) -> x.Expr:
    """``e`` with its placeholders replaced (unchanged subtrees shared; a subtree
    shared by several parents, as inlined functions make them, visited once)."""
    found = memo.get(id(e))
    if found is not None and found[0] is e:
        return found[1]
    if isinstance(e, x.Call) and e.name == NAME and isinstance(e.args[0], x.Var):
        out: x.Expr = x.Const(counts[e.args[0].name])
    elif isinstance(e, x.Const | x.Var):
        return e
    else:
        out = x.map_children(e, lambda c: _replace(c, counts, memo))
        if out is not e:
            out = _decided(out)
    memo[id(e)] = (e, out)
    return out


_LOGICAL = x.RELATIONS | {"and", "or"}


def _decided(e: x.Expr) -> x.Expr:
    """``e`` with a condition that the counts made constant evaluated, and an ``if``
    on it reduced to its branch: an if-equation on ``cardinality(flange_a) > 0``
    (LineForceWithMass) keeps only the equations of the branch that holds. Else the
    other branches' equations stay in the if-expressions as unknowns the equation
    reads (``fb = if 1 > 0 then flange_b.f else -fa``), which couples variables the
    model does not couple (a larger algebraic loop) and makes the constant relations
    events."""
    if isinstance(e, x.BinOp) and e.op in _LOGICAL and isinstance(e.left, x.Const) \
            and isinstance(e.right, x.Const):
        return x.Const(x.evaluate(e, {}))
    if isinstance(e, x.Not) and isinstance(e.arg, x.Const):
        return x.Const(not e.arg.value)
    if isinstance(e, x.If) and isinstance(e.cond, x.Const):
        return e.then if e.cond.value else e.otherwise
    return e


def apply_cardinalities(fl: FlatResults, counts: Counter[str]) -> None:
    """Replace every ``cardinality`` placeholder by the connector's count."""
    memo: dict[int, tuple[x.Expr, x.Expr]] = {}
    for items in (fl.equations, fl.initial_equations):
        for i, eq in enumerate(items):
            lhs, rhs = _replace(eq.lhs, counts, memo), _replace(eq.rhs, counts, memo)
            if lhs is not eq.lhs or rhs is not eq.rhs:
                items[i] = flat.Equation(lhs, rhs, eq.span, eq.origin)
    for i, (item, span) in enumerate(fl.assertions):
        condition = _replace(item.condition, counts, memo)
        if condition is not item.condition:
            fl.assertions[i] = (dataclasses.replace(item, condition=condition), span)
