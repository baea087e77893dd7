"""Access to protected elements (Modelica 3.6, section 4.1): a protected element is
used by its simple name only, never through a dot (``a.p``, ``A.P``), and modified only
by its own declaration or an extends clause. Input: the class view or entry reached and
the reference; output: nothing, or a located :class:`FlattenError`."""

from __future__ import annotations

from ..errors import Note, Span
from ..ir import syntax as s
from ..parse import ClassEntry
from .modification import Mod
from .rules import rule_error
from .scope import ClassView

ACCESS_RULE = ("a protected element can be used only by its simple name, inside its class "
               "and the classes extending it, not through a dot from outside")


def check_access_component(view: ClassView, name: str, span: Span, owner: str) -> None:
    """``a.p`` or ``P.p``: ``p`` must not be a protected component of ``view``'s class."""
    comp = view.components.get(name)
    if comp is not None and comp.decl.protected:
        raise rule_error(f"'{name}' is protected in '{view.entry.full_name}' and cannot be "
                         f"accessed as '{owner}.{name}'", span, ACCESS_RULE, "4.1",
                         (Note("declared protected here", comp.decl.span),))


def check_access_class(entry: ClassEntry, ref: s.Ref) -> None:
    """``A.B.C`` as a class name: none of ``B``, ``C`` may be a protected class."""
    hops = len(ref.parts) - 1
    current: ClassEntry | None = entry
    while hops > 0 and current is not None:
        if current.defn.protected:
            owner = current.parent.full_name if current.parent is not None else ""
            raise rule_error(f"class '{current.name}' is protected in '{owner}' and cannot be "
                             f"used as '{ref.dotted}'", ref.span, ACCESS_RULE, "4.1",
                             (Note("declared protected here", current.defn.span),))
        current = current.parent
        hops -= 1


def check_modified(view: ClassView, mod: Mod, owner: str) -> None:
    """A modification ``a(p = 1)`` of a component must not reach a protected ``p``."""
    for name, child in mod.children.items():
        comp = view.components.get(name)
        if comp is not None and comp.decl.protected:
            raise rule_error(f"'{name}' is protected in '{view.entry.full_name}' and cannot be "
                             f"modified in '{owner}'", child.span, "a protected element "
                             "may be modified only by its own declaration or by an extends "
                             "clause", "4.1", (Note("declared protected here",
                                                    comp.decl.span),))
