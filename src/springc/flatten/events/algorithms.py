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

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np

from ...errors import FlattenError, Span, SpringcError
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from .. import arrays as a
from ..array_ops import check_loop_nest, with_range
from ..calls import (
    Jumped,
    assertion,
    branch_jumps,
    call_for_effect,
    check_jumps,
    folded,
    guard_assertions,
    is_string,
    multiple_outputs,
    run_loop_body,
    run_while,
    stray,
    string_equation,
    without_events,
)
from ..connect import GRAPH_EQUATIONS, misplaced
from ..natives import skipped_call
from ..scopes import ClassScope, FlatResults, FlattenContext, LocalScope, Scope
from .loop_break import (
    BROKEN_TERMS,
    FALSE,
    TRUE,
    choose,
    kept,
    too_large,
)
from .section_starts import known_starts
from .when_statements import (
    WhenParts,
    check_nesting,
    check_place,
    reads_before_assignment,
    terminate_of,
    when_statement,
)


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
        self.context: list[str] = []  # the loops, variable ifs and whens around
        self.held: set[str] = set()  # assigned in when statements (discrete)
        self.parts: list[WhenParts] = []  # of the when statements around
        # where a break under a condition known only during the simulation has left
        # the innermost for loop: the statements after it hold their values there
        self.broken: x.Expr = FALSE
        self.body: tuple[s.Statement, ...] = ()  # the section's statements
        self.starts: dict[str, x.Const] | None = None  # see while_condition
        # each when statement's index in the flattener's list and the names when
        # statements had assigned before it (reads_before_assignment)
        self.whens: list[tuple[int, frozenset[str]]] = []

    def read(self, value: a.Value, span: Span) -> a.Value:
        if is_string(value):
            return value  # known while flattening (flatten/calls/strings.py)
        env = self.env
        return a.elementwise(lambda e: folded(x.substitute_at_event(e, env)) if env else e,
                             value)

    def guard_new(self, start: int, guard: x.Expr | None) -> None:
        """Make the assertions of inlined functions recorded since ``start`` hold
        where ``guard`` is false (they are evaluated only where it is true)."""
        if guard is not None:
            guard_assertions(self.fl.assertions, start, guard)

    def run(self, body: tuple[s.Statement, ...], where: Scope, guard: x.Expr | None) -> None:
        for stmt in body:
            start = len(self.fl.assertions)
            broken = self.broken
            if broken == FALSE:
                self.statement(stmt, where, guard)
            else:  # runs only where the loop was not left
                before, self.broken = dict(self.env), FALSE
                try:
                    self.statement(stmt, where, _and(guard, x.Not(broken)))
                finally:
                    for name, value in self.env.items():
                        old = before.get(name, x.Var(name))
                        if value is not old:
                            self.env[name] = kept(broken, old, value)
                    inner = self.broken
                    self.broken = broken if inner == FALSE else TRUE if inner == TRUE \
                        else x.BinOp("or", broken, inner)
            if not isinstance(stmt, s.IfStatement):
                self.guard_new(start, guard if broken == FALSE
                               else _and(guard, x.Not(broken)))

    def statement(self, stmt: s.Statement, where: Scope, guard: x.Expr | None) -> None:
        if isinstance(stmt, s.Assign):
            self.assign(stmt, where)
        elif isinstance(stmt, s.IfStatement):
            self.if_(stmt.branches, stmt.otherwise, where, guard)
        elif isinstance(stmt, s.ForStatement):
            self.for_(stmt, stmt.indices, where, guard)
        elif isinstance(stmt, s.WhileStatement):
            self.context.append("while")
            try:
                run_while(self.ev, stmt, lambda: self.while_condition(stmt, where),
                          lambda: self.run(stmt.body, where, guard))
            finally:
                self.context.pop()
        elif isinstance(stmt, s.WhenStatement):
            self.when(stmt, where, guard)
        elif isinstance(stmt, s.Jump):
            raise Jumped(stmt)
        else:
            self.call(stmt, where, guard)

    def while_condition(self, stmt: s.WhileStatement, where: Scope) -> x.Expr:
        """The condition of ``stmt`` now; where it reads variables the section assigns
        but has not assigned yet, their start values (11.1.2, as :func:`apply_starts`
        gives them at the end) are taken at once, so that the loop may be decided
        while flattening."""
        def value() -> x.Expr:
            return folded(cast(x.Expr, self.read(self.ev.scalar(stmt.condition, where),
                                                 stmt.span)))

        cond = value()
        if isinstance(cond, x.Const):
            return cond
        if self.starts is None:
            self.starts = known_starts(self.fl, self.body, where, self.owner)
        seeded = False
        for name in x.variables(cond) - self.env.keys():
            start = self.starts.get(name)
            if start is not None:
                self.env[name] = start
                self.spans.setdefault(name, stmt.span)
                seeded = True
        return value() if seeded else cond

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
        if a.shape(names) != a.shape(value):
            raise FlattenError(
                f"cannot assign a value of size {a.describe_shape(a.shape(value))} to "
                f"'{target.dotted}' of size {a.describe_shape(a.shape(names))}", stmt.span)
        for name, item in zip(a.scalars(names), a.scalars(value)):
            if isinstance(name, x.If):  # a subscript known only during the simulation
                for leaf, chosen in run_time_targets(name, target):
                    # the subscript's value now, as a read of it gives
                    now = cast(x.Expr, self.read(chosen, target.span))
                    self.store_scalar(leaf, x.If(now, item, self.env.get(leaf.name, leaf)),
                                      target, stmt)
                continue
            self.store_scalar(name, item, target, stmt)

    def store_scalar(self, name: x.Expr, item: x.Expr, target: s.Ref, stmt: s.Assign
                     ) -> None:
        bindings = self.fl.parameter_values.bindings
        if not isinstance(name, x.Var) or (name.name in bindings and not (
                self.initial and bindings[name.name] is None)):
            # (an initial algorithm computes parameters without a value: fixed =
            # false, section 8.6; simplify/free_parameters.py binds them)
            raise FlattenError(f"'{target.dotted}' cannot be assigned: it is a "
                               "parameter or constant", target.span,
                               hint="an algorithm section assigns variables only")
        if name.name in self.held and not self.parts:
            raise FlattenError(f"'{name.name}' is assigned both in a when statement "
                               "and outside of it in this algorithm section", stmt.span,
                               hint="a variable a when statement assigns is discrete: "
                               "assign it only in when statements")
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
        before, broken = dict(self.env), self.broken
        span = cond_expr.span
        self.context.append("if")
        try:
            broken_then = self.branch(lambda: self.run(body, where, _and(guard, cond)), span)
            then = self.env
            self.env, self.broken = dict(before), broken
            broken_else = self.branch(
                lambda: self.if_(rest, otherwise, where, _and(guard, x.Not(cond))), span)
        finally:
            self.context.pop()
        self.broken = choose(cond, broken_then, broken_else)
        for name in then.keys() | self.env.keys():
            old = before.get(name, x.Var(name))
            left, right = then.get(name, old), self.env.get(name, old)
            if left is not right:
                self.env[name] = x.If(cond, left, right)
                self.spans.setdefault(name, cond_expr.span)

    def branch(self, run: Callable[[], None], span: Span) -> x.Expr:
        """Run a branch of an if on a run-time condition: where the loop is left after
        it (true if it ends with a ``break`` of the innermost loop, a for loop; a
        ``break`` of a while loop there is not supported)."""
        loops = [k for k in self.context if k in ("for", "while")]
        if not loops or loops[-1] != "for":
            branch_jumps(run, span)
            return self.broken
        try:
            run()
        except Jumped as jumped:
            if jumped.jump.kind != "break":
                raise
            return TRUE
        return self.broken

    def for_(self, stmt: s.ForStatement, indices: tuple[s.ForIndex, ...], where: Scope,
             guard: x.Expr | None) -> None:
        index, rest = with_range(self.ev, indices[0], stmt.body, where), indices[1:]
        values = self.ev.range_values(index, where)
        self.fl.limits.add_iterations(len(values), index.span)
        self.context.append("for")
        try:
            self._iterations(stmt, values, index, rest, where, guard)
        finally:
            self.context.pop()

    def _iterations(self, stmt: s.ForStatement, values: Sequence[x.Expr | str],
                    index: s.ForIndex,
                    rest: tuple[s.ForIndex, ...], where: Scope, guard: x.Expr | None
                    ) -> None:
        outer, self.broken = self.broken, FALSE
        try:
            for value in values:
                if self.broken != FALSE and too_large(self.env.values()):
                    raise FlattenError(
                        "the values of a for loop left by a break under a condition known "
                        f"only during the simulation grow beyond {BROKEN_TERMS} terms",
                        index.span, hint="springc unrolls such a loop into if-expressions, "
                        "each iteration after the break nesting them deeper; shorten the "
                        "loop's range or compute the value with equations")
                local = LocalScope({index.name: value}, where)
                if rest:
                    self.for_(stmt, rest, local, guard)
                elif not run_loop_body(lambda: self.run(stmt.body, local, guard)):  # noqa: B023
                    break
                if self.broken == TRUE:
                    break
        finally:
            self.broken = outer

    def when(self, stmt: s.WhenStatement, where: Scope, guard: x.Expr | None) -> None:
        check_place(stmt, self.context, self.initial)

        def branch(body: tuple[s.Statement, ...], parts: WhenParts
                   ) -> dict[str, tuple[x.Expr, Span]]:
            before, spans = self.env, dict(self.spans)
            self.env = dict(before)
            self.context.append("when")
            self.parts.append(parts)
            try:
                self.run(body, where, guard)
                # the body runs at the when's events only: its relations are taken
                # literally there (no crossing, no held value: a function it calls
                # may read a variable the body has just assigned, TimeTable's last)
                return {n: (without_events(v), self.spans[n])
                        for n, v in self.env.items() if before.get(n) is not v}
            finally:
                self.context.pop()
                self.parts.pop()
                self.env, self.spans = before, spans

        self.whens.append((len(self.fl.whens), frozenset(self.held)))
        self.fl.whens.append(when_statement(
            self.ev, stmt, where, self.env, self.held,
            lambda v, span: self.read(cast(a.Value, v), span), branch, self.owner.prefix))

    def call(self, stmt: s.CallStatement, where: Scope, guard: x.Expr | None) -> None:
        name = stmt.call.func.dotted
        if name in GRAPH_EQUATIONS:
            raise misplaced(stmt.call, "an algorithm section")
        if name == "terminate" and self.parts:
            self.parts[-1].terminates.append(terminate_of(self.ev, stmt, where))
            return
        if name != "assert":
            start = len(self.fl.assertions)
            try:
                call_for_effect(self.ev, stmt.call, where, "a statement")
            except SpringcError as refused:  # springc writes no file a model names
                warning = skipped_call(refused, stmt.call)
                if warning is None:
                    raise
                del self.fl.assertions[start:]
                self.fl.warnings.append(warning)
            return
        if self.parts:
            guard = self.parts[-1].guard
            if guard is None:
                raise FlattenError("`assert` inside a when statement is not supported "
                                   "yet, unless the condition is initial() or terminal()",
                                   stmt.span, hint="springc supports a subset of Modelica; "
                                   "see \"Not supported yet\" in docs/language.md")
        origin = flat.Origin("algorithm", self.owner.prefix)
        item, span = assertion(self.ev, stmt.call, where, origin, guard,
                               lambda v: self.read(v, stmt.span))
        condition = cast(x.Expr, self.read(item.condition, span))
        self.fl.assertions.append((_with_condition(item, condition), span))


