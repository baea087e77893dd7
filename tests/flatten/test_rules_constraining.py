"""Constraining types and redeclarations (Modelica 3.6 sections 6.4, 7.3.2 and 7.3.3):
for each rule a valid model (its balance summary) and an invalid one (the exact error,
location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome
from springc.ir.expr import Const
from springc.ir.flat import format_equation
from springc.pipeline.files import flatten_files

SUBTYPE = ("help: the type of a replaceable or redeclared element must be a subtype of "
           "its constraining type: every public element of the constraining class present "
           "with a compatible type, and the same number of array dimensions (Modelica 3.6, "
           "section 7.3.2)")
NEW_CONSTRAINT = ("help: a redeclaration's constraining type must be a subtype of the "
                  "constraining type of the element it redeclares (Modelica 3.6, section "
                  "7.3.2)")
REPLACEABLE = ("help: only a replaceable element can be redeclared with a new type (an "
               "element redeclared without `replaceable` is no longer replaceable), and a "
               "final element cannot be redeclared at all (Modelica 3.6, section 7.3.3)")

CLASSES = """\
  model Small
    Real x = 1;
  end Small;
  model Big
    Real x = 2;
    Real y = 3;
  end Big;
"""

CASES = {
    # a replaceable component and its constraining clause
    "component_subtype": (f"""\
model M
{CLASSES}  replaceable Big b constrainedby Small;
end M;
""", "M: 2 unknowns, 2 equations, 0 parameters: balanced"),
    "component_not_subtype": (f"""\
model M
{CLASSES}  replaceable Small s constrainedby Big;
end M;
""", "9:21: 's' is not a subtype of its constraining type 'Big': 'Small' has no public "
         f"element 'y', which 'Big' has\n{SUBTYPE}"),
    "component_dims": ("""\
model M
  type Real3 = Real[3];
  replaceable Real3 x[2] = {{1, 2, 3}, {4, 5, 6}} constrainedby Real3;
end M;
""", "M: 6 unknowns, 6 equations, 0 parameters: balanced"),
    "component_wrong_dims": ("""\
model M
  type Real3 = Real[3];
  type Real23 = Real[2, 3];
  replaceable Real3 x[2] = {{1, 2, 3}, {4, 5, 6}} constrainedby Real23;
end M;
""", "4:21: 'x' is not a subtype of its constraining type 'Real23': 'Real3' has 1 array "
         f"dimension(s), 'Real23' has 2\n{SUBTYPE}"),
    "component_prefix_mismatch": ("""\
model M
  connector In
    input Real u;
  end In;
  connector Out
    output Real u;
  end Out;
  replaceable In c constrainedby Out;
equation
  c.u = 1;
end M;
""", "8:18: 'c' is not a subtype of its constraining type 'Out': its element 'u': "
         f"declared `input` against `output`\n{SUBTYPE}"),
    # replaceable classes, short and long
    "short_class_dims": ("""\
model M
  type Real3 = Real[3];
  replaceable type T = Real3[2] constrainedby Real3;
  T x = {{1, 2, 3}, {4, 5, 6}};
end M;
""", "M: 6 unknowns, 6 equations, 0 parameters: balanced"),
    "short_class_wrong_dims": ("""\
model M
  type Real3 = Real[3];
  type Real23 = Real[2, 3];
  replaceable type T = Real3[2] constrainedby Real23;
  T x = {{1, 2, 3}, {4, 5, 6}};
end M;
""", "4:15: class 'T' is not a subtype of its constraining type 'Real23': 'Real3' has 1 "
         f"array dimension(s), 'Real23' has 2\n{SUBTYPE}"),
    "short_class_not_subtype": (f"""\
model M
{CLASSES}  replaceable model C = Small constrainedby Big;
  C c;
end M;
""", "9:15: class 'C' is not a subtype of its constraining type 'Big': 'Small' has no "
         f"public element 'y', which 'Big' has\n{SUBTYPE}"),
    "long_class_not_subtype": (f"""\
model M
{CLASSES}  replaceable model C
    Real z = 4;
  end C constrainedby Small;
  C c;
end M;
""", "9:15: class 'C' is not a subtype of its constraining type 'Small': 'C' has no "
         f"public element 'x', which 'Small' has\n{SUBTYPE}"),
    "enumeration_not_subtype": ("""\
model M
  type E = enumeration(a, b);
  replaceable type T = Integer constrainedby E;
  T t = 1;
end M;
""", "3:15: class 'T' is not a subtype of its constraining type 'E': 'E' is an "
         f"enumeration type and 'Integer' is not\n{SUBTYPE}"),
    # redeclarations against the constraining type of what they replace
    "redeclare_subtype": (f"""\
model M
{CLASSES}  model H
    replaceable Small s;
  end H;
  H h(redeclare Big s);
end M;
""", "M: 2 unknowns, 2 equations, 0 parameters: balanced"),
    "redeclare_not_subtype_implicit": (f"""\
model M
{CLASSES}  model H
    replaceable Big b;
  end H;
  H h(redeclare Small b);
end M;
""", "12:23: the redeclaration of 'b' is not a subtype of its constraining type 'Big': "
         f"'Small' has no public element 'y', which 'Big' has\n{SUBTYPE}"),
    "redeclare_class_not_subtype": (f"""\
model M
{CLASSES}  model H
    replaceable model D = Big constrainedby Big;
    D d;
  end H;
  H h(redeclare model D = Small);
