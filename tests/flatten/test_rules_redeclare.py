"""Restrictions on redeclarations (Modelica 3.6 section 7.3.3): for each rule a valid
model (its balance summary) and an invalid one (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

HELP = ("help: a constant or final element cannot be redeclared, and a redeclaration keeps "
        "the element public or protected (Modelica 3.6, section 7.3.3)")

CASES = {
    "redeclare_element": ("""\
model M
  model A
    replaceable Real x = 2.0;
  protected
    replaceable Real y = 1.0;
  end A;
  extends A;
  redeclare Real x = 3.0;
protected
  redeclare Real y = 4.0;
end M;
""",
        "M: 2 unknowns, 2 equations, 0 parameters: balanced"),
    "constant_element": ("""\
model M
  model A
    replaceable constant Real x = 1.0;
  end A;
  extends A;
  redeclare Real x = 2.0;
end M;
""",
        f"6:18: the constant element 'x' cannot be redeclared\n{HELP}"),
    "final_element": ("""\
model M
  model A
    final replaceable Real x = 2.0;
  end A;
  extends A;
  redeclare Real x = 3.0;
end M;
""",
        f"6:18: the final element 'x' cannot be redeclared\n{HELP}"),
    "protected_to_public": ("""\
model M
  model A
  protected
    replaceable Real x = 2.0;
  end A;
  model B
    extends A;
    redeclare Real x = 3.0;
  end B;
  B b;
end M;
""",
        f"8:20: the protected element 'x' cannot be redeclared public\n{HELP}"),
    "public_to_protected": ("""\
model M
  model A
    replaceable Real x = 2.0;
  end A;
  model B
    extends A;
  protected
    redeclare Real x = 3.0;
  end B;
  B b;
end M;
""",
        f"8:20: the public element 'x' cannot be redeclared protected\n{HELP}"),
    "redeclare_modifier": ("""\
model M
  model A
    replaceable Real x = 1.0;
  end A;
  A a(redeclare Real x = 2.0);
end M;
""",
        "M: 1 unknown, 1 equation, 0 parameters: balanced"),
    "constant_modifier": ("""\
model M
  model A
    replaceable constant Real x = 1.0;
  end A;
  A a(redeclare Real x = 2.0);
end M;
""",
        f"5:7: the constant element 'x' cannot be redeclared\n{HELP}"),
    "final_modifier": ("""\
model M
  model A
    final replaceable Real x = 1.0;
  end A;
  A a(redeclare Real x = 2.0);
end M;
""",
        f"5:7: the final element 'x' cannot be redeclared\n{HELP}"),
    "extends_plain_class": ("""\
model M
  model A
    Real x = 2;
  end A;
  extends A;
end M;
""",
        "M: 1 unknown, 1 equation, 0 parameters: balanced"),
    "extends_replaceable_class": ("""\
model M
  replaceable model A
    Real x = 2;
  end A;
  extends A;
end M;
""",
        "5:11: 'M' extends the replaceable class 'A'\nhelp: a base class is not "
        "replaceable (a redeclaration could change what is inherited) (Modelica 3.6, "
        "section 7.1.4)"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
