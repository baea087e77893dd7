"""Restrictions of connections and connectors (Modelica 3.6, sections 9.3 and 9.3.1),
checked as ``connect`` statements are recorded and on connector instances.

Input: connector instances. Output: nothing, or a :class:`FlattenError` naming the rule
and its section.
"""

from __future__ import annotations

from collections.abc import Iterator
from collections.abc import Set as AbstractSet
from typing import Any

import numpy as np

from ...errors import FlattenError, Note
from ...ir import expr as x
from ...ir import syntax as s
from ...parse import member_class
from ..checks import rule_error
from ..scopes import ClassScope, ClassView, Ident, Primitive, equations


def primitives(scope: ClassScope, prefix: str = "") -> Iterator[tuple[str, Primitive]]:
    """Every primitive of a connector instance (parameters and constants included), by
    name relative to it."""
    for name, member in scope.all_members():
        if isinstance(member, Primitive):
            yield prefix + name, member
        else:
            items = member.flat if isinstance(member, np.ndarray) else [member]
            for k, item in enumerate(items):
                tag = f"{name}[{k + 1}]" if isinstance(member, np.ndarray) else name
                yield from primitives(item, f"{prefix}{tag}.")


def _a(word: str) -> str:
    return ("an " if word[0] in "AEIOUaeiou" else "a ") + word


def _kind(prim: Primitive) -> str:
    return prim.variability if prim.variability in ("parameter", "constant") else "variable"


def check_pair(ca: ClassScope, cb: ClassScope, eq: s.Connect) -> dict[str, str]:
    """The matched primitives of two connected connectors have the same type, the same
    kind (parameter, constant or variable), causality on both or neither, and equal
    constant values. Returns the causality of the flat variables met (``input`` or
    ``output``), for the one-source rule of :func:`check_sources`."""
    causal: dict[str, str] = {}
    right = dict(primitives(cb))
    head = f"cannot connect '{ca.prefix}' and '{cb.prefix}'"
    for name, pa in primitives(ca):
        pb = right.get(name)
        if pb is None:
            continue
        if _type_key(pa) != _type_key(pb):
            raise rule_error(f"{head}: '{name}' is {_a(type_name(pa))} in one and "
                             f"{_a(type_name(pb))} "
                             "in the other", eq.span, "connected variables must have the same "
                             "primitive type", "9.3",
                             _notes(ca, cb, name, pa, pb))
        if _kind(pa) != _kind(pb):
            raise rule_error(f"{head}: '{name}' is a {_kind(pa)} in one and a {_kind(pb)} "
                             "in the other", eq.span, "connect may join parameters only to "
                             "parameters and constants only to constants", "9.3",
                             _notes(ca, cb, name, pa, pb))
        if bool(pa.causality) != bool(pb.causality):
            raise rule_error(f"{head}: '{name}' is causal ({pa.causality or pb.causality}) "
                             "in one but not in the other", eq.span, "input and output "
                             "variables connect only to input or output variables", "9.3",
                             _notes(ca, cb, name, pa, pb))
        if pa.variability == "constant" and not _same(pa.value, pb.value):
            raise rule_error(f"{head}: the constant '{name}' has different values",
                             eq.span, "connected constants must have the same value", "9.3",
                             _notes(ca, cb, name, pa, pb))
        for prim in (pa, pb):
            if prim.causality:
                for flat_name in ([prim.names] if isinstance(prim.names, str)
                                  else list(prim.names.flat)):
                    causal[flat_name] = prim.causality
    return causal


def type_name(prim: Primitive) -> str:
    """``Real``, ``Integer``, ..., or the full name of an enumeration type."""
    return f"enumeration {prim.enumeration.name}" if prim.enumeration else prim.type


def _type_key(prim: Primitive) -> tuple[str, tuple[str, ...] | None]:
    """What must agree between connected variables: the primitive type, and of an
    enumeration its literals in order (section 6.4: enumeration types with the same
    literals in the same order are equivalent)."""
    return prim.type, prim.enumeration.literals if prim.enumeration else None


