"""Constraining types and redeclarations (Modelica 3.6, sections 7.3.2 and 7.3.3): the
type of a replaceable element must be a subtype (section 6.4) of its constraining type,
a redeclaration must be a subtype of the constraining type of the element it replaces
(the original declaration's ``constrainedby`` type, or its own type without one, or a
later redeclaration's ``constrainedby`` type), a new constraining type must be a subtype
of the one it replaces, an element redeclared without ``replaceable`` or declared
``final`` cannot be redeclared again, and the number of array dimensions of the type
part must agree.

Input: a class view (its own declarations) or an instance's merged modification.
Output: nothing, or a :class:`FlattenError` whose help states the rule and its section.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import FlattenError, Note, Span
from ...ir import syntax as s
from ...parse import ClassEntry, member_class
from ..checks import rule_error
from ..scopes import REDECLARE_RULES, ClassView, ClassViews, Mod, Redeclaration, ViewComponent
from .subtyping import Interface, incompatibility, interface

_SUBTYPE = ("the type of a replaceable or redeclared element must be a subtype of its "
            "constraining type: every public element of the constraining class present "
            "with a compatible type, and the same number of array dimensions")
_NEW_CONSTRAINT = ("a redeclaration's constraining type must be a subtype of the "
                   "constraining type of the element it redeclares")
_REPLACEABLE = ("only a replaceable element can be redeclared with a new type (an "
                "element redeclared without `replaceable` is no longer replaceable), and "
                "a final element cannot be redeclared at all")


def check_replaceables(ctx: ClassViews, view: ClassView) -> None:
    """The replaceable declarations and ``redeclare`` elements of ``view``'s class."""
    entry = view.entry
    for element in entry.defn.elements:
        if isinstance(element, s.Component) and element.constraint is not None:
            own = interface(ctx, element.type_name, entry, len(element.type_dims))
            _require(ctx, own, _constraint(ctx, element.constraint[0], entry),
                     element.span, f"'{element.name}'", _SUBTYPE)
        elif isinstance(element, s.ClassDef) and element.constraint is not None:
            _require(ctx, class_interface(ctx, element, entry),
                     _constraint(ctx, element.constraint[0], entry), element.span,
                     f"class '{element.name}'", _SUBTYPE)
        if isinstance(element, s.Component) and element.redeclare:
            inherited = _inherited_component(ctx, entry, element.name)
            if inherited is not None:
                _check_chain(ctx, element.name, component_bound(ctx, inherited),
                             [(element, entry)])
        elif isinstance(element, s.ClassDef) and element.redeclare:
            original = _inherited_class(ctx, entry, element.name)
            if original is not None and original.defn.protected != element.protected:
                was, now = (("protected", "public") if original.defn.protected
                            else ("public", "protected"))
                raise rule_error(f"the {was} class '{element.name}' cannot be redeclared "
                                 f"{now}", element.span, REDECLARE_RULES, "7.3.3",
                                 (Note("declared here", original.defn.span),))
            if original is not None:
                _check_chain(ctx, element.name, class_bound(ctx, original),
                             [(element, entry)])


def check_redeclarations(ctx: ClassViews, view: ClassView, mod: Mod | None) -> None:
    """The redeclarations in an instance's merged modification ``mod``, each against
    the declaration it replaces in ``view`` and against the redeclarations it overrides."""
    if mod is None:
        return
    for name, child in mod.children.items():
        if child.redeclare is None:
            continue
        chain: list[tuple[s.Component | s.ClassDef, ClassEntry]] = []
        link: Redeclaration | None = child.redeclare
        while link is not None:
            chain.append((link.element, link.scope.entry))
            link = link.replaced
        chain.reverse()  # innermost first
        comp = view.components.get(name)
        if comp is not None and isinstance(chain[0][0], s.Component):
            _check_chain(ctx, name, component_bound(ctx, comp), chain)
        elif comp is None and isinstance(chain[0][0], s.ClassDef):
            original = _own_or_inherited_class(ctx, view.entry, name)
            if original is not None:
                _check_chain(ctx, name, class_bound(ctx, original), chain)


@dataclass(frozen=True)
class Bound:
    """What a redeclaration of an element must respect: its constraining type, its
    current type, whether it is replaceable or final, and where it is declared."""

    constraint: Interface | None
    current: Interface | None
    replaceable: bool
    final: bool
    span: Span | None


def component_bound(ctx: ClassViews, comp: ViewComponent) -> Bound:
    """What a redeclaration of the component ``comp`` must respect."""
    decl = comp.decl
    current = interface(ctx, decl.type_name, comp.defined_in, len(decl.type_dims))
    bound = (_constraint(ctx, decl.constraint[0], comp.defined_in)
             if decl.constraint is not None else current)
    # a final, constant or non-replaceable declaration: declarations.redeclared and
    # scope.check_redeclarable report it where the redeclaration is applied; the chain
    # checks the redeclarations that follow
    return Bound(bound, current, True, False, decl.span)


