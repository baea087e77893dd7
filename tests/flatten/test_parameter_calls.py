"""A call whose arguments are parameters with known values, and whose execution decides
a ``while`` loop by their values, is evaluated numerically
(springc.flatten.calls.parameter_calls): its result is a constant and the parameters
are structural, so a new value compiles the model again and gives the new result."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.ir import expr as x
from springc.pipeline import flatten_files

ROOT = """
model Root
  function bisect "sqrt(a) by bisection: a while loop decided by a's value"
    input Real a;
    output Real r;
  protected
    Real lo = 0;
    Real hi = max(1, a);
  algorithm
    assert(a >= 0, "a must not be negative");
    while hi - lo > 1e-12 loop
      r := (lo + hi) / 2;
      if r * r > a then
        hi := r;
      else
        lo := r;
      end if;
    end while;
    r := (lo + hi) / 2;
  end bisect;
  function twice "no loop: stays symbolic"
    input Real u;
    output Real y;
  algorithm
    y := 2 * u;
  end twice;
  parameter Real b = 4;
  parameter Real a = b;
  parameter Real r = bisect(a);
  parameter Real k = twice(c);
  parameter Real c = 1;
  Real x(start = 1, fixed = true);
equation
  der(x) = -r * k * x;
end Root;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def _write(tmp_path: Path) -> str:
    path = tmp_path / "Root.mo"
    path.write_text(ROOT)
    return str(path)


def test_the_loop_call_is_a_constant_and_its_assertion_folds(tmp_path: Path) -> None:
    flat = flatten_files((_write(tmp_path),), "Root", ())
    binding = flat.variable("r").binding
    assert type(binding).__name__ == "Const"
    assert binding.value == pytest.approx(2.0, abs=1e-12)  # type: ignore[union-attr]
    assert flat.evaluated == ("a",)
    assert flat.assertions == ()  # its assertion holds for a = 4: no run-time check left
    # without a loop the call stays a parameter expression of c
    assert flat.variable("k").binding == x.BinOp("*", x.Const(2), x.Var("c"))


def test_a_new_value_of_an_evaluated_parameter_compiles_again(tmp_path: Path) -> None:
    model = springc.compile_model(_write(tmp_path))
    assert {"a", "b"} <= set(model.structural)
    assert "c" not in model.structural
    first = springc.simulate(model, stop=1.0, error_control="off", rtol=1e-10)
    assert first["x"][-1] == pytest.approx(np.exp(-4.0), rel=1e-7)
    # a = 9 (through b): sqrt is 3, k = 2 * c = 1
    again = springc.simulate(model, stop=1.0, error_control="off", rtol=1e-10,
                             parameters={"b": 9.0, "c": 0.5})
    assert again["x"][-1] == pytest.approx(np.exp(-3.0), rel=1e-7)
