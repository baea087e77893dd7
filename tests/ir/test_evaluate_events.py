"""The reference evaluator (springc.ir.expr.evaluate) knows every event operator: each
takes its value at the instant the environment describes, and an operator it has no
value for is its own error (NotEvaluable), never a KeyError read as a missing variable."""

from __future__ import annotations

import pytest

from springc.ir import expr as x

B = x.Var("b")


@pytest.mark.parametrize(("e", "env", "time", "initial", "value"), [
    (x.Call("initial", ()), {}, 0.0, None, False),  # the continuous phase
    (x.Call("initial", ()), {x.INITIAL: True}, 0.0, None, True),
    (x.Call("initial", ()), {}, 0.0, True, True),
    (x.Call("terminal", ()), {}, 0.0, None, False),
    (x.Call("pre", (B,)), {"b": 1.0}, 0.0, None, 1.0),  # away from events: v itself
    (x.Call("pre", (B,)), {"b": 1.0, "pre(b)": 0.0}, 0.0, None, 0.0),
    (x.Call("edge", (B,)), {"b": True, "pre(b)": False}, 0.0, None, True),
    (x.Call("edge", (B,)), {"b": True}, 0.0, None, False),
    (x.Call("change", (B,)), {"b": 2.0, "pre(b)": 1.0}, 0.0, None, True),
    (x.Call("change", (B,)), {"b": 2.0}, 0.0, None, False),
    (x.Call("sample", (x.Const(0.5), x.Const(0.25))), {}, 1.0, None, True),
    (x.Call("sample", (x.Const(0.5), x.Const(0.25))), {}, 0.9, None, False),
    (x.Call("sample", (x.Const(0.5), x.Const(0.25))), {}, 0.25, None, False),  # before start
    (x.If(x.Call("initial", ()), x.Const(1.0), x.Const(2.0)), {}, 0.0, True, 1.0),
])
def test_event_operators_take_the_values_of_the_instant(
        e: x.Expr, env: dict[str, object], time: float, initial: bool | None,
        value: object) -> None:
    assert x.evaluate(e, env, time, initial) == value


def test_an_operator_without_a_value_is_its_own_error() -> None:
    with pytest.raises(x.NotEvaluable, match=r"^delay\(\.\.\.\) has no value here$"):
        x.evaluate(x.Call("delay", (B, x.Const(1.0))), {"b": 1.0})
    assert issubclass(x.NotEvaluable, ValueError) and not issubclass(x.NotEvaluable,
                                                                       KeyError)
