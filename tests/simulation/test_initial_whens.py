"""Initial equations ``v = e`` of when-assigned variables whose ``e`` reads continuous
variables (section 8.6; Blocks.Math.SignalExtrema's ``y_min = u``): ``v`` takes ``e``'s
value at the initial event, then its when-clause's values (before: "the
initialization problem is over-determined: 3 initial conditions for 1 state(s)")."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc

MODEL = """model Extrema
  parameter Real Ts = 0.1;
  Real x(start = 1, fixed = true);
  Real u = sin(10*time) + x;
  discrete Real y_min;
  discrete Real y_max;
  discrete Real t_max;
initial equation
  y_min = u;
  y_max = u;
  t_max = time;
equation
  der(x) = -x;
  when sample(Ts, Ts) then
    y_min = min(u, pre(y_min));
    y_max = max(u, pre(y_max));
    t_max = if y_max > pre(y_max) then time else pre(t_max);
  end when;
end Extrema;
"""


def test_extrema_start_at_the_initial_value_of_a_continuous_input(tmp_path: Path) -> None:
    path = tmp_path / "extrema.mo"
    path.write_text(MODEL)
    result = springc.simulate([path], stop=1.0, interval=0.05, engine="scipy",
                              backend="python", rtol=1e-10, atol=1e-12,
                              error_control="off")
    t = np.asarray(result.time)
    ticks = np.arange(0, 11) * 0.1  # the initial value, then the samples at k Ts

    def u(s: np.ndarray) -> np.ndarray:
        return np.sin(10 * s) + np.exp(-s)

    seen = [ticks[ticks <= ti + 1e-9] for ti in t]
    y_min = np.array([u(s).min() for s in seen])
    y_max = np.array([u(s).max() for s in seen])
    t_max = np.array([s[np.argmax(u(s))] for s in seen])
    assert np.allclose(result["y_min"], y_min, rtol=0, atol=1e-7)
    assert np.allclose(result["y_max"], y_max, rtol=0, atol=1e-7)
    assert np.allclose(result["t_max"], t_max, rtol=0, atol=1e-12)
    assert result["y_min"][0] == 1.0
