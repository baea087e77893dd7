"""Static state selection where the rules allow it (issue 28, point 6): a choice of
states that cannot turn singular is kept for the whole run, on the compiled engine.

Rule 1: constraints with a constant Jacobian (``s_rel = flange_b.s - flange_a.s``);
rule 2: the ``StateSelect.prefer`` candidates are exactly the states a block keeps;
rule 3: the Jacobian on the dummies is block triangular with constant, regular diagonal
blocks (a MultiBody joint: ``der(x) = L*cos(phi)*der(phi)``).
Each trajectory is checked against an independent solution: a closed form (matrix
exponential) or scipy's DOP853 on a hand-written ODE at rtol 1e-12.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

import springc
from springc.ir import expr as x
from springc.simplify.static_choice import static_block
from springc.structure import kept_by_preference
from springc.structure.dummy import DEFAULT, PREFER

MODELS = Path(__file__).resolve().parents[2] / "models"

# The bundled library's SpringDamper (s_rel and v_rel with StateSelect.prefer) between
# two masses, the first on a spring to a wall.
TWO_MASS = """model TwoMass
  import T = Modelica.Mechanics.Translational.Components;
  T.Fixed fixed(s0 = 0);
  T.Spring spring(c = 100, s_rel0 = 1);
  T.Mass mass1(m = 1, s(start = 1.2, fixed = true), v(start = 0, fixed = true));
  T.SpringDamper springDamper(c = 50, d = 1, s_rel0 = 1, s_rel(start = 0.9, fixed = true));
  T.Mass mass2(m = 0.5, v(start = 0.3, fixed = true));
equation
  connect(fixed.flange, spring.flange_a);
  connect(spring.flange_b, mass1.flange_a);
  connect(mass1.flange_b, springDamper.flange_a);
  connect(springDamper.flange_b, mass2.flange_a);
end TwoMass;
"""

# A rod pendulum in Cartesian coordinates (index 3) with x preferred: y never reaches 0
# on this swing (|x| <= 0.6), so x stays a valid state.
PREFERRED_PENDULUM = """model PreferredPendulum
  parameter Real L = 1, g = 9.81;
  Real x(start = 0.6, stateSelect = StateSelect.prefer), y(start = -0.8);
  Real vx(start = 0, stateSelect = StateSelect.prefer), vy, F;
equation
  der(x) = vx;
  der(y) = vy;
  der(vx) = -F*x;
  der(vy) = -F*y - g;
  x^2 + y^2 = L^2;
end PreferredPendulum;
"""

# A pendulum in its angle (preferred, fixed start), with its Cartesian position and a
# second preferred angle phi2 = phi - p0 (as a damper's phi_rel on a revolute joint)
# that x reads: der(phi2) is a dummy, so rule 2 fails; the dummies' Jacobian is
# triangular with ones on its diagonal whatever phi (rule 3). Without rule 3 the
# position block was switchable.
ANGLE_PENDULUM = """model AnglePendulum
  parameter Real L = 0.8, g = 9.81, m = 2, p0 = 0.1;
  Real phi(start = 1.2, fixed = true, stateSelect = StateSelect.prefer);
  Real w(start = 0, fixed = true, stateSelect = StateSelect.prefer);
  Real phi2(stateSelect = StateSelect.prefer), w2(stateSelect = StateSelect.prefer);
  Real x, y, vx, vy, F, a;
equation
  x = L*sin(phi2 + p0);
  y = -L*cos(phi);
  vx = der(x);
  vy = der(y);
  m*der(vx) = -F*x/L;
  m*der(vy) = -F*y/L - m*g;
  w = der(phi);
  a = der(w);
  phi2 = phi - p0;
  w2 = der(phi2);
