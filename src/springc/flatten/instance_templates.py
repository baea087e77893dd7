"""Instance templates: instantiate a component once, then copy it per array element.

Input: a fully instantiated instance of a class (its member tree, the parameter bindings
and binding equations its instantiation recorded, its flat variables). Output: the same
for any further instance of that class with the same *modification shape*, names
prefixed anew (``p[1,2].flange.pos[1]`` -> ``p[7,3].flange.pos[1]``). The 2,500 masses
of a 50x50 cloth differ only in their names and in the values given from outside
(``r0``, ``v0``), so the general machinery (modification merge, binding evaluation,
attributes) runs for two instances per array instead of every one.

Why copying is valid: a template is used only for a class whose components all have
literal array sizes and no constants (:func:`_members_reusable`), so every instance has
the same members; the modification shape (:func:`shape`) equals, so the same merges
happen; instantiating the template instance read no parameter value and produced only
names inside it, so everything it evaluated is the same up to the prefix. Values
given from outside are evaluated anew per instance; they may only set whole parameters
(``Mass p[2](m = {1, 2})``), anything else is flattened instance by instance.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, fields
from itertools import islice
from typing import Any

import numpy as np

from ..errors import FlattenError
from ..ir import expr as x
from ..ir import flat
from . import arrays as a
from .equation_templates import fixed_shape, renamer
from .scopes import (
    ClassScope,
    ClassView,
    Disabled,
    FlattenContext,
    Ident,
    Mod,
    ObjectMember,
    Primitive,
    ViewComponent,
)

Shape = tuple[Any, ...]


@dataclass(frozen=True)
class InstanceTemplate:
    """One instance (``scope``) of a class, with what instantiating it recorded."""

    scope: ClassScope
    outer: dict[str, Primitive]  # parameters set from outside, by member name
    bindings: tuple[tuple[str, x.Expr | None], ...]  # in the order they were set
    equations: tuple[flat.Equation, ...]  # binding equations
    variables: tuple[tuple[flat.Variable, bool], ...]  # and whether attributes name it


@dataclass
class Recording:
    """Marks taken before walking the instance a template will be made from."""

    scope: ClassScope
    key: tuple[Ident[ClassView], Shape]
    equations: int
    bindings: int
    reads: int
    errors: int


class InstanceTemplates:
    """The instance templates of one flattening run, by (class view, modification shape)."""

    def __init__(self, flattener: FlattenContext) -> None:
        self.flattener = flattener
        self.seen: dict[tuple[Ident[ClassView], Shape], int] = {}  # instances met so far
        self.templates: dict[tuple[Ident[ClassView], Shape], InstanceTemplate | None] = {}
        self.reusable: dict[Ident[ClassView], bool] = {}

    def begin(self, scope: ClassScope) -> Recording | None:
        """Before walking ``scope``: fill it from its template if there is one, or start
        recording if it is the second instance of its kind (the first one has warmed
        the caches of values given from outside, which are then not read again)."""
        if scope.members or scope.failed or scope.variability or scope.flow or \
                scope.package is not None or not self._class_reusable(scope.view):
            return None
        mod_shape = shape(scope.mod, scope, 0)
        if mod_shape is None:
            return None
        key = (Ident(scope.view), mod_shape)
        template = self.templates.get(key)
        if template is not None:
            self._fill(scope, template)
            return None
        count = self.seen[key] = self.seen.get(key, 0) + 1
        if count != 2:
            return None
        fl = self.flattener
        return Recording(scope, key, len(fl.equations), len(fl.parameter_values.bindings),
                         fl.parameter_values.reads, len(fl.errors))

    def finish(self, rec: Recording) -> None:
        """After walking the recorded instance: make the template, or remember that
        there is none for its kind."""
        self.templates[rec.key] = self._make(rec)

    # ------------------------------------------------------------------ make

    def _make(self, rec: Recording) -> InstanceTemplate | None:
        fl, scope = self.flattener, rec.scope
        values = fl.parameter_values
        if len(fl.errors) != rec.errors or values.reads != rec.reads:
            return None
        outer = self._outer_parameters(scope)
        if outer is None:
            return None
        added = len(values.bindings) - rec.bindings
        bindings = tuple(reversed(list(islice(reversed(values.bindings.items()), added))))
        equations = tuple(fl.equations[rec.equations:])
        try:
            variables = tuple(fl.variables(scope))
        except FlattenError:
            return None  # reported again by the variables pass
        if values.reads != rec.reads:
            return None
        inside = scope.prefix + "."
        outer_names = {n for p in outer.values() for n in _scalar_names(p)}
        renamed = [b for n, b in bindings if n not in outer_names and b is not None]
        renamed += [e for eq in equations for e in (eq.lhs, eq.rhs)]
        renamed += [e for v in variables for e in _attribute_exprs(v.attributes)]
        names = [n for n, _ in bindings]
        names += [eq.origin.component + "." for eq in equations]
        names += [v.component + "." for v in variables]
        names += [n for e in renamed for n in x.variables(e)]
        if not all(n.startswith(inside) for n in names):
            return None
        return InstanceTemplate(scope, outer, bindings, equations, tuple(
            (v, bool(_attribute_exprs(v.attributes))) for v in variables))

    def _outer_parameters(self, scope: ClassScope) -> dict[str, Primitive] | None:
        """The members given a value from outside the instance; None unless all of them
        are parameters (whose values are then evaluated per instance)."""
        found: dict[str, Primitive] = {}
        if scope.mod is None:
            return found
        for name, child in scope.mod.children.items():
            if child.value is None or child.value.scope is scope:
                continue
            member = scope.members.get(name)
            if not isinstance(member, Primitive) or member.variability != "parameter":
                return None
            found[name] = member
        return found

    def _class_reusable(self, view: ClassView) -> bool:
        found = self.reusable.get(Ident(view))
        if found is None:
            self.reusable[Ident(view)] = False  # a class containing itself
            found = self.reusable[Ident(view)] = all(
                self._component_reusable(c) for c in view.components.values())
        return found

    def _component_reusable(self, comp: ViewComponent) -> bool:
        """Literal sizes and no constants: the same members in every instance."""
        return fixed_shape(self.flattener, comp, self._class_reusable)

    # ------------------------------------------------------------------ fill

    def _fill(self, scope: ClassScope, template: InstanceTemplate) -> None:
        """Give ``scope`` the members, parameter bindings and binding equations of the
        template, renamed; values from outside are evaluated for this instance first,
        and if one fails the instance is left to the general path (which reports it)."""
        fl = self.flattener
        outer: dict[str, x.Expr | None] = {}
        try:
            for name, prim in template.outer.items():
                value = fl.binding(scope.mod.children[name] if scope.mod else None,
                                   prim.dims, scope.flat_name(name), prim.decl)
                if value is None:
                    raise FlattenError(f"'{scope.flat_name(name)}' has no value")
                given = scope.mod.children[name] if scope.mod else None
                if given is not None and given.final and \
                        all(isinstance(v, x.Const) for v in a.scalars(value)):
                    return  # may be evaluated (18.3): the general path decides
                outer.update(zip(_scalar_names(prim, scope.prefix, template.scope.prefix),
                                 a.scalars(value)))
        except FlattenError:
            return
        fl.limits.add_scalars(len(template.variables), scope.prefix, scope.span)
        rename = renamer(template.scope.prefix, scope.prefix)
        cut = len(template.scope.prefix)
        _copy_members(template.scope, scope, rename, scope.prefix, cut)
        bindings = fl.parameter_values.bindings
        for name, binding in template.bindings:
            new = scope.prefix + name[cut:]
            if new in outer:
                bindings[new] = outer[new]
            else:
                bindings[new] = rename(binding) if binding is not None else None
        fl.equations += [flat.Equation(rename(eq.lhs), rename(eq.rhs), eq.span,
                                       flat.Origin(eq.origin.kind,
                                                   scope.prefix + eq.origin.component[cut:],
                                                   eq.origin.detail))
                         for eq in template.equations]
        scope.template = template

    def variables(self, scope: ClassScope) -> Iterator[flat.Variable]:
        """The flat variables of a filled instance: the template's, renamed."""
        template = scope.template
        assert isinstance(template, InstanceTemplate)
        rename = renamer(template.scope.prefix, scope.prefix)
        cut, prefix = len(template.scope.prefix), scope.prefix
        bindings = self.flattener.parameter_values.bindings
        for v, expressions in template.variables:
            name = prefix + v.name[cut:]
            yield flat.Variable(
                name, v.type, v.variability, v.causality, v.flow,
                bindings.get(name) if v.variability == "parameter" else None,
                _rename_attributes(v.attributes, rename) if expressions else v.attributes,
                v.description, prefix + v.component[cut:], v.span)