def check_signal_types(a: str, b: str, pa: Primitive, pb: Primitive, eq: s.Connect
                       ) -> None:
    """Two connected signals (``connect(u, bus.x)``) have the same type: an enumeration
    connects only to the same enumeration (section 9.3; 4.9.5: no implicit conversion)."""
    if _type_key(pa) != _type_key(pb):
        raise rule_error(f"cannot connect '{a}' and '{b}': one is {_a(type_name(pa))} and "
                         f"the other {_a(type_name(pb))}", eq.span, "connected variables "
                         "must have the same primitive type", "9.3",
                         (Note(f"'{a}' is declared here", pa.decl.span),
                          Note(f"'{b}' is declared here", pb.decl.span)))


def _notes(ca: ClassScope, cb: ClassScope, name: str, pa: Primitive, pb: Primitive
           ) -> tuple[Note, Note]:
    """Where the two sides of a mismatch declare ``name`` (made only for an error: a
    chain connects thousands of flanges)."""
    return (Note(f"'{name}' of '{ca.entry.full_name}' is declared here", pa.decl.span),
            Note(f"'{name}' of '{cb.entry.full_name}' is declared here", pb.decl.span))


def _same(a: Any, b: Any) -> bool:
    items_a = list(a.flat) if isinstance(a, np.ndarray) else [a]
    items_b = list(b.flat) if isinstance(b, np.ndarray) else [b]
    return len(items_a) == len(items_b) and all(
        isinstance(p, x.Const) and isinstance(q, x.Const) and p.value == q.value
        for p, q in zip(items_a, items_b))


def check_sources(members: list[tuple[str, bool]], causal: dict[str, str],
                  spans: dict[tuple[str, bool], Any],
                  protected: AbstractSet[str] = frozenset()
                  ) -> None:
    """A connection set of causal variables has at most one source: one inside output
    or one public outside input (9.3); an input of a protected outside connector
    (the MSL's ``f_internal`` of a conditional input) is not a source. ``protected``:
    the flat names of protected outside connectors (a variable of one starts with
    its name and a dot)."""
    def hidden(name: str) -> bool:
        return name in protected or any(name[:i] in protected
                                        for i, c in enumerate(name) if c == ".")

    sources = [(name, outside) for name, outside in members
               if causal.get(name) == ("input" if outside else "output")
               and not (outside and hidden(name))]
    if len(sources) > 1:
        names = ", ".join(f"'{n}' ({'outside input' if o else 'inside output'})"
                          for n, o in sources)
        raise rule_error(f"a connection set has {len(sources)} sources of its signal: "
                         f"{names}", spans.get(sources[1]), "a set of connected inputs "
                         "and outputs may contain at most one inside output or one public "
                         "outside input", "9.3")


def check_connector_size(scope: ClassScope,
                         known: dict[Ident[ClassView], dict[str, int]] | None = None) -> None:
    """A connector has as many flow variables as variables that are neither parameter,
    constant, input, output nor flow (9.3.1); checked on connector instances that are
    not nested in another connector. ``known``: the :func:`overdetermined` elements of
    the class views seen so far in this walk (one look-up per connector class, not per
    instance: the 50,000 flanges of a 10,000-mass chain)."""
    if scope.kind != "connector" or (scope.outer is not None
                                     and scope.outer.kind == "connector"):
        return
    flows = potentials = 0
    if known is None:
        special = overdetermined(scope)
    else:
        key = Ident(scope.view)
        if key not in known:
            known[key] = overdetermined(scope)
        special = known[key]
    for name, prim in primitives(scope):
        size = int(np.prod(prim.dims)) if prim.dims else 1
        if prim.variability in ("parameter", "constant") or prim.causality \
                or name.split(".")[0].split("[")[0] in special:
            continue
        if prim.flow:
            flows += size
        else:
            potentials += size
    potentials += sum(special.values())
    if flows and flows != potentials:
        raise rule_error(f"connector '{scope.prefix}' ({scope.entry.full_name}) has "
                         f"{flows} flow and {potentials} potential variables",
                         scope.span, "a connector has as many flow variables as "
                         "variables that are neither parameter, constant, input, output "
                         "nor flow", "9.3.1",
                         (Note(f"'{scope.entry.full_name}' is defined here",
                               scope.entry.defn.span),))


