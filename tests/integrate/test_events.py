"""Events inside the compiled loops: crossings located on the dense output (DOP853) or on
split steps (fixed-step methods), time events hit exactly, against closed forms and
scipy's solve_ivp events."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.integrate
from numba import njit

from springc.integrate import Crossings, Status, dop853, fixed_step, run_hybrid

JIT = {"cache": True, "error_model": "numpy"}
NO_Z = np.zeros(0)
GRAVITY, RESTITUTION, HEIGHT = 9.81, 0.8, 1.0


@njit(**JIT)
def falling(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """h' = v, v' = -g (p = [g])."""
    d = np.empty(2)
    d[0] = x[1]
    d[1] = -p[0]
    return d


@njit(**JIT)
def height(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The ball's one crossing: h = 0."""
    g = np.empty(1)
    g[0] = x[0]
    return g


@njit(**JIT)
def relay(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """x' = u, u = p[0] (+1 or -1), held by the relay."""
    d = np.empty(1)
    d[0] = p[0]
    return d


@njit(**JIT)
def relay_thresholds(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """x - 1 (switch off above 1) and x + 1 (switch on below -1)."""
    g = np.empty(2)
    g[0] = x[0] - 1.0
    g[1] = x[0] + 1.0
    return g


@njit(**JIT)
def oscillator(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    d = np.empty(2)
    d[0] = x[1]
    d[1] = -x[0]
    return d


def impact_times(count: int) -> np.ndarray:
    """Closed form: the first impact after a drop from HEIGHT, then flights of 2 e^k v1 / g."""
    t1 = math.sqrt(2 * HEIGHT / GRAVITY)
    v1 = GRAVITY * t1
    flights = [2 * RESTITUTION**k * v1 / GRAVITY for k in range(1, count)]
    return t1 + np.concatenate(([0.0], np.cumsum(flights)))


def bounce(t: float, x: np.ndarray, fired: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    assert fired is not None and fired[0] == -1  # falling through h = 0
    return np.array([x[0], -RESTITUTION * x[1]]), np.array([1.0])


def ball_closed_form(t: np.ndarray, impacts: np.ndarray) -> np.ndarray:
    """The height at times t (before the last impact listed)."""
    v1 = GRAVITY * impacts[0]
    out = HEIGHT - 0.5 * GRAVITY * t**2
    for k, start in enumerate(impacts):
        after = t >= start
        v = RESTITUTION ** (k + 1) * v1
        tau = t[after] - start
        out[after] = v * tau - 0.5 * GRAVITY * tau**2
    return out


@pytest.mark.parametrize("method", ["dop853", "rk4", "verlet"])
def test_bouncing_ball_impact_times_match_the_closed_form(method: str) -> None:
    expected = impact_times(8)
    grid = np.linspace(0.0, expected[-1] + 0.01, 301)
    options = ({"rtol": 1e-10, "atol": 1e-12} if method == "dop853"
               else {"step": 1e-3, "pairs": [(0, 1)]})
    run = run_hybrid(falling, grid, [HEIGHT, 0.0], [GRAVITY], NO_Z, height, [1.0], bounce,
                     method=method, **options)
    assert run.ok and not np.isnan(run.states).any()
    times = np.array([t for t, _ in run.events])
    assert len(times) == 8
    # DOP853 at rtol 1e-10 and rk4/verlet (exact on a constant acceleration) alike
    np.testing.assert_allclose(times, expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(run.states[:, 0], ball_closed_form(grid, expected), atol=1e-8)


def test_bouncing_ball_agrees_with_scipy_events() -> None:
    def ground(t: float, x: np.ndarray) -> float:
        return float(x[0])

    ground.terminal = True  # type: ignore[attr-defined]
    ground.direction = -1  # type: ignore[attr-defined]
    t, x, scipy_times = 0.0, np.array([HEIGHT, 0.0]), []
    while len(scipy_times) < 5:
        sol = scipy.integrate.solve_ivp(lambda s, y: falling(s, y, np.array([GRAVITY]), NO_Z),
                                        (t, 10.0), x, method="DOP853", rtol=1e-10,
                                        atol=1e-12, events=ground)
        t = float(sol.t_events[0][0])
        scipy_times.append(t)
        x = np.array([0.0, -RESTITUTION * sol.y_events[0][0][1]])
    grid = np.linspace(0.0, scipy_times[-1] + 0.01, 11)
    run = run_hybrid(falling, grid, [HEIGHT, 0.0], [GRAVITY], NO_Z, height, [1.0], bounce,
                     rtol=1e-10, atol=1e-12, max_events=5)
    ours = np.array([t for t, _ in run.events])
    np.testing.assert_allclose(ours, scipy_times, rtol=0, atol=1e-9)


def test_one_kernel_call_stops_at_the_crossing_with_the_left_limit() -> None:
    grid = np.linspace(0.0, 1.0, 11)
    run = dop853(falling, grid, [HEIGHT, 0.0], [GRAVITY], NO_Z, rtol=1e-10, atol=1e-12,
                 crossings=Crossings(height, [1.0]))
    t1 = impact_times(1)[0]
    assert run.status == Status.STATE_EVENT and list(run.fired) == [-1]
    assert t1 <= run.event_time <= t1 + 1e-11  # the right end of the bracket
    assert run.event_state[0] <= 0 and run.event_state[1] == pytest.approx(-GRAVITY * t1,
                                                                          rel=1e-10)
    assert run.filled == 5 and grid[run.filled - 1] < run.event_time < grid[run.filled]
    np.testing.assert_allclose(run.states[:5, 0], HEIGHT - 0.5 * GRAVITY * grid[:5]**2,
                               atol=1e-12)


def test_a_held_sign_on_the_wrong_side_at_the_start_does_not_fire() -> None:
    # a restart just below the ground moving up (the left limit after a bounce)
    run = dop853(falling, [0.0, 1.0], [-1e-13, 3.0], [GRAVITY], NO_Z, rtol=1e-10,
                 atol=1e-12, crossings=Crossings(height, [1.0]))
    assert run.status == Status.STATE_EVENT
    assert run.event_time == pytest.approx(2 * 3.0 / GRAVITY, abs=1e-9)  # the next landing


def test_direction_filter_ignores_the_other_crossings() -> None:
    # the oscillator's x = cos t crosses 0 falling at pi/2 and rising at 3 pi/2
    both = dop853(oscillator, [0.0, 6.0], [1.0, 0.0], [], NO_Z, rtol=1e-10, atol=1e-12,
                  crossings=Crossings(height, [1.0]))
    rising = dop853(oscillator, [0.0, 6.0], [1.0, 0.0], [], NO_Z, rtol=1e-10, atol=1e-12,
                    crossings=Crossings(height, [1.0], [1.0]))
    held_negative = dop853(oscillator, [0.0, 6.0], [1.0, 0.0], [], NO_Z, rtol=1e-10,
                           atol=1e-12, crossings=Crossings(height, [-1.0]))
    assert both.event_time == pytest.approx(math.pi / 2, abs=1e-9)
    assert rising.status == Status.SUCCESS  # held +1: only a falling crossing can fire
    assert held_negative.event_time == pytest.approx(3 * math.pi / 2, abs=1e-9)
    assert list(held_negative.fired) == [1]


@pytest.mark.parametrize("method", ["dop853", "rk4", "symplectic-euler"])
def test_relay_switches_at_its_thresholds(method: str) -> None:
    p = np.array([1.0])

    def switch(t: float, x: np.ndarray, fired: np.ndarray | None
               ) -> tuple[np.ndarray, np.ndarray]:
        assert fired is not None
        p[0] = -1.0 if fired[0] == 1 else 1.0  # off above 1, on below -1
        return x, np.array([-1.0, 1.0])

    grid = np.linspace(0.0, 8.0, 81)
    options = {"rtol": 1e-10, "atol": 1e-12} if method == "dop853" else {"step": 0.03}
    run = run_hybrid(relay, grid, [0.0], p, NO_Z, relay_thresholds, [-1.0, 1.0], switch,
                     method=method, directions=[1.0, -1.0], **options)
    times = [t for t, _ in run.events]
    # each located within ~1e-12 relative (the right end of the bracket): errors add up
    np.testing.assert_allclose(times, [1.0, 3.0, 5.0, 7.0], atol=5e-11)
    assert [list(f) for _, f in run.events] == [[1, 0], [0, -1], [1, 0], [0, -1]]
    triangle = 1 - np.abs((grid + 1) % 4 - 2)  # 0 -> 1 at t = 1 -> -1 at t = 3 -> ...
    np.testing.assert_allclose(run.states[:, 0], triangle, atol=1e-10)


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_time_event_ends_a_step_on_it_and_the_run_goes_on(method: str) -> None:
    grid = np.linspace(0.0, 6.0, 61)
    options = {"rtol": 1e-10, "atol": 1e-12} if method == "dop853" else {"step": 0.01}
    call = (lambda **kw: dop853(oscillator, grid, [1.0, 0.0], [], NO_Z, **options, **kw)) \
        if method == "dop853" else \
        (lambda **kw: fixed_step(method, oscillator, grid, [1.0, 0.0], [], NO_Z, **options,
                                 **kw))
    run = call(t_stop=2.5)
    assert run.status == Status.TIME_EVENT and run.event_time == 2.5
    np.testing.assert_allclose(run.event_state, [math.cos(2.5), -math.sin(2.5)], atol=1e-9)
    assert run.filled == 25  # output times before 2.5 (2.5 itself is the caller's)
    np.testing.assert_allclose(run.states[:25, 0], np.cos(grid[:25]), atol=1e-9)
    kicked = run_hybrid(oscillator, grid, [1.0, 0.0], [], NO_Z, None, [],
                        lambda t, x, fired: (x + np.array([0.0, 1.0]), np.empty(0)),
                        method=method, time_events=[2.5], **options)
    # x = cos t until 2.5, then a velocity kick of +1: x = cos t + sin(t - 2.5)
    expected = np.cos(grid) + np.where(grid >= 2.5, np.sin(grid - 2.5), 0.0)
    assert kicked.ok and kicked.events[0] == (2.5, None)
    np.testing.assert_allclose(kicked.states[:, 0], expected, atol=1e-8)
