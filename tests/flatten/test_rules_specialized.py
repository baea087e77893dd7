"""Rules on the elements of specialized classes (Modelica 3.6 section 4.6): for each rule
a valid model (its balance summary) and an invalid one (the exact error, location and
help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

CASES = {
    "record_inner": ("""\
model M
  record R
    inner Real x = 1.0;
  end R;
  R r;
end M;
""",
        "3:16: a record component cannot be declared `inner`\nhelp: the elements of a "
        "record cannot have the prefixes inner or outer (Modelica 3.6, section 4.6)"),
    "record_outer": ("""\
model M
  record R
    outer Real x;
  end R;
  inner Real x = 1.0;
  R r;
end M;
""",
        "3:16: a record component cannot be declared `outer`\nhelp: the elements of a "
        "record cannot have the prefixes inner or outer (Modelica 3.6, section 4.6)"),
    "connector_inner": ("""\
model M
  connector C
    inner Real e = 2.54;
    flow Real f;
  end C;
  C c;
end M;
""",
        "3:16: a connector component cannot be declared `inner`\nhelp: the elements of a "
        "connector cannot have the prefixes inner or outer (Modelica 3.6, section 4.6)"),
    "model_inner_outer": ("""\
model M
  model Sub
    outer Real x;
    Real y = 2 * x;
  end Sub;
  record R
    Real x = 1.0;
  end R;
  inner Real x = 1.0;
  R r;
  Sub s;
end M;
""",
        "M: 3 unknowns, 3 equations, 0 parameters: balanced"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
