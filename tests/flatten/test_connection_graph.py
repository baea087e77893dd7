"""Overdetermined connectors (Modelica 3.6, sections 9.3.1 and 9.4): an element of a
type defining ``equalityConstraint`` counts as its residues in the connector balance;
the graph operators are equations of an equation section (errors elsewhere); the
virtual connection graph: roots by priority, ``rooted`` and ``isRoot``, a loop broken
with ``equalityConstraint``. Exact outcomes and flat equations."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome
from springc.errors import ErrorGroup, SpringcError, errors_of
from springc.ir import expr as x
from springc.pipeline.files import flatten_files

BASE = """model M
  type Angle
    extends Real;
    function equalityConstraint
      input Angle a1;
      input Angle a2;
      output Real residue[RES];
    algorithm
      residue := fill(a1 - a2, RES);
    end equalityConstraint;
  end Angle;
  connector C
    Angle theta;
    Real v;
    flow Real i;
    flow Real j;
  end C;
  C c(theta = 1, v = 2);
  Real x(start = 0, fixed = true);
equation
  der(x) = -x;
BODY
end M;
"""
PLACES = ("help: Connections.branch, root and potentialRoot are equations of an equation "
          "section, outside when-clauses and if-equations with variable conditions "
          "(Modelica 3.6, section 9.4)")


def _model(residues: int, body: str = "") -> str:
    return BASE.replace("RES", str(residues)).replace("BODY\n", body)


CASES = {
    "theta_counts_as_one_residue": (
        _model(1), "M: 5 unknowns, 5 equations, 0 parameters: balanced"),
    "two_residues_unbalance_the_connector": (
        _model(2), "18:5: connector 'c' (M.C) has 2 flow and 3 potential variables\nhelp: a "
        "connector has as many flow variables as variables that are neither parameter, "
        "constant, input, output nor flow (Modelica 3.6, section 9.3.1)"),
    "root_of_an_unconnected_element": (
        _model(1, "  Connections.root(c.theta);\n"),
        "M: 5 unknowns, 5 equations, 0 parameters: balanced"),
    "branch_in_an_algorithm": (
        _model(1, "algorithm\n  Connections.branch(c.theta, c.theta);\n"),
        f"23:3: `Connections.branch` is not allowed in an algorithm section\n{PLACES}"),
    "root_in_an_if_with_a_variable_condition": (
        _model(1, "  if x > 0.5 then\n    Connections.root(c.theta);\n  end if;\n"),
        "23:5: `Connections.root` is not allowed in an if-equation with a variable "
        f"condition\n{PLACES}"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_overdetermined_connectors(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected


GRAPH = (Path(__file__).parent / "models" / "connection_graph.mo")


def _equations(name: str) -> set[str]:
    model = flatten_files([GRAPH], f"G.{name}")
    return {f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in model.equations}


def test_chain_from_a_definite_root() -> None:
    """The ground's root wins over the body's potential root: the body is no root,
    the joint's frame a is rooted (b computed from a), the connections are kept."""
    eqs = _equations("Chain")
    assert {"b.root = 0", "g.f.R.c = j.a.R.c", "j.b.R.s = b.f.R.s",
            "j.b.R.c = j.a.R.c * cos(j.phi) - j.a.R.s * sin(j.phi)"} <= eqs
    assert not any(e.startswith("0 = ") for e in eqs)


def test_potential_root_of_the_lowest_priority_number() -> None:
    """Without a definite root, priority 0 (b2) beats 1 (b1); the joint then computes
    frame a from frame b (not rooted)."""
    eqs = _equations("Priority")
    assert {"b1.root = 0", "b2.root = 1", "b2.f.R.c = cos(time)",
            "j.a.R.c = j.b.R.c * cos(-j.phi) - j.b.R.s * sin(-j.phi)"} <= eqs


def test_a_loop_is_broken_with_the_equality_constraint() -> None:
    """Two joints from the ground to one body close a loop: the connection reached
    last (j2.b to b.f) is broken, its 2 equalities replaced by the 1 residue."""
    eqs = _equations("Loop")
    assert "0 = j2.b.R.s * b.f.R.c - j2.b.R.c * b.f.R.s" in eqs
    assert {"j1.b.R.c = b.f.R.c", "j1.b.R.s = b.f.R.s"} <= eqs
    assert not {e for e in eqs if e.startswith("j2.b.R.") and "b.f.R" in e
                and "cos" not in e}


@pytest.mark.parametrize(("name", "message"), [
    ("NoRoot", "the connection graph of 'j.a.R' has no root"),
    ("RootInBinding", "`Connections.isRoot` is supported only in the conditions of "
     "if-equations"),
])
def test_graph_errors(name: str, message: str) -> None:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        flatten_files([GRAPH], f"G.{name}")
    assert [e.message for e in errors_of(info.value)] == [message]


def test_overdetermined_elements_looked_up_once_per_connector_class(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Four instances of C (c, d, e[1], e[2]): its overdetermined elements are found
    once, and each instance is still checked: with two residues the first one, c, is
    reported with the same counts as a single instance."""
    from springc.flatten.connect import connect_rules

    calls: list[str] = []
    found = connect_rules.overdetermined

    def counted(scope):
        calls.append(scope.entry.full_name)
        return found(scope)

    monkeypatch.setattr(connect_rules, "overdetermined", counted)
    balanced = _model(1).replace("  C c(theta = 1, v = 2);\n",
                                 "  C c(theta = 1, v = 2), d(theta = 1, v = 2);\n"
                                 "  C e[2](each theta = 1, each v = 2);\n")
    assert outcome(tmp_path, balanced) == \
        "M: 17 unknowns, 17 equations, 0 parameters: balanced"  # 4 x 4 + x
    assert calls == ["M.C"]
    calls.clear()
    text = _model(2).replace("  C c(theta = 1, v = 2);\n",
                             "  C c(theta = 1, v = 2), d(theta = 1, v = 2);\n")
    assert outcome(tmp_path, text).startswith(
        "18:5: connector 'c' (M.C) has 2 flow and 3 potential variables\n")
    assert calls == ["M.C"]


SCALAR_LOOP = """model L
  type Angle
    extends Real;
    function equalityConstraint
      input Angle a1;
      input Angle a2;
      output Real residue[1];
    algorithm
      residue := {2 * (a1 - a2)};
    end equalityConstraint;
  end Angle;
  connector C
    Angle theta;
    flow Real i;
  end C;
  C a, b, d;
equation
  a.theta = time;
  b.i = 1;
  d.i = 2;
  connect(a, b);
  connect(b, d);
  connect(d, a);
  Connections.root(a.theta);
end L;
"""


def test_a_loop_of_a_scalar_overdetermined_type(tmp_path: Path) -> None:
    """A type extending Real with an equalityConstraint (not a record): the loop a-b-d
    is broken at b-d (the spanning tree from the root a keeps a-b and d-a), its
    equality replaced by the residue 2 (b.theta - d.theta) of the type's function."""
    path = tmp_path / "loop.mo"
    path.write_text(SCALAR_LOOP)
    model = flatten_files([path])
    eqs = {f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in model.equations}
    thetas = {e for e in eqs if "theta" in e}
    assert thetas == {"a.theta = time", "a.theta = b.theta", "a.theta = d.theta",
                      "0 = 2 * (b.theta - d.theta)"}
