within Modelica.Mechanics.Rotational;
package Sensors "Sensors of rotational quantities"
  model AngleSensor "The absolute angle of a flange as an output signal"
    extends Rotational.Interfaces.PartialAbsoluteSensor;
    Modelica.Blocks.Interfaces.RealOutput phi(unit = "rad", displayUnit = "deg") "Absolute angle of the flange";
  equation
    phi = flange.phi;
  end AngleSensor;

  model SpeedSensor "The absolute angular velocity of a flange as an output signal"
    extends Rotational.Interfaces.PartialAbsoluteSensor;
    Modelica.Blocks.Interfaces.RealOutput w(unit = "rad/s") "Absolute angular velocity of the flange";
  equation
    w = der(flange.phi);
  end SpeedSensor;

  model AccSensor "The absolute angular acceleration of a flange as an output signal"
    extends Rotational.Interfaces.PartialAbsoluteSensor;
    SI.AngularVelocity w "Absolute angular velocity of the flange";
    Modelica.Blocks.Interfaces.RealOutput a(unit = "rad/s2") "Absolute angular acceleration of the flange";
  equation
    w = der(flange.phi);
    a = der(w);
  end AccSensor;

  model TorqueSensor "The torque in a cut between two flanges as an output signal"
    extends Rotational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput tau(unit = "N.m") "Torque in the flange_a cut";
  equation
    flange_a.phi = flange_b.phi;
    flange_a.tau = tau;
  end TorqueSensor;

  model RelAngleSensor "The relative angle of two flanges as an output signal"
    extends Rotational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput phi_rel(unit = "rad", displayUnit = "deg") "Relative angle (= flange_b.phi - flange_a.phi)";
  equation
    phi_rel = flange_b.phi - flange_a.phi;
    0 = flange_a.tau;
  end RelAngleSensor;

  model RelSpeedSensor "The relative angular velocity of two flanges as an output signal"
    extends Rotational.Interfaces.PartialRelativeSensor;
    SI.Angle phi_rel "Relative angle (= flange_b.phi - flange_a.phi)";
    Modelica.Blocks.Interfaces.RealOutput w_rel(unit = "rad/s") "Relative angular velocity (= der(phi_rel))";
  equation
    phi_rel = flange_b.phi - flange_a.phi;
    w_rel = der(phi_rel);
    0 = flange_a.tau;
  end RelSpeedSensor;
end Sensors;
