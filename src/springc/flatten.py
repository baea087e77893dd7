"""Flatten a model: load.ClassTree + model name -> flat.FlatModel.

Instantiates the model's components with their modifications and inheritance,
expands arrays, ``for`` loops and ``if``-equations with parameter conditions, and
turns ``connect`` statements into potential equalities and flow sums.
"""

from __future__ import annotations

import gc
import itertools
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import arrays as a
from . import expr as x
from . import flat
from . import syntax as s
from .builtins import CONSTANTS
from .connections import ConnectionSets
from .errors import ErrorGroup, FlattenError, FollowUpError, Note, SpringcError
from .evaluate import Evaluator
from .instance import (
    PRIMITIVES,
    ClassScope,
    ClassView,
    LocalScope,
    Primitive,
    ResolvedType,
    ViewComponent,
    build_view,
    instance_mod,
)
from .load import ClassEntry, ClassTree, lookup_class, member_class
from .modification import Mod, ModValue, each, from_syntax, merge_all, select
from .templates import Template, make_template, reusable
from .variables import attributes_of, check_attribute_mods

STATE_SELECT = ("never", "avoid", "default", "prefer", "always")


class ParameterValues(Mapping[str, Any]):
    """Numeric values of parameters and constants, evaluated from bindings on demand."""

    def __init__(self) -> None:
        self.bindings: dict[str, x.Expr | None] = {}
        self.cache: dict[str, Any] = {}
        self.active: set[str] = set()
        self.reads = 0  # how often a value was asked for (see templates.reusable)

    def __getitem__(self, name: str) -> Any:
        self.reads += 1
        if name in self.cache:
            return self.cache[name]
        if name not in self.bindings:
            raise KeyError(f"the variable '{name}'")
        binding = self.bindings[name]
        if binding is None or name in self.active:
            raise KeyError(f"the parameter '{name}', which has no value")
        self.active.add(name)
        try:
            value = x.evaluate(binding, self)
        finally:
            self.active.discard(name)
        self.cache[name] = value
        return value

    def __iter__(self) -> Iterator[str]:
        return iter(self.bindings)

    def __len__(self) -> int:
        return len(self.bindings)


