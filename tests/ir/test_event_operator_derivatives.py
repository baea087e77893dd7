"""The event operators are constant between events: their derivatives are zero (the
Jacobian of the MSL's logical networks, which read pre() of Boolean variables)."""

from __future__ import annotations

from springc.ir import expr as x


def test_event_operators_differentiate_to_zero() -> None:
    b = x.Var("b")
    for name in ("pre", "edge", "change"):
        e = x.mul(x.Var("u"), x.If(x.Call(name, (b,)), x.ONE, x.ZERO))
        assert x.evaluate(x.diff(e, "b"), {"u": 3.0, "b": 1.0, "pre(b)": 0.0}) == 0.0
    assert x.diff(x.Call("pre", (x.Var("v"),)), "v") == x.ZERO
    assert x.diff(x.Call("sample", (x.ZERO, x.ONE)), "v") == x.ZERO