def shape(mod: Mod | None, scope: ClassScope, depth: int) -> Shape | None:
    """What must agree between two instances for one to be a copy of the other: the
    modification tree without the element index of values given from outside. None
    (no template) where a value from outside reaches below a direct member."""
    if mod is None:
        return ()
    if mod.value is None:
        value: Any = None
    elif mod.value.scope is scope:
        value = "inner"  # an extends modification, evaluated in the instance
    elif depth == 1 and not mod.children:
        value = (Ident(mod.value.expr), Ident(mod.value.scope), len(mod.value.index))
    else:
        return None
    children = []
    for key, child in mod.children.items():
        sub = shape(child, scope, depth + 1)
        if sub is None:
            return None
        children.append((key, sub))
    return value, mod.each, mod.final, tuple(children)


def _copy_members(source: ClassScope, target: ClassScope, rename: Callable[[x.Expr], x.Expr],
                  prefix: str, cut: int) -> None:
    """Fill ``target`` with renamed copies of the members of ``source``."""
    for name, member in source.members.items():
        if isinstance(member, Primitive):
            target.members[name] = _copy_primitive(member, rename, prefix, cut)
        elif isinstance(member, ClassScope):
            target.members[name] = _copy_scope(member, target, rename, prefix, cut)
        elif isinstance(member, Disabled | ObjectMember):
            target.members[name] = member
        else:
            items = [_copy_scope(m, target, rename, prefix, cut) for m in member.flat]
            target.members[name] = a.make_array(items, member.shape)


