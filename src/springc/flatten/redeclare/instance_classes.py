"""Classes replaced in one instance (Modelica 3.6, section 7.3): where ``d`` is declared
``D d(redeclare package Medium = M1)``, the names ``Medium.nXi`` and
``Medium.BaseProperties`` written in ``D`` (and in what ``D`` passes the package on to,
``b(redeclare package Medium = Medium)``) denote ``M1``'s elements.

Input: an instance and a class name used in it. Output: the class that replaces the
name in that instance, or None when the name is not redeclared there.
"""

from __future__ import annotations

from ...errors import FlattenError, Note, Span
from ...ir import syntax as s
from ...parse import ClassEntry, member_class
from ..scopes import ClassScope, FlattenContext, LocalScope, Mod, Scope


def instance_scope(scope: Scope) -> ClassScope | None:
    """The instance that a scope of loop indices is written in, if any."""
    while isinstance(scope, LocalScope):
        scope = scope.parent
    return scope if isinstance(scope, ClassScope) else None


def redeclared_package(ctx: FlattenContext, scope: ClassScope, name: str,
                       depth: int = 0) -> ClassEntry | None:
    """The class a short class redeclaration (``redeclare package Medium = M1``, in the
    modification of ``scope`` or as an element of its class) puts in place of
    ``name`` in ``scope``."""
    if name in scope.view.components or depth > 50:
        return None
    child = scope.mod.children.get(name) if scope.mod is not None else None
    defn: s.ClassDef | None = None
    where = scope
    if child is not None and child.redeclare is not None \
            and isinstance(child.redeclare.element, s.ClassDef):
        defn = child.redeclare.element
        found = instance_scope(child.redeclare.scope)
        where = found if found is not None else scope
    else:
        defn = next((e for e in scope.entry.defn.elements if isinstance(e, s.ClassDef)
                     and e.redeclare and e.name == name and e.short is not None), None)
    if defn is None or defn.short is None:
        return None
    if defn.short.modification is not None:
        raise FlattenError("a modification in a class redeclaration used in this way "
                           "(`redeclare package Medium = M1(n = 2)`, read as "
                           f"'{name}.x' or called) is not supported yet",
                           defn.short.modification.span,
                           hint="define a class with the modification and redeclare it")
    return class_in_instance(ctx, where, defn.short.base, depth + 1)


def class_in_instance(ctx: FlattenContext, scope: ClassScope, ref: s.Ref, depth: int = 0
                      ) -> ClassEntry:
    """The class ``ref`` denotes in ``scope``: its first name may be redeclared there."""
    first = ref.parts[0].name
    entry = None if ref.is_global else redeclared_package(ctx, scope, first, depth)
    if entry is None:
        return ctx.resolve_class(ref, scope.entry)
    for part in ref.parts[1:]:
        member = member_class(entry, part.name)
        if member is None:
            raise FlattenError(f"class '{entry.full_name}' has no member class "
                               f"'{part.name}'", part.span)
        entry = member
    return entry


def type_name_package(ctx: FlattenContext, scope: ClassScope, decl: s.Component
                      ) -> ClassEntry | None:
    """The package replacing the first name of ``P.C c`` in this instance, if any."""
    parts = decl.type_name.parts
    if len(parts) == 1 or decl.type_name.is_global:
        return None
    return redeclared_package(ctx, scope, parts[0].name)


def named_through(ctx: FlattenContext, scope: ClassScope, decl: s.Component,
                  package: ClassEntry | None, entry: ClassEntry) -> ClassScope | None:
    """The package a component's class is named through (``P.C c``), when it is not
    the class that declares ``C``: its constants are the ones ``C`` sees."""
    parts = decl.type_name.parts
    if len(parts) == 1 or entry.defn.short is not None:
        return None
    if package is None or len(parts) > 2:
        prefix = s.Ref(parts[:-1], decl.type_name.span, decl.type_name.is_global)
        try:
            package = class_in_instance(ctx, scope, prefix)
        except FlattenError:
            return None
    if package is entry.parent or package.defn.kind != "package":
        return None
    return ctx.package_scope(package)


def inner_class(scope: Scope, outer: ClassEntry, span: Span) -> ClassEntry:
    """The ``inner`` class of the name of the ``outer`` class ``outer`` in the nearest
    enclosing instance (section 5.4): ``outer function fc = A;`` calls the function
    ``inner function fc = B;`` of an enclosing instance."""
    instance = instance_scope(scope)
    enclosing = instance.outer if instance is not None else None
    while enclosing is not None:
        found = member_class(enclosing.entry, outer.name)
        if found is not None and found.defn.inner:
            return found
        enclosing = enclosing.outer
    raise FlattenError(f"the outer class '{outer.full_name}' has no inner class "
                       f"'{outer.name}' in an enclosing instance", span,
                       [Note("declared outer here", outer.defn.span)],
                       f"declare `inner ... {outer.name} = ...` in a model that contains "
                       "this one (Modelica 3.6, section 5.4)")


def class_modification(scope: ClassScope, decl: s.Component) -> Mod | None:
    """``extends A(B(x = 4))`` or ``a(B(x = 4))``: a modification of the class ``B`` of
    the instance, which applies to its components of type ``B`` (section 7.2)."""
    if scope.mod is None or len(decl.type_name.parts) != 1:
        return None
    name = decl.type_name.parts[0].name
    child = scope.mod.children.get(name)
    if child is None or child.redeclare is not None or name in scope.view.components:
        return None
    return Mod(None, child.children, True, child.final, child.span)
