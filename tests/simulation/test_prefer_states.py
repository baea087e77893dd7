"""``StateSelect.prefer`` variables are states where the structure allows (Modelica 3.6,
4.8.7.1), as OpenModelica and Dymola choose them: a spring's ``s_rel`` and ``v_rel =
der(s_rel)`` between two masses, rather than the first mass's ``s`` and ``v``. Before,
``v_rel`` could not be a state (no equation differentiates it) and the default ``s1``,
``v1`` were kept. The choice decides what a ``reinit`` keeps: reinit(v2, 0) leaves the
relative motion unchanged (Translational.HeatLosses: massWithStopAndFriction's stop and
springDamper1)."""

from __future__ import annotations

import math
from pathlib import Path

import springc

PREFER_CHAIN = '''\
model PreferChain
  parameter Real m1 = 1, m2 = 1, c = 100;
  Real s1(start = 0), v1(start = 0, fixed = true);
  Real s2(start = 1, fixed = true, stateSelect = StateSelect.always);
  Real v2(start = 0, fixed = true, stateSelect = StateSelect.always);
  Real s_rel(start = 1, fixed = true, stateSelect = StateSelect.prefer);
  Real v_rel(stateSelect = StateSelect.prefer);
  Real f;
equation
  s_rel = s2 - s1;
  v_rel = der(s_rel);
  f = c*s_rel;
  der(s1) = v1;
  m1*der(v1) = f;
  der(s2) = v2;
  m2*der(v2) = -f;
  when time > 0.5 then
    reinit(v2, 0);
  end when;
end PreferChain;
'''


def test_preferred_relative_states_are_chosen_and_survive_a_reinit(tmp_path: Path) -> None:
    path = tmp_path / "PreferChain.mo"
    path.write_text(PREFER_CHAIN)
    model = springc.compile_model([str(path)], "PreferChain", backend="python")
    assert sorted(model.states) == ["s2", "s_rel", "v2", "v_rel"]
    result = springc.simulate(model, engine="scipy", stop=1.0, interval=0.25, rtol=1e-10,
                              atol=1e-12, error_control="off")
    # closed form: the relative motion s_rel = cos(w t), w^2 = c (1/m1 + 1/m2), is
    # untouched by reinit(v2, 0) at 0.5 (s_rel, v_rel are states); the centre of mass
    # moves at -v_rel(0.5) / 2 after it, and v2 = v_cm + v_rel / 2
    w = math.sqrt(200.0)
    assert abs(result["s_rel"][-1] - math.cos(w)) < 1e-6
    v2 = w * math.sin(0.5 * w) / 2 - w * math.sin(w) / 2
    assert abs(result["v2"][-1] - v2) < 1e-6 * w


PREFER_ALGEBRAIC = '''\
model PreferAlgebraic
  Real x(start = 1, fixed = true);
  Real y(stateSelect = StateSelect.prefer);
equation
  der(x) = -x;
  y = x + sin(x);
end PreferAlgebraic;
'''


def test_a_preferred_algebraic_variable_is_not_solved_backwards(tmp_path: Path) -> None:
    # y is a function of the state, not a derivative: x stays the state (making y one
    # would solve y = x + sin(x) for x at every step)
    path = tmp_path / "PreferAlgebraic.mo"
    path.write_text(PREFER_ALGEBRAIC)
    model = springc.compile_model([str(path)], "PreferAlgebraic", backend="python")
    assert model.states == ("x",)
    result = springc.simulate(model, engine="scipy", stop=1.0, interval=0.5, rtol=1e-10,
                              atol=1e-12, error_control="off")
    x = math.exp(-1.0)
    assert abs(result["y"][-1] - (x + math.sin(x))) < 1e-8
