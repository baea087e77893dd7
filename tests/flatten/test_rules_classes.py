"""Class rules (Modelica 3.6 sections 4.2, 4.5.2, 4.6, 4.8, 7.1, 7.1.3, 12.2): for each rule a
valid model (its balance summary) and an invalid one (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

CASES = {
    "extends_model_function": ("""\
model M
  function F
    input Real u;
    output Real y;
  algorithm
    y := u;
  end F;
  model D
    extends F;
  end D;
  D d;
end M;
""",
        "9:13: a model cannot extend a function: 'F' is a function\nhelp: models may"
        ' extend only records, blocks, models or classes (Modelica 3.6, section 7.1.3)'),
    "extends_block_record": ("""\
model M
  record R
    parameter Real k = 2;
  end R;
  block B
    extends R;
    output Real y = k;
  end B;
  B b;
end M;
""",
        'M: 1 unknown, 1 equation, 1 parameter: balanced'),
    "extends_record_block": ("""\
model M
  block B
    Real x = 5.0;
  end B;
  record R
    extends B;
  end R;
  R r;
end M;
""",
        "6:13: a record cannot extend a block: 'B' is a block\nhelp: records may extend"
        ' only records or classes (Modelica 3.6, section 7.1.3)'),
    "extends_local_class": ("""\
