"""The virtual connection graph solved (section 9.4), after every equation section of
the model is flat and before the initial equations: the spanning trees
(``connect.ConnectionGraph.solve``), the equality equations of the connections they
keep, ``0 = equalityConstraint(a, b)`` for each connection they break, then the
if-equations that test ``Connections.isRoot`` or ``rooted``, which waited.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import FlattenError
from ..ir import expr as x
from ..ir import flat
from ..ir import syntax as s
from ..parse import member_class
from . import arrays as a
from .calls import call_function
from .connect import Edge
from .scopes import ClassScope, Primitive

if TYPE_CHECKING:
    from .equations import EquationFlattening as Flattener


def solve_graph(fl: Flattener) -> None:
    """Solve the graph, add the equations of its connections, run the waiting ifs."""
    graph = fl.connections.graph
    try:
        graph.solve()
    except FlattenError as err:
        fl.report(err)
        return
    fl.connections.join_kept()
    for edge in graph.broken:
        try:
            fl.equations += _residues(fl, edge)
        except FlattenError as err:
            fl.report(err)
    for eq, where, owner, initial, written_in in fl.deferred_ifs:
        fl.written_in = written_in
        try:
            fl.equation(eq, where, owner, initial)
        except FlattenError as err:
            fl.report(err)
        finally:
            fl.written_in = None
    fl.deferred_ifs.clear()


def _residues(fl: Flattener, edge: Edge) -> list[flat.Equation]:
    """``0 = equalityConstraint(a, b)`` of a broken connection, one per residue."""
    ca, cb = edge.scopes
    elements = [c.member(edge.element) for c in (ca, cb)]
    if all(isinstance(e, ClassScope) and e.kind == "record" for e in elements):
        constraint = member_class(elements[0].entry, "equalityConstraint")
        values = [fl.evaluator.record_value(e) for e in elements]
    elif all(isinstance(e, Primitive) and not e.dims for e in elements):
        # a scalar of a type extending Real (`type Angle extends Real; function
        # equalityConstraint ...`): the function of the type the connector declares
        comp = ca.view.components[edge.element]
        constraint = member_class(fl.resolve_class(comp.decl.type_name, comp.defined_in),
                                  "equalityConstraint")
        values = [e.value for e in elements]
    else:
        raise FlattenError(f"breaking the connection of '{edge.a}' and '{edge.b}' needs "
                           "the equalityConstraint of an overdetermined type that is "
                           "neither a record nor a scalar type, which is not supported "
                           "yet", edge.link.span)
    assert constraint is not None  # the element is overdetermined because of it
    span = edge.link.span
    call = s.Call(s.Ref((s.RefPart("equalityConstraint", (), span),), span), (), (), span)
    residue = call_function(fl.evaluator, constraint, values, {}, call)
    origin = flat.Origin("connect", edge.link.owner,
                         f"equalityConstraint of broken {edge.link.text}")
    items = list(residue.flat) if a.is_array(residue) else [residue]
    out = []
    for r in items:
        if isinstance(r, str | a.RecordValue | np.ndarray):
            raise FlattenError("equalityConstraint must return an array of Real residues",
                               constraint.defn.span)
        out.append(flat.Equation(x.ZERO, r, span, origin))
    return out
