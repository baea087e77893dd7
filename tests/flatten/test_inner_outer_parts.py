"""An ``inner outer`` element (Modelica 3.6, section 5.4) is an outer element for the
references of its own class and an inner element for the outer ones below it; and
names in a function are looked up from the function (its imports, section 13.2).
Exact flat models."""

from __future__ import annotations

from pathlib import Path

from rule_outcome import outcome
from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files


def flat(tmp_path: Path, text: str) -> str:
    path = tmp_path / "m.mo"
    path.write_text(text)
    return format_flat(flatten_files([path]))


def test_inner_outer_is_both(tmp_path: Path) -> None:
    assert flat(tmp_path, """model M
  model Leaf
    outer Boolean on;
    Real x(start = 1, fixed = true);
  equation
    der(x) = if on then -x else 0;
  end Leaf;
  model Group
    Boolean enabled = false;
    inner outer Boolean on = on and enabled;
    Leaf leaf;
  end Group;
  Group group;
  inner Boolean on = true;
  Boolean seen = group.on;
end M;
""") == """model M
  discrete Boolean 'group.enabled';
  discrete Boolean 'group.on';
  Real 'group.leaf.x'(start = 1, fixed = true);
  discrete Boolean on;
  discrete Boolean seen;
equation
  'group.enabled' = false;
  on = true;
  'group.on' = on and 'group.enabled';
  seen = on;
  der('group.leaf.x') = if 'group.on' then -'group.leaf.x' else 0;
end M;
"""


def test_a_function_sees_its_imports(tmp_path: Path) -> None:
    assert flat(tmp_path, """model M
  encapsulated package P
    constant Real c = 2.5;
  end P;
  function f
    import M.P.c;
    input Real u;
    output Real y;
  algorithm
    y := c * u;
  end f;
  Real y = f(time);
end M;
""") == "model M\n  Real y;\nequation\n  y = 2.5 * time;\nend M;\n"


def test_outer_elements_of_two_classes_without_inner(tmp_path: Path) -> None:
    assert outcome(tmp_path, """model M
  model W1
    parameter Real g = 1;
  end W1;
  model W2
    parameter Real g = 2;
  end W2;
  model A
    outer W1 world;
  end A;
  model B
    outer W2 world;
  end B;
  A a;
  B b;
end M;
""") == ("12:14: the outer elements 'world' have no inner element and are of different "
         "classes\nhelp: an inner element is added at the top of the model only for outer "
         "elements of one class (Modelica 3.6, section 5.4)")


FUNCTIONS = """model M
  partial function A
    input Integer u;
    output Integer y;
  end A;
  function B
    extends A;
  algorithm
    y := u;
  end B;
  function C
    extends A;
  algorithm
    y := u + 1;
  end C;
  model D
    outer function fc = A;
    Integer y;
    parameter Integer u = 1;
  equation
    y = fc(u);
  end D;
  model E
    inner function fc = B;
    D d;
  end E;
  model F
    inner function fc = C;
    D d;
  end F;
  E e;
  F f;
end M;
"""


def test_an_outer_function_calls_the_inner_one(tmp_path: Path) -> None:
    assert flat(tmp_path, FUNCTIONS) == """model M
  discrete Integer 'e.d.y';
  parameter Integer 'e.d.u' = 1;
  discrete Integer 'f.d.y';
  parameter Integer 'f.d.u' = 1;
equation
  'e.d.y' = 'e.d.u';
  'f.d.y' = 'f.d.u' + 1;
end M;
"""


def test_an_outer_function_without_inner(tmp_path: Path) -> None:
    text = FUNCTIONS.replace("  E e;\n  F f;\n", "  D d;\n")
    assert outcome(tmp_path, text) == (
        "21:9: the outer class 'M.D.fc' has no inner class 'fc' in an enclosing instance\n"
        "help: declare `inner ... fc = ...` in a model that contains this one (Modelica "
        "3.6, section 5.4)")
