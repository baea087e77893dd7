"""Flattening semantics on small inline models, with exact expected variables and equations."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import ErrorGroup, FlattenError, SpringcError, errors_of
from springc.flatten.flattener import flatten
from springc.ir import expr as x
from springc.ir.flat import FlatModel, Variable
from springc.parse import load
from springc.pipeline.files import flatten_files

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, text: str, model: str | None = None, name: str = "m.mdl"
            ) -> FlatModel:
    path = tmp_path / name
    path.write_text(text)
    return flatten_files([path], model)


def equations(m: FlatModel, initial: bool = False) -> list[str]:
    eqs = m.initial_equations if initial else m.equations
    return [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in eqs]


def bindings(m: FlatModel) -> dict[str, str]:
    return {v.name: x.to_text(v.binding) for v in m.parameters if v.binding is not None}


def var(m: FlatModel, name: str) -> Variable:
    return m.variable(name)


def error_of(tmp_path: Path, text: str, model: str | None = None) -> SpringcError:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        flat_of(tmp_path, text, model)
    errors = errors_of(info.value)
    assert len(errors) == 1, [e.message for e in errors]
    return errors[0]


# --------------------------------------------------------------------- the seed


def test_seed_counts_and_parameters() -> None:
    m = flatten_files([ROOT / "models" / "SpringMass.mdl"])
    assert m.name == "SpringMass"
    assert [v.name for v in m.unknowns] == [
        "mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]",
        "spring.x", "spring.dir[1]", "spring.dir[2]"]
    assert len(m.equations) == 7
    assert [v.name for v in m.parameters if "[" not in v.name] == [
        "mass.m", "spring.k", "spring.l"]
    assert sorted({v.name.split("[")[0] for v in m.parameters if "[" in v.name}) == [
        "center", "g", "mass.u", "mass.xy"]
    assert bindings(m)["mass.xy[2]"] == "-1"
    assert x.to_text(var(m, "mass.pos[2]").attributes.start) == "mass.xy[2]"
    assert x.derivatives(m.equations[0].lhs) == {"mass.pos[1]"}


# ---------------------------------------------------------------- modifications

BASES = """
model Inner
  parameter Real c = 1;
  parameter Real d = 2;
end Inner;
model Middle
  Inner sub(d = 20);
  parameter Real e = 3;
end Middle;
"""


def test_nested_and_dotted_modifications(tmp_path: Path) -> None:
    m = flat_of(tmp_path, BASES + """
model M
  Middle a(sub(c = 10), e = 30);
  Middle b(sub.c = 11, sub.d = 21);
  Middle c;
end M;
""")
    assert bindings(m) == {
        "a.sub.c": "10", "a.sub.d": "20", "a.e": "30",
        "b.sub.c": "11", "b.sub.d": "21", "b.e": "3",
        "c.sub.c": "1", "c.sub.d": "20", "c.e": "3"}


def test_outer_modification_wins_over_inner(tmp_path: Path) -> None:
    m = flat_of(tmp_path, BASES + "model M\n  Middle a(sub(d = 99));\nend M;\n")
    assert bindings(m)["a.sub.d"] == "99"


def test_modification_refers_to_the_enclosing_scope(tmp_path: Path) -> None:
    m = flat_of(tmp_path, BASES + """
model M
  parameter Real c = 5;
  Inner i(c = 2 * c);
end M;
""")
    assert bindings(m) == {"c": "5", "i.c": "2 * c", "i.d": "2"}


def test_each_and_per_element_values(tmp_path: Path) -> None:
    m = flat_of(tmp_path, BASES + """
model M
  Inner p[3](each c = 7, d = {1, 2, 3});
end M;
""")
    assert bindings(m) == {"p[1].c": "7", "p[1].d": "1", "p[2].c": "7", "p[2].d": "2",
                           "p[3].c": "7", "p[3].d": "3"}


def test_each_on_array_attribute(tmp_path: Path) -> None:
    m = flat_of(tmp_path, "model M\n  Real v[2](each start = 4);\nequation\n"
                "  der(v) = -v;\nend M;\n")
    assert [x.to_text(v.attributes.start) for v in m.unknowns] == ["4", "4"]


def test_final_declaration_cannot_be_modified(tmp_path: Path) -> None:
    err = error_of(tmp_path, """
