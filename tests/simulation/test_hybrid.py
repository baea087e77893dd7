"""Hybrid models against exact or independent references: the bouncing ball's
piecewise parabola, a time event hit exactly, the event output rows."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc
from hybrid_reference import wall_reference
from springc.errors import SimulationError

BALL = """
model BouncingBall
  parameter Real e = 0.8 "coefficient of restitution";
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

E, G = 0.8, 9.81


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def write(tmp_path: Path, text: str, name: str = "m.mo") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def ball_exact(t: np.ndarray, bounces: int) -> tuple[np.ndarray, np.ndarray, list[float]]:
    """h, v of the ball dropped from 1 m, and its impact times."""
    u = math.sqrt(2 * G)  # speed at the first impact
    impacts = [u / G]
    for k in range(1, bounces):
        impacts.append(impacts[-1] + 2 * E**k * u / G)
    h = 1 - G * t**2 / 2
    v = -G * t
    for k, tk in enumerate(impacts):
        after = t >= tk
        w = E ** (k + 1) * u
        h = np.where(after, w * (t - tk) - G * (t - tk) ** 2 / 2, h)
        v = np.where(after, w - G * (t - tk), v)
    return h, v, impacts


def test_bouncing_ball_matches_the_exact_parabolas(tmp_path: Path) -> None:
    _, _, impacts = ball_exact(np.zeros(1), 11)
    stop = impacts[9] + 0.5 * (impacts[10] - impacts[9])
    result = springc.simulate(write(tmp_path, BALL), rtol=1e-8, stop=stop, interval=1e-3)
    h, v, _ = ball_exact(result.time, 11)
    assert np.max(np.abs(result["h"] - h)) < 1e-6
    assert np.max(np.abs(result["v"] - v)) < 1e-6
    bounces = [e.time for e in result.events if e.x_right[1] != e.x_left[1]]
    assert len(bounces) == 10
    assert np.max(np.abs(np.array(bounces) - impacts[:10])) < 1e-9
    assert result.stats.state_events >= 10 and result.stats.time_events == 0


MORE = """
model Switched
  parameter Real t0 = 1.234;
  Real x(start = 0, fixed = true);
equation
  der(x) = if time >= t0 then 1 else 0;
end Switched;

model Counter
  Integer n(start = 0);
  Boolean high(start = false);
  discrete Real last(start = -1);
  Real y(start = 0, fixed = true);
equation
  der(y) = 1;
  when sample(0, 0.25) then
    n = pre(n) + 1;
    last = time;
  end when;
  when y > 0.6 then
    high = true;
  end when;
end Counter;

model Wall
  parameter Real m = 1;
  parameter Real k = 100;
  parameter Real kw = 1e4;
  parameter Real dw = 10;
  parameter Real xw = 0.05;
  Real x(start = 0, fixed = true);
  Real v(start = 2, fixed = true);
  Real f;
equation
  der(x) = v;
  m * der(v) = -k * x + f;
  f = if x > xw then -kw * (x - xw) - dw * v else 0;
end Wall;
"""


