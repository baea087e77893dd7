"""Values whose sub-expressions are shared (a function's loop builds them: the
Bessel/Chebyshev coefficients of ``Blocks.Examples.Filter``) are visited as graphs,
not trees, by the flattener's own passes: the power check of a parameter value and
the de-duplication of assertions. Each graph below is a tree of 2^80 nodes."""

from __future__ import annotations

import pytest

from springc.errors import Span
from springc.flatten.calls import unique
from springc.flatten.scopes import check_powers
from springc.ir import expr as x
from springc.ir import flat


def doubling(leaf: x.Expr, times: int = 80) -> x.Expr:
    """``leaf`` added to itself ``times`` times over: 2^times leaves, times + 1 nodes."""
    e = leaf
    for _ in range(times):
        e = x.BinOp("+", e, e)
    return e


def test_the_power_check_visits_a_shared_node_once() -> None:
    check_powers(doubling(x.BinOp("^", x.Var("p"), x.Const(3))), {"p": 2})
    huge = x.BinOp("^", x.Const(10), x.Var("n"))
    with pytest.raises(OverflowError) as caught:
        check_powers(doubling(huge), {"n": 5000})
    assert str(caught.value) == "10 ^ 5000 is too large"


def test_equal_assertions_of_shared_values_are_kept_once() -> None:
    span = Span("m.mo", 3, 5, 3, 20)
    origin = flat.Origin("equation", "f")

    def item(condition: x.Expr, message: str = "too large") -> tuple[flat.Assertion, Span]:
        return flat.Assertion(condition, message, "error", span, origin), span

    def below(limit: float) -> x.Expr:  # built anew each time: equal, not identical
        return x.BinOp("<", doubling(x.Var("a")), x.Const(limit))

    kept = unique([item(below(1.0)), item(below(1.0)), item(below(2.0)),
                   item(below(1.0), "other"), item(below(1))])
    assert [(x.to_text(a.condition.right), a.message) for a in kept] == [  # type: ignore[union-attr]
        ("1.0", "too large"), ("2.0", "too large"), ("1.0", "other")]