model A
  final parameter Real k = 1;
end A;
model M
  A a(k = 2);
end M;
""")
    assert err.message == "'a.k' is final and cannot be modified"
    assert (err.span.line, err.span.column) == (6, 7)
    assert err.notes[0].message == "declared final here"


def test_final_modification_cannot_be_overridden(tmp_path: Path) -> None:
    err = error_of(tmp_path, BASES + """
model Holder
  Inner i(final c = 3);
end Holder;
model M
  Holder h(i(c = 4));
end M;
""")
    assert "final" in err.message and "h.i.c" in err.message


def test_extends_merges_modifications_outer_wins(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model Base
  parameter Real k = 1;
  parameter Real l = 2;
  Real x;
equation
  x = k + l;
end Base;
model Derived
  extends Base(k = 10, l = 20);
  parameter Real extra = 3;
end Derived;
model M
  Derived d(k = 100);
end M;
""")
    assert bindings(m) == {"d.k": "100", "d.l": "20", "d.extra": "3"}
    assert equations(m) == ["d.x = d.k + d.l"]
    assert m.equations[0].origin.component == "d"


def test_multiple_extends(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model A
  Real a;
equation
  a = 1;
end A;
model B
  Real b;
equation
  b = 2;
end B;
model M
  extends A;
  extends B;
end M;
""")
    assert [v.name for v in m.unknowns] == ["a", "b"]
    assert equations(m) == ["a = 1", "b = 2"]


def test_short_type_with_attributes(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
type Force = Real(unit = "N", nominal = 10);
type Mass = Real(unit = "kg", min = 0);
model M
  Force f(start = 2);
  parameter Mass m = 3;
equation
  der(f) = -f / m;
end M;
""")
    f = var(m, "f")
    assert (f.attributes.unit, x.to_text(f.attributes.nominal), x.to_text(f.attributes.start)) \
        == ("N", "10", "2")
    assert (var(m, "m").attributes.unit, x.to_text(var(m, "m").attributes.min)) == ("kg", "0")


def test_short_model_definition_with_modification(tmp_path: Path) -> None:
    m = flat_of(tmp_path, BASES + "model M = Middle(e = 9, sub(c = 8));\n")
    assert m.name == "M"
    assert bindings(m) == {"sub.c": "8", "sub.d": "20", "e": "9"}


# ------------------------------------------------------------- arrays and loops


def test_arrays_of_components_and_nested_for(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model Cell
  Real u;
end Cell;
model M
  parameter Integer n = 2;
  Cell c[n, 3];
equation
  for i in 1:n loop
    for j in 1:3 loop
      c[i, j].u = 10 * i + j;
    end for;
  end for;
end M;
""")
    assert equations(m) == [f"c[{i},{j}].u = {10 * i + j}" for i in (1, 2) for j in (1, 2, 3)]


def test_for_with_two_indices_and_step_range(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model M
  Real y[5];
equation
  for i in 1:2:5 loop
    y[i] = i;
  end for;
  for i in {2, 4} loop
    y[i] = -i;
  end for;
end M;
""")
    assert equations(m) == ["y[1] = 1", "y[3] = 3", "y[5] = 5", "y[2] = -2", "y[4] = -4"]


def test_array_expressions(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model M
  parameter Real w[3] = {1, 2, 3};
  Real v[3];
  Real s;
  Real t[2];
equation
  v = 2 * w;
  s = v * w;
  t = v[2:3] .* w[1:2];
end M;
""")
    assert equations(m) == [
        "v[1] = 2 * w[1]", "v[2] = 2 * w[2]", "v[3] = 2 * w[3]",
        "s = v[1] * w[1] + v[2] * w[2] + v[3] * w[3]",
        "t[1] = v[2] * w[1]", "t[2] = v[3] * w[2]"]


def test_array_size_from_parameter_of_component(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model A
  parameter Integer n = 2;
  Real z[n];
equation
  z = zeros(n);
end A;
model M
  A a(n = 3);
end M;
""")
    assert [v.name for v in m.unknowns] == ["a.z[1]", "a.z[2]", "a.z[3]"]


