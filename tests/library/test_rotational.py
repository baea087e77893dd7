"""The bundled Modelica.Mechanics.Rotational (event-free classes), each component against
a closed form: inertia on a spring, damped inertia, torque sources, prescribed speed,
an ideal gear, and the sensors."""

from __future__ import annotations

import numpy as np
import pytest

import springc


@pytest.fixture(autouse=True)
def _no_environment_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)
    monkeypatch.delenv("MODELICAPATH", raising=False)


def simulate(text: str, stop: float) -> springc.SimulationResult:
    compiled = springc.load_model_from_string(text, cache=False)
    return springc.simulate(compiled, stop=stop, interval=stop / 200, rtol=1e-10,
                            atol=1e-12)


R = "Modelica.Mechanics.Rotational"

SPRING = f"""
model Torsion "an inertia on a torsion spring, and an inertia with a damper"
  {R}.Components.Fixed fixed;
  {R}.Components.Spring spring(c = 50);
  {R}.Components.Inertia inertia(J = 2, phi(start = 0.1, fixed = true), w(start = 0, fixed = true));
  {R}.Sensors.AngleSensor angle;
  {R}.Sensors.SpeedSensor speed;
  {R}.Sensors.AccSensor acc;
  {R}.Sensors.RelAngleSensor relAngle;
  {R}.Sensors.RelSpeedSensor relSpeed;
  {R}.Components.Fixed fixed2(phi0 = 1);
  {R}.Components.Damper damper(d = 4);
  {R}.Components.Inertia disc(J = 1, phi(start = 1, fixed = true), w(start = 2, fixed = true));
equation
  connect(fixed.flange, spring.flange_a);
  connect(spring.flange_b, inertia.flange_a);
  connect(angle.flange, inertia.flange_b);
  connect(speed.flange, inertia.flange_b);
  connect(acc.flange, inertia.flange_b);
  connect(relAngle.flange_a, fixed.flange);
  connect(relAngle.flange_b, inertia.flange_b);
  connect(relSpeed.flange_a, fixed.flange);
  connect(relSpeed.flange_b, inertia.flange_b);
  connect(fixed2.flange, damper.flange_a);
  connect(damper.flange_b, disc.flange_a);
end Torsion;
"""


def test_inertia_spring_damper_and_sensors() -> None:
    result = simulate(SPRING, 1.0)
    t = result.time
    # J*phi'' = -c*phi: omega = 5.
    phi = 0.1 * np.cos(5 * t)
    assert np.max(np.abs(result["inertia.phi"] - phi)) < 1e-9
    assert np.max(np.abs(result["angle.phi"] - phi)) < 1e-9
    assert np.max(np.abs(result["relAngle.phi_rel"] - phi)) < 1e-9
    assert np.max(np.abs(result["speed.w"] + 0.5 * np.sin(5 * t))) < 1e-8
    assert np.max(np.abs(result["relSpeed.w_rel"] + 0.5 * np.sin(5 * t))) < 1e-8
    assert np.max(np.abs(result["acc.a"] + 2.5 * np.cos(5 * t))) < 1e-6
    # J*w' = -d*w: w = 2 exp(-4 t), phi = 1 + (1 - exp(-4 t))/2.
    assert np.max(np.abs(result["disc.phi"] - (1 + 0.5 * (1 - np.exp(-4 * t))))) < 1e-9
    assert np.max(np.abs(result["damper.lossPower"] - 4 * (2 * np.exp(-4 * t)) ** 2)) < 1e-6


TORQUES = f"""
model Torques "torque sources and a prescribed speed"
  {R}.Sources.Torque torque;
  Modelica.Blocks.Sources.Constant tau(k = 3);
  {R}.Sensors.TorqueSensor sensor;
  {R}.Components.Inertia a(J = 1.5, phi(start = 0, fixed = true), w(start = 0, fixed = true));
  {R}.Sources.ConstantTorque constTorque(tau_constant = 3);
  {R}.Components.Inertia b(J = 1, phi(start = 0, fixed = true), w(start = 0, fixed = true));
  {R}.Sources.Speed speed(exact = true);
  Modelica.Blocks.Sources.Constant w_ref(k = 2);
  {R}.Components.Inertia c(J = 1);
  {R}.Sources.ConstantSpeed constantSpeed(w_fixed = -1);
  {R}.Components.Inertia d(J = 1);
equation
  connect(tau.y, torque.tau);
  connect(torque.flange, sensor.flange_a);
  connect(sensor.flange_b, a.flange_a);
  connect(constTorque.flange, b.flange_a);
  connect(w_ref.y, speed.w_ref);
  connect(speed.flange, c.flange_a);
  connect(constantSpeed.flange, d.flange_a);
end Torques;
"""