class Flattener:
    """One flattening run over a class tree."""

    def __init__(self, tree: ClassTree) -> None:
        self.tree = tree
        self.views: dict[int, ClassView] = {}
        self.package_scopes: dict[int, ClassScope] = {}
        self.parameter_values = ParameterValues()
        self.evaluator = Evaluator(self)
        self.connections = ConnectionSets()
        self.equations: list[flat.Equation] = []
        self.initial_equations: list[flat.Equation] = []
        self.errors: list[SpringcError] = []
        # Evaluated modification values by (expression, scope); the scope is kept
        # alive in the entry so that its id cannot be reused.
        self.mod_values: dict[tuple[int, int], tuple[Any, a.Value]] = {}
        self.declared_types: dict[int, Declared] = {}
        self.attribute_cache: dict[tuple[tuple[str, int], ...],
                                   tuple[tuple[Mod, ...], flat.Attributes]] = {}
        self.reusable_views: dict[int, bool] = {}
        # Equation templates by (id of the ClassView, initial); None: not reusable.
        self.templates: dict[tuple[int, bool], Template | None] = {}

    # ------------------------------------------------------------ class lookup

    def view(self, entry: ClassEntry, seen: tuple[ClassEntry, ...] = ()) -> ClassView:
        found = self.views.get(id(entry))
        if found is None:
            found = self.views[id(entry)] = build_view(entry, self, seen)
        return found

    def resolve_class(self, ref: s.Ref, scope: ClassEntry, owner: ClassEntry | None = None
                      ) -> ClassEntry:
        for part in ref.parts:
            if part.subscripts:
                raise FlattenError("a class name cannot have subscripts", part.span)
        return self.tree.resolve([p.name for p in ref.parts], scope, ref.span)

    def resolve_type(self, ref: s.Ref, scope: ClassEntry) -> ResolvedType:
        """Follow short class definitions down to a primitive type or a full class."""
        name = ref.dotted
        dims: list[tuple[s.Expr, Any]] = []
        mods: list[tuple[s.Modification, ClassEntry]] = []
        prefixes = ("", "", False)
        if name in PRIMITIVES and lookup_class(name, scope) is None:
            return ResolvedType(name, None, (), (), prefixes)
        if name in ("String", "StateSelect") or name.startswith("Modelica."):
            raise FlattenError(f"the type `{name}` is not supported yet", ref.span,
                               hint="use Real, Integer, Boolean or classes of your own")
        entry = self.resolve_class(ref, scope)
        for _ in range(100):
            short = entry.defn.short
            if short is None:
                return ResolvedType(None, entry, tuple(dims), tuple(mods), prefixes)
            if short.modification is not None:
                mods.append((short.modification, entry))
            dims += [(d, entry) for d in short.dims]
            prefixes = (prefixes[0] or short.variability, prefixes[1] or short.causality,
                        prefixes[2] or short.flow)
            base = short.base.dotted
            if base in PRIMITIVES and lookup_class(base, entry.parent or entry) is None:
                return ResolvedType(base, None, tuple(dims), tuple(mods), prefixes)
            entry = self.resolve_class(short.base, entry.parent or entry)
        raise FlattenError(f"type '{name}' is defined in terms of itself", ref.span)

    def follow_short(self, entry: ClassEntry) -> tuple[ClassEntry, list[Mod | None]]:
        """``model M2 = M(k = 2)``: the full class behind a short definition, and the
        modifications met on the way (outermost first)."""
        mods: list[Mod | None] = []
        seen = 0
        while entry.defn.short is not None and seen < 100:
            short = entry.defn.short
            if short.dims:
                raise FlattenError("a model defined as an array is not supported", short.span)
            mods.append(from_syntax(short.modification, self.package_scope(entry.parent
                                                                            or entry)))
            entry = self.resolve_class(short.base, entry.parent or entry)
            seen += 1
        if entry.defn.short is not None:
            raise FlattenError(f"'{entry.full_name}' is defined in terms of itself",
                               entry.defn.span)
        return entry, mods

    def find_function(self, name: str, scope: Any) -> ClassEntry | None:
        entry = lookup_class(name, scope.entry)
        return entry if entry is not None and entry.defn.kind == "function" else None

    def resolve_function(self, ref: s.Ref, scope: Any) -> ClassEntry:
        if lookup_class(ref.parts[0].name, scope.entry) is None:
            import difflib

            close = difflib.get_close_matches(ref.dotted, sorted(self.evaluator.builtins.table), 1)
            raise FlattenError(f"unknown function '{ref.dotted}'", ref.span,
                               hint=f"did you mean '{close[0]}'?" if close else
                               "define it as a `function`, or load the file that defines it")
        entry = self.resolve_class(ref, scope.entry)
        if entry.defn.kind != "function":
            raise FlattenError(f"'{ref.dotted}' is a {entry.defn.kind}, not a function",
                               ref.span, [Note("defined here", entry.defn.span)])
        return entry

    def class_member(self, entry: ClassEntry, name: str, span: s.Span) -> Any:
        """``P.c``: a nested class or a constant of a package."""
        nested = member_class(entry, name)
        if nested is not None:
            return nested
        package = self.package_scope(entry)
        if package.has_member(name):
            return package.member(name, span)
        raise FlattenError(f"'{entry.full_name}' has no element '{name}'", span)

    def package_scope(self, entry: ClassEntry) -> ClassScope:
        scope = self.package_scopes.get(id(entry))
        if scope is None:
            view = self.view(entry)
            scope = ClassScope(self, entry.full_name, view, None, entry.defn.span)
            self.package_scopes[id(entry)] = scope
        return scope

    def lookup_global(self, name: str, entry: ClassEntry, span: s.Span) -> Any:
        """A name not declared in the instance: time, a constant of an enclosing class,
        a class (for dotted references), or a built-in constant."""
        if name == "time":
            return x.TIME
        enclosing: ClassEntry | None = entry
        while enclosing is not None:
            view = self.view(enclosing) if enclosing.parent is not None else None
            if view is not None and name in view.components and enclosing is not entry:
                decl = view.components[name].decl
                if decl.variability != "constant":
                    raise FlattenError(
                        f"'{name}' belongs to the enclosing class '{enclosing.full_name}'; "
                        "only its constants are visible here", span,
                        [Note("declared here", decl.span)])
                return self.package_scope(enclosing).member(name, span)
            enclosing = enclosing.parent
        found = lookup_class(name, entry)
        if found is not None:
            return found
        if name in CONSTANTS:
            return x.Const(CONSTANTS[name])
        raise FlattenError(f"undefined name '{name}'", span,
                           hint="declare it, or check the spelling")

    # --------------------------------------------------------- instantiation

    def instantiate(self, scope: ClassScope, comp: ViewComponent) -> Any:
        decl = comp.decl
        declared = self.declared_type(comp)
        rtype = declared.rtype
        name = scope.flat_name(decl.name)
        outer = scope.mod.children.get(decl.name) if scope.mod is not None else None
        own = from_syntax(decl.modification, scope)
        if outer is None and own is None and len(declared.type_mods) <= 1:
            mod = declared.type_mods[0] if declared.type_mods else None  # nothing to merge
        else:
            mod = merge_all([outer, own, *declared.type_mods], name)
        if decl.final and outer is not None:
            raise FlattenError(f"'{name}' is final and cannot be "
                               "modified", outer.span, [Note("declared final here",
                                                              decl.span)])
        dims = declared.dims if declared.dims is not None else self._dims(decl, scope, rtype)
        if rtype.primitive is not None:
            return self._primitive(scope, decl, rtype, mod, dims, name)
        assert rtype.entry is not None
        if rtype.entry.defn.kind in ("function", "package"):
            raise FlattenError(f"'{rtype.entry.full_name}' is a {rtype.entry.defn.kind} and "
                               "cannot be instantiated", decl.type_name.span)
        view = self.view(rtype.entry)
        if not dims:
            return self._class_scope(name, view, mod, decl, scope)
        if mod is not None:
            self._check_array_mod(mod, dims, name, "")
        out = np.empty(dims, dtype=object)
        for idx in np.ndindex(dims):
            sub = tuple(i + 1 for i in idx)
            out[idx] = self._class_scope(f"{name}[{','.join(map(str, sub))}]", view,
                                         select(mod, sub), decl, scope)
        return out

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
        key = id(comp)
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
        if mod is not None or view.extends_mods:
            scope.mod = instance_mod(mod, view, scope)
        if scope.mod is not None:
            for key, child in scope.mod.children.items():
                if key not in view.components:
                    self._unknown_target(key, child, view, name)
            if scope.mod.value is not None:
                raise FlattenError(f"'{name}' is a component of class "
                                   f"'{view.entry.full_name}' and cannot be given a value",
                                   scope.mod.value.span)
        return scope

    def _unknown_target(self, key: str, child: Mod, view: ClassView, name: str) -> None:
        import difflib

        close = difflib.get_close_matches(key, list(view.components), 1)
        raise FlattenError(
            f"'{name}' (of class '{view.entry.full_name}') has no element '{key}' to modify",
            child.span, [Note(f"class '{view.entry.full_name}' is defined here",
                              view.entry.defn.span)],
            f"did you mean '{close[0]}'?" if close else
            f"the elements of '{view.entry.full_name}' are: "
            + ", ".join(view.components))

    def _dims(self, decl: s.Component, scope: ClassScope, rtype: ResolvedType
              ) -> tuple[int, ...]:
        exprs = [(d, scope) for d in decl.dims + decl.type_dims]
        exprs += [(d, self.package_scope(e.parent or e)) for d, e in rtype.dims]
        dims = []
        for d, where in exprs:
            if isinstance(d, s.Colon):
                raise FlattenError("the size of this dimension must be given ('[:]' is only "
                                   "allowed for function inputs)", d.span)
            n = self.evaluator.integer(d, where, "an array size")
            if n < 0:
                raise FlattenError(f"array size must not be negative, found {n}", d.span)
            dims.append(n)
        return tuple(dims)

    def _primitive(self, scope: ClassScope, decl: s.Component, rtype: ResolvedType,
                   mod: Mod | None, dims: tuple[int, ...], name: str) -> Primitive:
        variability = decl.variability or rtype.prefixes[0] or (
            "discrete" if rtype.primitive in ("Integer", "Boolean") else "continuous")
        causality = decl.causality or rtype.prefixes[1]
        check_attribute_mods(mod, rtype.primitive, name)
        name_list = _element_names(name, dims)
        names = a.make_array(name_list, dims) if dims else name
        binding = self._binding(mod, dims, name, decl)
        if variability == "constant":
            if binding is None:
                raise FlattenError(f"constant '{name}' needs a value", decl.span)
            value = self.evaluator.fold(binding)
            value = a.elementwise(lambda v: x.Const(v), value) if a.is_array(value) \
                else x.Const(value)
        else:
            value = a.make_array([x.Var(n) for n in name_list], dims) if dims else x.Var(name)
        prim = Primitive(names, value, decl, variability, causality,
                         decl.flow or rtype.prefixes[2], rtype.primitive or "Real", mod, dims)
        if variability in ("parameter", "constant"):
            for n, b in zip(a.scalars(names), _binding_scalars(binding, dims)):  # type: ignore
                self.parameter_values.bindings[n] = b
        else:
            prim_binding = binding
            self._binding_equations(scope, prim, prim_binding)
        return prim

    def _binding(self, mod: Mod | None, dims: tuple[int, ...], name: str, decl: s.Component
                 ) -> a.Value | None:
        if mod is None or mod.value is None:
            return None
        value = self.mod_value(mod.value)
        if isinstance(value, str):
            raise FlattenError(f"'{name}' cannot be given a string", mod.value.span)
        if a.shape(value) != dims:
            raise FlattenError(
                f"'{name}' has size {a.describe_shape(dims)} but is given a value of size "
                f"{a.describe_shape(a.shape(value))}", mod.value.span,
                [Note("declared here", decl.span)],
                "make the sizes agree, or use `each` to give every element the same value")
        return value

    def mod_value(self, mv: ModValue) -> a.Value:
        """Evaluate a modification value where it was written, then pick the element."""
        key = (id(mv.expr), id(mv.scope))
        cached = self.mod_values.get(key)
        if cached is None:
            cached = self.mod_values[key] = (mv.scope, self.evaluator.value(mv.expr, mv.scope))
        value = cached[1]
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

    # ----------------------------------------------------------------- queries

    def is_parameter_expression(self, e: x.Expr) -> bool:
        bindings = self.parameter_values.bindings
        return all(n in bindings for n in x.variables(e)) and not any(
            isinstance(n, (x.Der, x.Time)) for n in x.walk(e))

    # --------------------------------------------------------------- equations

    def equations_of(self, scope: ClassScope, initial: bool = False) -> None:
        """The equations of one instance; from the class's template when it has one."""
        view = scope.view
        items = view.initial_equations if initial else view.equations
        if not items:
            return
        target = self.initial_equations if initial else self.equations
        key = (id(view), initial)
        template = self.templates.get(key)
        if template is not None:
            target += template.instantiate(scope.prefix)
            return
        start, errors, reads = len(target), len(self.errors), self.parameter_values.reads
        for item in items:
            try:
                self.equation(item.equation, scope, scope, initial)
            except FlattenError as err:
                self.report(err)
        if key not in self.templates and scope.prefix and len(self.errors) == errors:
            independent = self.parameter_values.reads == reads and reusable(self, view)
            self.templates[key] = make_template(scope.prefix, target[start:]) \
                if independent else None

    def equation(self, eq: s.Equation, where: Any, owner: ClassScope, initial: bool) -> None:
        if isinstance(eq, s.Equality):
            self._equality(eq, where, owner, initial)
        elif isinstance(eq, s.Connect):
            if initial:
                raise FlattenError("`connect` is not allowed in an initial equation section",
                                   eq.span)
            self.connections.connect(self.evaluator, eq, where, owner)
        elif isinstance(eq, s.ForEquation):
            self._for(eq, eq.indices, where, owner, initial)
        elif isinstance(eq, s.IfEquation):
            for cond, body in eq.branches:
                if self._if_condition(cond, where):
                    self._body(body, where, owner, initial)
                    return
            self._body(eq.otherwise, where, owner, initial)
        else:
            name = eq.call.func.dotted
            raise FlattenError(f"`{name}` is not supported yet as an equation", eq.span,
                               hint="springc supports a subset of Modelica; see the "
                               "\"Later\" list in LANGUAGE.md")

    def _if_condition(self, cond: s.Expr, where: Any) -> Any:
        """The value of an if-equation condition, which must be a parameter expression
        (a condition on variables would switch equations at events)."""
        self.evaluator.no_event += 1
        try:
            return self.evaluator.constant(
                cond, where, "the condition of an if-equation",
                "switching equations on a variable needs events, which are not supported "
                "yet; for a continuous switch write one equation with an if-expression "
                "inside noEvent(...)")
        finally:
            self.evaluator.no_event -= 1

    def _body(self, body: tuple[s.Equation, ...], where: Any, owner: ClassScope,
              initial: bool) -> None:
        for eq in body:
            self.equation(eq, where, owner, initial)

    def _for(self, eq: s.ForEquation, indices: tuple[s.ForIndex, ...], where: Any,
             owner: ClassScope, initial: bool) -> None:
        index, rest = indices[0], indices[1:]
        for value in self.evaluator.range_values(index, where):
            local = LocalScope({index.name: value}, where)
            if rest:
                self._for(eq, rest, local, owner, initial)
            else:
                self._body(eq.body, local, owner, initial)

    def _equality(self, eq: s.Equality, where: Any, owner: ClassScope, initial: bool) -> None:
        lhs = self.evaluator.value(eq.lhs, where)
        rhs = self.evaluator.value(eq.rhs, where)
        if a.shape(lhs) != a.shape(rhs):
            raise FlattenError(
                f"the two sides of this equation differ in size: "
                f"{a.describe_shape(a.shape(lhs))} and {a.describe_shape(a.shape(rhs))}",
                eq.span, hint="both sides of an equation must have the same size")
        for side, e in ((lhs, eq.lhs), (rhs, eq.rhs)):
            if isinstance(side, str):
                raise FlattenError("strings cannot appear in equations", e.span)
        origin = flat.Origin("initial" if initial else "equation", owner.prefix)
        target = self.initial_equations if initial else self.equations
        for left, right in zip(a.scalars(lhs), a.scalars(rhs)):
            target.append(flat.Equation(left, right, eq.span, origin))

    # --------------------------------------------------------------- the model

    def report(self, err: FlattenError) -> None:
        """Record an error and go on; a follow-up error records its original, once."""
        original = err.original if isinstance(err, FollowUpError) else err
        if all(e is not original for e in self.errors):
            self.errors.append(original)

    def walk(self, scope: ClassScope) -> Iterator[ClassScope]:
        """Every class instance below ``scope`` (depth first, declaration order);
        a component that cannot be instantiated is reported and skipped."""
        for name in scope.view.components:
            try:
                member = scope.member(name)
            except FlattenError as err:
                self.report(err)
                continue
            if isinstance(member, ClassScope):
                yield from self._walk_one(member)
            elif isinstance(member, np.ndarray):
                for item in member.flat:
                    yield from self._walk_one(item)

    def _walk_one(self, scope: ClassScope) -> Iterator[ClassScope]:
        yield from self.walk(scope)
        yield scope

    def variables(self, scope: ClassScope) -> Iterator[flat.Variable]:
        for _name, member in scope.all_members():
            if isinstance(member, Primitive):
                if member.variability != "constant":
                    yield from attributes_of(self, scope, member)
            else:
                for item in (member.flat if isinstance(member, np.ndarray) else [member]):
                    yield from self.variables(item)


