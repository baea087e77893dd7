"""An ideal switch in a loop (the MSL's ``v = s*(if off then 1 else Ron)``,
``i = s*(if off then Goff else 1)``) makes a loop linear in its unknowns whatever the
switch's state: the derivative of ``s*(if off then 1 else Ron)`` by ``s`` folds to the
if-expression, its ``s*(if off then 0 else 0)`` term to zero. Such a loop is one linear
solve per evaluation, not Newton iterations (Electrical.Analog.Examples.CauerLowPassSC:
eleven switched capacitors in every right-hand side)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc
from springc.ir import ode
from springc.pipeline.files import flatten_files
from springc.simplify.passes import simplify

MODEL = '''\
model SwitchedRC
  parameter Real V0 = 1;
  parameter Real R = 1;
  parameter Real C = 0.5;
  parameter Real Ron = 1e-2;
  parameter Real Goff = 0.25;
  Real vC(start = 0, fixed = true);
  Real i;
  Real v "the switch's voltage";
  Real s;
  Boolean off(start = false, fixed = true);
equation
  when sample(0.5, 0.5) then
    off = not pre(off);
  end when;
  V0 - v - vC = R*i;
  v = s*(if off then 1 else Ron);
  i = s*(if off then Goff else 1);
  C*der(vC) = i;
end SwitchedRC;
'''

V0, R, C, RON, GOFF, HALF = 1.0, 1.0, 0.5, 1e-2, 0.25, 0.5


def capacitor(t: float) -> float:
    """The closed form: from 0, a charge through ``R + Ron`` (closed) and ``R + 1/Goff``
    (open) in turn, the switch toggling every 0.5 s from 0.5 s."""
    v, start, closed = 0.0, 0.0, True
    while start + HALF <= t:
        tau = (R + (RON if closed else 1 / GOFF)) * C
        v = V0 + (v - V0) * math.exp(-HALF / tau)
        start, closed = start + HALF, not closed
    tau = (R + (RON if closed else 1 / GOFF)) * C
    return V0 + (v - V0) * math.exp(-(t - start) / tau)


def test_the_switch_loop_is_a_linear_block(tmp_path: Path) -> None:
    path = tmp_path / "SwitchedRC.mo"
    path.write_text(MODEL)
    steps = simplify(flatten_files([path], "SwitchedRC")).ode.steps
    linear = [s for s in steps if isinstance(s, ode.LinearBlock)]
    assert [sorted(s.names) for s in linear] == [["i", "s", "v"]]
    assert not [s for s in steps if isinstance(s, ode.NonlinearBlock)]


def test_the_capacitor_after_five_switchings_is_the_closed_form(tmp_path: Path) -> None:
    path = tmp_path / "SwitchedRC.mo"
    path.write_text(MODEL)
    result = springc.simulate(str(path), backend="python", engine="scipy", solver="radau",
                              stop=2.9, interval=0.1, rtol=1e-9, atol=1e-12,
                              error_control="off")
    times = np.asarray(result.time)
    expected = [capacitor(float(t)) for t in times]
    assert np.allclose(np.asarray(result["vC"]), expected, rtol=0, atol=1e-7)
    assert capacitor(2.9) > 0.5  # charged: the check is not of a constant
    assert result.stats.time_events == 5


def test_the_switch_loop_keeps_one_matrix_per_switch_state(tmp_path: Path) -> None:
    """The python backend keeps the block's matrix and inverse per value of its
    entries (codegen/linear_cache.py): the switch is open or closed, two matrices, and
    the run on them is the closed form above."""
    path = tmp_path / "SwitchedRC.mo"
    path.write_text(MODEL)
    model = springc.compile_model([str(path)], "SwitchedRC", backend="python")
    kept = model.module._LINEAR_FACTORS  # type: ignore[attr-defined]
    kept.clear()
    result = springc.simulate(model, engine="scipy", solver="radau", stop=1.2,
                              interval=0.1, rtol=1e-9, atol=1e-12, error_control="off")
    assert [len(matrices) for matrices in kept.values()] == [2]
    (matrices,) = kept.values()
    # row 1 is v = s*(if off then 1 else Ron): the coefficient of s, open and closed
    assert sorted(-a[1, 2] for a, _ in matrices.values()) == [RON, 1.0]
    for a, inverse in matrices.values():
        assert np.allclose(inverse @ a, np.eye(3), rtol=0, atol=1e-12)
    assert np.allclose(np.asarray(result["vC"]),
                       [capacitor(float(t)) for t in result.time], rtol=0, atol=1e-7)


MOVING = '''\
model Moving
  Real x(start = 1, fixed = true);
  Real y;
  Real w;
equation
  der(x) = -y;
  x*y + w = 1;
  y - 2*w = 0;
end Moving;
'''


def test_a_matrix_that_reads_a_state_is_solved_at_every_evaluation(tmp_path: Path) -> None:
    """``x*y + w = 1``, ``y = 2 w``: the matrix reads the state ``x``, nothing is kept;
    ``y = 1/(x + 1/2)``, so ``x = sqrt(9/4 - 2t) - 1/2``."""
    path = tmp_path / "Moving.mo"
    path.write_text(MOVING)
    steps = simplify(flatten_files([path], "Moving")).ode.steps
    assert [sorted(s.names) for s in steps if isinstance(s, ode.LinearBlock)] == [["w", "y"]]
    model = springc.compile_model([str(path)], "Moving", backend="python")
    assert not hasattr(model.module, "_LINEAR_FACTORS")
    result = springc.simulate(model, engine="scipy", solver="radau", stop=1.0, interval=0.25,
                              rtol=1e-10, atol=1e-12, error_control="off")
    times = np.asarray(result.time)
    assert np.allclose(np.asarray(result["x"]), np.sqrt(2.25 - 2 * times) - 0.5, rtol=0,
                       atol=1e-7)


STUCK = '''\
model Stuck
  parameter Real Goff = 0;
  Real q(start = 0, fixed = true);
  Real i;
  Real s1;
  Real s2;
  Real v1;
  Real v2;
  Boolean off = time >= 0.5;
equation
  v1 = s1*(if off then 1 else 0);
  i = s1*(if off then Goff else 1);
  v2 = s2*(if off then 1 else 0);
  i = s2*(if off then Goff else 1);
  1 - v1 - v2 = 2*i;
  der(q) = i;
end Stuck;
'''


def test_two_open_switches_in_series_share_the_voltage_as_the_torn_blocks_did(
        tmp_path: Path) -> None:
    """Two ideal switches (Ron = 0, Goff = 0) in series with 2 ohms across 1 V: closed,
    ``i = 0.5``; open, the kept matrix is singular but consistent (``s1 + s2 = 1``): the
    basic solution, as the torn blocks' Newton step gives, one switch takes the voltage;
    the charge ``q`` stops at 0.25."""
    path = tmp_path / "Stuck.mo"
    path.write_text(STUCK)
    model = springc.compile_model([str(path)], "Stuck", backend="python")
    kept = model.module._LINEAR_FACTORS  # type: ignore[attr-defined]
    kept.clear()
    result = springc.simulate(model, engine="scipy", solver="radau", stop=1.0,
                              interval=0.25, rtol=1e-9, atol=1e-12, error_control="off")
    (matrices,) = kept.values()
    assert sorted(inverse is None for _, inverse in matrices.values()) == [False, True]
    assert np.allclose(np.asarray(result["q"]), [0.0, 0.125, 0.25, 0.25, 0.25],
                       rtol=0, atol=1e-9)
    assert np.allclose(np.asarray(result["i"]), [0.5, 0.5, 0.0, 0.0, 0.0], rtol=0, atol=1e-9)
    v1, v2 = np.asarray(result["v1"])[2:], np.asarray(result["v2"])[2:]
    assert np.allclose(v1 + v2, 1.0, rtol=0, atol=1e-12)
    assert np.allclose(v1 * v2, 0.0, rtol=0, atol=1e-12)
