"""Records as values (12.6): constructor calls with positional, named and default
arguments, record bindings and record equations field by field, flow on record
components (4.4.2.2): exact flat equations and located errors."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from springc.errors import ErrorGroup, SpringcError, errors_of
from springc.ir import expr as x
from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files

RECORDS = """  record R
    Real x;
    Real y;
  end R;
  record S
    R a;
    Real k = 1;
    constant Real c = 9;
  end S;
"""


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, body: str) -> FlatModel:
    path = tmp_path / "m.mo"
    path.write_text(f"model M\n{RECORDS}{body}end M;\n")
    return flatten_files([path], None)


def equations(m: FlatModel) -> list[str]:
    return [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in m.equations]


def error_of(tmp_path: Path, body: str) -> str:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        flat_of(tmp_path, body)
    (err,) = errors_of(info.value)
    assert err.span is not None
    return f"{err.span.line}:{err.span.column}: {err.message}"


def test_bindings_and_equations_field_by_field(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """  R r1, r2;
  S s1 = S(R(1, 2), 4);
  S s2 = S(k = 3, a = r1);
  S s3 = s1;
  S s4 = S(R(y = 5, x = 6));
equation
  r1 = R(time, 2 * time);
  r2 = r1;
""")
    assert equations(m) == [
        "s1.a.x = 1", "s1.a.y = 2", "s1.k = 4",
        "s2.a.x = r1.x", "s2.a.y = r1.y", "s2.k = 3",
        "s3.a.x = s1.a.x", "s3.a.y = s1.a.y", "s3.k = s1.k",
        # k keeps its default where the constructor leaves it out
        "s4.a.x = 6", "s4.a.y = 5", "s4.k = 1",
        "r1.x = time", "r1.y = 2 * time", "r2.x = r1.x", "r2.y = r1.y"]


def test_flow_on_a_record_component_of_a_connector(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """  connector C
    flow R f;
    Real e;
    Real g;
  end C;
  C c;
equation
  c.e = 1;
  c.g = 2;
""")
    assert [(v.name, v.flow) for v in m.variables] == [
        ("c.f.x", True), ("c.f.y", True), ("c.e", False), ("c.g", False)]
    # unconnected flows are zero (9.2), so the model is balanced
    assert equations(m) == ["c.e = 1", "c.g = 2", "c.f.x = 0", "c.f.y = 0"]


@pytest.mark.parametrize(("body", "message"), [
    ("  R r = R(1, 2, 3);\n", "11:9: record constructor 'M.R' takes 2 argument(s), 3 given"),
    ("  R r = R(1, z = 2);\n", "11:14: record 'M.R' has no field 'z' to set"),
    ("  R r = S(R(1, 2));\n", "11:9: 'r' is a record 'M.R', but its value is a 'M.S'"),
    ("  R r = 3;\n", "11:9: the value of record 'r' must be a record"),
    ("  R r;\nequation\n  r = R(time);\n",
     "13:7: field 'y' of 'r' needs a value in this equation"),
])
def test_record_value_errors(tmp_path: Path, body: str, message: str) -> None:
    assert error_of(tmp_path, body) == message


FUNCTIONS = """  record O
    Real T[2, 2];
    Real w;
  end O;
  record P
    O o;
    Real s;
  end P;
  function null
    output O r;
  algorithm
    r := O(T = [1, 0; 0, 1], w = 0);
  end null;
  function planar
    input Real a;
    input Real wa;
    output O r;
  algorithm
    r.T := [cos(a), sin(a); -sin(a), cos(a)];
    r.w := wa;
  end planar;
  function compose
    input O r1;
    input O r2;
    output O r;
  algorithm
    r := O(T = r2.T * r1.T, w = r1.w + r2.w);
  end compose;
  function scaled
    input P p;
    output P q;
  algorithm
    q := P(o = compose(p.o, p.o), s = 2 * p.s);
  end scaled;
  function resolve
    input O r;
    input Real v[2];
    output Real y[2];
  algorithm
    y := r.T * v;
  end resolve;
  function g = gain(k = kk);
  function gain
    input Real u;
    input Real k = 1;
    output Real y;
  algorithm
    y := k * u;
  end gain;
  parameter Real kk = 3;