# ----------------------------------------------------------------- if-equations


def test_if_equation_with_parameter_condition(tmp_path: Path) -> None:
    src = """
model M
  parameter Boolean linear = {flag};
  parameter Integer n = 2;
  Real y;
equation
  if linear then
    y = time;
  elseif n > 1 then
    y = time ^ n;
  else
    y = 0;
  end if;
end M;
"""
    assert equations(flat_of(tmp_path, src.replace("{flag}", "true"))) == ["y = time"]
    assert equations(flat_of(tmp_path, src.replace("{flag}", "false"))) == ["y = time ^ n"]


def test_if_expression_inside_no_event(tmp_path: Path) -> None:
    m = flat_of(tmp_path, "model M\n  Real y;\nequation\n"
                "  y = noEvent(if time > 1 then 1 else 0);\nend M;\n")
    assert equations(m) == ["y = noEvent(if time > 1 then 1 else 0)"]


# ------------------------------------------------------------------ connections

PINS = """
connector Pin
  Real v;
  flow Real i;
end Pin;
model Two
  Pin p;
  Pin n;
equation
  p.i + n.i = 0;
end Two;
"""


def test_connection_sets_potentials_and_flow_sums(tmp_path: Path) -> None:
    m = flat_of(tmp_path, PINS + """
model M
  Two a;
  Two b;
  Two c;
equation
  connect(a.n, b.p);
  connect(b.p, c.p);
  connect(a.p, c.n);
end M;
""")
    conn = [eq for eq in m.equations if eq.origin.kind in ("connect", "flow", "unconnected")]
    text = {f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in conn}
    assert text == {
        "a.n.v = b.p.v", "a.n.v = c.p.v", "a.n.i + b.p.i + c.p.i = 0",
        "a.p.v = c.n.v", "a.p.i + c.n.i = 0",
        "b.n.i = 0"}
    assert {e.origin.kind for e in conn if "b.n.i" in x.variables(e.lhs)} == {"unconnected"}


def test_outside_connector_flow_sign(tmp_path: Path) -> None:
    m = flat_of(tmp_path, PINS + """
model Wrapper
  Pin outer_p;
  Pin outer_n;
  Two two;
equation
  connect(outer_p, two.p);
  connect(outer_n, two.n);
end Wrapper;
model M
  Wrapper w;
  Two load;
equation
  connect(w.outer_p, load.p);
  connect(w.outer_n, load.n);
end M;
""")
    text = {f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in m.equations
            if e.origin.kind == "flow"}
    # inside the wrapper, w.outer_p and w.outer_n are outside connectors: their flows
    # enter with -1
    assert text == {"-w.outer_p.i + w.two.p.i = 0", "w.outer_p.i + load.p.i = 0",
                    "-w.outer_n.i + w.two.n.i = 0", "w.outer_n.i + load.n.i = 0"}
    # 2 own equations, 4 potential equalities, 4 flow sums; no unconnected flows
    assert len(m.equations) == 10


def test_connectors_in_arrays_of_components(tmp_path: Path) -> None:
    m = flat_of(tmp_path, PINS + """
model M
  Two r[3];
equation
  for i in 1:2 loop
    connect(r[i].n, r[i + 1].p);
  end for;
  connect(r[3].n, r[1].p);
end M;
""")
    text = [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in m.equations
            if e.origin.kind in ("connect", "flow")]
    assert sorted(text) == sorted([
        "r[1].n.v = r[2].p.v", "r[1].n.i + r[2].p.i = 0",
        "r[2].n.v = r[3].p.v", "r[2].n.i + r[3].p.i = 0",
        "r[3].n.v = r[1].p.v", "r[3].n.i + r[1].p.i = 0"])


