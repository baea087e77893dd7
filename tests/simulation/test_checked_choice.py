"""A static choice of states checked at run time (issue 25): a free body's quaternion
constraint ``Q*Q = 1`` leaves a one-equation dummy-derivative block (``2*Q*der(Q) = 0``)
whose pivot may turn singular. The default choice runs on the generated code while an
assertion per block holds (its pivot at least 0.2 times every other coefficient); a
run whose check fails is run again with dynamic state selection.

References: a body spinning at a constant rate about a principal axis of a spherical
inertia, thrown in gravity: ``Q = {0, 0, sin(w0*t/2), cos(w0*t/2)}`` and a parabola.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc
from springc.ir import expr as x
from springc.simplify import CHECK_MESSAGE, pivot_checks

# MSL's Body with useQuaternions: w = 2*G(Q)*der(Q) (Frames.Quaternions.angularVelocity2)
# and the orientation constraint; Euler's equations of a spherical inertia, no torque.
SPINNING = """model SpinningFreeBody
  parameter Real w0 = 1, g = 9.81;
  Real Q[4](start = {0, 0, 0, 1});
  Real w[3](start = {0, 0, w0}, each fixed = true);
  Real r[3](start = {0, 0, 0}, each fixed = true);
  Real v[3](start = {1, 2, 0}, each fixed = true);
initial equation
  Q[1] = 0; Q[2] = 0; Q[3] = 0;
equation
  w = 2*{Q[4]*der(Q[1]) + Q[3]*der(Q[2]) - Q[2]*der(Q[3]) - Q[1]*der(Q[4]),
         -Q[3]*der(Q[1]) + Q[4]*der(Q[2]) + Q[1]*der(Q[3]) - Q[2]*der(Q[4]),
         Q[2]*der(Q[1]) - Q[1]*der(Q[2]) + Q[4]*der(Q[3]) - Q[3]*der(Q[4])};
  0 = Q*Q - 1;
  der(w) = zeros(3);
  der(r) = v;
  der(v) = {0, -g, 0};
end SpinningFreeBody;
"""


def _spin(tmp_path: Path, stop: float) -> springc.SimulationResult:
    path = tmp_path / "spin.mo"
    path.write_text(SPINNING)
    return springc.simulate(str(path), stop=stop, interval=0.05, rtol=1e-10, atol=1e-12,
                            engine="scipy", error_control="off")


def _closed_form_error(result: springc.SimulationResult) -> float:
    t = result.time
    return max(float(np.max(np.abs(result["Q[3]"] - np.sin(t / 2)))),
               float(np.max(np.abs(result["Q[4]"] - np.cos(t / 2)))),
               float(np.max(np.abs(result["Q[1]"]))),
               float(np.max(np.abs(result["r[1]"] - t))),
               float(np.max(np.abs(result["r[2]"] - (2 * t - 9.81 * t**2 / 2)))))


def test_a_body_turning_one_radian_keeps_its_states_on_the_generated_code(
        tmp_path: Path) -> None:
    result = _spin(tmp_path, 1.0)  # Q[4] >= cos(0.5): the check holds throughout
    assert result.stats.engine_reason == (
        "dop853 ran in scipy's loop, as --engine scipy asks; the states chosen at compile "
        "time stayed well conditioned (checked at every step): no switch of states")
    assert _closed_form_error(result) < 1e-8


def test_a_body_turning_past_the_check_switches_where_the_pivot_is_too_small(
        tmp_path: Path) -> None:
    result = _spin(tmp_path, 3.0)
    # der(Q[4]) is the dummy until |2*Q[4]| = 0.2*|2*Q[3]|: cos(t/2) = 0.2*sin(t/2).
    assert result.stats.reason == (
        f"dynamic state selection, 1 switch (t = {2 * math.atan(5):.6g})")
    assert _closed_form_error(result) < 1e-7


def _rod_block() -> tuple[x.Expr, ...]:
    xs, ys = x.Var("x"), x.Var("y")
    return (x.add(x.mul(xs, x.Var("der(x)")), x.mul(ys, x.Var("der(y)"))),)


def test_the_check_of_a_one_equation_block_compares_its_pivot_with_the_others() -> None:
    span = springc.errors.Span("m.mo", 3, 1, 3, 9)
    checks = pivot_checks([(_rod_block(), ("der(y)", "der(x)"), ("der(y)",), (0, 0),
                            span)])
    assert checks is not None and len(checks) == 1
    assert x.to_text(checks[0].condition) == "noEvent(abs(y) >= 0.2 * abs(x))"
    assert checks[0].message.startswith(CHECK_MESSAGE + ": 'der(y)'")
    assert checks[0].span == span
    # A lower-priority class is not compared; a block of two equations has no check.
    assert pivot_checks([(_rod_block(), ("der(y)", "der(x)"), ("der(y)",), (0, 1),
                          span)]) == ()
    assert pivot_checks([(_rod_block() * 2, ("der(y)", "der(x)", "der(z)"),
                          ("der(y)", "der(x)"), (0, 0, 0), span)]) is None
