"""Instances of classes while flattening: scopes, members and primitive variables, and
the Protocols through which the flattening helpers reach their driver.

A :class:`ClassScope` is one instantiated component (or the simulated model itself):
its flat prefix, its class, the modification that applies to it, and its members,
created on first use so that parameters needed for array sizes are evaluated in
dependency order. Inheritance is resolved once per class into a :class:`ClassView`.

The helpers (lookup, instantiation, equations, evaluation, connections, templates) do
not import the :class:`~springc.flatten.flattener.Flattener` or the evaluator; they take
a :class:`FlattenContext` or an :class:`ExpressionEvaluator`, the Protocols defined here
(the pattern of mypy's ``semanal_shared``), so that the package has no import cycle.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Protocol

import numpy as np

from ...errors import FlattenError, FollowUpError, Note, Span, SpringcError
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ...ir.when import When
from ...parse import ClassEntry
from .. import arrays as a
from .class_extends import inherited_class
from .enumerations import DimensionKind, Enumeration
from .event_uses import EventUses
from .identity import Ident
from .limits import Limits
from .modification import Mod, ModValue, from_syntax, merge_all
from .parameters import ParameterValues
from .syntax_walk import same_text

PRIMITIVES = frozenset({"Real", "Integer", "Boolean"})
#: The predefined types, which no class may be named (section 4.8).
PREDEFINED = frozenset({"Real", "Integer", "Boolean", "String"})



@dataclass(frozen=True)
class ViewComponent:
    """A component declaration as seen in a class, with the class that wrote it."""

    decl: s.Component
    defined_in: ClassEntry


@dataclass(frozen=True)
class ViewEquation:
    equation: s.Equation
    defined_in: ClassEntry


@dataclass(frozen=True)
class ClassView:
    """A class with its inheritance resolved: all components and equations in order,
    and the ``extends`` modifications (outermost first)."""

    entry: ClassEntry
    components: dict[str, ViewComponent]
    equations: tuple[ViewEquation, ...]
    initial_equations: tuple[ViewEquation, ...]
    extends_mods: tuple[tuple[s.Modification, ClassEntry], ...]


@dataclass(frozen=True)
class ResolvedType:
    """What a type name denotes after following short class definitions:
    a primitive type name or a class entry, plus the extra dimensions and
    modifications (outermost first, each with the scope to evaluate it in)."""

    primitive: str | None
    entry: ClassEntry | None
    dims: tuple[tuple[s.Expr, Any], ...]
    mods: tuple[tuple[s.Modification, ClassEntry], ...]
    prefixes: tuple[str, str, bool]
    connector: bool = False  # a primitive reached through `connector C = input Real`
    enumeration: Enumeration | None = None  # the type of an enumeration ("Integer")


@dataclass(eq=False)
class Primitive:
    """A declared ``Real``/``Integer``/``Boolean`` component of an instance."""

    names: np.ndarray | str
    value: Any
    decl: s.Component
    variability: str
    causality: str
    flow: bool
    type: str
    mod: Mod | None
    dims: tuple[int, ...]
    connector: bool = False  # declared with a short connector class (RealInput)
    enumeration: Enumeration | None = None  # its type, if an enumeration ("Integer")
    kinds: tuple[DimensionKind, ...] = ()  # of its dimensions; () if all are Integer


@dataclass(frozen=True, eq=False)
class Disabled:
    """A conditional component whose condition is false: it is not part of the model,
    and only ``connect`` statements may name it (they are dropped; Modelica 4.4.5)."""

    decl: s.Component
    name: str


class ObjectMember:
    """A member that is a value of its own and no variables: an external object
    (``flatten/natives/tables.py``: a ModelicaStandardTables table)."""


class DisabledReference(FlattenError):
    """A reference to a disabled conditional component (see :class:`Disabled`)."""


@dataclass(eq=False)
class ClassScope:
    """One instance of a class; ``prefix`` is its flat name (``""`` for the model)."""

    flattener: FlattenContext
    prefix: str
    view: ClassView
    mod: Mod | None
    span: Span
    outer: ClassScope | None = None
    members: dict[str, Member] = field(default_factory=dict)
    in_progress: dict[str, None] = field(default_factory=dict)  # ordered: a chain
    failed: dict[str, SpringcError] = field(default_factory=dict)
    # The InstanceTemplate this instance was copied from, if any.
    template: object | None = None
    # declared `flow` (or inside a flow component): its elements are flows (4.4.2.2)
    flow: bool = False
    # Filled by connections.connector_leaves for a connector: its scalar variables, and
    # what must match for two connectors to be connected (names and flow prefixes).
    connector_leaves: list[Leaf] | None = None
    connector_signature: tuple[tuple[str, bool], ...] = ()
    # constant/parameter/discrete on this (structured) component, which applies to its
    # elements of a less restrictive variability (Modelica 3.6, section 4.4.4.1)
    variability: str = ""
    # The package its class was named through (`Medium.Props p` with Medium a package
    # extending the one that declares Props): its constants are those the class sees
    # (the package is the class's enclosing class there, section 5.3).
    package: ClassScope | None = None
    # The inner parts of its `inner outer` elements (section 5.4): local references
    # name the outer part (the member), the outer elements below the inner part.
    inner_parts: dict[str, Member] = field(default_factory=dict)
    # Of the model: the inner elements added for outer ones that have none (5.4), with
    # the outer declaration that caused each.
    added_inners: dict[str, tuple[Member, ViewComponent]] = field(default_factory=dict)
    # Of an expandable connector: the variables connections added to it (9.1.3), each
    # declared like the variable on the connection's other side.
    augmented: dict[str, ViewComponent] = field(default_factory=dict)

    @property
    def entry(self) -> ClassEntry:
        return self.view.entry

    @property
    def kind(self) -> str:
        return self.view.entry.defn.kind

    @property
    def expandable(self) -> bool:
        """An instance of an ``expandable connector`` (section 9.1.3)."""
        return self.view.entry.defn.expandable

    def flat_name(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def has_member(self, name: str) -> bool:
        return name in self.view.components or name in self.augmented

    def component(self, name: str) -> ViewComponent:
        """The declaration of the member ``name``: of the class, or added (9.1.3)."""
        found = self.view.components.get(name)
        return found if found is not None else self.augmented[name]

    def member(self, name: str, span: Span | None = None) -> Member:
        """The member ``name``, instantiating it on first use."""
        found = self.members.get(name)
        if found is not None:
            return found
        if name in self.failed:
            raise FollowUpError(self.failed[name])
        if name in self.in_progress:
            decl = self.component(name).decl
            chain = [*list(self.in_progress)[list(self.in_progress).index(name):], name]
            raise FlattenError(f"'{self.flat_name(name)}' is defined in terms of itself: "
                               + " -> ".join(self.flat_name(n) for n in chain),
                               span or decl.span, [Note("declared here", decl.span)],
                               "break the cycle in the bindings or array sizes")
        self.in_progress[name] = None
        try:
            created = self.flattener.instantiate(self, self.component(name))
        except FlattenError as err:
            self.failed[name] = err.original if isinstance(err, FollowUpError) else err
            raise
        finally:
            self.in_progress.pop(name, None)
        self.members[name] = created
        return created

    def inner_part(self, name: str) -> Member:
        """The inner part of the ``inner outer`` element ``name``, instantiated on first
        use: the element as if declared ``inner`` only."""
        found = self.inner_parts.get(name)
        if found is None:
            comp = self.view.components[name]
            inner = ViewComponent(replace(comp.decl, outer=False), comp.defined_in)
            found = self.inner_parts[name] = self.flattener.instantiate(self, inner)
        return found

    def all_members(self) -> Iterator[tuple[str, Primitive | ClassScope | np.ndarray]]:
        """The members this instance owns: not disabled conditional components, and not
        ``outer`` ones (they are the ``inner`` instance's, reached from here), but the
        inner parts of ``inner outer`` ones."""
        for name, comp in self.view.components.items():
            if comp.decl.outer and not comp.decl.inner:
                continue
            member = self.inner_part(name) if comp.decl.outer else self.member(name)
            if not isinstance(member, Disabled | ObjectMember):
                yield name, member
        for name, (added, _) in self.added_inners.items():
            yield name, added  # type: ignore[misc]
        for name in self.augmented:
            yield name, self.member(name)  # type: ignore[misc]

    def lookup(self, name: str, span: Span) -> Any:
        if name in self.view.components or name in self.augmented:
            return self.member(name, span)
        if self.package is not None and self.package.has_member(name):
            return self.package.member(name, span)
        try:
            return self.flattener.lookup_global(name, self.entry, span)
        except FlattenError as err:
            if not err.message.startswith("undefined name"):
                raise
            found = self.flattener.inherited_name(self, name, span)
            if found is None:
                raise
            return found


@dataclass(eq=False)
class LocalScope:
    """Loop indices over an enclosing scope; inside a subscript that uses ``end``, also
    the size of the subscripted dimension (``end_value``)."""

    names: dict[str, Any]
    parent: Scope
    end_value: int | None = None

    @property
    def entry(self) -> ClassEntry:
        return self.parent.entry

    def lookup(self, name: str, span: Span) -> Any:
        if name in self.names:
            return self.names[name]
        return self.parent.lookup(name, span)


@dataclass(eq=False)
class FunctionScope:
    """Variables of one function call, over the function's package (for constants);
    None marks a variable not assigned yet."""

    names: dict[str, Any]
    parent: ClassScope
    entry: ClassEntry

    def lookup(self, name: str, span: Span) -> Any:
        if name not in self.names:
            if self.parent.has_member(name):
                return self.parent.lookup(name, span)
            # from the function itself: its imports, then its enclosing classes
            return self.parent.flattener.lookup_global(name, self.entry, span)
        value = self.names[name]
        if value is None:
            raise FlattenError(f"'{name}' is used before it is assigned", span)
        if isinstance(value, a.FunctionArgument):
            raise FlattenError(f"'{name}' is a function (a functional input), not a value",
                               span, hint=f"call it: {name}(...) (section 12.4.2)")
        return value


#: Where a name is looked up: an instance, loop indices over one, or a function call.
Scope = ClassScope | LocalScope | FunctionScope
#: A member of an instance: a primitive variable, a component, or an array of components.
Member = Primitive | ClassScope | np.ndarray | Disabled | ObjectMember


@dataclass(frozen=True, slots=True)
class Leaf:
    """A scalar variable of a connector: its name relative to the connector, its flat
    name, and whether it is a flow variable."""

    relative: str
    name: str
    flow: bool


@dataclass(frozen=True)
class Declared:
    """What a component declaration contributes independently of the instance: its
    resolved type, the type's modifications, and its sizes when they are literals."""

    comp: ViewComponent
    rtype: ResolvedType
    type_mods: list[Mod | None]
    dims: tuple[int, ...] | None


Handler = Callable[[s.Call, Scope], a.Value]
AttributeCache = dict[tuple[tuple[str, Ident[Mod]], ...], flat.Attributes]


class BuiltinFunctions(Protocol):
    """The built-in functions of the language, by name."""

    table: dict[str, Handler]

    def lookup(self, name: str, scope: Scope) -> Handler | None: ...


class ExpressionEvaluator(Protocol):
    """What the flattening helpers call on the expression evaluator (``evaluate.py``)."""

    flattener: FlattenContext

    def record_value(self, record: ClassScope) -> Any: ...
    no_event: int  # > 0 inside noEvent(...) and smooth(...)
    literal: int  # > 0 inlining a function body without GenerateEvents = true (12.8)
    eventful: int  # > 0 evaluating a when-condition: the functions it calls switch at events
    call_depth: int  # nesting of user-defined function calls being inlined
    events: EventUses  # pre/edge/change uses and when-clause nesting (event_calls.py)

    @property
    def builtins(self) -> BuiltinFunctions: ...

    def value(self, e: s.Expr, scope: Scope) -> a.Value: ...

    def scalar(self, e: s.Expr, scope: Scope) -> x.Expr: ...

    def constant(self, e: s.Expr, scope: Scope, what: str,
                 hint: str = ...) -> Any: ...

    def integer(self, e: s.Expr, scope: Scope, what: str) -> int: ...

    def fold(self, v: a.Value) -> Any: ...

    def describe(self, v: Any) -> str: ...

    def reference(self, e: s.Ref, scope: Scope) -> Any: ...

    def iterate(self, body: s.Expr, indices: tuple[s.ForIndex, ...], scope: Scope
                ) -> Iterator[a.Value]: ...

    def range_values(self, index: s.ForIndex, scope: Scope) -> Sequence[x.Expr | str]: ...


class ClassViews(Protocol):
    """Classes as the static rules, the redeclaration checks and the class views see
    them: the view of a class (inheritance resolved) and what class and type names
    denote. The small face of the driver for :mod:`..checks` and :mod:`..redeclare`."""

    def view(self, entry: ClassEntry, seen: tuple[ClassEntry, ...] = ()) -> ClassView: ...

    def resolve_class(self, ref: s.Ref, scope: ClassEntry, owner: ClassEntry | None = None
                      ) -> ClassEntry: ...

    def resolve_type(self, ref: s.Ref, scope: ClassEntry) -> ResolvedType: ...


class FlatResults(Protocol):
    """The flat model built so far: equations, when-clauses and assertions (what
    connection placeholders and algorithm start values are written into)."""

    equations: list[flat.Equation]
    initial_equations: list[flat.Equation]
    whens: list[When]
    # assertions and the spans of their conditions (flatten/calls/assertions.py)
    assertions: list[tuple[flat.Assertion, Span]]
    # located warnings, the flat model's notes (a call skipped: natives.skipped_call)
    warnings: list[str]


class FlattenContext(ClassViews, FlatResults, Protocol):
    """What the flattening helpers call on the driver
    (:class:`~springc.flatten.flattener.Flattener`): its results so far, its caches,
    and class lookup and instantiation. Helpers that need less take
    :class:`ClassViews` or :class:`FlatResults`."""

    parameter_values: ParameterValues
    evaluator: ExpressionEvaluator
    limits: Limits
    errors: list[SpringcError]
    # conditions of if-statements, checked to be Boolean once the types are known
    statement_conditions: list[tuple[x.Expr, Span]]
    # while loops decided by the parameters' values, and the parameters of the calls
    # evaluated numerically for them (flatten/calls/parameter_calls.py)
    parameter_decisions: int
    evaluated: set[str]
    attribute_cache: AttributeCache
    # the class that wrote the equation being flattened: an inherited equation finds
    # the functions of its base class's scope
    written_in: ClassEntry | None

    def report(self, err: FlattenError) -> None: ...

    def resolve_function(self, ref: s.Ref, scope: Scope) -> ClassEntry: ...

    def find_function(self, name: str, scope: Scope) -> ClassEntry | None: ...

    def lookup_global(self, name: str, entry: ClassEntry, span: Span) -> Any: ...

    def inherited_name(self, scope: ClassScope, name: str, span: Span) -> Any: ...

    def class_member(self, entry: ClassEntry, name: str, span: Span) -> Any: ...

    def package_scope(self, entry: ClassEntry) -> ClassScope: ...

    def follow_short(self, entry: ClassEntry) -> tuple[ClassEntry, list[Any]]: ...

    def instantiate(self, scope: ClassScope, comp: ViewComponent) -> Member: ...

    def declared_type(self, comp: ViewComponent) -> Declared: ...

    def binding(self, mod: Mod | None, dims: tuple[int, ...], name: str,
                decl: s.Component) -> a.Value | None: ...

    def mod_value(self, mv: ModValue) -> a.Value: ...

    def is_parameter_expression(self, e: x.Expr) -> bool: ...

    def equation(self, eq: s.Equation, where: Scope, owner: ClassScope, initial: bool
                 ) -> None: ...

    def variables(self, scope: ClassScope) -> Iterator[flat.Variable]: ...


def build_view(entry: ClassEntry, flattener: ClassViews, seen: tuple[ClassEntry, ...] = ()
               ) -> ClassView:
    """Resolve ``extends`` clauses: base elements first, then the class's own."""
    if entry in seen:
        raise FlattenError(f"class '{entry.full_name}' extends itself", entry.defn.span)
    components: dict[str, ViewComponent] = {}
    equations: list[ViewEquation] = []
    initial: list[ViewEquation] = []
    mods: list[tuple[s.Modification, ClassEntry]] = []
    for element in entry.defn.elements:
        if not isinstance(element, s.Extends) or element.base.dotted == "ExternalObject":
            continue  # the predefined base of external objects has no elements (12.9.7)
        if entry.defn.kind == "type" and element.base.dotted in PREDEFINED:
            continue  # type Angle extends Real: no components (its functions are members)
        if entry.defn.class_extends and element is entry.defn.elements[0]:
            base = inherited_class(flattener.resolve_class, entry, element.span)
        else:
            base = flattener.resolve_class(element.base, entry.parent or entry, entry)
        if base.defn.short is not None and entry.defn.kind == "type":
            continue  # type T extends Real[4]: no components (its functions are members)
        if base.defn.short is not None:
            raise FlattenError("extending a short class definition is not supported yet",
                               element.span)
        base_view = flattener.view(base, (*seen, entry))
        if element.modification is not None:
            mods.append((element.modification, entry))
        mods.extend(base_view.extends_mods)
        for name, comp in base_view.components.items():
            if element.protected and not comp.decl.protected:  # protected extends
                comp = ViewComponent(replace(comp.decl, protected=True), comp.defined_in)
            _add_component(components, name, comp)
        equations += base_view.equations
        initial += base_view.initial_equations
    for element in entry.defn.elements:
        if isinstance(element, s.Component) and element.redeclare:
            _redeclare_component(components, element, entry)
        elif isinstance(element, s.Component):
            _add_component(components, element.name, ViewComponent(element, entry))
    equations += (ViewEquation(e, entry) for e in entry.defn.equations)
    initial += (ViewEquation(e, entry) for e in entry.defn.initial_equations)
    return ClassView(entry, components, tuple(equations), tuple(initial), tuple(mods))


def _redeclare_component(components: dict[str, ViewComponent], element: s.Component,
                         entry: ClassEntry) -> None:
    """``redeclare Steel part;`` as an element: it replaces the inherited declaration of
    ``part``, which must be replaceable (Modelica 7.3)."""
    existing = components.get(element.name)
    if existing is None:
        raise FlattenError(f"'{element.name}' is redeclared but no inherited element has "
                           "that name", element.span, hint="redeclare an element of a base "
                           "class, or drop `redeclare`")
    check_redeclarable(existing.decl, element.span)
    if not existing.decl.replaceable:
        raise FlattenError(f"'{element.name}' is not replaceable and cannot be redeclared",
                           element.span, [Note("declared here", existing.decl.span)])
    if element.protected != existing.decl.protected:
        was, now = ("protected", "public") if existing.decl.protected else ("public",
                                                                            "protected")
        raise FlattenError(f"the {was} element '{element.name}' cannot be redeclared "
                           f"{now}", element.span, [Note("declared here",
                                                         existing.decl.span)],
                           f"{REDECLARE_RULES} (Modelica 3.6, section 7.3.3)")
    constraint = existing.decl.constraint
    if element.modification is None and constraint is not None and constraint[1] is not None:
        element = replace(element, modification=constraint[1])
    components[element.name] = ViewComponent(element, entry)


#: The restrictions on redeclarations (section 7.3.3), in a help line.
REDECLARE_RULES = ("a constant or final element cannot be redeclared, and a redeclaration "
                   "keeps the element public or protected")


def check_redeclarable(decl: s.Component, span: Span | None) -> None:
    """A ``constant`` or ``final`` component cannot be redeclared (section 7.3.3)."""
    what = "constant" if decl.variability == "constant" else "final" if decl.final else ""
    if what:
        raise FlattenError(f"the {what} element '{decl.name}' cannot be redeclared", span,
                           [Note("declared here", decl.span)],
                           f"{REDECLARE_RULES} (Modelica 3.6, section 7.3.3)")


def _add_component(components: dict[str, ViewComponent], name: str,
                   comp: ViewComponent) -> None:
    existing = components.get(name)
    if existing is None:
        components[name] = comp
    elif not same_text(existing.decl, comp.decl):  # identical copies merge (7.1)
        raise FlattenError(f"'{name}' is declared twice", comp.decl.span,
                           [Note("first declared here", existing.decl.span)],
                           "rename one of the components")


def instance_mod(outer: Mod | None, view: ClassView, scope: ClassScope | None) -> Mod | None:
    """The modification of an instance: the outer one, then its ``extends`` clauses."""
    mods = [outer] + [from_syntax(m, scope) for m, _ in view.extends_mods]
    return merge_all(mods)
