"""Solving one equation for one variable, on :mod:`springc.expr` trees.

``linear_split(r, v)`` writes a residual as ``a*v + b`` when ``v`` appears linearly
(``a`` free of ``v``) in one pass over the tree; ``solve_for`` then gives ``v = -b/a``.
``fold`` rebuilds an expression with constant folding after a substitution.
``free_variables`` is a fast ``expr.variables``. Inside ``with counting() as work``,
``work`` counts the symbolic work of the body (``solve``: equations solved for a
variable, ``diff``: symbolic differentiations), which the benchmark reports to show
that it grows linearly with the model; outside, nothing is counted.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

from ..ir import expr as x
from ..ir.builtins import lookup

_BUILD = {"+": x.add, "-": x.sub, "*": x.mul, "/": x.div, "^": x.power}


@dataclass
class SymbolicWork:
    """The symbolic work done inside one :func:`counting` block."""

    solve: int = 0  # equations solved for a variable
    diff: int = 0  # symbolic differentiations


# The counts of the innermost ``counting`` block of this thread (or task), if any.
_WORK: ContextVar[SymbolicWork | None] = ContextVar("springc_symbolic_work", default=None)


@contextmanager
def counting() -> Iterator[SymbolicWork]:
    """Count the symbolic work done by the body, in this thread (or task) only."""
    work = SymbolicWork()
    token = _WORK.set(work)
    try:
        yield work
    finally:
        _WORK.reset(token)


def count_diff() -> None:
    """One symbolic differentiation, counted where a :func:`counting` block asks."""
    work = _WORK.get()
    if work is not None:
        work.diff += 1


def free_variables(e: x.Expr) -> set[str]:
    """Names of the variables in ``e`` (as ``expr.variables``, about 3x faster)."""
    out: set[str] = set()
    stack = [e]
    pop, push = stack.pop, stack.append
    var, binop, call = x.Var, x.BinOp, x.Call
    while stack:
        node = pop()
        kind = type(node)
        if kind is var:
            out.add(node.name)  # type: ignore[union-attr]
        elif kind is binop:
            push(node.left)  # type: ignore[union-attr]
            push(node.right)  # type: ignore[union-attr]
        elif kind is call:
            stack.extend(node.args)  # type: ignore[union-attr]
        elif kind is x.If:
            push(node.cond)  # type: ignore[union-attr]
            push(node.then)  # type: ignore[union-attr]
            push(node.otherwise)  # type: ignore[union-attr]
        elif kind in (x.Neg, x.Not, x.Der):
            push(node.arg)  # type: ignore[union-attr]
    return out


def pre_only(e: x.Expr) -> frozenset[str]:
    """The variables ``e`` reads only inside ``pre(...)``."""
    inside: set[str] = set()
    outside: set[str] = set()
    stack: list[tuple[x.Expr, bool]] = [(e, False)]
    while stack:
        node, held = stack.pop()
        if isinstance(node, x.Var):
            (inside if held else outside).add(node.name)
            continue
        held = held or (isinstance(node, x.Call) and node.name == "pre")
        stack.extend((child, held) for child in x.children(node))
    return frozenset(inside - outside)


def partial(e: x.Expr, name: str) -> x.Expr:
    """``d e / d name``, folded, and counted (:func:`count_diff`)."""
    count_diff()
    return fold(x.diff(e, name))


def neg(e: x.Expr) -> x.Expr:
    """``-e``, turning ``-(a - b)`` into ``b - a``."""
    if isinstance(e, x.BinOp) and e.op == "-":
        return x.sub(e.right, e.left)
    return x.neg(e)


def fold(e: x.Expr) -> x.Expr:
    """Rebuild ``e`` bottom-up, folding constants and dropping zeros and ones."""
    if isinstance(e, (x.Const, x.Var, x.Time)):
        return e
    if isinstance(e, x.BinOp):
        left, right = fold(e.left), fold(e.right)
        build = _BUILD.get(e.op)
        if build is not None:
            if e.op == "-" and isinstance(right, x.Neg):
                return x.add(left, right.arg)
            if e.op == "/" and right == x.Const(-1):
                return neg(left)
            return build(left, right)
        if isinstance(left, x.Const) and isinstance(right, x.Const):
            return x.Const(x.evaluate(x.BinOp(e.op, left, right), {}))
        return x.BinOp(e.op, left, right)
    if isinstance(e, x.Neg):
        return neg(fold(e.arg))
    if isinstance(e, x.Not):
        arg = fold(e.arg)
        return x.Const(not arg.value) if isinstance(arg, x.Const) else x.Not(arg)
    if isinstance(e, x.Call):
        args = tuple(fold(a) for a in e.args)
        seen = lookup(e.name)
        if seen is not None and seen.transparent is not None and \
                isinstance(args[seen.transparent], x.Const):  # smooth(1, 0) is 0
            return args[seen.transparent]
        if all(isinstance(a, x.Const) for a in args) and e.name in x.MATH:
            try:
                values = [a.value for a in args if isinstance(a, x.Const)]
                return x.Const(x.MATH[e.name](*values))
            except (ValueError, ZeroDivisionError, OverflowError):
                pass
        return x.Call(e.name, args)
    if isinstance(e, x.If):
        cond = fold(e.cond)
        if isinstance(cond, x.Const):
            return fold(e.then) if cond.value else fold(e.otherwise)
        then, otherwise = fold(e.then), fold(e.otherwise)
        if then == otherwise:  # d/ds of s*(if c then 1 else R): linear in s, whatever c
            return then
        return x.If(cond, then, otherwise)
    return e


_Split = tuple["x.Expr | None", x.Expr]


def _split(e: x.Expr, name: str) -> _Split | None:
    """``(a, b)`` with ``e == a*name + b``; ``a`` is None when ``name`` is absent (then
    ``b`` is ``e`` itself); None when ``e`` is not linear in ``name``."""
    kind = type(e)
    if kind is x.Var:
        return (x.ONE, x.ZERO) if e.name == name else (None, e)  # type: ignore[union-attr]
    if kind is x.Const or kind is x.Time:
        return None, e
    if kind is x.Neg:
        inner = _split(e.arg, name)  # type: ignore[union-attr]
        if inner is None or inner[0] is None:
            return None if inner is None else (None, e)
        return neg(inner[0]), neg(inner[1])
    if kind is x.BinOp and e.op in "+-*/":  # type: ignore[union-attr]
        return _split_binop(e, name)  # type: ignore[arg-type]
    for child in x.children(e):
        inner = _split(child, name)
        if inner is None or inner[0] is not None:
            return None
    return None, e


def _split_binop(e: x.BinOp, name: str) -> _Split | None:
    left, right = _split(e.left, name), _split(e.right, name)
    if left is None or right is None:
        return None
    (al, bl), (ar, br) = left, right
    if al is None and ar is None:
        return None, e
    op = e.op
    if op in "+-":
        build = x.add if op == "+" else x.sub
        a = build(al or x.ZERO, ar or x.ZERO)
        return a, build(bl if al is not None else e.left, br if ar is not None else e.right)
    if op == "*":
        if al is not None and ar is not None:
            return None
        if al is not None:
            return x.mul(al, e.right), x.mul(bl, e.right)
        return x.mul(e.left, ar), x.mul(e.left, br)  # type: ignore[arg-type]
    if ar is not None:  # division by an expression of ``name``
        return None
    return x.div(al, e.right), x.div(bl, e.right)  # type: ignore[arg-type]


def linear_split(r: x.Expr, name: str) -> tuple[x.Expr, x.Expr] | None:
    """``(a, b)`` with ``r == a*name + b`` and neither depending on ``name``, or None."""
    split = _split(r, name)
    if split is None or split[0] is None:
        return None
    a = fold(split[0])
    if a == x.ZERO:
        return None
    return a, split[1]


def solve_for(r: x.Expr, name: str) -> x.Expr | None:
    """The value of ``name`` that makes the residual ``r`` zero, if ``r`` is linear in it."""
    work = _WORK.get()
    if work is not None:
        work.solve += 1
    split = linear_split(r, name)
    if split is None:
        return None
    a, b = split
    if a == x.ONE:
        return neg(b)
    if a == x.Const(-1):
        return b
    if isinstance(a, x.Neg):
        return fold(x.div(b, a.arg))
    return fold(x.div(neg(b), a))


def solvable(r: x.Expr, name: str, knowns_only: bool = True) -> bool:
    """Can ``name`` be solved from ``r`` explicitly, with a coefficient that cannot be
    zero by accident (a constant, or a parameter expression when ``knowns_only``)?"""
    split = linear_split(r, name)
    if split is None:
        return False
    a = split[0]
    return isinstance(a, x.Const) or not knowns_only
