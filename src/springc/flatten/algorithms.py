"""``algorithm`` sections of models and blocks while flattening (section 11.1).

Input: an algorithm section (statements: assignments, ``if``, ``for``, ``assert``) and
its instance. Output: one flat equation ``v = e`` per scalar variable ``v`` the section
assigns, where ``e`` is the value the statements leave in ``v``, found by executing
them symbolically as :mod:`.functions` inlines a function: later statements read the
values that earlier ones assigned, an ``if`` on a non-constant condition merges the
branch values with if-expressions, loops over parameter ranges are unrolled. The
section thus counts as many equations as scalars it assigns and is sorted with the
other equations. A variable read before the section assigns it has its start value
(section 11.1.2); as the start values are known only once every variable is, those
reads are replaced at the end of flattening (:func:`apply_starts`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

from ..errors import FlattenError, Span
from ..ir import expr as x
from ..ir import flat
from ..ir import syntax as s
from . import arrays as a
from .assertions import assertion, guard_assertions
from .connection_graph import GRAPH_EQUATIONS, misplaced
from .control import (
    Jumped,
    branch_jumps,
    check_jumps,
    folded,
    run_loop_body,
    run_while,
    stray,
)
from .functions import call_for_effect, multiple_outputs
from .loops import check_loop_nest
from .ranges import with_range
from .scope import ClassScope, FlattenContext, LocalScope, Scope
from .strings import is_string, string_equation


@dataclass(frozen=True)
class Section:
    """The equations and assertions one section added (slices of the flattener's
    lists) and the names it assigns, for :func:`apply_starts`."""

    initial: bool
    equations: tuple[int, int]
    assertions: tuple[int, int]
    assigned: frozenset[str]


class _Run:
    """One execution of a section: ``env`` holds the value each assigned variable has
    so far (an expression of the model's variables), ``spans`` the last assignment."""

    def __init__(self, fl: FlattenContext, owner: ClassScope, initial: bool) -> None:
        self.fl, self.ev, self.owner, self.initial = fl, fl.evaluator, owner, initial
        self.env: dict[str, x.Expr] = {}
        self.spans: dict[str, Span] = {}

    def read(self, value: a.Value, span: Span) -> a.Value:
        if is_string(value):
            return value  # known while flattening (flatten/strings.py)
        env = self.env
        return a.elementwise(lambda e: folded(x.substitute(e, env)) if env else e, value)

    def guard_new(self, start: int, guard: x.Expr | None) -> None:
        """Make the assertions of inlined functions recorded since ``start`` hold
        where ``guard`` is false (they are evaluated only where it is true)."""
        if guard is not None:
            guard_assertions(self.fl.assertions, start, guard)

    def run(self, body: tuple[s.Statement, ...], where: Scope, guard: x.Expr | None) -> None:
        for stmt in body:
            start = len(self.fl.assertions)
            self.statement(stmt, where, guard)
            if not isinstance(stmt, s.IfStatement):
                self.guard_new(start, guard)

    def statement(self, stmt: s.Statement, where: Scope, guard: x.Expr | None) -> None:
        if isinstance(stmt, s.Assign):
            self.assign(stmt, where)
        elif isinstance(stmt, s.IfStatement):
            self.if_(stmt.branches, stmt.otherwise, where, guard)
        elif isinstance(stmt, s.ForStatement):
            self.for_(stmt, stmt.indices, where, guard)
        elif isinstance(stmt, s.WhileStatement):
            run_while(self.ev, stmt,
                      lambda: cast(x.Expr, self.read(self.ev.scalar(stmt.condition, where),
                                                     stmt.span)),
                      lambda: self.run(stmt.body, where, guard))
        elif isinstance(stmt, s.Jump):
            raise Jumped(stmt)
        else:
            self.call(stmt, where, guard)

    def assign(self, stmt: s.Assign, where: Scope) -> None:
        if len(stmt.targets) > 1:
            values = multiple_outputs(self.ev, stmt.targets, stmt.value, where)
            for target, value in zip(stmt.targets, values):
                if target is not None:
                    self.store(target, self.read(value, stmt.value.span), stmt, where)
            return
        target = stmt.targets[0]
        assert target is not None
        self.store(target, self.read(self.ev.value(stmt.value, where), stmt.value.span),
                   stmt, where)

    def store(self, target: s.Ref, value: a.Value, stmt: s.Assign, where: Scope) -> None:
        names = self.ev.value(target, where)
        if string_equation(names, value, stmt.span):
            return
            raise FlattenError(
                f"cannot assign a value of size {a.describe_shape(a.shape(value))} to "
                f"'{target.dotted}' of size {a.describe_shape(a.shape(names))}", stmt.span)
        for name, item in zip(a.scalars(names), a.scalars(value)):
            if not isinstance(name, x.Var) or name.name in self.fl.parameter_values.bindings:
                raise FlattenError(f"'{target.dotted}' cannot be assigned: it is a "
                                   "parameter or constant", target.span,
                                   hint="an algorithm section assigns variables only")
            self.env[name.name] = item
            self.spans[name.name] = stmt.span

    def if_(self, branches: tuple[tuple[s.Expr, tuple[s.Statement, ...]], ...],
            otherwise: tuple[s.Statement, ...], where: Scope, guard: x.Expr | None) -> None:
        if not branches:
            self.run(otherwise, where, guard)
            return
        (cond_expr, body), rest = branches[0], branches[1:]
        start = len(self.fl.assertions)
        cond = self.read(self.ev.scalar(cond_expr, where), cond_expr.span)
        self.guard_new(start, guard)
        assert not isinstance(cond, (str, np.ndarray))
        self.fl.statement_conditions.append((cond, cond_expr.span))
        if isinstance(cond, x.Const):
            if cond.value:
                self.run(body, where, guard)
            else:
                self.if_(rest, otherwise, where, guard)
            return
        before = dict(self.env)
        span = cond_expr.span
        branch_jumps(lambda: self.run(body, where, _and(guard, cond)), span)
        then = self.env
        self.env = dict(before)
        branch_jumps(lambda: self.if_(rest, otherwise, where, _and(guard, x.Not(cond))), span)
        for name in then.keys() | self.env.keys():
            old = before.get(name, x.Var(name))
            left, right = then.get(name, old), self.env.get(name, old)
            if left is not right:
                self.env[name] = x.If(cond, left, right)
                self.spans.setdefault(name, cond_expr.span)

    def for_(self, stmt: s.ForStatement, indices: tuple[s.ForIndex, ...], where: Scope,
             guard: x.Expr | None) -> None:
        index, rest = with_range(self.ev, indices[0], stmt.body, where), indices[1:]
        values = self.ev.range_values(index, where)
        self.fl.limits.add_iterations(len(values), index.span)
        for value in values:
            local = LocalScope({index.name: value}, where)
            if rest:
                self.for_(stmt, rest, local, guard)
            elif not run_loop_body(lambda: self.run(stmt.body, local, guard)):  # noqa: B023
                break

    def call(self, stmt: s.CallStatement, where: Scope, guard: x.Expr | None) -> None:
        if stmt.call.func.dotted in GRAPH_EQUATIONS:
            raise misplaced(stmt.call, "an algorithm section")
        if stmt.call.func.dotted != "assert":
            call_for_effect(self.ev, stmt.call, where, "a statement")
            return
        origin = flat.Origin("algorithm", self.owner.prefix)
        item, span = assertion(self.ev, stmt.call, where, origin, guard,
                               lambda v: self.read(v, stmt.span))
        condition = cast(x.Expr, self.read(item.condition, span))
        self.fl.assertions.append((_with_condition(item, condition), span))


def _and(guard: x.Expr | None, cond: x.Expr) -> x.Expr:
    return cond if guard is None else x.BinOp("and", guard, cond)


def _with_condition(item: flat.Assertion, condition: x.Expr) -> flat.Assertion:
    return flat.Assertion(condition, item.message, item.level, item.span, item.origin)


def algorithm_section(fl: FlattenContext, section: s.AlgorithmSection, where: Scope,
                      owner: ClassScope, initial: bool) -> Section:
    """Flatten one section into the flattener's lists; the :class:`Section` to pass
    to :func:`apply_starts` once the variables are known."""
    run = _Run(fl, owner, initial)
    target = fl.initial_equations if initial else fl.equations
    eq_start, assert_start = len(target), len(fl.assertions)
    for stmt in section.body:
        if isinstance(stmt, s.ForStatement):
            check_loop_nest(fl.evaluator, stmt, where)
    check_jumps(section.body, in_function=False)
    try:
        run.run(section.body, where, None)
    except Jumped as jumped:
        raise stray(jumped) from None
    origin = flat.Origin("algorithm", owner.prefix)
    for name, value in run.env.items():
        target.append(flat.Equation(x.Var(name), value, run.spans[name], origin))
    return Section(initial, (eq_start, len(target)), (assert_start, len(fl.assertions)),
                   frozenset(run.env))


def apply_starts(fl: FlattenContext, sections: list[Section],
                 variables: tuple[flat.Variable, ...]) -> None:
    """Replace the reads of assigned variables before their assignment (still plain
    variables in the equations of a section) by the variables' start values."""
    by_name = {v.name: v for v in variables}
    for section in sections:
        starts: dict[str, x.Expr] = {}
        for name in section.assigned:
            v = by_name.get(name)
            if v is None:
                continue
            default = x.Const(False) if v.type == "Boolean" else x.ZERO
            starts[name] = v.attributes.start if v.attributes.start is not None else default
        target = fl.initial_equations if section.initial else fl.equations
        lo, hi = section.equations
        for i in range(lo, hi):
            eq = target[i]
            rhs = x.substitute(eq.rhs, starts)
            if rhs is not eq.rhs:
                target[i] = flat.Equation(eq.lhs, rhs, eq.span, eq.origin)
        lo, hi = section.assertions
        for i in range(lo, hi):
            item, span = fl.assertions[i]
            fl.assertions[i] = (_with_condition(item, x.substitute(item.condition, starts)),
                                span)
