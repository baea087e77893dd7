"""Lookup through an outer element and through a component (Modelica 3.6 sections 4.1
and 5.4): an outer element is used through its own declared class; a protected function
of a component's class cannot be called from outside. For each rule a valid model (its
balance summary) and an invalid one (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

RECORDS = """\
  record R
    Real i;
  end R;
  record RI
    extends R;
    Real a;
  end RI;
"""
FUNCTION = """\
    function f
      input Real x;
      output Real y;
    algorithm
      y := 2 * x;
    end f;
"""

CASES = {
    "outer_declared_element": (f"""\
model M
{RECORDS}  model A
    outer R t;
    Real x = t.i;
  end A;
  inner RI t(i = 1, a = 2);
  A a;
end M;
""", "M: 3 unknowns, 3 equations, 0 parameters: balanced"),
    "outer_element_of_inner_only": (f"""\
model M
{RECORDS}  model A
    outer R t;
    Real x = t.a;
  end A;
  inner RI t(i = 1, a = 2);
  A a;
end M;
""", "11:14: 't.a': the outer element 't' is declared of class 'M.R', which has no element "
         "'a'\nhelp: an outer element references only the part of its inner element that "
         "its own declared class has (Modelica 3.6, section 5.4)"),
    "public_function_via_component": (f"""\
model M
  model A
{FUNCTION}  end A;
  A a;
  Real x = a.f(2.0);
end M;
""", "M: 1 unknown, 1 equation, 0 parameters: balanced"),
    "protected_function_via_component": (f"""\
model M
  model A
  protected
{FUNCTION}  end A;
  A a;
  Real x = a.f(2.0);
end M;
""", "12:12: class 'f' is protected in 'M.A' and cannot be used as 'a.f'\nhelp: a "
         "protected element can be used only by its simple name, inside its class and the "
         "classes extending it, not through a dot from outside (Modelica 3.6, section 4.1)"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