def class_bound(ctx: ClassViews, entry: ClassEntry) -> Bound:
    """What a redeclaration of the class ``entry`` must respect."""
    defn = entry.defn
    where = entry.parent or entry
    current = class_interface(ctx, defn, where)
    bound = (_constraint(ctx, defn.constraint[0], where) if defn.constraint is not None
             else current)
    return Bound(bound, current, defn.replaceable, defn.final, defn.span)


def class_interface(ctx: ClassViews, defn: s.ClassDef, where: ClassEntry
                    ) -> Interface | None:
    """The interface of the class ``defn`` declared in ``where`` as a constraining
    type compares it: a short definition's base type without the dimensions the
    definition adds (``type T = T1[n]`` is constrained as ``T1``), or the long class."""
    if defn.short is not None:
        return interface(ctx, defn.short.base, where)
    if defn.enumeration is not None:
        return Interface(defn.name, None, None, defn.enumeration, 0, ("", "", False))
    entry = where.child(defn.name)
    if entry is None or entry.defn is not defn:
        return None  # a long class in a modification: not placed in the class tree
    return Interface(defn.name, None, entry, None, 0, ("", "", False))


def _constraint(ctx: ClassViews, ref: s.Ref, where: ClassEntry) -> Interface | None:
    return interface(ctx, ref, where)


def _element_interface(ctx: ClassViews, element: s.Component | s.ClassDef,
                       where: ClassEntry) -> Interface | None:
    if isinstance(element, s.Component):
        return interface(ctx, element.type_name, where, len(element.type_dims))
    return class_interface(ctx, element, where)


def _check_chain(ctx: ClassViews, name: str, bound: Bound,
                 chain: list[tuple[s.Component | s.ClassDef, ClassEntry]]) -> None:
    """Each redeclaration of ``chain`` (innermost first; the new element and the class
    it is written in) against what it replaces."""
    constraint, current = bound.constraint, bound.current
    replaceable, final, where = bound.replaceable, bound.final, bound.span
    for element, written_in in chain:
        new = _element_interface(ctx, element, written_in)
        notes = (Note("the element it redeclares", where),) if where is not None else ()
        if final:
            raise rule_error(f"the final element '{name}' cannot be redeclared",
                             element.span, _REPLACEABLE, "7.3.3", notes)
        if not replaceable and not _same_type(new, current):
            raise rule_error(f"'{name}' is not replaceable here and cannot be redeclared "
                             "with another type", element.span, _REPLACEABLE, "7.3.3",
                             notes)
        _require(ctx, new, constraint, element.span, f"the redeclaration of '{name}'",
                 _SUBTYPE)
        if element.constraint is not None:
            tighter = _constraint(ctx, element.constraint[0], written_in)
            _require(ctx, tighter, constraint, element.constraint[0].span,
                     f"the new constraining type of '{name}'", _NEW_CONSTRAINT)
            constraint = tighter
        current, replaceable, final, where = new, element.replaceable, False, element.span


def _same_type(a: Interface | None, b: Interface | None) -> bool:
    """A redeclaration keeping the type (it may change array sizes or variability);
    an unresolved type counts as the same (its error is reported where it is used)."""
    if a is None or b is None:
        return True
    return (a.primitive, a.enumeration) == (b.primitive, b.enumeration) and a.entry is b.entry


def _require(ctx: ClassViews, own: Interface | None, bound: Interface | None,
             span: Span | None, what: str, rule: str) -> None:
    if own is None or bound is None:
        return
    reason = incompatibility(ctx, own, bound)
    if reason is not None:
        raise rule_error(f"{what} is not a subtype of its constraining type "
                         f"'{bound.name}': {reason}", span, rule,
                         "7.3.2")


def _bases(ctx: ClassViews, entry: ClassEntry) -> list[ClassEntry]:
    found = []
    for element in entry.defn.elements:
        if isinstance(element, s.Extends):
            try:
                found.append(ctx.resolve_class(element.base, entry.parent or entry, entry))
            except FlattenError:
                continue
    return found


def _inherited_component(ctx: ClassViews, entry: ClassEntry, name: str
                         ) -> ViewComponent | None:
    for base in _bases(ctx, entry):
        try:
            comp = ctx.view(base).components.get(name)
        except FlattenError:
            continue
        if comp is not None:
            return comp
    return None


def _inherited_class(ctx: ClassViews, entry: ClassEntry, name: str) -> ClassEntry | None:
    for base in _bases(ctx, entry):
        try:
            found = member_class(base, name)
        except FlattenError:
            continue
        if found is not None:
            return found
    return None


def _own_or_inherited_class(ctx: ClassViews, entry: ClassEntry, name: str
                            ) -> ClassEntry | None:
    own = entry.child(name)
    if own is not None and not own.defn.redeclare:
        return own
    return _inherited_class(ctx, entry, name)
