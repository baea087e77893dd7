"""Connection rules (Modelica 3.6 sections 9.3 and 9.3.1): for each rule a valid model (its
balance summary) and an invalid one (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

CASES = {
    "connect_same_types": ("""\
model M
  connector Pin
    Real v;
    flow Real i;
  end Pin;
  connector IntPin
    Integer v;
    flow Real i;
  end IntPin;
  model Part
    Pin p;
  equation
    p.v = p.i;
  end Part;
  Part a, b;
equation
  connect(a.p, b.p);
end M;
""",
        'M: 4 unknowns, 4 equations, 0 parameters: balanced'),
    "connect_real_to_integer": ("""\
model M
  connector Pin
    Real v;
    flow Real i;
  end Pin;
  connector IntPin
    Integer v;
    flow Real i;
  end IntPin;
  model Two
    Pin p;
    IntPin q;
  end Two;
  Two t;
equation
  connect(t.p, t.q);
  t.p.v = 1;
  t.p.i = 2;
end M;
""",
        "16:3: cannot connect 't.p' and 't.q': 'v' is a Real in one and an Integer in the"
        ' other\nhelp: connected variables must have the same primitive type (Modelica'
        ' 3.6, section 9.3)'),
    "connect_constant_to_parameter": ("""\
model M
  connector C1
    constant Real x = 1.0;
    Real e;
    flow Real f;
  end C1;
  connector C2
    parameter Real x = 1.0;
    Real e;
    flow Real f;
  end C2;
  model Two
    C1 c1;
    C2 c2;
  end Two;
  Two t;
equation
  connect(t.c1, t.c2);
  t.c1.e = 1.0;
  t.c1.f = 2.0;
end M;
""",
        "18:3: cannot connect 't.c1' and 't.c2': 'x' is a constant in one and a parameter"
        ' in the other\nhelp: connect may join parameters only to parameters and constants'
        ' only to constants (Modelica 3.6, section 9.3)'),
    "connect_different_constants": ("""\
model M
  connector C
    Real e;
    flow Real f;
    constant Real c;
  end C;
  model Two
    C c1(c = 1.0), c2(c = 2.0);
  end Two;
  Two t;
equation
  connect(t.c1, t.c2);
  t.c1.e = 1.0;
  t.c1.f = 3.0;
end M;
""",
        "12:3: cannot connect 't.c1' and 't.c2': the constant 'c' has different values\n"
        'help: connected constants must have the same value (Modelica 3.6, section 9.3)'),
    "connect_equal_constants": ("""\
model M
  connector C
    Real e;
    flow Real f;
    constant Real c;
  end C;
  model Two
    C c1(c = 1.0), c2(c = 1.0);
  end Two;
  Two t;
equation
  connect(t.c1, t.c2);
  t.c1.e = 1.0;
  t.c1.f = 3.0;
end M;
""",
        'M: 4 unknowns, 4 equations, 0 parameters: balanced'),
    "connect_causal_to_acausal": ("""\
model M
  connector C1
    input Real x;
  end C1;
  connector C2
    Real x;
  end C2;
  model Two
    C1 c1;
    C2 c2;
  end Two;
  Two t;
equation
  connect(t.c1, t.c2);
  t.c1.x = 3.0;
end M;
""",
        "14:3: cannot connect 't.c1' and 't.c2': 'x' is causal (input) in one but not in"
        ' the other\nhelp: input and output variables connect only to input or output'
        ' variables (Modelica 3.6, section 9.3)'),
    "connect_output_to_input": ("""\
model M
  connector Out
    output Real y;
  end Out;
  connector In
    input Real y;
  end In;
  block Source
    Out o(y = 2);
  end Source;
  block Gain
    In i;
    Out o(y = 3 * i.y);
  end Gain;
  Source s;
  Gain g;
equation
  connect(s.o, g.i);
end M;
""",
        'M: 3 unknowns, 3 equations, 0 parameters: balanced'),
    "connect_two_inside_outputs": ("""\
model M
  connector Out
    output Real y;
  end Out;
  block Source
    Out o(y = 2);
  end Source;
  Source s1, s2;
equation
  connect(s1.o, s2.o);
end M;
""",
        "10:3: a connection set has 2 sources of its signal: 's1.o.y' (inside output),"
        " 's2.o.y' (inside output)\nhelp: a set of connected inputs and outputs may"
        ' contain at most one inside output or one public outside input (Modelica 3.6,'
        ' section 9.3)'),
    "connector_parameter": ("""\
model M
  connector C
    input Real x = 1.0;
  end C;
  parameter C c;
end M;
""",
        "5:15: the connector 'c' cannot be declared `parameter`\nhelp: a connector"
        ' component cannot be a parameter or a constant (Modelica 3.6, section 9.3)'),
    "connector_size": ("""\
model M
  record R
    Real x = 1.0;
    Real y = 2.0;
  end R;
  connector C
    R e;
    flow Real f;
  end C;
  C c;
end M;
""",
        "10:5: connector 'c' (M.C) has 1 flow and 2 potential variables\nhelp: a connector"
        ' has as many flow variables as variables that are neither parameter, constant,'
        ' input, output nor flow (Modelica 3.6, section 9.3.1)'),
    "connect_component_connectors": ("""\
model M
  connector C
    Real e;
    flow Real f;
  end C;
  connector Pair
    C x;
    C y;
  end Pair;
  model B
    C c1;
    Pair p;
  equation
    c1.e = 1.0;
    p.x.e = 2.0;
    p.y.e = 3.0;
  end B;
  B b;
  C c;
  Pair q;
equation
  connect(b.c1, c);
  connect(b.p.x, q.y);
  q.x.e = 4.0;
end M;
""",
        "M: 12 unknowns, 12 equations, 0 parameters: balanced"),
    "connect_too_deep": ("""\
model M
  connector C
    Real e;
    flow Real f;
  end C;
  model A
    model B
      C c1;
      C c2;
    end B;
    B b;
  end A;
  A a;
equation
  connect(a.b.c1, a.b.c2);
  a.b.c1.e = 1.0;
  a.b.c1.f = 2.0;
end M;
""",
        "15:11: 'a.b.c1' cannot be connected here: 'a.b' is a component of 'a', not a "
        "connector\nhelp: a connect equation joins connectors of the class or of its "
        "components (`m.c`), not connectors deeper inside components (Modelica 3.6, "
        "section 9.1)"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