def test_connect_of_incompatible_connectors(tmp_path: Path) -> None:
    err = error_of(tmp_path, PINS + """
connector Flange
  Real s;
  flow Real f;
end Flange;
model M
  Two a;
  Flange fl;
equation
  connect(a.p, fl);
end M;
""")
    assert err.message == "connectors 'a.p' (Pin) and 'fl' (Flange) do not match"


# ------------------------------------------------------- initial equations, attributes


def test_initial_equation_section(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model M
  Real x;
  Real v;
initial equation
  x = 1;
  der(x) = 0;
equation
  der(x) = v;
  der(v) = -x;
end M;
""")
    assert equations(m, initial=True) == ["x = 1", "der(x) = 0"]
    assert {e.origin.kind for e in m.initial_equations} == {"initial"}
    assert equations(m) == ["der(x) = v", "der(v) = -x"]


def test_all_attributes(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model M
  parameter Real s0 = 2;
  Real x(start = s0, fixed = true, nominal = 1e3, min = -1, max = 10, unit = "m",
         displayUnit = "mm", stateSelect = StateSelect.prefer);
equation
  der(x) = 1;
end M;
""")
    a = var(m, "x").attributes
    assert (x.to_text(a.start), a.fixed, x.to_text(a.nominal), x.to_text(a.min),
            x.to_text(a.max), a.unit, a.display_unit, a.state_select) == (
        "s0", True, "1000.0", "-1", "10", "m", "mm", "prefer")


def test_unknown_attribute_is_an_error(tmp_path: Path) -> None:
    err = error_of(tmp_path, "model M\n  Real x(strat = 1);\nequation\n  x = 1;\nend M;\n")
    assert "strat" in err.message
    assert err.hint == "did you mean 'start'?"


def test_experiment_annotation(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model M
  Real x;
equation
  x = time;
  annotation(experiment(StartTime = 1, StopTime = 4, Interval = 0.5, Tolerance = 1e-7));
end M;
""")
    e = m.experiment
    assert (e.start, e.stop, e.interval, e.tolerance) == (1.0, 4.0, 0.5, 1e-7)


# -------------------------------------------------------------------- functions


def test_function_with_algorithm_is_inlined(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
function clampSum
  input Real u[:];
  input Real limit = 10;
  output Real y;
algorithm
  y := 0;
  for i in 1:size(u, 1) loop
    y := y + u[i];
  end for;
  if limit < 5 then
    y := 2 * y;
  end if;
end clampSum;
model M
  Real a;
  Real b;
equation
  a = clampSum({1, 2, time});
  b = clampSum({time}, limit = 1);
end M;
""")
    assert equations(m) == ["a = 3 + time", "b = 2 * time"]


