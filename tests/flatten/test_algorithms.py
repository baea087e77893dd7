"""Algorithm sections in models (section 11.1) and assert (section 8.3.7) while
flattening: exact flat equations, assertions and located errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import ErrorGroup, SpringcError, errors_of
from springc.ir import expr as x
from springc.ir.flat import FlatModel, format_flat
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, text: str, name: str = "m.mo") -> FlatModel:
    path = tmp_path / name
    path.write_text(text)
    return flatten_files([path], None)


def equations(m: FlatModel, initial: bool = False) -> list[str]:
    eqs = m.initial_equations if initial else m.equations
    return [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in eqs]


def asserts(m: FlatModel) -> list[tuple[str, str, str]]:
    return [(x.to_text(a.condition), a.message, a.level) for a in m.assertions]


def error_of(tmp_path: Path, text: str) -> str:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        flat_of(tmp_path, text)
    errors = errors_of(info.value)
    assert len(errors) == 1, [e.message for e in errors]
    err = errors[0]
    assert err.span is not None
    return f"{err.span.line}:{err.span.column}: {err.message}"


def test_assignments_become_one_equation_per_assigned_variable(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  Real x(start = 1);
  Real y;
  Real z[2];
equation
  der(x) = -x;
algorithm
  y := 2 * x;
  z := {y, 3};
  z[2] := z[1] + y;
end M;
""")
    assert equations(m) == ["der(x) = -x", "y = 2 * x", "z[1] = 2 * x",
                            "z[2] = 2 * x + 2 * x"]
    assert [e.origin.kind for e in m.equations[1:]] == ["algorithm"] * 3


def test_if_on_a_variable_merges_branches_and_for_loops_unroll(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  parameter Integer n = 3;
  Real x(start = 1);
  Real s;
  Real y(start = 5);
equation
  der(x) = -x;
algorithm
  s := 0;
  for i in 1:n loop
    s := s + i * x;
  end for;
  if noEvent(x > 0.5) then
    y := 1;
  end if;
end M;
""")
    # y keeps its start value (5) where the branch does not assign it (11.1.2)
    assert equations(m)[1:] == ["s = 0 + x + 2 * x + 3 * x",
                                "y = if noEvent(x > 0.5) then 1 else 5"]


def test_a_parameter_condition_keeps_both_branches(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  parameter Boolean up = false;
  Real y;
algorithm
  if up then
    y := 1;
  else
    y := -1;
  end if;
end M;
""")
    assert equations(m) == ["y = if up then 1 else -1"]


def test_initial_algorithm_gives_initial_equations(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  Real x;
initial algorithm
  x := 3;
equation
  der(x) = -x;
end M;
""")
    assert equations(m, initial=True) == ["x = 3"]


def test_assigning_a_parameter_is_an_error(tmp_path: Path) -> None:
    assert error_of(tmp_path, """model M
  parameter Real k = 1;
  Real y;
algorithm
  k := 2;
  y := k;
end M;
""") == "5:3: 'k' cannot be assigned: it is a parameter or constant"


def test_other_call_statements_are_not_supported_yet(tmp_path: Path) -> None:
    assert error_of(tmp_path, """model M
  Real y;
algorithm
  y := 1;
  print("a");
end M;
""") == "5:3: `print` is not supported yet as a statement"


def test_calls_for_effect_keep_function_assertions_under_their_branch(tmp_path: Path
                                                                      ) -> None:
    m = flat_of(tmp_path, """model M
  function f
    input Real u;
    output Boolean b;
  algorithm
    assert(u < 10, "u too large");
    b := true;
  end f;
  function msg
    output String s;
  algorithm
    assert(false, "never: the message is evaluated only on failure");
    s := "m";
  end msg;
  parameter Integer i = 4;
  Real x;
  Real y = time;
equation
  f(y);
algorithm
  assert(true, msg());
  if i == 4 then
    x := 3;
  elseif f(2 * y) then
    x := 4;
  end if;
  assert(x > 2, "x = " + String(x));
end M;
""")
    # f(2 * y) is true: the elseif branch is taken where i <> 4
    assert equations(m)[1:] == ["x = if i == 4 then 3 else 4"]
    assert asserts(m) == [
        ("y < 10", "u too large", "error"),
        # msg()'s own assertion is not the model's (8.3.7)
        ("true", "m", "error"),
        # f(2 * y) is evaluated only where i <> 4 (11.2.6)
        ("if not i == 4 then 2 * y < 10 else true", "u too large", "error"),
        # String(x) reads the value assigned so far
        ("(if i == 4 then 3 else 4) > 2", "x = 3", "error")]


def test_asserts_as_equation_statement_and_in_functions(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  function f
    input Real u;
    output Real y;
  algorithm
    if u > 0 then
      assert(u < 100, "u too large: limit " + String(100));
    end if;
    y := 2 * u;
  end f;
  parameter Real k = 2;
  Real x(start = 1);
  Real y;
equation
  der(x) = -k * x;
  y = noEvent(f(x));
  assert(k > 0, "k must be positive", AssertionLevel.warning);
algorithm
  assert(level = AssertionLevel.error, message = "y\\\\ \\"neg\\"", condition = y >= 0);
end M;
""")
    assert asserts(m) == [
        # the guard is f's branch condition: literal, as relations in function bodies
        # are (12.8); the assertion's own condition stays as written
        ("if noEvent(x > 0) then x < 100 else true", "u too large: limit 100", "error"),
        ("k > 0", "k must be positive", "warning"),
        ("y >= 0", 'y\\ "neg"', "error")]
    assert [(a.span.line, a.span.column) for a in m.assertions] == [(7, 7), (17, 3), (19, 3)]
    # the flat model prints them and reads back to the same assertions
    text = format_flat(m)
    assert 'assert(y >= 0, "y\\\\ \\"neg\\"");' in text
    again = flat_of(tmp_path, text, "flat.mo")
    assert asserts(again) == asserts(m)


