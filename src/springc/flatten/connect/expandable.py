"""Expandable connectors (Modelica 3.6, section 9.1.3), the subset springc supports.

Every component of an expandable connector is a connector: ``connect(sine.y,
bus.speed)`` joins the declared Real ``bus.speed`` to ``sine.y`` as if it were a
signal connector (``flatten/instantiate.py`` marks it so). Two expandable connectors
of one class connect element by element, as ordinary connectors do. A declared
variable of an expandable connector is only *potentially present*: one whose
connection set holds no variable of another connector (connecting two buses alone
makes nothing present), and that no equation reads, is no variable of the flat model,
and its connections give no equations.

Not supported yet (located errors): adding a variable to an expandable connector by
connecting to a name it does not declare, and connecting two expandable connectors
that declare different variables (the augmentation of 9.1.3).
"""

from __future__ import annotations

from collections.abc import Iterable

from ...errors import FlattenError, Span
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ..scopes import ClassScope


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