model M
  model Base
    Real x = 1;
  end Base;
  model D
    model Base
      Real y = 2;
    end Base;
    extends Base;
  end D;
  D d;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "connector_equation": ("""\
model M
  connector C
    Real e;
    flow Real f;
  equation
    e = 1.0;
  end C;
  C c;
end M;
""",
        '6:5: a connector cannot have equations\nhelp: a connector may have only public'
        ' elements: no equation, algorithm or protected section (Modelica 3.6, section'
        ' 4.6)'),
    "connector_protected": ("""\
model M
  connector C
    Real e = pe;
    flow Real f;
  protected
    constant Real pe = 4.2;
  end C;
  C c;
end M;
""",
        '6:19: a connector cannot have protected elements\nhelp: a connector may have only'
        ' public elements: no equation, algorithm or protected section (Modelica 3.6,'
        ' section 4.6)'),
    "connector_of_model": ("""\
model M
  model A
    Real x = 1.0;
  end A;
  connector C
    Real e = 1.0;
    flow Real f;
    A a;
  end C;
  C c;
end M;
""",
        "8:7: a connector cannot have a component of the model 'M.A'\nhelp: the components"
        ' of a connector may only be of a connector, record or type (Modelica 3.6,'
        ' section 4.6)'),
    "record_equation": ("""\
model M
  record R
    Real x;
  equation
    x = 1.0;
  end R;
  R r;
end M;
""",
        '5:5: a record cannot have equations\nhelp: a record may have only public'
        ' elements: no equation, algorithm or protected section (Modelica 3.6, section'
        ' 4.6)'),
    "record_input": ("""\
model M
  record R
    input Real x = 1.0;
  end R;
  R r;
end M;
""",
        '3:16: a record component cannot be declared `input`\nhelp: the elements of a'
        ' record cannot have the prefixes input, output or flow (Modelica 3.6, section'
        ' 4.6)'),
    "record_protected": ("""\
model M
  record R
    Real x = 1.0;
  protected
    Real y = 2.0;
  end R;
  R r;
end M;
""",
        '5:10: a record cannot have protected elements\nhelp: a record may have only'
        ' public elements: no equation, algorithm or protected section (Modelica 3.6,'
        ' section 4.6)'),
    "block_undirected_connector": ("""\
model M
  connector C
    Real e = 1.0;
    flow Real f;
  end C;
  block B
    C c;
  end B;
  B b;
end M;
""",
        "7:7: 'c' is a connector of a block, but its variable 'e' is neither input nor"
        ' output\nhelp: every variable of a public connector of a block must be an input'
        ' or an output (Modelica 3.6, section 4.6)'),
    "block_directed_connector": ("""\
model M
  connector C
    output Real e;
    input Real f;
  end C;
  block B
    C c(f = 2);
  equation
    c.e = 1;
  end B;
  B b;
end M;
""",
        'M: 2 unknowns, 2 equations, 0 parameters: balanced'),
    "function_public_local": ("""\
model M
  function F
    input Real a;
    output Real b;
    Real c;
  algorithm
    c := a;
    b := c;
  end F;
  Real x = F(2);
end M;
""",
        "5:10: 'c' is a public element of a function but neither input nor output\nhelp:"
        ' the public components of a function must be inputs or outputs; declare the'
        ' others protected (Modelica 3.6, section 12.2)'),
    "function_protected_local": ("""\
model M
  function F
    input Real a;
    output Real b;
  protected
    Real c;
  algorithm
    c := 2 * a;
    b := c;
  end F;
  Real x = F(2);
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "function_assign_input": ("""\
model M
  function F
    input Real a;
    output Real b;
  algorithm
    for i in 1:2 loop
      a := a + 1;
    end for;
    b := a;
  end F;
  Real x = F(2);
end M;
""",
        "7:7: the input 'a' of a function cannot be assigned\nhelp: the inputs of a"
        ' function are read-only (Modelica 3.6, section 12.2)'),
    "reserved_class": ("""\
model M
  class Boolean
    Real x = 1.0;
  end Boolean;
  Boolean b;
end M;
""",
        "2:3: 'Boolean' is a predefined type and cannot be the name of a class\nhelp:"
        ' Real, Integer, Boolean and String are reserved names, like keywords (Modelica'
        ' 3.6, section 4.8)'),
    "reserved_component": ("""\
model M
  Integer Real = 2;
end M;
""",
        "2:11: 'Real' is a predefined type and cannot be the name of a component\nhelp:"
        ' Real, Integer, Boolean and String are reserved names, like keywords (Modelica'
        ' 3.6, section 4.8)'),
    "component_and_class": ("""\
model M
  Real x = 1.0;
  class x end x;
end M;
""",
        "2:8: 'x' is declared twice, as a component and as a class\nhelp: the elements of"
        ' a class must have different names (Modelica 3.6, section 4.2)'),
    "function_two_algorithms": ("""\
model M
  function F
    input Real a;
    output Real b;
  protected
    Real c;
  algorithm
    c := a;
  algorithm
    b := c;
  end F;
  Real x = F(2);
end M;
""",
        '9:3: a function can have at most one `algorithm` section\nhelp: merge the'
        ' statements into one section (Modelica 3.6, section 12.2)'),
    "inherited_class_differs": ("""\
model M
  model Base
    model A
      Real x = 2;
    end A;
  end Base;
  model A
    Real x = 3;
  end A;
  extends Base;
  A a;
end M;
""",
        "7:3: class 'A' is inherited from 'M.Base' and declared here differently\nhelp: an"
        ' inherited element may have the name of a local one only if both are identical'
        ' (Modelica 3.6, section 7.1)'),
    "inherited_class_identical": ("""\
model M
  model Base
    model A
      Real x = 2;
    end A;
  end Base;
  model A
    Real x = 2;
  end A;
  extends Base;
  A a;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "protected_extends": ("""\
model M
  model A
    Real x = 2;
  end A;
  model B
  protected
    extends A;
  end B;
  B b;
  Real y = b.x;
end M;
""",
        "10:14: 'x' is protected in 'M.B' and cannot be accessed as 'b.x'\nhelp: a"
        ' protected element can be used only by its simple name, inside its class and the'
        ' classes extending it, not through a dot from outside (Modelica 3.6, section'
        ' 4.1)'),
    "public_extends": ("""\
model M
  model A
    Real x = 2;
  end A;
  model B
    extends A;
  end B;
  B b;
  Real y = b.x;
end M;
""",
        'M: 2 unknowns, 2 equations, 0 parameters: balanced'),
    "class_extends_model": ("""\
model M
  model Base
    Real x = 1;
  end Base;
  class C
    extends Base;
  end C;
  C c;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "identical_inherited_component": ("""\
model M
  model Base
    Real x = 1;
  end Base;
  model D
    extends Base;
    Real x = 1;
  end D;
  D d;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "different_inherited_component": ("""\
model M
  model Base
    Real x = 1;
  end Base;
  model D
    extends Base;
    Real x = 2;
  end D;
  D d;
end M;
""",
        "7:10: 'x' is declared twice\nhelp: rename one of the components"),
    "extends_array_class_with_component": ("""\
model M
  model A
    Real x = 1.0;
  end A;
  model A3 = A[3];
  model B
    extends A3;
    Real y = 2.0;
  end B;
  B b;
end M;
""",
        "7:5: 'B' extends 'A3', an array class, and cannot have other components,"
        ' equations or base classes\nhelp: a class extending an array class, a class with'
        ' type prefixes or a simple type holds nothing else (Modelica 3.6, section 4.5.2)'),
    "block_extends_type": ("""\
model M
  type Base = Real;
  block Derived
    extends Base;
  end Derived;
  Derived d = 1.0;
end M;
""",
        "4:13: a block cannot extend a type: 'Base' is a type\nhelp: blocks may extend"
        ' only records, blocks or classes (Modelica 3.6, section 7.1.3)'),
    "connector_extends_type": ("""\
model M
  type Voltage = Real(unit = "V");
  connector Pin
    Voltage v;
    flow Real i;
  end Pin;
  connector PosPin
    extends Pin;
  end PosPin;
  PosPin p;
equation
  p.v = 1;
end M;
""",
        'M: 2 unknowns, 2 equations, 0 parameters: balanced'),
    "partial_function_called": ("""\
model M
  partial function F
    input Integer a;
    output Integer b;
  algorithm
    b := a;
  end F;
  Integer x = F(2);
end M;
""",
        "8:15: the partial function 'F' cannot be called\nhelp: a function called in a"
        ' simulation model is not partial (Modelica 3.6, section 12.2)'),
    "function_called": ("""\
model M
  function F
    input Integer a;
    output Integer b;
  algorithm
    b := a;
  end F;
  Integer x = F(2);
end M;
""",
        'M: 1 unknown (1 discrete), 1 equation, 0 parameters: balanced'),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
