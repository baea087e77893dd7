"""What a declaration becomes in one instance before it is instantiated: conditional
components (Modelica 4.4.5), ``outer`` elements (5.4) and redeclarations (7.3).

Input: a component declaration seen from an instance (:class:`ClassScope`) and the
modification that reaches it. Output: :class:`Disabled` for a conditional component
whose condition is false, the ``inner`` member an ``outer`` element stands for, or the
declaration a ``redeclare`` puts in place of the original one.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...errors import FlattenError, Note
from ...ir import syntax as s
from ..checks import rule_error
from ..scopes import (
    ClassScope,
    Declared,
    Disabled,
    FlattenContext,
    Member,
    Mod,
    ViewComponent,
    check_redeclarable,
    from_syntax,
    merge,
)


def condition_holds(fl: FlattenContext, scope: ClassScope, decl: s.Component) -> bool:
    """The value of ``decl``'s condition (``if useSupport``), a parameter expression."""
    assert decl.condition is not None
    value = fl.evaluator.constant(decl.condition, scope,
                                  "the condition of a conditional component",
                                  hint="use a Boolean parameter expression")
    if not isinstance(value, bool | np.bool_):
        raise FlattenError("the condition of a conditional component must be a Boolean, "
                           f"found {value!r}", decl.condition.span)
    return bool(value)


def disabled(scope: ClassScope, decl: s.Component) -> Disabled:
    return Disabled(decl, scope.flat_name(decl.name))


def inner_member(fl: FlattenContext, scope: ClassScope, outer: ViewComponent) -> Member:
    """The ``inner`` element that the ``outer`` declaration of ``scope`` refers to: the
    one of the same name in the nearest enclosing instance (Modelica 5.4)."""
    decl = outer.decl
    enclosing = scope.outer
    while enclosing is not None:
        comp = enclosing.view.components.get(decl.name)
        if comp is not None and comp.decl.inner:
            _check_inner_type(fl, outer, comp)
            if comp.decl.outer:  # `inner outer`: its inner part
                return enclosing.inner_part(decl.name)
            return enclosing.member(decl.name, decl.span)
        enclosing = enclosing.outer
    added = added_inner(fl, scope, outer)
    if added is not None:
        return added
    where = f"'{scope.prefix}'" if scope.prefix else "the model"
    raise FlattenError(
        f"the outer element '{scope.flat_name(decl.name)}' has no inner element "
        f"'{decl.name}' in an enclosing instance", decl.span,
        hint=f"declare `inner {decl.type_name.dotted} {decl.name}` in a model that "
        f"contains {where}")


def added_inner(fl: FlattenContext, scope: ClassScope, outer: ViewComponent
                ) -> Member | None:
    """The inner element added at the top of the model for an outer one that has none
    (section 5.4): of the outer element's class, if that is not partial; one for all
    the outer elements of that name, which must all be of one class."""
    root = scope
    while root.outer is not None:
        root = root.outer
    decl = outer.decl
    try:
        rtype = fl.declared_type(outer).rtype
    except FlattenError:
        return None  # reported where the element is instantiated
    if rtype.entry is not None and rtype.entry.defn.partial:
        return None
    found = root.added_inners.get(decl.name)
    if found is not None:
        first = fl.declared_type(found[1]).rtype
        if (first.entry, first.primitive) != (rtype.entry, rtype.primitive):
            raise rule_error(f"the outer elements '{decl.name}' have no inner element and "
                             "are of different classes", decl.span,
                             "an inner element is added at the top of the model only "
                             "for outer elements of one class", "5.4",
                             (Note("another outer element of that name", found[1].decl.span),))
        return found[0]
    if decl.name in root.view.components:
        return None
    inner = ViewComponent(replace(decl, outer=False, inner=True), outer.defined_in)
    member = fl.instantiate(root, inner)
    root.added_inners[decl.name] = (member, outer)
    return member


def _check_inner_type(fl: FlattenContext, outer: ViewComponent, inner: ViewComponent
                      ) -> None:
    """The inner element has the predefined type, the number of dimensions and the
    literal sizes of the outer one (a subtype of it, section 5.4)."""
    try:
        types = [fl.declared_type(outer), fl.declared_type(inner)]
    except FlattenError:
        return  # reported where the element is instantiated
    ndims = [len(d.comp.decl.dims) + len(d.comp.decl.type_dims) + len(d.rtype.dims)
             for d in types]
    prims = [d.rtype.primitive for d in types]
    sizes = [d.dims for d in types]
    if ndims[0] != ndims[1] or (None not in sizes and sizes[0] != sizes[1]) or (
            None not in prims and prims[0] != prims[1]):
        shown = [_shown(d, k) for d, k in zip(types, ndims, strict=True)]
        name = outer.decl.name
        raise rule_error(f"the outer element '{name}' is of type {shown[0]}, but its inner "
                         f"element is of type {shown[1]}", outer.decl.span,
                         "an inner element must be a subtype of its outer elements, "
                         "with the same sizes", "5.4",
                         (Note("the inner element is declared here", inner.decl.span),))


