"""An ``outer`` component is used through its declared type (Modelica 3.6, section
5.4): ``outer R T0`` references only the part of the ``inner`` element that ``R``
declares, so ``T0.a`` is an error when ``R`` has no element ``a``, even if the inner
element's class (a subtype of ``R``) has one.

Input: a class view. Output: nothing, or a :class:`FlattenError` at the reference.
"""

from __future__ import annotations

from collections.abc import Iterator

from ...errors import ErrorGroup, Note, SpringcError
from ...ir import syntax as s
from ...parse import member_class
from ..scopes import (
    ClassView,
    ClassViews,
    ViewComponent,
    mod_values,
    refs,
    statement_exprs,
    statements,
)
from .rules import rule_error


def check_outer_uses(ctx: ClassViews, view: ClassView) -> None:
    """Each ``o.x`` with ``o`` an outer component of ``view`` names an element of
    ``o``'s declared class."""
    outers = {n: c for n, c in view.components.items()
              if c.decl.outer and c.defined_in is view.entry}
    if not outers:
        return
    for ref in _used_refs(view):
        comp = outers.get(ref.parts[0].name)
        if comp is not None and len(ref.parts) > 1 and not ref.is_global:
            _check(ctx, comp, ref)


def _used_refs(view: ClassView) -> Iterator[s.Ref]:
    for comp in view.components.values():
        if comp.defined_in is view.entry:
            for e in mod_values(comp.decl.modification):
                yield from refs(e)
    for eq in (*view.equations, *view.initial_equations):
        if eq.defined_in is view.entry:
            yield from _equation_refs(eq.equation)
    for stmt in statements(view.entry.defn.algorithm):
        for e in statement_exprs(stmt):
            yield from refs(e)


def _equation_refs(eq: s.Equation) -> Iterator[s.Ref]:
    if isinstance(eq, s.Equality):
        yield from refs(eq.lhs)
        yield from refs(eq.rhs)
    elif isinstance(eq, s.CallEquation):
        yield from refs(eq.call)
    elif isinstance(eq, s.ForEquation):
        for inner in eq.body:
            yield from _equation_refs(inner)
    elif isinstance(eq, s.IfEquation | s.WhenEquation):
        for cond, body in eq.branches:
            yield from refs(cond)
            for inner in body:
                yield from _equation_refs(inner)
        if isinstance(eq, s.IfEquation):
            for inner in eq.otherwise:
                yield from _equation_refs(inner)


def _check(ctx: ClassViews, comp: ViewComponent, ref: s.Ref) -> None:
    try:
        rtype = ctx.resolve_type(comp.decl.type_name, comp.defined_in)
        if rtype.entry is None:
            return
        declared = ctx.view(rtype.entry)
    except (SpringcError, ErrorGroup):
        return  # reported where the component is instantiated
    name = ref.parts[1].name
    if name in declared.components or member_class(rtype.entry, name) is not None:
        return
    outer = ref.parts[0].name
    raise rule_error(
        f"'{ref.dotted}': the outer element '{outer}' is declared of class "
        f"'{rtype.entry.full_name}', which has no element '{name}'", ref.span,
        "an outer element references only the part of its inner element that its own "
        "declared class has", "5.4",
        (Note(f"'{outer}' is declared outer here", comp.decl.span),))
