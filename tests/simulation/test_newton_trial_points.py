"""A nonlinear system that does not converge at a point a step only tries rejects the
step, which the integrator retries smaller, instead of stopping the run (scipy's
engine; established tools do the same). Between events a relation is held, and past
the point where it switches the held branch's equations may have no solution: the
thermal loop of Electrical.Analog.Examples.HeatingRectifier's diode, whose held
``exlin`` branch is exponential where the diode starts to conduct."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc

MODEL = '''\
model HeldBranch
  Real x(start = 0, fixed = true);
  Real z(start = 0, fixed = true);
  Real y(start = 1);
equation
  der(x) = 1;
  y*y = if x < 1 then 1.01 - x else 0.01;
  der(z) = y;
end HeldBranch;
'''


def z_exact(t: float) -> float:
    """z = integral of sqrt(1.01 - s) up to t <= 1, then 0.1 per second."""
    if t <= 1.0:
        return 2.0 / 3.0 * (1.01 ** 1.5 - (1.01 - t) ** 1.5)
    return z_exact(1.0) + 0.1 * (t - 1.0)


@pytest.mark.parametrize("solver", ["dop853", "rk45", "radau"])
def test_a_failing_trial_point_rejects_the_step(tmp_path: Path, solver: str) -> None:
    # (before: "the nonlinear system for y did not converge at time 1.1111")
    path = tmp_path / "HeldBranch.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=6.0,
                              interval=0.5, solver=solver, rtol=1e-3, atol=1e-3,
                              error_control="off")
    times = np.asarray(result.time)
    expected = [z_exact(float(t)) for t in times]
    assert np.allclose(np.asarray(result["z"]), expected, rtol=0, atol=1e-4)
    assert [e.cause for e in result.events if e.kind == "state"] == ["x < 1"]



INFINITE = '''\
model HeldOverflow
  parameter Real big = 1e308;
  Real x(start = 0, fixed = true);
  Real z(start = 0, fixed = true);
equation
  der(x) = 1;
  der(z) = if x < 1 then 1.01 - x + noEvent(max(x - 1.01, 0))*big*big else 0.01;
end HeldOverflow;
'''


def z_linear(t: float) -> float:
    """z = 1.01 t - t^2/2 up to t <= 1, then 0.01 per second."""
    return 1.01 * t - t * t / 2 if t <= 1.0 else 0.51 + 0.01 * (t - 1.0)


@pytest.mark.parametrize("solver", ["dop853", "rk45"])
def test_a_non_finite_trial_point_rejects_the_step(tmp_path: Path, solver: str) -> None:
    # (the held branch overflows past x = 1.01: before, "der(z) is infinite at time
    # 1.1111" at a point only a step tried)
    path = tmp_path / "HeldOverflow.mo"
    path.write_text(INFINITE)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=6.0,
                              interval=0.5, solver=solver, rtol=1e-3, atol=1e-3,
                              error_control="off")
    expected = [z_linear(float(t)) for t in np.asarray(result.time)]
    assert np.allclose(np.asarray(result["z"]), expected, rtol=0, atol=1e-6)


RAISING = INFINITE.replace("HeldOverflow", "HeldExp").replace(
    "noEvent(max(x - 1.01, 0))*big*big", "exp(noEvent(max(x - 1.01, 0))*big) - 1")


def test_an_overflow_at_a_trial_point_rejects_the_step(tmp_path: Path) -> None:
    # (the python backend raises OverflowError in exp past x = 1.01: before,
    # "overflow while computing der(z)" at a point only a step tried)
    path = tmp_path / "HeldExp.mo"
    path.write_text(RAISING)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=6.0,
                              interval=0.5, solver="dop853", rtol=1e-3, atol=1e-3,
                              error_control="off")
    expected = [z_linear(float(t)) for t in np.asarray(result.time)]
    assert np.allclose(np.asarray(result["z"]), expected, rtol=0, atol=1e-6)