@dataclass(frozen=True)
class Declared:
    """What a component declaration contributes independently of the instance: its
    resolved type, the type's modifications, and its sizes when they are literals."""

    comp: ViewComponent  # kept alive: declared_types is keyed by its id
    rtype: ResolvedType
    type_mods: list[Mod | None]
    dims: tuple[int, ...] | None


def _literal_dims(decl: s.Component, rtype: ResolvedType) -> tuple[int, ...] | None:
    """The sizes of a declaration if all are integer literals (``pos[2]``), else None."""
    exprs = [*decl.dims, *decl.type_dims, *(d for d, _ in rtype.dims)]
    if all(isinstance(d, s.Number) and type(d.value) is int for d in exprs):
        return tuple(d.value for d in exprs)  # type: ignore[union-attr]
    return None


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
        return [None] * int(np.prod(dims, dtype=int))
    return a.scalars(binding)


def flatten(tree: ClassTree, model: str | None = None) -> flat.FlatModel:
    """Flatten ``model`` (a dotted name; default: the last model of the last user file)."""
    with _gc_paused():
        return _flatten(tree, model)


@contextmanager
def _gc_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector: flattening allocates millions of long-lived
    objects and frees almost none, so collections only re-scan live data (a 40% cost
    on large models). Reference counting still frees acyclic garbage."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _flatten(tree: ClassTree, model: str | None) -> flat.FlatModel:
    entry = select_model(tree, model)
    flattener = Flattener(tree)
    base, mods = flattener.follow_short(entry)
    view = flattener.view(base)
    top = ClassScope(flattener, "", view, None, entry.defn.span)
    top.mod = instance_mod(merge_all(mods), view, top)
    scopes = [top]
    try:
        scopes = [*flattener.walk(top), top]
        for scope in scopes:
            flattener.equations_of(scope)
        for scope in scopes:
            flattener.equations_of(scope, initial=True)
        if not flattener.errors:
            variables = tuple(flattener.variables(top))
    except FlattenError as err:
        flattener.report(err)
    if flattener.errors:
        errs = flattener.errors
        raise errs[0] if len(errs) == 1 else ErrorGroup(errs)
    flattener.equations += flattener.connections.equations(scopes, top)
    from .experiment import experiment_of

    return flat.FlatModel(entry.full_name, variables, tuple(flattener.equations),
                          tuple(flattener.initial_equations),
                          experiment_of(flattener, entry, top), entry.defn.span)


