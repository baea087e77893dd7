"""A when-clause branch's assignments under one guard (codegen.statements.Guard): the
exact statements and lines printed, values against closed forms, a guarded value that
must not run where its guard is false, and a sampled when-clause simulated by the
python and numba backends against its closed form."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

import springc
from springc.codegen.c_printer import c_function_body
from springc.codegen.printer import function_lines
from springc.codegen.statements import Guard, Let, Load, Namer, Raw, Store, guarded
from springc.ir.expr import BinOp, Call, Const, If, Not, Var

N, S = Var("m"), Var("s")
TEST = BinOp("<", N, Const(3))
ROOT = Call("sqrt", (S,))
SHARED = BinOp("+", ROOT, Const(1.0))  # read by both values of the else branch
LETS = [Let("a", Call("noEvent", (If(TEST, Const(1.0), SHARED),))),
        Let("b", If(TEST, Const(2.0), BinOp("*", Const(2.0), SHARED)))]


def _run(fire: float, n: float, s: float) -> tuple[dict[str, float], list[str]]:
    stmts = [Load("fire", "fire_in"), Load("m", "n_in"), Load("s", "s_in"),
             Load("a", "0.0"), Load("b", "0.0"),
             guarded(BinOp("<>", Var("fire"), Const(0.0)), LETS),
             Raw("out = [0.0, 0.0]"), Store("out[0]", Var("a")), Store("out[1]", Var("b"))]
    body = function_lines(Namer(), set(), stmts)
    scope: dict[str, object] = {"math": math}
    exec("def f(fire_in, n_in, s_in):\n" + "\n".join(body) + "\n    return out\n", scope)
    out = scope["f"](fire, n, s)  # type: ignore[operator]
    return {"a": out[0], "b": out[1]}, body


def test_a_run_of_values_on_one_test_becomes_two_guards() -> None:
    guard = guarded(Var("fire"), LETS)
    assert guard.cond == Var("fire")
    assert [type(s).__name__ for s in guard.body] == ["Guard", "Guard"]
    first, second = guard.body
    assert isinstance(first, Guard) and isinstance(second, Guard)
    assert first.cond is TEST and second.cond == Not(TEST)
    assert [(s.name, s.expr) for s in first.body if isinstance(s, Let)] == [
        ("a", Const(1.0)), ("b", Const(2.0))]
    assert [(s.name, s.expr) for s in second.body if isinstance(s, Let)] == [
        ("a", SHARED), ("b", BinOp("*", Const(2.0), SHARED))]


def test_the_guarded_values_print_once_under_their_guards() -> None:
    _, body = _run(1.0, 5.0, 16.0)
    assert [re.sub(r"_c[0-9]+", "_c#", line) for line in body[5:]] == [
        "    if fire != 0.0:",
        "        _c# = m < 3",
        "        if _c#:",
        "            a = 1.0",
        "            b = 2.0",
        "        if not _c#:",
        "            a = math.sqrt(s) + 1.0",  # the shared value, which a holds
        "            b = 2.0 * a",
        "    out = [0.0, 0.0]",
        "    out[0] = a",
        "    out[1] = b",
    ]


@pytest.mark.parametrize(("fire", "n", "s", "a", "b"), [
    (1.0, 5.0, 16.0, 5.0, 10.0),  # sqrt(16) + 1 and twice that
    (1.0, 1.0, -4.0, 1.0, 2.0),   # math.sqrt(-4) must not run: its guard is false
    (0.0, 5.0, -4.0, 0.0, 0.0),   # not fired: the values before the guard
])
def test_guarded_values_equal_their_closed_forms(
        fire: float, n: float, s: float, a: float, b: float) -> None:
    values, _ = _run(fire, n, s)
    assert values == {"a": a, "b": b}


def test_a_run_ends_before_a_value_of_its_test_is_assigned() -> None:
    lets = [Let("a", If(TEST, Const(1.0), Const(4.0))),
            Let("m", If(TEST, BinOp("+", N, Const(1.0)), N)),
            Let("b", If(TEST, Const(2.0), Const(5.0)))]
    guard = guarded(Var("fire"), lets)
    # 'm' is the test's variable: the test is read again after it is assigned
    assert [type(s).__name__ for s in guard.body] == ["Let", "Let", "Let"]


def test_the_c_printer_opens_and_closes_a_guard() -> None:
    lines = c_function_body(Namer(), set(), [
        Load("a", "z[0]"), Load("m", "z[1]"),
        Guard(BinOp(">", N, Const(0.0)), [Let("a", BinOp("*", N, Const(2.0)))]),
        Store("z[0]", Var("a"))])
    assert lines == ["    double a, m;", "    a = z[0];", "    m = z[1];",
                     "    if (m > 0.0) {", "        a = m * 2.0;", "    }",
                     "    z[0] = a;"]


SAMPLED = """model Sampled "one when-clause assigning several variables"
  Real a(start = 0, fixed = true);
  Real b(start = 0, fixed = true);
  Real c(start = 0, fixed = true);
  Integer n(start = 0, fixed = true);
algorithm
  when sample(0.1, 0.25) then
    n := pre(n) + 1;
    if n < 3 then
      a := 1;
      b := 2;
      c := a + b;
    else
      a := (time + 1)^2 + exp(time);
      b := 2*((time + 1)^2 + exp(time));
      c := a + ((time + 1)^2 + exp(time));
    end if;
  end when;
end Sampled;
"""


def _f(t: float) -> float:
    return (t + 1) ** 2 + math.exp(t)


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_a_sampled_when_clause_equals_its_closed_form(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, backend: str) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "Sampled.mo"
    path.write_text(SAMPLED, encoding="utf-8")
    model = springc.compile_model([str(path)], backend=backend)
    result = springc.simulate(model, stop=1.0)
    # samples at 0.1, 0.35 (n = 1, 2), 0.6 and 0.85 (n = 3, 4)
    at = {round(float(t), 9): i for i, t in enumerate(result.time)}
    for t, a, b, c in [(0.5, 1.0, 2.0, 3.0), (0.7, _f(0.6), 2 * _f(0.6), 2 * _f(0.6)),
                       (1.0, _f(0.85), 2 * _f(0.85), 2 * _f(0.85))]:
        k = at[t]
        assert result["a"][k] == pytest.approx(a, rel=1e-14)
        assert result["b"][k] == pytest.approx(b, rel=1e-14)
        assert result["c"][k] == pytest.approx(c, rel=1e-14)
    assert result["n"][at[1.0]] == 4.0


def test_a_left_fold_of_max_prints_as_one_call() -> None:
    # RealFFT's 0.0001*max(amplitudes) of 401 values: nested, Python refuses it
    # (too many nested parentheses)
    fold = Var("v0")
    for k in range(1, 401):
        fold = Call("max", (fold, BinOp("*", Const(float(k % 7)), Var("w"))))
    body = function_lines(Namer(), set(), [Load("v0", "-1.0"), Load("w", "w_in"),
                                           Raw("out = [0.0]"), Store("out[0]", fold)])
    assert body[-1].count("max(") == 1
    scope: dict[str, object] = {"math": math}
    exec("def f(w_in):\n" + "\n".join(body) + "\n    return out\n", scope)
    assert scope["f"](2.0) == [12.0]  # type: ignore[operator]
    assert scope["f"](-2.0) == [0.0]  # type: ignore[operator]