@pytest.fixture(scope="module")
def more(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("hybrid") / "more.mo"
    path.write_text(MORE)
    return str(path)


@pytest.mark.parametrize("solver", ["dop853", "rk45", "radau", "bdf", "lsoda"])
def test_a_time_event_is_hit_exactly(more: str, solver: str) -> None:
    result = springc.simulate(more, model_name="Switched", solver=solver, rtol=1e-8,
                              stop=3.0, interval=0.01)
    assert 1.234 in result.step_times
    assert [(e.kind, e.time) for e in result.events[1:]] == [("time", 1.234)]
    assert np.max(np.abs(result["x"] - np.maximum(0.0, result.time - 1.234))) < 1e-9
    assert (result.stats.state_events, result.stats.time_events) == (0, 1)


def test_discrete_integer_boolean_and_real_variables(more: str) -> None:
    result = springc.simulate(more, model_name="Counter", stop=2.0, interval=0.125)
    t = result.time
    # sample(0, 0.25) ticks at 0, 0.25, ..., 2.0: "the first event iteration occurs
    # after the initialization even if the start argument is identical to the start
    # time of the simulation" (3.7.5); a row shows the values after its time's event
    ticks = np.floor(t / 0.25 + 1e-9)
    assert np.array_equal(result["n"], ticks + 1)
    assert np.array_equal(result["last"], ticks * 0.25)
    assert np.array_equal(result["high"], (t > 0.6).astype(float))
    crossing = [e.time for e in result.events if e.kind == "state"]
    assert crossing == pytest.approx([0.6], abs=1e-11)


@pytest.mark.parametrize(("solver", "step"), [
    ("dop853", None), ("rk45", None), ("radau", None), ("bdf", None), ("lsoda", None),
    ("auto", None), ("rk4", 2.5e-4), ("verlet", 1e-5), ("symplectic-euler", 1e-5)])
def test_wall_contact_matches_an_independent_solve(more: str, solver: str,
                                                   step: float | None) -> None:
    grid, reference, crossings = wall_reference(2.0)
    result = springc.simulate(more, model_name="Wall", solver=solver, step=step, rtol=1e-8,
                              atol=1e-11, stop=2.0, interval=0.005)
    assert np.array_equal(result.time, grid)
    # verlet and symplectic Euler are first order with the velocity-dependent contact
    # force (measured 2.2e-6 and 2.4e-6 at this step)
    tolerance = 1e-6 if step is None or solver == "rk4" else 5e-6
    assert np.max(np.abs(result["x"] - reference[:, 0])) < tolerance
    assert crossings >= 8
    assert result.stats.state_events == crossings


ZENO = """
model Chatter
  Real x(start = 1, fixed = true);
equation
  der(x) = if x > 0 then -1 else 1;
end Chatter;
"""


def test_a_ball_coming_to_rest_stops_with_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(write(tmp_path, BALL), stop=10.0)
    error = info.value
    # the bounces accumulate at t* = t1 + 2 u / g * e / (1 - e) = 4.06370...
    assert error.message.startswith("chattering: 100 events in ")
    assert error.message.endswith("most of them of 'h <= 0'")
    last = float(error.message.split("up to time ")[1].split(",")[0])
    assert abs(last - (1 + 2 * E / (1 - E)) * math.sqrt(2 / G)) < 1e-4
    assert "minimum bounce velocity" in (error.hint or "")


def test_a_relation_flipping_at_every_step_stops(tmp_path: Path) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(write(tmp_path, ZENO), stop=3.0)
    assert info.value.message.endswith("up to time 1, most of them of 'x > 0'")


def test_event_rows_add_the_left_and_right_limits(more: str) -> None:
    plain = springc.simulate(more, model_name="Counter", stop=0.55, interval=0.275)
    rows = springc.simulate(more, model_name="Counter", stop=0.55, interval=0.275,
                            event_rows=True)
    assert list(plain.time) == [0.0, 0.275, 0.55]
    assert list(plain["n"]) == [1, 2, 3]  # the sample at t = 0 after the initialization
    assert list(rows.time) == [0.0, 0.25, 0.25, 0.275, 0.5, 0.5, 0.55]
    assert list(rows["n"]) == [1, 1, 2, 2, 2, 3, 3]
    assert list(rows["last"]) == [0, 0, 0.25, 0.25, 0.25, 0.5, 0.5]


def test_numba_backend_gives_the_python_backend_results(tmp_path: Path) -> None:
    path = write(tmp_path, BALL)
    python = springc.simulate(path, stop=2.0, interval=0.01, rtol=1e-8, backend="python")
    numba = springc.simulate(path, stop=2.0, interval=0.01, rtol=1e-8, backend="numba",
                             engine="scipy")  # the same loop: only the backend differs
    assert np.max(np.abs(python.values - numba.values)) < 1e-12
    assert [e.time for e in python.events] == [e.time for e in numba.events]


def test_the_compiled_engine_runs_a_model_with_events(tmp_path: Path) -> None:
    """(simulation/hybrid_compiled.py; more in test_events_compiled.py)"""
    compiled = springc.simulate(write(tmp_path, BALL), engine="compiled", stop=1.0)
    assert compiled.stats.engine == "compiled" and compiled.stats.state_events == 2
    auto = springc.simulate(write(tmp_path, BALL), engine="auto", backend="numba", stop=1.0)
    assert auto.stats.engine == "compiled" and auto.stats.state_events == 2
    scipy = springc.simulate(write(tmp_path, BALL), engine="scipy", backend="numba", stop=1.0)
    assert [e.cause for e in scipy.events] == [e.cause for e in auto.events]
    assert np.max(np.abs(np.array([e.time for e in scipy.events])
                         - [e.time for e in auto.events])) < 1e-9


def test_the_generated_module_runs_its_events_without_springc(tmp_path: Path) -> None:
    """The module's own functions, driven as module_api.HybridModule says: the first
    impact located on the zero-crossing function, then the event update."""
    import importlib.util

    import scipy.optimize

    model = springc.compile_model(write(tmp_path, BALL))
    target = tmp_path / "ball_module.py"
    target.write_text(model.source)
    spec = importlib.util.spec_from_file_location("ball_module", target)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    p = mod.parameters()
    z = mod.guesses(p)
    assert len(z) == mod.Z_SIZE
    x = mod.start(p)
    z[mod.Z_INITIAL] = 1.0
    x = mod.event_update(0.0, x, p, z)
    assert z[mod.Z_RELATIONS] == 0.0  # h <= 0 is false at h = 1

    def flight(t: float) -> np.ndarray:
        return np.array([1 - G * t**2 / 2, -G * t])

    impact = scipy.optimize.brentq(
        lambda t: mod.zero_crossings(t, flight(t), p, z)[0], 0.1, 1.0, xtol=1e-14)
    assert abs(impact - math.sqrt(2 / G)) < 1e-12
    after = mod.event_update(impact, flight(impact + 1e-13), p, z)
    assert after[1] == pytest.approx(E * G * impact, rel=1e-12)
    assert (z[mod.Z_RELATIONS], z[mod.Z_STATUS]) == (1.0, 0.0)
    assert mod.ZERO_CROSSINGS == ("h <= 0",) and mod.RELATION_OPS == ("<=",)


CLAUSES = """
model H
  Real x(start = 1, fixed = true);
  Boolean b(start = false);
  Integer n(start = 0);
  discrete Real t1(start = -1);
equation
  der(x) = -2 * x;
  when {x < 0.8, sample(0, 0.5)} then
    n = pre(n) + 1;
  elsewhen initial() then
    n = 0;
  end when;
  when change(n) then
    t1 = time;
  end when;
  when x < 0.7 then
    b = true;
    reinit(x, 0.9);
  end when;
end H;
"""


def test_clauses_see_what_earlier_clauses_assigned_at_the_same_event(tmp_path: Path) -> None:
    result = springc.simulate(write(tmp_path, CLAUSES), stop=1.0, interval=0.5,
                              rtol=1e-10, event_rows=True)
    t, n, t1 = result.time, result["n"], result["t1"]
    steps = [i for i in range(1, len(t)) if n[i] != n[i - 1]]
    assert len(steps) >= 4
    for i in steps:  # change(n) fires in the same event, after n's clause
        assert t1[i] == t[i]
    # x leaves 1 as exp(-2 t): the first crossing of 0.8 is at log(1.25) / 2
    assert t[steps[0]] == pytest.approx(math.log(1.25) / 2, abs=1e-9)
    assert set(result["b"][t > 0.3]) == {1.0}


ENDING = """
model Ending
  Real x(start = 0, fixed = true);
  discrete Real final_x(start = -1);
  Integer stops(start = 0);
equation
  der(x) = 1;
  when terminal() then
    final_x = x;
  end when;
  when x >= 0.75 then
    stops = pre(stops) + 1;
    terminate("x reached 0.75");
  end when;
end Ending;
"""


def test_terminate_ends_the_run_and_terminal_fires_at_the_end(tmp_path: Path) -> None:
    path = write(tmp_path, ENDING)
    ended = springc.simulate(path, stop=2.0, interval=0.5)
    assert list(ended.time[:2]) == [0.0, 0.5] and len(ended.time) == 3
    assert ended.time[2] == pytest.approx(0.75, abs=1e-9)
    assert ended["stops"][-1] == 1
    assert ended.stats.note == "terminate() at time 0.75: x reached 0.75"
    full = springc.simulate(path, stop=0.6, interval=0.2)
    assert list(full["final_x"]) == [-1, -1, -1, pytest.approx(0.6, abs=1e-12)]


INITIAL = """
model I
  Real x;
  Real v;
  Integer n(start = 2);
initial equation
  x = 1;
  v = 0;
equation
  der(x) = v;
  der(v) = -n * x;
  when x < 0 then
    n = pre(n) + 1;
  end when;
end I;
"""


def test_initial_equations_with_a_discrete_variable(tmp_path: Path) -> None:
    result = springc.simulate(write(tmp_path, INITIAL), stop=2.0, interval=0.01, rtol=1e-10)
    t = result.time
    tc = math.pi / (2 * math.sqrt(2))  # x = cos(sqrt(2) t) reaches 0
    exact = np.where(t < tc, np.cos(math.sqrt(2) * t),
                     -math.sqrt(2 / 3) * np.sin(math.sqrt(3) * (t - tc)))
    assert np.max(np.abs(result["x"] - exact)) < 1e-8
    assert np.array_equal(result["n"], np.where(t < tc, 2.0, 3.0))


EDGE = """
model E
  Real x(start = 0, fixed = true);
  Boolean b;
  Integer n(start = 0);
equation
  der(x) = 1;
  b = x > 0.5;
  when edge(b) then
    n = pre(n) + 1;
  end when;
end E;
"""


def test_edge_of_an_algebraic_boolean_fires_once(tmp_path: Path) -> None:
    result = springc.simulate(write(tmp_path, EDGE), stop=2.0, interval=0.25)
    assert list(result["n"]) == [0, 0, 0, 1, 1, 1, 1, 1, 1]
    assert list(result["b"]) == [0, 0, 0, 1, 1, 1, 1, 1, 1]


SAMPLES = """
model S
  Integer n(start = 0);
equation
  when sample(0, 0.1) then
    n = pre(n) + 1;
  end when;
end S;
"""


@pytest.mark.parametrize(("solver", "step"), [("auto", None), ("rk4", 0.05),
                                              ("verlet", 0.025)])
def test_samples_without_states_tick_at_every_multiple(tmp_path: Path, solver: str,
                                                       step: float | None) -> None:
    result = springc.simulate(write(tmp_path, SAMPLES), solver=solver, step=step, stop=1.0,
                              interval=0.25)
    assert list(result["n"]) == [1, 3, 6, 8, 11]  # 0, 0.1, ..., 1: 0 after initialization
    assert result.stats.time_events == 10
    assert [(e.kind, e.cause) for e in result.events[:2]] == [
        ("initial", "initial()"), ("initial", "after initialization")]


HOSTILE = r"""
model H
  Real x(start = 0, fixed = true);
  discrete Real 'a"b\n\')'(start = 0);
equation
  der(x) = 1;
  when x > 0.5 then
    'a"b\n\')' = time;
    terminate("done\"\n''' import os");
  end when;
end H;
"""


def test_hostile_names_and_messages_stay_data(tmp_path: Path) -> None:
    model = springc.compile_model(write(tmp_path, HOSTILE))
    assert "\n''' import os" not in model.source
    assert model.module.TERMINATE_MESSAGES == ("done\"\n''' import os",)  # type: ignore[attr-defined]
    assert model.module.DISCRETE == ("a\"b\n')",)  # type: ignore[attr-defined]
    result = springc.simulate(model, stop=1.0, interval=0.5)
    assert result.stats.note == "terminate() at time 0.5: done\"\\n''' import os"
    assert result["a\"b\n')"][-1] == pytest.approx(0.5, abs=1e-9)


BANG = """
model Bang
  Real x(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
  Real speed;
equation
  der(x) = v;
  der(v) = -10 * sign(x);
  speed = abs(v);
end Bang;
"""


def test_sign_and_abs_switch_at_events(tmp_path: Path) -> None:
    """x'' = -10 sign(x): parabolas joined where x = 0 (every 2/sqrt(5) s after the
    first quarter period 1/sqrt(5))."""
    result = springc.simulate(write(tmp_path, BANG), stop=3.0, interval=0.01, rtol=1e-10)
    tau, r = 1 / math.sqrt(5), math.sqrt(20)
    u = np.mod(result.time, 4 * tau)
    s2, s3 = u - tau, u - 3 * tau
    exact = np.where(u < tau, 1 - 5 * u**2,
                     np.where(u < 3 * tau, -r * s2 + 5 * s2**2, r * s3 - 5 * s3**2))
    assert np.max(np.abs(result["x"] - exact)) < 1e-8
    assert np.max(np.abs(result["speed"] - np.abs(result["v"]))) < 1e-12
    crossings = [e.time for e in result.events if e.cause in ("x > 0", "x < 0")]
    expected = [tau + 2 * tau * k for k in range(3)]
    assert np.max(np.abs(np.array(crossings) - expected)) < 1e-9


SAMPLED = """
model Sampled
  Real x(start = 0, fixed = true);
  discrete Real h(start = 0);
equation
  der(x) = 1;
  when sample(0, 0.001) then
    h = x;
  end when;
end Sampled;
"""


@pytest.mark.parametrize("event_rows", [False, True])
def test_events_are_counted_and_kept_only_as_the_output_needs(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, event_rows: bool) -> None:
    """1001 sample instants in [0, 1]: memory follows the output, so without
    event_rows only the first KEPT_EVENTS events are kept (the rest counted)."""
    from springc.simulation import events

    monkeypatch.setattr(events, "KEPT_EVENTS", 10)
    path = tmp_path / "sampled.mo"
    path.write_text(SAMPLED)
    result = springc.simulate(str(path), stop=1.0, interval=0.5, event_rows=event_rows)
    assert result.stats.time_events == 1000  # t = 0: the event after the initialization
    kept = [e for e in result.events if e.kind == "time"]
    assert len(result.events) == (1002 if event_rows else 10)
    assert result.events[0].kind == result.events[1].kind == "initial"
    assert abs(kept[-1].time - (1.0 if event_rows else 0.008)) < 1e-12
    assert len(result.time) == (3 + 2 * 1000 if event_rows else 3)
    assert abs(result["h"][-1] - 1.0) < 1e-9
