"""Component, expression and access rules (Modelica 3.6 sections 3.6.7, 3.7.1, 3.7.4, 3.8.2,
3.8.4, 4.1, 4.4.2.2, 4.4.4.1, 8.3.4, 10.6.5): for each rule a valid model (its balance
summary) and an invalid one (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

CASES = {
    "flow_integer": ("""\
model M
  connector C
    flow Integer f;
    Real e = 2.0;
  end C;
  C c;
end M;
""",
        "3:18: 'f' is a flow variable of type Integer\nhelp: flow variables must be of"
        ' type Real (or a type derived from Real) (Modelica 3.6, section 4.4.2.2)'),
    "flow_real": ("""\
model M
  connector C
    flow Real f;
    Real e;
  end C;
  C c;
equation
  c.e = 2.0;
end M;
""",
        'M: 2 unknowns, 2 equations, 0 parameters: balanced'),
    "input_output_conflict": ("""\
model M
  connector C
    Real e;
    output Real x;
  end C;
  input C c(e = 1.0, x = 2.0);
end M;
""",
        "6:11: 'c' is declared `input`, but its element 'x' is already `output`\nhelp:"
        ' flow, input and output on a structured component apply to its elements, which'
        ' then may not have any of these prefixes (Modelica 3.6, section 4.4.2.2)'),
    "input_connector_without_prefixes": ("""\
model M
  connector C
    Real e;
    Real x;
  end C;
  input C c(e = 1.0, x = 2.0);
end M;
""",
        'M: 2 unknowns, 2 equations, 0 parameters: balanced'),
    "short_class_prefix_conflict": ("""\
model M
  connector C
    input Real x;
  end C;
  connector InputC = output C;
  InputC c(x = 2.0);
end M;
""",
        "6:10: 'c' is declared `output`, but its element 'x' is already `input`\nhelp:"
        ' flow, input and output on a structured component apply to its elements, which'
        ' then may not have any of these prefixes (Modelica 3.6, section 4.4.2.2)'),
    "parameter_model_component": ("""\
model M
  model A
    Real x = 1.0;
  end A;
  parameter A a;
end M;
""",
        "5:15: the prefix `parameter` cannot be applied to 'a', a component of the model"
        " 'M.A'\nhelp: type prefixes (flow, discrete, parameter, constant, input, output)"
        ' apply only to components of a type, record or connector (Modelica 3.6, section'
        ' 4.4.2.2)'),
    "parameter_record_component": ("""\
model M
  record R
    Real x = 1.0;
  end R;
  parameter R r;
end M;
""",
        'M: 0 unknowns, 0 equations, 1 parameter: balanced'),
    "constant_connector_with_input": ("""\
model M
  connector C
    input Real x = 1.0;
  end C;
  constant C c;
end M;
""",
        "5:14: the connector 'c' cannot be declared `constant`\nhelp: a connector"
        ' component cannot be a parameter or a constant (Modelica 3.6, section 9.3)'),
    "constant_bound_to_parameter": ("""\
model M
  parameter Real x = 6.3;
  constant Real y = x;
end M;
""",
        "3:21: the value of constant 'y' must be a constant expression, but it depends on"
        " the parameter 'x'\nhelp: a constant is bound only to literals, constants and"
        ' functions of them; make it a parameter, or the parameter a constant (Modelica'
        ' 3.6, section 3.8.2)'),
    "structured_constant": ("""\
