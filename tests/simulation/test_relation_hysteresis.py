"""A relation that the configuration it selects puts on its own boundary: the arc
switch of the MSL's Electrical.Analog.SwitchWithArc (``Interfaces.IdealSwitchWithArc``).

Once the arc is quenched, ``i = Goff*v`` makes ``abs(i) <= abs(v)*Goff`` an identity:
its two sides differ only by the rounding, and the event iteration flipped it with
every pass (main: "the event iteration at time 0.678807276 did not settle in 100
passes: abs(i) <= abs(v) * Goff keep changing"). The relations' hysteresis
(``codegen.hysteresis``) keeps its value, and the run follows the closed form of
each phase: closed (``v = Ron i``), arcing (``v = Varc sign(i)``), quenched
(``i = Goff v``), of ``L di/dt = E - R i - v``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc

ARC_SWITCH = '''\
model ArcSwitch
  parameter Real L = 0.1, R = 1, E = 50, Ron = 1e-5, Goff = 1e-3, Varc = 60;
  Real i(start = 0, fixed = true);
  Real v;
  Boolean off = time >= 0.5;
  Boolean quenched(start = true, fixed = true);
equation
  L*der(i) = E - R*i - v;
  quenched = off and (abs(i) <= abs(v)*Goff or pre(quenched));
  if off then
    if quenched then
      i = Goff*v;
    else
      v = Varc*sign(i);
    end if;
  else
    v = Ron*i;
  end if;
end ArcSwitch;
'''
L, R, E, RON, GOFF, VARC = 0.1, 1.0, 50.0, 1e-5, 1e-3, 60.0


def _closed(t: float) -> float:
    """The current before the switch opens at 0.5 and while the arc burns."""
    i_open = E / (R + RON) * (1 - math.exp(-(R + RON) * 0.5 / L))
    if t < 0.5:
        return E / (R + RON) * (1 - math.exp(-(R + RON) * t / L))
    return (E - VARC) / R + (i_open - (E - VARC) / R) * math.exp(-R * (t - 0.5) / L)


def test_a_quenched_arc_switch_settles_on_its_own_boundary(tmp_path: Path) -> None:
    path = tmp_path / "ArcSwitch.mo"
    path.write_text(ARC_SWITCH)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1.0,
                              interval=0.001, rtol=1e-10, atol=1e-12, error_control="off")
    t = result.time
    before = t < 0.675  # the current reaches Varc*Goff at 0.678014
    expected = np.array([_closed(float(s)) for s in t[before]])
    assert np.max(np.abs(result["i"][before] - expected)) < 1e-7
    assert list(result["quenched"][before]) == [0.0] * int(np.sum(before))
    # quenched: L di/dt = E - (R + 1/Goff) i, settled within 1e-3 s
    after = t >= 0.69
    assert np.max(np.abs(result["i"][after] - E / (R + 1 / GOFF))) < 1e-9
    assert np.max(np.abs(result["v"][after] - E / (R + 1 / GOFF) / GOFF)) < 1e-6
    assert list(result["quenched"][after]) == [1.0] * int(np.sum(after))
