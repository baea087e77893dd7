"""Compiled DOP853 against scipy's DOP853 (same steps, same solution) and closed forms."""

from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest
import scipy.integrate
from scipy.integrate._ivp import dop853_coefficients

from springc.integrate import Status, dop853

if TYPE_CHECKING:
    from conftest import Problem

GRID_POINTS = 101


def reference(problem: Problem, rtol: float, atol: float) -> Any:
    """scipy's run of the same problem, with its dense output."""
    return scipy.integrate.solve_ivp(problem.scipy_rhs(), (0.0, problem.stop), problem.x0,
                                     method="DOP853", rtol=rtol, atol=atol,
                                     dense_output=True)


def test_tableau_is_the_published_one() -> None:
    from springc.integrate import dop853_tableau as ours  # the coefficients themselves

    for name in ("A", "B", "C", "D", "E3", "E5"):
        np.testing.assert_array_equal(getattr(ours, name), getattr(dop853_coefficients, name))


@pytest.mark.parametrize("rtol", [1e-6, 1e-8, 1e-10])
def test_same_steps_and_solution_as_scipy(problem: Problem, rtol: float) -> None:
    atol = rtol * 1e-3
    ref = reference(problem, rtol, atol)
    grid = np.linspace(0.0, problem.stop, GRID_POINTS)
    run = dop853(problem.rhs, grid, problem.x0, problem.p, np.zeros(0), rtol=rtol, atol=atol)
    assert run.status == Status.SUCCESS and run.filled == GRID_POINTS
    accepted = len(ref.t) - 1
    assert run.accepted_steps == accepted
    # scipy: 2 evaluations to start, 12 per attempted step, 3 per dense output
    attempted = (ref.nfev - 2 - 3 * accepted) // 12
    assert run.rejected_steps == attempted - accepted
    expected = ref.sol(grid).T
    scale = np.abs(expected).max()
    assert np.abs(run.states - expected).max() <= 1e-12 * scale
    np.testing.assert_allclose(run.states[-1], ref.y[:, -1], rtol=1e-12, atol=1e-12 * scale)


@pytest.mark.parametrize("rtol", [1e-4, 1e-8, 1e-10])
def test_plain_loops_agree_with_scipy_within_the_tolerance(problem: Problem, rtol: float) -> None:
    # other summation order: the first steps' error estimates (rounding noise) differ,
    # so the steps differ slightly; the count and the solution (to the tolerance) do not
    atol = rtol * 1e-3
    ref = reference(problem, rtol, atol)
    grid = np.linspace(0.0, problem.stop, GRID_POINTS)
    run = dop853(problem.rhs, grid, problem.x0, problem.p, np.zeros(0), rtol=rtol, atol=atol,
                 scipy_arithmetic=False)
    assert run.accepted_steps == len(ref.t) - 1
    expected = ref.sol(grid).T
    assert np.abs(run.states - expected).max() <= 10 * rtol * np.abs(expected).max()


def test_oscillator_closed_form_and_observed(odes: SimpleNamespace) -> None:
    w = 2.0
    grid = np.linspace(0.0, 5.0, 51)
    run = dop853(odes.oscillator, grid, [1.0, 0.0], [w], np.zeros(0), rtol=1e-10,
                 atol=1e-13, observed=odes.oscillator_energy)
    np.testing.assert_allclose(run.states[:, 0], np.cos(w * grid), atol=2e-9)
    np.testing.assert_allclose(run.states[:, 1], -w * np.sin(w * grid), atol=4e-9)
    energy = 0.5 * run.states[:, 1] ** 2 + 0.5 * w**2 * run.states[:, 0] ** 2
    np.testing.assert_array_equal(run.observed[:, 0], energy)  # evaluated on the grid states
    np.testing.assert_array_equal(run.observed[:, 1], grid)
    assert np.abs(energy - 0.5 * w**2).max() < 1e-8


def test_first_and_max_step_follow_scipy(odes: SimpleNamespace) -> None:
    p, x0 = np.array([1.0]), np.array([2.0, 0.0])
    ref = scipy.integrate.solve_ivp(lambda t, x: odes.van_der_pol(t, x, p, np.zeros(0)),
                                    (0.0, 4.0), x0, method="DOP853", rtol=1e-7, atol=1e-10,
                                    first_step=1e-3, max_step=0.05)
    run = dop853(odes.van_der_pol, [0.0, 4.0], x0, p, np.zeros(0), rtol=1e-7, atol=1e-10,
                 first_step=1e-3, max_step=0.05)
    assert run.accepted_steps == len(ref.t) - 1
    np.testing.assert_allclose(run.states[-1], ref.y[:, -1], rtol=1e-12)


def test_grid_times_at_step_ends_take_the_step_state(odes: SimpleNamespace) -> None:
    # a two-point grid: the end state is the last step's own state, no interpolation
    p, x0 = np.array([2.0]), np.array([1.0, 0.0])
    ref = scipy.integrate.solve_ivp(lambda t, x: odes.oscillator(t, x, p, np.zeros(0)),
                                    (0.0, 5.0), x0, method="DOP853", rtol=1e-9, atol=1e-12)
    run = dop853(odes.oscillator, [0.0, 5.0], x0, p, np.zeros(0), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(run.states[1], ref.y[:, -1], rtol=1e-13, atol=1e-14)
    np.testing.assert_array_equal(run.states[0], x0)
    assert run.rhs_evaluations == ref.nfev + 3  # the one dense output of the last step


def test_the_face_keeps_its_functions_after_the_kernels_load(odes: SimpleNamespace) -> None:
    import springc.integrate as face

    dop853(odes.oscillator, [0.0, 1.0], [1.0, 0.0], [2.0], np.zeros(0), rtol=1e-6, atol=1e-9)
    face.fixed_step("rk4", odes.oscillator, [0.0, 1.0], [1.0, 0.0], [2.0], np.zeros(0),
                    step=0.5)
    # a kernel module named like a face function would replace it on import
    assert face.dop853 is dop853 and face.fixed_step.__module__ == "springc.integrate.engine"
