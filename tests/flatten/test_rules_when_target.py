"""A variable assigned in a when-clause is not declared inside a model or block
component (Modelica 3.6 section 4.4.4): valid models (their balance summary, which
leaves out the when-assigned variables) and invalid ones (the exact error, location and
help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

HELP = ("help: a variable assigned in a when-clause shall not be defined in a "
        "sub-component of a model or block; assign it inside that class, or connect to its "
        "input (Modelica 3.6, section 4.4.4)")

CASES = {
    "own_variable": ("""\
model M
  discrete Real x(start = 0, fixed = true);
equation
  when sample(0, 1) then
    x = pre(x) + 1;
  end when;
end M;
""", "M: 1 unknown (1 discrete), 1 equation (1 in when-clauses), 0 parameters: balanced"),
    "record_element": ("""\
model M
  record R
    Real a;
  end R;
  R r(a(start = 0, fixed = true));
equation
  when sample(0, 1) then
    r.a = pre(r.a) + 1;
  end when;
end M;
""", "M: 1 unknown (1 discrete), 1 equation (1 in when-clauses), 0 parameters: balanced"),
    "model_component": ("""\
model M
  model Sub
    discrete Real x;
  end Sub;
  Sub m;
equation
  when sample(0, 1) then
    m.x = 1;
  end when;
end M;
""", "8:5: 'm.x' is assigned in a when-clause but is declared inside 'm', a model "
         f"component\n{HELP}"),
    "block_input": ("""\
model M
  connector RealInput = input Real;
  block B
    discrete RealInput u;
  end B;
  B b;
equation
  when sample(0, 1) then
    b.u = 1;
  end when;
end M;
""", "9:5: 'b.u' is assigned in a when-clause but is declared inside 'b', a block "
         f"component\n{HELP}"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
