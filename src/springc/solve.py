"""Solving one equation for one variable, on :mod:`springc.expr` trees.

``linear_split(r, v)`` writes a residual as ``a*v + b`` when ``v`` appears linearly
(``a`` free of ``v``); ``solve_for`` then gives ``v = -b/a``. ``fold`` rebuilds an
expression with constant folding after a substitution.
"""

from __future__ import annotations

from collections.abc import Mapping

from . import expr as x

_BUILD = {"+": x.add, "-": x.sub, "*": x.mul, "/": x.div, "^": x.power}


def fold(e: x.Expr) -> x.Expr:
    """Rebuild ``e`` bottom-up, folding constants and dropping zeros and ones."""
    if isinstance(e, (x.Const, x.Var, x.Time)):
        return e
    if isinstance(e, x.BinOp):
        left, right = fold(e.left), fold(e.right)
        build = _BUILD.get(e.op)
        if build is not None:
            return build(left, right)
        if isinstance(left, x.Const) and isinstance(right, x.Const):
            return x.Const(x.evaluate(x.BinOp(e.op, left, right), {}))
        return x.BinOp(e.op, left, right)
    if isinstance(e, x.Neg):
        return x.neg(fold(e.arg))
    if isinstance(e, x.Not):
        arg = fold(e.arg)
        return x.Const(not arg.value) if isinstance(arg, x.Const) else x.Not(arg)
    if isinstance(e, x.Call):
        args = tuple(fold(a) for a in e.args)
        if all(isinstance(a, x.Const) for a in args) and e.name in x.MATH:
            try:
                return x.Const(x.MATH[e.name](*(a.value for a in args)))  # type: ignore
            except (ValueError, ZeroDivisionError, OverflowError):
                pass
        return x.Call(e.name, args)
    if isinstance(e, x.If):
        cond = fold(e.cond)
        if isinstance(cond, x.Const):
            return fold(e.then) if cond.value else fold(e.otherwise)
        return x.If(cond, fold(e.then), fold(e.otherwise))
    return e


def substitute_fold(e: x.Expr, mapping: Mapping[str, x.Expr]) -> x.Expr:
    return fold(x.substitute(e, mapping))


def linear_split(r: x.Expr, name: str) -> tuple[x.Expr, x.Expr] | None:
    """``(a, b)`` with ``r == a*name + b`` and neither depending on ``name``, or None."""
    a = fold(x.diff(r, name))
    if a == x.ZERO or name in x.variables(a):
        return None
    b = substitute_fold(r, {name: x.ZERO})
    return a, b


def solve_for(r: x.Expr, name: str) -> x.Expr | None:
    """The value of ``name`` that makes the residual ``r`` zero, if ``r`` is linear in it."""
    split = linear_split(r, name)
    if split is None:
        return None
    a, b = split
    return fold(x.div(x.neg(b), a))


def solvable(r: x.Expr, name: str, knowns_only: bool = True) -> bool:
    """Can ``name`` be solved from ``r`` explicitly, with a coefficient that cannot be
    zero by accident (a constant, or a parameter expression when ``knowns_only``)?"""
    split = linear_split(r, name)
    if split is None:
        return False
    a = split[0]
    return isinstance(a, x.Const) or not knowns_only