def select_model(tree: ClassTree, model: str | None) -> ClassEntry:
    """The class to flatten: ``model`` by dotted name, else the last model of the last
    user file."""
    if model is not None:
        parts = model.split(".")
        entry: ClassEntry | None = tree.root
        for part in parts:
            entry = entry.classes.get(part) if entry is not None else None
        if entry is None:
            raise FlattenError(f"no class named '{model}' is loaded",
                               hint=_model_hint(tree, model))
        if entry.defn.kind not in ("model", "block", "class"):
            inner = [e.full_name for e in entry.classes.values()
                     if e.defn.kind in ("model", "block", "class")]
            raise FlattenError(f"'{model}' is a {entry.defn.kind}, not a model",
                               hint=("its models are: " + ", ".join(inner)) if inner
                               else "give the dotted name of a model")
        return entry
    user_files = [f for f in tree.files if _from_user(tree, f)]
    for stored in reversed(user_files):
        for defn in reversed(stored.classes):
            if defn.kind in ("model", "block", "class"):
                return _entry_of(tree, stored, defn)
    nested = [name for f in user_files for d in f.classes
              for name in _models_below(_entry_of(tree, f, d))]
    raise FlattenError("no model found in the given files",
                       hint=f"choose a model with --model, e.g. --model {nested[0]}" if nested
                       else "name a file that defines a model, or use --model")


