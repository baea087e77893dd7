"""State events of a model on a nanosecond scale are located to its own scale.

The pulse source of the MSL's ``Blocks.Sources.Trapezoid`` (NandGate's inputs: edges
of 1 ns every 40 ns): a when-clause on ``time >= (pre(count) + 1)*period + startTime``
starts a period (``Ts = time``) and ``time < Ts + rising`` ends its rising edge. Both
relations read discrete values, so they are state events. The narrow band of the
relations' hysteresis (``codegen.hysteresis``) moves the root of ``time - c`` off the
point where it is exactly 0, and the locator's bracket of 1e-12 * max(1, |t|) then
ended 5e-13 s after the root: every edge of 1 ns started 5e-13 late, an error of 5e-4
of the ramp (NandGate's worst error went from 3.75e-4 to 1.78e-3). Events are now
located to 1e-12 of max(|t|, step).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc

NANO_PULSE = '''\
model NanoPulse
  parameter Real period = 40e-9, startTime = 10e-9, rising = 1e-9;
  Integer count(start = -1, fixed = true);
  discrete Real Ts(start = startTime - period, fixed = true);
  Real v(start = 0, fixed = true);
equation
  when time >= (pre(count) + 1)*period + startTime then
    count = pre(count) + 1;
    Ts = time;
  end when;
  der(v) = if time < Ts + rising then 1/rising else 0;
end NanoPulse;
'''
STARTS = (1e-8, 5e-8, 9e-8)


def test_nanosecond_edges_are_located_at_their_times(tmp_path: Path) -> None:
    path = tmp_path / "NanoPulse.mo"
    path.write_text(NANO_PULSE)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=1e-7,
                              interval=1e-10, error_control="off")
    times = [e.time for e in result.events if e.kind == "state"]
    exact = [t + d for t in STARTS for d in (0.0, 1e-9)]  # each start, then its edge's end
    assert len(times) == len(exact)
    for located, t in zip(times, exact):
        assert t <= located <= t * (1 + 4e-12)  # the old locator: 5e-13 late (1e-5 of t)
    # v counts the edges: (t - start)/rising on the k-th edge; the old one gave 0.4995
    for k, start in enumerate(STARTS):
        mid = start + 0.5e-9
        assert abs(float(np.interp(mid, result.time, result["v"])) - (k + 0.5)) < 1e-8
