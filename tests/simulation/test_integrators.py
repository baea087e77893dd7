"""Fixed-step integrators against closed-form solutions of the harmonic oscillator."""

from __future__ import annotations

import numpy as np
import pytest

from springc.simulation.integrators import NonFiniteState, Pairs, integrate

OMEGA = 2.0


def oscillator(t: float, x: np.ndarray) -> np.ndarray:
    """q' = v, v' = -omega^2 q."""
    return np.array([x[1], -OMEGA**2 * x[0]])


def exact(t: np.ndarray) -> np.ndarray:
    return np.cos(OMEGA * t)  # q(0) = 1, v(0) = 0


PAIRS = Pairs.of([(0, 1)])
TIMES = np.linspace(0.0, 5.0, 51)


def energy(x: np.ndarray) -> np.ndarray:
    return 0.5 * x[:, 1] ** 2 + 0.5 * OMEGA**2 * x[:, 0] ** 2


def max_error(method: str, h: float) -> float:
    result = integrate(method, oscillator, TIMES, np.array([1.0, 0.0]), h, PAIRS)
    return float(np.max(np.abs(result.x[:, 0] - exact(TIMES))))


@pytest.mark.parametrize(("method", "order"), [("symplectic-euler", 1), ("verlet", 2),
                                                 ("rk4", 4), ("euler", 1)])
def test_convergence_order(method: str, order: int) -> None:
    coarse, fine = max_error(method, 0.01), max_error(method, 0.005)
    observed = np.log2(coarse / fine)
    assert abs(observed - order) < 0.25, observed


def test_rk4_accuracy_at_small_step() -> None:
    assert max_error("rk4", 0.001) < 1e-11


def test_verlet_energy_bounded_over_a_thousand_periods() -> None:
    period = 2 * np.pi / OMEGA
    times = np.linspace(0.0, 1e3 * period, 2001)
    h = period / 40
    verlet = integrate("verlet", oscillator, times, np.array([1.0, 0.0]), h, PAIRS)
    euler = integrate("euler", oscillator, times[:50], np.array([1.0, 0.0]), h)
    e0 = energy(verlet.x[:1])[0]
    # Velocity Verlet: the energy error stays O(h^2) and does not grow with time.
    assert np.max(np.abs(energy(verlet.x) - e0)) / e0 < (OMEGA * h) ** 2 / 4
    # Explicit Euler at the same step already gained energy within 50 output points.
    assert energy(euler.x)[-1] > 1.5 * e0


def test_verlet_uses_one_rhs_evaluation_per_step_for_conservative_forces() -> None:
    result = integrate("verlet", oscillator, TIMES, np.array([1.0, 0.0]), 0.01, PAIRS)
    assert result.steps == 500
    assert result.rhs_evaluations == result.steps + 1


def test_output_exactly_at_requested_times_with_uneven_step() -> None:
    result = integrate("rk4", oscillator, TIMES, np.array([1.0, 0.0]), 0.03)
    assert np.array_equal(result.t, TIMES)
    assert result.steps == 50 * 4  # 0.1 / 0.03 rounds up to 4 steps of 0.025


def test_non_finite_state_names_time_and_states() -> None:
    def blows_up(t: float, x: np.ndarray) -> np.ndarray:
        return np.array([x[0] ** 2, 0.0])

    with pytest.raises(NonFiniteState) as info:
        integrate("rk4", blows_up, np.linspace(0, 2, 21), np.array([1.0, 0.0]), 0.1)
    assert info.value.indices.tolist() == [0]
    # The exact solution 1/(1 - t) blows up at t = 1; RK4 at h = 0.1 lags a little.
    assert 1.0 <= info.value.time <= 1.5


def test_invalid_arguments() -> None:
    with pytest.raises(ValueError, match="unknown fixed-step method 'leapfrog'"):
        integrate("leapfrog", oscillator, TIMES, np.array([1.0, 0.0]), 0.1)
    with pytest.raises(ValueError, match="the step must be positive"):
        integrate("rk4", oscillator, TIMES, np.array([1.0, 0.0]), 0.0)
