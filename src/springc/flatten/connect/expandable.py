"""Expandable connectors (Modelica 3.6, section 9.1.3), the subset springc supports.

Every component of an expandable connector is a connector: ``connect(sine.y,
bus.speed)`` joins the declared Real ``bus.speed`` to ``sine.y`` as if it were a
signal connector (``flatten/instantiate.py`` marks it so). Two expandable connectors
of one class connect element by element, as ordinary connectors do. A declared
variable of an expandable connector is only *potentially present*: one whose
connection set holds no variable of another connector (connecting two buses alone
makes nothing present), and that no equation reads, is no variable of the flat model,
and its connections give no equations.

A connection naming an undeclared variable of an expandable connector adds it (the
augmentation of 9.1.3, :func:`augmented_declaration`) when the other side is a signal
variable of type Real, Integer or Boolean, or a scalar connector (a component of its
class, :func:`augmented_connector`), and the name has no subscripts: the new variable
has the other side's type and sizes, its causality deduced as 9.1.3 says
(copied from an inside connector, the opposite of an outside one), used only by the
rule on added inputs (the variable is declared without causality). An input added so
needs a non-input in another expandable connector of its augmentation set, so the
connector must be connected to another expandable connector.

Not supported yet (located errors): the other augmentations (an array of connectors,
an array element, an enumeration), and connecting two expandable connectors that
declare different variables.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

from ...errors import FlattenError, Span
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ..checks import rule_error
from ..scopes import ClassScope, Primitive, ViewComponent

_FLIP = {"input": "output", "output": "input"}


def both_undeclared(ref: s.Ref, span: Span) -> FlattenError:
    """``connect(bus1.a, bus2.a)`` with ``a`` declared in neither bus."""
    return rule_error(f"'{ref.dotted}' and the other side of the connection are both "
                      "undeclared variables of expandable connectors", span, "at least one "
                      "side of a connection must name a declared component", "9.1.3")


def augmented_declaration(bus: ClassScope, part: s.RefPart, other: Primitive,
                          outside: bool) -> tuple[ViewComponent, str] | None:
    """The variable ``part`` added to the expandable connector ``bus`` by a connection
    to ``other`` (an ``outside`` connector of the connecting class, or an inside one),
    and its causality as 9.1.3 deduces it, or None where springc does not add it. The
    variable is declared without causality (springc's connection sets key a bus
    variable as inside, so a deduced output would count as a second source); the
    deduced causality serves the rule on added inputs (:func:`lone_input`)."""
    if part.subscripts or other.enumeration is not None or \
            other.type not in ("Real", "Integer", "Boolean"):
        return None
    causality = _FLIP.get(other.causality, "") if outside else other.causality
    decl = s.Component(
        name=part.name, type_name=s.Ref((s.RefPart(other.type, (), part.span),), part.span),
        type_dims=(), dims=tuple(s.Number(n, part.span) for n in other.dims),
        modification=None, variability=other.variability
        if other.variability in ("parameter", "constant") else "",
        causality="", flow=other.flow, final=False, protected=False,
        description="", span=part.span)
    return ViewComponent(decl, bus.entry), causality


def augmented_connector(part: s.RefPart, other: ClassScope, declared: ViewComponent
                        ) -> tuple[ViewComponent, str] | None:
    """The connector ``part`` added to an expandable connector by a connection to the
    scalar connector ``other`` (declared by ``declared``): a component of the same
    class, without modification, or None where springc does not add it."""
    decl = declared.decl
    if other.kind != "connector" or other.expandable or part.subscripts or decl.dims \
            or decl.type_dims or decl.causality or decl.flow:
        return None
    added = replace(decl, name=part.name, modification=None, condition=None, inner=False,
                    outer=False, replaceable=False, redeclare=False, protected=False,
                    constraint=None, span=part.span)
    return ViewComponent(added, declared.defined_in), ""


def lone_input(name: str, span: Span) -> FlattenError:
    """An input added to an expandable connector connected to no other one."""
    return rule_error(f"'{name}' is added to an expandable connector as an input, and no "
                      "other expandable connector of its augmentation set has it as a "
                      "non-input", span, "a variable that is an input in one expandable "
                      "connector must be a non-input in another of its augmentation set",
                      "9.1.3")


def undeclared_member(owner: ClassScope, ref: s.Ref) -> FlattenError:
    """``connect(x, bus.name)`` with ``name`` not declared in the expandable ``bus``."""
    last = ref.parts[-1]
    return FlattenError(
        f"adding '{last.name}' to the expandable connector '{owner.prefix}' "
        f"({owner.entry.full_name}) by a connection is not supported yet", last.span,
        hint=f"declare '{last.name}' in '{owner.entry.full_name}' (section 9.1.3)")


def augmenting(a: ClassScope, b: ClassScope, span: Span) -> FlattenError:
    """``connect(bus1, bus2)`` of expandable connectors that declare different variables."""
    return FlattenError(
        f"connecting the expandable connectors '{a.prefix}' ({a.entry.full_name}) and "
        f"'{b.prefix}' ({b.entry.full_name}), which declare different variables, is not "
        "supported yet", span, hint="declare the same variables in both (section 9.1.3)")


def absent(candidates: set[str], sets: Iterable[list[str]], model: flat.FlatModel
           ) -> set[str]:
    """Of the ``candidates`` (the variables declared in expandable connectors), those
    that are not present (section 9.1.3): in no connection set with a variable of
    another connector (``sets``: the flat names of each set), and read nowhere in
    ``model`` (its equations so far, bindings, assertions and when-clauses)."""
    left = set(candidates)
    for members in sets:
        if not candidates.issuperset(members):
            left.difference_update(members)
    if not left:
        return left
    read = _read(model)
    for members in sets:  # a set the model reads is present as a whole
        if not read.isdisjoint(members):
            left.difference_update(members)
    return left - read


def _read(model: flat.FlatModel) -> set[str]:
    """The variables ``model`` reads or assigns anywhere."""
    read: set[str] = set()
    for eq in (*model.equations, *model.initial_equations):
        read |= x.variables(eq.lhs) | x.variables(eq.rhs)
    for v in model.variables:
        if v.binding is not None:
            read |= x.variables(v.binding)
    for a in model.assertions:
        read |= x.variables(a.condition)
    for w in model.whens:
        for b in w.branches:
            read.update(a.name for a in b.assignments)
            for e in (*b.conditions, *(a.value for a in b.assignments),
                      *(r.value for r in b.reinits)):
                read |= x.variables(e)
    return read
