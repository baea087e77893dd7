"""The event operators are constant between events: their derivatives are zero (the
Jacobian of the MSL's logical networks, which read pre() of Boolean variables); of a
variable found to be a constant, ``pre`` is that constant and ``edge``/``change``
false (LogicalNetwork1's alias elimination)."""

from __future__ import annotations

from springc.ir import expr as x


def test_event_operators_differentiate_to_zero() -> None:
    b = x.Var("b")
    for name in ("pre", "edge", "change"):
        e = x.mul(x.Var("u"), x.If(x.Call(name, (b,)), x.ONE, x.ZERO))
        assert x.evaluate(x.diff(e, "b"), {"u": 3.0, "b": 1.0, "pre(b)": 0.0}) == 0.0
    assert x.diff(x.Call("pre", (x.Var("v"),)), "v") == x.ZERO
    assert x.diff(x.Call("sample", (x.ZERO, x.ONE)), "v") == x.ZERO


def test_event_operators_of_a_constant() -> None:
    e = x.BinOp("or", x.Call("edge", (x.Var("b"),)), x.Call("pre", (x.Var("b"),)))
    assert x.substitute(e, {"b": x.Const(True)}) == \
        x.BinOp("or", x.Const(False), x.Const(True))
    assert x.substitute(x.Call("change", (x.Var("k"),)), {"k": x.Const(2)}) == \
        x.Const(False)
