"""Merged modifications (Modelica chapter 7.2) used while flattening.

A :class:`Mod` is the tree of modifications that applies to one element: an optional
value, the modifications of its sub-elements (or attributes such as ``start``), and
the ``each``/``final`` flags. Values remember the scope they are evaluated in, since
``Mass m(k = k0)`` evaluates ``k0`` where the modification was written.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from ...errors import FlattenError, Note, Span
from ...ir import syntax as s


@dataclass(frozen=True, slots=True)
class ModValue:
    """An expression to evaluate in ``scope``; then ``index`` (1-based) selects an element,
    as when ``Mass ms[3](m = {1, 2, 3})`` gives ``ms[2]`` the value ``m = 2``."""

    expr: s.Expr
    scope: Any  # the scope.ClassScope it is written in (scope.py imports this module)
    index: tuple[int, ...] = ()

    @property
    def span(self) -> Span:
        return self.expr.span


@dataclass(frozen=True, slots=True)
class Redeclaration:
    """``redeclare T x(...)`` or ``redeclare model M = T(...)`` written in ``scope``
    (a scope.ClassScope, where the new type name is looked up)."""

    element: s.Component | s.ClassDef
    scope: Any
    # the redeclaration this one overrides (of an inner modification, as an extends
    # clause's), checked against it by redeclare_rules
    replaced: Redeclaration | None = None


def _chain(outer: Redeclaration | None, inner: Redeclaration | None) -> Redeclaration | None:
    """``outer`` overriding ``inner``: the chain of redeclarations, outermost first."""
    if outer is None or inner is None:
        return outer or inner
    link: Redeclaration | None = outer
    while link is not None:
        if link is inner:  # the same modification met twice
            return outer
        link = link.replaced
    return replace(outer, replaced=_chain(outer.replaced, inner))


@dataclass(frozen=True)
class Mod:
    value: ModValue | None = None
    children: dict[str, Mod] = field(default_factory=dict)
    each: bool = False
    final: bool = False
    span: Span | None = None
    redeclare: Redeclaration | None = None


def from_syntax(modification: s.Modification | None, scope: Any) -> Mod | None:
    """Build a :class:`Mod` from source, its values to be evaluated in ``scope``."""
    if modification is None:
        return None
    children: dict[str, Mod] = {}
    for arg in modification.arguments:
        redeclare = Redeclaration(arg.redeclare, scope) if arg.redeclare is not None else None
        inner = from_syntax(arg.redeclare.modification if isinstance(arg.redeclare, s.Component)
                            else arg.modification, scope)
        sub = Mod(inner.value, inner.children, arg.each, arg.final, arg.span, redeclare) \
            if inner is not None else Mod(each=arg.each, final=arg.final, span=arg.span,
                                          redeclare=redeclare)
        for name in reversed(arg.path[1:]):
            sub = Mod(children={name: sub}, span=arg.span)
        head = arg.path[0]
        children[head] = _combine(children[head], sub) if head in children else sub
    value = ModValue(modification.value, scope) if modification.value is not None else None
    return Mod(value, children, span=modification.span)


def _combine(a: Mod, b: Mod) -> Mod:
    """Two modifications of the same element written side by side (``a.x = 1, a.y = 2``)."""
    if a.value is not None and b.value is not None:
        raise FlattenError("element is modified twice in the same modification", b.span,
                           [Note("first modification here", a.span)],
                           "remove one of the two modifications")
    children = dict(a.children)
    for name, mod in b.children.items():
        children[name] = _combine(children[name], mod) if name in children else mod
    return Mod(a.value or b.value, children, a.each or b.each, a.final or b.final, a.span,
               a.redeclare or b.redeclare)


def merge(outer: Mod | None, inner: Mod | None, name: str = "") -> Mod | None:
    """Merge two modifications of one element; the outer one wins (spec 7.2.4)."""
    if outer is None:
        return inner
    if inner is None:
        return outer
    if inner.final and (outer.value is not None or outer.children):
        raise FlattenError(
            f"'{name}' is final and cannot be modified", outer.span,
            [Note("declared final here", inner.span)],
            "remove this modification or the `final` prefix")
    children = dict(inner.children)
    for key, mod in outer.children.items():
        merged = merge(mod, inner.children.get(key), f"{name}.{key}" if name else key)
        assert merged is not None  # the outer one is not None
        children[key] = merged
    value = outer.value if outer.value is not None else inner.value
    each = outer.each if outer.value is not None else inner.each
    return Mod(value, children, each, inner.final or outer.final, outer.span or inner.span,
               _chain(outer.redeclare, inner.redeclare))


def merge_all(mods: list[Mod | None], name: str = "") -> Mod | None:
    """Merge a list of modifications ordered from outermost to innermost."""
    present = [m for m in mods if m is not None]
    if len(present) <= 1:
        return present[0] if present else None
    result: Mod | None = present[-1]
    for mod in reversed(present[:-1]):
        result = merge(mod, result, name)
    return result


def select(mod: Mod | None, index: tuple[int, ...]) -> Mod | None:
    """The modification of one element of an array of components (``each`` is kept whole)."""
    if mod is None or mod.each:
        return mod
    if mod.value is None and all(v.each for v in mod.children.values()):
        return mod  # nothing to pick (type modifiers): share the object
    value = ModValue(mod.value.expr, mod.value.scope, mod.value.index + index) \
        if mod.value else None
    children = {k: select(v, index) for k, v in mod.children.items()}
    return Mod(value, children, False, mod.final, mod.span,  # type: ignore[arg-type]
               mod.redeclare)


def each(mod: Mod | None) -> Mod | None:
    """``mod`` with ``each`` on all its element modifications (for type modifiers)."""
    if mod is None:
        return None
    children = {k: replace(v, each=True) for k, v in mod.children.items()}
    return replace(mod, children=children)
