"""The operators of overdetermined connection graphs (Modelica 3.6, section 9.4):
``Connections.branch``, ``root`` and ``potentialRoot`` as equations, ``isRoot`` and
``rooted`` in expressions. springc does not build the graph: written as equations they
are "not supported yet"; written where the specification does not allow them (in an
algorithm section, in an if-equation with a variable condition) they are errors.
"""

from __future__ import annotations

from ...errors import FlattenError
from ...ir import syntax as s
from ..checks import rule_error

#: The operators written as equations, and those used in expressions.
GRAPH_EQUATIONS = frozenset({"Connections.branch", "Connections.root",
                             "Connections.potentialRoot"})
GRAPH_FUNCTIONS = frozenset({"Connections.isRoot", "Connections.rooted"})

_HINT = "springc supports a subset of Modelica; see \"Not supported yet\" in docs/language.md"


def graph_equation(call: s.Call) -> FlattenError:
    """``Connections.root(f.R);`` as an equation."""
    return FlattenError(f"`{call.func.dotted}` (overdetermined connection graphs, section "
                        "9.4) is not supported yet", call.func.span, hint=_HINT)


def misplaced(call: s.Call, where: str) -> FlattenError:
    """``Connections.branch(...)`` in a place where only an equation may be."""
    return rule_error(f"`{call.func.dotted}` is not allowed in {where}", call.func.span,
                      "Connections.branch, root and potentialRoot are equations of an "
                      "equation section, outside when-clauses and if-equations with "
                      "variable conditions", "9.4")


def check_branches(body: tuple[s.Equation, ...], where: str) -> None:
    """The equations of ``body`` (at any depth) include no graph operator."""
    for eq in body:
        if isinstance(eq, s.CallEquation) and eq.call.func.dotted in GRAPH_EQUATIONS:
            raise misplaced(eq.call, where)
        if isinstance(eq, s.ForEquation):
            check_branches(eq.body, where)
        elif isinstance(eq, s.IfEquation):
            for _, inner in eq.branches:
                check_branches(inner, where)
            check_branches(eq.otherwise, where)
