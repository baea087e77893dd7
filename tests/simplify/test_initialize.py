"""Initialization (fixed starts, initial equations, start values) and the numerical
check of the index-reduced pendulum with the reference evaluator."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from springc.pipeline.files import flatten_files
from springc.simplify.initialize import (
    InitializationError,
    RedundantInitialWarning,
    conditions,
    initial_state,
)
from springc.simplify.ode_eval import OdeEvaluator
from springc.simplify.passes import simplify

ROOT = Path(__file__).resolve().parents[2]


def compile_text(tmp_path: Path, text: str):
    path = tmp_path / "m.mdl"
    path.write_text(text)
    return simplify(flatten_files([path])).ode


def test_start_on_eliminated_variable_adds_no_initial_equation(tmp_path: Path) -> None:
    model = compile_text(tmp_path, """
model S
  Real x(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
  Real w(start = 5) "an alias of v with a different, non-fixed start";
  Real a(start = 7) "algebraic, non-fixed start";
equation
  der(x) = v;
  der(v) = a;
  a = -x;
  w = v;
end S;
""")
    assert {s.name for s in model.states} == {"x", "v"}
    assert conditions(model) == ()
    x0, info = initial_state(model)
    assert dict(zip([s.name for s in model.states], x0)) == {"x": 1.0, "v": 0.0}
    assert info.observed["a"] == -1.0 and info.observed["w"] == 0.0


def test_states_default_to_start_values(tmp_path: Path) -> None:
    model = compile_text(tmp_path, """
model D
  parameter Real p = 2;
  Real x(start = p + 1);
  Real y;
equation
  der(x) = -x;
  der(y) = x;
end D;
""")
    x0, info = initial_state(model)
    assert dict(zip([s.name for s in model.states], x0)) == {"x": 3.0, "y": 0.0}
    assert set(info.defaulted) == {"x", "y"} and info.solved == ()
    x0, _ = initial_state(model, {"p": 5.0})
    assert x0[[s.name for s in model.states].index("x")] == 6.0


STEADY = """
model Steady "a hanging mass starting at rest in equilibrium"
  parameter Real k = 100;
  parameter Real m = 2;
  parameter Real g = 9.81;
  Real s(start = 0);
  Real v(start = 0, fixed = true);
  Real f;
equation
  der(s) = v;
  m*der(v) = f - m*g;
  f = -k*s;
initial equation
  der(v) = 0;
end Steady;
"""


def test_initial_equation_solves_states(tmp_path: Path) -> None:
    model = compile_text(tmp_path, STEADY)
    x0, info = initial_state(model)
    assert info.solved == ("s",) and info.fixed == ("v",)
    assert x0[0] == pytest.approx(-2 * 9.81 / 100, rel=1e-9)
    assert info.values["der(v)"] == pytest.approx(0, abs=1e-9)


def test_fixed_start_on_algebraic_variable(tmp_path: Path) -> None:
    model = compile_text(tmp_path, STEADY.replace("Real f;", "Real f(start = 3, fixed = true);")
                         .replace("der(v) = 0;", ""))
    x0, info = initial_state(model)
    assert info.solved == ("s",)
    assert x0[0] == pytest.approx(-0.03, rel=1e-9)


def test_overdetermined_names_user_equations(tmp_path: Path) -> None:
    model = compile_text(tmp_path, STEADY.replace('Real s(start = 0);',
                                                  'Real s(start = 0, fixed = true);'))
    with pytest.raises(InitializationError) as info:
        initial_state(model)
    err = info.value
    assert "over-determined" in str(err)
    notes = [n.message for n in err.notes]
    assert "condition: der(v) = 0" in notes
    assert "'s' has a fixed start value" in notes and "'v' has a fixed start value" in notes
    assert all(n.span is not None and n.span.file.endswith("m.mdl") for n in err.notes)


REDUNDANT = """
model R
  Real x(start = 1);
  Real y(start = 2);
equation
  der(x) = y;
  der(y) = -x;
initial equation
  x = 1;
  2*x = RHS;
end R;
"""


def test_redundant_consistent_initial_equation_is_dropped(tmp_path: Path) -> None:
    model = compile_text(tmp_path, REDUNDANT.replace("RHS", "2"))
    with pytest.warns(RedundantInitialWarning) as caught:
        x0, info = initial_state(model)
    assert str(caught[0].message) == ("R: 1 redundant initial condition(s) left out, "
                                      "consistent with the others: 2 * x = 2")
    assert [c.text for c in info.dropped] == ["2 * x = 2"]
    assert info.solved == ("x",) and info.defaulted == ("y",)
    assert x0.tolist() == pytest.approx([1.0, 2.0], abs=1e-12)


def test_redundant_inconsistent_initial_equation_is_an_error(tmp_path: Path) -> None:
    model = compile_text(tmp_path, REDUNDANT.replace("RHS", "3"))
    with pytest.raises(InitializationError) as info:
        initial_state(model)
    assert str(info.value).splitlines()[0].endswith(
        "error: the initialization problem is singular: 2 initial conditions determine "
        "only 1 state(s), and the redundant ones do not hold")
    assert [n.message for n in info.value.notes] == [
        "condition: 2 * x = 3 (residual -1 at the solution of the others)"]


def test_redundant_through_the_dynamics(tmp_path: Path) -> None:
    """An RC pair whose initial current and capacitor voltage say the same thing
    (i = (u - v)/R): v = 1 and i = (3 - 1)/2 = 1 are one condition; v = 1 is the
    state's value, the other state w takes the second equation w = 2*v."""
    model = compile_text(tmp_path, """
model RC
  parameter Real R = 2;
  Real v(start = 0);
  Real w(start = 0);
  Real i;
equation
  i = (3 - v)/R;
  der(v) = i;
  der(w) = v - w;
initial equation
  v = 1;
  i = 1;
  w = 2*v;
end RC;
""")
    with pytest.warns(RedundantInitialWarning):
        x0, info = initial_state(model)
    assert len(info.dropped) == 1 and info.defaulted == ()
    assert dict(zip(info.solved, x0.tolist())) == pytest.approx({"v": 1.0, "w": 2.0})
    assert info.residual <= 1e-9


def test_fixed_start_and_equal_initial_equation(tmp_path: Path) -> None:
    """More conditions than free states: ``x(fixed = true, start = 1)`` and ``x = 1``."""
    model = compile_text(tmp_path, REDUNDANT.replace("Real x(start = 1);",
                                                     "Real x(start = 1, fixed = true);")
                         .replace("  2*x = RHS;\n", "  y = 5;\n"))
    with pytest.warns(RedundantInitialWarning):
        x0, info = initial_state(model)
    assert [c.text for c in info.dropped] == ["x = 1"]
    assert x0.tolist() == pytest.approx([1.0, 5.0], abs=1e-12)


def test_pendulum_start_is_consistent_with_dummy_derivatives() -> None:
    model = simplify(flatten_files([ROOT / "models" / "Scenes.mdl"], "Scenes.Pendulum")).ode
    _, info = initial_state(model)
    v = info.values
    assert v["x"] ** 2 + v["y"] ** 2 == pytest.approx(1.0, abs=1e-12)
    assert v["x"] * v["vx"] + v["y"] * v["vy"] == pytest.approx(0.0, abs=1e-12)
    # The dummy derivatives satisfy the twice differentiated constraint.
    acc = v["vx"] ** 2 + v["vy"] ** 2 + v["x"] * v["der(vx)"] + v["y"] * v["der(vy)"]
    assert acc == pytest.approx(0.0, abs=1e-12)
    assert v["lambda"] == pytest.approx(9.81 * math.cos(math.pi / 4), rel=1e-12)


def test_pendulum_numerics() -> None:
    """Constraint drift below 1e-6 over 10 s at rtol 1e-8, and the angle within 1e-6
    of a tight independent solve of theta'' = -(g/L) sin(theta)."""
    model = simplify(flatten_files([ROOT / "models" / "Scenes.mdl"], "Scenes.Pendulum")).ode
    x0, info = initial_state(model)
    params = {p.name: info.values[p.name] for p in model.parameters}
    evaluator = OdeEvaluator(model, params)
    times = np.linspace(0, 10, 201)
    sol = solve_ivp(evaluator.rhs, (0, 10), x0, method="DOP853", rtol=1e-8, atol=1e-10,
                    t_eval=times)
    assert sol.status == 0
    envs = [evaluator.values(t, sol.y[:, k]) for k, t in enumerate(sol.t)]
    drift = max(abs(e["x"] ** 2 + e["y"] ** 2 - 1.0) for e in envs)
    assert drift < 1e-6
    theta = np.array([math.atan2(e["x"], -e["y"]) for e in envs])
    g, length = 9.81, 1.0
    ref = solve_ivp(lambda t, s: [s[1], -(g / length) * math.sin(s[0])], (0, 10),
                    [math.pi / 4, 0.0], method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=times)
    assert np.max(np.abs(theta - ref.y[0])) < 1e-6


def test_singular_at_the_start_values_only(tmp_path: Path) -> None:
    """``x*y = 2`` and ``x + y = 3`` from ``x = y = 0``: the Jacobian ``[[y, x], [1, 1]]``
    is singular there but not at the roots, so nothing is redundant (LightningImpulse's
    time constants); and a time constant of 1e-5 beside a factor of 1 counts alike."""
    model = compile_text(tmp_path, """
model S
  Real x(start = 0);
  Real y(start = 0);
  Real t(start = 1e-5);
equation
  der(x) = 0;
  der(y) = 0;
  der(t) = 0;
initial equation
  x*y = 2;
  x + y = 3;
  exp(-1e-5/t) = x*exp(-1);
end S;
""")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RedundantInitialWarning)
        x0, info = initial_state(model)
    assert info.dropped == () and info.residual <= 1e-9
    x, y, t = x0.tolist()
    assert sorted([x, y]) == pytest.approx([1.0, 2.0], rel=1e-9)
    assert t == pytest.approx(1e-5 / (1 - math.log(x)), rel=1e-9)
