"""Coulomb friction with the MSL's stuck/forward/backward state machine (the pattern of
``Rotational.Interfaces.PartialFriction``: a path parameter ``sa``, ``pre(mode)``,
``startForward`` with ``pre(startForward)`` hysteresis, ``locked``): a mixed system of
Real and Boolean unknowns that the event iteration must settle (Modelica 3.6, 8.6:
``pre(v) := v`` after each pass until no discrete variable changes).

A light block (mass 0.1) under F = A sin(t) on a rough floor (sliding friction f0,
static f0_max): its velocity and position against the closed form of each stick and
slip phase (the phase ends found by a root finder on the closed-form velocity). The
block is light so that the path parameter of the sliding configuration lies beyond
+-f0_max when the block stops: the relations of the configuration before the event
point to the other direction, and only an iteration that updates ``pre(mode)`` and
settles the relations finds the consistent one (stuck, or sliding back)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import springc

MODEL = '''\
model StickSlip
  parameter Real m = 0.1;
  parameter Real A = 2;
  parameter Real f0 = 1.2 "sliding friction";
  parameter Real f0_max = 1.5 "static friction";
  constant Integer Forward = 1, Stuck = 0, Backward = -1;
  Real s(start = 0, fixed = true);
  Real v(start = 0, fixed = true);
  Real a;
  Real f "friction force";
  Real sa "path parameter";
  Boolean startForward(start = false, fixed = true);
  Boolean startBackward(start = false, fixed = true);
  Boolean locked;
  Integer mode(start = Stuck, fixed = true);
equation
  der(s) = v;
  der(v) = a;
  m*a = A*sin(time) - f;
  startForward = pre(mode) == Stuck and (sa > f0_max or pre(startForward) and sa > f0)
    or initial() and v > 0;
  startBackward = pre(mode) == Stuck and (sa < -f0_max or pre(startBackward) and sa < -f0)
    or initial() and v < 0;
  locked = not (pre(mode) == Forward or startForward or pre(mode) == Backward
    or startBackward);
  a = if locked then 0 else if startForward then sa - f0_max
    else if startBackward then sa + f0_max
    else if pre(mode) == Forward then sa - f0_max
    else if pre(mode) == Backward then sa + f0_max
    else sa - sign(v)*f0_max;
  f = if locked then sa else if startForward then f0 else if startBackward then -f0
    else if pre(mode) == Forward then f0 else if pre(mode) == Backward then -f0
    else sign(v)*f0;
  mode = if (pre(mode) == Forward or startForward) and v > 0 then Forward
    else if (pre(mode) == Backward or startBackward) and v < 0 then Backward
    else Stuck;
end StickSlip;
'''


def closed_form(t: np.ndarray, m: float, A: float, f0: float, f0_max: float
                ) -> tuple[np.ndarray, np.ndarray, list[float]]:
    """v and s at ``t``, phase by phase, and the times the phases end."""
    v, s = np.zeros_like(t), np.zeros_like(t)
    t0, s0, d, ends = 0.0, 0.0, 0, []
    stop = float(t[-1])
    while t0 < stop:
        if d == 0:  # stuck until |F| reaches f0_max
            def g(tt: float) -> float:
                return abs(A * np.sin(tt)) - f0_max
            grid = np.linspace(t0, stop, 4001)[1:]
            k = next((i for i in range(len(grid)) if g(grid[i]) > 0), None)
            t1 = stop if k is None else brentq(g, grid[k - 1], grid[k], xtol=1e-14)
            s[(t >= t0) & (t <= t1)] = s0
            d = 0 if k is None else (1 if np.sin(t1) > 0 else -1)
        else:  # sliding in direction d from rest at t0: m dv/dt = A sin(t) - d f0
            def vel(tt: float, t0: float = t0, d: int = d) -> float:
                return (A * (np.cos(t0) - np.cos(tt)) - d * f0 * (tt - t0)) / m

            def pos(tt: np.ndarray, t0: float = t0, d: int = d, s0: float = s0
                    ) -> np.ndarray:
                return s0 + (A * (np.cos(t0) * (tt - t0) - (np.sin(tt) - np.sin(t0)))
                             - d * f0 * (tt - t0) ** 2 / 2) / m
            grid = np.linspace(t0, stop, 4001)[1:]
            k = next((i for i in range(1, len(grid)) if d * vel(grid[i]) <= 0), None)
            t1 = stop if k is None else brentq(vel, grid[k - 1], grid[k], xtol=1e-14)
            inside = (t > t0) & (t <= t1)
            v[inside] = [vel(tt) for tt in t[inside]]
            s[inside] = pos(t[inside])
            s0 = float(pos(np.array(t1)))
            force = A * np.sin(t1)
            d = 0 if abs(force) < f0_max else (1 if force > 0 else -1)
        ends.append(float(t1))
        t0 = t1
    return v, s, ends


@pytest.mark.parametrize(("f0", "f0_max", "expected_ends"), [
    # stick, slip forward, stick, slip backward, stick, slip forward
    (1.2, 1.5, [0.848062, 3.507056, 3.989655, 6.648648, 7.131247, 9.790241, 10.0]),
    # stick, then the velocity reverses without sticking (Forward -> Stuck ->
    # startBackward within one event iteration)
    (0.9, 1.3, [0.707584, 3.942738, 7.065436, 10.0]),
])
def test_stick_slip_matches_the_closed_form(tmp_path: Path, f0: float, f0_max: float,
                                            expected_ends: list[float]) -> None:
    path = tmp_path / "StickSlip.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=10.0,
                              interval=0.01, rtol=1e-10, atol=1e-12, error_control="off",
                              parameters={"f0": f0, "f0_max": f0_max})
    t = np.asarray(result.time)
    v, s, ends = closed_form(t, 0.1, 2.0, f0, f0_max)
    assert np.allclose(ends, expected_ends, rtol=0, atol=1e-6)
    # away from the phase ends (an output row within 1e-3 of one may hold either side)
    away = np.min(np.abs(t[:, None] - np.array(ends)[None, :]), axis=1) > 1e-3
    assert np.allclose(np.asarray(result["v"])[away], v[away], rtol=0, atol=1e-6)
    assert np.allclose(np.asarray(result["s"])[away], s[away], rtol=0, atol=1e-6)
    # the mode: stuck (0) in the stick phases, +-1 while sliding
    mode = np.asarray(result["mode"])[away]
    assert np.array_equal(mode, np.sign(np.round(v[away], 12)))