model M
  record R
    constant Real x = 1.0;
    parameter Real y = 2.0;
    Real z;
  end R;
  constant R r(z = 3.0);
  constant Real w = r.y + r.z;
  Real v = w;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "integer_division": ("""\
model M
  constant Integer i = 4000 / 100;
end M;
""",
        "2:24: 'i' is an Integer, but its value is a Real expression\nhelp: `/` and `^`"
        ' give a Real even on Integers (use div(a, b) for integer division, integer(...)'
        ' to convert); a Real is not converted to Integer implicitly (Modelica 3.6,'
        ' section 10.6.5)'),
    "integer_div": ("""\
model M
  constant Integer i = div(4000, 100);
  Real x = i;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "integer_power": ("""\
model M
  parameter Integer i = 2 ^ 3;
end M;
""",
        "2:25: 'i' is an Integer, but its value is a Real expression\nhelp: `/` and `^`"
        ' give a Real even on Integers (use div(a, b) for integer division, integer(...)'
        ' to convert); a Real is not converted to Integer implicitly (Modelica 3.6,'
        ' section 10.6.5)'),
    "der_integer": ("""\
model M
  constant Integer pa = 1;
  Real a = der(pa);
end M;
""",
        "3:16: der needs a Real argument, but 'pa' is of type Integer\nhelp: the argument"
        ' of der must be of type Real (Modelica 3.6, section 3.7.4)'),
    "der_discrete_real": ("""\
model M
  discrete Real pa(start = 1, fixed = true);
  Real a = der(pa);
end M;
""",
        "3:16: der of the discrete-time variable 'pa'\nhelp: the argument of der must be"
        ' continuous-time (a parameter or constant gives zero) (Modelica 3.6, section'
        ' 3.7.4)'),
    "der_real_parameter": ("""\
model M
  parameter Real p = 1;
  Real a = der(p);
end M;
""",
        'M: 1 unknown, 1 equation, 1 parameter: balanced'),
    "if_integer_condition": ("""\
model M
  Real x;
  parameter Integer i = 1;
equation
  if i then
    x = 3.0;
  else
    x = 4.0;
  end if;
end M;
""",
        '5:6: the condition of an if-equation must be a Boolean, found an Integer\nhelp:'
        ' conditions are Boolean expressions; compare the number, e.g. `i <> 0` (Modelica'
        ' 3.6, section 8.3.4)'),
    "if_boolean_condition": ("""\
model M
  Real x;
  parameter Integer i = 1;
equation
  if i <> 0 then
    x = 3.0;
  else
    x = 4.0;
  end if;
end M;
""",
        'M: 1 unknown, 1 equation, 1 parameter: balanced'),
    "time_in_function": ("""\
model M
  function f
    output Real t;
  algorithm
    t := time;
  end f;
  Real x = f();
end M;
""",
        '5:10: `time` cannot be used in a function\nhelp: the built-in variable time is'
        ' available only in models and blocks (Modelica 3.6, section 3.6.7)'),
    "time_in_record": ("""\
model M
  record R
    Real x = time;
  end R;
  R r;
end M;
""",
        '3:14: `time` cannot be used in a record\nhelp: the built-in variable time is'
        ' available only in models and blocks (Modelica 3.6, section 3.6.7)'),
    "time_in_block": ("""\
model M
  block B
    output Real y = time;
  end B;
  B b;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "protected_component_access": ("""\
model M
  model A
  protected
    Real x = 23.0;
  end A;
  A a;
  Real y = a.x;
end M;
""",
        "7:14: 'x' is protected in 'M.A' and cannot be accessed as 'a.x'\nhelp: a"
        ' protected element can be used only by its simple name, inside its class and the'
        ' classes extending it, not through a dot from outside (Modelica 3.6, section'
        ' 4.1)'),
    "protected_inherited_by_name": ("""\
model M
  model A
  protected
    Real x = 4.21;
  end A;
  extends A(x = 2);
  Real y = x;
end M;
""",
        'M: 2 unknowns, 2 equations, 0 parameters: balanced'),
    "protected_class_access": ("""\
model M
  model A
  protected
    model B
      Real x = 42.0;
    end B;
  end A;
  A.B b;
end M;
""",
        "8:3: class 'B' is protected in 'M.A' and cannot be used as 'A.B'\nhelp: a"
        ' protected element can be used only by its simple name, inside its class and the'
        ' classes extending it, not through a dot from outside (Modelica 3.6, section'
        ' 4.1)'),
    "protected_modified": ("""\
model M
  model A
  protected
    Real x = 2.0;
  end A;
  A a(x = 4.0);
end M;
""",
        "6:7: 'x' is protected in 'M.A' and cannot be modified in 'a'\nhelp: a protected"
        ' element may be modified only by its own declaration or by an extends clause'
        ' (Modelica 3.6, section 4.1)'),
    "protected_package_constant": ("""\
model M
  package P
    constant Real c = 2;
  protected
    constant Real d = 3;
  end P;
  Real y = P.d;
end M;
""",
        "7:14: 'd' is protected in 'M.P' and cannot be accessed as 'M.P.d'\nhelp: a"
        ' protected element can be used only by its simple name, inside its class and the'
        ' classes extending it, not through a dot from outside (Modelica 3.6, section'
        ' 4.1)'),
    "public_package_constant": ("""\
model M
  package P
    constant Real c = 2;
  protected
    constant Real d = 3;
  end P;
  Real y = P.c;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),
    "abs_of_boolean": ("""\
model M
  Boolean b;
equation
  b = abs(b);
end M;
""",
        "4:11: abs needs a number: 'b' is a Boolean\nhelp: the arguments of abs are"
        ' Integer or Real (Modelica 3.6, section 3.7.1)'),
    "abs_of_integer": ("""\
model M
  parameter Integer i = -2;
  Real y = abs(i);
end M;
""",
        'M: 1 unknown, 1 equation, 1 parameter: balanced'),
    "if_equation_on_time": ("""\
model M
  Real x;
equation
  if time < 1.0 then
    x = 1;
  else
    x = 2;
  end if;
end M;
""",
        'M: 1 unknown, 1 equation, 0 parameters: balanced'),  # switches at a time event
    "if_equation_on_parameter": ("""\
model M
  parameter Real t0 = 0.5;
  Real x;
equation
  if t0 < 1.0 then
    x = 1;
  else
    x = 2;
  end if;
end M;
""",
        'M: 1 unknown, 1 equation, 1 parameter: balanced'),
    "integer_of_function_of_continuous": ("""\
model M
  function f
    input Real x;
    output Integer y;
  algorithm
    y := integer(x);
  end f;
  Real x = time;
  Integer y = f(x);
end M;
""",
        "9:15: 'y' is an Integer variable, but its value depends on the continuous-time"
        " variable 'x'\nhelp: Integer, Boolean and discrete variables change only at"
        ' events: their values are discrete-time expressions (relations, integer(),'
        ' pre(), ... of continuous-time variables, not the variables themselves)'
        ' (Modelica 3.6, section 3.8.4)'),
    "integer_of_event_function": ("""\
model M
  Real x = 2.5;
  Integer n = integer(x);
  Integer s = size({x, x}, 1);
end M;
""",
        'M: 3 unknowns (2 discrete), 3 equations, 0 parameters: balanced'),
    "boolean_of_no_event_relation": ("""\
model M
  Real x = 2.5;
  Boolean b = noEvent(x > 1);
end M;
""",
        "3:15: 'b' is a Boolean variable, but its value depends on the continuous-time"
        " variable 'x'\nhelp: Integer, Boolean and discrete variables change only at"
        ' events: their values are discrete-time expressions (relations, integer(),'
        ' pre(), ... of continuous-time variables, not the variables themselves)'
        ' (Modelica 3.6, section 3.8.4)'),
    "flow_record_in_connector": ("""\
model M
  record R
    Real x;
    Real y;
  end R;
  connector C
    flow R r;
    Real z = 1.0;
    Real w = 2.0;
  end C;
  C c;
end M;
""",
        'M: 4 unknowns, 4 equations, 0 parameters: balanced'),
    "flow_record_over_flow_element": ("""\
model M
  connector C
    Real e = 1.0;
    flow Real f;
  end C;
  connector D
    flow C c;
    Real e;
  end D;
  D d;
end M;
""",
        "7:12: 'c' is declared `flow`, but its element 'f' is already `flow`\nhelp: flow,"
        ' input and output on a structured component apply to its elements, which then'
        ' may not have any of these prefixes (Modelica 3.6, section 4.4.2.2)'),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
