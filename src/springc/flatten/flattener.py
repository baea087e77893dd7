"""Flatten a model: load.ClassTree + model name -> flat.FlatModel.

Instantiates the model's components with their modifications and inheritance,
expands arrays, ``for`` loops and ``if``-equations with parameter conditions, and
turns ``connect`` statements into potential equalities and flow sums.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from typing import cast

import numpy as np

from ..collector import collector_paused
from ..errors import ErrorGroup, FlattenError, FollowUpError, Span, SpringcError
from ..ir import expr as x
from ..ir import flat
from ..ir.when import When
from ..parse import ClassEntry, ClassTree
from .calls import check_conditions, undefined_strings, unique
from .connect import ConnectionSets, apply_cardinalities, check_connector_size
from .equations import EquationFlattening
from .evaluate import Evaluator
from .events import Section, apply_starts, check_events
from .experiment import experiment_of
from .instance_templates import InstanceTemplates
from .instantiate import Instantiation
from .names import ClassLookup, select_model
from .overdetermined import solve_graph
from .redeclare import check_redeclarations
from .scopes import (
    DEFAULT_MAX_SIZE,
    ClassScope,
    ClassView,
    ExpressionEvaluator,
    Ident,
    Limits,
    ParameterValues,
    Primitive,
    attributes_of,
    binding_errors,
    instance_mod,
    max_size_setting,
    merge_all,
)

__all__ = ["Flattener", "flatten"]


class Flattener(ClassLookup, Instantiation, EquationFlattening):
    """One flattening run over a class tree: the caches and results of the run, and
    the walk over instances. Class lookup (``lookup.py``), instantiation
    (``instantiate.py``) and equations (``equations.py``) are mixed in."""

    def __init__(self, tree: ClassTree, max_size: int = DEFAULT_MAX_SIZE) -> None:
        self.tree = tree
        self.limits = Limits(max_size)
        self.views: dict[ClassEntry, ClassView] = {}
        self.package_scopes: dict[ClassEntry, ClassScope] = {}
        self.rule_errors: dict[ClassEntry, FlattenError] = {}
        self.parameter_values = ParameterValues()
        evaluator = Evaluator(self)
        self.evaluator: ExpressionEvaluator = evaluator
        self.connections = ConnectionSets()
        evaluator.graph = self.connections.graph
        self.deferred_ifs = []
        self.equations: list[flat.Equation] = []
        self.initial_equations: list[flat.Equation] = []
        self.whens: list[When] = []
        self.assertions: list[tuple[flat.Assertion, Span]] = []
        self.warnings: list[str] = []
        self.algorithm_sections: list[Section] = []
        self.statement_conditions: list[tuple[x.Expr, Span]] = []
        self.parameter_decisions = 0
        self.evaluated: set[str] = set()
        self.errors: list[SpringcError] = []
        self.mod_values = {}
        self.declared_types = {}
        self.attribute_cache = {}
        self.reusable_views = {}
        self.templates = {}
        self.instance_templates = InstanceTemplates(self)
        self.written_in: ClassEntry | None = None

    # ----------------------------------------------------------------- queries

    def is_parameter_expression(self, e: x.Expr) -> bool:
        bindings = self.parameter_values.bindings
        return all(n in bindings for n in x.variables(e)) and not any(
            isinstance(n, (x.Der, x.Time)) for n in x.walk(e))

    # --------------------------------------------------------------- the model

    def report(self, err: FlattenError) -> None:
        """Record an error and go on; a follow-up error records its original, once."""
        original = err.original if isinstance(err, FollowUpError) else err
        if all(e is not original for e in self.errors):
            self.errors.append(original)

    def walk(self, scope: ClassScope) -> Iterator[ClassScope]:
        """Every class instance below ``scope`` (depth first, declaration order);
        a component that cannot be instantiated is reported and skipped."""
        for name, comp in scope.view.components.items():
            try:
                member = scope.member(name)
                if comp.decl.outer and comp.decl.inner:
                    member = scope.inner_part(name)  # the outer part is walked elsewhere
            except FlattenError as err:
                self.report(err)
                continue
            if comp.decl.outer and not comp.decl.inner:
                continue  # the inner instance is walked where it is declared
            if isinstance(member, ClassScope):
                yield from self._walk_one(member)
            elif isinstance(member, np.ndarray):
                for item in member.flat:
                    yield from self._walk_one(item)

    def _walk_one(self, scope: ClassScope) -> Iterator[ClassScope]:
        recording = self.instance_templates.begin(scope)  # may fill scope's members
        yield from self.walk(scope)
        if recording is not None:
            self.instance_templates.finish(recording)
        yield scope

    def walk_added(self, top: ClassScope) -> Iterator[ClassScope]:
        """The instances below the inner elements added for outer ones without
        (``ClassScope.added_inners``), and those they add in turn."""
        done = 0
        while done < len(top.added_inners):
            added = list(top.added_inners.values())[done][0]
            done += 1
            for item in (added.flat if isinstance(added, np.ndarray) else [added]):
                if isinstance(item, ClassScope):
                    yield from self._walk_one(item)

    def variables(self, scope: ClassScope) -> Iterator[flat.Variable]:
        for _name, member in scope.all_members():
            if isinstance(member, Primitive):
                if member.type == "String":
                    self.errors += undefined_strings(member.value)
                elif member.variability != "constant":
                    yield from attributes_of(self, scope, member)
            else:
                for item in (member.flat if isinstance(member, np.ndarray) else [member]):
                    if item.template is not None:
                        yield from self.instance_templates.variables(item)
                    else:
                        yield from self.variables(item)

    def augmented_variables(self, known: tuple[flat.Variable, ...]
                            ) -> Iterator[flat.Variable]:
        """The variables connections added to expandable connectors (9.1.3) that an
        instance copied from a template does not list (its template has no record of
        them)."""
        names = {v.name for v in known}
        for bus in self.connections.augmented_buses:
            for name in bus.augmented:
                member = bus.member(name)
                found = attributes_of(self, bus, member) if isinstance(member, Primitive) \
                    else self.variables(member) if isinstance(member, ClassScope) else ()
                for v in found:
                    if v.name not in names:
                        names.add(v.name)
                        yield v


def flatten(tree: ClassTree, model: str | None = None, max_size: int | None = None
            ) -> flat.FlatModel:
    """Flatten ``model`` (a dotted name; default: the last model of the last user file).

    ``max_size`` caps the scalar variables of the flat model and the iterations of its
    loops (default: ``$SPRINGC_MAX_SIZE``, else 2 million; see :mod:`.limits`)."""
    cap = max_size_setting(max_size)
    with collector_paused():
        return _flatten(tree, model, cap)


def _flatten(tree: ClassTree, model: str | None, max_size: int) -> flat.FlatModel:
    entry = select_model(tree, model)
    flattener = Flattener(tree, max_size)
    base, mods = flattener.follow_short(entry)
    if base.defn.partial:
        raise FlattenError(f"'{entry.full_name}' is partial and cannot be simulated",
                           entry.defn.span, hint="simulate a model that extends it")
    view = flattener.view(base)
    top = ClassScope(flattener, "", view, None, entry.defn.span)
    top.mod = instance_mod(merge_all(mods), view, top)
    check_redeclarations(flattener, view, top.mod)
    scopes = [top]
    try:
        scopes = [*flattener.walk(top), *flattener.walk_added(top), top]
        overdetermined: dict[Ident[ClassView], dict[str, int]] = {}  # by connector class
        for scope in scopes:
            check_connector_size(scope, overdetermined)
        for scope in scopes:
            flattener.equations_of(scope)
        solve_graph(flattener)
        for scope in scopes:
            flattener.equations_of(scope, initial=True)
        if cast(Evaluator, flattener.evaluator).cardinality_used:
            apply_cardinalities(flattener, flattener.connections.counts)
        if not flattener.errors:
            variables = tuple(flattener.variables(top))
            variables += tuple(flattener.augmented_variables(variables))
            flattener.errors += binding_errors(variables, flattener.parameter_values)
            check_events(flattener, variables)
            apply_starts(flattener, flattener.algorithm_sections, variables)
            flattener.errors += check_conditions(flattener.assertions, variables,
                                                 flattener.statement_conditions)
    except FlattenError as err:
        flattener.report(err)
    if flattener.errors:
        errs = flattener.errors
        raise errs[0] if len(errs) == 1 else ErrorGroup(errs)
    flat_model = flat.FlatModel(entry.full_name, variables, tuple(flattener.equations),
                                tuple(flattener.initial_equations),
                                experiment_of(flattener, entry, top), entry.defn.span,
                                notes=(*tree.notes, *added_inner_notes(top),
                                       *flattener.warnings),
                                whens=tuple(flattener.whens),
                                assertions=unique(flattener.assertions),
                                evaluated=tuple(sorted(flattener.evaluated)))
    # the variables of expandable connectors that are not present (9.1.3)
    gone = flattener.connections.absent(scopes, flat_model)
    connected = flattener.connections.equations(scopes, top, gone)
    return replace(flat_model, variables=tuple(v for v in variables if v.name not in gone),
                   equations=(*flat_model.equations, *connected))


def added_inner_notes(top: ClassScope) -> Iterator[str]:
    """The diagnostics of the inner elements added for outer ones (section 5.4)."""
    for name, (_, outer) in top.added_inners.items():
        where = f"{outer.decl.span}: " if outer.decl.span is not None else ""
        yield (f"{where}warning: the outer element '{name}' has no inner element: "
               f"`inner {outer.decl.type_name.dotted} {name}` is added at the top of the "
               "model (Modelica 3.6, section 5.4)")

