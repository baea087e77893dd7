"""A variable assigned in a when-clause must not be declared inside a component of a
``model`` or ``block`` class (Modelica 3.6, section 4.4.4): ``m.x = 1`` in a
when-clause, with ``m`` a model instance, assigns a variable that ``m`` itself must
define.

Input: the left-hand side of an equation (or assignment) in a when-clause and the class
it is written in. Output: nothing, or a :class:`FlattenError` at the reference.
"""

from __future__ import annotations

from ...errors import ErrorGroup, Note, SpringcError
from ...ir import syntax as s
from ...parse import ClassEntry
from ..checks import rule_error
from ..scopes import ClassViews


def check_when_target(ctx: ClassViews, lhs: s.Expr, where: ClassEntry) -> None:
    """No proper prefix of the reference ``lhs`` is a model or block component."""
    if not isinstance(lhs, s.Ref) or lhs.is_global:
        return
    entry = where
    for depth, part in enumerate(lhs.parts[:-1]):
        try:
            comp = ctx.view(entry).components.get(part.name)
            if comp is None:
                return  # a name outside the instance: reported where it is evaluated
            rtype = ctx.resolve_type(comp.decl.type_name, comp.defined_in)
        except (SpringcError, ErrorGroup):
            return  # reported where the component is instantiated
        if rtype.entry is None:
            return
        kind = rtype.entry.defn.kind
        if kind in ("model", "block"):
            inside = ".".join(p.name for p in lhs.parts[:depth + 1])
            raise rule_error(
                f"'{lhs.dotted}' is assigned in a when-clause but is declared inside "
                f"'{inside}', a {kind} component", lhs.span,
                "a variable assigned in a when-clause shall not be defined in a "
                "sub-component of a model or block; assign it inside that class, or "
                "connect to its input", "4.4.4",
                (Note(f"'{inside}' is declared here", comp.decl.span),))
        entry = rtype.entry
