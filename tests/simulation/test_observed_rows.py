"""The observed variables at output rows (simulation/observed_rows.py): each row a
solution at its states, a row whose Newton iteration fails from the previous row's
solution solved by continuation, and a row that cannot be solved never written."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, cast

import numpy as np
import pytest

import springc
from springc.errors import SimulationError
from springc.simulation.failures import Stop
from springc.simulation.observed_rows import observed_at_rows, observed_on_rows
from springc.simulation.steps import Problem, Progress

CLAMP = Path(__file__).resolve().parent / "models" / "ZenerClamp.mo"


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def clamp() -> springc.CompiledModel:
    return springc.compile_model(str(CLAMP), "ZenerClamp")


def _rows(clamp: springc.CompiledModel) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray]:
    mod: Any = clamp.module
    p = np.asarray(mod.parameters(), dtype=float)
    times = np.array([0.1, 0.2])
    states = np.array([[5.5], [-4.0]])
    return mod, p, times, states


class AtanModule:
    """A generated module in small: one torn variable ``w`` with ``atan(w - x) = 0``,
    plain Newton of 20 steps from the warm start ``z[0]`` (it diverges from more than
    1.39 away), the failure flag in ``z[-1]``."""

    GUESSES = ("w",)
    OBSERVED = ("w",)

    def observed(self, t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
        w = float(z[0])
        for _ in range(20):
            d = w - float(x[0])
            if abs(d) > 1e100:  # diverged
                break
            step = math.atan(d) * (1.0 + d * d)
            w -= step
            if abs(step) <= 1e-12:
                z[0] = w
                return np.array([w])
        z[0], z[-1] = w, 1.0
        return np.array([w])

    def observed_grid(self, ts: np.ndarray, states: np.ndarray, p: np.ndarray,
                      z: np.ndarray) -> np.ndarray:
        out = np.empty((len(ts), 1))
        for i in range(len(ts)):
            out[i] = self.observed(float(ts[i]), states[i], p, z)
            if z[-1] != 0.0:
                out[i:] = np.nan
                break
        return out


class AtanProblem:
    """What ``observed_at_rows`` asks of a run's :class:`~springc.simulation.steps.Problem`."""

    def __init__(self) -> None:
        self.p, self.z = np.zeros(0), np.zeros(2)

    def newton_failure(self, t: float, x: np.ndarray) -> Stop:
        return Stop(SimulationError(f"flag {self.z[-1]:g} at time {t:g}"))


def test_a_row_that_fails_from_the_previous_solution_is_solved_by_continuation() -> None:
    module, p = AtanModule(), np.zeros(0)
    times, states = np.array([0.0, 1.0, 2.0]), np.array([[0.0], [10.0], [10.5]])
    z = np.zeros(2)
    module.observed(1.0, states[1], p, z)
    assert z[-1] == 1.0  # the premise: Newton from w = 0 diverges at x = 10
    zs = np.zeros((3, 2))
    rows = observed_at_rows(module, cast(Any, AtanProblem()), times, states, zs)
    assert np.allclose(rows[:, 0], [0.0, 10.0, 10.5], atol=1e-12)
    z = np.zeros(2)
    grid_rows = observed_on_rows(module, times, states, p, z)
    assert z[-1] == 0.0 and z[0] == pytest.approx(10.5, abs=1e-12)
    assert np.allclose(grid_rows[:, 0], [0.0, 10.0, 10.5], atol=1e-12)


def test_a_row_beyond_continuation_stops_the_run() -> None:
    module = AtanModule()
    times, states = np.array([0.0, 1.0]), np.array([[0.0], [1e6]])  # 2**8 steps of 3906
    with pytest.raises(Stop) as stop:
        observed_at_rows(module, cast(Any, AtanProblem()), times, states, np.zeros((2, 2)))
    assert stop.value.error.message == "flag 1 at time 1"


def test_a_row_that_cannot_be_solved_stops_the_run(clamp: springc.CompiledModel) -> None:
    mod, p, times, states = _rows(clamp)
    states[1, 0] = np.nan  # no Newton iteration converges at a NaN state
    zs = np.array([mod.guesses(p), mod.guesses(p)], dtype=float)
    problem = Problem(clamp, p, "dop853", Progress(None, 0.0, 1.0))
    with pytest.raises(Stop) as stop:
        observed_at_rows(mod, problem, times, states, zs)
    assert stop.value.error.message == "the nonlinear system for vm did not converge at time 0.2"
    z = np.asarray(mod.guesses(p), dtype=float)
    grid_rows = observed_on_rows(mod, times, states, p, z)
    assert z[-1] != 0.0 and np.isnan(grid_rows[1]).all() and np.isfinite(grid_rows[0]).all()


def test_the_rhs_converges_from_a_warm_start_across_the_diode_knee(
        clamp: springc.CompiledModel) -> None:
    # Newton moves about one thermal voltage per step on the exponential: from vm = 3 V
    # (or 5 V) to the solution -0.028 V takes about 100 steps (codegen's NEWTON_ITERATIONS)
    mod: Any = clamp.module
    p = np.asarray(mod.parameters(), dtype=float)
    x = np.array([-2.89858])
    near = np.asarray(mod.guesses(p), dtype=float)
    expected = mod.rhs(0.338, x, p, near)
    assert near[-1] == 0.0 and abs(near[0] + 0.0282903) < 1e-6
    for warm in (3.0, 5.0):
        z = np.asarray(mod.guesses(p), dtype=float)
        z[0] = warm
        derivative = mod.rhs(0.338, x, p, z)
        assert z[-1] == 0.0
        assert abs(derivative[0] - expected[0]) <= 1e-9 * abs(expected[0])


@pytest.mark.parametrize("engine", ["compiled", "scipy"])
def test_the_clamp_runs_where_a_stale_warm_start_stopped_it(engine: str) -> None:
    result = springc.simulate(str(CLAMP), model_name="ZenerClamp", stop=0.36,
                              engine=engine)
    i = result["i"]
    # the charging current peaks at 0.247 A at the start (the same run to 0.46 s)
    assert abs(np.max(np.abs(i)) - 0.247) < 1e-3


def test_rows_go_into_the_given_columns_a_few_at_a_time(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A large result holds one copy: the rows are written into the view given (the
    result's observed columns), through calls of at most ROWS_PER_CALL rows, each row
    warm started from the one before across the calls, as in one call."""
    from springc.simulation import observed_rows

    module, p = AtanModule(), np.zeros(0)
    times = np.arange(7.0)
    states = np.array([[0.0], [1.0], [2.0], [3.0], [4.0], [5.0], [6.0]])
    calls: list[int] = []
    grid = module.observed_grid

    def counted(ts: np.ndarray, xs: np.ndarray, q: np.ndarray, z: np.ndarray) -> np.ndarray:
        calls.append(len(ts))
        return grid(ts, xs, q, z)

    monkeypatch.setattr(module, "observed_grid", counted)
    monkeypatch.setattr(observed_rows, "ROWS_PER_CALL", 3)
    result = np.full((7, 3), -1.0)
    z = np.zeros(2)
    written = observed_on_rows(module, times, states, p, z, result[:, 2:])
    assert written.base is result and calls == [3, 3, 1]
    assert np.allclose(result[:, 2], np.arange(7.0), atol=1e-12)
    assert (result[:, :2] == -1.0).all() and z[-1] == 0.0
