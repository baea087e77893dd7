"""assert(...) during simulation: the step at which a decaying state crosses its bound
(against the closed form exp(-k t)), warnings that do not stop the run, parameter-only
assertions before the integration, the generated module's table and function."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimulationError

DECAY = """model Decay
  parameter Real k = 2;
  parameter Real bound = 0.5;
  Real x(start = 1, fixed = true);
  Real y;
equation
  der(x) = -k * x;
  assert(k > 0, "k must be positive");
algorithm
  y := 2 * x;
  assert(y > 2 * bound, "x fell below the bound", level = AssertionLevel.%s);
  annotation(experiment(StopTime = 1, Interval = 0.01));
end Decay;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def model_file(tmp_path: Path, level: str = "error") -> str:
    path = tmp_path / "decay.mo"
    path.write_text(DECAY % level)
    return str(path)


CROSSING = math.log(2) / 2  # exp(-2 t) = 0.5


@pytest.mark.parametrize(("solver", "step"), [("dop853", None), ("radau", None),
                                              ("rk4", 0.001), ("verlet", 0.001)])
def test_failing_assertion_stops_at_the_first_step_past_the_crossing(
        tmp_path: Path, solver: str, step: float | None) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(model_file(tmp_path), solver=solver, step=step, rtol=1e-8,
                         engine="scipy")
    err = info.value
    head, _, message = err.message.partition(": ")
    assert message == "x fell below the bound"
    t = float(head.removeprefix("assertion failed at t = "))
    # fixed step: the first step past the crossing; scipy's solvers: the crossing,
    # located on the step's interpolant (rtol 1e-8; the message shows 9 digits)
    if step is not None:
        assert t == pytest.approx(math.ceil(CROSSING / step) * step, abs=1e-12)
    else:
        assert abs(t - CROSSING) < 1e-6
    assert err.span is not None and (err.span.line, err.span.column) == (11, 3)


def test_compiled_engine_locates_the_failing_step(tmp_path: Path) -> None:
    pytest.importorskip("numba")
    with pytest.raises(SimulationError) as info:
        springc.simulate(model_file(tmp_path), solver="rk4", step=0.001,
                         engine="compiled", backend="numba")
    # checked at the output times (interval 0.01): fails at 0.35; that interval run
    # again step by step: the first step past the crossing at 0.3466, as on scipy
    assert info.value.message == "assertion failed at t = 0.347: x fell below the bound"


def test_parameter_assertion_fails_before_the_integration(tmp_path: Path) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(model_file(tmp_path), parameters={"k": -1.0})
    assert info.value.message == "assertion failed before the simulation started: " \
        "k must be positive"
    assert info.value.span is not None and info.value.span.line == 8


def test_warning_is_printed_once_and_the_run_goes_on(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]
                                                     ) -> None:
    result = springc.simulate(model_file(tmp_path, "warning"), rtol=1e-8, progress=io.StringIO())
    assert np.max(np.abs(result["x"] - np.exp(-2 * result.time))) < 1e-6
    err = capsys.readouterr().err
    assert err.count("warning: assertion failed") == 1
    assert "decay.mo:11:3: warning: assertion failed at t = " in err
    assert err.endswith(": x fell below the bound\n")


def test_cli_exit_code_and_location(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from springc.cli import main

    result = CliRunner().invoke(main, ["simulate", model_file(tmp_path), "--solver", "rk4",
                                       "--step", "0.01", "-o", str(tmp_path / "o.csv")])
    assert result.exit_code == 1
    assert "decay.mo:11:3: error: assertion failed at t = 0.35: x fell below the bound" \
        in result.stderr
    assert not (tmp_path / "o.csv").exists()


def test_generated_module_holds_the_messages_as_literals(tmp_path: Path) -> None:
    path = tmp_path / "q.mo"
    statement = 'assert(x < 2, "\\"\\"\\" + __import__(\'os\')")'
    path.write_text(f'model Q\n  Real x = time;\nequation\n  {statement};\nend Q;\n')
    compiled = springc.compile_model(str(path))
    module = compiled.module
    assert (('""" + __import__(\'os\')', "error",
             f"{path}:4:3", False, len(statement)),) == module.ASSERTIONS
    p = module.parameters()
    assert module.assertions(1.0, np.zeros(0), p, module.guesses(p)).tolist() == [1.0]
    assert module.assertions(2.5, np.zeros(0), p, module.guesses(p)).tolist() == [0.0]


BALL = """model Ball
  parameter Real bound = %s;
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81;
  assert(h > bound, "h fell below the bound");
  when h <= 0 then
    reinit(v, -0.8 * pre(v));
  end when;
end Ball;
"""


@pytest.mark.parametrize("engine", ["scipy", "compiled"])
def test_hybrid_model_assertions_are_checked_at_output_times(tmp_path: Path,
                                                             engine: str) -> None:
    """h = 1 - 9.81 t^2 / 2 reaches 0.5 at t = 0.3193: on the 0.002 s grid the first
    output time past it is 0.32 (h = 0.497728); a bound the bouncing ball never
    crosses (-0.01) lets the run finish, one impact at sqrt(2/g) included."""
    path = tmp_path / "ball.mo"
    path.write_text(BALL % "0.5")
    with pytest.raises(SimulationError) as info:
        springc.simulate([path], stop=1, interval=0.002, rtol=1e-8, engine=engine,
                         cache=False)
    assert info.value.message == "assertion failed at t = 0.32: h fell below the bound"
    assert info.value.span is not None and (info.value.span.line, info.value.span.column) \
        == (8, 3)
    path.write_text(BALL % "-0.01")
    result = springc.simulate([path], stop=1, interval=0.002, rtol=1e-8, engine=engine,
                              cache=False)
    assert result.stats.state_events == 2  # h <= 0 becomes true, then false again
    impact = math.sqrt(2 / 9.81)
    up, after = 0.8 * 9.81 * impact, 1 - impact
    assert result.time[-1] == 1.0
    assert abs(result["h"][-1] - (up * after - 9.81 / 2 * after**2)) < 1e-6
