"""The event-generating built-ins of Modelica 3.6, 3.7.2 (``floor``, ``ceil``,
``integer``, ``div``, ``mod``, ``rem``): outside ``noEvent`` they keep their value
from the last event and switch at events (time events for arguments affine in time,
state events otherwise), against closed forms."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence

import numpy as np
import pytest

import springc


def simulate(text: str, stop: float, solver: str = "dop853", **options: object
             ) -> springc.SimulationResult:
    compiled = springc.load_model_from_string(text, cache=False)
    return springc.simulate(compiled, stop=stop, interval=stop / 200, rtol=1e-10,
                            atol=1e-12, solver=solver, **options)  # type: ignore[arg-type]


def integral(f: Callable[[float], float], breaks: Sequence[float],
             t: np.ndarray) -> np.ndarray:
    """The integral from 0 to each ``t`` of ``f``, linear between ``breaks``
    (exact: the midpoint rule on every linear piece)."""
    out = np.empty(len(t))
    for i, end in enumerate(t):
        points = [0.0, *[b for b in sorted(breaks) if 0.0 < b < end], float(end)]
        out[i] = sum((b - a) * f(0.5 * (a + b)) for a, b in itertools.pairwise(points))
    return out


SAWTOOTH = """
model Sawtooth
  Real x(start = 0, fixed = true);
equation
  der(x) = mod(time, 0.3);
end Sawtooth;
"""


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_mod_of_time_switches_at_time_events(solver: str) -> None:
    options = {"step": 0.005} if solver == "rk4" else {}
    r = simulate(SAWTOOTH, 1.0, solver, **options)
    wraps = [0.3, 0.6, 0.9]
    # x(t) = n T^2 / 2 + s^2 / 2, n = floor(t / T), s = t - n T
    n = np.floor(r.time / 0.3 + 1e-12)
    s = r.time - 0.3 * n
    assert np.max(np.abs(r["x"] - (n * 0.045 + 0.5 * s * s))) < 1e-8
    events = [e for e in r.events if e.kind != "initial"]
    assert [e.kind for e in events] == ["time"] * 3
    assert (r.stats.state_events, r.stats.time_events) == (0, 3)
    assert np.max(np.abs(np.array([e.time for e in events]) - wraps)) < 1e-12
    assert all(e.time in r.step_times for e in events)


SHIFTED = """
model Shifted "the Trapezoid's period clock: mod(time - t0, T), T and t0 parameters"
  parameter Real t0 = 0.15;
  parameter Real T = 0.25;
  Real x(start = 0, fixed = true);
  Real k;
equation
  k = div(time - t0, T) + 10 * ceil((time - t0) / T) + 100 * integer(time / T);
  der(x) = rem(time - t0, T);
end Shifted;
"""


def test_div_rem_ceil_integer_of_time() -> None:
    r = simulate(SHIFTED, 1.0)
    t0, period = 0.15, 0.25
    crossings = [t0 + period * j for j in range(4)] + [period * j for j in range(1, 5)]

    def rem(t: float) -> float:
        return math.fmod(t - t0, period)

    assert np.max(np.abs(r["x"] - integral(rem, crossings, r.time))) < 1e-8
    k = [math.trunc((t - t0) / period) + 10 * math.ceil((t - t0) / period)
         + 100 * math.floor(t / period) for t in r.time]
    near = np.min(np.abs(r.time[:, None] - np.array(crossings)[None, :]), axis=1) < 1e-9
    assert np.array_equal(r["k"][~near], np.array(k, dtype=float)[~near])
    events = [e for e in r.events if e.kind != "initial"]
    # every crossing in (0, 1] (1.0 is the stop time), one time event each, hit to
    # rounding and in the step sequence
    assert np.max(np.abs(np.array([e.time for e in events]) - sorted(crossings))) < 1e-12
    assert [e.kind for e in events] == ["time"] * 8
    assert all(e.time in r.step_times for e in events)


SINE = """
model Sine "floor of a state that rises and falls: x = sin(time)"
  Real x(start = 0, fixed = true);
  Real y(start = 0, fixed = true);
equation
  der(x) = cos(time);
  der(y) = floor(1.5 * x);
end Sine;
"""


def test_floor_of_a_state_switches_at_state_events() -> None:
    r = simulate(SINE, 6.0)
    a = math.asin(2 / 3)
    crossings = [a, math.pi - a, math.pi, math.pi + a, 2 * math.pi - a]

    def floor(t: float) -> float:
        return math.floor(1.5 * math.sin(t))

    assert np.max(np.abs(r["y"] - integral(floor, crossings, r.time))) < 1e-8
    events = [e for e in r.events if e.kind != "initial"]
    assert [e.kind for e in events] == ["state"] * 5
    up, down = "floor(1.5 * x) increases", "floor(1.5 * x) decreases"
    assert [e.cause for e in events] == [up, down, down, down, up]
    assert np.max(np.abs(np.array([e.time for e in events]) - crossings)) < 1e-9


RAMP = """
model Ramp "x = time - 1.3: ceil, integer, div, mod and rem of a state"
  Real x(start = -1.3, fixed = true);
  Real c(start = 0, fixed = true);
  Real i(start = 0, fixed = true);
  Real d(start = 0, fixed = true);
  Real m(start = 0, fixed = true);
  Real r(start = 0, fixed = true);