@pytest.mark.parametrize(("line", "message"), [
    ('assert(x, "m");', "4:10: the condition of 'assert' must be a Boolean expression"),
    ("assert(x > 0, 3);", "4:17: the message of 'assert' must be a String, found a scalar"),
    ('assert(x > 0, "m", 2);',
     "4:22: the level of 'assert' must be AssertionLevel.error or AssertionLevel.warning"),
    ("assert(x > 0);", "4:3: 'assert' needs a message"),
])
def test_assert_misuse_is_located(tmp_path: Path, line: str, message: str) -> None:
    assert error_of(tmp_path, f"""model M
  Real x = time;
equation
  {line}
end M;
""") == message


def test_non_boolean_if_statement_condition_is_an_error(tmp_path: Path) -> None:
    assert error_of(tmp_path, """model M
  parameter Integer i = 1;
  Real x;
algorithm
  if i then
    x := 3;
  else
    x := 4;
  end if;
end M;
""") == "5:6: the condition of an if-statement must be a Boolean expression"


def test_an_error_assertion_that_always_fails_is_an_error(tmp_path: Path) -> None:
    assert error_of(tmp_path, """model M
  Real x = time;
algorithm
  assert(false, "always");
end M;
""") == "4:3: this assertion always fails: always"
    # as a warning it is kept (and reported during the simulation)
    m = flat_of(tmp_path, """model M
  Real x = time;
algorithm
  assert(1 > 2, "always", AssertionLevel.warning);
end M;
""")
    assert asserts(m) == [("false", "always", "warning")]


def test_function_assertions_in_if_expressions_hold_where_the_branch_is_not_taken(
        tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  function f
    input Real u;
    output Real y;
  algorithm
    assert(u > 0, "u must be positive");
    y := u;
  end f;
  parameter Boolean b = true;
  Real x = time;
  Real y = if not b then f(-1) else 1;
  Real z = noEvent(if x > 1 then f(x) elseif x > 0 then 2 else f(x + 3));
  Real w = if true then 1 else f(-1);
end M;
""")
    assert asserts(m) == [
        ("if not b then false else true", "u must be positive", "error"),
        ("if x > 1 then x > 0 else true", "u must be positive", "error"),
        ("if not x > 1 and not x > 0 then x + 3 > 0 else true", "u must be positive",
         "error")]


def test_functions_called_in_a_branch_of_a_function(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  function f
    input Real u;
    output Real y;
  algorithm
    assert(u > 0, "u must be positive");
    y := u;
  end f;
  function g
    input Real u;
    output Real y;
  algorithm
    if u > 1 then
      y := f(u - 1);
    else
      y := 0;
    end if;
  end g;
  Real x = time;
  Real y = noEvent(g(x));
end M;
""")
    # g's branch condition guards f's assertion: literal, as in any function body (12.8)
    assert asserts(m) == [("if noEvent(x > 1) then x - 1 > 0 else true",
                           "u must be positive", "error")]
