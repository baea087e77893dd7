"""The bundled Modelica.Mechanics.Translational (event-free classes): each component
against a closed form, and the Standard Library's own examples (Damper, SignConvention,
Accelerate, InitialConditions) written with ``Modelica.*`` names only,
simulated with the bundled library and matched against solutions derived by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

import springc


@pytest.fixture(autouse=True)
def _no_environment_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)
    monkeypatch.delenv("MODELICAPATH", raising=False)


def simulate(text: str, stop: float, model: str | None = None) -> springc.SimulationResult:
    compiled = springc.load_model_from_string(text, model, cache=False)
    return springc.simulate(compiled, stop=stop, interval=stop / 200, rtol=1e-10,
                            atol=1e-12)


def second_order(t: np.ndarray, damping: float, stiffness: float, y0: float,
                 v0: float) -> np.ndarray:
    """y'' + damping*y' + stiffness*y = 0 with y(0) = y0, y'(0) = v0 (real or complex roots)."""
    disc = complex(damping * damping - 4 * stiffness) ** 0.5
    r1, r2 = (-damping + disc) / 2, (-damping - disc) / 2
    c1 = (v0 - r2 * y0) / (r1 - r2)
    c2 = y0 - c1
    return np.real(c1 * np.exp(r1 * t) + c2 * np.exp(r2 * t))


T = "Modelica.Mechanics.Translational"

DAMPER = f"""
model Damper "Modelica.Mechanics.Translational.Examples.Damper, with full names"
  extends Modelica.Icons.Example;
  {T}.Components.Mass mass1(L = 1, s(start = 3, fixed = true), v(start = 10, fixed = true), m = 1);
  {T}.Components.Damper damper1(d = 25);
  {T}.Components.Fixed fixed1(s0 = 4.5);
  {T}.Components.Mass mass2(L = 1, s(start = 3, fixed = true), v(start = 10, fixed = true), m = 1);
  {T}.Components.Damper damper2(d = 25);
  {T}.Components.Fixed fixed2(s0 = 4.5);
  {T}.Components.Mass mass3(L = 1, s(start = 3, fixed = true), v(start = 10, fixed = true), m = 1);
  {T}.Components.Fixed fixed3(s0 = 4.5);
  {T}.Components.Spring spring2(s_rel0 = 1, c = 1);
  {T}.Components.SpringDamper springDamper3(s_rel0 = 1, d = 25, c = 1);
equation
  connect(mass1.flange_b, damper1.flange_a);
  connect(mass2.flange_b, damper2.flange_a);
  connect(damper2.flange_b, spring2.flange_b);
  connect(damper2.flange_a, spring2.flange_a);
  connect(mass3.flange_b, springDamper3.flange_a);
  connect(damper1.flange_b, fixed1.flange);
  connect(damper2.flange_b, fixed2.flange);
  connect(springDamper3.flange_b, fixed3.flange);
end Damper;
"""


def test_damper_example() -> None:
    result = simulate(DAMPER, 1.0)
    t = result.time
    # mass1: m*a = -d*v: v = 10*exp(-25 t), s = 3 + 0.4*(1 - exp(-25 t)).
    assert np.max(np.abs(result["mass1.s"] - (3 + 0.4 * (1 - np.exp(-25 * t))))) < 1e-8
    # mass2 and mass3: the spring is unstretched at s = 3 (flange_b at 3.5, fixed at 4.5,
    # s_rel0 = 1): y = s - 3 solves y'' + 25 y' + y = 0, y(0) = 0, y'(0) = 10.
    y = second_order(t, 25, 1, 0, 10)
    assert np.max(np.abs(result["mass2.s"] - (3 + y))) < 1e-8
    assert np.max(np.abs(result["mass3.s"] - (3 + y))) < 1e-8
    # The damper's lost power is d*v_rel^2.
    assert np.max(np.abs(result["damper1.lossPower"] - 25 * result["mass1.v"] ** 2)) < 1e-6


SIGN_CONVENTION = f"""
model SignConvention "Modelica.Mechanics.Translational.Examples.SignConvention, with full names"
  extends Modelica.Icons.Example;
  {T}.Components.Mass mass1(L = 1, s(fixed = true), v(fixed = true), m = 1);
  {T}.Sources.Force force1;
  Modelica.Blocks.Sources.Constant constant1(k = 1);
  {T}.Components.Mass mass2(L = 1, s(fixed = true), v(fixed = true), m = 1);
  {T}.Sources.Force force2;
  Modelica.Blocks.Sources.Constant constant2(k = 1);
  {T}.Components.Mass mass3(L = 1, s(fixed = true), v(fixed = true), m = 1);
  {T}.Sources.Force force3(useSupport = false);
  Modelica.Blocks.Sources.Constant constant3(k = 1);
  {T}.Components.Fixed fixed;
