"""Language pieces the Modelica Standard Library's examples need (issue 25), each on a
small model written here (no MSL file): external string functions evaluated natively and
a located error for other external functions, if-expressions whose branches differ in
size under a parameter condition, protected outside inputs in the one-source rule,
functions found from the class that wrote an inherited equation, ``String(v)`` of a
time-varying value in an assert message."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome
from springc.errors import SpringcError, errors_of
from springc.ir import expr as x
from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files

STRINGS = '''\
package P
  function len
    input String string;
    output Integer result;
  external "C" result = ModelicaStrings_length(string);
  end len;
  function sub
    input String string;
    input Integer startIndex = 1;
    input Integer endIndex = startIndex;
    output String result;
  external "C" result = ModelicaStrings_substring(string, startIndex, endIndex);
  end sub;
  function cmp
    input String string1;
    input String string2;
    input Boolean caseSensitive = true;
    output Integer result;
  external "C" result = ModelicaStrings_compare(string1, string2, caseSensitive);
  end cmp;
  function skip
    input String string;
    input Integer startIndex = 1;
    output Integer nextIndex;
  external "C" nextIndex = ModelicaStrings_skipWhiteSpace(string, startIndex);
  end skip;
  function foreign
    input Real u;
    output Real y;
  external "C" y = my_c_function(u);
  end foreign;
  model M
    parameter String s = "hello";
    parameter Integer n = len(s);
    parameter Integer m = len(sub(s, 2, 4));
    parameter Integer c[3] = {cmp("a", "b"), cmp("ab", "AB", false), cmp("b", "a")};
    parameter Integer k = skip("   x", 1);
    Real y[n] = ones(n);
  end M;
  model Foreign
    Real y = foreign(time);
  end Foreign;
end P;
'''


def _bindings(model) -> dict[str, object]:
    return {v.name: v.binding for v in model.variables if v.binding is not None}


def test_string_functions_are_evaluated(tmp_path: Path) -> None:
    path = tmp_path / "P.mo"
    path.write_text(STRINGS)
    model = flatten_files([path], "P.M")
    values = _bindings(model)
    # "hello" has 5 characters, "ell" 3; compare gives Less 1, Equal 2, Greater 3
    assert values["n"] == x.Const(5) and values["m"] == x.Const(3)
    assert [values[f"c[{i}]"] for i in (1, 2, 3)] == [x.Const(1), x.Const(2), x.Const(3)]
    assert values["k"] == x.Const(4)
    assert [v.name for v in model.unknowns] == [f"y[{i}]" for i in range(1, 6)]


def test_an_unknown_external_function_is_located_where_called(tmp_path: Path) -> None:
    lines = STRINGS.splitlines()
    call = next(i for i, line in enumerate(lines, 1) if "foreign(time)" in line)
    text = outcome(tmp_path, STRINGS + "model Top\n  P.Foreign f;\nend Top;\n")
    assert text == (f"{call}:14: the external function 'P.foreign' (C function "
                    "'my_c_function') is not supported: its library does not ship its C "
                    "sources\nhelp: springc compiles and calls the C functions whose "
                    "sources the library ships (its Resources/C-Sources); it evaluates "
                    "the tables (ModelicaStandardTables) and "
                    "string functions (ModelicaStrings) of the Modelica Standard Library "
                    "itself")


def test_declaring_an_external_function_is_not_an_error(tmp_path: Path) -> None:
    text = STRINGS.replace("    Real y[n] = ones(n);\n", "    Real y[n] = ones(n);\n"
                           "    Real z = foreign(1) if false;\n")
    assert outcome(tmp_path, text + "model Top\n  P.M m;\nend Top;\n") == \
        "Top: 5 unknowns, 5 equations, 3 parameters, 1 parameter array: balanced"


def test_if_expression_branches_of_other_sizes_under_a_parameter(tmp_path: Path) -> None:
    assert outcome(tmp_path, '''\
model M
  parameter Integer n = 2;
  parameter Real t[:, 2] = if n > 0 then [0, 1; 1, 0; 2, 1] else [0, 0];
  Real y[size(t, 1)] = t[:, 2];
end M;
''') == "M: 3 unknowns, 3 equations, 1 parameter, 1 parameter array: balanced"
    assert outcome(tmp_path, '''\
model M
  Real t[:] = if time > 1 then {1, 2} else {1};
end M;
''') == ("2:15: branches of an if-expression differ in size\nhelp: sizes may differ only "
         "where the condition is a parameter expression")


SOURCE = '''\
connector RealInput = input Real;
connector RealOutput = output Real;
block Constant
  parameter Real k = 1;
  RealOutput y = k;
end Constant;
block Sine
  parameter Boolean useConstantAmplitude = false;
  RealInput amplitude if not useConstantAmplitude;
  RealOutput y;
protected
  RealInput amplitude_internal;
  Constant amplitude_constant(k = 3) if useConstantAmplitude;
equation
  y = amplitude_internal * sin(time);
  connect(amplitude, amplitude_internal);
  connect(amplitude_constant.y, amplitude_internal);
end Sine;
'''


def test_a_protected_outside_input_is_not_a_source(tmp_path: Path) -> None:
    path = tmp_path / "m.mo"
    path.write_text(SOURCE + '''\
model M
  Sine fixed(useConstantAmplitude = true);
  Sine driven;
  Constant two(k = 2);
equation
  connect(two.y, driven.amplitude);
end M;
''')
    text = format_flat(flatten_files([path], "M"))
    assert "'fixed.amplitude_constant.y' = 'fixed.amplitude_internal';" in text
    assert "'driven.amplitude' = 'driven.amplitude_internal';" in text
    assert "'two.y' = 'driven.amplitude';" in text


def test_two_public_sources_are_still_rejected(tmp_path: Path) -> None:
    assert outcome(tmp_path, SOURCE + '''\
block Twice
  RealInput u;
  RealOutput y;
  Constant c;
equation
  connect(u, y);
  connect(c.y, y);
end Twice;
model M
  Twice t;
  Constant one;
equation
  connect(one.y, t.u);
end M;
''').startswith("25:3: a connection set has 2 sources of its signal")


def test_an_inherited_equation_finds_functions_of_its_base_class(tmp_path: Path) -> None:
    path = tmp_path / "L.mo"
    path.write_text('''\
package L
  package Base
    partial model Adaptor
      Real p = time;
      Real u;
    equation
      u = Functions.first({2 * p, 1}, time);
    end Adaptor;
    package Functions
      function first
        input Real u[2];
        input Real dummy;
        output Real s;
      algorithm
        s := u[1];
      end first;
    end Functions;
  end Base;
  package Use
    model A
      extends L.Base.Adaptor;
    end A;
  end Use;
end L;
''')
    model = flatten_files([path], "L.Use.A")
    assert "  u = 2 * p;" in format_flat(model).splitlines()


def test_string_of_a_variable_in_an_assert_message_names_it(tmp_path: Path) -> None:
    path = tmp_path / "m.mo"
    path.write_text('''\
model M
  Real x = time;
equation
  assert(x < 5, "x = " + String(x) + ", limit " + String(5));
end M;
''')
    (item,) = flatten_files([path], "M").assertions
    assert item.message == "x = String(x), limit 5"


def test_a_type_extending_string(tmp_path: Path) -> None:
    """``type TypeString extends String;`` (the MSL's Icons.TypeString, which
    MultiBody's AxisLabel and ShapeType are defined by) is a String type."""
    assert outcome(tmp_path, '''\
package TS
  type TypeString
    extends String;
  end TypeString;
  type Label = TypeString;
  model M
    parameter Label l = "x";
    Real y = 1;
  equation
    assert(l == "x", "the label");
  end M;
end TS;
model Top
  TS.M m;
end Top;
''') == "Top: 1 unknown, 1 equation, 0 parameters: balanced"


def test_a_function_branch_ruled_out_by_a_parameter_may_be_out_of_bounds(
        tmp_path: Path) -> None:
    """Blocks.Continuous.Internal.Filter.Utilities.BesselBaseCoefficients' pattern:
    the branch for another order writes elements the outputs do not have."""
    path = tmp_path / "m.mo"
    path.write_text('''\
model BF
  function coeffs
    input Integer order;
    output Real c2[integer(order / 2), 2];
  algorithm
    if order == 2 then
      c2[1, 1] := 1; c2[1, 2] := 2;
    elseif order == 4 then
      c2[1, 1] := 1; c2[1, 2] := 2; c2[2, 1] := 3; c2[2, 2] := 4;
    end if;
  end coeffs;
  parameter Integer n = 2;
  parameter Real c[1, 2] = coeffs(n);
  Real y = c[1, 2];
end BF;
''')
    model = flatten_files([path], "BF")
    binding = _bindings(model)["c[1,2]"]
    assert x.evaluate(binding, {"n": 2}) == 2



def test_a_connector_of_an_enumeration_type(tmp_path: Path) -> None:
    # connector DigitalSignal = Logic (an enumeration): the MSL's Digital connectors,
    # connected in Electrical.Analog.Examples.AD_DA_conversion (section 9.1)
    path = tmp_path / "m.mo"
    path.write_text("""model EnumConn
  type Logic = enumeration(U, X, Z0, Z1);
  connector Sig = Logic;
  connector SigOut = output Sig;
  connector SigIn = input Sig;
  block Src
    SigOut y;
  equation
    y = if time < 0.5 then Logic.Z0 else Logic.Z1;
  end Src;
  block Snk
    SigIn u;
    Boolean high = u == Logic.Z1;
  end Snk;
  Src src;
  Snk snk;
equation
  connect(src.y, snk.u);
end EnumConn;
""")
    assert format_flat(flatten_files([path], "EnumConn")) == """model EnumConn
  discrete output Integer 'src.y';
  discrete input Integer 'snk.u';
  discrete Boolean 'snk.high';
equation
  'snk.high' = 'snk.u' == 4;
  'src.y' = if time < 0.5 then 3 else 4;
  'src.y' = 'snk.u';
end EnumConn;
"""


LIBRARY = '''package Lib
  function twice
    input Real u;
    output Real y;
  external "C" y = lib_twice(u)
    annotation(IncludeDirectory="modelica://Lib/Resources/C-Sources",
               Include="#include \\"twice.h\\"", Library={"LibC", "m"});
  end twice;
  model M
    Real y = twice(time);
  end M;
end Lib;
'''


@pytest.mark.parametrize("shipped", [True, False])
def test_an_external_function_names_its_libraries_and_sources(tmp_path: Path,
                                                               shipped: bool) -> None:
    # the MSL's FFT: external "C" with IncludeDirectory and Library annotations (12.9.4)
    folder = tmp_path / "libs" / "Lib"
    folder.mkdir(parents=True)
    (folder / "package.mo").write_text(LIBRARY)
    sources = folder / "Resources" / "C-Sources"
    if shipped:
        sources.mkdir(parents=True)
        (sources / "twice.c").write_text("double lib_twice(double u) { return 2*u; }\n")
    with pytest.raises(SpringcError) as info:
        flatten_files([], "Lib.M", [tmp_path / "libs"])
    (err,) = errors_of(info.value)
    assert err.message == ("the external function 'Lib.twice' (C function 'lib_twice') is "
                           "not supported: its library does not ship its C sources")
    assert err.span is not None and (err.span.line, err.span.column) == (10, 14)
    where = f"its include directory modelica://Lib/Resources/C-Sources ({sources})"
    assert [n.message for n in err.notes] == [
        "its external clause", "it links the libraries 'LibC', 'm'",
        "the C sources of 'LibC' are not in this copy of the library (looked for in its "
        "include directory and Resources/C-Sources)",
        f"{where} holds C sources (twice.c)" if shipped
        else f"{where} is not in this copy of the library"]


def test_pieces_of_the_msl_time_table_and_radio_button(tmp_path: Path) -> None:
    # TimeTable: 'next0' is assigned in one branch of an if on a run-time condition
    # only (undefined in the other, which never reads it); RadioButtonSource: a
    # when-statement on a Boolean vector its algorithm assigns from pre(...)
    path = tmp_path / "m.mo"
    path.write_text("""model M
  function f
    input Real u;
    output Real y;
  protected
    Real d;
  algorithm
    if u > 1 then
      d := u - 1;
      y := 2 * d;
    else
      y := 0;
    end if;
  end f;
  Real y = f(time);
  Boolean reset[1] = {time > 0.5};
  Boolean pre_reset[1];
  Boolean on(start = true, fixed = true);
initial equation
  pre(reset) = {false};
algorithm
  pre_reset := pre(reset);
  when pre_reset then
    on := false;
  end when;
end M;
""")
    model = flatten_files([path])
    equations = {x.to_text(e.lhs): x.to_text(e.rhs) for e in model.equations}
    # f's branch condition is literal: a function body generates no events (12.8)
    assert equations["y"] == "if noEvent(time > 1) then 2 * (time - 1) else 0"
    (when,) = model.whens
    assert [x.to_text(c) for c in when.branches[0].conditions] == ["pre(reset[1])"]