def test_builtins(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
model M
  parameter Real v[3] = {3, 0, 4};
  Real n;
  Real c[3];
equation
  n = norm(v) + sum(v) + size(v, 1) + abs(-2) + max(1, 2);
  c = cross(v, {0, 1, 0});
end M;
""")
    assert equations(m) == [
        "n = sqrt(v[1] * v[1] + v[2] * v[2] + v[3] * v[3]) + (v[1] + v[2] + v[3]) + 3 + 2 + 2",
        "c[1] = -v[3]", "c[2] = 0", "c[3] = v[1]"]


# -------------------------------------------------------- imports, within, lookup


def test_import_forms(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """
package Lib
  model A
    Real a = 1;
  end A;
  model B
    Real b = 2;
  end B;
  package Deep
    model C
      Real c = 3;
    end C;
  end Deep;
end Lib;
model M
  import L = Lib;
  import Lib.A;
  import Lib.Deep.*;
  import Lib.{B};
  A a;
  L.B b1;
  B b2;
  C c;
end M;
""")
    assert [v.name for v in m.unknowns] == ["a.a", "b1.b", "b2.b", "c.c"]


def test_within_places_classes_in_a_package(tmp_path: Path) -> None:
    (tmp_path / "p.mdl").write_text("package P\n  constant Real k = 3;\nend P;\n")
    (tmp_path / "m.mdl").write_text("within P;\nmodel M\n  Real x = k;\nend M;\n")
    m = flatten_files([tmp_path / "p.mdl", tmp_path / "m.mdl"])
    assert m.name == "P.M"
    assert equations(m) == ["x = 3"]


def library(tmp_path: Path, folder: str, k: int) -> Path:
    lib = tmp_path / folder
    lib.mkdir()
    (lib / "lib.mdl").write_text(f"package Lib\n  model A\n    Real a = {k};\n"
                                 "  end A;\nend Lib;\n")
    return lib


def test_library_lookup_with_L_and_springc_path(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    first, second = library(tmp_path, "first", 1), library(tmp_path, "second", 2)
    user = tmp_path / "m.mdl"
    user.write_text("model M\n  Lib.A x;\nend M;\n")
    assert equations(flatten_files([user], None, [first])) == ["x.a = 1"]
    monkeypatch.setenv("SPRINGC_PATH", f"{second}")
    assert equations(flatten_files([user])) == ["x.a = 2"]
    # -L takes precedence over SPRINGC_PATH
    assert equations(flatten_files([user], None, [first])) == ["x.a = 1"]


def test_default_model_is_last_model_of_last_file(tmp_path: Path) -> None:
    (tmp_path / "a.mdl").write_text("model A\n  Real a = 1;\nend A;\n"
                                    "model B\n  Real b = 2;\nend B;\n")
    (tmp_path / "c.mdl").write_text("model C\n  Real c = 3;\nend C;\n"
                                    "package P\n  model D\n  Real d = 4;\n  end D;\nend P;\n"
                                    "connector K\n  Real k;\nend K;\n")
    assert flatten_files([tmp_path / "a.mdl"]).name == "B"
    assert flatten_files([tmp_path / "a.mdl", tmp_path / "c.mdl"]).name == "C"
    assert flatten_files([tmp_path / "c.mdl", tmp_path / "a.mdl"]).name == "B"


def test_model_by_dotted_name() -> None:
    tree = load([ROOT / "models" / "Scenes.mdl"])
    m = flatten(tree, "Scenes.Pendulum")
    assert (m.name, len(m.unknowns), len(m.equations)) == ("Scenes.Pendulum", 5, 5)


# ---------------------------------------------------------------- located errors


def test_undefined_names_are_all_reported(tmp_path: Path) -> None:
    with pytest.raises(ErrorGroup) as info:
        flat_of(tmp_path, "model M\n  Real x;\n  Real y;\nequation\n  x = p;\n"
                "  y = q + 1;\n  x = 2 * r;\nend M;\n")
    assert [(e.message, e.span.line, e.span.column) for e in info.value.errors] == [
        ("undefined name 'p'", 5, 7), ("undefined name 'q'", 6, 7),
        ("undefined name 'r'", 7, 11)]


def test_size_mismatch_in_equation(tmp_path: Path) -> None:
    err = error_of(tmp_path, "model M\n  Real x[2];\nequation\n  x = {1, 2, 3};\nend M;\n")
    assert isinstance(err, FlattenError)
    assert err.message == "the two sides of this equation differ in size: [2] and [3]"


def test_per_element_values_must_match_the_component_array(tmp_path: Path) -> None:
    src = BASES + "model M\n  Inner p[2, 2](c = {VALUE});\nend M;\n"
    m = flat_of(tmp_path, src.replace("VALUE", "{1, 2}, {3, 4}"))
    assert [bindings(m)[f"p[{i},{j}].c"] for i in (1, 2) for j in (1, 2)] == \
        ["1", "2", "3", "4"]
    err = error_of(tmp_path, src.replace("VALUE", "{1, 2, 3}, {4, 5, 6}"))
    assert err.message == ("the value of 'c' has size [2, 3], but 'p' is an array of "
                           "components of size [2, 2]")
