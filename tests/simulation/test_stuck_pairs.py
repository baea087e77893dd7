"""Friction elements whose stuck configuration the event iteration cannot decide from
one relation at a time (the MSL's LossyGearDemo2, Rotational.HeatLosses).

1. Two brakes on one block, both stuck: the block's balance fixes only the sum of
   their path parameters (a statically indeterminate pair: the torn system has a
   zero row). The Newton correction takes the basic solution (the free unknown 0),
   one brake starts while the other holds the block, the starting one's path
   parameter then sits exactly on its breakaway force, and its relation keeps its
   value there (the relations' band) until the applied force exceeds both
   breakaway forces together. Closed form: the block stays until ``k t = F1 + F2``,
   then ``m a = k t - F1 - F2``.
2. A one-way clutch's start condition (``Rotational.Components.OneWayClutch``):
   sliding accelerates with ``sa - tau0`` while the breakaway is ``tau0_max``, so
   ``sa > tau0_max`` holds when locked and not once sliding; only
   ``pre(startForward) and sa > tau0`` keeps it, once ``pre(startForward)`` has
   become true in the event iteration while that relation still moves.
   Closed form: stuck until ``k t = tau0_max``, then ``m a = k t - tau0``.
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

ONE_WAY = '''\
model OneWay
  parameter Real m = 10, k = 1, tau0 = 1, tau0_max = 1.2;
  Real s(start = 0, fixed = true), v(start = 0, fixed = true);
  Real a, sa, f;
  Boolean startForward(start = false, fixed = true), locked;
  Boolean stuck(start = true, fixed = true);
equation
  der(s) = v;
  der(v) = a;
  m*a = k*time - f;
  startForward = pre(stuck) and (sa > tau0_max or pre(startForward) and sa > tau0);
  locked = pre(stuck) and not startForward;
  a = if locked then 0 else sa - tau0;
  f = if locked then sa else tau0;
  stuck = locked or v <= 0;
end OneWay;
'''


def _run(tmp_path: Path, name: str, text: str) -> SimulationResult:
    path = tmp_path / f"{name}.mo"
    path.write_text(text)
    return springc.simulate(str(path), backend="python", engine="scipy", stop=3.0,
                            interval=0.01, rtol=1e-10, atol=1e-12, error_control="off")


def test_two_stuck_brakes_hold_until_both_break_away(tmp_path: Path) -> None:
    result = _run(tmp_path, "TwoBrakes", TWO_BRAKES)
    t = np.asarray(result.time)
    t1 = 1.5  # k t1 = f1max + f2max
    v = np.where(t > t1, (t - t1) ** 2, 0.0)  # (k / 2m) (t - t1)^2
    s = np.where(t > t1, (t - t1) ** 3 / 3, 0.0)
    assert np.allclose(np.asarray(result["v"]), v, rtol=0, atol=1e-6)
    assert np.allclose(np.asarray(result["s"]), s, rtol=0, atol=1e-6)
    # while stuck, the brakes together hold the applied force; sliding, each its own
    stuck, sliding = t < t1 - 1e-3, t > t1 + 1e-3
    f1, f2 = np.asarray(result["f1"]), np.asarray(result["f2"])
    assert np.allclose((f1 + f2)[stuck], 2 * t[stuck], rtol=0, atol=1e-8)
    assert np.allclose(f1[sliding], 1.0) and np.allclose(f2[sliding], 2.0)


def test_one_way_clutch_start_is_kept_by_its_pre_hysteresis(tmp_path: Path) -> None:
    result = _run(tmp_path, "OneWay", ONE_WAY)
    t = np.asarray(result.time)
    t1 = 1.2  # k t1 = tau0_max; then 10 a = t - 1
    v = np.where(t > t1, ((t ** 2 - t1 ** 2) / 2 - (t - t1)) / 10, 0.0)
    assert np.allclose(np.asarray(result["v"]), v, rtol=0, atol=1e-6)
    f = np.asarray(result["f"])
    assert np.allclose(f[t > t1 + 1e-3], 1.0)
    assert np.allclose(f[t < t1 - 1e-3], t[t < t1 - 1e-3], rtol=0, atol=1e-8)