def _models_below(entry: ClassEntry) -> list[str]:
    """Dotted names of the models nested in ``entry`` (depth first)."""
    found = []
    for inner in entry.classes.values():
        if inner.defn.kind in ("model", "block", "class"):
            found.append(inner.full_name)
        found += _models_below(inner)
    return found


def _model_hint(tree: ClassTree, model: str) -> str:
    import difflib

    names: list[str] = []
    pending = list(tree.root.classes.values())
    while pending:
        entry = pending.pop()
        if entry.defn.kind in ("model", "block", "class"):
            names.append(entry.full_name)
        pending += entry.classes.values()
    close = difflib.get_close_matches(model, sorted(names), 3, 0.8)
    if close:
        return "did you mean " + " or ".join(f"'{n}'" for n in close) + "?"
    return "give the dotted name of a model in the loaded files, e.g. --model Scenes.Chain"


def _from_user(tree: ClassTree, stored: s.StoredDefinition) -> bool:
    package = tree.root
    for part in stored.within or ():
        package = package.classes.get(part, package)
    return any(package.classes.get(d.name) is not None and package.classes[d.name].from_user
               and package.classes[d.name].defn is d for d in stored.classes)


def _entry_of(tree: ClassTree, stored: s.StoredDefinition, defn: s.ClassDef) -> ClassEntry:
    package = tree.root
    for part in stored.within or ():
        package = package.classes[part]
    return package.classes[defn.name]
