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


EXTREMA = '''\
model Extrema "the least value of u seen at the events where u turns (a first-order lag x)"
  parameter Real T = 1e-3;
  Real u = cos(6.283185307179586*time);
  Real x(start = 1, fixed = true);
  discrete Real y_min(start = 1, fixed = true);
  discrete Real t_min(start = 0, fixed = true);
equation
  der(x) = (u - x)/T;
  when {u <= x, u >= x} then
    y_min = min(pre(y_min), u);
    t_min = if y_min < pre(y_min) then time else pre(t_min);
  end when;
end Extrema;
'''


def test_a_relation_in_a_when_body_is_taken_literally_at_its_events(tmp_path: Path
                                                                     ) -> None:
    # 8.5: the body is evaluated at the clause's events only, so 'y_min < pre(y_min)'
    # (with y_min = min(pre(y_min), u): on its boundary after each event) gets no zero
    # crossing (main: a third one, 'pre(y_min) < u'; the MSL's
    # DemonstrateContinuousSignalExtrema chattered on it at 5e-11 s)
    path = tmp_path / "Extrema.mo"
    path.write_text(EXTREMA)
    model = springc.compile_model(str(path), backend="python")
    assert model.module.ZERO_CROSSINGS == ("u <= x", "u >= x")
    result = springc.simulate(model, stop=0.9, interval=0.01, engine="scipy",
                              error_control="off")
    y_min, t_min = float(result["y_min"][-1]), float(result["t_min"][-1])
    # the minimum of cos(2 pi t) at t = 0.5, found when u turns above its lag
    assert abs(t_min - 0.5) < 2e-3
    assert abs(y_min - math.cos(2 * math.pi * t_min)) < 1e-9
    assert y_min + 1 < 1e-4
