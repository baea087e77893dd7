model ZenerClamp "A capacitor charged through a resistor from a sine source that starts at startTime (a time event), its voltage clamped by two Zener diodes in anti-series (MSL 4's ZDiode, twice: a torn nonlinear system); the structure of Modelica.Electrical.Analog.Examples.OvervoltageProtection"
  parameter Real C = 1e-3 "Capacitance";
  parameter Real Rv = 20 "Series resistance";
  parameter Real RL = 2000 "Load resistance";
  parameter Real V = 10 "Source amplitude";
  parameter Real f = 5 "Source frequency";
  parameter Real startTime = 0.01 "The source starts here";
  parameter Real Ids = 1e-6, Vt = 0.04, Maxexp = 30, R = 1e8, Bv = 5.1, Ibv = 0.7, Nbv = 0.74;
  Real v(start = 0, fixed = true) "Capacitor voltage";
  Real i "Capacitor current";
  Real vs "Source voltage";
  Real vm "Voltage between the diodes";
  Real v1 "Voltage of the first diode (from v to vm)";
  Real v2 "Voltage of the second diode (from ground to vm)";
  Real id "Current through both diodes (from v to ground)";
  Real loss "Power lost in the first diode";
equation
  vs = if time < startTime then 0 else V*sin(2*Modelica.Constants.pi*f*(time - startTime));
  i = C*der(v);
  (vs - v)/Rv = i + v/RL + id;
  v1 = v - vm;
  v2 = -vm;
  id = smooth(1, if v1 > Maxexp*Vt then Ids*(exp(Maxexp)*(1 + v1/Vt - Maxexp) - 1) + v1/R
    else if v1 + Bv < -Maxexp*(Nbv*Vt) then -Ids - Ibv*exp(Maxexp)*(1 - (v1 + Bv)/(Nbv*Vt) - Maxexp) + v1/R
    else Ids*(exp(v1/Vt) - 1) - Ibv*exp(-(v1 + Bv)/(Nbv*Vt)) + v1/R);
  -id = smooth(1, if v2 > Maxexp*Vt then Ids*(exp(Maxexp)*(1 + v2/Vt - Maxexp) - 1) + v2/R
    else if v2 + Bv < -Maxexp*(Nbv*Vt) then -Ids - Ibv*exp(Maxexp)*(1 - (v2 + Bv)/(Nbv*Vt) - Maxexp) + v2/R
    else Ids*(exp(v2/Vt) - 1) - Ibv*exp(-(v2 + Bv)/(Nbv*Vt)) + v2/R);
  loss = v1*id;
  annotation(experiment(StopTime = 0.46, Interval = 0.0008));
end ZenerClamp;
