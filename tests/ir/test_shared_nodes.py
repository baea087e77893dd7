"""Expressions that share sub-expressions (inlined functions build them: MultiBody's
``Frames.from_nxy`` is a graph of 150 nodes whose tree has 76 000): ``walk`` visits a
shared node once and ``substitute`` rewrites it once, keeping it shared."""

from __future__ import annotations

from springc.ir import expr as x


def _doubling(depth: int) -> x.Expr:
    """``e_k = e_(k-1) + e_(k-1)`` from ``e_0 = a * b``: a graph of ``depth + 3``
    nodes whose tree has ``2**(depth + 2) - 1``."""
    e: x.Expr = x.BinOp("*", x.Var("a"), x.Var("b"))
    for _ in range(depth):
        e = x.BinOp("+", e, e)
    return e


def test_walk_visits_a_shared_node_once() -> None:
    e = _doubling(60)  # a tree of 2**62 nodes
    nodes = list(x.walk(e))
    assert sum(isinstance(n, x.BinOp) for n in nodes) == 61
    assert x.variables(e) == {"a", "b"}


def test_substitute_keeps_sharing() -> None:
    e = _doubling(60)
    out = x.substitute(e, {"a": x.Const(2)})
    assert isinstance(out, x.BinOp) and out.left is out.right
    assert x.variables(out) == {"b"}
    inner = out
    for _ in range(60):
        assert isinstance(inner, x.BinOp)
        inner = inner.left
    assert x.to_text(inner) == "2 * b"


def test_evaluate_visits_a_shared_node_once() -> None:
    e = _doubling(60)
    assert x.evaluate(e, {"a": 3.0, "b": 0.5}) == 1.5 * 2.0**60
