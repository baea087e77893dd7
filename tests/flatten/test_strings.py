"""String variables, String(...) conversions, concatenation and relations (Modelica 3.6,
sections 3.6.1, 3.7.1, 4.9.4, 10.6.2), evaluated while flattening: a valid model whose
assertions hold (any wrong value would make one always fail), and invalid ones (the
exact error and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

SUBSET = 'help: springc supports a subset of Modelica; see "Not supported yet" in ' \
    "docs/language.md"

CASES = {
    "values_known_while_flattening": ('''\
model M
  type E = enumeration(low, high);
  parameter Integer n = 3;
  parameter String unit = "m";
  String label(start = "none") = "x in " + unit;
  String parts[3];
  String joined;
  String number;
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
  for p in {"a", "b", "c"} loop
    if p == "a" then
      parts[1] = p;
    elseif p < "c" then
      parts[2] = p + p;
    else
      parts[3] = String(E.high);
    end if;
  end for;
  joined = parts[1] + parts[2] + parts[3];
  number = String(n, minimumLength = 3, leftJustified = false)
    + String(2.0 / 3.0, significantDigits = 3) + String(1234.5, format = "10.2e")
    + String(true);
  assert(joined == "abbhigh" and label == "x in m", "strings");
  assert(number == "  30.667  1.23e+03true", "conversions");
algorithm
  assert(parts[2] <> "b", "algorithm");
end M;
''', "M: 1 unknown, 1 equation, 1 parameter: balanced"),
    "string_of_a_variable_bound_to_a_constant": ('''\
model M
  type E = enumeration(one, two);
  E e = E.two;
  Integer k = 2 * 3;
equation
  assert(String(e) + String(k) == "two6", "bound values");
end M;
''', "M: 2 unknowns (2 discrete), 2 equations, 0 parameters: balanced"),
    "an_assertion_on_strings_that_fails": ('''\
model M
  String s;
equation
  s = "a" + "b";
  assert(s == "ba", "s is " + s);
end M;
''', "5:3: this assertion always fails: s is ab\nhelp: its condition is false whatever the "
        "values; use AssertionLevel.warning to only report it"),
    "given_a_number": ('''\
model M
  String s;
equation
  s = 1;
end M;
''', "4:3: the String 's' is given a number\nhelp: convert with String(...)"),
    "given_twice": ('''\
model M
  String s;
equation
  s = "a";
  s = "b";
end M;
''', "5:3: both sides of this equation are Strings known already\nhelp: a String "
        "variable is given its value by one equation (or its binding)"),
    "without_an_equation": ('''\
model M
  String s;
  Real x = 1;
end M;
''', "2:10: the String variable 's' has no equation giving its value\nhelp: bind it "
        "(String s = \"...\") or write an equation s = \"...\""),
    "read_before_its_equation": ('''\
model M
  String s, t;
equation
  t = s + "!";
  s = "a";
end M;
''', "4:7: the String variable 's' is read before the equation that gives its value\n"
        "help: springc evaluates Strings while flattening: write the equation that gives "
        "its value before its uses"),
    "string_plus_number": ('''\
model M
  String s;
equation
  s = "a" + 1;
end M;
''', "4:7: '+' needs two Strings here, found a String and a number or an array\n"
        "help: convert a number with String(...)"),
    "a_discrete_string_read": ('''\
model M
  discrete String s;
  Boolean b;
equation
  when sample(0, 1) then
    s = "tick";
  end when;
  b = s == "tick";
end M;
''', "8:7: reading the discrete String 's' (assigned in a when-clause) is not supported "
        f"yet\n{SUBSET}"),
    "string_of_time": ('''\
model M
  String s;
equation
  s = String(time);
end M;
''', "4:14: 'String' of a value that changes during the simulation is not supported yet: "
        f"it depends on time\n{SUBSET}"),
    "a_real_format_for_an_integer": ('''\
model M
  String s;
equation
  s = String(15, format = "8.3f");
end M;
''', "4:7: the format of an Integer is written like \"5d\", found '8.3f'\nhelp: flags, "
        "width, precision and a conversion: e, f or g for a Real, d for an Integer "
        "(Modelica 3.6, section 3.7.1)"),
    "an_attribute_strings_do_not_have": ('''\
model M
  String s(unit = "m") = "a";
end M;
''', "2:12: 's' is a String and has no attribute 'unit' to modify\nhelp: the "
        "attributes of String are: start, fixed, quantity"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_strings(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
