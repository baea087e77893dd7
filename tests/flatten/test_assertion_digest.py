"""Assertions are kept once each (an inlined function may run twice) by a structural
hash that visits a node shared by several parents once: the conditions of
Blocks.Continuous.Filter's coefficient functions are graphs whose trees are
exponential, and hashing them as trees took minutes (the check timed out)."""

from __future__ import annotations

from springc.errors import Span
from springc.flatten.calls import unique
from springc.ir import expr as x
from springc.ir import flat


def _doubling(levels: int, leaf: str) -> x.Expr:
    """``e_k = e_{k-1} * e_{k-1} + 1``: a graph of 2 levels nodes, a tree of 2^levels."""
    e: x.Expr = x.Var(leaf)
    for _ in range(levels):
        e = x.BinOp("+", x.BinOp("*", e, e), x.Const(1))
    return e


def _pending(condition: x.Expr, line: int) -> tuple[flat.Assertion, Span]:
    span = Span("f.mo", line, 1, line, 9)
    origin = flat.Origin("function", "a")
    return flat.Assertion(condition, "too large", "error", span, origin), span


def test_equal_conditions_built_twice_are_kept_once() -> None:
    first, again = _doubling(200, "p"), _doubling(200, "p")
    assert first is not again
    kept = unique([_pending(first, 3), _pending(again, 3)])
    assert [a.condition for a in kept] == [first] and kept[0].condition is first


def test_conditions_that_differ_are_both_kept() -> None:
    one, other = _doubling(200, "p"), _doubling(200, "q")
    assert [a.condition is c for a, c in zip(unique([_pending(one, 3), _pending(other, 3)]),
                                             (one, other))] == [True, True]
    assert len(unique([_pending(one, 3), _pending(one, 4)])) == 2
