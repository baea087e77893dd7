model TranslationalOscillator "A mass on a spring and a damper to the wall, pushed by a constant force (Modelica.Mechanics.Translational)"
  import Modelica.Mechanics.Translational.Components;
  import Modelica.Mechanics.Translational.Sources;
  Components.Fixed fixed(s0 = 0);
  Components.Spring spring(c = 100, s_rel0 = 1);
  Components.Damper damper(d = 2);
  Components.Mass mass(m = 1, L = 0, s(start = 1.5, fixed = true), v(start = 0, fixed = true));
equation
  connect(fixed.flange, spring.flange_a);
  connect(spring.flange_b, mass.flange_a);
  connect(fixed.flange, damper.flange_a);
  connect(damper.flange_b, mass.flange_a);
  annotation(experiment(StartTime = 0, StopTime = 3, Interval = 0.01, Tolerance = 1e-8));
end TranslationalOscillator;

model Chain100 "The bundled chain of springs and masses with 100 masses"
  extends Scenes.Chain(N = 100);
end Chain100;

model Kicked "A damped mass kicked every 0.4 s (sample) and pushed from t = 1 s (a time relation)"
  parameter Real c = 40 "Spring constant";
  parameter Real d = 1 "Damping";
  parameter Real kick = 0.5 "Velocity added by each kick";
  Real x(start = 0, fixed = true, unit = "m");
  Real v(start = 0, fixed = true, unit = "m/s");
  Integer kicks(start = 0);
equation
  der(x) = v;
  der(v) = -c*x - d*v + (if time >= 1 then 2 else 0);
  when sample(0.4, 0.4) then
    reinit(v, pre(v) + kick);
    kicks = pre(kicks) + 1;
  end when;
  annotation(experiment(StopTime = 2));
end Kicked;
