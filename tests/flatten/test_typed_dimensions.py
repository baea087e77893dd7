"""Boolean and enumeration types as array dimensions, indices and for-loop ranges
(Modelica 3.6, sections 10.1, 10.4.3, 10.5.1, 11.2.2), and enumeration values kept
apart from numbers (section 4.9.5): valid models (their balance summary, or their
simulated values against closed forms) and invalid ones (the exact error and help)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from rule_outcome import outcome

INDEX_HELP = ("help: a dimension declared [Boolean] is indexed by false and true, one "
              "declared [E] by the literals of E, an Integer size by Integers (Modelica 3.6, "
              "section 10.5.1)")
ENUM_HELP = ("help: enumeration values are neither Integers nor Reals: convert with "
             "Integer(e), and compare only values of the same enumeration type (Modelica "
             "3.6, section 4.9.5)")

CASES = {
    "conversions_and_comparisons": ("""\
model M
  type E = enumeration(a, b, c);
  type E2 = E;
  parameter E2 e = E.c;
  parameter Integer n = Integer(e);
  parameter Real r[E] = {Integer(E.c), Integer(E.a), 2.5};
  parameter Boolean later = e > E.a and E.b <= e;
  Real x[E2] = r;
  Real y = x[e];
end M;
""", "M: 4 unknowns, 4 equations, 3 parameters, 1 parameter array: balanced"),
    "ranges_of_values_and_types": ("""\
model M
  type E = enumeration(a, b, c);
  Boolean b[Boolean];
  Real x[E];
  Real w[E, 2];
equation
  for v in false:true loop
    b[v] = not v;
  end for;
  for e in E.b:E.c loop
    x[e] = Integer(e);
  end for;
  x[E.a] = 0;
  for e in E, i loop
    w[e, i] = i;
  end for;
end M;
""", "M: 11 unknowns (2 discrete), 11 equations, 0 parameters: balanced"),
    "integer_index_of_an_enumeration_dimension": ("""\
model M
  type E = enumeration(a, b, c);
  Real x[E] = {1, 2, 3};
  Real y = x[2];
end M;
""", "4:14: 'x' has a dimension indexed by enumeration 'M.E' values, but the subscript "
        f"is the Integer 2\n{INDEX_HELP}"),
    "boolean_index_of_an_integer_dimension": ("""\
model M
  Real x[2] = {1, 2};
  Real y = x[true];
end M;
""", "3:14: 'x' has a dimension indexed by Integer values, but the subscript is true\n"
        f"{INDEX_HELP}"),
    "literal_of_another_enumeration": ("""\
model M
  type E = enumeration(a, b);
  type F = enumeration(a, b);
  Real x[E] = {1, 2};
  Real y = x[F.a];
end M;
""", "5:14: 'x' has a dimension indexed by enumeration 'M.E' values, but the subscript "
        f"is M.F.a\n{INDEX_HELP}"),
    "literal_index_of_an_integer_dimension": ("""\
model M
  type E = enumeration(a, b);
  Real x[2] = {1, 2};
  Real y = x[E.b];
end M;
""", "4:14: 'x' has a dimension indexed by Integer values, but the subscript is M.E.b\n"
        f"{INDEX_HELP}"),
    "range_of_mixed_bounds": ("""\
model M
  type E = enumeration(a, b);
  Real x[2];
equation
  for i in E.a:true loop
    x[1] = 1;
  end for;
  x[2] = 0;
end M;
""", "5:12: the bounds of a range are of different types: enumeration 'M.E' and "
        "Boolean\nhelp: both bounds are Integers or Reals, both Booleans, or both literals "
        "of one enumeration (Modelica 3.6, section 10.4.3)"),
    "enumeration_range_with_a_step": ("""\
model M
  type E = enumeration(a, b, c);
  Real x[E];
equation
  for e in E.a:1:E.c loop
    x[e] = 1;
  end for;
end M;
""", "5:16: a range of enumeration 'M.E' values has no step\nhelp: write 'a:b' (Modelica "
        "3.6, section 10.4.3)"),
    "deduced_range_over_two_kinds": ("""\
model M
  type E = enumeration(a, b);
  Real x[E], y[2];
equation
  for i loop
    x[i] = y[i];
  end for;
  y = {1, 2};
end M;
""", "5:7: the range of 'i' cannot be deduced: it subscripts dimensions indexed by "
        "enumeration 'M.E' and by Integer values\nhelp: a deduced range needs dimensions "
        "of one size and kind (Modelica 3.6, section 11.2.2.1)"),
    "integer_bound_to_a_literal": ("""\
