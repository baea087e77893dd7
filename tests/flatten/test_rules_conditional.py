"""Conditional components are only modified and connected (Modelica 3.6 section
4.4.5): valid models (their balance summary) and invalid ones (the exact error, location
and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

HELP = ("help: a component declared with a condition (`if ...`) may only be modified and "
        "used in connect equations (Modelica 3.6, section 4.4.5)")

CASES = {
    "connected_and_modified": ("""\
model M
  connector P
    Real v;
    flow Real i;
  end P;
  model Load
    parameter Real R = 1;
    P p;
  equation
    p.v = R * p.i;
  end Load;
  parameter Boolean use = true;
  Load load(R = 2) if use;
  Load other;
equation
  connect(load.p, other.p);
end M;
""",
        "M: 4 unknowns, 4 equations, 3 parameters: balanced"),
    "in_equation": ("""\
model M
  Real x if true;
equation
  x = 2.0;
end M;
""",
        f"4:3: the conditional component 'x' is used outside a connect equation\n{HELP}"),
    "in_algorithm": ("""\
model M
  Real x if true;
algorithm
  x := 2.0;
end M;
""",
        f"4:3: the conditional component 'x' is used outside a connect equation\n{HELP}"),
    "in_modifier": ("""\
model M
  model A
    Real y = 1.0;
  end A;
  Real x = 3.0 if true;
  A a(y = x);
end M;
""",
        f"6:11: the conditional component 'x' is used outside a connect equation\n{HELP}"),
    "in_call": ("""\
model M
  model A
    function f
      input Real x;
      output Real y;
    algorithm
      y := x;
    end f;
  end A;
  A a if true;
  Real x = a.f(2.0);
end M;
""",
        f"11:12: the conditional component 'a' is used outside a connect equation\n{HELP}"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
