"""Access to protected elements (Modelica 3.6, section 4.1): a protected element is
used by its simple name only, never through a dot (``a.p``, ``A.P``), and modified only
by its own declaration or an extends clause. Input: the class view or entry reached and
the reference; output: nothing, or a located :class:`FlattenError`."""

from __future__ import annotations

import itertools

from ...errors import Note, Span
from ...ir import syntax as s
from ...parse import ClassEntry, member_class
from ..scopes import ClassView, Mod
from .rules import rule_error

ACCESS_RULE = ("a protected element can be used only by its simple name, inside its class "
               "and the classes extending it, not through a dot from outside")


def check_access_component(view: ClassView, name: str, span: Span, owner: str) -> None:
    """``a.p`` or ``P.p``: ``p`` must not be a protected component of ``view``'s class."""
    comp = view.components.get(name)
    if comp is not None and comp.decl.protected:
        raise rule_error(f"'{name}' is protected in '{view.entry.full_name}' and cannot be "
                         f"accessed as '{owner}.{name}'", span, ACCESS_RULE, "4.1",
                         (Note("declared protected here", comp.decl.span),))


def check_access_path(chain: list[ClassEntry], ref: s.Ref) -> None:
    """``A.B.C`` as a class name, ``chain`` the classes its prefixes denote: neither
    ``B`` nor ``C`` is protected (4.1), and each is found as section 5.3.2 says."""
    for container, member in itertools.pairwise(chain):
        check_access_class(container, member, ref)
        check_inside(container, member.name, member.defn.encapsulated, ref)


def check_access_class(container: ClassEntry, member: ClassEntry, ref: s.Ref) -> None:
    """``A.f`` or ``a.f``: the class ``f`` of ``A`` (or of ``a``'s class) is not
    protected (4.1)."""
    if member.defn.protected:
        raise rule_error(f"class '{member.name}' is protected in "
                         f"'{container.full_name}' and cannot be used as '{ref.dotted}'",
                         ref.span, ACCESS_RULE, "4.1",
                         (Note("declared protected here", member.defn.span),))


def package_like(entry: ClassEntry) -> bool:
    """A package, or a class that holds only classes and constants (treated as one)."""
    defn = entry.defn
    if defn.kind == "package":
        return True
    return not (defn.equations or defn.initial_equations or defn.algorithm) and all(
        e.variability == "constant" for e in defn.elements if isinstance(e, s.Component))


def check_inside(container: ClassEntry, name: str, encapsulated: bool, ref: s.Ref) -> None:
    """``A.B``: lookup inside a class finds every element of a package, only the
    encapsulated elements of other classes; it never looks inside a partial class."""
    if container.parent is None:
        return
    if container.defn.partial:
        raise rule_error(f"'{ref.dotted}' looks inside the partial {container.defn.kind} "
                         f"'{container.full_name}'", ref.span, "a name cannot be looked up "
                         "inside a partial class", "5.3.2",
                         (Note(f"'{container.full_name}' is declared partial here",
                               container.defn.span),))
    if not encapsulated and not package_like(container):
        raise rule_error(f"'{name}' cannot be looked up inside the {container.defn.kind} "
                         f"'{container.full_name}' (as '{ref.dotted}')", ref.span,
                         "inside a class that is not a package, lookup finds only its "
                         "encapsulated elements", "5.3.2",
                         (Note(f"'{container.full_name}' is defined here",
                               container.defn.span),))


def check_modified(view: ClassView, mod: Mod, owner: str) -> None:
    """A modification ``a(p = 1)`` of a component must not reach a protected ``p``."""
    for name, child in mod.children.items():
        if child.redeclare is not None and isinstance(child.redeclare.element, s.ClassDef):
            local = next((e for e in view.entry.defn.elements
                          if isinstance(e, s.ClassDef) and e.name == name), None)
            if local is None:  # an inherited class keeps its protection (7.3)
                found = member_class(view.entry, name)
                local = found.defn if found is not None else None
            if local is not None and local.protected:
                raise rule_error(f"class '{name}' is protected in '{view.entry.full_name}' "
                                 f"and cannot be redeclared in '{owner}'", child.span,
                                 "a protected element may be modified only by its own "
                                 "declaration or by an extends clause", "4.1",
                                 (Note("declared protected here", local.span),))
        modified = member_class(view.entry, name) if child.redeclare is None \
            and name not in view.components else None
        if modified is not None and modified.defn.protected:  # a(B(x = 4)), section 7.2
            raise rule_error(f"class '{name}' is protected in '{view.entry.full_name}' "
                             f"and cannot be modified in '{owner}'", child.span,
                             "a protected element may be modified only by its own "
                             "declaration or by an extends clause", "4.1",
                             (Note("declared protected here", modified.defn.span),))
        comp = view.components.get(name)
        if comp is not None and comp.decl.protected:
            raise rule_error(f"'{name}' is protected in '{view.entry.full_name}' and cannot be "
                             f"modified in '{owner}'", child.span, "a protected element "
                             "may be modified only by its own declaration or by an extends "
                             "clause", "4.1", (Note("declared protected here",
                                                    comp.decl.span),))