model M
  type E = enumeration(a, b);
  parameter Integer n = E.b;
end M;
""", f"3:25: 'n' is an Integer, but it is given a value of enumeration type 'M.E'\n"
        f"{ENUM_HELP}"),
    "enumeration_bound_to_an_integer": ("""\
model M
  type E = enumeration(a, b);
  parameter E e = 2;
end M;
""", f"3:19: 'e' is of enumeration type 'M.E', but it is given a number\n{ENUM_HELP}"),
    "enumeration_bound_to_another": ("""\
model M
  type E = enumeration(a, b);
  type F = enumeration(a, b);
  parameter E e = F.a;
end M;
""", "4:19: 'e' is of enumeration type 'M.E', but it is given a value of enumeration "
        f"type 'M.F'\n{ENUM_HELP}"),
    "enumeration_compared_with_a_real": ("""\
model M
  type E = enumeration(a, b);
  parameter E e = E.a;
  Real x = if e < 1.5 then 1 else 2;
end M;
""", "4:15: '<' compares a value of enumeration type 'M.E' with a number\n"
        f"{ENUM_HELP}"),
    "unspecified_enumeration_redeclared": ("""\
model M
  model A
    replaceable type E = enumeration(:);
    parameter E e;
  end A;
  type Colors = enumeration(red, green);
  A a(redeclare type E = Colors, e = Colors.green);
end M;
""", "M: 0 unknowns, 0 equations, 1 parameter: balanced"),
    "unspecified_enumeration_variable": ("""\
model M
  type E = enumeration(:);
  parameter E e;
end M;
""", "3:15: 'e' is of the enumeration type 'M.E', which has no literals\nhelp: a simulated "
        "model has no variables of an unspecified enumeration `enumeration(:)`: redeclare "
        "the type (`redeclare type E = Colors`) (Modelica 3.6, section 4.9.5.4)"),
    "two_enumerations_compared": ("""\
model M
  type E = enumeration(a, b);
  type F = enumeration(a, b);
  Boolean same = E.a == F.a;
end M;
""", "4:18: '==' compares a value of enumeration type 'M.E' with a value of enumeration "
        f"type 'M.F'\n{ENUM_HELP}"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_typed_dimensions_and_enumeration_rules(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected


SIMULATED = """model M
  type Phase = enumeration(a, b, c);
  parameter Real k[Phase] = {1, 2, 4};
  Real x[Phase](each start = 1, each fixed = true);
  Real y[Boolean];
  Real z[2, Phase];
equation
  for p loop
    der(x[p]) = -k[p] * x[p];
  end for;
  for b in Boolean loop
    y[b] = if b then time else -2 * time;
  end for;
  for i, p loop
    z[i, p] = i * Integer(p) + (if p == Phase.a then 0 else x[Phase.a]);
  end for;
end M;
"""


def test_enumeration_and_boolean_dimensions_simulate() -> None:
    """Elements are named by their position: x[2] is x[Phase.b], y[1] is y[false]."""
    model = springc.load_model_from_string(SIMULATED, cache=False)
    r = springc.simulate(model, stop=1.0, interval=0.1, rtol=1e-10, atol=1e-12)
    t = r.time
    for i, k in enumerate((1, 2, 4), 1):  # x' = -k x, x(0) = 1
        assert np.max(np.abs(r[f"x[{i}]"] - np.exp(-k * t))) < 1e-8
    assert np.max(np.abs(r["y[1]"] + 2 * t)) < 1e-12
    assert np.max(np.abs(r["y[2]"] - t)) < 1e-12
    assert np.max(np.abs(r["z[2,3]"] - (6 + np.exp(-t)))) < 1e-8
    assert np.max(np.abs(r["z[1,1]"] - 1)) < 1e-12


def test_an_enumeration_value_survives_pickling() -> None:
    """A cache entry holding ``E.b`` (a flat constant, a RunSystem) loads back as ``E.b``:
    int's own pickling called ``EnumLiteral(2)`` and failed ("missing 'ordinal'")."""
    import copy
    import pickle

    from springc.flatten.scopes import Enumeration, EnumLiteral, literal_value

    colour = Enumeration("M.Colour", ("red", "green", "blue"))
    const = literal_value(colour, 2)
    for again in (pickle.loads(pickle.dumps(const, protocol=pickle.HIGHEST_PROTOCOL)),
                  pickle.loads(pickle.dumps(const, protocol=2)), copy.deepcopy(const)):
        value = again.value
        assert type(value) is EnumLiteral
        assert (int(value), value.enumeration, value.literal) == (2, colour, "green")
