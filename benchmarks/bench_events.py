"""Hybrid models with events against the same physics without events.

Two scenes, each written twice:

- the bouncing ball (drop from 1 m, e = 0.8, to t = 3.5 s): ``when h <= 0 then
  reinit(v, -e*pre(v))`` against a smooth penalty floor (stiffness 1e6, damping
  chosen for the same restitution, everything inside noEvent: no events);
- the wall contact (a mass on a spring hitting a damped elastic wall, 2 s): the
  force written with an if-expression on a relation (state events at every contact
  begin and end) against the same force inside noEvent (the integrator steps over
  the switch by step-size control).

For each: the solver, steps, right-hand-side evaluations, state and time events, wall
time (best of --repeat warm runs, python backend, scipy engine) and the time per event
(the hybrid run's wall time over its number of events). Accuracy is printed too:
the ball's first impact time against the exact sqrt(2/g), the wall's final position
against the event-located run at rtol 1e-10.

Run: ``PYTHONPATH=src python benchmarks/bench_events.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import springc

MODELS = """
model Ball
  parameter Real e = 0.8;
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81;
  when h <= 0 then
    reinit(v, -e*pre(v));
  end when;
end Ball;

model PenaltyBall
  parameter Real k = 1e6;
  parameter Real d = 2 * 0.0708 * sqrt(k) "damping ratio 0.0708: restitution 0.8";
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81 + noEvent(if h < 0 then -k * h - d * v else 0);
end PenaltyBall;

model Wall
  parameter Real k = 100, kw = 1e4, dw = 10, xw = 0.05;
  Real x(start = 0, fixed = true);
  Real v(start = 2, fixed = true);
equation
  der(x) = v;
  der(v) = -k * x + (if x > xw then -kw * (x - xw) - dw * v else 0);
end Wall;

model SmoothWall
  parameter Real k = 100, kw = 1e4, dw = 10, xw = 0.05;
  Real x(start = 0, fixed = true);
  Real v(start = 2, fixed = true);
equation
  der(x) = v;
  der(v) = -k * x + noEvent(if x > xw then -kw * (x - xw) - dw * v else 0);
end SmoothWall;
"""

CASES = [("Ball", "PenaltyBall", 3.5), ("Wall", "SmoothWall", 2.0)]


def best(path: str, name: str, stop: float, repeat: int, rtol: float
         ) -> tuple[float, Any]:
    model = springc.compile_model(path, name, backend="python")  # the scipy engine
    springc.simulate(model, stop=stop, rtol=rtol)  # warm
    times, result = [], None
    for _ in range(repeat):
        began = time.perf_counter()
        result = springc.simulate(model, stop=stop, rtol=rtol, interval=stop / 500)
        times.append(time.perf_counter() - began)
    assert result is not None
    return min(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--rtol", type=float, default=1e-6)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        path = str(Path(folder) / "events.mo")
        Path(path).write_text(MODELS)
        print(f"{'model':<12} {'steps':>6} {'RHS':>7} {'state ev':>9} {'time ev':>8} "
              f"{'wall s':>8} {'per event':>10}  accuracy")
        for hybrid, smooth, stop in CASES:
            t_h, r_h = best(path, hybrid, stop, args.repeat, args.rtol)
            t_s, r_s = best(path, smooth, stop, args.repeat, args.rtol)
            events = r_h.stats.state_events + r_h.stats.time_events
            per = t_h / events if events else math.nan
            if hybrid == "Ball":
                first = next(e.time for e in r_h.events if e.kind == "state")
                accuracy = f"first impact {first - math.sqrt(2 / 9.81):+.1e} s from exact"
                smooth_acc = ""
            else:
                reference = springc.simulate(springc.compile_model(path, hybrid), stop=stop,
                                             rtol=1e-10, interval=stop / 500)
                accuracy = f"max |x - ref| {np.max(np.abs(r_h['x'] - reference['x'])):.1e}"
                smooth_acc = (f"max |x - ref| "
                              f"{np.max(np.abs(r_s['x'] - reference['x'])):.1e}")
            for name, r, t, extra, acc in ((hybrid, r_h, t_h, f"{per * 1e3:8.3f} ms", accuracy),
                                           (smooth, r_s, t_s, "", smooth_acc)):
                print(f"{name:<12} {r.stats.steps:>6} {r.stats.rhs_evaluations:>7} "
                      f"{r.stats.state_events:>9} {r.stats.time_events:>8} {t:>8.3f} "
                      f"{extra:>10}  {acc}")


if __name__ == "__main__":
    main()
