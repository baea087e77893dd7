"""Tearing never computes an inner variable by dividing by a time-varying coefficient
(as Dymola and OpenModelica): the MSL's semiconductors with a heat port write
``LossPower = v*i`` inside the loop through their temperature, and ``i = LossPower/v``
divided by zero at ``t = 0`` where ``v = 0`` (Electrical.Analog.Examples.HeatingRectifier,
HeatingMOSInverter). Such a pair is left to Newton's method as a residual."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc

MODEL = '''\
model HeatedDiode
  parameter Real G = 10 "thermal conductance";
  parameter Real T0 = 300;
  parameter Real a = 1e-6;
  Real x(start = 0, fixed = true);
  Real v = time "zero at the start";
  Real T(start = 300) "heat port temperature";
  Real i;
  Real P;
equation
  P = v*i;
  P = G*(T - T0);
  i = v*(1 + a*T^2);
  der(x) = T;
end HeatedDiode;
'''


def temperature(v: float, g: float = 10.0, t0: float = 300.0, a: float = 1e-6) -> float:
    """The root near ``t0`` of ``g (T - t0) = v^2 (1 + a T^2)``."""
    if v == 0.0:
        return t0
    q = a * v * v
    return (g - math.sqrt(g * g - 4 * q * (g * t0 + v * v))) / (2 * q)


def test_no_division_by_a_variable_that_is_zero_at_the_start(tmp_path: Path) -> None:
    path = tmp_path / "HeatedDiode.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=2.0,
                              interval=0.5, rtol=1e-10, atol=1e-10, error_control="off")
    times = np.asarray(result.time)
    expected = [temperature(float(t)) for t in times]
    assert np.allclose(np.asarray(result["T"]), expected, rtol=0, atol=1e-8)
    assert abs(float(np.asarray(result["i"])[0])) < 1e-12
