"""The Newton warm starts of a torn block are taken from accepted points only (scipy's
engine, :class:`springc.simulation.steps.Problem`).

A diode behind 100 ohm fed by a source that holds 8 V until the time event at 1 s,
then falls to 0 V along a ramp that ends at a state event (``c < 1002``, ``c`` a
clock that starts at 1000: its large value makes scipy's first step probe far ahead).
The probe of the first step after the time event evaluates at 15.1 s, on the ramp's
branch held past its end (the source at -105 V), where the diode's solution is
``v = -105 V``. Before, that solution stayed the warm start of the next evaluation
(1.013 s, 8 V again): Newton's full step from the flat side of the knee lands near
8 V, from where it creeps down by about ``Vt`` per iteration (exp(320) is finite: no
backtracking) and runs out of its 200 iterations; the step was rejected, retried
from the same warm start, and the run stopped ("the nonlinear system for v did not
converge at time 1") with dop853, rk45, radau and bdf (lsoda, checked too, probes
its first step otherwise). Now the probe's warm starts are
dropped (those of the event iteration kept), and a block that does not converge is
solved again from the last accepted point's warm starts
(:meth:`~springc.simulation.steps.Problem.evaluate`).

``v`` is checked against ``scipy.optimize.brentq`` on the same equation and the
charge ``q`` against ``scipy.integrate.quad`` of the current computed by ``brentq``
(the MSL's HeatingNPN_NORGate and HeatingPNP_NORGate stopped at 85 s of 200 on
the same path: the probe at 99.9 s on V2's falling ramp held past 90 s)."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

import springc
from springc.simulation.steps import Problem, Progress

MODEL = '''\
model ProbeWarmStart
  parameter Real R = 100;
  parameter Real Is = 1e-12;
  parameter Real Vt = 0.025;
  Real c(start = 1000, fixed = true);
  Real q(start = 1000, fixed = true);
  Real u;
  Real v(start = 0.7);
equation
  der(c) = 1;
  u = if time < 1 then 8 else if c < 1002 then 8*(1002 - c) else 0;
  Is*(exp(v/Vt) - 1) = (u - v)/R;
  der(q) = (u - v)/R;
end ProbeWarmStart;
'''

IS, VT, R = 1e-12, 0.025, 100.0


def source(t: float) -> float:
    return 8.0 if t < 1.0 else (8.0 * (2.0 - t) if t < 2.0 else 0.0)


def diode_voltage(u: float) -> float:
    """The root of ``Is (exp(v/Vt) - 1) = (u - v)/R``, in ``[min(u, 0), max(u, 0)]``
    (the left side rises, the right side falls, both 0 at ``v = 0`` where ``u = 0``)."""
    if u == 0.0:
        return 0.0
    f = lambda v: IS * math.expm1(v / VT) - (u - v) / R  # noqa: E731
    return float(brentq(f, min(u, 0.0), max(u, 0.0), xtol=1e-15, rtol=1e-15))


def current(t: float) -> float:
    u = source(t)
    return (u - diode_voltage(u)) / R


def charge(t: float) -> float:
    """``q(t) = 1000 + integral of the current``, by pieces (the source's corners)."""
    edges = [0.0] + [e for e in (1.0, 2.0) if e < t] + [t]
    return 1000.0 + sum(quad(current, a, b, epsabs=1e-13, epsrel=1e-13)[0]
                        for a, b in itertools.pairwise(edges))


@pytest.mark.parametrize("solver", ["dop853", "rk45", "radau", "bdf", "lsoda"])
def test_the_first_steps_probe_leaves_no_warm_start(tmp_path: Path, solver: str) -> None:
    path = tmp_path / "ProbeWarmStart.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", stop=20.0,
                              interval=0.25, solver=solver, rtol=1e-9, atol=1e-9,
                              error_control="off")
    times = [float(t) for t in result.time]
    assert times[-1] == 20.0
    expected_v = [diode_voltage(source(t)) for t in times]
    assert np.allclose(np.asarray(result["v"]), expected_v, rtol=0, atol=1e-11)
    expected_q = [charge(t) for t in times]  # (rtol 1e-9 of q near 1000; bdf: 9e-6)
    assert np.allclose(np.asarray(result["q"]), expected_q, rtol=0, atol=5e-5)
    assert [e.cause for e in result.events if e.kind == "state"] == ["c < 1002"]


def test_a_block_that_fails_is_solved_again_from_the_accepted_warm_start(
        tmp_path: Path) -> None:
    """One evaluation at 1.013 s (7.9 V) from the probe's warm start ``v = -105 V``:
    the generated function alone does not converge (flag set, warm start kept), the
    problem's evaluation converges to the root from the accepted ``v``."""
    path = tmp_path / "ProbeWarmStart.mo"
    path.write_text(MODEL)
    model = springc.compile_model([str(path)], "ProbeWarmStart", backend="python")
    mod = model.module
    p = np.asarray(mod.parameters(), dtype=float)
    problem = Problem(model, p, "dop853", Progress(None, 0.0, 20.0))
    t, x = 1.013, np.array([1001.013, 1000.0])
    root = diode_voltage(8.0 * (1002.0 - 1001.013))
    mod.event_update(t, x.copy(), p, problem.z)  # the relations: u on its ramp
    z = np.array(problem.z)
    z[0] = -105.0
    mod.rhs(t, x, p, z)
    assert z[-1] != 0.0 and z[0] == -105.0  # 200 iterations not enough from there
    problem.z[0] = root + 0.01  # an accepted point's solution, nearby
    problem.accept()
    problem.z[0] = -105.0
    dx = problem.rhs(t, x)
    assert problem.z[-1] == 0.0 and abs(problem.z[0] - root) < 1e-12
    assert abs(float(dx[1]) - (8.0 * (1002.0 - 1001.013) - root) / R) < 1e-14
    assert problem.accepted[0] == root + 0.01
