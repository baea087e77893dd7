"""Failures come back as a status with the time and state where they happened."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.integrate

from springc.integrate import Status, dop853, fixed_step

NO_Z = np.zeros(0)


def test_nan_derivative_stops_at_that_evaluation(failing: SimpleNamespace) -> None:
    grid = np.linspace(0.0, 2.0, 21)
    run = dop853(failing.sqrt_of_falling, grid, [1.0, 0.0], [0.0], NO_Z, rtol=1e-6, atol=1e-9)
    assert run.status == Status.NON_FINITE_DERIVATIVE
    x0 = run.failure_state[0]
    # sqrt of a negative x0 = 1 - t: the attempts that reach past t = 1 are rejected
    # (shorter steps) down to the smallest step there, where the NaN is the run's error
    assert run.failure_time == pytest.approx(1.0, abs=1e-9) and x0 < 0
    assert x0 == pytest.approx(1.0 - run.failure_time, abs=1e-12)
    assert run.filled >= 2 and grid[run.filled - 1] < run.failure_time
    np.testing.assert_allclose(run.states[:run.filled, 1],
                               (1 - (1 - grid[:run.filled]) ** 1.5) / 1.5, atol=1e-6)
    assert np.isnan(run.states[run.filled:]).all()


def test_blow_up_ends_in_a_step_too_small(failing: SimpleNamespace) -> None:
    run = dop853(failing.blow_up, [0.0, 0.5, 2.0], [1.0], [0.0], NO_Z, rtol=1e-6, atol=1e-9)
    assert run.status == Status.STEP_TOO_SMALL
    assert run.failure_time == pytest.approx(1.0, abs=1e-6)  # x = 1 / (1 - t)
    assert run.failure_state[0] > 1e10
    assert run.filled == 2 and run.states[1, 0] == pytest.approx(2.0, rel=1e-6)


def test_max_steps_stops_where_scipy_is_after_as_many_steps(odes: SimpleNamespace) -> None:
    p, x0 = np.array([2.0]), np.array([1.0, 0.0])
    run = dop853(odes.oscillator, [0.0, 5.0], x0, p, NO_Z, rtol=1e-8, atol=1e-11, max_steps=5)
    assert run.status == Status.MAX_STEPS
    assert run.accepted_steps + run.rejected_steps == 5
    ref = scipy.integrate.solve_ivp(lambda t, x: odes.oscillator(t, x, p, NO_Z), (0.0, 5.0),
                                    x0, method="DOP853", rtol=1e-8, atol=1e-11)
    assert run.failure_time == ref.t[run.accepted_steps]
    np.testing.assert_array_equal(run.failure_state, ref.y[:, run.accepted_steps])


def test_model_failure_flag_stops_the_run(failing: SimpleNamespace) -> None:
    z = np.zeros(2)
    run = dop853(failing.flags_after_half, np.linspace(0.0, 1.0, 11), [0.0], [0.0], z,
                 rtol=1e-6, atol=1e-9)
    assert run.status == Status.MODEL_FAILED and z[-1] == 7.0
    assert run.failure_time > 0.5
    assert run.failure_state[0] == pytest.approx(run.failure_time, abs=1e-12)  # x = t


def test_fixed_step_nan_derivative_and_infinite_state(failing: SimpleNamespace,
                                                      odes: SimpleNamespace) -> None:
    grid = np.linspace(0.0, 2.0, 21)
    run = fixed_step("rk4", failing.sqrt_of_falling, grid, [1.0, 0.0], [0.0], NO_Z,
                     step=0.03)
    assert run.status == Status.NON_FINITE_DERIVATIVE
    assert run.failure_state[0] < 0
    assert run.failure_state[0] == pytest.approx(1.0 - run.failure_time, abs=1e-12)
    # finite derivatives (-1e308), but one Euler step of 10 overflows the velocity
    run = fixed_step("euler", odes.oscillator, [0.0, 10.0, 20.0], [1.0, 0.0], [1e154], NO_Z,
                     step=10.0)
    assert run.status == Status.NON_FINITE_STATE
    assert run.failure_time == 10.0 and run.failure_state[1] == -np.inf
    assert run.filled == 1


def test_fixed_step_model_failure(failing: SimpleNamespace) -> None:
    z = np.zeros(1)
    run = fixed_step("verlet", failing.flags_after_half, np.linspace(0.0, 1.0, 5), [0.0],
                     [0.0], z, step=0.1)
    assert run.status == Status.MODEL_FAILED and z[0] == 7.0
    assert run.failure_time > 0.5 and run.filled == 3


@pytest.mark.parametrize(("call", "error", "message"), [
    (lambda o: dop853(o.oscillator, [0.0, 1.0, 0.5], [1.0, 0.0], [1.0], NO_Z, rtol=1e-6,
                      atol=1e-9), ValueError, "strictly increasing"),
    (lambda o: dop853(lambda t, x, p, z: -x, [0.0, 1.0], [1.0], [1.0], NO_Z, rtol=1e-6,
                      atol=1e-9), TypeError, "rhs must be a numba-jitted function"),
    (lambda o: dop853(o.wrong_length, [0.0, 1.0], [1.0, 0.0], [1.0], NO_Z, rtol=1e-6,
                      atol=1e-9), ValueError, r"rhs returns shape \(3,\) for 2 states"),
    (lambda o: dop853(o.oscillator, [0.0, 1.0], [1.0, 0.0], [1.0], NO_Z, rtol=0.0,
                      atol=1e-9), ValueError, "rtol must be positive"),
    (lambda o: fixed_step("leapfrog", o.oscillator, [0.0, 1.0], [1.0, 0.0], [1.0], NO_Z,
                          step=0.1), ValueError, "unknown fixed-step method 'leapfrog'"),
    (lambda o: fixed_step("verlet", o.oscillator, [0.0, 1.0], [1.0, 0.0], [1.0], NO_Z,
                          step=0.1, pairs=[(0, 2)]), ValueError, "outside the state vector"),
])
def test_bad_arguments_are_refused_before_the_loop(
        odes: SimpleNamespace, failing: SimpleNamespace,
        call: Callable[[SimpleNamespace], object], error: type[Exception], message: str
) -> None:
    both = SimpleNamespace(**vars(odes), **vars(failing))
    with pytest.raises(error, match=message):
        call(both)
