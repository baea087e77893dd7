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

  model RelAccSensor "The relative angular acceleration of two flanges as an output signal"
    extends Rotational.Interfaces.PartialRelativeSensor;
    SI.Angle phi_rel "Relative angle (= flange_b.phi - flange_a.phi)";
    SI.AngularVelocity w_rel "Relative angular velocity (= der(phi_rel))";
    Modelica.Blocks.Interfaces.RealOutput a_rel(unit = "rad/s2") "Relative angular acceleration (= der(w_rel))";
  equation
    phi_rel = flange_b.phi - flange_a.phi;
    w_rel = der(phi_rel);
    a_rel = der(w_rel);
    0 = flange_a.tau;
  end RelAccSensor;

  model PowerSensor "The power flowing from flange_a to flange_b as an output signal"
    extends Rotational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput power(unit = "W") "Power flowing through the cut (= flange_a.tau*der(flange_a.phi))";
  equation
    flange_a.phi = flange_b.phi;
    power = flange_a.tau*der(flange_a.phi);
  end PowerSensor;

  model MultiSensor "The torque, angular velocity and power in a cut between two flanges as output signals"
    extends Rotational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput power(unit = "W") "Power flowing through the cut (= tau*w)";
    Modelica.Blocks.Interfaces.RealOutput w(unit = "rad/s") "Absolute angular velocity of the flanges";
    Modelica.Blocks.Interfaces.RealOutput tau(unit = "N.m") "Torque in the flange_a cut";
  equation
    flange_a.phi = flange_b.phi;
    w = der(flange_a.phi);
    tau = flange_a.tau;
    power = tau*w;
  end MultiSensor;
end Sensors;
