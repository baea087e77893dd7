"""Simulation against closed-form solutions, the seed against an independent solve,
output grids, defaults, parameters and failures (Python API)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg

import springc
from same_method import assert_same_method
from springc.errors import SimulationError
from springc.simulation.runner import output_grid

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")

OSCILLATORS = """
model Harmonic
  parameter Real k = 4;
  parameter Real m = 1;
  Real x(start = 1);
  Real v(start = 0);
equation
  der(x) = v;
  m * der(v) = -k * x;
end Harmonic;

model Damped
  parameter Real k = 25;
  parameter Real d = 2;
  parameter Real m = 1;
  Real x(start = 1, unit = "m");
  Real v(start = 0, unit = "m/s");
equation
  der(x) = v;
  m * der(v) = -k * x - d * v;
end Damped;

model Blowup
  Real x(start = 1);
equation
  der(x) = x^2;
end Blowup;

model Circle
  Real x(start = 0);
  Real y(start = -1);
equation
  der(x) = 1;
  x^2 + y^2 = 1;
end Circle;

model DivZero
  Real x(start = 1);
  Real y;
equation
  y = 1 / (x - 1);
  der(x) = y;
end DivZero;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def models(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("models") / "oscillators.mdl"
    path.write_text(OSCILLATORS)
    return str(path)


@pytest.mark.parametrize("solver", ["dop853", "rk45", "radau", "bdf", "lsoda"])
def test_harmonic_oscillator_matches_closed_form(models: str, solver: str) -> None:
    result = springc.simulate(models, model_name="Harmonic", solver=solver, rtol=1e-8,
                              stop=10.0, interval=0.05)
    t = result.time
    assert np.max(np.abs(result["x"] - np.cos(2 * t))) < 1e-6
    assert np.max(np.abs(result["v"] + 2 * np.sin(2 * t))) < 2e-6


@pytest.mark.parametrize("solver", ["dop853", "radau"])
def test_damped_oscillator_matches_closed_form(models: str, solver: str) -> None:
    result = springc.simulate(models, model_name="Damped", solver=solver, rtol=1e-8)
    t = result.time
    zeta_w, wd = 1.0, math.sqrt(25 - 1)  # d/(2m), sqrt(k/m - (d/2m)^2)
    exact = np.exp(-zeta_w * t) * (np.cos(wd * t) + zeta_w / wd * np.sin(wd * t))
    assert np.max(np.abs(result["x"] - exact)) < 1e-6
    assert result.units == ("m", "m/s")


@pytest.mark.parametrize("solver", ["dop853", "radau"])
def test_linear_chain_matches_matrix_exponential(solver: str) -> None:
    model = springc.compile_model(SCENES, "Scenes.Chain", parameters={"N": 4})
    result = springc.simulate(model, solver=solver, rtol=1e-8, stop=3.0, interval=0.01)
    mod = model.module
    p = mod.parameters()
    n = len(mod.STATES)
    z = mod.guesses(p)
    a = mod.jacobian_dense(0.0, np.zeros(n), p, z)  # the chain is affine: f = A x + b
    b = mod.rhs(0.0, np.zeros(n), p, z)
    augmented = np.zeros((n + 1, n + 1))
    augmented[:n, :n], augmented[:n, n] = a, b
    x0 = np.append(mod.start(p), 1.0)
    exact = np.array([(scipy.linalg.expm(augmented * t) @ x0)[:n] for t in result.time])
    states = np.column_stack([result[s] for s in mod.STATES])
    scale = np.abs(exact).max()
    assert np.max(np.abs(states - exact)) < 1e-6 * scale


def test_seed_matches_independent_solve() -> None:
    result = springc.simulate(SEED, rtol=1e-8, stop=2.0, interval=0.01)

    def f(t: float, x: np.ndarray) -> np.ndarray:
        length = math.hypot(x[0], x[1])
        acc = -1e4 * x[:2] * (length - 1.0) / length + np.array([0.0, -9.81])
        return np.concatenate([x[2:], acc])

    ref = scipy.integrate.solve_ivp(f, (0.0, 2.0), [1.0, -1.0, 0.0, 0.0], method="DOP853",
                                    rtol=1e-12, atol=1e-12, t_eval=result.time)
    for i, name in enumerate(["mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]"]):
        scale = np.abs(ref.y[i]).max()
        assert np.max(np.abs(result[name] - ref.y[i])) < 1e-6 * scale, name
    length = np.hypot(result["mass.pos[1]"], result["mass.pos[2]"])
    assert np.allclose(result["spring.x"], length, rtol=1e-14)


def test_seed_defaults_without_experiment() -> None:
    result = springc.simulate(SEED)
    assert len(result.time) == 501 and result.time[0] == 0.0 and result.time[-1] == 10.0
    assert result.names == ("mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]",
                            "spring.dir[1]", "spring.dir[2]", "spring.x")
    assert result.stats.solver == "dop853" and result.stats.steps > 0


def test_experiment_annotation_sets_defaults() -> None:
    result = springc.simulate(SCENES, model_name="Scenes.Oscillator")
    assert len(result.time) == 1001 and result.time[-1] == 10.0
    assert result.time[1] == 0.01


def test_output_grid_is_exact() -> None:
    grid = output_grid(0.0, 1.0, 0.1)
    assert len(grid) == 11 and grid[-1] == 1.0 and grid[3] == 0.1 * 3
    grid = output_grid(1.0, 2.05, 0.5)  # not a whole number of intervals
    assert grid.tolist() == [1.0, 1.5, 2.0, 2.05]
    with pytest.raises(SimulationError, match="after the start"):
        output_grid(1.0, 1.0, 0.1)
    with pytest.raises(SimulationError, match="positive"):
        output_grid(0.0, 1.0, 0.0)


def test_start_and_interval_options(models: str) -> None:
    result = springc.simulate(models, model_name="Harmonic", start=1.0, stop=2.0,
                              interval=0.25, rtol=1e-9)
    assert result.time.tolist() == [1.0, 1.25, 1.5, 1.75, 2.0]
    assert result["x"][0] == 1.0  # states start at their start values at t0


def test_parameters_change_the_solution_without_recompiling(models: str) -> None:
    model = springc.compile_model(models, "Harmonic")
    result = springc.simulate(model, parameters={"k": 9.0}, rtol=1e-9, stop=1.0)
    assert np.max(np.abs(result["x"] - np.cos(3 * result.time))) < 1e-6
    assert result.parameters["k"] == 9.0


def test_unknown_parameter_names_close_matches(models: str) -> None:
    with pytest.raises(SimulationError,
                       match="'kk' is not a parameter or a state of Harmonic") as info:
        springc.simulate(models, model_name="Harmonic", parameters={"kk": 1.0})
    assert "'k'" in (info.value.hint or "")


def test_structural_parameter_recompiles() -> None:
    result = springc.simulate(SCENES, model_name="Scenes.Chain", parameters={"N": 3, "k": 50},
                              stop=1.0)
    assert [n for n in result.names if n.startswith("m[") and n.endswith("].s")] == [
        "m[1].s", "m[2].s", "m[3].s"]
    assert result.model == "Scenes.Chain"
    assert len(result.time) == 101  # the experiment's Interval (0.01) still applies


def test_outputs_select_columns(models: str) -> None:
    result = springc.simulate(SEED, outputs=["spring.x", "mass.v[?]"], stop=0.1)
    assert result.names == ("mass.v[1]", "mass.v[2]", "spring.x")
    assert result.values.shape == (len(result.time), 3)
    with pytest.raises(SimulationError, match="matches no state") as info:
        springc.simulate(SEED, outputs=["spring.xx"])
    assert "spring.x" in (info.value.hint or "")


def test_result_object() -> None:
    result = springc.simulate(SEED, stop=0.5)
    table = result.to_dict()
    assert list(table)[:2] == ["time", "mass.pos[1]"]
    assert "spring.x" in result and "nothing" not in result
    with pytest.raises(KeyError):
        result["nothing"]
    assert "SpringMass" in repr(result)


@pytest.mark.parametrize("solver", ["dop853", "radau"])
def test_finite_time_blowup_names_time_and_state(models: str, solver: str) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(models, model_name="Blowup", solver=solver, stop=3.0)
    err = info.value
    assert "at time 1.0" in err.message or "at time 0.99" in err.message
    assert any(n.message.startswith("x = ") for n in err.notes)
    if solver == "dop853":
        assert "--solver radau" in (err.hint or "")


def test_newton_failure_names_tearing_variable(models: str) -> None:
    with pytest.raises(SimulationError, match=r"nonlinear system for y did not converge "
                                              r"at time 1\b"):
        springc.simulate(models, model_name="Circle", stop=3.0, interval=0.001)


def test_division_by_zero_names_the_equation(models: str) -> None:
    with pytest.raises(SimulationError, match=r"division by zero while computing y "
                                              r"\(.*oscillators.mdl:\d+\) at time 0"):
        springc.simulate(models, model_name="DivZero")


def test_unknown_solver(models: str) -> None:
    with pytest.raises(SimulationError, match="unknown solver"):
        springc.simulate(models, model_name="Harmonic", solver="euler")


def test_numba_backend_simulates_like_python(models: str) -> None:
    pytest.importorskip("numba")
    a = springc.simulate(models, model_name="Damped", backend="numba", rtol=1e-9, stop=2.0)
    b = springc.simulate(models, model_name="Damped", backend="python", rtol=1e-9, stop=2.0)
    assert (a.stats.engine, b.stats.engine) == ("compiled", "scipy")
    assert_same_method(a, b, 1e-9)


def test_progress_bar_draws_and_clears() -> None:
    import io

    from springc.simulation.steps import Progress

    stream = io.StringIO()
    bar = Progress(stream, 0.0, 10.0)
    bar.update(5.0)
    assert stream.getvalue() == ""  # nothing during the first second
    bar.next = 0.0
    bar.update(5.0)
    assert "50.0%" in stream.getvalue() and "t = 5 s" in stream.getvalue()
    bar.close()
    assert stream.getvalue().endswith("\r")
    quiet = Progress(None, 0.0, 1.0)
    quiet.next = 0.0
    quiet.update(0.5)
    quiet.close()


def test_progress_stream_receives_updates(models: str) -> None:
    import io

    stream = io.StringIO()
    springc.simulate(models, model_name="Harmonic", stop=1.0, progress=stream)
    assert stream.getvalue() == ""  # a short run shows no bar


def test_output_size_guard(monkeypatch: pytest.MonkeyPatch, models: str) -> None:
    import springc.simulation.runner

    monkeypatch.setattr(springc.simulation.runner, "MAX_OUTPUT_BYTES", 1000)
    with pytest.raises(SimulationError, match="output times") as info:
        springc.simulate(models, model_name="Harmonic")
    assert "--vars" in (info.value.hint or "")


def test_selected_columns_are_those_of_the_whole_result(models: str) -> None:
    """A selection whose order is not [states | observed] (an observed variable before
    the states) takes each column from its source: the same values as the run of
    every output, within rounding (two generated modules)."""
    every = springc.simulate(SEED, stop=0.1, solver="dop853", error_control="off")
    some = springc.simulate(SEED, outputs=["spring.x", "mass.v[?]"], stop=0.1,
                            solver="dop853", error_control="off")
    assert some.names == ("mass.v[1]", "mass.v[2]", "spring.x")
    columns = [every.names.index(n) for n in some.names]
    assert np.allclose(some.values, every.values[:, columns], rtol=1e-12, atol=1e-15)
