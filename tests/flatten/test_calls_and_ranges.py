"""Multiple-output calls (`(a, b) = f(x)`, `(a, b) := f(x)`), `a.f()` through a
component (5.3.2) and deduced for ranges (11.2.2.1): exact flat equations and located
errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import ErrorGroup, SpringcError, errors_of
from springc.ir import expr as x
from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files

F = """  function f
    input Real u;
    output Real a;
    output Real b;
  algorithm
    a := u + 1;
    b := 2 * u;
  end f;
"""


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, body: str) -> FlatModel:
    path = tmp_path / "m.mo"
    path.write_text(f"model M\n{F}{body}end M;\n")
    return flatten_files([path], None)


def equations(m: FlatModel) -> list[str]:
    return [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in m.equations]


def error_of(tmp_path: Path, body: str) -> str:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        flat_of(tmp_path, body)
    (err,) = errors_of(info.value)
    assert err.span is not None
    return f"{err.span.line}:{err.span.column}: {err.message}"


def test_multiple_outputs_as_equations_and_statements(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """  function g
    input Real u;
    output Real s;
  protected
    Real p, q;
  algorithm
    (p, q) := f(u);
    s := p * q;
  end g;
  Real x, y, z, w, v;
equation
  (x, y) = f(time);
  (, z) = f(3);
  v = g(time);
algorithm
  (w, ) := f(x);
end M;
""".removesuffix("end M;\n"))
    assert equations(m) == ["x = time + 1", "y = 2 * time", "z = 6",
                            "v = (time + 1) * (2 * time)", "w = x + 1"]


@pytest.mark.parametrize(("body", "message"), [
    ("  Real x, y, z;\nequation\n  (x, y, z) = f(1);\n", "12:15: 'M.f' has 2 output(s), 3 "
     "are used"),
    ("  Real x, y;\nequation\n  (x, y) = 3;\n", "12:12: several outputs need a function "
     "call on the right-hand side"),
    ("  Real x[2], y[2];\nequation\n  (x, y) = f({1, 2});\n",
     "12:12: 'M.f' has several outputs and cannot be called element-wise: its input 'u' "
     "is a scalar, given an array of size [2] (section 12.4.6)"),
    ("  Real x = (1, 2);\n", "10:12: an output list (`(a, b)`) is only allowed on the "
     "left of `(a, b) = f(x)` or `(a, b) := f(x)`"),
])
def test_multiple_output_misuse(tmp_path: Path, body: str, message: str) -> None:
    assert error_of(tmp_path, body) == message


def test_function_through_a_component(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """  model A
    function h
      input Real u;
      output Real y = 3 * u;
    algorithm
    end h;
  end A;
  A c;
  Real y = c.h(time);
""")
    assert equations(m) == ["y = 3 * time"]
    assert error_of(tmp_path, "  model A\n  end A;\n  A c;\n  Real y = c.h(time);\n") == \
        "13:12: 'M.A' (the class of 'c') has no function 'h'"


def test_deduced_ranges_in_equations_algorithms_and_reductions(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """  Real x[3], y[2];
  Real m[2, 3];
  Real s = sum(x[i] for i);
equation
  for i loop
    x[i] = i * time;
  end for;
  for i, j loop
    m[i, j] = i + j;
  end for;
algorithm
  for k loop
    y[k] := m[k, 1];
  end for;
""")
    assert equations(m) == [
        "s = x[1] + x[2] + x[3]", "x[1] = time", "x[2] = 2 * time", "x[3] = 3 * time",
        "m[1,1] = 2", "m[1,2] = 3", "m[1,3] = 4", "m[2,1] = 3", "m[2,2] = 4", "m[2,3] = 5",
        "y[1] = m[1,1]", "y[2] = m[2,1]"]


@pytest.mark.parametrize(("body", "message"), [
    ("  Real x[3], y[4];\nequation\n  for i loop\n    x[i] = y[i];\n  end for;\n",
     "12:7: the range of 'i' cannot be deduced: it subscripts dimensions of sizes 3 and 4"),
    ("  Real x[3];\nequation\n  for i loop\n    x = fill(i, 3);\n  end for;\n",
     "12:7: cannot deduce the range of 'i': it is not used as a subscript of an array in "
     "the loop"),
])
def test_deduced_range_errors(tmp_path: Path, body: str, message: str) -> None:
    assert error_of(tmp_path, body) == message


def test_function_defaults_from_extends_and_causality_from_types(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """  type In = input Real;
  type Out = output Real;
  function base
    input Real x;
  end base;
  function derived
    extends base(x = 10);
    Out y;
    In k = 2;
  algorithm
    y := k * x;
  end derived;
  Real a = derived();
  Real b = derived(1, 3);
""")
    assert equations(m) == ["a = 20", "b = 3"]
