within Modelica.Mechanics.Translational;
package Sensors "Sensors of translational quantities"
  model PositionSensor "The absolute position of a flange as an output signal"
    extends Translational.Interfaces.PartialAbsoluteSensor;
    Modelica.Blocks.Interfaces.RealOutput s(unit = "m") "Absolute position of the flange";
  equation
    s = flange.s;
  end PositionSensor;

  model SpeedSensor "The absolute velocity of a flange as an output signal"
    extends Translational.Interfaces.PartialAbsoluteSensor;
    Modelica.Blocks.Interfaces.RealOutput v(unit = "m/s") "Absolute velocity of the flange";
  equation
    v = der(flange.s);
  end SpeedSensor;

  model AccSensor "The absolute acceleration of a flange as an output signal"
    extends Translational.Interfaces.PartialAbsoluteSensor;
    SI.Velocity v "Absolute velocity of the flange";
    Modelica.Blocks.Interfaces.RealOutput a(unit = "m/s2") "Absolute acceleration of the flange";
  equation
    v = der(flange.s);
    a = der(v);
  end AccSensor;

  model ForceSensor "The force in a cut between two flanges as an output signal"
    extends Translational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput f(unit = "N") "Force in the flange_a cut (positive along the axis)";
  equation
    flange_a.s = flange_b.s;
    flange_a.f = f;
  end ForceSensor;

  model RelPositionSensor "The relative position of two flanges as an output signal"
    extends Translational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput s_rel(unit = "m") "Distance between the flanges (= flange_b.s - flange_a.s)";
  equation
    s_rel = flange_b.s - flange_a.s;
    0 = flange_a.f;
  end RelPositionSensor;

  model RelSpeedSensor "The relative velocity of two flanges as an output signal"
    extends Translational.Interfaces.PartialRelativeSensor;
    SI.Position s_rel "Distance between the flanges (= flange_b.s - flange_a.s)";
    Modelica.Blocks.Interfaces.RealOutput v_rel(unit = "m/s") "Relative velocity (= der(s_rel))";
  equation
    s_rel = flange_b.s - flange_a.s;
    v_rel = der(s_rel);
    0 = flange_a.f;
  end RelSpeedSensor;

  model RelAccSensor "The relative acceleration of two flanges as an output signal"
    extends Translational.Interfaces.PartialRelativeSensor;
    SI.Position s_rel "Distance between the flanges (= flange_b.s - flange_a.s)";
    SI.Velocity v_rel "Relative velocity (= der(s_rel))";
    Modelica.Blocks.Interfaces.RealOutput a_rel(unit = "m/s2") "Relative acceleration (= der(v_rel))";
  equation
    s_rel = flange_b.s - flange_a.s;
    v_rel = der(s_rel);
    a_rel = der(v_rel);
    0 = flange_a.f;
  end RelAccSensor;

  model PowerSensor "The power flowing from flange_a to flange_b as an output signal"
    extends Translational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput power(unit = "W") "Power flowing through the cut (= flange_a.f*der(flange_a.s))";
  equation
    flange_a.s = flange_b.s;
    power = flange_a.f*der(flange_a.s);
  end PowerSensor;

  model MultiSensor "The force, velocity and power in a cut between two flanges as output signals"
    extends Translational.Interfaces.PartialRelativeSensor;
    Modelica.Blocks.Interfaces.RealOutput power(unit = "W") "Power flowing through the cut (= f*v)";
    Modelica.Blocks.Interfaces.RealOutput f(unit = "N") "Force in the flange_a cut";
    Modelica.Blocks.Interfaces.RealOutput v(unit = "m/s") "Absolute velocity of the flanges";
  equation
    flange_a.s = flange_b.s;
    f = flange_a.f;
    v = der(flange_a.s);
    power = f*v;
  end MultiSensor;
end Sensors;
