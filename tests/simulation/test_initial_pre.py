"""Initial equations that give discrete values (section 8.6): ``pre(v) = e`` of a
variable no when-clause assigns (simplify/pre_starts.py: the MSL's OnOffController) and
``fixed = true`` on one (IdealGTOThyristor's ``off``),
and ``v = e(time)`` of a when-assigned one (the MSL's Pulse: its period count)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc

MODEL = '''\
model OnOff
  parameter Boolean startOn = true;
  Real T(start = 0.5, fixed = true);
  Boolean on;
  Integer count;
  Boolean off(start = true, fixed = true);
initial equation
  pre(on) = startOn;
  count = integer(time + 2.5);
equation
  on = pre(on) and T < 1 or T < 0;
  der(T) = if on then 1 else -1;
  off = not on;
  when T > 0.9 then
    count = pre(count) + 1;
  end when;
end OnOff;
'''


def test_pre_and_time_in_initial_equations(tmp_path: Path) -> None:
    path = tmp_path / "OnOff.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=2.0,
                              interval=0.25, rtol=1e-9, error_control="off")
    # pre(on) = true: on, T rises from 0.5 to 1 (t = 0.5), falls to 0 (t = 1.5), rises
    t = np.asarray(result.time)
    expected = np.where(t <= 0.5, 0.5 + t, np.where(t <= 1.5, 1.5 - t, t - 1.5))
    assert np.allclose(result["T"], expected, rtol=0, atol=1e-6)
    on = dict(zip(t.tolist(), np.asarray(result["on"]).tolist()))
    assert (on[0.0], on[0.25], on[1.0], on[1.75]) == (1.0, 1.0, 0.0, 1.0)
    # fixed = true on off sets pre(off), not off: off = not on = false at the start
    assert float(np.asarray(result["off"])[0]) == 0.0
    # count = integer(0 + 2.5) at the start, one more when T passes 0.9 (t = 0.4)
    count = np.asarray(result["count"])
    assert (count[0], count[1], count[-1]) == (2.0, 2.0, 3.0)


SAMPLED = '''\
model Sampled
  parameter Real f = 2;
  parameter Real t0(fixed = false);
  Integer n(start = 0, fixed = true);
initial equation
  t0 = time;
equation
  when sample(t0 + 1/f, 1/f) then
    n = pre(n) + 1;
  end when;
end Sampled;
'''


def test_sample_starting_at_a_parameter_the_initialization_fixes(tmp_path: Path) -> None:
    """``t0(fixed = false)`` with ``t0 = time`` is a constant state; the samples after
    ``t0`` are time events read from it (the MSL's Blocks.Math.Mean)."""
    path = tmp_path / "Sampled.mo"
    path.write_text(SAMPLED)
    result = springc.simulate(str(path), backend="python", engine="scipy", start=0.1,
                              stop=2.0, interval=0.1, error_control="off")
    t = np.asarray(result.time)
    # t0 = 0.1: ticks at 0.6, 1.1, 1.6 (each grid row on a tick holds the new count)
    expected = np.floor((t - 0.1) / 0.5 + 1e-9)
    assert np.array_equal(np.asarray(result["n"]), expected)
    assert np.allclose(result["t0"], 0.1, rtol=0, atol=1e-12)
