"""Overdetermined connectors (Modelica 3.6, sections 9.3.1 and 9.4): an element of a
type defining ``equalityConstraint`` counts as its residues in the connector balance;
the graph operators are equations of an equation section (``not supported yet`` there,
errors elsewhere). Exact outcomes."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

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
    "root_as_an_equation": (
        _model(1, "  Connections.root(c.theta);\n"),
        "22:3: `Connections.root` (overdetermined connection graphs, section 9.4) is not "
        "supported yet\nhelp: springc supports a subset of Modelica; see \"Not supported "
        "yet\" in docs/language.md"),
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