def run_time_targets(names: x.Expr, target: s.Ref) -> list[tuple[x.Var, x.Expr]]:
    """The elements a subscript known only during the simulation may name, each with
    the condition that selects it: ``names`` is the if-expression that reading
    ``target`` gives (``if i == 1 then buf[1] elseif ... else buf[n]``); the last
    element is chosen by ``i == n``, so that an index out of range assigns none."""
    found: list[tuple[x.Var, x.Expr]] = []
    pending: list[tuple[x.Expr, x.Expr | None]] = [(names, None)]
    while pending:  # along a chain without recursion: a subscript may range over 4000
        e, path = pending.pop()
        if isinstance(e, x.Var):
            found.append((e, path if path is not None else x.Const(True)))
            continue
        if not (isinstance(e, x.If) and _index_test(e.cond)):
            raise FlattenError(f"'{target.dotted}' cannot be assigned: it is a "
                               "parameter or constant", target.span,
                               hint="an algorithm section assigns variables only")
        while True:
            test = cast(x.BinOp, e.cond)
            pending.append((e.then, _and(path, test)))
            rest = e.otherwise
            if isinstance(rest, x.If) and _index_test(rest.cond) \
                    and cast(x.BinOp, rest.cond).left == test.left:
                e = rest  # the same subscript's next element
                continue
            # the last element (or an inner subscript's chain)
            last = x.Const(cast(x.Const, test.right).value + 1)
            pending.append((rest, _and(path, x.BinOp("==", test.left, last))))
            break
    found.reverse()  # in the order of the elements
    return found


def _index_test(cond: x.Expr) -> bool:
    """Whether ``cond`` is ``i == k`` with ``k`` an Integer, as references._selected
    builds it."""
    return isinstance(cond, x.BinOp) and cond.op == "==" \
        and isinstance(cond.right, x.Const) and isinstance(cond.right.value, int) \
        and not isinstance(cond.right.value, bool)


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
    check_nesting(section.body, initial)
    run.body = section.body
    try:
        run.run(section.body, where, None)
    except Jumped as jumped:
        raise stray(jumped) from None
    for index, before in run.whens:
        later = run.held - before
        if later:
            fl.whens[index] = reads_before_assignment(fl.whens[index], later)
    origin = flat.Origin("algorithm", owner.prefix)
    for name, value in run.env.items():
        target.append(flat.Equation(x.Var(name), value, run.spans[name], origin))
    return Section(initial, (eq_start, len(target)), (assert_start, len(fl.assertions)),
                   frozenset(run.env))


def apply_starts(fl: FlatResults, sections: list[Section],
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
