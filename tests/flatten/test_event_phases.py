"""If-equations on ``initial()`` and ``terminal()`` (8.3.4, 3.7.5), evaluated in order
up to the first true condition, and ``assert`` in a when-clause on them (8.3.5):
exact flat assertions and located errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import SpringcError
from springc.ir import expr as x
from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, text: str) -> FlatModel:
    path = tmp_path / "M.mo"
    path.write_text(text)
    return flatten_files([path], None)


def asserts(m: FlatModel) -> list[str]:
    return [x.to_text(a.condition) for a in m.assertions]


def test_assertions_in_if_equations_on_initial_and_terminal_are_guarded(tmp_path: Path
                                                                          ) -> None:
    m = flat_of(tmp_path, """model M
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
  if initial() then
    assert(x > 0.5, "starts high");
  elseif terminal() then
    assert(x < 0.5, "ends low");
  else
    assert(x > 0, "stays positive");
  end if;
end M;
""")
    assert asserts(m) == [
        "if initial() then x > 0.5 else true",
        "if not initial() and terminal() then x < 0.5 else true",
        "if not (initial() or terminal()) then x > 0 else true"]


def test_if_equation_conditions_stop_at_the_first_true_one(tmp_path: Path) -> None:
    # f() would fail its assertion: it is not evaluated once 'i == 4' holds (8.3.4)
    m = flat_of(tmp_path, """model M
  function f
    output Boolean b;
  algorithm
    assert(false, "evaluated");
    b := true;
  end f;
  Real x;
  parameter Integer i = 4;
equation
  if i == 4 then
    x = 3.0;
  elseif f() then
    x = 4.0;
  end if;
end M;
""")
    assert [(x.to_text(e.lhs), x.to_text(e.rhs)) for e in m.equations] == [("x", "3.0")]


def test_assert_in_a_when_clause_on_terminal(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
  when initial() then
    assert(x > 0.5, "starts high");
  elsewhen terminal() then
    assert(x < 0.5, "ends low");
  end when;
end M;
""")
    assert asserts(m) == ["if initial() then x > 0.5 else true",
                          "if terminal() and not initial() then x < 0.5 else true"]


def test_terminal_is_no_number(tmp_path: Path) -> None:
    with pytest.raises(SpringcError) as info:
        flat_of(tmp_path, "model M\n  Real t;\nequation\n  t = 2.0*terminal();\nend M;\n")
    assert str(info.value) == (
        f"{tmp_path / 'M.mo'}:4:11: error: 'terminal()' is a Boolean and cannot be an "
        "operand of '*'\n"
        "    4 |   t = 2.0*terminal();\n"
        "      |           ^^^^^^^^^^\n"
        "help: arithmetic needs Integer or Real operands (Modelica 3.6, section 3.4); "
        "choose a number with an if-expression ('if terminal() then 1.0 else 0.0')")