end M;
""", "13:17: the redeclaration of 'D' is not a subtype of its constraining type 'Big': "
         f"'Small' has no public element 'y', which 'Big' has\n{SUBTYPE}"),
    "new_constraint_not_subtype": (f"""\
model M
{CLASSES}  model H
    replaceable Big b constrainedby Big;
  end H;
  model K
    extends H(replaceable Big b constrainedby Small);
  end K;
  K k;
end M;
""", "13:47: the new constraining type of 'b' is not a subtype of its constraining type "
         f"'Big': 'Small' has no public element 'y', which 'Big' has\n{NEW_CONSTRAINT}"),
    "redeclare_after_new_constraint": (f"""\
model M
{CLASSES}  model H
    replaceable Big b constrainedby Small;
  end H;
  model K
    extends H(replaceable Big b constrainedby Big);
  end K;
  K k(redeclare Small b);
end M;
""", "15:23: the redeclaration of 'b' is not a subtype of its constraining type 'Big': "
         f"'Small' has no public element 'y', which 'Big' has\n{SUBTYPE}"),
    # redeclaring again needs `replaceable`; a final element is never redeclared
    "redeclare_again_replaceable": (f"""\
model M
{CLASSES}  model H
    replaceable Small s;
  end H;
  model K
    extends H(redeclare replaceable Small s);
  end K;
  K k(redeclare Big s);
end M;
""", "M: 2 unknowns, 2 equations, 0 parameters: balanced"),
    "redeclare_again_not_replaceable": (f"""\
model M
{CLASSES}  model H
    replaceable Small s;
  end H;
  model K
    extends H(redeclare Small s);
  end K;
  K k(redeclare Big s);
end M;
""", "15:21: 's' is not replaceable here and cannot be redeclared with another type\n"
         f"{REPLACEABLE}"),
    "redeclare_final_class": (f"""\
model M
{CLASSES}  model H
    final replaceable model D = Small;
    D d;
  end H;
  H h(redeclare model D = Big);
end M;
""", f"13:17: the final element 'D' cannot be redeclared\n{REPLACEABLE}"),
    # a redeclared class keeps its protection
    "redeclare_class_same_protection": (f"""\
model M
{CLASSES}  model H
  protected
    replaceable model D = Small;
  end H;
  model K
    extends H;
  protected
    redeclare model D = Big;
  end K;
  K k;
end M;
""", "M: 0 unknowns, 0 equations, 0 parameters: balanced"),
    "redeclare_protected_class_public": (f"""\
model M
{CLASSES}  model H
  protected
    replaceable model D = Small;
  end H;
  model K
    extends H;
    redeclare model D = Big;
  end K;
  K k;
end M;
""", "15:15: the protected class 'D' cannot be redeclared public\nhelp: a constant or final "
         "element cannot be redeclared, and a redeclaration keeps the element public or "
         "protected (Modelica 3.6, section 7.3.3)"),
    # an inherited protected class stays protected
    "redeclare_inherited_protected_class": ("""\
model M
  model A
    C1 c;
  protected
    replaceable model C1
      Real x = 1;
    end C1;
  end A;
  model B
    extends A;
  end B;
  model C3
    Real x = 3;
  end C3;
  B b(redeclare model C1 = C3);
end M;
""", "15:7: class 'C1' is protected in 'M.B' and cannot be redeclared in 'b'\nhelp: a "
         "protected element may be modified only by its own declaration or by an extends "
         "clause (Modelica 3.6, section 4.1)"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected


def _bindings(folder: Path, text: str) -> dict[str, float]:
    path = folder / "m.mo"
    path.write_text(text)
    model = flatten_files([path])
    return {v.name: float(v.binding.value) for v in model.variables
            if isinstance(v.binding, Const)}


def test_constraining_modifiers_apply(tmp_path: Path) -> None:
    """`constrainedby A(x = 2)` modifies the declaration, under the declaration's own
    modifiers, and in later redeclarations; without a constraining clause the original
    declaration's modifiers apply to a redeclaration (section 7.3.2)."""
    text = """\
model M
  model Small
    parameter Real x = 1;
  end Small;
  model Big
    parameter Real x = 2;
    parameter Real y = 3;
  end Big;
  model H
    replaceable Big b(y = 5) constrainedby Small(x = 4);
    replaceable Small s(x = 6);
  end H;
  H h1;
  H h2(redeclare Big b, redeclare Big s);
end M;
"""
    assert _bindings(tmp_path, text) == {
        "h1.b.x": 4.0, "h1.b.y": 5.0, "h1.s.x": 6.0,
        "h2.b.x": 4.0, "h2.b.y": 3.0, "h2.s.x": 6.0, "h2.s.y": 3.0}


def test_redeclared_function_called_through_a_component(tmp_path: Path) -> None:
    """`b.f(3)` where `b`'s class redeclares `f` in its extends clause calls the new
    function (section 7.3; the suite's Redeclare.Flattening.InheritancePublicClass)."""
    path = tmp_path / "m.mo"
    path.write_text("""\
model M
  model A
    replaceable function f
      input Real u;
      output Real y;
    algorithm
      y := u;
    end f;
  end A;
  model B
    extends A(redeclare function f = g);
  protected
    function g
      input Real u;
      output Real y;
    algorithm
      y := 2 * u;
    end g;
  end B;
  B b;
  Real x = b.f(3);
end M;
""")
    assert [format_equation(eq) for eq in flatten_files([path]).equations] == ["x = 6;"]