def test_torque_and_speed_sources() -> None:
    result = simulate(TORQUES, 1.0)
    t = result.time
    assert np.max(np.abs(result["a.phi"] - t ** 2)) < 1e-9
    assert np.max(np.abs(result["sensor.tau"] - 3)) < 1e-9
    assert np.max(np.abs(result["b.phi"] - 1.5 * t ** 2)) < 1e-9
    assert np.max(np.abs(result["c.phi"] - 2 * t)) < 1e-9
    assert np.max(np.abs(result["d.w"] + 1)) < 1e-9


GEAR = f"""
model Gear "a torque on an inertia driving a second one through an ideal gear"
  {R}.Sources.Torque torque;
  Modelica.Blocks.Sources.Constant tau(k = 2);
  {R}.Components.Inertia a(J = 1, phi(start = 0, fixed = true), w(start = 0, fixed = true));
  {R}.Components.IdealGear gear(ratio = 2);
  {R}.Components.Inertia b(J = 4);
equation
  connect(tau.y, torque.tau);
  connect(torque.flange, a.flange_a);
  connect(a.flange_b, gear.flange_a);
  connect(gear.flange_b, b.flange_a);
end Gear;
"""


def test_ideal_gear() -> None:
    # Inertia seen at flange_a: J_a + J_b/ratio^2 = 2, so phi_a'' = tau/2 = 1.
    result = simulate(GEAR, 1.0)
    t = result.time
    assert np.max(np.abs(result["a.phi"] - t ** 2 / 2)) < 1e-9
    assert np.max(np.abs(result["b.phi"] - t ** 2 / 4)) < 1e-9


DRIVEN = f"""
model Driven "prescribed acceleration and angle, through power, multi and relative sensors"
  {R}.Sources.Accelerate accelerate;
  Modelica.Blocks.Sources.Constant a_ref(k = 2);
  {R}.Sensors.MultiSensor multi;
  {R}.Sensors.PowerSensor power;
  {R}.Components.Inertia a(J = 3);
  {R}.Sources.Position position(f_crit = 5);
  Modelica.Blocks.Sources.Constant phi_ref(k = 0.5);
  {R}.Components.Inertia b(J = 1);
  {R}.Sensors.RelAccSensor relAcc;
equation
  connect(a_ref.y, accelerate.a_ref);
  connect(accelerate.flange, multi.flange_a);
  connect(multi.flange_b, power.flange_a);
  connect(power.flange_b, a.flange_a);
  connect(phi_ref.y, position.phi_ref);
  connect(position.flange, b.flange_a);
  connect(relAcc.flange_a, b.flange_b);
  connect(relAcc.flange_b, a.flange_b);
end Driven;
"""


def test_accelerate_position_and_power_sensors() -> None:
    result = simulate(DRIVEN, 1.0)
    t = result.time
    # a'' = 2 from rest: phi = t^2; the torque J*a = 6 passes through both sensors.
    assert np.max(np.abs(result["a.phi"] - t ** 2)) < 1e-9
    assert np.max(np.abs(result["multi.tau"] - 6)) < 1e-8
    assert np.max(np.abs(result["multi.w"] - 2 * t)) < 1e-8
    assert np.max(np.abs(result["multi.power"] - 12 * t)) < 1e-7
    assert np.max(np.abs(result["power.power"] - 12 * t)) < 1e-7
    # The filter starts at its constant reference: b stays at 0.5.
    assert np.max(np.abs(result["b.phi"] - 0.5)) < 1e-9
    assert np.max(np.abs(result["relAcc.a_rel"] - 2)) < 1e-6
