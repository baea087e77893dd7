"""A rigid pendulum written as an index-3 DAE, started at rest 37 degrees from the
vertical: the model of dynamic state selection that several tests compile."""

PENDULUM = """model Pendulum
  parameter Real L = 1, g = 9.81;
  Real x(start = 0.6), y(start = -0.8), vx(start = 0), vy(start = 0), F;
equation
  der(x) = vx;
  der(y) = vy;
  der(vx) = -F*x;
  der(vy) = -F*y - g;
  x^2 + y^2 = L^2;
end Pendulum;
"""
