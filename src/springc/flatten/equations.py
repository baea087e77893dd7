"""Equation sections while flattening, as methods of :class:`~springc.flatten.Flattener`.

Input: the equations of an instance's class (equalities, ``for`` loops, ``if``-equations
with parameter conditions, ``connect`` statements). Output: scalar flat equations
appended to the Flattener's lists, and connections recorded in its connection sets.
"""

from __future__ import annotations

import numpy as np

from ..errors import FlattenError
from ..ir import expr as x
from ..ir import flat
from ..ir import syntax as s
from ..parse import ClassEntry
from . import arrays as a
from .array_ops import check_loop_nest, with_range
from .calls import assertion, call_for_effect, multiple_outputs, string_equation
from .checks import check_boolean_condition
from .connect import GRAPH_EQUATIONS, ConnectionSets, misplaced, operator_nodes, uses_graph
from .equation_templates import Template, make_template, reusable
from .events import (
    EVENT_EQUATIONS,
    Section,
    algorithm_section,
    event_dependent,
    flatten_when,
    variable_if_equation,
)
from .redeclare import record_equation
from .scopes import ClassScope, ClassView, FlattenContext, Ident, LocalScope, Primitive, Scope


class EquationFlattening(FlattenContext):
    """Equation flattening; mixed into the Flattener, which provides the lists."""

    connections: ConnectionSets
    # Equation templates by (the ClassView, initial); None: not reusable.
    templates: dict[tuple[Ident[ClassView], bool], Template | None]
    reusable_views: dict[Ident[ClassView], bool]  # whether a view's equations are a template
    algorithm_sections: list[Section]
    written_in: ClassEntry | None
    # if-equations on Connections.isRoot/rooted, flattened once the graph is solved
    deferred_ifs: list[tuple[s.IfEquation, Scope, ClassScope, bool, ClassEntry | None]]

    def equations_of(self, scope: ClassScope, initial: bool = False) -> None:
        """The equations of one instance; from the class's template when it has one."""
        view = scope.view
        items = view.initial_equations if initial else view.equations
        if not items:
            return
        target = self.initial_equations if initial else self.equations
        key = (Ident(view), initial)
        # an instance with evaluated parameters (Evaluate = true, or final and bound to
        # those) has its own folded equations: no template for it, none from it
        shared = scope.package is None and not _evaluated_members(scope)
        template = self.templates.get(key) if shared else None
        if template is not None:
            target += template.instantiate(scope.prefix)
            return
        start, errors, reads = len(target), len(self.errors), self.parameter_values.reads
        deferred = len(self.deferred_ifs)
        for item in items:
            self.written_in = item.defined_in
            try:
                self.equation(item.equation, scope, scope, initial)
            except FlattenError as err:
                self.report(err)
            finally:
                self.written_in = None
        if key not in self.templates and scope.prefix and len(self.errors) == errors \
                and shared and len(self.deferred_ifs) == deferred:
            independent = self.parameter_values.reads == reads \
                and reusable(self, view, self.reusable_views)
            self.templates[key] = make_template(scope.prefix, target[start:]) \
                if independent else None

    def equation(self, eq: s.Equation, where: Scope, owner: ClassScope, initial: bool) -> None:
        if isinstance(eq, s.Equality):
            self._equality(eq, where, owner, initial)
        elif isinstance(eq, s.Connect):
            if initial:
                raise FlattenError("`connect` is not allowed in an initial equation section",
                                   eq.span)
            self.connections.connect(self.evaluator, eq, where, owner)
        elif isinstance(eq, s.ForEquation):
            if not isinstance(where, LocalScope):  # the outermost loop of a nest
                check_loop_nest(self.evaluator, eq, where)
            self._for(eq, eq.indices, where, owner, initial)
        elif isinstance(eq, s.WhenEquation):
            flatten_when(self, eq, where, owner, initial)
        elif isinstance(eq, s.IfEquation):
            if not self.connections.graph.solved \
                    and uses_graph(tuple(c for c, _ in eq.branches)):
                # on Connections.isRoot/rooted: once every connection is known
                self.deferred_ifs.append((eq, where, owner, initial, self.written_in))
                return
            for cond, body in eq.branches:  # in order, up to the first true (8.3.4)
                if self._variable_condition(cond, where):
                    variable_if_equation(self, eq, where, owner, initial)
                    return
                if self._if_condition(cond, where):
                    self._body(body, where, owner, initial)
                    return
            self._body(eq.otherwise, where, owner, initial)
        elif isinstance(eq, s.AlgorithmSection):
            self.algorithm_sections.append(
                algorithm_section(self, eq, where, owner, initial))
        elif eq.call.func.dotted in EVENT_EQUATIONS:
            name = eq.call.func.dotted
            raise FlattenError(f"{name}(...) is only allowed inside a when-clause", eq.span,
                               hint=f"write 'when condition then {name}(...); end when;'")
        elif eq.call.func.dotted in GRAPH_EQUATIONS:
            if initial:
                raise misplaced(eq.call, "an initial equation section")
            nodes, priority = operator_nodes(self.evaluator, eq.call, where)
            self.connections.graph.operator(eq.call, nodes, priority)
        elif eq.call.func.dotted == "assert":
            kind = "initial" if initial else "equation"
            self.assertions.append(
                assertion(self.evaluator, eq.call, where, flat.Origin(kind, owner.prefix)))
        else:
            call_for_effect(self.evaluator, eq.call, where, "an equation")

    def _variable_condition(self, cond: s.Expr, where: Scope) -> bool:
        """Whether an if-equation condition depends on variables (then the branches
        switch at events: flatten/events/when.py)."""
        value = self.evaluator.value(cond, where)
        return isinstance(value, (x.BinOp, x.Var, x.Not, x.Call, x.If)) and (
            not self.is_parameter_expression(value) or event_dependent(value)
            or self._unknown_until_initialized(value))

    def _unknown_until_initialized(self, value: x.Expr) -> bool:
        """Whether ``value`` reads a parameter with no value while flattening (``fixed =
        false``, section 8.6: the initialization computes it): the if-equation then
        switches at run time, its branches the same size (8.3.4), as Dymola and
        OpenModelica do (Electrical.Analog.Sources.DCPowerSupply's ``cp``)."""
        bindings = self.parameter_values.bindings
        return any(bindings.get(n, x.ZERO) is None for n in x.variables(value))

    def _if_condition(self, cond: s.Expr, where: Scope) -> bool:
        """The value of an if-equation condition, which must be a parameter expression
        (a condition on variables would switch equations at events)."""
        self.evaluator.no_event += 1
        try:
            value = self.evaluator.constant(
                cond, where, "the condition of an if-equation",
                "switching equations on a variable needs events, which are not supported "
                "yet; for a continuous switch write one equation with an if-expression "
                "inside noEvent(...)")
        finally:
            self.evaluator.no_event -= 1
        check_boolean_condition(value, cond.span, "the condition of an if-equation")
        if not isinstance(value, bool | int | float | np.bool_):
            kind = "a string" if isinstance(value, str) else "an array"
            raise FlattenError(f"the condition of an if-equation must be a scalar Boolean, "
                               f"found {kind}", cond.span)
        return bool(value)

    def _body(self, body: tuple[s.Equation, ...], where: Scope, owner: ClassScope,
              initial: bool) -> None:
        for eq in body:
            self.equation(eq, where, owner, initial)

    def _for(self, eq: s.ForEquation, indices: tuple[s.ForIndex, ...], where: Scope,
             owner: ClassScope, initial: bool) -> None:
        index, rest = with_range(self.evaluator, indices[0], eq.body, where), indices[1:]
        values = self.evaluator.range_values(index, where)
        self.limits.add_iterations(len(values), index.span)
        for value in values:
            local = LocalScope({index.name: value}, where)
            if rest:
                self._for(eq, rest, local, owner, initial)
            else:
                self._body(eq.body, local, owner, initial)

    def _equality(self, eq: s.Equality, where: Scope, owner: ClassScope, initial: bool) -> None:
        fields = record_equation(self, eq, where)
        if fields is not None:
            for field in fields:
                self._equality(field, where, owner, initial)
            return
        if isinstance(eq.lhs, s.Tuple):
            outputs = multiple_outputs(self.evaluator, eq.lhs.items, eq.rhs, where)
            for item, value in zip(eq.lhs.items, outputs):
                if item is not None:
                    self._sides(eq, self.evaluator.value(item, where), value, owner, initial)
            return
        lhs = self.evaluator.value(eq.lhs, where)
        rhs = self.evaluator.value(eq.rhs, where)
        self._sides(eq, lhs, rhs, owner, initial)

    def _sides(self, eq: s.Equality, lhs: a.Value, rhs: a.Value, owner: ClassScope,
               initial: bool) -> None:
        if a.shape(lhs) != a.shape(rhs):
            raise FlattenError(
                f"the two sides of this equation differ in size: "
                f"{a.describe_shape(a.shape(lhs))} and {a.describe_shape(a.shape(rhs))}",
                eq.span, hint="both sides of an equation must have the same size")
        if string_equation(lhs, rhs, eq.span):
            return  # known while flattening (flatten/calls/strings.py)
        for side, e in ((lhs, eq.lhs), (rhs, eq.rhs)):
            if isinstance(side, str):
                raise FlattenError("strings cannot appear in equations", e.span)
        origin = flat.Origin("initial" if initial else "equation", owner.prefix)
        target = self.initial_equations if initial else self.equations
        for left, right in zip(a.scalars(lhs), a.scalars(rhs)):
            target.append(flat.Equation(left, right, eq.span, origin))


def _evaluated_members(scope: ClassScope) -> bool:
    """Whether a parameter of ``scope`` was folded into a constant (18.3)."""
    return any(isinstance(m, Primitive) and m.variability == "constant"
               and m.decl.variability == "parameter" for m in scope.members.values())
