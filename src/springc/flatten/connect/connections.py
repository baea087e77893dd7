"""Connection sets (Modelica chapter 9.2): from ``connect`` statements to equations.

Set members are scalar connector variables tagged inside or outside: a connector
reached through a sub-component (``spring.flange_a``) is inside, a connector of the
model that writes the ``connect`` (``flange_a``) is outside. Each set gives equal
potentials and a zero sum of flows (outside flows counted negative); flow variables of
connectors that are connected nowhere are set to zero.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import FlattenError, Note, Span
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ..scopes import (
    ClassScope,
    DisabledReference,
    ExpressionEvaluator,
    Leaf,
    LocalScope,
    Primitive,
    Scope,
    ViewComponent,
)
from .connect_rules import (
    check_pair,
    check_reference_form,
    check_signal_types,
    check_sources,
    overdetermined,
)
from .connection_graph import ConnectionGraph, Edge
from .expandable import (
    absent,
    augmented_connector,
    augmented_declaration,
    augmenting,
    both_undeclared,
    lone_input,
    undeclared_member,
)

Key = tuple[str, bool]  # (flat variable name, outside)


@dataclass(frozen=True, slots=True)
class Link:
    """Why a member joined its set: the connect statement, its owner and its text."""

    span: Span
    owner: str
    text: str


def connector_leaves(scope: ClassScope) -> list[Leaf]:
    """Scalar non-parameter variables of a connector, in declaration order."""
    if scope.connector_leaves is not None:
        return scope.connector_leaves
    leaves: list[Leaf] = []
    cut = len(scope.prefix) + 1
    for _, member in scope.all_members():
        if isinstance(member, Primitive):
            if member.variability in ("parameter", "constant"):
                continue
            names = [member.names] if isinstance(member.names, str) else list(member.names.flat)
            leaves += [Leaf(n[cut:], n, member.flow) for n in names]
        else:
            for item in (member.flat if isinstance(member, np.ndarray) else [member]):
                leaves += [Leaf(leaf.name[cut:], leaf.name, leaf.flow)
                           for leaf in connector_leaves(item)]
    scope.connector_leaves = leaves
    scope.connector_signature = tuple((leaf.relative, leaf.flow) for leaf in leaves)
    return leaves


def direct_reference(ref: s.Ref, where: Scope) -> ClassScope | None:
    """``p[i - 1, j].flange`` inside ``for`` loops, resolved by indexing the arrays of
    components directly; None (use the general evaluator) for anything else. Valid
    because the general evaluator gives the same instance for such a reference: the
    components exist (the walk created them), the subscripts are integers computed
    from loop indices and literals, and an index out of range goes the general way,
    which reports it."""
    indices: dict[str, Any] = {}
    while type(where) is LocalScope:
        for name, value in where.names.items():
            indices.setdefault(name, value)
        where = where.parent
    current: Any = where
    for part in ref.parts:
        if type(current) is not ClassScope or part.name in indices \
                or part.name not in current.view.components:
            return None
        current = current.member(part.name)
        if part.subscripts:
            if type(current) is not np.ndarray or current.ndim != len(part.subscripts):
                return None
            position = []
            for sub, size in zip(part.subscripts, current.shape):
                k = _integer(sub, indices)
                if k is None or not 1 <= k <= size:
                    return None
                position.append(k - 1)
            current = current[tuple(position)]
    return current if type(current) is ClassScope else None


def _integer(e: s.Expr, indices: dict[str, Any]) -> int | None:
    """An integer subscript made of literals, loop indices, ``+`` and ``-``; else None."""
    kind = type(e)
    if kind is s.Number:
        return e.value if type(e.value) is int else None  # type: ignore[union-attr]
    if kind is s.Ref:
        if len(e.parts) != 1 or e.parts[0].subscripts:  # type: ignore[union-attr]
            return None
        found = indices.get(e.parts[0].name)  # type: ignore[union-attr]
        if type(found) is x.Const and type(found.value) is int:
            return found.value
        return None
    if kind is s.Binary and e.op in ("+", "-"):  # type: ignore[union-attr]
        left = _integer(e.left, indices)  # type: ignore[union-attr]
        right = _integer(e.right, indices)  # type: ignore[union-attr]
        if left is None or right is None:
            return None
        return left + right if e.op == "+" else left - right  # type: ignore[union-attr]
    return None


def _protected_head(ref: s.Ref, owner: ClassScope) -> bool:
    """Whether ``ref`` starts at a protected component of ``owner``."""
    comp = owner.view.components.get(ref.parts[0].name)
    return comp is not None and comp.decl.protected


class ConnectionSets:
    def __init__(self) -> None:
        self.parent: dict[Key, Key] = {}
        self.flow: dict[Key, bool] = {}
        self.link: dict[Key, Link] = {}
        self.causal: dict[str, str] = {}  # flat name -> input/output, for check_sources
        self.leaf_types: dict[str, Primitive] = {}  # flat name -> its signal's declaration
        self.counts: Counter[str] = Counter()  # connect equations per connector (cardinality)
        # protected outside connectors: a signal's source only when public (9.3)
        self.protected: set[str] = set()
        self.graph = ConnectionGraph()  # overdetermined elements (section 9.4)
        self._special: dict[str, dict[str, int]] = {}  # by connector class
        # inputs added to expandable connectors (9.1.3), and the expandable connectors
        # connected to another one: an added input needs one (see expandable.lone_input)
        self.added_inputs: list[tuple[ClassScope, str, Span]] = []
        self.joined: set[int] = set()
        self.augmented_buses: list[ClassScope] = []  # in the order first augmented

    def _find(self, key: Key) -> Key:
        root = key
        while self.parent[root] != root:
            root = self.parent[root]
        while self.parent[key] != root:
            self.parent[key], key = root, self.parent[key]
        return root

    def _add(self, key: Key, flow: bool, link: Link) -> None:
        if key not in self.parent:
            self.parent[key] = key
            self.flow[key] = flow
            self.link[key] = link

    def connect(self, ev: ExpressionEvaluator, eq: s.Connect, where: Scope,
                owner: ClassScope) -> None:
        """Record ``connect(a, b)``; both sides may be arrays of connectors. A connection
        naming a disabled conditional component is dropped (Modelica 4.4.5)."""
        self._augment(ev, eq, where)
        try:
            sides = [self._connectors(ev, ref, where, owner) for ref in (eq.a, eq.b)]
        except DisabledReference:
            return
        (left_shape, left, left_out), (right_shape, right, right_out) = sides
        if left_shape != right_shape:
            raise FlattenError(
                f"cannot connect arrays of {len(left)} and {len(right)} connectors",
                eq.span, hint="connect arrays of connectors of the same size")
        for ref, out, items in ((eq.a, left_out, left), (eq.b, right_out, right)):
            if out and _protected_head(ref, owner):
                self.protected.update(c.name if isinstance(c, Leaf) else c.prefix
                                      for c in items)
        for ca, cb in zip(left, right):
            self._pair(ca, cb, left_out, right_out, eq, owner)
            for c in (ca, cb):
                self.counts[c.name if isinstance(c, Leaf) else c.prefix] += 1

    def _connectors(self, ev: ExpressionEvaluator, ref: s.Ref, where: Scope, owner: ClassScope
                    ) -> tuple[tuple[int, ...], list[Any], bool]:
        """The connectors a reference denotes: their array shape (a single connector
        counts as an array of one), the connectors in order, and whether they are
        outside connectors of ``owner``."""
        check_reference_form(ref, owner)
        value = direct_reference(ref, where)
        if value is None:
            signal = _signal_connector(ev, ref, where, self.causal, self.leaf_types)
            if signal is not None:
                return signal
            value = ev.reference(ref, where)
        if isinstance(value, ClassScope):  # the common case, without numpy
            shape, items = (1,), [value]
        else:
            array = np.atleast_1d(np.asarray(value, dtype=object))
            shape, items = array.shape, list(array.flat)
        if not items or not all(isinstance(c, ClassScope) and c.kind == "connector"
                                for c in items):
            raise FlattenError(f"'{ref.dotted}' is not a connector", ref.span,
                               hint="connect(...) joins connectors, such as flanges")
        # outside: a connector of the class itself, or an element of one (`q.y` with
        # `q` a connector of the class); inside: one of a component (section 9.1.2)
        head = ref.parts[0].name
        first = owner.member(head) if owner.has_member(head) else None
        if isinstance(first, np.ndarray):
            first = first.flat[0] if first.size else None
        outside = isinstance(first, ClassScope) and first.kind == "connector" \
            and first.outer is owner
        return shape, items, outside

    def _augment(self, ev: ExpressionEvaluator, eq: s.Connect, where: Scope) -> None:
        """``connect(u, bus.x)`` with ``x`` not declared in the expandable ``bus``:
        ``x`` added to ``bus`` (9.1.3), where springc can."""
        buses = [_undeclared_in(ev, ref, where) for ref in (eq.a, eq.b)]
        if buses[0] is not None and buses[1] is not None:
            raise both_undeclared(eq.a, eq.span)
        for bus, ref, other in ((buses[0], eq.a, eq.b), (buses[1], eq.b, eq.a)):
            if bus is None:
                continue
            found = _declared_member(ev, other, where)
            member = found[0] if found is not None else None
            added = None
            if isinstance(member, Primitive) and member.connector:
                added = augmented_declaration(bus, ref.parts[-1], member,
                                              len(other.parts) == 1)
            elif isinstance(member, ClassScope) and found is not None:
                added = augmented_connector(ref.parts[-1], member, found[1])
            if added is not None:  # else the located "not supported yet" follows
                decl, deduced = added
                if not bus.augmented:
                    self.augmented_buses.append(bus)
                bus.augmented[decl.decl.name] = decl
                if deduced == "input":
                    self.added_inputs.append((bus, bus.flat_name(decl.decl.name), eq.span))

    def _pair(self, ca: ClassScope | Leaf, cb: ClassScope | Leaf, out_a: bool, out_b: bool,
              eq: s.Connect, owner: ClassScope) -> None:
        if isinstance(ca, Leaf) or isinstance(cb, Leaf):
            self._pair_signals(ca, cb, out_a, out_b, eq, owner)
            return
        leaves_a, leaves_b = connector_leaves(ca), connector_leaves(cb)
        if ca.connector_signature != cb.connector_signature and ca.expandable \
                and cb.expandable:
            raise augmenting(ca, cb, eq.span)
        if ca.expandable and cb.expandable:
            self.joined.update((id(ca), id(cb)))
        if ca.connector_signature != cb.connector_signature:
            raise FlattenError(
                f"connectors '{ca.prefix}' ({ca.entry.full_name}) and '{cb.prefix}' "
                f"({cb.entry.full_name}) do not match", eq.span,
                [Note(f"'{ca.entry.full_name}' has {_describe_leaves(leaves_a)}",
                      ca.entry.defn.span),
                 Note(f"'{cb.entry.full_name}' has {_describe_leaves(leaves_b)}",
                      cb.entry.defn.span)],
                "connect connectors with the same variables (names, sizes and flow "
                "prefixes)")
        self.causal.update(check_pair(ca, cb, eq))
        link = Link(eq.span, owner.prefix, f"connect({ca.prefix}, {cb.prefix})")
        special = self._special.get(ca.entry.full_name)
        if special is None:
            special = self._special[ca.entry.full_name] = overdetermined(ca)
        edges: dict[str, Edge] = {}
        for p, q in zip(leaves_a, leaves_b):
            ka, kb = (p.name, out_a), (q.name, out_b)
            element = p.relative.split(".")[0].split("[")[0]
            if element in special:  # joined when the graph keeps the edge
                if element not in edges:
                    edges[element] = Edge(f"{ca.prefix}.{element}", f"{cb.prefix}.{element}",
                                          (ca, cb), element, [], link)
                    self.graph.edges.append(edges[element])
                edges[element].pairs.append((ka, kb))
                self._add(ka, p.flow, link)
                self._add(kb, q.flow, link)
                continue
            self._add(ka, p.flow, link)
            self._add(kb, q.flow, link)
            ra, rb = self._find(ka), self._find(kb)
            if ra != rb:
                self.parent[rb] = ra

    def _pair_signals(self, ca: ClassScope | Leaf, cb: ClassScope | Leaf, out_a: bool,
                      out_b: bool, eq: s.Connect, owner: ClassScope) -> None:
        """Connect two connectors declared with a short connector class of a primitive
        type (``connector RealInput = input Real``): one scalar variable each."""
        if not (isinstance(ca, Leaf) and isinstance(cb, Leaf)) or ca.flow != cb.flow:
            names = [c.name if isinstance(c, Leaf) else c.prefix for c in (ca, cb)]
            raise FlattenError(f"connectors '{names[0]}' and '{names[1]}' do not match",
                               eq.span, hint="connect a signal connector (such as "
                               "RealInput) only to another signal connector")
        pa, pb = self.leaf_types.get(ca.name), self.leaf_types.get(cb.name)
        if pa is not None and pb is not None:
            check_signal_types(ca.name, cb.name, pa, pb, eq)
        link = Link(eq.span, owner.prefix, f"connect({ca.name}, {cb.name})")
        ka, kb = (ca.name, out_a), (cb.name, out_b)
        self._add(ka, ca.flow, link)
        self._add(kb, cb.flow, link)
        ra, rb = self._find(ka), self._find(kb)
        if ra != rb:
            self.parent[rb] = ra

    def join_kept(self) -> None:
        """Join the overdetermined elements of the connections the graph keeps."""
        for edge in self.graph.kept:
            for ka, kb in edge.pairs:
                ra, rb = self._find(ka), self._find(kb)
                if ra != rb:
                    self.parent[rb] = ra

    def equations(self, scopes: list[ClassScope], top: ClassScope,
                  absent: AbstractSet[str] = frozenset()) -> list[flat.Equation]:
        """Equations of all sets (in order of first connection), then zero flows; none
        for the sets of ``absent`` variables (of expandable connectors, 9.1.3)."""
        for bus, name, span in self.added_inputs:
            if id(bus) not in self.joined:
                raise lone_input(name, span)
        out: list[flat.Equation] = []
        for members in self._sets().values():
            if members[0][0] in absent:
                continue
            first = self.link[members[0]]
            if self.flow[members[0]]:
                out.append(self._flow_sum(members, first))
            else:
                check_sources(members, self.causal, {k: self.link[k].span for k in members},
                              self.protected)
                out += [flat.Equation(x.Var(members[0][0]), x.Var(k[0]), self.link[k].span,
                                      flat.Origin("connect", self.link[k].owner,
                                                  self.link[k].text))
                        for k in members[1:]]
        out += self._unconnected(scopes, top)
        return out

    def absent(self, scopes: list[ClassScope], model: flat.FlatModel) -> set[str]:
        """The variables of expandable connectors that are not present (9.1.3), given
        the model without its connection equations."""
        declared = {leaf.name for scope in scopes if scope.kind == "connector"
                    and scope.expandable for leaf in connector_leaves(scope)}
        if not declared:
            return declared
        return absent(declared, [[name for name, _ in keys]
                                 for keys in self._sets().values()], model)

    def _sets(self) -> dict[Key, list[Key]]:
        sets: dict[Key, list[Key]] = {}
        for key in self.parent:
            sets.setdefault(self._find(key), []).append(key)
        return sets

    def _flow_sum(self, members: list[Key], first: Link) -> flat.Equation:
        total: x.Expr = x.ZERO
        for name, outside in members:
            total = x.sub(total, x.Var(name)) if outside else x.add(total, x.Var(name))
        names = ", ".join(("-" if o else "") + n for n, o in members)
        return flat.Equation(total, x.ZERO, first.span,
                             flat.Origin("flow", first.owner, f"sum of {{{names}}}"))

    def _unconnected(self, scopes: list[ClassScope], top: ClassScope) -> list[flat.Equation]:
        out = []
        for scope in scopes:
            if scope.kind != "connector" or (scope.outer is not None
                                             and scope.outer.kind == "connector"):
                continue
            # every flow variable is also an inside element of its own set (9.2): one
            # never connected as inside, as those of the model's own connectors, is zero
            for leaf in connector_leaves(scope):
                if not leaf.flow:
                    continue
                if (leaf.name, False) in self.parent:
                    continue
                out.append(flat.Equation(x.Var(leaf.name), x.ZERO, scope.span,
                                         flat.Origin("unconnected", scope.outer.prefix
                                                     if scope.outer else "",
                                                     f"{scope.prefix} is not connected")))
        return out


def _signal_connector(ev: ExpressionEvaluator, ref: s.Ref, where: Scope,
                      causal: dict[str, str], types: dict[str, Primitive]
                      ) -> tuple[tuple[int, ...], list[Any], bool] | None:
    """``connect(u, gain.u)`` where ``u`` is declared ``RealInput u``: the scalar
    variables as leaves (shape, leaves, outside), or None for any other reference.
    Their causality goes to ``causal``, for the one-source rule (9.3), and their
    declarations to ``types``, for the type rule."""
    last = ref.parts[-1]
    owners: list[Any]
    if len(ref.parts) == 1:
        member = _owner_scope(where)
        owners = [member] if member is not None and member.has_member(last.name) else []
    else:
        head = s.Ref(ref.parts[:-1], ref.span)
        found = ev.reference(head, where)
        owners = list(found.flat) if isinstance(found, np.ndarray) else [found]
    if not owners or not all(isinstance(o, ClassScope) and o.has_member(last.name)
                             for o in owners):
        if owners and isinstance(owners[0], ClassScope) and owners[0].expandable:
            raise undeclared_member(owners[0], ref)
        return None
    members = [o.member(last.name, last.span) for o in owners]
    if not all(isinstance(m, Primitive) and m.connector for m in members):
        return None
    value = ev.reference(ref, where)
    array = np.atleast_1d(np.asarray(value, dtype=object))
    if not all(isinstance(v, x.Var) for v in array.flat):
        return None
    flow = members[0].flow
    if members[0].causality:
        causal.update((v.name, members[0].causality) for v in array.flat)
    types.update((v.name, members[0]) for v in array.flat)
    leaves = [Leaf("", v.name, flow) for v in array.flat]
    return array.shape, leaves, len(ref.parts) == 1


def _undeclared_in(ev: ExpressionEvaluator, ref: s.Ref, where: Scope) -> ClassScope | None:
    """The expandable connector ``bus`` of a reference ``bus.x`` to a variable it does
    not declare, else None."""
    if len(ref.parts) < 2:
        return None
    try:
        found = ev.reference(s.Ref(ref.parts[:-1], ref.span), where)
    except FlattenError:
        return None
    if isinstance(found, ClassScope) and found.expandable and \
            not found.has_member(ref.parts[-1].name):
        return found
    return None


def _declared_member(ev: ExpressionEvaluator, ref: s.Ref, where: Scope
                     ) -> tuple[Any, ViewComponent] | None:
    """The member a reference without subscripts names, with its declaration."""
    last = ref.parts[-1]
    if any(p.subscripts for p in ref.parts):
        return None
    if len(ref.parts) == 1:
        owner: Any = _owner_scope(where)
    else:
        try:
            owner = ev.reference(s.Ref(ref.parts[:-1], ref.span), where)
        except FlattenError:
            return None
    if not isinstance(owner, ClassScope) or not owner.has_member(last.name):
        return None
    return owner.member(last.name, last.span), owner.component(last.name)


def _owner_scope(where: Scope) -> ClassScope | None:
    while type(where) is LocalScope:
        where = where.parent
    return where if isinstance(where, ClassScope) else None


def _describe_leaves(leaves: list[Leaf]) -> str:
    """``s, flow f``: the scalar variables of a connector, relative to it."""
    return ", ".join(("flow " if p.flow else "") + p.relative for p in leaves) or "no variables"
