"""Two stuck friction elements in series (the MSL's LossyGearDemo2: a gear and its
bearing friction, both locked at the start).

The block's balance fixes only the sum of the two brakes' path parameters: the torn
Newton system has a zero row. Before, the run stopped at once ("sensitivity is
singular at time 0"). The Newton correction now takes the basic solution (the free
unknown 0): brake 1 carries the whole applied force ``k t`` until ``k t = f1max``.
There the starting brake's path parameter sits exactly on its breakaway force while
the other holds the block, and its relation flipped with the rounding (main: "did
not settle at 0.5: sa1 > f1max keep changing"); the relations' hysteresis
(``codegen.hysteresis``) keeps the value its first passes gave, and the block stays
until the force exceeds both breakaway forces together.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc
from springc.simulation import SimulationResult

TWO_BRAKES = '''\
model TwoBrakes
  parameter Real m = 1, k = 2, f1max = 1, f2max = 2;
  Real s(start = 0, fixed = true), v(start = 0, fixed = true);
  Real a, sa1, sa2, f1, f2;
  Boolean start1, start2, locked1, locked2;
  Boolean stuck1(start = true, fixed = true), stuck2(start = true, fixed = true);
equation
  der(s) = v;
  der(v) = a;
  m*a = k*time - f1 - f2;
  start1 = pre(stuck1) and sa1 > f1max;
  locked1 = pre(stuck1) and not start1;
  a = if locked1 then 0 else sa1 - f1max;
  f1 = if locked1 then sa1 else f1max;
  stuck1 = locked1 or v <= 0;
  start2 = pre(stuck2) and sa2 > f2max;
  locked2 = pre(stuck2) and not start2;
  a = if locked2 then 0 else sa2 - f2max;
  f2 = if locked2 then sa2 else f2max;
  stuck2 = locked2 or v <= 0;
end TwoBrakes;
'''

def _run(tmp_path: Path, name: str, text: str) -> SimulationResult:
    path = tmp_path / f"{name}.mo"
    path.write_text(text)
    return springc.simulate(str(path), backend="python", engine="scipy", stop=3.0,
                            interval=0.01, rtol=1e-10, atol=1e-12, error_control="off")


def test_two_stuck_brakes_hold_the_block_until_both_break_away(tmp_path: Path) -> None:
    # closed form: stuck while k t <= f1max + f2max (t <= 1.5), then
    # m a = k t - f1max - f2max: v = (t - 1.5)^2, s = (t - 1.5)^3 / 3
    result = _run(tmp_path, "TwoBrakes", TWO_BRAKES)
    t = result.time
    v = np.where(t > 1.5, (t - 1.5) ** 2, 0.0)
    s = np.where(t > 1.5, (t - 1.5) ** 3 / 3, 0.0)
    assert np.max(np.abs(result["v"] - v)) < 1e-8
    assert np.max(np.abs(result["s"] - s)) < 1e-8
    assert list(result["stuck1"][t < 1.49]) == [1.0] * int(np.sum(t < 1.49))
    assert list(result["stuck2"][t > 1.51]) == [0.0] * int(np.sum(t > 1.51))
    breakaways = [e.time for e in result.events if e.kind == "state"]
    assert any(abs(tb - 1.5) < 1e-9 for tb in breakaways)
