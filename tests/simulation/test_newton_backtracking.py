"""A diode behind a resistor whose source rises from 0 to 20 V in about 0.1 ms
(``E = 10 (1 + tanh((t - 0.5) 1e4))``): the torn block ``(E - v)/R = Is (exp(v/Vt) - 1)``
is warm started on the flat side of the diode's knee (``v`` near 0), where Newton's
full step goes to ``v = E``, and ``exp(E/Vt)`` overflows (``exp(800)``). Before the
backtracking of ``codegen.newton_search`` every engine stopped there ("the nonlinear
system for v did not converge at time 0.5", "overflow while computing i"); now a trial
that is not finite is retried 10x shorter, and a block that does not converge keeps
its warm start for the step retried smaller. ``v`` is checked against
``scipy.optimize.brentq`` on the same equation, ``x = integral of i`` against
``scipy.integrate.quad`` of the current computed by ``brentq``."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

import springc
from springc.pipeline import c_library

MODEL = '''\
model DiodeRamp
  parameter Real Is = 1e-14;
  parameter Real Vt = 0.025;
  parameter Real R = 1;
  Real x(start = 0, fixed = true);
  Real E;
  Real v(start = 0);
  Real i;
equation
  E = 10*(1 + tanh((time - 0.5)*1e4));
  der(x) = i;
  i = (E - v)/R;
  i = Is*(exp(v/Vt) - 1);
end DiodeRamp;
'''

IS, VT, R = 1e-14, 0.025, 1.0


def diode_voltage(e: float) -> float:
    """The root of ``(e - v)/R = Is (exp(v/Vt) - 1)`` for ``0 <= e <= 20`` (one root:
    the left side falls, the right side rises; at 1.5 V the diode's current is 1e12 A,
    so the root lies in ``[0, min(e, 1.5)]``), to 1e-15 V."""
    if e == 0.0:
        return 0.0
    f = lambda v: (e - v) / R - IS * math.expm1(v / VT)  # noqa: E731
    return float(brentq(f, 0.0, min(e, 1.5), xtol=1e-15, rtol=1e-15))


def source(t: float) -> float:
    return 10.0 * (1.0 + math.tanh((t - 0.5) * 1e4))


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_overflowing_newton_step_is_shortened(tmp_path: Path, backend: str) -> None:
    # scipy's steps: a point a step tries whose block does not converge rejects the
    # step (the compiled loops stop at the first such point: not tested here)
    path = tmp_path / "DiodeRamp.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend=backend, engine="scipy", stop=1.0,
                              interval=0.25, rtol=1e-9, atol=1e-12, error_control="off")
    times = [float(t) for t in result.time]
    assert times == [0.0, 0.25, 0.5, 0.75, 1.0]
    expected_v = [diode_voltage(source(t)) for t in times]
    assert np.allclose(np.asarray(result["v"]), expected_v, rtol=0, atol=1e-12)
    assert abs(expected_v[-1] - 0.8796735820365846) < 1e-12  # E = 20 V, v past the knee

    def current(t: float) -> float:
        return (source(t) - diode_voltage(source(t))) / R

    def charge(t: float) -> float:  # the ramp's 0.2 ms integrated on its own
        edges = [e for e in (0.0, 0.499, 0.501, t) if e <= t]
        return sum(quad(current, a, b, limit=400, epsabs=1e-13, epsrel=1e-12)[0]
                   for a, b in itertools.pairwise(edges))

    expected_x = [charge(t) for t in times]
    assert np.allclose(np.asarray(result["x"]), expected_x, rtol=1e-7, atol=1e-9)


def test_generated_functions_backtrack_and_keep_the_warm_start(tmp_path: Path) -> None:
    """One evaluation of the derivative at t = 0.75 s (E = 20 V) from the warm start
    v = 0: Python (OverflowError caught), numba and C (inf) each converge to the root;
    from v = 10 V (on the steep side, exp(400) finite: Newton creeps down by about
    Vt per step and runs out of its 200 iterations) the flag is set and the warm
    start is kept (before: the last iterate, near 5 V, was left for the next call)."""
    path = tmp_path / "DiodeRamp.mo"
    path.write_text(MODEL)
    root = diode_voltage(20.0)
    python = springc.compile_model([str(path)], "DiodeRamp", backend="python")
    numba = springc.compile_model([str(path)], "DiodeRamp", backend="numba")
    lib = c_library(python)
    p = python.module.parameters()
    calls = [lambda x, z: python.module.rhs(0.75, x, p, z),
             lambda x, z: numba.module.rhs(0.75, x, p, z),
             lambda x, z: lib.rhs(0.75, x, p, z)[1]]
    for call in calls:
        z = np.array([0.0, 0.0])
        dx = call(np.zeros(1), z)
        assert z[1] == 0.0 and abs(z[0] - root) < 1e-12
        assert abs(float(dx[0]) - (20.0 - root) / R) < 1e-12
        z = np.array([10.0, 0.0])
        call(np.zeros(1), z)
        assert tuple(python.module.NEWTON_SYSTEMS[int(z[1])]) == ("v",) and z[0] == 10.0