equation
  der(x) = 1;
  der(c) = ceil(x);
  der(i) = integer(2 * x);
  der(d) = div(x, 0.4);
  der(m) = mod(x, 0.4);
  der(r) = rem(x, 0.4);
end Ramp;
"""


def test_ceil_integer_div_mod_rem_of_a_state() -> None:
    r = simulate(RAMP, 3.0)
    t = r.time
    breaks = sorted({1.3 + 0.5 * j for j in range(-3, 4)} | {1.3 + 0.4 * j for j in range(-4, 5)}
                    | {1.3 + j for j in range(-2, 3)})
    funcs: dict[str, Callable[[float], float]] = {
        "c": lambda s: math.ceil(s - 1.3),
        "i": lambda s: math.floor(2 * (s - 1.3)),
        "d": lambda s: math.trunc((s - 1.3) / 0.4),
        "m": lambda s: (s - 1.3) - math.floor((s - 1.3) / 0.4) * 0.4,
        "r": lambda s: math.fmod(s - 1.3, 0.4),
    }
    for name, f in funcs.items():
        assert np.max(np.abs(r[name] - integral(f, breaks, t))) < 1e-8, name
    assert r.stats.time_events == 0
    located = [e.time for e in r.events if e.kind == "state"]
    assert min(np.min(np.abs(np.array(breaks) - te)) for te in located) < 1e-9
    assert max(np.min(np.abs(np.array(breaks) - te)) for te in located) < 1e-9


QUIET = """
model Quiet
  parameter Integer n = div(7, 2) + integer(2.5) + mod(7, 3);
  Real x(start = 0, fixed = true);
  Real y(start = 0, fixed = true);
equation
  der(x) = cos(time);
  der(y) = noEvent(floor(1.5 * x)) + n;
end Quiet;
"""


def test_no_events_inside_noEvent_and_in_parameter_expressions() -> None:
    r = simulate(QUIET, 6.0)
    assert [e.kind for e in r.events] in ([], ["initial"])
    assert (r.stats.state_events, r.stats.time_events) == (0, 0)
    assert r.parameters["n"] == 3 + 2 + 1


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_the_compiled_engine_switches_the_same_floors(solver: str) -> None:
    """numba-generated module, compiled loop: the same events and values as scipy's."""
    options = {"step": 0.03} if solver == "rk4" else {}
    runs = []
    for backend, engine in (("numba", "compiled"), ("python", "scipy")):
        compiled = springc.load_model_from_string(SINE, cache=False, backend=backend)
        runs.append(springc.simulate(compiled, stop=6.0, interval=0.03, rtol=1e-10,
                                     atol=1e-12, solver=solver, engine=engine,
                                     **options))  # type: ignore[arg-type]
    fast, slow = runs
    assert fast.stats.engine == "compiled" and slow.stats.engine == "scipy"
    assert [(e.kind, e.cause) for e in fast.events] == [(e.kind, e.cause) for e in slow.events]
    assert np.max(np.abs(np.array([e.time for e in fast.events])
                         - [e.time for e in slow.events])) < 1e-9
    assert np.max(np.abs(fast.values - slow.values)) < 1e-9


COUNTER = """
model Counter "a when-condition on mod(time, 0.4): n counts its rising edges"
  discrete Integer n(start = 0);
  discrete Real last(start = -1);
equation
  when mod(time, 0.4) >= 0.1 then
    n = pre(n) + 1;
    last = time;
  end when;
end Counter;
"""


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_mod_in_a_when_condition(solver: str) -> None:
    """No states: the relation on the held mod is watched at every output time."""
    r = simulate(COUNTER, 2.0, solver, **({"step": 0.01} if solver == "rk4" else {}))
    # rising edges at 0.1, 0.5, ..., 1.7 (the wrap at each 0.4 k makes it false again)
    assert r["n"][-1] == 5
    assert abs(r["last"][-1] - 1.7) < 1e-9
    wraps = [e.time for e in r.events if e.kind == "time"]
    assert np.max(np.abs(np.array(wraps) - [0.4, 0.8, 1.2, 1.6, 2.0])) < 1e-12
    edges = [e.time for e in r.events if e.kind == "state"]
    assert np.max(np.abs(np.array(edges) - (0.1 + 0.4 * np.arange(5)))) < 1e-9
