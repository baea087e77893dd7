"""The observed variables at output rows (simulation/observed_rows.py): each row a
solution at its states, a row whose Newton iteration fails from the previous row's
solution solved by continuation, and a row that cannot be solved never written."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import springc
from springc.simulation.failures import Stop
from springc.simulation.observed_rows import observed_at_rows, observed_on_rows
from springc.simulation.steps import Problem, Progress

CLAMP = Path(__file__).resolve().parent / "models" / "ZenerClamp.mo"
V_FIRST, V_SECOND = 5.5, -4.0
"""Capacitor voltages of two rows: Newton on the clamp's vm from the first row's
solution does not converge at the second within its 50 steps."""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def clamp() -> springc.CompiledModel:
    return springc.compile_model(str(CLAMP), "ZenerClamp")


def _solve(mod: Any, p: np.ndarray, t: float, v: float,
           warm: float) -> tuple[np.ndarray, np.ndarray]:
    z = np.asarray(mod.guesses(p), dtype=float)
    z[0] = warm
    return np.asarray(mod.observed(t, np.array([v]), p, z)), z


def _rows(clamp: springc.CompiledModel) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray]:
    mod: Any = clamp.module
    p = np.asarray(mod.parameters(), dtype=float)
    times = np.array([0.1, 0.2])
    states = np.array([[V_FIRST], [V_SECOND]])
    return mod, p, times, states


def test_a_row_that_fails_from_the_previous_solution_is_solved_by_continuation(
        clamp: springc.CompiledModel) -> None:
    mod, p, times, states = _rows(clamp)
    _, first = _solve(mod, p, 0.1, V_FIRST, 0.0)
    _, direct = _solve(mod, p, 0.2, V_SECOND, float(first[0]))
    assert direct[-1] != 0.0  # the premise: Newton from the first row's vm fails
    expected, near = _solve(mod, p, 0.2, V_SECOND, 0.0)  # from 0 V it converges
    assert near[-1] == 0.0
    zs = np.array([mod.guesses(p), mod.guesses(p)], dtype=float)
    problem = Problem(clamp, p, "dop853", Progress(None, 0.0, 1.0))
    rows = observed_at_rows(mod, problem, times, states, zs)
    assert np.allclose(rows[1], expected, rtol=1e-9, atol=1e-12)
    z = np.asarray(mod.guesses(p), dtype=float)
    grid_rows = observed_on_rows(mod, times, states, p, z)
    assert z[-1] == 0.0
    assert np.allclose(grid_rows[1], expected, rtol=1e-9, atol=1e-12)


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