equation
  connect(constant1.y, force1.f);
  connect(constant2.y, force2.f);
  connect(constant3.y, force3.f);
  connect(force1.flange, mass1.flange_a);
  connect(force2.flange, mass2.flange_b);
  connect(mass3.flange_b, force3.flange);
  connect(fixed.flange, force3.support);
end SignConvention;
"""


def test_sign_convention_example() -> None:
    result = simulate(SIGN_CONVENTION, 1.0)
    # A positive force signal pushes each mass along the axis, whichever flange it
    # acts at: s = t^2/2 for all three (force3's disabled support drops its connection).
    for mass in ("mass1", "mass2", "mass3"):
        assert np.max(np.abs(result[f"{mass}.s"] - result.time ** 2 / 2)) < 1e-9


ACCELERATE = f"""
model Accelerate "Modelica.Mechanics.Translational.Examples.Accelerate, with full names"
  extends Modelica.Icons.Example;
  {T}.Sources.Accelerate accelerate;
  {T}.Components.Mass mass(L = 1, m = 1);
  Modelica.Blocks.Sources.Constant constantAcc(k = 1);
equation
  connect(accelerate.flange, mass.flange_a);
  connect(constantAcc.y, accelerate.a_ref);
end Accelerate;
"""


def test_accelerate_example() -> None:
    result = simulate(ACCELERATE, 1.0)
    t = result.time
    assert np.max(np.abs(result["accelerate.s"] - t ** 2 / 2)) < 1e-9
    assert np.max(np.abs(result["mass.s"] - (t ** 2 / 2 + 0.5))) < 1e-9


INITIAL_CONDITIONS = f"""
model InitialConditions "Modelica.Mechanics.Translational.Examples.InitialConditions"
  extends Modelica.Icons.Example;
  {T}.Components.Fixed fixed2(s0 = 1);
  {T}.Components.Spring s2(s_rel0 = 2, c = 1e3);
  {T}.Components.Mass m3(L = 3, s(start = 4.5, fixed = true), v(fixed = true), m = 1);
  {T}.Components.SpringDamper sd2(s_rel0 = 4, c = 111, d = 1);
  {T}.Components.Mass m4(L = 5, s(start = 12.5, fixed = true), v(fixed = true), m = 1);
  {T}.Components.Fixed fixed1(s0 = -1);
  {T}.Components.Spring s1(s_rel0 = 1, c = 1e3, s_rel(start = 0.5, fixed = true));
  {T}.Components.Mass m1(L = 1, v(fixed = true), m = 1);
  {T}.Components.SpringDamper sd1(s_rel0 = 1, c = 111, s_rel(start = 1, fixed = true),
    v_rel(fixed = true), d = 1);
  {T}.Components.Mass m2(L = 2, m = 1);
equation
  connect(s2.flange_a, fixed2.flange);
  connect(s1.flange_a, fixed1.flange);
  connect(m1.flange_a, s1.flange_b);
  connect(sd1.flange_a, m1.flange_b);
  connect(m2.flange_a, sd1.flange_b);
  connect(m4.flange_a, sd2.flange_b);
  connect(sd2.flange_a, m3.flange_b);
  connect(m3.flange_a, s2.flange_b);
end InitialConditions;
"""


def test_initial_conditions_example_starts_at_rest_in_equilibrium() -> None:
    # Upper half: s2 from 1 to m3.flange_a = 3 (rest length 2), sd2 from 6 to
    # m4.flange_a = 10 (rest length 4). Lower half, given by relative states: s1 from -1
    # to m1.flange_a = -0.5 (rest length 1: compressed by 0.5), sd1 unstretched (1).
    result = simulate(INITIAL_CONDITIONS, 1.0)
    assert np.max(np.abs(result["m3.s"] - 4.5)) < 1e-12
    assert np.max(np.abs(result["m4.s"] - 12.5)) < 1e-12
    assert abs(float(result["m1.s"][0])) < 1e-12
    assert abs(float(result["sd1.s_rel"][0]) - 1) < 1e-12
    # The compressed spring pushes m1 (and m2 through sd1) along the axis: m1 starts
    # with a = 500 m/s2 (the damper carries no force at v_rel = 0).
    assert abs(float(result["m1.a"][0]) - 500) < 1e-6


TWO_MASSES = f"""
model TwoMasses "two masses coupled by a damper, a relative acceleration sensor"
  {T}.Components.Mass m1(m = 1, s(start = 0, fixed = true), v(start = 1, fixed = true));
  {T}.Components.Damper damper(d = 1);
  {T}.Components.Mass m2(m = 1, L = 0.5, s(start = 1, fixed = true), v(start = 0, fixed = true));
  {T}.Sensors.RelAccSensor relAcc;
