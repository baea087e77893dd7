"""A conditional component (``Real x if c;``) may only be modified and connected
(Modelica 3.6, section 4.4.5): no equation, algorithm, binding or modifier of another
element names it, whether or not its condition holds.

Input: a class view. Output: nothing, or a :class:`FlattenError` at the first reference.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import fields, is_dataclass

from ...errors import Note
from ...ir import syntax as s
from ..scopes import ClassView, mod_values
from .rules import rule_error


def check_conditional_uses(view: ClassView) -> None:
    """No element of ``view`` but a connect equation uses a conditional component."""
    conditional = {name: comp.decl for name, comp in view.components.items()
                   if comp.decl.condition is not None}
    if not conditional:
        return
    nodes: list[object] = [eq.equation for eq in (*view.equations, *view.initial_equations)]
    for name, comp in view.components.items():
        if name not in conditional:
            nodes += mod_values(comp.decl.modification)
    for node in nodes:
        for ref in _all_refs(node):
            decl = conditional.get(ref.parts[0].name)
            if decl is not None:
                raise rule_error(
                    f"the conditional component '{decl.name}' is used outside a connect "
                    "equation", ref.span, "a component declared with a condition (`if "
                    "...`) may only be modified and used in connect equations", "4.4.5",
                    (Note("declared here", decl.span),))


def _all_refs(node: object) -> Iterator[s.Ref]:
    """Every name in a syntax node (function names and assigned names included), except
    inside connect equations."""
    if isinstance(node, s.Connect):
        return
    if isinstance(node, s.Ref):
        yield node
    if isinstance(node, tuple):
        for item in node:
            yield from _all_refs(item)
    elif is_dataclass(node):
        for f in fields(node):
            if f.name != "span":
                yield from _all_refs(getattr(node, f.name))
