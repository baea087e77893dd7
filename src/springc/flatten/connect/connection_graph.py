"""Overdetermined connection graphs (Modelica 3.6, section 9.4).

An element of a connector whose type defines ``equalityConstraint`` (MultiBody's
``Frames.Orientation``) is a node of the virtual connection graph; ``connect`` gives
an optional (breakable) edge between two such nodes, ``Connections.branch`` a
required one, ``Connections.root`` a definite root and ``Connections.potentialRoot``
a potential one (the lowest priority number wins). :meth:`ConnectionGraph.solve`
builds, per connected part, a spanning tree from its roots (required edges first,
breadth first): the connect edges of the tree give the usual equality equations of
the element, each one left out is broken and gives the residues of
``equalityConstraint`` instead (made by the flattener: ``flatten/overdetermined``).
``Connections.isRoot(a)`` and ``Connections.rooted(a)`` are then constants; the
if-equations that test them wait until the graph is solved.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import FlattenError, Span
from ...ir import expr as x
from ...ir import syntax as s
from ..checks import rule_error
from ..scopes import ClassScope, ExpressionEvaluator, Scope

#: The operators written as equations, and those used in expressions.
GRAPH_EQUATIONS = frozenset({"Connections.branch", "Connections.root",
                             "Connections.potentialRoot"})
GRAPH_FUNCTIONS = frozenset({"Connections.isRoot", "Connections.rooted", "rooted"})


@dataclass
class Edge:
    """An optional edge: ``connect`` of two connectors ``a`` and ``b`` (scopes) whose
    element ``element`` is overdetermined; ``pairs``: the scalar variables the
    element's equality equations would join; ``link``: the connect's origin."""

    a: str
    b: str
    scopes: tuple[Any, Any]
    element: str
    pairs: list[tuple[Any, Any]]
    link: Any


@dataclass
class ConnectionGraph:
    roots: dict[str, Span] = field(default_factory=dict)
    potential: dict[str, tuple[int, Span]] = field(default_factory=dict)
    branches: dict[str, list[tuple[str, Span]]] = field(default_factory=dict)
    edges: list[Edge] = field(default_factory=list)
    # after solve(): the chosen roots, each node's parent in its tree, the broken edges
    solved: bool = False
    chosen: set[str] = field(default_factory=set)
    parent: dict[str, str | None] = field(default_factory=dict)
    broken: list[Edge] = field(default_factory=list)
    kept: list[Edge] = field(default_factory=list)

    def operator(self, call: s.Call, nodes: list[str], priority: int) -> None:
        """Record ``Connections.root/potentialRoot/branch`` of ``nodes``."""
        name = call.func.dotted
        if self.solved:
            raise FlattenError(f"`{name}` inside an if-equation on Connections.isRoot or "
                               "rooted is not supported yet", call.span)
        if name == "Connections.root":
            self.roots.setdefault(nodes[0], call.span)
        elif name == "Connections.potentialRoot":
            old = self.potential.get(nodes[0])
            if old is None or priority < old[0]:
                self.potential[nodes[0]] = (priority, call.span)
        else:
            self.branches.setdefault(nodes[0], []).append((nodes[1], call.span))
            self.branches.setdefault(nodes[1], []).append((nodes[0], call.span))

    def solve(self) -> None:
        """The spanning trees; broken edges in ``broken``, kept ones in ``kept``."""
        self.solved = True
        adjacent: dict[str, list[tuple[int, str, Edge | None]]] = {}
        for a, others in self.branches.items():
            for b, _ in others:
                adjacent.setdefault(a, []).append((0, b, None))
        for edge in self.edges:
            adjacent.setdefault(edge.a, []).append((1, edge.b, edge))
            adjacent.setdefault(edge.b, []).append((1, edge.a, edge))
        nodes = [*self.roots, *self.potential, *adjacent]
        parts = _parts(nodes, adjacent)
        for part in parts:
            self.chosen.update(self._roots_of(part))
        # 0-1 breadth first search from all roots: required edges before optional ones
        queue: deque[tuple[str, str | None, Edge | None]] = deque(
            (r, None, None) for r in nodes if r in self.chosen)
        used: set[int] = set()
        while queue:
            node, parent, through = queue.popleft()
            if node in self.parent:
                continue
            self.parent[node] = parent
            if through is not None:
                used.add(id(through))
            for cost, other, via in adjacent.get(node, ()):
                if other not in self.parent:
                    (queue.appendleft if cost == 0 else queue.append)((other, node, via))
        for a, others in self.branches.items():
            for b, span in others:
                if self.parent.get(a) != b and self.parent.get(b) != a:
                    raise rule_error(f"the required branches of '{a}' and '{b}' "
                                     "(Connections.branch) close a loop, or join two "
                                     "roots", span, "a loop of the virtual connection "
                                     "graph must contain a connect that can be broken",
                                     "9.4.2")
        for edge in self.edges:
            (self.kept if id(edge) in used else self.broken).append(edge)

    def _roots_of(self, part: list[str]) -> list[str]:
        definite = [n for n in part if n in self.roots]
        if definite:
            return definite
        candidates = [n for n in part if n in self.potential]
        if not candidates:
            raise FlattenError(f"the connection graph of '{part[0]}' has no root",
                               None, hint="one of its overdetermined elements needs "
                               "Connections.root or Connections.potentialRoot (9.4)")
        best = min(self.potential[n][0] for n in candidates)
        return [next(n for n in candidates if self.potential[n][0] == best)]

    def is_root(self, node: str) -> bool:
        return node in self.chosen

    def rooted(self, node: str, span: Span) -> bool:
        """Whether ``node`` is closer to the root than the other end of its branch."""
        others = self.branches.get(node, [])
        if len(others) != 1:
            raise FlattenError(f"Connections.rooted('{node}') needs exactly one "
                               f"Connections.branch of '{node}', found {len(others)}",
                               span)
        return self.parent.get(others[0][0]) == node


def _parts(nodes: list[str], adjacent: dict[str, list[tuple[int, str, Any]]]
           ) -> list[list[str]]:
    """The connected parts, each in the order of ``nodes``."""
    seen: set[str] = set()
    out = []
    order: dict[str, int] = {}
    for node in nodes:
        order.setdefault(node, len(order))
    for start in nodes:
        if start in seen:
            continue
        part, todo = [], [start]
        seen.add(start)
        while todo:
            node = todo.pop()
            part.append(node)
            for _, other, _ in adjacent.get(node, ()):
                if other not in seen:
                    seen.add(other)
                    todo.append(other)
        out.append(sorted(part, key=order.__getitem__))
    return out


def graph_node(ev: ExpressionEvaluator, arg: s.Expr, where: Scope) -> str:
    """The node an operator's argument names: the flat name of an overdetermined
    record (``frame_a.R``) or of an overdetermined array or scalar."""
    target = ev.reference(arg, where) if isinstance(arg, s.Ref) else None
    if isinstance(target, ClassScope):
        return target.prefix
    first = target.flat[0] if isinstance(target, np.ndarray) and target.size else target
    if isinstance(first, x.Var):
        return first.name.split("[")[0] if isinstance(target, np.ndarray) else first.name
    raise FlattenError("the argument of a Connections operator must name an element of "
                       "an overdetermined type", arg.span, hint="such as frame_a.R "
                       "(section 9.4)")


def operator_nodes(ev: ExpressionEvaluator, call: s.Call, where: Scope
                   ) -> tuple[list[str], int]:
    """The nodes of ``Connections.root/potentialRoot/branch(...)`` and the priority."""
    name = call.func.dotted
    count = 2 if name == "Connections.branch" else 1
    args = list(call.args)
    priority = 0
    for named in call.named:
        if name == "Connections.potentialRoot" and named.name == "priority":
            priority = ev.integer(named.value, where, "the priority of a potential root")
        else:
            raise FlattenError(f"`{name}` has no argument '{named.name}'", named.span)
    if name == "Connections.potentialRoot" and len(args) == 2:
        priority = ev.integer(args.pop(), where, "the priority of a potential root")
    if len(args) != count:
        raise FlattenError(f"`{name}` takes {count} argument(s), {len(args)} given",
                           call.span)
    return [graph_node(ev, arg, where) for arg in args], priority


def graph_value(ev: ExpressionEvaluator, graph: ConnectionGraph, call: s.Call,
                where: Scope) -> x.Expr:
    """``Connections.isRoot(a)`` or ``Connections.rooted(a)`` once the graph is solved."""
    name = call.func.dotted
    if not graph.solved:
        raise FlattenError(f"`{name}` is supported only in the conditions of if-equations",
                           call.func.span, hint="its value is known once every "
                           "connection of the model is (section 9.4)")
    if len(call.args) != 1 or call.named:
        raise FlattenError(f"`{name}` takes one argument", call.span)
    node = graph_node(ev, call.args[0], where)
    value = graph.is_root(node) if name == "Connections.isRoot" \
        else graph.rooted(node, call.span)
    return x.Const(value)


def uses_graph(e: object) -> bool:
    """Whether a syntax expression calls ``Connections.isRoot`` or ``rooted``."""
    if isinstance(e, s.Call) and e.func.dotted in GRAPH_FUNCTIONS:
        return True
    if isinstance(e, tuple):
        return any(uses_graph(item) for item in e)
    fields = getattr(e, "__dataclass_fields__", None)
    if fields is None or isinstance(e, Span):
        return False
    return any(uses_graph(getattr(e, name)) for name in fields)


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

