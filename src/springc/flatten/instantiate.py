"""Instantiation of components while flattening, as methods of
:class:`~springc.flatten.Flattener`.

Input: a component declaration seen from an instance (:class:`ClassScope`) and the
modifications that reach it. Output: a :class:`Primitive` (with its binding equations
and parameter bindings recorded), a :class:`ClassScope`, or an array of them.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from ..errors import ErrorGroup, FlattenError, Note, ParseError, close_names
from ..ir import expr as x
from ..ir import flat
from ..ir import syntax as s
from ..parse import ClassEntry, member_class
from . import arrays as a
from .array_ops import typed_dimension
from .calls import string_component
from .checks import (
    check_constant_binding,
    check_discrete_binding,
    check_enum_binding,
    check_integer_binding,
    check_modified,
    rule_error,
    stronger,
)
from .natives import is_external_object, table_object
from .redeclare import (
    check_redeclarations,
    class_modification,
    condition_holds,
    disabled,
    inner_member,
    named_through,
    record_mod,
    redeclared,
    redeclared_class,
    redeclared_class_mod,
    type_name_package,
)
from .scopes import (
    ClassScope,
    ClassView,
    Declared,
    DimensionKind,
    FlattenContext,
    Ident,
    Member,
    Mod,
    ModValue,
    Primitive,
    ResolvedType,
    ViewComponent,
    check_attribute_mods,
    each,
    from_syntax,
    instance_mod,
    merge_all,
    select,
)


class Instantiation(FlattenContext):
    """Member instantiation; mixed into the Flattener, which provides the caches and
    the lookup methods (``view``, ``resolve_type``, ``package_scope``)."""

    # Evaluated modification values by (id of the expression, id of the scope); the
    # scope is kept alive in the entry so that its id cannot be reused.
    mod_values: dict[tuple[Ident[s.Expr], Ident[object]], a.Value]
    declared_types: dict[Ident[ViewComponent], Declared]

    def instantiate(self, scope: ClassScope, comp: ViewComponent) -> Member:
        decl = comp.decl
        name = scope.flat_name(decl.name)
        if decl.condition is not None and not condition_holds(self, scope, decl):
            return disabled(scope, decl)
        if decl.outer:  # (of an `inner outer` element: its outer part, section 5.4)
            modified = decl.modification or (scope.mod.children.get(decl.name)
                                             if scope.mod is not None else None)
            if modified is not None and not decl.inner:
                raise FlattenError(f"the outer element '{name}' cannot be modified",
                                   modified.span, [Note("declared here", decl.span)],
                                   "modify the inner element instead (Modelica 5.4)")
            return inner_member(self, scope, comp)
        outer = scope.mod.children.get(decl.name) if scope.mod is not None else None
        if outer is not None and outer.redeclare is not None:
            comp, outer = redeclared(comp, outer, name)
            decl = comp.decl
        declared = self.declared_type(comp)
        rtype = declared.rtype
        own = from_syntax(decl.modification, scope)
        if decl.constraint is not None and decl.constraint[1] is not None:
            # `constrainedby A(x = 2)` modifies the declaration too, under its own
            # modifiers (section 7.3.2)
            own = merge_all([own, from_syntax(decl.constraint[1], scope)], name)
        type_mods = declared.type_mods
        by_class = redeclared_class(scope, decl.type_name)
        if by_class is not None:
            rtype, type_mods = self._redeclared_type(by_class[0], by_class[1])
        package = None if by_class is not None else type_name_package(self, scope, decl)
        retyped = by_class is not None or package is not None
        if package is not None:  # Medium.BaseProperties, with Medium redeclared
            rest = decl.type_name.parts[1:]
            rtype = self.resolve_type(s.Ref(rest, decl.type_name.span), package)
            type_mods = [each(from_syntax(m, self.package_scope(e.parent or e)))
                         for m, e in rtype.mods]
        classmod = class_modification(scope, decl)
        if classmod is not None:  # `extends A(B(x = 4))` on `B b;` (section 7.2)
            type_mods = [classmod, *type_mods]
        if outer is None and own is None and len(type_mods) <= 1:
            mod = type_mods[0] if type_mods else None  # nothing to merge
        else:
            mod = merge_all([outer, own, *type_mods], name)
        if decl.final and outer is not None:
            raise FlattenError(f"'{name}' is final and cannot be "
                               "modified", outer.span, [Note("declared final here",
                                                              decl.span)])
        dims, kinds = (declared.dims, ()) if declared.dims is not None and not retyped \
            else self._dims(decl, scope, rtype, mod, name)
        for n in dims:
            self.limits.check_size(n, f"a dimension of '{name}'", decl.span)
        self.limits.add_scalars(math.prod(dims), name, decl.span)
        if rtype.primitive == "String":
            return string_component(self, decl, rtype, mod, dims, name)
        if rtype.primitive is not None:
            return self._primitive(scope, decl, rtype, mod, dims, name, kinds)
        assert rtype.entry is not None
        if rtype.entry.defn.kind in ("function", "package"):
            raise FlattenError(f"'{rtype.entry.full_name}' is a {rtype.entry.defn.kind} and "
                               "cannot be instantiated", decl.type_name.span)
        if rtype.entry.defn.partial:
            raise FlattenError(f"'{name}' is of the partial class '{rtype.entry.full_name}', "
                               "which cannot be instantiated", decl.span,
                               [Note(f"'{rtype.entry.full_name}' is declared partial here",
                                     rtype.entry.defn.span)],
                               "use a class that extends it")
        if is_external_object(rtype.entry):
            value = self.mod_value(mod.value) if mod is not None and mod.value is not None \
                else None
            return table_object(self.evaluator, rtype.entry, value, name, decl.span)
        self._check_containment(scope, rtype.entry, decl, name)
        view = self._used_view(rtype.entry, decl, name)
        through = named_through(self, scope, comp.decl, package, rtype.entry)
        if not dims:
            made = self._class_scope(name, view, mod, decl, scope)
            made.package = through
            return made
        if mod is not None:
            self._check_array_mod(mod, dims, name, "")
        out = np.empty(dims, dtype=object)
        for idx in np.ndindex(dims):
            sub = tuple(i + 1 for i in idx)
            item = self._class_scope(f"{name}[{','.join(map(str, sub))}]", view,
                                     select(mod, sub), decl, scope)
            item.package = through
            out[idx] = item
        return out

    def _used_view(self, entry: ClassEntry, decl: s.Component, name: str) -> ClassView:
        """The view of a component's class; a construct outside the subset in that class
        is reported with a note on the component that uses it."""
        try:
            return self.view(entry)
        except (ParseError, ErrorGroup) as err:
            note = Note(f"'{name}' uses class '{entry.full_name}' here", decl.span)
            errors = err.errors if isinstance(err, ErrorGroup) else (err,)
            if not all(isinstance(e, ParseError) for e in errors):
                raise
            noted = [ParseError(e.message, e.span, (*e.notes, note), e.hint) for e in errors]
            raise (noted[0] if len(noted) == 1 else ErrorGroup(noted)) from None

    def _redeclared_type(self, defn: s.ClassDef, where: ClassScope
                         ) -> tuple[ResolvedType, list[Mod | None]]:
        """The type and type modifiers of a class replaced by ``redeclare model M = T(...)``."""
        if defn.short is None:  # `redeclare model M ... end M;`: that class itself
            return self.resolve_type(s.Ref((s.RefPart(defn.name, (), defn.span),),
                                           defn.span), where.entry), []
        rtype = self.resolve_type(defn.short.base, where.entry)
        mods = [each(from_syntax(m, self.package_scope(e.parent or e))) for m, e in rtype.mods]
        return rtype, [redeclared_class_mod(defn, where, None), *mods]

    def _check_containment(self, scope: ClassScope, entry: ClassEntry, decl: s.Component,
                           name: str) -> None:
        """A component may not be of a class that (directly or through its components)
        contains it: ``model A  A a; end A;`` would be infinitely large."""
        chain: list[ClassScope] = []
        outer: ClassScope | None = scope
        while outer is not None:
            chain.append(outer)
            if outer.entry is entry:
                path = " -> ".join(f"'{c.prefix}' ({c.entry.full_name})" if c.prefix
                                   else f"the model ({c.entry.full_name})"
                                   for c in reversed(chain))
                raise FlattenError(
                    f"'{name}' is of class '{entry.full_name}', which contains it: the "
                    "model would be infinitely large", decl.span,
                    [Note(f"the chain of components: {path} -> '{name}'"),
                     Note(f"class '{entry.full_name}' is defined here", entry.defn.span)],
                    "a class cannot contain a component of its own class, directly or "
                    "through its components")
            outer = outer.outer

    def _check_array_mod(self, mod: Mod, dims: tuple[int, ...], name: str, path: str
                         ) -> None:
        """Values (without ``each``) modifying an array of components must start with
        the array's sizes: ``Mass m[3](s0 = {1, 2, 3})``."""
        if mod.each:
            return
        if mod.value is not None:
            value = self.mod_value(mod.value)
            if not isinstance(value, str) and a.shape(value)[:len(dims)] != dims:
                raise FlattenError(
                    f"the value of '{path or name}' has size {a.describe_shape(a.shape(value))}, "
                    f"but '{name}' is an array of components of size "
                    f"{a.describe_shape(dims)}", mod.value.span,
                    hint="give one value per element, or use `each` to give every element "
                    "the same value")
        for key, child in mod.children.items():
            self._check_array_mod(child, dims, name, f"{path}.{key}" if path else key)

    def declared_type(self, comp: ViewComponent) -> Declared:
        """The resolved type of a declaration and its type modifiers, computed once."""
        key = Ident(comp)
        found = self.declared_types.get(key)
        if found is None:
            rtype = self.resolve_type(comp.decl.type_name, comp.defined_in)
            # A type's own modifications apply to every element of an array of that type.
            mods = [each(from_syntax(m, self.package_scope(e.parent or e)))
                    for m, e in rtype.mods]
            found = self.declared_types[key] = Declared(comp, rtype, mods,
                                                        _literal_dims(comp.decl, rtype))
        return found

    def _class_scope(self, name: str, view: ClassView, mod: Mod | None, decl: s.Component,
                     parent: ClassScope) -> ClassScope:
        scope = ClassScope(self, name, view, None, decl.span, parent)
        scope.variability = stronger(decl.variability, parent.variability)
        scope.flow = decl.flow or parent.flow
        if mod is not None:
            check_modified(view, mod, name)
        if mod is not None or view.extends_mods:
            scope.mod = instance_mod(mod, view, scope)
            check_redeclarations(self, view, scope.mod)
        if scope.mod is not None:
            for key, child in scope.mod.children.items():
                if key not in view.components and not (
                        child.redeclare is not None
                        and isinstance(child.redeclare.element, s.ClassDef)) \
                        and member_class(view.entry, key) is None:
                    self._unknown_target(key, child, view, name)
            if scope.mod.value is not None and view.entry.defn.kind == "record":
                scope.mod = record_mod(self, scope.mod, view, name)
            if scope.mod.value is not None:
                raise FlattenError(f"'{name}' is a component of class "
                                   f"'{view.entry.full_name}' and cannot be given a value",
                                   scope.mod.value.span)
        scope.flow = decl.flow or parent.flow  # flow applies to the elements (4.4.2.2)
        return scope

    def _unknown_target(self, key: str, child: Mod, view: ClassView, name: str) -> None:
        close = close_names(key, list(view.components), 1)
        raise FlattenError(
            f"'{name}' (of class '{view.entry.full_name}') has no element '{key}' to modify",
            child.span, [Note(f"class '{view.entry.full_name}' is defined here",
                              view.entry.defn.span)],
            f"did you mean '{close[0]}'?" if close else
            f"the elements of '{view.entry.full_name}' are: "
            + ", ".join(view.components))

    def _dims(self, decl: s.Component, scope: ClassScope, rtype: ResolvedType,
              mod: Mod | None = None, name: str = ""
              ) -> tuple[tuple[int, ...], tuple[DimensionKind, ...]]:
        """The sizes of a declaration's dimensions, and their kinds (() if every
        dimension is an Integer size)."""
        exprs = [(d, scope) for d in decl.dims + decl.type_dims]
        exprs += [(d, self.package_scope(e.parent or e)) for d, e in rtype.dims]
        dims = []
        kinds: list[DimensionKind] = []
        for k, (d, where) in enumerate(exprs):
            kinds.append(None)
            if isinstance(d, s.Colon):
                dims.append(self._colon_size(k, d, mod, name or decl.name))
                continue
            typed = typed_dimension(self, d, where)
            if typed is not None:  # [Boolean], [E] (section 10.1)
                dims.append(typed[0])
                kinds[-1] = typed[1]
                continue
            n = self.evaluator.integer(d, where, "an array size")
            if n < 0:
                raise FlattenError(f"array size must not be negative, found {n}", d.span)
            dims.append(n)
        return tuple(dims), tuple(kinds) if any(k is not None for k in kinds) else ()

    def _colon_size(self, k: int, d: s.Colon, mod: Mod | None, name: str) -> int:
        """The size of a ``[:]`` dimension: that of the binding (section 10.1)."""
        if mod is None or mod.value is None:
            raise FlattenError(f"the size of dimension {k + 1} of '{name}' ('[:]') is not "
                               "given by a binding", d.span,
                               hint="give the size ([3]) or a value that has it "
                                    "(= {1, 2, 3})")
        value = self.mod_value(mod.value)
        dims = a.shape(value)
        if k >= len(dims):
            raise FlattenError(f"'{name}' has '[:]' as dimension {k + 1}, but its value "
                               f"has size {a.describe_shape(dims)}", mod.value.span,
                               [Note("the dimension is here", d.span)])
        return dims[k]

    def _primitive(self, scope: ClassScope, decl: s.Component, rtype: ResolvedType,
                   mod: Mod | None, dims: tuple[int, ...], name: str,
                   kinds: tuple[DimensionKind, ...] = ()) -> Primitive:
        if rtype.enumeration is not None and not rtype.enumeration.literals:
            raise rule_error(f"'{name}' is of the enumeration type "
                             f"'{rtype.enumeration.name}', which has no literals",
                             decl.span, "a simulated model has no variables of an "
                             "unspecified enumeration `enumeration(:)`: redeclare the type "
                             "(`redeclare type E = Colors`)", "4.9.5.4")
        variability = stronger(decl.variability or rtype.prefixes[0] or (
            "discrete" if rtype.primitive in ("Integer", "Boolean") else "continuous"),
            scope.variability)
        check_integer_binding(name, rtype.primitive or "Real",
                              mod.value.expr if mod is not None and mod.value else None)
        if mod is not None and mod.value is not None:
            check_enum_binding(name, rtype.primitive or "Real", rtype.enumeration,
                               mod.value.expr, mod.value.scope, self.evaluator)
        causality = decl.causality or rtype.prefixes[1]
        check_attribute_mods(mod, rtype.primitive, name)
        name_list = _element_names(name, dims)
        names = a.make_array(name_list, dims) if dims else name
        binding = self.binding(mod, dims, name, decl)
        if mod is not None and mod.value is not None:
            check_discrete_binding(name, rtype.primitive or "Real", variability,
                                   mod.value.expr, mod.value.scope)
        if variability == "parameter" and self._evaluated(decl, mod, binding, name):
            variability = "constant"
        if variability == "constant":
            if binding is None:
                raise FlattenError(f"constant '{name}' needs a value", decl.span)
            value = self._constant_value(binding, name, mod)
            value = a.elementwise(lambda v: x.Const(v), value) if a.is_array(value) \
                else x.Const(value)
        else:
            value = a.make_array([x.Var(n) for n in name_list], dims) if dims else x.Var(name)
        flow = decl.flow or rtype.prefixes[2] or scope.flow
        prim = Primitive(names, value, decl, variability, causality,
                         flow, rtype.primitive or "Real", mod, dims,
                         rtype.connector or scope.expandable,  # 9.1.3: all connectors
                         rtype.enumeration, kinds)
        if variability in ("parameter", "constant"):
            for n, b in zip(name_list, _binding_scalars(binding, dims)):
                self.parameter_values.bindings[n] = b
        else:
            prim_binding = binding
            self._binding_equations(scope, prim, prim_binding)
        return prim

    def _evaluated(self, decl: s.Component, mod: Mod | None, binding: a.Value | None,
                   name: str) -> bool:
        """Whether a parameter is folded into the model as a constant (Modelica 18.3):
        ``annotation(Evaluate = true)``, or ``final`` with a binding that names such
        parameters or constants only (``final C = CapVal``), as the established tools
        do; its binding must be a constant expression."""
        if binding is None or mod is None or mod.value is None:
            return False
        if not decl.evaluate:
            final = decl.final or mod.final
            if not final or isinstance(mod.value.expr, (s.Number, s.Bool, s.String)) or \
                    not all(isinstance(v, x.Const) for v in a.scalars(binding)):
                return False
        try:
            self._constant_value(binding, name, mod)
        except FlattenError:
            return False
        return True

    def _constant_value(self, binding: a.Value, name: str, mod: Mod | None) -> Any:
        """The numeric value of a constant's binding (a constant expression): a number,
        or a numpy array of numbers."""
        span = mod.value.span if mod is not None and mod.value is not None else None
        check_constant_binding(name, a.scalars(binding), self.parameter_values.bindings, span)
        try:
            value = self.evaluator.fold(binding)
        except KeyError as missing:
            raise FlattenError(f"the value of constant '{name}' must be a constant "
                               f"expression, but it depends on {missing.args[0]}", span,
                               hint="use only constants and literals in the binding of a "
                               "constant, or make it a parameter") from None
        except (ArithmeticError, ValueError, TypeError) as err:
            reason = "division by zero" if isinstance(err, ZeroDivisionError) else str(err)
            raise FlattenError(f"cannot evaluate the value of constant '{name}': {reason}",
                               span) from None
        for item in (value.flat if isinstance(value, np.ndarray) else [value]):
            if isinstance(item, float) and not math.isfinite(item):
                raise FlattenError(f"the value of constant '{name}' is {item} (an "
                                   "operation overflows or is undefined)", span)
        return value

    def binding(self, mod: Mod | None, dims: tuple[int, ...], name: str, decl: s.Component
                 ) -> a.Value | None:
        if mod is None or mod.value is None:
            return None
        value = self.mod_value(mod.value)
        if isinstance(value, str):
            raise FlattenError(f"'{name}' cannot be given a string", mod.value.span)
        if isinstance(value, a.RecordValue):
            raise FlattenError(f"'{name}' is not a record, but its value is a record "
                               f"'{value.name}'", mod.value.span,
                               [Note("declared here", decl.span)])
        if a.shape(value) != dims:
            raise FlattenError(
                f"'{name}' has size {a.describe_shape(dims)} but is given a value of size "
                f"{a.describe_shape(a.shape(value))}", mod.value.span,
                [Note("declared here", decl.span)],
                "make the sizes agree, or use `each` to give every element the same value")
        return value

    def mod_value(self, mv: ModValue) -> a.Value:
        """Evaluate a modification value where it was written, then pick the element."""
        key = (Ident(mv.expr), Ident(mv.scope))
        cached = self.mod_values.get(key)
        if cached is None:
            cached = self.mod_values[key] = self.evaluator.value(mv.expr, mv.scope)
        value: a.Value = cached
        for i in mv.index:
            if not a.is_array(value) or value.shape[0] < i:
                raise FlattenError(
                    "the value of this modification is not an array matching the array "
                    "of components it modifies", mv.span,
                    hint="use `each` to give every element the same value")
            value = value[i - 1]
        return value

    def _binding_equations(self, scope: ClassScope, prim: Primitive,
                           binding: a.Value | None) -> None:
        if binding is None:
            return
        origin = flat.Origin("binding", scope.prefix, prim.decl.name)
        span = prim.mod.value.span if prim.mod and prim.mod.value else prim.decl.span
        for v, b in zip(a.scalars(prim.value), a.scalars(binding)):
            self.equations.append(flat.Equation(v, b, span, origin))


def _literal_dims(decl: s.Component, rtype: ResolvedType) -> tuple[int, ...] | None:
    """The sizes of a declaration if all are integer literals (``pos[2]``), else None."""
    exprs = [*decl.dims, *decl.type_dims, *(d for d, _ in rtype.dims)]
    sizes = [d.value for d in exprs if isinstance(d, s.Number) and type(d.value) is int]
    return tuple(int(n) for n in sizes) if len(sizes) == len(exprs) else None


def _element_names(name: str, dims: tuple[int, ...]) -> list[str]:
    """The flat names of the elements of ``name`` in row-major order (``x[1,2]``)."""
    if not dims:
        return [name]
    if len(dims) == 1:
        return [f"{name}[{i}]" for i in range(1, dims[0] + 1)]
    indices = itertools.product(*(range(1, n + 1) for n in dims))
    return [f"{name}[{','.join(map(str, idx))}]" for idx in indices]


def _binding_scalars(binding: a.Value | None, dims: tuple[int, ...]) -> list[x.Expr | None]:
    if binding is None:
        return [None] * math.prod(dims)
    return list(a.scalars(binding))
