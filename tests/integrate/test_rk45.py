"""Compiled RK45 against scipy's RK45: the published tableau, the same steps and the same
solution bit for bit (scipy's arithmetic), and events on its dense output."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import TYPE_CHECKING

import numpy as np
import pytest
import scipy.integrate
from scipy.integrate._ivp.rk import RK45

from springc.integrate import Crossings, Status, rk45
from springc.integrate import rk45_tableau as tableau

if TYPE_CHECKING:
    from conftest import Problem


def test_tableau_is_scipys() -> None:
    for name in ("A", "B", "C", "E", "P"):
        np.testing.assert_array_equal(getattr(tableau, name), getattr(RK45, name))


@pytest.mark.parametrize("rtol", [1e-3, 1e-6, 1e-9])
def test_same_steps_and_solution_as_scipy(problem: Problem, rtol: float) -> None:
    atol = rtol * 1e-3
    ref = scipy.integrate.solve_ivp(problem.scipy_rhs(), (0.0, problem.stop), problem.x0,
                                    method="RK45", rtol=rtol, atol=atol, dense_output=True)
    grid = np.linspace(0.0, problem.stop, 101)
    run = rk45(problem.rhs, grid, problem.x0, problem.p, np.zeros(0), rtol=rtol, atol=atol)
    assert run.ok and run.accepted_steps == len(ref.t) - 1
    assert run.rhs_evaluations == ref.nfev
    expected = ref.sol(grid).T
    assert np.abs(run.states - expected).max() <= 1e-13 * np.abs(expected).max()


def test_bouncing_ball_on_the_dense_output(stiff: SimpleNamespace) -> None:
    # a constant acceleration: the 4th-order interpolant is exact
    run = rk45(stiff.falling, [0.0, 1.0], [1.0, 0.0], [9.81], np.zeros(0), rtol=1e-10,
               atol=1e-12, crossings=Crossings(stiff.height, [1.0]))
    assert run.status == Status.STATE_EVENT and list(run.fired) == [-1]
    assert run.event_time == pytest.approx(math.sqrt(2 / 9.81), abs=1e-9)
