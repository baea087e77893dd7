"""Compiled fixed-step methods against springc's Python integrators and closed forms."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from springc.integrate import FIXED_STEP_METHODS, Status, fixed_step
from springc.simulation.integrators import Pairs, integrate

PENDULUM_P = np.array([100.0, 1.0, 1.0, 9.81])
PENDULUM_X0 = np.array([1.0, -1.0, 0.3, 0.0, 0.5])
PAIRS = [(0, 2), (1, 3)]


@pytest.mark.parametrize("method", FIXED_STEP_METHODS)
def test_equal_to_springc_integrators(odes: SimpleNamespace, method: str) -> None:
    # uneven output intervals, a step that does not divide them, a non-pair state x[4]
    grid = np.concatenate([np.linspace(0.0, 1.0, 11), [1.05, 1.3, 2.0]])
    z = np.zeros(0)
    ref = integrate(method, lambda t, x: odes.damped_pendulum(t, x, PENDULUM_P, z), grid,
                    PENDULUM_X0, 0.003, Pairs.of(PAIRS))
    run = fixed_step(method, odes.damped_pendulum, grid, PENDULUM_X0, PENDULUM_P, z,
                     step=0.003, pairs=PAIRS)
    assert run.status == Status.SUCCESS
    assert (run.accepted_steps, run.rhs_evaluations) == (ref.steps, ref.rhs_evaluations)
    np.testing.assert_allclose(run.states, ref.x, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize(("method", "order"), [("symplectic-euler", 1), ("verlet", 2),
                                               ("rk4", 4)])
def test_oscillator_converges_at_the_method_order(odes: SimpleNamespace, method: str,
                                                 order: int) -> None:
    w, grid = 2.0, np.linspace(0.0, 5.0, 11)

    def max_error(h: float) -> float:
        run = fixed_step(method, odes.oscillator, grid, [1.0, 0.0], [w], np.zeros(0), step=h,
                         pairs=[(0, 1)])
        return float(np.abs(run.states[:, 0] - np.cos(w * grid)).max())

    ratio = max_error(0.01) / max_error(0.005)
    assert ratio == pytest.approx(2.0**order, rel=0.1)


def test_verlet_energy_stays_bounded(odes: SimpleNamespace) -> None:
    w, grid = 2.0, np.linspace(0.0, 200.0, 401)
    run = fixed_step("verlet", odes.oscillator, grid, [1.0, 0.0], [w], np.zeros(0),
                     step=0.01, pairs=[(0, 1)], observed=odes.oscillator_energy)
    # velocity Verlet's shadow energy: the drift stays O(h^2), not growing with time
    assert np.abs(run.observed[:, 0] - 0.5 * w**2).max() < 1e-3
    np.testing.assert_array_equal(run.observed[:, 1], grid)
