"""Equation sections while flattening, as methods of :class:`~springc.flatten.Flattener`.

Input: the equations of an instance's class (equalities, ``for`` loops, ``if``-equations
with parameter conditions, ``connect`` statements). Output: scalar flat equations
appended to the Flattener's lists, and connections recorded in its connection sets.
"""

from __future__ import annotations

import numpy as np

from ..errors import FlattenError
from ..ir import flat
from ..ir import syntax as s
from . import arrays as a
from .connections import ConnectionSets
from .equation_templates import Template, make_template, reusable
from .loops import check_loop_nest
from .scope import ClassScope, FlattenContext, LocalScope, Scope
from .type_rules import check_boolean_condition


class EquationFlattening(FlattenContext):
    """Equation flattening; mixed into the Flattener, which provides the lists."""

    connections: ConnectionSets
    # Equation templates by (id of the ClassView, initial); None: not reusable.
    templates: dict[tuple[int, bool], Template | None]

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
        elif isinstance(eq, s.IfEquation):
            for cond, body in eq.branches:
                if self._if_condition(cond, where):
                    self._body(body, where, owner, initial)
                    return
            self._body(eq.otherwise, where, owner, initial)
        else:
            name = eq.call.func.dotted
            raise FlattenError(f"`{name}` is not supported yet as an equation", eq.span,
                               hint="springc supports a subset of Modelica; see "
                               "\"Not supported yet\" in docs/language.md")

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
        index, rest = indices[0], indices[1:]
        values = self.evaluator.range_values(index, where)
        self.limits.add_iterations(len(values), index.span)
        for value in values:
            local = LocalScope({index.name: value}, where)
            if rest:
                self._for(eq, rest, local, owner, initial)
            else:
                self._body(eq.body, local, owner, initial)

    def _equality(self, eq: s.Equality, where: Scope, owner: ClassScope, initial: bool) -> None:
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