equation
  connect(m1.flange_b, damper.flange_a);
  connect(damper.flange_b, m2.flange_a);
  connect(relAcc.flange_a, m1.flange_b);
  connect(relAcc.flange_b, m2.flange_b);
end TwoMasses;
"""


def test_two_masses_coupled_by_a_damper() -> None:
    # Momentum is kept: v1 + v2 = 1; the relative velocity decays with rate d/m1 + d/m2.
    result = simulate(TWO_MASSES, 1.0)
    t = result.time
    assert np.max(np.abs(result["m1.v"] - (0.5 + 0.5 * np.exp(-2 * t)))) < 1e-8
    assert np.max(np.abs(result["m2.v"] - (0.5 - 0.5 * np.exp(-2 * t)))) < 1e-8
    assert np.max(np.abs(result["relAcc.a_rel"] - 2 * np.exp(-2 * t))) < 1e-6


OSCILLATOR = f"""
model Oscillator "a mass on a spring to a fixed point, with sensors"
  {T}.Components.Fixed fixed(s0 = 1);
  {T}.Components.Spring spring(c = 400, s_rel0 = 0.5);
  {T}.Components.Mass mass(m = 4, L = 0.2, s(start = 0.2, fixed = true),
    v(start = 0, fixed = true));
  {T}.Components.Rod rod(L = 0.1);
  {T}.Sensors.PositionSensor position;
  {T}.Sensors.SpeedSensor speed;
  {T}.Sensors.AccSensor acc;
  {T}.Sensors.ForceSensor force;
  {T}.Sensors.RelPositionSensor relPosition;
  {T}.Sensors.RelSpeedSensor relSpeed;
equation
  connect(mass.flange_b, force.flange_a);
  connect(force.flange_b, rod.flange_a);
  connect(rod.flange_b, spring.flange_a);
  connect(spring.flange_b, fixed.flange);
  connect(position.flange, mass.flange_a);
  connect(speed.flange, mass.flange_a);
  connect(acc.flange, mass.flange_a);
  connect(relPosition.flange_a, mass.flange_b);
  connect(relPosition.flange_b, fixed.flange);
  connect(relSpeed.flange_a, mass.flange_b);
  connect(relSpeed.flange_b, fixed.flange);
end Oscillator;
"""


def test_mass_spring_rod_and_sensors() -> None:
    result = simulate(OSCILLATOR, 1.0)
    t = result.time
    # Spring from rod end (s + 0.1 + 0.1) to 1 with rest length 0.5: equilibrium at
    # s = 0.3; omega = sqrt(400/4) = 10; s(0) = 0.2, v(0) = 0.
    s = 0.3 - 0.1 * np.cos(10 * t)
    v = np.sin(10 * t)
    assert np.max(np.abs(result["mass.s"] - s)) < 1e-8
    assert np.max(np.abs(result["position.s"] - (s - 0.1))) < 1e-8
    assert np.max(np.abs(result["speed.v"] - v)) < 1e-7
    assert np.max(np.abs(result["acc.a"] - 10 * np.cos(10 * t))) < 1e-6
    # The spring pulls the mass along the axis: the cut force at force.flange_a.
    spring_force = 400 * (1 - (s + 0.2) - 0.5)
    assert np.max(np.abs(result["force.f"] + spring_force)) < 1e-6
    assert np.max(np.abs(result["relPosition.s_rel"] - (1 - (s + 0.1)))) < 1e-8
    assert np.max(np.abs(result["relSpeed.v_rel"] + v)) < 1e-7


SOURCES = f"""
model Sources "prescribed force, speed and position"
  {T}.Sources.ConstantForce push(f_constant = 3);
  {T}.Components.Mass m1(m = 2, s(start = 0, fixed = true), v(start = 0, fixed = true));
  {T}.Sources.Speed speed(exact = true);
  Modelica.Blocks.Sources.Constant v_ref(k = 1.5);
  {T}.Components.Mass m2(m = 1);
  {T}.Sources.Speed filtered;
  {T}.Components.Mass m3(m = 1);
  {T}.Sources.Position position(exact = true);
  Modelica.Blocks.Sources.Constant s_ref(k = 0.25);
  {T}.Components.Spring spring(c = 100);
  {T}.Components.Mass m4(m = 1, s(start = 0.25, fixed = true), v(start = 1, fixed = true));
