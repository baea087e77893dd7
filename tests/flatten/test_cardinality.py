"""``cardinality(c)`` (Modelica 3.6, 3.7.4.4): the number of connect equations naming
the connector ``c``, counted after the whole model is flat (the connects of the
enclosing model included); exact flat equations and the located error for a
non-connector argument."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import SpringcError
from springc.ir import expr as x
from springc.pipeline.files import flatten_files

MODEL = """model Card
  connector C
    Real e;
    flow Real f;
  end C;
  model M
    C c1, c2, c3, c4;
    Integer n1 = cardinality(c1);
    Integer n2 = cardinality(c2);
    Integer n4 = cardinality(c4);
  equation
    c1.e = 1.0;
    c1.f = 1.0;
    c2.f = 2.0;
    c4.e = 3.0;
    c4.f = 0.0;
    assert(cardinality(c3) == 1, "c3 is connected once");
  end M;
  M m;
equation
  connect(m.c1, m.c2);
  connect(m.c2, m.c3);
end Card;
"""


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def test_cardinality_counts_the_connects_of_the_enclosing_model(tmp_path: Path) -> None:
    path = tmp_path / "Card.mo"
    path.write_text(MODEL)
    m = flatten_files([path], None)
    eqs = {x.to_text(e.lhs): x.to_text(e.rhs) for e in m.equations}
    assert (eqs["m.n1"], eqs["m.n2"], eqs["m.n4"]) == ("1", "2", "0")
    # the condition the count decides is evaluated
    assert [x.to_text(a.condition) for a in m.assertions] == ["true"]


def test_cardinality_of_a_real_variable_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "Bad.mo"
    path.write_text("model Bad\n  Real x = 1.0;\n  Integer n = cardinality(x);\nend Bad;\n")
    with pytest.raises(SpringcError) as info:
        flatten_files([path], None)
    assert str(info.value) == (
        f"{path}:3:27: error: the argument of cardinality must be a connector\n"
        "    3 |   Integer n = cardinality(x);\n"
        "      |                           ^\n"
        "help: cardinality(c) counts the connect equations that name the connector c, a "
        "scalar connector (Modelica 3.6, section 3.7.4.4)")


# Three springs meeting at a massless node (MultiBody.Examples.Elementary.ThreeSprings in
# one dimension); each spring's fa, fb as MultiBody's LineForceWithMass defines them, by
# an if-equation on the cardinalities of its flanges.
NODE_SPRINGS = """model NodeSprings
  connector Flange
    Real s;
    flow Real f;
  end Flange;
  model LineSpring "fa, fb as in MultiBody's LineForceWithMass"
    parameter Real c, s0 = 0.5;
    Flange flange_a, flange_b;
    Real fa, fb, f;
  equation
    if cardinality(flange_a) > 0 and cardinality(flange_b) > 0 then
      fa = flange_a.f;
      fb = flange_b.f;
    elseif cardinality(flange_a) > 0 and cardinality(flange_b) == 0 then
      fa = flange_a.f;
      fb = -fa;
    elseif cardinality(flange_a) == 0 and cardinality(flange_b) > 0 then
      fa = -fb;
      fb = flange_b.f;
    else
      fa = 0;
      fb = 0;
    end if;
    f = c*(flange_b.s - flange_a.s - s0);
    fb = f;
    fa = -f;
  end LineSpring;
  model Fixed
    parameter Real s0;
    Flange flange;
  equation
    flange.s = s0;
  end Fixed;
  model Mass
    parameter Real m = 1;
    Flange flange;
    Real v(start = 0, fixed = true);
  equation
    der(flange.s) = v;
    m*der(v) = flange.f;
  end Mass;
  Fixed left(s0 = 0), right(s0 = 2);
  LineSpring sp1(c = 10), sp2(c = 20), sp3(c = 30);
  Mass mass(flange.s(start = 1.5, fixed = true));
equation
  connect(left.flange, sp1.flange_a);
  connect(sp1.flange_b, sp2.flange_a);
  connect(sp3.flange_b, sp1.flange_b);
  connect(right.flange, sp3.flange_a);
  connect(sp2.flange_b, mass.flange);
end NodeSprings;
"""


def test_an_if_equation_on_cardinalities_keeps_the_branch_that_holds(
        tmp_path: Path) -> None:
    import numpy as np

    import springc

    path = tmp_path / "NodeSprings.mo"
    path.write_text(NODE_SPRINGS)
    m = flatten_files([path], None)
    eqs = [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in m.equations]
    # Not `sp1.fb = if 1 > 0 and 2 > 0 then sp1.flange_b.f else if 1 > 0 and 2 == 0
    # then -sp1.fa else ...`, which reads sp1.fa: ThreeSprings' node became one torn
    # system of positions and forces whose Newton iteration, from forces 0, never
    # moved the forces (did not converge at t = 0).
    assert [e for e in eqs if e.startswith(("sp1.fa =", "sp1.fb ="))] == [
        "sp1.fa = sp1.flange_a.f", "sp1.fb = sp1.flange_b.f", "sp1.fb = sp1.f",
        "sp1.fa = -sp1.f"]
    result = springc.simulate(path, stop=2.0, interval=0.01, rtol=1e-10, atol=1e-12,
                              cache=False)
    # Closed form: node n = (c1 L + c2 (x - L) + c3 (2 + L))/C, C = c1 + c2 + c3, so
    # m x'' = -c2 (x - n - L) = -k (x - x_eq), k = c2 (c1 + c3)/C.
    c1, c2, c3, rest = 10.0, 20.0, 30.0, 0.5
    total = c1 + c2 + c3
    offset = (c1 * rest - c2 * rest + c3 * (2 + rest)) / total
    k = c2 * (c1 + c3) / total
    equilibrium = (rest + offset) / (1 - c2 / total)
    exact = equilibrium + (1.5 - equilibrium) * np.cos(np.sqrt(k) * result.time)
    assert np.max(np.abs(result["mass.flange.s"] - exact)) < 1e-8
