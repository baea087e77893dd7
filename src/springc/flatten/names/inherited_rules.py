"""Names in inherited elements are looked up from the class that declares them
(Modelica 3.6, section 5.6.1 / 7.1): a binding written in ``Base`` cannot use a
component that only the class extending ``Base`` declares.

Input: a class view. Output: nothing, or a :class:`FlattenError` at the reference.
springc evaluates inherited bindings in the instance, where such a name would be found;
this check rejects what the specification does not find.
"""

from __future__ import annotations

from ...errors import Note
from ...ir import syntax as s
from ...parse import ClassEntry, lookup_class
from ..calls import CONSTANTS
from ..checks import rule_error
from ..scopes import ClassView, ClassViews, mod_values, refs


def check_inherited_names(ctx: ClassViews, view: ClassView) -> None:
    """Each inherited binding and equation uses only names visible where written."""
    entry = view.entry
    for comp in view.components.values():
        if comp.defined_in is not entry:
            for e in mod_values(comp.decl.modification):
                _check(ctx, view, comp.defined_in, e)
    for eq in view.equations:
        if eq.defined_in is not entry and isinstance(eq.equation, s.Equality):
            _check(ctx, view, eq.defined_in, eq.equation.lhs)
            _check(ctx, view, eq.defined_in, eq.equation.rhs)


def _check(ctx: ClassViews, view: ClassView, declaring: ClassEntry, e: s.Expr) -> None:
    for ref in refs(e):
        name = ref.parts[0].name
        if ref.is_global or name not in view.components or _visible(ctx, name, declaring):
            continue
        raise rule_error(
            f"'{name}' is not visible in '{declaring.full_name}', where this is written",
            ref.span, "names in an inherited element are looked up from the class that "
            "declares it, not from the class extending it", "5.6.1",
            (Note(f"'{name}' is declared in '{view.entry.full_name}'",
                  view.components[name].decl.span),))


def _visible(ctx: ClassViews, name: str, declaring: ClassEntry) -> bool:
    if name in ("time", *CONSTANTS) or lookup_class(name, declaring) is not None:
        return True
    enclosing: ClassEntry | None = declaring
    while enclosing is not None and enclosing.parent is not None:
        if name in ctx.view(enclosing).components:
            return True
        if enclosing.defn.encapsulated:
            return False
        enclosing = enclosing.parent
    return False
