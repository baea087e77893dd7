"""``abs(v)`` expands into ``noEvent(if v >= 0 then v else -v)`` (Modelica 3.6, 3.7.1):
no event at ``v = 0`` and the value ``|v|`` at every point the integrator tries. As a
held branch it was ``v`` (negative) at the trial points of a step past the zero, and
the MSL's Stribeck friction ``exp(-fexp*abs(v))`` overflowed there
(Translational.Examples.Friction)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc

MODEL = '''\
model Bump
  parameter Real c = 1e-3;
  Real v(start = 1, fixed = true);
  discrete Real tHit(start = -1, fixed = true);
equation
  der(v) = -1 + c*exp(-40*abs(v));
  when v < -5 then
    tHit = time;
  end when;
end Bump;
'''


def reach(v: float, c: float = 1e-3) -> float:
    """When v (< 0) is reached from 1: dt = dv / (c exp(-40 |v|) - 1), integrated in
    closed form on each side of 0."""
    def up(u: float) -> float:  # u >= 0
        return u + math.log(1 - c * math.exp(-40 * u)) / 40

    def down(u: float) -> float:  # u <= 0
        return u - math.log(1 - c * math.exp(40 * u)) / 40
    return (up(1.0) - up(0.0)) + (down(0.0) - down(v))


def test_abs_is_literal_and_makes_no_event(tmp_path: Path) -> None:
    path = tmp_path / "Bump.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=100.0,
                              interval=10.0, rtol=1e-10, atol=1e-12, error_control="off")
    assert abs(float(np.asarray(result["tHit"])[-1]) - reach(-5.0)) < 1e-8
    # the only state event is v < -5 (none at v = 0)
    assert [e.cause for e in result.events if e.kind == "state"] == ["v < (-5)"]
