"""Instances of classes while flattening: scopes, members and primitive variables.

A :class:`ClassScope` is one instantiated component (or the simulated model itself):
its flat prefix, its class, the modification that applies to it, and its members,
created on first use so that parameters needed for array sizes are evaluated in
dependency order. Inheritance is resolved once per class into a :class:`ClassView`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import FlattenError, FollowUpError, Note
from ..ir import syntax as s
from ..parse import ClassEntry
from .modification import Mod, from_syntax, merge_all

if TYPE_CHECKING:
    from .flattener import Flattener

PRIMITIVES = frozenset({"Real", "Integer", "Boolean"})
UNSUPPORTED_TYPES = {"String": "`String` variables", "StateSelect": None}


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


@dataclass(eq=False)
class ClassScope:
    """One instance of a class; ``prefix`` is its flat name (``""`` for the model)."""

    flattener: Flattener
    prefix: str
    view: ClassView
    mod: Mod | None
    span: s.Span
    outer: ClassScope | None = None
    members: dict[str, Any] = field(default_factory=dict)
    in_progress: dict[str, None] = field(default_factory=dict)  # ordered: a chain
    failed: dict[str, FlattenError] = field(default_factory=dict)
    template: Any = None  # the InstanceTemplate this instance was copied from, if any

    @property
    def entry(self) -> ClassEntry:
        return self.view.entry

    @property
    def kind(self) -> str:
        return self.view.entry.defn.kind

    def flat_name(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def has_member(self, name: str) -> bool:
        return name in self.view.components

    def member(self, name: str, span: s.Span | None = None) -> Any:
        """The member ``name``, instantiating it on first use."""
        found = self.members.get(name)
        if found is not None:
            return found
        if name in self.failed:
            raise FollowUpError(self.failed[name])
        if name in self.in_progress:
            decl = self.view.components[name].decl
            chain = [*list(self.in_progress)[list(self.in_progress).index(name):], name]
            raise FlattenError(f"'{self.flat_name(name)}' is defined in terms of itself: "
                               + " -> ".join(self.flat_name(n) for n in chain),
                               span or decl.span, [Note("declared here", decl.span)],
                               "break the cycle in the bindings or array sizes")
        self.in_progress[name] = None
        try:
            created = self.flattener.instantiate(self, self.view.components[name])
        except FlattenError as err:
            self.failed[name] = err.original if isinstance(err, FollowUpError) else err
            raise
        finally:
            self.in_progress.pop(name, None)
        self.members[name] = created
        return created

    def all_members(self) -> Iterator[tuple[str, Any]]:
        for name in self.view.components:
            yield name, self.member(name)

    def lookup(self, name: str, span: s.Span) -> Any:
        if name in self.view.components:
            return self.member(name, span)
        return self.flattener.lookup_global(name, self.entry, span)


@dataclass(eq=False)
class LocalScope:
    """Loop indices (or function variables) over an enclosing scope."""

    names: dict[str, Any]
    parent: Any

    @property
    def entry(self) -> ClassEntry:
        return self.parent.entry

    def lookup(self, name: str, span: s.Span) -> Any:
        if name in self.names:
            return self.names[name]
        return self.parent.lookup(name, span)


def build_view(entry: ClassEntry, flattener: Flattener, seen: tuple[ClassEntry, ...] = ()
               ) -> ClassView:
    """Resolve ``extends`` clauses: base elements first, then the class's own."""
    if entry in seen:
        raise FlattenError(f"class '{entry.full_name}' extends itself", entry.defn.span)
    components: dict[str, ViewComponent] = {}
    equations: list[ViewEquation] = []
    initial: list[ViewEquation] = []
    mods: list[tuple[s.Modification, ClassEntry]] = []
    for element in entry.defn.elements:
        if not isinstance(element, s.Extends):
            continue
        base = flattener.resolve_class(element.base, entry.parent or entry, entry)
        if base.defn.short is not None:
            raise FlattenError("extending a short class definition is not supported yet",
                               element.span)
        base_view = flattener.view(base, (*seen, entry))
        if element.modification is not None:
            mods.append((element.modification, entry))
        mods.extend(base_view.extends_mods)
        for name, comp in base_view.components.items():
            _add_component(components, name, comp)
        equations += base_view.equations
        initial += base_view.initial_equations
    for element in entry.defn.elements:
        if isinstance(element, s.Component):
            _add_component(components, element.name, ViewComponent(element, entry))
    equations += (ViewEquation(e, entry) for e in entry.defn.equations)
    initial += (ViewEquation(e, entry) for e in entry.defn.initial_equations)
    return ClassView(entry, components, tuple(equations), tuple(initial), tuple(mods))


def _add_component(components: dict[str, ViewComponent], name: str,
                   comp: ViewComponent) -> None:
    existing = components.get(name)
    if existing is None:
        components[name] = comp
    elif existing.decl != comp.decl:
        raise FlattenError(f"'{name}' is declared twice", comp.decl.span,
                           [Note("first declared here", existing.decl.span)],
                           "rename one of the components")


def instance_mod(outer: Mod | None, view: ClassView, scope: ClassScope | None) -> Mod | None:
    """The modification of an instance: the outer one, then its ``extends`` clauses."""
    mods = [outer] + [from_syntax(m, scope) for m, _ in view.extends_mods]
    return merge_all(mods)
