"""Hybrid models on the two engines: the bouncing ball (tests/simulation/test_events.py's
model, e = 0.8, ten and a half bounces, rtol 1e-8, 1 ms output interval), warm, in
process, with dop853, radau and rk4 (step 1 ms): the scipy engine (scipy's solvers or the
Python fixed-step loop, stepped from Python) against the compiled engine (the kernels of
springc.integrate between events, simulation/hybrid_compiled.py); the ratio, the events
and the time per event on each.

Run: ``PYTHONPATH=src python benchmarks/bench_hybrid.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time

import springc

BALL = """
model BouncingBall
  parameter Real e = 0.8;
  parameter Real g = 9.81;
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -g;
  when h <= 0 then
    reinit(v, -e*pre(v));
  end when;
end BouncingBall;
"""


def stop_time(bounces: int = 10, e: float = 0.8, g: float = 9.81) -> float:
    """Half-way between the 10th and the 11th impact of the ball dropped from 1 m."""
    u = math.sqrt(2 * g)
    impacts = [u / g]
    for k in range(1, bounces + 1):
        impacts.append(impacts[-1] + 2 * e**k * u / g)
    return impacts[bounces - 1] + 0.5 * (impacts[bounces] - impacts[bounces - 1])


def best(model: springc.CompiledModel, repeat: int, **options: object
         ) -> tuple[float, springc.SimulationResult]:
    """The fastest of ``repeat`` warm runs (one warm-up run first)."""
    result = springc.simulate(model, **options)  # type: ignore[arg-type]
    times = []
    for _ in range(repeat):
        began = time.perf_counter()
        result = springc.simulate(model, **options)  # type: ignore[arg-type]
        times.append(time.perf_counter() - began)
    return min(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    os.environ.setdefault("SPRINGC_CACHE_DIR", tempfile.mkdtemp(prefix="springc-bench-"))
    model = springc.load_model_from_string(BALL, backend="numba")
    common = {"rtol": 1e-8, "stop": stop_time(), "interval": 1e-3}
    print(f"bouncing ball, 0..{common['stop']:.4f} s, rtol 1e-8, warm, best of {args.repeat}")
    for solver, step in (("dop853", None), ("radau", None), ("rk4", 1e-3)):
        row = {}
        for engine in ("scipy", "compiled"):
            seconds, result = best(model, args.repeat, solver=solver, step=step,
                                   engine=engine, **common)
            events = result.stats.state_events + result.stats.time_events
            row[engine] = seconds
            print(f"  {solver:7s} {engine:8s} {seconds * 1e3:8.2f} ms  {result.stats.steps:5d} "
                  f"steps  {events} events  {seconds / events * 1e6:7.1f} us per event")
        print(f"  {solver:7s} compiled is {row['scipy'] / row['compiled']:.1f}x faster")


if __name__ == "__main__":
    main()