def _copy_scope(source: ClassScope, outer: ClassScope, rename: Callable[[x.Expr], x.Expr],
                prefix: str, cut: int) -> ClassScope:
    scope = ClassScope(outer.flattener, prefix + source.prefix[cut:], source.view, None,
                       source.span, outer)
    _copy_members(source, scope, rename, prefix, cut)
    return scope


def _copy_primitive(prim: Primitive, rename: Callable[[x.Expr], x.Expr], prefix: str,
                    cut: int) -> Primitive:
    names: np.ndarray | str
    value: a.Value
    if isinstance(prim.names, np.ndarray):
        names = a.make_array([prefix + n[cut:] for n in prim.names.flat], prim.dims)
        value = a.make_array([rename(v) for v in a.scalars(prim.value)], prim.dims)
    else:
        names = prefix + prim.names[cut:]
        value = rename(a.scalars(prim.value)[0])
    # dataclasses.replace without its per-call field checks (150,000 primitives of the
    # 10,000-mass chain): Primitive is a plain dataclass without __post_init__
    copied = object.__new__(Primitive)
    copied.__dict__.update(prim.__dict__, names=names, value=value)
    return copied


def _scalar_names(prim: Primitive, new: str = "", old: str = "") -> list[str]:
    names = [prim.names] if isinstance(prim.names, str) else list(prim.names.flat)
    return [new + n[len(old):] for n in names] if old else names


_EXPR_FIELDS = ("start", "nominal", "min", "max")


def _attribute_exprs(attributes: flat.Attributes) -> list[x.Expr]:
    return [e for e in (getattr(attributes, f) for f in _EXPR_FIELDS)
            if isinstance(e, x.Expr)]


def _rename_attributes(attributes: flat.Attributes, rename: Callable[[x.Expr], x.Expr]
                       ) -> flat.Attributes:
    """Attributes whose expressions (``start = 'p[1,2].r0[1]'``) name the new instance."""
    values = {f.name: getattr(attributes, f.name) for f in fields(attributes)}
    for f in _EXPR_FIELDS:
        if isinstance(values[f], x.Expr):
            values[f] = rename(values[f])
    return flat.Attributes(**values)