equation
  connect(push.flange, m1.flange_a);
  connect(v_ref.y, speed.v_ref);
  connect(speed.flange, m2.flange_a);
  connect(v_ref.y, filtered.v_ref);
  connect(filtered.flange, m3.flange_a);
  connect(s_ref.y, position.s_ref);
  connect(position.flange, spring.flange_a);
  connect(spring.flange_b, m4.flange_a);
end Sources;
"""


def test_force_speed_and_position_sources() -> None:
    result = simulate(SOURCES, 1.0)
    t = result.time
    # A constant push of 3 N on 2 kg: s = 3/4 t^2.
    assert np.max(np.abs(result["m1.s"] - 0.75 * t ** 2)) < 1e-9
    # A prescribed speed 1.5 from s = 0, exact and filtered (the filter starts at v_ref).
    assert np.max(np.abs(result["m2.s"] - 1.5 * t)) < 1e-9
    assert np.max(np.abs(result["m3.s"] - 1.5 * t)) < 1e-9
    # A spring anchored at the prescribed position 0.25: m4 oscillates about it.
    expected = 0.25 + np.sin(10 * t) / 10
    assert np.max(np.abs(result["m4.s"] - expected)) < 1e-8


SUPPORT = f"""
model Support "a force between two masses through its support flange"
  {T}.Sources.Force force(useSupport = true);
  Modelica.Blocks.Sources.Constant f(k = 6);
  {T}.Components.Mass a(m = 1, s(start = 0, fixed = true), v(start = 0, fixed = true));
  {T}.Components.Mass b(m = 2, s(start = 0, fixed = true), v(start = 0, fixed = true));
equation
  connect(f.y, force.f);
  connect(force.flange, a.flange_a);
  connect(force.support, b.flange_a);
end Support;
"""


def test_an_enabled_support_takes_the_reaction_force() -> None:
    result = simulate(SUPPORT, 1.0)
    t = result.time
    assert np.max(np.abs(result["a.s"] - 3 * t ** 2)) < 1e-9
    assert np.max(np.abs(result["b.s"] + 1.5 * t ** 2)) < 1e-9
    assert math.isclose(float(result["force.s"][-1]), 4.5, rel_tol=1e-9)


SENSED = f"""
model Sensed "a constant force through power and multi sensors"
  {T}.Sources.ConstantForce push(f_constant = 2);
  {T}.Sensors.MultiSensor multi;
  {T}.Sensors.PowerSensor power;
  {T}.Components.Mass mass(m = 1, s(start = 0, fixed = true), v(start = 0, fixed = true));
equation
  connect(push.flange, multi.flange_a);
  connect(multi.flange_b, power.flange_a);
  connect(power.flange_b, mass.flange_a);
end Sensed;
"""


def test_multi_and_power_sensors() -> None:
    result = simulate(SENSED, 1.0)
    t = result.time
    # a = 2: v = 2 t; the force 2 N through the cuts, power 2*v.
    assert np.max(np.abs(result["multi.f"] - 2)) < 1e-9
    assert np.max(np.abs(result["multi.v"] - 2 * t)) < 1e-8
    assert np.max(np.abs(result["multi.power"] - 4 * t)) < 1e-8
    assert np.max(np.abs(result["power.power"] - 4 * t)) < 1e-8


MOVED = f"""
model Moved "a filtered position source and a Move source with constant signals"
  {T}.Sources.Position position(f_crit = 5);
  Modelica.Blocks.Sources.Constant s_ref(k = 0.25);
  {T}.Components.Mass m1(m = 1);
  {T}.Sources.Move move;
  Modelica.Blocks.Sources.Constant u1(k = 1), u2(k = 0), u3(k = 0);
  {T}.Components.Mass m2(m = 1);
equation
  connect(s_ref.y, position.s_ref);
  connect(position.flange, m1.flange_a);
  connect(u1.y, move.u[1]);
  connect(u2.y, move.u[2]);
  connect(u3.y, move.u[3]);
  connect(move.flange, m2.flange_a);
end Moved;
"""


def test_position_filter_starts_at_its_reference_and_move_follows_u() -> None:
    result = simulate(MOVED, 1.0)
    assert np.max(np.abs(result["m1.s"] - 0.25)) < 1e-9
    assert np.max(np.abs(result["m2.s"] - 1)) < 1e-12
