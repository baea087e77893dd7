"""The compiled engine's C loop (``single_loop.c`` around the model's C functions)
against the numba loop on the same generated model: the same steps, evaluations and
states (within 1e-12 relative: the C math library's functions may round otherwise
than numba's), its resumption after the step limit, and its status codes."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.integrate import Status, dop853, rk45
from springc.pipeline import loop_library

ROOT = Path(__file__).resolve().parents[2]
SEED = ROOT / "models" / "SpringMass.mdl"
SCENES = ROOT / "models" / "Scenes.mdl"
OSCILLATOR = """
model Oscillator
  parameter Real w = 3;
  Real q(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
  Real e;
equation
  der(q) = v;
  der(v) = -w * w * q;
  e = 0.5 * v * v + 0.5 * w * w * q * q;
end Oscillator;
"""
ROOT_MODEL = """
model Root
  Real x(start = 1, fixed = true);
equation
  der(x) = -sqrt(x);
end Root;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))


def _numba_model(files: list[Path], name: str, **options: object) -> springc.CompiledModel:
    return springc.compile_model(files, name, backend="numba", **options)  # type: ignore[arg-type]


def _start(model: springc.CompiledModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    mod = model.module
    p = np.asarray(mod.parameters(), dtype=float)
    return p, np.asarray(mod.start(p), dtype=float), np.asarray(mod.guesses(p), dtype=float)


def _close(a: np.ndarray, b: np.ndarray) -> None:
    scale = max(float(np.abs(b).max()), 1.0)
    assert float(np.abs(a - b).max()) <= 1e-12 * scale


@pytest.mark.parametrize(("files", "name", "parameters"), [
    ([SEED], "SpringMass", None), ([SCENES], "Scenes.Chain", {"N": 20})])
@pytest.mark.parametrize("method", ["dop853", "rk45"])
def test_the_c_loop_takes_the_numba_loops_steps(files: list[Path], name: str,
                                                parameters: dict[str, float] | None,
                                                method: str) -> None:
    model = _numba_model(files, name, parameters=parameters)
    lib = loop_library(model)
    p, x0, z = _start(model)
    grid = np.linspace(0.0, 3.0, 301)
    numba_run = (dop853 if method == "dop853" else rk45)(
        model.module.rhs, grid, x0, p, z.copy(), rtol=1e-8, atol=1e-10,
        scipy_arithmetic=False)
    c_run = lib.run(method, grid, x0, p, z.copy(), rtol=1e-8, atol=1e-10)
    assert (c_run.status, c_run.filled) == (Status.SUCCESS, len(grid))
    assert (c_run.accepted_steps, c_run.rejected_steps, c_run.rhs_evaluations) == (
        numba_run.accepted_steps, numba_run.rejected_steps, numba_run.rhs_evaluations)
    _close(np.frombuffer(c_run.states).reshape(numba_run.states.shape), numba_run.states)
    assert math.isclose(c_run.next_step, numba_run.next_step, rel_tol=1e-9)
    # the observed variables on the grid by the C model, against the Python module's
    z_obs = z.copy()
    row, values = lib.observed(grid, numba_run.states, p, z_obs)
    expected = model.module.observed_grid(grid, numba_run.states, p, z.copy())
    assert row == -1
    _close(np.frombuffer(values).reshape(expected.shape), np.asarray(expected))


def test_the_oscillator_against_its_solution() -> None:
    model = springc.load_model_from_string(OSCILLATOR, backend="python")
    lib = loop_library(model)
    p, x0, z = _start(model)
    grid = np.linspace(0.0, 5.0, 51)
    run = lib.run("dop853", grid, x0, p, z, rtol=1e-11, atol=1e-13)
    states = np.frombuffer(run.states).reshape(len(grid), 2)
    np.testing.assert_allclose(states[:, 0], np.cos(3 * grid), atol=1e-8)
    np.testing.assert_allclose(states[:, 1], -3 * np.sin(3 * grid), atol=3e-8)
    row, energy = lib.observed(grid, run.states, p, z)
    assert row == -1
    np.testing.assert_allclose(np.frombuffer(energy), 4.5, rtol=1e-8)  # w^2 / 2


@pytest.mark.parametrize("method", ["dop853", "rk45"])
def test_a_run_stopped_at_the_step_limit_goes_on_as_one_run(method: str) -> None:
    model = springc.compile_model([SEED], "SpringMass", backend="python")
    lib = loop_library(model)
    p, x0, z = _start(model)
    grid = np.linspace(0.0, 2.0, 201)
    whole = lib.run(method, grid, x0, p, z.copy(), rtol=1e-7, atol=1e-10)
    first = lib.run(method, grid, x0, p, z.copy(), rtol=1e-7, atol=1e-10, max_steps=40)
    assert first.status == Status.MAX_STEPS
    assert first.accepted_steps + first.rejected_steps == 40
    rest = np.concatenate(([first.failure_time], grid[grid > first.failure_time]))
    second = lib.run(method, rest, first.failure_state, p, z.copy(), rtol=1e-7, atol=1e-10,
                     first_step=first.next_step)
    assert second.status == Status.SUCCESS
    assert first.accepted_steps + second.accepted_steps == whole.accepted_steps
    n = len(x0)
    joined = np.concatenate((np.frombuffer(first.states)[:first.filled * n],
                             np.frombuffer(second.states)[n:]))
    _close(joined.reshape(-1, n), np.frombuffer(whole.states).reshape(-1, n))


@pytest.mark.parametrize("method", ["dop853", "rk45"])
def test_a_derivative_that_turns_nan_stops_where_the_numba_loop_stops(method: str) -> None:
    # x = (1 - t/2)^2 reaches 0 at t = 2; a stage past it takes sqrt of a negative x
    model = springc.load_model_from_string(ROOT_MODEL, backend="numba")
    lib = loop_library(model)
    p, x0, z = _start(model)
    grid = np.linspace(0.0, 3.0, 31)
    c_run = lib.run(method, grid, x0, p, z.copy(), rtol=1e-6, atol=1e-9)
    numba_run = (dop853 if method == "dop853" else rk45)(
        model.module.rhs, grid, x0, p, z.copy(), rtol=1e-6, atol=1e-9,
        scipy_arithmetic=False)
    assert c_run.status == numba_run.status == Status.NON_FINITE_DERIVATIVE
    assert (c_run.filled, c_run.accepted_steps) == (numba_run.filled,
                                                    numba_run.accepted_steps)
    assert 1.99 < c_run.failure_time < 2.01  # (1 - t/2)^2 = 0 at t = 2
    assert math.isclose(c_run.failure_time, numba_run.failure_time, rel_tol=1e-12)
    assert c_run.failure_state[0] < 0 and math.isclose(
        c_run.failure_state[0], numba_run.failure_state[0], rel_tol=1e-9)
