"""``break`` under a condition known only during the simulation in a ``for`` loop of
an algorithm section (section 11.2.5), for :mod:`.algorithms`.

The statements execute symbolically, so the loop is unrolled and its break becomes a
Boolean expression ``broken``: where it holds the loop was left, and the statements
and iterations after the break keep the values (:func:`kept`). The values grow by
one if-expression per iteration; :func:`too_large` bounds them.
"""

from __future__ import annotations

from collections.abc import Iterable

from ...ir import expr as x
from ..scopes import Ident

TRUE, FALSE = x.Const(True), x.Const(False)

NEUTRAL = {"+": x.Const(0), "-": x.Const(0), "*": x.Const(1), "/": x.Const(1)}
#: Terms (nodes of the expression tree) a value may reach in a for loop after a break
#: under a run-time condition: each iteration nests the values one if-expression deeper.
BROKEN_TERMS = 20_000


def too_large(values: Iterable[x.Expr]) -> bool:
    """Whether an expression tree of ``values`` has more than :data:`BROKEN_TERMS`
    nodes (counted on the shared nodes, in time linear in the distinct ones)."""
    sizes: dict[Ident[x.Expr], int] = {}

    def size(e: x.Expr) -> int:
        found = sizes.get(Ident(e))
        if found is None:
            found = sizes[Ident(e)] = 1 + sum(size(c) for c in x.children(e))
        return found

    return any(size(v) > BROKEN_TERMS for v in values)


def kept(broken: x.Expr, old: x.Expr, value: x.Expr) -> x.Expr:
    """``value`` where the loop was not left (``broken`` false), else ``old``; an
    if-expression that keeps ``old`` in a branch takes ``broken`` into its condition,
    so that ``old`` appears once."""
    if isinstance(value, x.If) and value.otherwise is old:
        return x.If(x.BinOp("and", x.Not(broken), value.cond), value.then, old)
    if isinstance(value, x.If) and value.then is old:
        return x.If(x.BinOp("or", broken, value.cond), old, value.otherwise)
    if isinstance(value, x.BinOp) and value.left is old and value.op in NEUTRAL:
        # an accumulation old + r: old + (if broken then 0 else r)
        return x.BinOp(value.op, old, x.If(broken, NEUTRAL[value.op], value.right))
    return x.If(broken, old, value)


def choose(cond: x.Expr, then: x.Expr, otherwise: x.Expr) -> x.Expr:
    """``if cond then then else otherwise`` for Boolean flags, folded."""
    if then == otherwise:
        return then
    if then == TRUE:
        return cond if otherwise == FALSE else x.BinOp("or", cond, otherwise)
    if then == FALSE and otherwise == TRUE:
        return x.Not(cond)
    return x.If(cond, then, otherwise)
