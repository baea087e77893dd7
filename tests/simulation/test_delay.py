"""``delay(expr, delayTime[, delayMax])`` simulated (3.7.4.1): the history of the
delayed expression kept by the run, against closed forms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SimulationError

FEEDBACK = """model Feedback
  parameter Real tau = 1;
  Real x(start = 1, fixed = true);
equation
  der(x) = -delay(x, tau);
  annotation(experiment(StopTime = 3, Interval = 0.05));
end Feedback;
"""

VARYING = """model Varying
  Real d = 0.2 + 0.1 * sin(3 * time);
  Real y = delay(sin(time), d, 0.5);
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
  annotation(experiment(StopTime = 3, Interval = 0.05));
end Varying;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def steps_solution(t: np.ndarray) -> np.ndarray:
    """x' = -x(t - 1), x = 1 before 0: by the method of steps, on [0, 3]."""
    return np.where(t <= 1, 1 - t, np.where(
        t <= 2, 1 - t + (t - 1) ** 2 / 2, 1 - t + (t - 1) ** 2 / 2 - (t - 2) ** 3 / 6))


@pytest.mark.parametrize("solver", ["dop853", "radau"])
def test_delayed_feedback_matches_the_method_of_steps(tmp_path: Path, solver: str) -> None:
    path = tmp_path / "Feedback.mo"
    path.write_text(FEEDBACK)
    result = springc.simulate(str(path), solver=solver, rtol=1e-9)
    assert np.max(np.abs(result["x"] - steps_solution(result.time))) < 1e-6


def test_a_varying_delay_time_bounded_by_delay_max(tmp_path: Path) -> None:
    path = tmp_path / "Varying.mo"
    path.write_text(VARYING)
    result = springc.simulate(str(path), rtol=1e-9)
    t = result.time
    d = 0.2 + 0.1 * np.sin(3 * t)
    # the start value sin(0) = 0 while t - d(t) lies before the start
    expected = np.where(t - d < 0, 0.0, np.sin(t - d))
    assert np.max(np.abs(result["y"] - expected)) < 1e-6


def test_delay_needs_an_adaptive_solver(tmp_path: Path) -> None:
    path = tmp_path / "Feedback.mo"
    path.write_text(FEEDBACK)
    with pytest.raises(SimulationError) as info:
        springc.simulate(str(path), solver="rk4", step=0.01)
    assert (info.value.message, info.value.hint) == (
        "delay() needs an adaptive solver, not rk4",
        "use --solver dop853, rk45, radau or bdf")