end AnglePendulum;
"""

TIGHT = {"rtol": 1e-10, "atol": 1e-12, "engine": "compiled"}


def test_two_masses_on_the_bundled_spring_damper_keep_its_relative_position(
        tmp_path: Path) -> None:
    path = tmp_path / "two_mass.mo"
    path.write_text(TWO_MASS)
    model = springc.compile_model(str(path), libraries=[str(MODELS)], backend="numba")
    assert not model.module.SWITCHABLE
    # both preferred relative states (v_rel = der(s_rel) ranks above mass2's fixed v)
    assert model.states == ("mass1.s", "mass1.v", "springDamper.s_rel", "springDamper.v_rel")
    result = springc.simulate(model, stop=5.0, interval=0.05, **TIGHT)
    assert result.stats.engine == "compiled"

    def rhs(t: float, y: np.ndarray) -> list[float]:
        s1, v1, s_rel, v_rel = y
        f = 50 * (s_rel - 1) + 1 * v_rel  # the spring-damper's force
        a1 = -100 * (s1 - 1) + f
        return [v1, a1, v_rel, -f / 0.5 - a1]

    ref = solve_ivp(rhs, (0.0, 5.0), [1.2, 0.0, 0.9, 0.3], method="DOP853", rtol=1e-12,
                    atol=1e-14, t_eval=result.time)
    for k, name in enumerate(model.states):
        assert np.max(np.abs(result[name] - ref.y[k])) < 1e-8, name  # measured 2.3e-10


def test_the_oscillator_scene_runs_compiled_and_matches_its_closed_form() -> None:
    result = springc.simulate([MODELS / "Scenes.mdl"], model_name="Scenes.Oscillator",
                              stop=3.0, interval=0.05, **TIGHT)
    assert result.stats.engine == "compiled"
    # mass1 (m 1): spring 100 and damper 2 to the wall; springDamper (c 50, d 1, rest
    # length 1) to mass2 (m 0.5), pulled by 5 N. x = (s1, v1, s2, v2), x' = A x + b.
    a = np.array([[0, 1, 0, 0], [-150, -3, 50, 1], [0, 0, 0, 1], [100, 2, -100, -2]], float)
    b = np.array([0.0, 100 - 50, 0.0, 100 + 10])
    rest = -np.linalg.solve(a, b)
    start = np.array([1.2, 0.0, 2.2, 0.0])
    exact = np.array([rest + expm(a * t) @ (start - rest) for t in result.time])
    for k, name in enumerate(("mass1.s", "mass1.v", "mass2.s", "mass2.v")):
        assert np.max(np.abs(result[name] - exact[:, k])) < 1e-8, name  # measured 2.7e-10


def test_preferred_states_of_a_nonlinear_constraint_are_kept(tmp_path: Path) -> None:
    path = tmp_path / "pendulum.mo"
    path.write_text(PREFERRED_PENDULUM)
    model = springc.compile_model(str(path), backend="numba")
    assert not model.module.SWITCHABLE and model.states == ("x", "vx")
    result = springc.simulate(model, stop=2.0, interval=0.05, **TIGHT)
    assert result.stats.engine == "compiled"
    angle = solve_ivp(lambda t, y: [y[1], -9.81 * np.sin(y[0])], (0.0, 2.0),
                      [np.arcsin(0.6), 0.0], method="DOP853", rtol=1e-12, atol=1e-14,
                      t_eval=result.time).y[0]
    assert np.max(np.abs(result["x"] - np.sin(angle))) < 1e-8  # measured 2.9e-11
    assert np.max(np.abs(result["y"] + np.cos(angle))) < 1e-8


def test_without_preference_the_pendulum_still_switches(tmp_path: Path) -> None:
    path = tmp_path / "pendulum.mo"
    path.write_text(PREFERRED_PENDULUM.replace(", stateSelect = StateSelect.prefer", ""))
    result = springc.simulate(str(path), stop=0.2, interval=0.1, rtol=1e-8)
    assert result.stats.engine == "scipy"
    assert result.stats.reason == "dynamic state selection, no switch in this run"
    assert result.stats.engine_reason == ("dop853 ran in scipy's loop, the only one that "
                                          "switches states")
    # Real counts: every accepted step takes 12 evaluations of DOP853's stages or more.
    assert result.stats.steps > 0
    assert result.stats.rhs_evaluations >= 12 * result.stats.steps


@pytest.mark.parametrize(("priorities", "dummies", "static"), [
    ((DEFAULT, PREFER), (True, False), True),     # the preferred one is kept
    ((DEFAULT, PREFER), (False, True), False),    # a dummy was preferred
    ((DEFAULT, DEFAULT), (True, False), False),   # nothing preferred
    ((PREFER, PREFER, DEFAULT), (False, True, False), False),  # one preferred too many
])
def test_kept_by_preference(priorities: tuple[float, ...], dummies: tuple[bool, ...],
                            static: bool) -> None:
    assert kept_by_preference(priorities, dummies) is static


def test_a_constant_block_is_static_and_a_nonlinear_one_is_not() -> None:
    # der(s_rel) - (der(s2) - k*der(s1)) = 0: constant; der(x)*x + der(y)*y = 0: not.
    linear = x.sub(x.Var("der(r)"), x.sub(x.Var("der(b)"), x.mul(x.Var("k"), x.Var("der(a)"))))
    names = ("der(r)", "der(b)", "der(a)")
    assert static_block([linear], names, ("der(r)",), [DEFAULT] * 3, {"k": 2.0})
    assert not static_block([linear], names, ("der(r)",), [DEFAULT] * 3, None)
    circle = x.add(x.mul(x.Var("der(x)"), x.Var("x")), x.mul(x.Var("der(y)"), x.Var("y")))
    assert not static_block([circle], ("der(y)", "der(x)"), ("der(y)",), [DEFAULT] * 2,
                            {})


def test_a_triangular_block_of_a_preferred_angle_is_static(tmp_path: Path) -> None:
    path = tmp_path / "angle.mo"
    path.write_text(ANGLE_PENDULUM)
    model = springc.compile_model(str(path), backend="python")
    assert not model.module.SWITCHABLE and model.states == ("phi", "w")
    result = springc.simulate(model, stop=2.0, interval=0.05, rtol=1e-10, atol=1e-12,
                              engine="scipy")
    exact = solve_ivp(lambda t, y: [y[1], -9.81 / 0.8 * np.sin(y[0])], (0.0, 2.0),
                      [1.2, 0.0], method="DOP853", rtol=1e-12, atol=1e-14,
                      t_eval=result.time).y
    assert np.max(np.abs(result["phi"] - exact[0])) < 1e-7
    assert np.max(np.abs(result["w2"] - exact[1])) < 1e-7
    # the rod's tension: m*(g*cos(phi) + L*w^2)
    tension = 2 * (9.81 * np.cos(exact[0]) + 0.8 * exact[1] ** 2)
    assert np.max(np.abs(result["F"] - tension)) < 1e-6


def test_rule_3_needs_constant_diagonal_blocks() -> None:
    # der(t) - cos(p)*der(p) = 0 and der(q) - der(p) = 0, dummies der(t), der(q): the
    # diagonal is (1, 1) whatever p; with der(t)*p instead, it depends on p.
    p, dp = x.Var("p"), x.Var("der(p)")
    first = x.sub(x.Var("der(t)"), x.mul(x.Call("cos", (p,)), dp))
    second = x.sub(x.Var("der(q)"), dp)
    names, dummies = ("der(t)", "der(q)", "der(p)"), ("der(t)", "der(q)")
    assert static_block([first, second], names, dummies, [DEFAULT] * 3, {})
    scaled = x.sub(x.mul(x.Var("der(t)"), p), x.mul(x.Call("cos", (p,)), dp))
    assert not static_block([scaled, second], names, dummies, [DEFAULT] * 3, {})
    # a zero on the diagonal: der(t) - der(t) + ... folds to no dependence
    singular = x.sub(x.mul(x.Const(0.0), x.Var("der(t)")), dp)
    assert not static_block([singular, second], names, dummies, [DEFAULT] * 3, {})
