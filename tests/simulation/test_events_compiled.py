"""Hybrid models on the compiled engine (springc.integrate's kernels with the generated
zero_crossings; simulation/hybrid_compiled.py) against exact references (the ball's of
test_hybrid.py) and against the scipy engine: the bouncing ball, a time event, sample
clocks, a relation in an if-expression, terminate(), chattering, the step limit, the
event rows, chunked runs and the engine choice."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from simulation.test_hybrid import BALL, E, G, ball_exact
from springc.cli import main
from springc.errors import SimulationError, UsageError
from springc.pipeline import CompiledModel
from springc.simulation import SimulationOptions, simulate_model

SWITCH = """
model Switch "a force switched on at t = 1.234"
  Real x(start = 0, fixed = true);
  Real v(start = 0, fixed = true);
  Real f;
equation
  der(x) = v;
  der(v) = f;
  f = if time >= 1.234 then 1 else 0;
end Switch;
"""

CLOCK = """
model Clock "n counts the samples 0.5, 0.75, ...; x integrates n"
  discrete Integer n(start = 0);
  Real x(start = 0, fixed = true);
equation
  der(x) = n;
  when sample(0.5, 0.25) then
    n = pre(n) + 1;
  end when;
end Clock;
"""

RELAY = """
model Relay "a unit force towards x = 0, switched by the relation x > 0"
  Real x(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(x) = v;
  der(v) = if x > 0 then -1 else 1;
end Relay;
"""

STOP = """
model StopBall
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81;
  when h <= 0 then
    terminate("the ball hit the floor");
  end when;
end StopBall;
"""

TENTHS = """
model Tenths "n counts sample(0, 0.1): the sample times 0.1 * k are 0.30000000000000004..."
  discrete Integer n(start = 0);
  Real x(start = 0, fixed = true);
equation
  der(x) = n;
  when sample(0, 0.1) then
    n = pre(n) + 1;
  end when;
end Tenths;
"""

BANG = """
model Bang "x'' = -10 sign(x): parabolas joined where x = 0"
  Real x(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
  Real speed;
equation
  der(x) = v;
  der(v) = -10 * sign(x);
  speed = abs(v);
end Bang;
"""

TEXTS = {"ball": BALL, "switch": SWITCH, "clock": CLOCK, "relay": RELAY, "stop": STOP,
         "tenths": TENTHS, "bang": BANG}
STEP = {"dop853": None, "rk45": None, "radau": None, "bdf": None, "rk4": 1e-3,
        "verlet": 1e-3}  # solver -> step


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def models(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, CompiledModel]]:
    """Every model compiled once with the numba backend (into the session's cache)."""
    mp = pytest.MonkeyPatch()
    mp.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
    try:
        yield {name: springc.load_model_from_string(text, backend="numba")
               for name, text in TEXTS.items()}
    finally:
        mp.undo()


def both(model: CompiledModel, solver: str, **options: object
         ) -> tuple[springc.SimulationResult, springc.SimulationResult]:
    """The run on the scipy engine and on the compiled one."""
    runs = tuple(springc.simulate(model, solver=solver, step=STEP[solver], engine=engine,
                                  **options)  # type: ignore[arg-type]
                 for engine in ("scipy", "compiled"))
    assert runs[1].stats.engine == "compiled" and runs[0].stats.engine == "scipy"
    return runs[0], runs[1]


def kinds(result: springc.SimulationResult) -> list[tuple[str, str]]:
    return [(e.kind, e.cause) for e in result.events]


@pytest.mark.parametrize("solver", sorted(STEP))  # all exact on parabolas
def test_bouncing_ball_matches_the_parabolas_and_the_scipy_engine(
        models: dict[str, CompiledModel], solver: str) -> None:
    _, _, impacts = ball_exact(np.zeros(1), 11)
    stop = impacts[9] + 0.5 * (impacts[10] - impacts[9])
    scipy, compiled = both(models["ball"], solver, rtol=1e-8, stop=stop, interval=1e-3)
    h, v, _ = ball_exact(compiled.time, 11)
    assert np.max(np.abs(compiled["h"] - h)) < 1e-6
    assert np.max(np.abs(compiled["v"] - v)) < 1e-6
    bounces = [e.time for e in compiled.events if e.x_right[1] != e.x_left[1]]
    assert len(bounces) == 10
    # bdf's impacts are 4.8e-9 off on both engines at rtol 1e-8 (the method's accuracy)
    assert np.max(np.abs(np.array(bounces) - impacts[:10])) < (1e-8 if solver == "bdf"
                                                                else 1e-9)
    assert np.max(np.abs(np.array(bounces) - [e.time for e in scipy.events
                                              if e.x_right[1] != e.x_left[1]])) < 1e-9
    # each bounce: h <= 0 becomes true (the reinit), then false just after
    assert kinds(compiled) == kinds(scipy) == [("initial", "initial()")] + 20 * [
        ("state", "h <= 0")]
    assert (compiled.stats.state_events, compiled.stats.time_events) == (20, 0)
    assert (scipy.stats.state_events, scipy.stats.time_events) == (20, 0)
    assert np.max(np.abs(compiled.values - scipy.values)) < 1e-9


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_a_time_event_is_hit_exactly(models: dict[str, CompiledModel], solver: str) -> None:
    scipy, compiled = both(models["switch"], solver, stop=3.0, interval=0.01)
    events = [e for e in compiled.events if e.kind == "time"]
    assert [e.time for e in events] == [1.234]
    assert 1.234 in compiled.step_times
    assert events[0].z_left[events[0].z_left.size - 1] == 0.0
    # x = (t - 1.234)^2 / 2 after the switch, 0 before: every method here is exact on it
    exact = np.where(compiled.time >= 1.234, 0.5 * (compiled.time - 1.234) ** 2, 0.0)
    assert np.max(np.abs(compiled["x"] - exact)) < 1e-12
    assert kinds(compiled) == kinds(scipy)
    assert (compiled.stats.state_events, compiled.stats.time_events) == (0, 1)
    assert (scipy.stats.state_events, scipy.stats.time_events) == (0, 1)


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_sample_clock_counts_the_same_events(models: dict[str, CompiledModel], solver: str
                                             ) -> None:
    scipy, compiled = both(models["clock"], solver, stop=4.0, interval=0.01)
    samples = 0.5 + 0.25 * np.arange(15)  # 0.5 ... 4.0 (one at the stop time too)
    assert [e.time for e in compiled.events if e.kind == "time"] == samples.tolist()
    assert (compiled.stats.state_events, compiled.stats.time_events) == (0, 15)
    assert kinds(compiled) == kinds(scipy)
    np.testing.assert_array_equal(compiled["n"], scipy["n"])
    assert compiled["n"][-1] == 15  # the row at the stop time is after its event
    # x(4) = sum over the intervals of 0.25 * n = 0.25 * (1 + ... + 14)
    assert abs(compiled["x"][-1] - 26.25) < 1e-12


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_relation_in_an_if_expression(models: dict[str, CompiledModel], solver: str) -> None:
    scipy, compiled = both(models["relay"], solver, rtol=1e-10, stop=4.0, interval=0.01)
    assert kinds(compiled) == kinds(scipy) == [("initial", "initial()"), ("state", "x > 0")]
    crossing = math.sqrt(2.0)  # x = 1 - t^2 / 2
    assert abs(compiled.events[1].time - crossing) < 1e-9
    s = compiled.time - crossing
    exact = np.where(s < 0, 1 - compiled.time ** 2 / 2, -crossing * s + s ** 2 / 2)
    assert np.max(np.abs(compiled["x"] - exact)) < 1e-9
    assert np.max(np.abs(compiled.values - scipy.values)) < 1e-8


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_terminate_ends_the_run_at_its_time(models: dict[str, CompiledModel], solver: str
                                            ) -> None:
    scipy, compiled = both(models["stop"], solver, rtol=1e-8, stop=2.0, interval=0.01)
    hit = math.sqrt(2 / 9.81)
    for result in (scipy, compiled):  # the last row is the one at terminate()
        assert abs(result.time[-1] - hit) < 1e-9
        assert result.time[-2] == 0.45
        assert abs(result["h"][-1]) < 1e-9
        assert result.stats.note == "terminate() at time 0.451523641: the ball hit the floor"


def test_chattering_stops_with_the_scipy_engine_s_message(models: dict[str, CompiledModel]
                                                          ) -> None:
    with pytest.raises(SimulationError) as caught:
        springc.simulate(models["ball"], solver="dop853", engine="compiled", rtol=1e-8,
                         stop=5.0)
    error = caught.value
    assert error.message.startswith("chattering: 100 events in ")
    assert error.message.endswith("most of them of 'h <= 0'")
    # the bounces accumulate at t* = t1 + 2 u / g * e / (1 - e) = 4.06370...
    last = float(error.message.split("up to time ")[1].split(",")[0])
    assert abs(last - (1 + 2 * E / (1 - E)) * math.sqrt(2 / G)) < 1e-4
    assert "minimum bounce velocity" in (error.hint or "")


def test_step_limit(models: dict[str, CompiledModel]) -> None:
    with pytest.raises(SimulationError) as caught:
        springc.simulate(models["ball"], solver="dop853", engine="compiled", rtol=1e-8,
                         stop=3.0, max_steps=20)
    assert "20 steps of dop853 reached the step limit (--max-steps 20)" in str(caught.value)
    # the whole run to 1.76 s takes 21 steps on both engines: a limit of 22 is enough
    scipy, compiled = both(models["ball"], "dop853", rtol=1e-8, stop=1.76, max_steps=22)
    assert compiled.stats.steps == scipy.stats.steps == 21


def test_event_rows_are_the_same_on_both_engines(models: dict[str, CompiledModel]) -> None:
    runs = [simulate_model(models["ball"], SimulationOptions(
        stop=1.5, interval=0.1, rtol=1e-8, engine=engine, event_rows=True))
        for engine in ("scipy", "compiled")]
    scipy, compiled = runs
    assert compiled.stats.engine == "compiled"
    assert len(compiled.time) == len(scipy.time) == 16 + 4 * 2  # 2 bounces, 2 rows each
    assert np.max(np.abs(compiled.time - scipy.time)) < 1e-9
    assert np.max(np.abs(compiled.values - scipy.values)) < 1e-8
    first = int(np.flatnonzero(np.diff(compiled.time) == 0)[0])
    # left limit, then right limit: v jumps from -u to e * u at the first impact
    u = math.sqrt(2 * G)
    assert abs(compiled["v"][first] + u) < 1e-8 and abs(compiled["v"][first + 1] - E * u) < 1e-8


def test_auto_engine_chooses_compiled_for_numba_hybrid_models(
        models: dict[str, CompiledModel], tmp_path: Path) -> None:
    result = springc.simulate(models["ball"], stop=1.0)  # solver auto, engine auto
    assert (result.stats.solver, result.stats.engine) == ("dop853", "compiled")
    assert result.stats.reason == "a hybrid model: dop853 with event location"
    assert result.stats.engine_reason == ("dop853 ran in the compiled loop (numba, no Python "
                                          "per step)")
    assert springc.load_model_from_string(BALL).module.BACKEND == "numba"  # the default
    python = springc.load_model_from_string(BALL, backend="python")  # scipy's loop
    assert springc.simulate(python, stop=1.0).stats.engine == "scipy"
    with pytest.raises(UsageError, match="engine compiled: the lsoda solver has no "
                                         "compiled loop"):
        springc.simulate(models["ball"], solver="lsoda", engine="compiled")
    with pytest.raises(UsageError, match="engine compiled runs the numba backend's "
                                         "functions, not backend python"):
        springc.simulate(python, engine="compiled")
    path = tmp_path / "ball.mo"
    path.write_text(BALL)
    lines = []
    for engine in ("scipy", "compiled"):
        out = CliRunner().invoke(main, ["simulate", str(path), "--backend", "numba",
                                        "--solver", "rk4", "--step", "0.001", "--stop", "1.5",
                                        "--engine", engine, "--error-control", "off", "-v"])
        assert out.exit_code == 0, out.output
        lines.append(out.output.splitlines()[-1])
    # the same steps (1500 and one more after each event) and events on both engines
    assert lines[0].startswith("BouncingBall: rk4 (scipy), 1504 steps, ")
    assert lines[1].startswith("BouncingBall: rk4 (compiled), 1504 steps, ")
    assert all(line.endswith(", 4 state and 0 time events") for line in lines)


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_chunked_runs_equal_a_single_run(models: dict[str, CompiledModel], solver: str,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """Stretches cut into chunks (for the limits) give the same run: dop853 goes on with
    its next step size, a fixed-step chunk ends on an output time (one ending on a time
    event is extended, so that the event is one)."""
    import springc.simulation.hybrid_compiled as glue

    options = {"solver": solver, "step": STEP[solver], "engine": "compiled", "stop": 1.0,
               "interval": 0.01}
    whole = springc.simulate(models["clock"], **options)  # type: ignore[arg-type]
    monkeypatch.setattr(glue, "ADAPTIVE_CHUNK", 3)
    monkeypatch.setattr(glue, "FIXED_CHUNK", 20)  # two output intervals of 10 steps
    chunked = springc.simulate(models["clock"], **options)  # type: ignore[arg-type]
    assert kinds(chunked) == kinds(whole) == [
        ("initial", "initial()"), ("initial", "after initialization"),
        ("time", "time = 0.5"), ("time", "time = 0.75"), ("time", "time = 1")]
    assert chunked.stats.steps == whole.stats.steps
    np.testing.assert_array_equal(chunked.values, whole.values)
    assert abs(chunked["x"][-1] - 0.75) < 1e-12  # 0.25 * 1 + 0.25 * 2


@pytest.mark.parametrize(("solver", "rows"), [("rk4", [1, 4, 7, 10, 11]),
                                              ("verlet", [1, 4, 7, 10, 11]),
                                              ("dop853", [1, 3, 6, 9, 11])])
def test_time_events_within_rounding_of_an_output_time(models: dict[str, CompiledModel],
                                                       solver: str, rows: list[int]) -> None:
    """Output times 0.3, 0.6, 0.8999999999999999 lie an ulp before the samples 0.1 * k:
    the fixed-step loops end their step at the event and show the value after it there,
    the adaptive ones show the value before it; each engine as the other. The sample
    at t = 0 ticks at the event after the initialization (3.7.5)."""
    scipy, compiled = both(models["tenths"], solver, stop=1.0, interval=0.3)
    assert compiled["n"].tolist() == scipy["n"].tolist() == rows
    assert compiled.stats.time_events == scipy.stats.time_events == 10
    assert compiled.stats.steps == scipy.stats.steps


@pytest.mark.parametrize("solver", ["dop853", "rk4"])
def test_sign_and_abs_switch_at_the_same_events(models: dict[str, CompiledModel], solver: str
                                                ) -> None:
    """sign outside noEvent switches at events (its relations in zero_crossings); abs
    is noEvent(if v >= 0 then v else -v) (3.7.1): its value is |v| at every row."""
    scipy, compiled = both(models["bang"], solver, stop=3.0, interval=0.01, rtol=1e-10)
    tau, r = 1 / math.sqrt(5), math.sqrt(20)  # x = 0 at tau + 2 k tau
    u = np.mod(compiled.time, 4 * tau)
    s2, s3 = u - tau, u - 3 * tau
    exact = np.where(u < tau, 1 - 5 * u**2,
                     np.where(u < 3 * tau, -r * s2 + 5 * s2**2, r * s3 - 5 * s3**2))
    assert np.max(np.abs(compiled["x"] - exact)) < 1e-8
    assert np.max(np.abs(compiled["speed"] - np.abs(compiled["v"]))) < 1e-12
    crossings = [e.time for e in compiled.events if e.cause in ("x > 0", "x < 0")]
    assert np.max(np.abs(np.array(crossings) - [tau + 2 * tau * k for k in range(3)])) < 1e-9
    assert kinds(compiled) == kinds(scipy)
    assert compiled.stats.state_events == scipy.stats.state_events
