"""A Real declared discrete is assigned only in when-clauses, so it has no binding
equation (Modelica 3.6 section 4.4.4): a valid model (its balance summary) and invalid
ones (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

HELP = ("help: a Real declared discrete is assigned only in when-clauses; give its initial "
        "value with `start` instead (Modelica 3.6, section 4.4.4)")

CASES = {
    "assigned_in_when": ("""\
model M
  discrete Real x(start = 1.0, fixed = true);
  parameter Integer n = 2;
  discrete Integer k = n;
equation
  when sample(0.0, 1.0) then
    x = pre(x) + 1.0;
  end when;
end M;
""",
        "M: 2 unknowns (2 discrete), 2 equations (1 in when-clauses), 1 parameter: balanced"),
    "binding": ("""\
model M
  discrete Real x = 1.0;
end M;
""",
        f"2:21: the discrete Real 'x' cannot have a binding equation\n{HELP}"),
    "binding_in_a_component": ("""\
model M
  model A
    discrete Real y = time;
  end A;
  A a;
end M;
""",
        f"3:23: the discrete Real 'y' cannot have a binding equation\n{HELP}"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
