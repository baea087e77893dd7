"""while, break and return (11.2.3-11.2.5) decided while flattening: exact results of
loops on values known before the simulation, located errors otherwise."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import ErrorGroup, SpringcError, errors_of
from springc.ir import expr as x
from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, text: str) -> FlatModel:
    path = tmp_path / "m.mo"
    path.write_text(text)
    return flatten_files([path], None)


def equations(m: FlatModel) -> list[str]:
    return [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in m.equations]


def error_of(tmp_path: Path, text: str) -> str:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        flat_of(tmp_path, text)
    (err,) = errors_of(info.value)
    assert err.span is not None
    return f"{err.span.line}:{err.span.column}: {err.message}"


def test_loops_with_break_and_return(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  function halve "halvings of u down to 1 or less (Collatz-free: a while loop)"
    input Real u;
    output Integer n;
  protected
    Real v;
  algorithm
    n := 0;
    v := u;
    while v > 1 loop
      v := v / 2;
      n := n + 1;
    end while;
  end halve;
  function early
    input Real u;
    output Real r;
  algorithm
    r := 2 * u;
    if r > 20 then
      return;
    end if;
    r := r * u;
  end early;
  Real a = halve(100);
  Real b = early(11);
  Real c = early(5);
  Real d;
algorithm
  d := 1;
  for i in 1:10 loop
    d := d * 2;
    if noEvent(d > 25) then
      break;
    end if;
  end for;
end M;
""")
    # 100 / 2^7 = 0.78 <= 1; early(11) returns 22 at once; 2 * 5 * 5 = 50; 2^5 = 32
    assert equations(m) == ["a = 7", "b = 22", "c = 50", "d = 32"]


@pytest.mark.parametrize(("text", "message"), [
    ("model M\n  Real y;\nalgorithm\n  y := time;\n  while noEvent(y > 1) loop\n"
     "    y := y / 2;\n  end while;\nend M;\n",
     "5:9: `while` loops whose condition is known only during the simulation are not "
     "supported yet"),
    ("model M\n  Real y;\nalgorithm\n  y := 0;\n  while true loop\n"
     "    if noEvent(time > 1) then\n      break;\n    end if;\n    y := y + 1;\n"
     "  end while;\nend M;\n",
     "7:7: `break` under a condition known only during the simulation is not supported "
     "yet"),
    ("model M\n  Real y;\nalgorithm\n  y := 0;\n  for i in 1:40 loop\n"
     "    if noEvent(time > i) then\n      break;\n    end if;\n    y := y * y + 1;\n"
     "  end for;\nend M;\n",
     "5:7: the values of a for loop left by a break under a condition known only during "
     "the simulation grow beyond 20000 terms"),
    ("model M\n  Real y;\nalgorithm\n  y := 1;\n  return;\nend M;\n",
     "5:3: `return` is only allowed in a function"),
    ("model M\n  Real y;\nalgorithm\n  y := 1;\n  break;\nend M;\n",
     "5:3: `break` is only allowed inside a loop"),
    ("model M\n  parameter Integer i = 4;\n  Real y;\nalgorithm\n  if i == 4 then\n"
     "    return;\n  end if;\n  y := 1;\nend M;\n",
     "6:5: `return` is only allowed in a function"),
    ("model M\n  parameter Integer i = 1;\n  Real y;\nalgorithm\n  y := 0;\n"
     "  while i loop\n    y := 1;\n    break;\n  end while;\nend M;\n",
     "6:9: the condition of a while loop must be a Boolean expression"),
])
def test_control_flow_errors(tmp_path: Path, text: str, message: str) -> None:
    assert error_of(tmp_path, text) == message


def test_break_under_a_run_time_condition_leaves_a_for_loop(tmp_path: Path) -> None:
    # after the break at i the statements and iterations that follow keep the values
    m = flat_of(tmp_path, "model M\n  Real y;\nalgorithm\n  y := 0;\n  for i in 1:3 loop\n"
                "    if noEvent(time > i) then\n      break;\n    end if;\n"
                "    y := y + 1;\n  end for;\nend M;\n")
    assert equations(m) == [
        "y = (if noEvent(time > 1) then 0 else 1) + (if noEvent(time > 1) or "
        "noEvent(time > 2) then 0 else 1) + (if noEvent(time > 1) or noEvent(time > 2) or "
        "noEvent(time > 3) then 0 else 1)"]


def test_a_while_loop_on_start_values_is_decided_while_flattening(tmp_path: Path) -> None:
    # n is read before the section assigns it: its start value 3 (11.1.2)
    m = flat_of(tmp_path, "model M\n  Integer n(start = 3);\n  Real s;\nalgorithm\n"
                "  s := 0;\n  while n < 6 loop\n    n := n + 1;\n    s := s + n;\n"
                "  end while;\nend M;\n")
    assert sorted(equations(m)) == ["n = 6", "s = 15"]


RUN_TIME_JUMPS = """model M
  function firstTrue
    input Boolean b[:];
    output Integer index;
  algorithm
    index := 0;
    for i in 1:size(b, 1) loop
      if b[i] then
        index := i;
        return;
      end if;
    end for;
  end firstTrue;
  function sumUntil
    input Real u[:];
    input Real limit;
    output Real s;
  algorithm
    s := 0;
    for i in 1:size(u, 1) loop
      if s + u[i] > limit then
        break;
      end if;
      s := s + u[i];
    end for;
    s := 2 * s;
  end sumUntil;
  Integer k = firstTrue({time > 0.5, time > 0.25, true});
  Real y = sumUntil({1, time, 2}, 2.5);
end M;
"""


def _first_true(b: list[bool]) -> int:
    return next((i + 1 for i, v in enumerate(b) if v), 0)


def _sum_until(u: list[float], limit: float) -> float:
    s = 0.0
    for v in u:
        if s + v > limit:
            break
        s += v
    return 2 * s


@pytest.mark.parametrize("t", [0.0, 0.3, 0.6, 1.2, 1.6, 3.0])
def test_return_and_break_under_run_time_conditions_in_functions(tmp_path: Path,
                                                                 t: float) -> None:
    # the jumps become flags (flatten/calls/jumps.py): the flat equations, evaluated at
    # time t, give what running the functions gives
    m = flat_of(tmp_path, RUN_TIME_JUMPS)
    rhs = {x.to_text(e.lhs): e.rhs for e in m.equations}
    assert x.evaluate(rhs["k"], {}, time=t) == _first_true([t > 0.5, t > 0.25, True])
    assert x.evaluate(rhs["y"], {}, time=t) == pytest.approx(_sum_until([1, t, 2], 2.5),
                                                             abs=1e-12)


def test_a_variable_assigned_in_one_branch_of_an_if_on_a_parameter(tmp_path: Path) -> None:
    # the parameter decides the branch, so alpha has a value (the MSL's
    # Blocks.Continuous.Internal.Filter.Utilities.BesselBaseCoefficients)
    m = flat_of(tmp_path, """model M
  function coefficient
    input Integer order;
    output Real alpha;
  algorithm
    if order == 1 then
      alpha := 1.5;
    elseif order == 2 then
      alpha := 2.5;
    else
      assert(false, "order out of range");
    end if;
  end coefficient;
  parameter Integer n = 2;
  parameter Real a = coefficient(n);
  Real y = a * time;
end M;
""")
    assert equations(m) == ["y = a * time"]
    (a,) = [v for v in m.variables if v.name == "a"]
    assert a.binding is not None and x.evaluate(a.binding, {"n": 2}) == 2.5
