"""Rules of constructs outside springc's subset (operator records and operators,
section 14 and 4.6; stream variables, sections 4.4.2.2 and 15), checked before the
"not supported yet" error, and the type rule of connected enumeration signals (9.3):
for each rule an invalid model (the exact error, location and help) and a valid one
(still "not supported yet", or its balance summary)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

_OR = "an operator record may have only public components: no equation, algorithm or " \
    "protected section (Modelica 3.6, section 4.6)"

CASES = {
    "operator_record_equation": ("""\
model M
  operator record R
    Real a;
  equation
    a = 2;
  end R;
  R r;
end M;
""", "5:5: an operator record cannot have equations or algorithms\nhelp: " + _OR),
    "operator_record_protected": ("""\
model M
  operator record R
    Real a = 1;
  protected
    Real b = 2;
  end R;
  R r;
end M;
""", "5:10: an operator record cannot have protected elements\nhelp: " + _OR),
    "operator_record_valid": ("""\
model M
  operator record R
    Real a = 1;
  end R;
  R r;
end M;
""", "2:3: `operator` classes are not supported yet\nhelp: springc supports a subset "
        "of Modelica; see \"Not supported yet\" in docs/language.md"),
    "extends_operator_record": ("""\
model M
  operator record R
    Real a = 1;
  end R;
  record S
    extends R(a = 3);
  end S;
  S s;
end M;
""", "6:13: extending the operator record 'R'\nhelp: an operator record can be extended "
        "only by a short class definition modifying its components (Modelica 3.6, "
        "section 4.6)"),
    "extends_enclosing_scope": ("""\
model M
  package P
    operator record R
      Real a = 1;
    end R;
  end P;
  package Q
    extends P;
    constant Real c = 2;
  end Q;
  Real x = Q.c;
end M;
""", "8:13: extending 'P', which encloses the operator record 'R'\nhelp: no class may "
        "extend a class enclosing an operator record (Modelica 3.6, section 4.6)"),
    "operator_component": ("""\
model M
  operator record R
    Real a = 1;
    encapsulated operator '*'
      constant Real k = 2;
    end '*';
  end R;
  R r;
end M;
""", "5:21: the operator '*' holds the component 'k'\nhelp: an operator may hold only "
        "declarations of functions (Modelica 3.6, section 4.6)"),
    "constructor_two_outputs": ("""\
model M
  operator record R
    Real a;
    encapsulated operator 'constructor'
      function make
        input Real v;
        output Real w1;
        output Real w2;
      algorithm
        w1 := v;
        w2 := v;
      end make;
    end 'constructor';
  end R;
  R r(a = 1);
end M;
""", "5:7: the function 'make' of the operator 'constructor' has 2 outputs\nhelp: every "
        "function of an operator returns exactly one output (Modelica 3.6, section "
        "14.1)"),
    "constructor_output_type": ("""\
model M
  operator record R
    Real a;
    encapsulated operator 'constructor'
      function make
        input Real v;
        output Real w = v;
      algorithm
      end make;
    end 'constructor';
  end R;
  R r(a = 1);
end M;
""", "7:16: the output 'w' of the constructor 'make' is of type Real\nhelp: a "
        "constructor of an operator record returns the operator record ('R') (Modelica "
        "3.6, section 14.3)"),
    "binary_one_input": ("""\
model M
  operator record R
    Real a;
    encapsulated operator function '*'
      import M.R;
      input R p;
      output R q = p;
    algorithm
    end '*';
  end R;
  R r(a = 1);
end M;
""", "4:5: the function '*' of the binary operator '*' has 1 input\nhelp: a binary "
        "operator's function takes at least two inputs (Modelica 3.6, section 14.5)"),
    "stream_in_model": ("""\
model M
  stream Real h = 1;
end M;
""", "2:15: the stream variable 'h' is declared in a model\nhelp: the prefix stream may "
        "be used only in a connector (Modelica 3.6, section 4.4.2.2)"),
    "stream_integer": ("""\
model M
  connector C
    Real p;
    flow Real m;
    stream Integer h;
  end C;
  C c;
end M;
""", "5:12: the stream variable 'h' is of type Integer, not Real\nhelp: a stream "
        "variable is a subtype of Real, or a record of such (Modelica 3.6, section "
        "15.1)"),
    "stream_two_flows": ("""\
model M
  connector C
    Real p;
    flow Real m;
    flow Real n;
    stream Real h;
  end C;
  C c;
end M;
""", "6:17: the stream connector 'C' has 2 flow declarations\nhelp: a connector with "
        "stream variables has exactly one scalar flow variable (Modelica 3.6, section "
        "15.1)"),
    "stream_connector_unbalanced": ("""\
model M
  connector C
    Real p;
    Real q;
    flow Real m;
    stream Real h;
    parameter Real k = 1;
    input Real u;
  end C;
  C c;
end M;
""", "2:3: the connector 'C' has 1 flow and 2 potential variables\nhelp: a connector "
        "has as many flow variables as variables that are neither parameter, constant, "
        "input, output, stream nor flow (Modelica 3.6, section 9.3.1)"),
    "stream_valid": ("""\
model M
  connector C
    Real p;
    flow Real m;
    stream Real h;
  end C;
  C c;
end M;
""", "5:5: `stream` connectors are not supported yet\nhelp: springc supports a subset "
        "of Modelica; see \"Not supported yet\" in docs/language.md"),
    "in_stream_of_potential": ("""\
model M
  connector C
    Real p;
    flow Real m;
  end C;
  C c;
  Real y = inStream(c.p);
end M;
""", "7:21: the argument of inStream must be a stream variable, and 'c.p' is not one\n"
        "help: inStream(v) is defined for a stream variable v of a connector (Modelica "
        "3.6, section 15.2)"),
    "connect_enumeration_integer": ("""\
model M
  type E = enumeration(a, b);
  connector EIn = input E;
  connector IOut = output Integer;
  EIn u;
  IOut y = 1;
equation
  connect(u, y);
end M;
""", "8:3: cannot connect 'u' and 'y': one is an enumeration M.E and the other an "
        "Integer\nhelp: connected variables must have the same primitive type (Modelica "
        "3.6, section 9.3)"),
    "connect_enumeration_same": ("""\
model M
  type E = enumeration(a, b);
  connector EIn = input E;
  connector EOut = output E;
  EIn u;
  EOut y = E.b;
  Boolean z = u == E.b;
equation
  connect(u, y);
end M;
""", "M: 3 unknowns (3 discrete), 3 equations, 0 parameters: balanced"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected


def test_equivalent_enumerations_connect(tmp_path: Path) -> None:
    """Two enumeration types with the same literals in the same order are equivalent
    (section 6.4): their signals connect."""
    text = """\
model M
  type E = enumeration(a, b);
  type F = enumeration(a, b);
  connector EIn = input E;
  connector FOut = output F;
  EIn u;
  FOut y = F.b;
equation
  connect(u, y);
end M;
"""
    assert outcome(tmp_path, text) == "M: 2 unknowns (2 discrete), 2 equations, " \
        "0 parameters: balanced"


def test_flow_over_a_stream_element(tmp_path: Path) -> None:
    """`flow C c` where C (outside the subset, never flattened) has a stream element."""
    text = """\
model M
  connector C
    Real p;
    flow Real m;
    stream Real h;
  end C;
  flow C c;
end M;
"""
    assert outcome(tmp_path, text) == (
        "7:10: 'c' is declared `flow`, but its element 'm' is already `flow`\nhelp: flow, "
        "input and output on a structured component apply to its elements, which then "
        "may not have any of these prefixes (Modelica 3.6, section 4.4.2.2)")