def _shown(declared: Declared, ndims: int) -> str:
    """``Real[10]``, ``Real[:]`` or ``P.Pin``: a declared type as the user writes it."""
    rtype = declared.rtype
    base = rtype.primitive or (rtype.entry.full_name if rtype.entry is not None else "")
    sizes = declared.dims
    if sizes is not None:
        return base + (f"[{','.join(map(str, sizes))}]" if sizes else "")
    return base + (f"[{','.join([':'] * ndims)}]" if ndims else "")


def redeclared(comp: ViewComponent, mod: Mod, name: str) -> tuple[ViewComponent, Mod | None]:
    """``b(redeclare Steel m(k = 2))`` on the declaration ``replaceable Iron m``: the new
    declaration (its type looked up where the redeclaration is written) and the
    modification that applies: the redeclaration's own, over the constraining clause's
    (the original declaration's modifiers are replaced, Modelica 7.3.2)."""
    assert mod.redeclare is not None
    new = mod.redeclare.element
    decl = comp.decl
    if not isinstance(new, s.Component):
        raise FlattenError(f"'{name}' is a component and cannot be redeclared as a class",
                           new.span, [Note("declared here", decl.span)])
    check_redeclarable(decl, mod.span)
    # a non-replaceable element keeps its type (redeclare_rules checks it resolves to
    # the same class) and may change its array sizes or variability (section 7.3.3)
    if not decl.replaceable and new.type_name.dotted != decl.type_name.dotted:
        raise FlattenError(f"'{name}' is not replaceable and cannot be redeclared",
                           mod.span, [Note("declared here", decl.span)],
                           f"declare it `replaceable {decl.type_name.dotted} {decl.name}`")
    # the constraining clause in force: the declaration's, or that of a redeclaration
    # this one overrides (`extends D(replaceable C b constrainedby C(x = 2))`)
    effective = decl.constraint
    link = mod.redeclare.replaced
    while link is not None:
        if isinstance(link.element, s.Component) and link.element.constraint is not None:
            effective = link.element.constraint
            break
        link = link.replaced
    # without a constraining clause, the declaration's own modifiers are those of its
    # (implicit) constraining type, and apply to the redeclaration (section 7.3.2)
    constraint = effective[1] if effective is not None else decl.modification
    new_decl = replace(decl, type_name=new.type_name, type_dims=new.type_dims,
                       dims=new.dims or decl.dims, modification=constraint,
                       variability=new.variability or decl.variability,
                       causality=new.causality or decl.causality, flow=new.flow or decl.flow,
                       replaceable=new.replaceable, constraint=new.constraint or
                       effective)
    outer = replace(mod, redeclare=None)
    return ViewComponent(new_decl, mod.redeclare.scope.entry), outer


def redeclared_class(scope: ClassScope, type_name: s.Ref) -> tuple[s.ClassDef, ClassScope] | None:
    """``b(redeclare model M = Other(k = 2))``, or ``redeclare model M = Other;`` as an
    element of ``b``'s class extending the one that declares ``M``: where ``b`` declares
    a component of type ``M``, the class definition that replaces ``M`` and the scope it
    is written in."""
    if len(type_name.parts) != 1:
        return None
    first = type_name.parts[0].name
    child = scope.mod.children.get(first) if scope.mod is not None else None
    if child is None or child.redeclare is None:
        own = next((e for e in scope.entry.defn.elements if isinstance(e, s.ClassDef)
                    and e.redeclare and e.name == first), None)
        return (own, scope) if own is not None else None
    element = child.redeclare.element
    if not isinstance(element, s.ClassDef):
        raise FlattenError(f"'{type_name.dotted}' is a class and cannot be redeclared as a "
                           "component", element.span)
    return element, child.redeclare.scope


def redeclared_class_mod(defn: s.ClassDef, where: ClassScope, outer: Mod | None
                         ) -> Mod | None:
    """The modification a short class redeclaration adds (``= Other(k = 2)``)."""
    short = defn.short
    if short is None:
        return outer
    return merge(outer, from_syntax(short.modification, where))
