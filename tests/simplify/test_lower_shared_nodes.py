"""Lowering ``der`` visits a node shared by several parents once and keeps it shared:
the assertions of Blocks.Continuous.Filter's coefficient functions are graphs whose
trees are exponential, and lowering them as trees never finished."""

from __future__ import annotations

from springc.ir import dae
from springc.ir import expr as x
from springc.simplify.lower import lower_derivatives


def test_a_shared_graph_is_lowered_once_and_stays_shared() -> None:
    e: x.Expr = x.Der(x.Var("v"))
    for _ in range(200):  # a tree of 2^200 leaves
        e = x.BinOp("+", x.BinOp("*", e, e), x.Const(1))
    lowered = lower_derivatives(e, lambda name: name == "v")
    node = lowered
    for _ in range(200):
        assert isinstance(node, x.BinOp) and isinstance(node.left, x.BinOp)
        assert node.left.left is node.left.right
        node = node.left.left
    assert node == x.Var(dae.derivative_name("v"))
    assert x.evaluate(lower_derivatives(
        x.BinOp("*", x.Der(x.Var("v")), x.Var("p")), lambda n: n == "v"),
        {dae.derivative_name("v"): 3.0, "p": 2.0}) == 6.0
