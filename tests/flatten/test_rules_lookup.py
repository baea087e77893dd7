"""Lookup rules (Modelica 3.6 sections 4.1, 4.6, 5.3.1, 5.3.2, 5.3.3, 5.6.1, 13.2.1): for each
rule a valid model (its balance summary) and an invalid one (the exact error, location and
help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome
from springc.ir import expr as x
from springc.pipeline.files import flatten_files

CASES = {
    "extends_base_of_own_subpackage": ("""\
package P
  package Sub
    model Base
      Real x = 1;
    end Base;
  end Sub;
  model M
    extends Sub.Base;
  end M;
end P;
model Top
  P.M m;
end Top;
""",
        'Top: 1 unknown, 1 equation, 0 parameters: balanced'),
    "outside_encapsulation": ("""\
model M
  constant Real x = 2.0;
  encapsulated model A
    constant Real y = x;
  end A;
  A a;
end M;
""",
        "4:23: undefined name 'x': 'M.A' is encapsulated\nhelp: name lookup stops at an"
        ' encapsulated class; import what it needs (Modelica 3.6, section 5.3.1)'),
    "inside_encapsulation": ("""\
model M
  constant Real x = 2.0;
  model A
    constant Real y = x;
    Real z = y;
  end A;
  A a;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "import_from_model": ("""\
model M
  encapsulated model A
    Real x = 1.0;
  end A;
  model B
    import A2 = M.A;
    A2 a;
  end B;
  B b;
end M;
""",
        "6:5: 'M' is a model, and an import takes classes and constants from packages"
        ' only\nhelp: import from a package, or use the class by its full name (Modelica'
        ' 3.6, section 13.2.1)'),
    "import_from_package": ("""\
package P
  model A
    Real x = 1.0;
  end A;
end P;
model M
  import A2 = P.A;
  A2 a;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "nested_class_of_model": ("""\
model M
  class A
    Real x = 2.0;
    class B
      Real y = 3.0;
    end B;
  end A;
  A.B ab;
end M;
""",
        "8:3: 'B' cannot be looked up inside the class 'M.A' (as 'A.B')\nhelp: inside a"
        ' class that is not a package, lookup finds only its encapsulated elements'
        ' (Modelica 3.6, section 5.3.2)'),
    "encapsulated_class_of_model": ("""\
model M
  class A
    Real x = 2.0;
    encapsulated class B
      Real y = 3.0;
    end B;
  end A;
  A.B ab;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "inside_partial_package": ("""\
model M
  partial package P
    constant Real x = 45.2;
  end P;
  Real y = P.x;
end M;
""",
        "5:14: 'P.x' looks inside the partial package 'M.P'\nhelp: a name cannot be looked"
        ' up inside a partial class (Modelica 3.6, section 5.3.2)'),
    "protected_class_of_package": ("""\
model M
  package P
  protected
    package P2
      constant Real x = 2.3;
    end P2;
  end P;
  Real y = P.P2.x;
end M;
""",
        "8:14: class 'P2' is protected in 'M.P' and cannot be used as 'P.P2'\nhelp: a"
        ' protected element can be used only by its simple name, inside its class and the'
        ' classes extending it, not through a dot from outside (Modelica 3.6, section'
        ' 4.1)'),
    "global_type_and_constant": ("""\
package P
  constant Real c = 2;
  model B
    Real y = 3;
  end B;
end P;
model M
  package P
    constant Real c = 5;
  end P;
  .P.B b;
  Real x = .P.c;
end M;
""",
        'M: 2 unknowns, 2 equations, 0 parameters: balanced'),
    "package_constant": ("""\
model M
  package P
    constant Real p = 4.23;
  end P;
  Real x = P.p;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "package_parameter": ("""\
model M
  package P
    parameter Real p = 4.23;
  end P;
  Real x = P.p;
end M;
""",
        "3:20: a package cannot have a parameter: 'p'\nhelp: a package may contain only"
        ' classes and constants (Modelica 3.6, section 4.6)'),
    "inherited_binding_uses_derived_name": ("""\
model M
  model Base
    Integer x = y;
  end Base;
  model Derived
    Integer y = 2;
    extends Base;
  end Derived;
  Derived d;
end M;
""",
        "3:17: 'y' is not visible in 'M.Base', where this is written\nhelp: names in an"
        ' inherited element are looked up from the class that declares it, not from the'
        ' class extending it (Modelica 3.6, section 5.6.1)'),
    "inherited_binding_uses_own_name": ("""\
model M
  model Base
    parameter Integer y = 2;
    Integer x = y;
  end Base;
  model Derived
    extends Base(y = 3);
  end Derived;
  Derived d;
end M;
""",
        'M: 1 unknown (1 discrete), 1 equation, 1 parameter: balanced'),
    "component_named_as_its_type": ("""\
model M
  type x = Real;
  x x = 1.0;
end M;
""",
        "3:5: the component 'x' has the name of its type 'x'\nhelp: a component hides the"
        ' class of the same name from the lookup of its own type; rename one of them'
        ' (Modelica 3.6, section 5.3.2)'),
    "component_named_as_global_type": ("""\
type x = Real;
model M
  .x x = 1.0;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "redeclare_public_class": ("""\
model M
  model A
    replaceable model B
      Real x = 2.0;
    end B;
    B b;
  end A;
  model C
    Real x = 3.0;
    Real y = 4.0;
  end C;
  A a(redeclare model B = C);
end M;
""",
        "M: 2 unknowns, 2 equations, 0 parameters: balanced"),
    "redeclare_protected_class": ("""\
model M
  model A
  protected
    replaceable model B
      Real x = 2.0;
    end B;
    B b;
  end A;
  model C
    Real x = 3.0;
  end C;
  A a(redeclare model B = C);
end M;
""",
        "12:7: class 'B' is protected in 'M.A' and cannot be redeclared in 'a'\nhelp: a "
        "protected element may be modified only by its own declaration or by an extends "
        "clause (Modelica 3.6, section 4.1)"),
    "unqualified_imports_one_match": ("""\
package P
  constant Real x = 1.0;
end P;
package P2
  constant Real y = 2.0;
  constant Real x = 3.0;
end P2;
model M
  import P.*;
  import P2.*;
  import P2.x;
  Real a = x;
  Real b = y;
end M;
""",
        "M: 2 unknowns, 2 equations, 0 parameters: balanced"),
    "unqualified_imports_conflict": ("""\
package P
  constant Real x = 1.0;
end P;
package P2
  constant Real x = 2.0;
end P2;
model M
  import P.*;
  import P2.*;
  Real y = x;
end M;
""",
        "9:3: 'x' is found by two unqualified imports, in 'P' and 'P2'\nhelp: a name may "
        "be found in only one unqualified import; import it by name (Modelica 3.6, "
        "section 13.2.1.1)"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected


def test_global_names_start_at_the_top_level(tmp_path: Path) -> None:
    """.P.c and .P.B are the top-level package's, not the local P's."""
    path = tmp_path / "m.mo"
    path.write_text(CASES["global_type_and_constant"][0])
    flat = flatten_files([path])
    assert [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in flat.equations] == [
        "b.y = 3", "x = 2"]
