"""``class extends`` (Modelica 3.6, section 7.3.1): ``model extends M ... end M;`` in a
class C defines C's own M, which extends the M that C inherits (from a base class of
C), and must be replaceable there; written ``redeclare model extends M``, it also
replaces M for the components that the base classes declare of type M.

Input: the entry of a ``class extends`` definition. Output: the inherited class its
first ``extends`` clause names, or an error naming the rule.
"""

from __future__ import annotations

from collections.abc import Callable

from ...errors import FlattenError, Note, Span
from ...ir import syntax as s
from ...parse import ClassEntry, member_class

Resolve = Callable[[s.Ref, ClassEntry, ClassEntry], ClassEntry]

_RULE = ("`class extends M` extends the class M that the enclosing class inherits, which "
         "must be replaceable there (Modelica 3.6, section 7.3.1)")


def inherited_class(resolve: Resolve, entry: ClassEntry, span: Span) -> ClassEntry:
    """The class named ``entry.name`` that the class enclosing ``entry`` inherits."""
    enclosing = entry.parent
    found: ClassEntry | None = None
    if enclosing is not None:
        for element in enclosing.defn.elements:
            if not isinstance(element, s.Extends):
                continue
            base = resolve(element.base, enclosing.parent or enclosing, enclosing)
            found = member_class(base, entry.name)
            if found is not None:
                break
    if found is None:
        where = f"'{enclosing.full_name}'" if enclosing is not None else "its class"
        raise FlattenError(f"`class extends {entry.name}`: {where} inherits no class named "
                           f"'{entry.name}'", span, hint=_RULE)
    if not found.defn.replaceable:
        raise FlattenError(f"`class extends {entry.name}` extends '{found.full_name}', "
                           "which is not replaceable", span,
                           [Note("declared here", found.defn.span)], _RULE)
    return found


def check_class_redeclarations(resolve: Resolve, entry: ClassEntry) -> None:
    """A class redeclared with a long definition (``redeclare model M ... end M;``,
    ``redeclare model extends M``) as an element of ``entry`` replaces an inherited
    class that is replaceable, not final, and as public or protected as it (section
    7.3.3)."""
    for element in entry.defn.elements:
        if not isinstance(element, s.ClassDef) or not element.redeclare \
                or element.short is not None:
            continue
        span = element.span
        found = _inherited(resolve, entry, element.name)
        if found is None:
            raise FlattenError(f"'{element.name}' is redeclared but no inherited class has "
                               "that name", span, hint="redeclare a class of a base class, "
                               "or drop `redeclare`")
        notes = [Note("declared here", found.defn.span)]
        if found.defn.final:
            raise FlattenError(f"the final class '{element.name}' cannot be redeclared",
                               span, notes, _RESTRICTIONS)
        if not found.defn.replaceable:
            raise FlattenError(f"'{element.name}' is not replaceable and cannot be "
                               "redeclared", span, notes, _RESTRICTIONS)
        if found.defn.protected != element.protected:
            was, now = ("protected", "public") if found.defn.protected else \
                ("public", "protected")
            raise FlattenError(f"the {was} class '{element.name}' cannot be redeclared "
                               f"{now}", span, notes, _RESTRICTIONS)


_RESTRICTIONS = ("only a replaceable, non-final class can be redeclared, and it stays "
                 "public or protected (Modelica 3.6, section 7.3.3)")


def _inherited(resolve: Resolve, entry: ClassEntry, name: str) -> ClassEntry | None:
    for element in entry.defn.elements:
        if isinstance(element, s.Extends):
            base = resolve(element.base, entry.parent or entry, entry)
            found = member_class(base, name)
            if found is not None:
                return found
    return None