def overdetermined(scope: ClassScope) -> dict[str, int]:
    """The elements of a connector of an overdetermined type (one that defines an
    ``equalityConstraint`` function), each counting as many potential variables as
    that function has residues (sections 9.3.1, 9.4)."""
    found: dict[str, int] = {}
    for comp in scope.view.components.values():
        if comp.decl.dims or comp.decl.type_dims:
            continue
        try:
            entry = scope.flattener.resolve_class(comp.decl.type_name, comp.defined_in)
        except FlattenError:
            continue
        constraint = member_class(entry, "equalityConstraint")
        if constraint is None:
            continue
        outputs = [e for e in constraint.defn.elements
                   if isinstance(e, s.Component) and e.causality == "output"]
        dims = outputs[0].dims if len(outputs) == 1 else ()
        if len(dims) == 1 and isinstance(dims[0], s.Number) \
                and isinstance(dims[0].value, int):
            found[comp.decl.name] = dims[0].value  # residue[n]: n potentials
            continue
        raise FlattenError(f"overdetermined connectors (the element '{comp.decl.name}' "
                               f"of '{scope.prefix}' has the type '{entry.full_name}' with "
                               "an equalityConstraint function, section 9.4) are not "
                               "supported yet", comp.decl.span,
                               hint="springc supports a subset of Modelica; see \"Not "
                               "supported yet\" in docs/language.md")
    return found


def check_reference_form(ref: s.Ref, owner: ClassScope) -> None:
    """A connector of a connect equation is one of ``owner`` or one of a component of it
    (``m.c``), possibly an element of such a connector (``m.c.d``): every part between
    the first and the last names a connector (section 9.1)."""
    if len(ref.parts) < 3 or not owner.has_member(ref.parts[0].name):
        return
    current: Any = owner.member(ref.parts[0].name)
    for k, part in enumerate(ref.parts[1:-1], start=1):
        if isinstance(current, np.ndarray):
            current = current.flat[0] if current.size else None
        if not isinstance(current, ClassScope) or not current.has_member(part.name):
            return
        current = current.member(part.name)
        first = current.flat[0] if isinstance(current, np.ndarray) and current.size \
            else current
        if isinstance(first, ClassScope) and first.kind != "connector":
            path = ".".join(p.name for p in ref.parts[:k + 1])
            raise rule_error(
                f"'{ref.dotted}' cannot be connected here: '{path}' is a component "
                f"of '{ref.parts[0].name}', not a connector", ref.span,
                "a connect equation joins connectors of the class or of its components "
                "(`m.c`), not connectors deeper inside components", "9.1")


def check_no_connect(eq: s.IfEquation) -> None:
    """An if-equation whose condition is not a parameter expression holds no ``connect``
    (section 8.3.3): the connection structure is fixed at translation time."""
    for _, body in [*eq.branches, (None, eq.otherwise)]:
        found = _connect_in(body)
        if found is not None:
            raise rule_error("connect inside an if-equation whose condition is not a "
                             "parameter expression", found.span, "connect-equations may "
                             "be inside if-equations only when the conditions are parameter "
                             "expressions", "8.3.3",
                             (Note("the condition of this if-equation varies during the "
                                   "simulation", eq.branches[0][0].span),))


def _connect_in(body: tuple[s.Equation, ...]) -> s.Connect | None:
    return next((eq for eq in equations(body) if isinstance(eq, s.Connect)), None)
