"""Parameters with ``fixed = false`` (section 8.6), computed during the initialization
(simplify/free_parameters.py): bound by an initial equation on parameters, or kept
constant as a state the initial equations determine."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc
from springc.ir import expr as x
from springc.ir import flat
from springc.pipeline.files import flatten_files
from springc.simplify.free_parameters import free_parameters

MODEL = '''\
model FP
  function f
    input Real k;
    output Real a;
    output Real b;
  algorithm
    a := 2 * k;
    b := k + 1;
  end f;
  parameter Real k = 3;
  parameter Real a(fixed = false);
  parameter Real b(fixed = false);
  parameter Real d(fixed = false);
  parameter Real c(fixed = false, start = 0);
  Real x(start = 1, fixed = true);
  Real y(start = 2, fixed = true);
initial equation
  (a, b) = f(k);
  d + 1 = b;
  c = (x + y) / 2;
equation
  der(x) = -a * (x - c);
  der(y) = -d * (y - c);
end FP;
'''


def test_bound_by_parameters_or_kept_as_a_constant_state(tmp_path: Path) -> None:
    path = tmp_path / "FP.mo"
    path.write_text(MODEL)
    model = free_parameters(flatten_files([path], "FP"))
    kinds = {v.name: (v.variability, v.binding) for v in model.variables}
    assert kinds["a"] == ("parameter", x.BinOp("*", x.Const(2), x.Var("k")))
    assert kinds["b"] == ("parameter", x.BinOp("+", x.Var("k"), x.Const(1)))
    # d + 1 = b is not of the form d = e: d stays an unknown of the initialization
    assert kinds["c"] == ("continuous", None) and kinds["d"] == ("continuous", None)
    assert [eq for eq in model.equations if eq.lhs in (x.Der(x.Var("c")),
                                                       x.Der(x.Var("d")))] != []
    assert len(model.initial_equations) == 2


def test_simulated_against_the_closed_form(tmp_path: Path) -> None:
    path = tmp_path / "FP.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              interval=0.25, rtol=1e-10, error_control="off")
    # a = 6, d = b - 1 = 3, c = (1 + 2) / 2: x = c - 0.5 exp(-6 t), y = c + 0.5 exp(-3 t)
    t = np.asarray(result.time)
    assert np.allclose(result["c"], 1.5, rtol=0, atol=1e-9)
    assert np.allclose(result["x"], 1.5 - 0.5 * np.exp(-6 * t), rtol=0, atol=1e-7)
    assert np.allclose(result["y"], 1.5 + 0.5 * np.exp(-3 * t), rtol=0, atol=1e-7)
    assert math.isclose(float(result["d"][-1]), 3.0, abs_tol=1e-9)


CHAIN = '''\
model SC "a mass on a spring at rest at x = 0.5: k from the steady state"
  parameter Real m = 2;
  parameter Real g = 9.81;
  parameter Real k(fixed = false, start = 10);
  parameter Real k2 = 2 * k;
  parameter Real k3 = k2 + 1;
  Real x(start = 0.5, fixed = true);
  Real v(start = 0, fixed = true);
initial equation
  der(v) = 0;
equation
  der(x) = v;
  m * der(v) = -k2 / 2 * x + m * g - 0.1 * v + (k3 - k2 - 1) * x;
end SC;
'''


def test_parameters_bound_to_a_free_parameter_follow_it(tmp_path: Path) -> None:
    # rule 3: k2 reads the free k, k3 reads k2 (MultiBody's InitSpringConstant: the
    # spring's c passed on to its line force)
    path = tmp_path / "SC.mo"
    path.write_text(CHAIN)
    model = free_parameters(flatten_files([path], "SC"))
    kinds = {v.name: (v.variability, v.binding) for v in model.variables}
    assert kinds["k2"] == ("continuous", None) and kinds["k3"] == ("continuous", None)
    assert flat_equation(model, "k3") == x.BinOp("+", x.Var("k2"), x.Const(1))
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              interval=0.5, rtol=1e-10, error_control="off")
    # at rest at x = 0.5: k x = m g, k = 2 * 9.81 / 0.5
    assert np.allclose(result["k"], 39.24, rtol=0, atol=1e-9)
    assert np.allclose(result["k3"], 2 * 39.24 + 1, rtol=0, atol=1e-9)
    assert np.allclose(result["x"], 0.5, rtol=0, atol=1e-9)


def flat_equation(model: flat.FlatModel, name: str) -> x.Expr:
    """The right-hand side of ``name = e`` among ``model``'s equations."""
    found = [eq.rhs for eq in model.equations if eq.lhs == x.Var(name)]
    assert len(found) == 1
    return found[0]