"""


def test_records_returned_by_functions(tmp_path: Path) -> None:
    """A record returned by a function binds a parameter record, an array field and a
    nested record; record components are function inputs; a record output is filled
    field by field; a function defined by a modification of another gives its input
    defaults."""
    m = flat_of(tmp_path, FUNCTIONS + """  parameter O r0 = null();
  parameter P p = scaled(P(o = planar(0.5, 2), s = 4));
  O r;
  Real y[2];
  Real z;
equation
  r = compose(r0, planar(time, 1));
  y = resolve(r, {1, 2});
  z = g(time);
""")
    got = {v.name: v.binding for v in m.variables if v.binding is not None}
    assert x.to_text(got["r0.T[1,1]"]) == "1" and x.to_text(got["r0.T[1,2]"]) == "0"
    c, s_ = math.cos(1.0), math.sin(1.0)  # planar(0.5) twice is planar(1)
    assert float(x.to_text(got["p.o.T[1,1]"])) == pytest.approx(c, abs=1e-12)
    assert float(x.to_text(got["p.o.T[1,2]"])) == pytest.approx(s_, abs=1e-12)
    assert float(x.to_text(got["p.o.w"])) == 4 and float(x.to_text(got["p.s"])) == 8
    eqs = equations(m)
    assert "r.w = r0.w + 1" in eqs
    assert "z = kk * time" in eqs
    assert len(eqs) == 4 + 1 + 2 + 1


@pytest.mark.parametrize(("body", "message"), [
    ("  Real y[2] = resolve(O(w = 1), {1, 2});\n",
     "field 'T' of record 'M.O' needs a value in this constructor call"),
    ("  Real y = null();\n", "'y' is not a record, but its value is a record 'M.O'"),
    ("  Real y[2] = resolve(1, {1, 2});\n", "'T' cannot be selected from a value"),
])
def test_record_function_errors(tmp_path: Path, body: str, message: str) -> None:
    assert error_of(tmp_path, FUNCTIONS + body).split(": ", 1)[1] == message


def test_final_record_bound_to_a_function(tmp_path: Path) -> None:
    """``final R = f(x)`` in a modification (MultiBody's World.surface)."""
    m = flat_of(tmp_path, FUNCTIONS + """  model Holder
    input O R = null();
  end Holder;
  Holder h(final R = planar(0, 2));
""")
    assert equations(m) == ["h.R.T[1,1] = 1.0", "h.R.T[1,2] = 0.0", "h.R.T[2,1] = -0.0",
                            "h.R.T[2,2] = 1.0", "h.R.w = 2"]


def test_a_redeclared_function_keeps_the_values_its_redeclaration_gives(
        tmp_path: Path) -> None:
    """``world(redeclare function gravityAcceleration = g(phi = lat))`` and a call
    ``world.gravityAcceleration(r)`` (MultiBody's UserDefinedGravityField): ``phi`` takes
    the value the redeclaration gives, evaluated where it is written (was "input 'phi' is
    missing in this call")."""
    path = tmp_path / "m.mo"
    path.write_text("""package P
  function constant_g
    input Real r;
    output Real g;
  algorithm
    g := 2;
  end constant_g;
  function latitude_g
    input Real r;
    input Real phi;
    output Real g;
  algorithm
    g := r * phi;
  end latitude_g;
  model World
    replaceable function gravityAcceleration = constant_g;
  end World;
  model M
    parameter Real lat = 3;
    World world(redeclare function gravityAcceleration = latitude_g(phi = lat));
    World plain;
    Real z = world.gravityAcceleration(5);
    Real w = plain.gravityAcceleration(5);
  end M;
end P;
""")
    m = flatten_files([path], "P.M")
    assert equations(m) == ["z = 5 * lat", "w = 2"]
