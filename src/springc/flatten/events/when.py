"""When-equations and if-equations with variable conditions, while flattening.

Input: a ``when`` equation (or an ``if`` equation whose condition is not a parameter
expression) of an instance; output: a :class:`springc.ir.when.When` appended to the
flattener's ``whens`` (or scalar equations whose sides are if-expressions).
:func:`check_events` runs once the whole model is flat: the checks that need every
variable (``pre`` of a continuous variable outside a when-clause, Boolean
when-conditions, reinit of a variable that is not Real).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

from ...errors import FlattenError, Note, Span
from ...ir import expr as x
from ...ir import flat
from ...ir import syntax as s
from ...ir import when as w
from ...ir.builtins import BUILTINS, SAME, names
from .. import arrays as a
from ..calls import assertion, condition_value, string_equation, without_events
from ..connect import check_branches, check_no_connect
from ..scopes import ClassScope, FlattenContext, LocalScope, Scope, equations
from .when_rules import check_when_target

_EXPRS = (x.Const, x.Var, x.Time, x.Der, x.Neg, x.Not, x.BinOp, x.Call, x.If)
_WHEN_HINT = ("a when-clause holds equations 'v = expression', reinit(x, value) and "
              "terminate(\"why\")")


def flatten_when(ctx: FlattenContext, eq: s.WhenEquation, where: Scope, owner: ClassScope,
                 initial: bool) -> None:
    """Append the when-clause ``eq`` to ``ctx.whens``."""
    if initial:
        raise FlattenError("a when-equation is not allowed in an initial equation section",
                           eq.span, hint="move it to the equation section")
    uses = ctx.evaluator.events
    uses.in_when += 1
    try:
        branches = []
        earlier: list[x.Expr] = []  # the conditions of the branches before
        for cond_expr, body in eq.branches:
            conditions = when_conditions(condition_value(ctx.evaluator, cond_expr, where),
                                         cond_expr)
            parts = _Body(phase_guard(conditions, earlier), owner)
            earlier += conditions
            for item in body:
                _body_item(ctx, item, where, parts)
            branches.append(w.WhenBranch(tuple(conditions), tuple(parts.assignments),
                                         tuple(parts.reinits), tuple(parts.terminates),
                                         cond_expr.span))
    finally:
        uses.in_when -= 1
    ctx.whens.append(w.When(tuple(branches), eq.span, owner.prefix))


def when_conditions(cond: a.Value, cond_expr: s.Expr) -> list[x.Expr]:
    """The scalar conditions of a when-clause's condition value (a vector fires when
    any element becomes true)."""
    items: list[object] = list(a.scalars(cond)) if a.is_array(cond) else [cond]
    conditions: list[x.Expr] = []
    for c in items:
        if not isinstance(c, _EXPRS) or not _boolean_shape(c):
            raise FlattenError("the condition of a when-clause must be a Boolean "
                               "expression", cond_expr.span,
                               hint="write a relation such as 'h <= 0', a Boolean "
                               "variable, sample(start, interval) or initial()")
        conditions.append(c)
    return conditions


class _Body:
    def __init__(self, guard: x.Expr | None = None, owner: ClassScope | None = None
                 ) -> None:
        self.assignments: list[w.Assignment] = []
        self.reinits: list[w.Reinit] = []
        self.terminates: list[w.Terminate] = []
        self.guard, self.owner = guard, owner  # for assert (see phase_guard)


_PHASES = tuple(x.Call(name, ()) for name in sorted(names(lambda b: b.phase)))


def phase_guard(conditions: list[x.Expr], earlier: list[x.Expr]) -> x.Expr | None:
    """When a branch whose conditions are ``initial()`` or ``terminal()`` is active (the
    result rows where it holds are exactly its events), else None: an ``assert`` in
    the branch is checked where this guard holds."""
    if not all(c in _PHASES for c in [*conditions, *earlier]):
        return None
    guard: x.Expr = conditions[0]
    for c in conditions[1:]:
        guard = x.BinOp("or", guard, c)
    for c in earlier:
        guard = x.BinOp("and", guard, x.Not(c))
    return guard


def _boolean_shape(e: x.Expr) -> bool:
    """Whether ``e`` can be Boolean from its form (a variable's type is checked later,
    in :func:`check_events`)."""
    if isinstance(e, x.Const):
        return isinstance(e.value, bool)
    if isinstance(e, x.BinOp):
        return e.op in x.RELATIONS or e.op in ("and", "or")
    if isinstance(e, x.Call):
        builtin = BUILTINS.get(e.name)
        if builtin is not None and builtin.result == SAME and len(e.args) == 1:
            return _boolean_shape(e.args[0])  # pre(b), noEvent(b)
        return builtin is not None and builtin.boolean
    if isinstance(e, x.If):
        return _boolean_shape(e.then) and _boolean_shape(e.otherwise)
    return isinstance(e, (x.Not, x.Var))


def _body_item(ctx: FlattenContext, item: s.Equation, where: Scope, parts: _Body) -> None:
    ev = ctx.evaluator
    if isinstance(item, s.Equality):
        check_when_target(ctx, item.lhs, where.entry)
        lhs = ev.value(item.lhs, where)
        rhs = ev.value(item.rhs, where)
        if a.shape(lhs) != a.shape(rhs):
            raise FlattenError("the two sides of this equation differ in size", item.span)
        if string_equation(lhs, rhs, item.span, at_events=True):
            return  # a discrete String: not simulated (flatten/calls/strings.py)
        for left, right in zip(_scalars(lhs), _scalars(rhs)):
            if not isinstance(left, x.Var):
                raise FlattenError("the left-hand side of an equation in a when-clause must "
                                   "be a variable", item.lhs.span,
                                   hint="a when-equation is solved for its left-hand side: "
                                   "write 'v = expression'")
            # the value is taken at the when's events only: its relations are
            # literal there (no crossing, no held value; 8.5), as in a when
            # statement; so are reinit's values below
            parts.assignments.append(w.Assignment(left.name, without_events(right),
                                                  item.span))
    elif isinstance(item, s.CallEquation) and item.call.func.dotted == "reinit":
        call = item.call
        if len(call.args) != 2 or call.named:
            raise FlattenError("reinit takes 2 arguments: reinit(x, value)", item.span)
        target = ev.value(call.args[0], where)
        value = ev.value(call.args[1], where)
        if a.shape(target) != a.shape(value):
            raise FlattenError("the two arguments of reinit differ in size", item.span)
        for t, v in zip(_scalars(target), _scalars(value)):
            if not isinstance(t, x.Var):
                raise FlattenError("the first argument of reinit must be a variable",
                                   call.args[0].span,
                                   hint="write reinit(x, value) with x a state")
            parts.reinits.append(w.Reinit(t.name, without_events(v), item.span))
    elif isinstance(item, s.CallEquation) and item.call.func.dotted == "terminate":
        call = item.call
        message = ev.value(call.args[0], where) if len(call.args) == 1 else None
        if not isinstance(message, str) or call.named:
            raise FlattenError("terminate takes one string: terminate(\"why\")", item.span)
        parts.terminates.append(w.Terminate(message, item.span))
    elif isinstance(item, s.ForEquation):
        for local in _iterations(ctx, item.indices, where):
            for inner in item.body:
                _body_item(ctx, inner, local, parts)
    elif isinstance(item, s.IfEquation):
        _if_in_when(ctx, item, where, parts)
    elif isinstance(item, s.WhenEquation):
        raise FlattenError("when-equations cannot be nested", item.span,
                           hint="combine the conditions: 'when a and b then' or use "
                           "elsewhen")
    elif isinstance(item, s.CallEquation) and item.call.func.dotted == "assert":
        if parts.guard is None or parts.owner is None:
            # valid Modelica (section 8.3.5), not simulated by springc yet
            raise FlattenError("`assert` inside a when-clause is not supported yet, "
                               "unless the condition is initial() or terminal()",
                               item.span, hint="springc supports a subset of Modelica; "
                               "see \"Not supported yet\" in docs/language.md")
        ctx.assertions.append(assertion(ev, item.call, where, flat.Origin(
            "equation", parts.owner.prefix), parts.guard))
    else:
        what = ("connect" if isinstance(item, s.Connect)
                else "an algorithm section" if isinstance(item, s.AlgorithmSection)
                else f"'{item.call.func.dotted}'")
        raise FlattenError(f"{what} is not allowed in a when-clause", item.span,
                           hint=_WHEN_HINT)


def _scalars(v: a.Value) -> list[x.Expr]:
    return list(a.scalars(v)) if a.is_array(v) else [v]  # type: ignore[list-item]


def _iterations(ctx: FlattenContext, indices: tuple[s.ForIndex, ...], where: Scope
                ) -> Iterator[Scope]:
    index, rest = indices[0], indices[1:]
    for value in ctx.evaluator.range_values(index, where):
        local = LocalScope({index.name: value}, where)
        if rest:
            yield from _iterations(ctx, rest, local)
        else:
            yield local


def _if_in_when(ctx: FlattenContext, item: s.IfEquation, where: Scope, parts: _Body) -> None:
    """An if-equation inside a when-clause: each variable it assigns takes the value of
    the first branch whose condition holds; a branch that does not assign it keeps
    ``pre`` of it. Reinit and terminate inside such an if are not supported yet."""
    conds: list[x.Expr] = []
    bodies: list[_Body] = []
    for cond_expr, body in [*item.branches, (s.Bool(True, item.span), item.otherwise)]:
        conds.append(ctx.evaluator.scalar(cond_expr, where))
        sub = _Body()
        for inner in body:
            _body_item(ctx, inner, where, sub)
        if sub.reinits or sub.terminates:
            raise FlattenError("reinit and terminate inside an if-equation in a "
                               "when-clause are not supported yet", item.span,
                               hint="write a separate when-clause with the condition")
        bodies.append(sub)
    names: dict[str, w.Assignment] = {}
    for sub in bodies:
        for assignment in sub.assignments:
            names.setdefault(assignment.name, assignment)
    for name, first in names.items():
        value: x.Expr = x.Call("pre", (x.Var(name),))
        for cond, sub in reversed(list(zip(conds, bodies))):
            found = [b for b in sub.assignments if b.name == name]
            branch = found[-1].value if found else x.Call("pre", (x.Var(name),))
            value = branch if cond == x.Const(True) else x.If(cond, branch, value)
        parts.assignments.append(w.Assignment(name, value, first.span))


# --------------------------------------------------------- variable if-equations


def variable_if_equation(ctx: FlattenContext, eq: s.IfEquation, where: Scope,
                         owner: ClassScope, initial: bool) -> None:
    """An if-equation whose condition depends on variables: every branch must hold the
    same number of scalar equations; the i-th equations of the branches become one
    equation with if-expressions (``lhs = if c then r1 else r2`` when the branches
    share the left-hand side, ``0 = if c then l1 - r1 else l2 - r2`` otherwise)."""
    check_no_connect(eq)
    for _, body in [*eq.branches, (None, eq.otherwise)]:
        check_branches(body, "an if-equation with a variable condition")
        nested = _find_when(body)
        if nested is not None:
            raise FlattenError("a when-equation cannot be inside an if-equation with a "
                               "variable condition", nested.span,
                               hint="put the when-equation outside the if-equation and "
                               "its condition into the when's condition")
    target = ctx.initial_equations if initial else ctx.equations
    conds = [ctx.evaluator.scalar(c, where) for c, _ in eq.branches]
    lists: list[list[flat.Equation]] = []
    earlier: x.Expr | None = None  # some earlier branch is taken
    for k, (_, body) in enumerate([*eq.branches, (None, eq.otherwise)]):
        start, asserts = len(target), len(ctx.assertions)
        for item in body:
            ctx.equation(item, where, owner, initial)  # the driver's dispatcher
        lists.append(target[start:])
        del target[start:]
        taken = conds[k] if k < len(conds) else None
        guard = _branch_guard(taken, earlier)
        if guard is not None:
            _guard_all(ctx.assertions, asserts, guard)
        if taken is not None:
            earlier = taken if earlier is None else x.BinOp("or", earlier, taken)
    sizes = {len(eqs) for eqs in lists}
    if len(sizes) > 1:
        counts = ", ".join(str(len(eqs)) for eqs in lists)
        raise FlattenError(f"the branches of an if-equation with a variable condition must "
                           f"have the same number of equations (found {counts})", eq.span,
                           [Note("the condition depends on variables, so the branch "
                                 "switches during the simulation")],
                           hint="give every branch, including 'else', one equation for "
                           "each variable the if-equation determines")
    for rows in zip(*lists):
        first = rows[0]
        if all(r.lhs == first.lhs for r in rows):
            value = rows[-1].rhs
            for cond, r in reversed(list(zip(conds, rows[:-1]))):
                value = x.If(cond, r.rhs, value)
            target.append(flat.Equation(first.lhs, value, first.span, first.origin))
        else:
            value = x.sub(rows[-1].lhs, rows[-1].rhs)
            for cond, r in reversed(list(zip(conds, rows[:-1]))):
                value = x.If(cond, x.sub(r.lhs, r.rhs), value)
            target.append(flat.Equation(x.ZERO, value, first.span, first.origin))


def _branch_guard(cond: x.Expr | None, earlier: x.Expr | None) -> x.Expr | None:
    """When a branch of an if-equation is taken: its condition and no earlier one."""
    if earlier is None:
        return cond
    if cond is None:
        return x.Not(earlier)
    return x.BinOp("and", x.Not(earlier), cond)


def _guard_all(assertions: list[tuple[flat.Assertion, Span]], start: int, guard: x.Expr
               ) -> None:
    """The assertions recorded since ``start`` are checked only where ``guard`` holds
    (they sit in a branch of an if-equation with a variable condition)."""
    for i in range(start, len(assertions)):
        item, span = assertions[i]
        condition = x.If(guard, item.condition, x.Const(True))
        assertions[i] = (dataclasses.replace(item, condition=condition), span)


def _find_when(body: tuple[s.Equation, ...]) -> s.WhenEquation | None:
    return next((eq for eq in equations(body) if isinstance(eq, s.WhenEquation)), None)


# ------------------------------------------------------------------ final checks


def check_events(ctx: FlattenContext, variables: tuple[flat.Variable, ...]) -> None:
    """The checks that need the whole flat model (module docstring)."""
    by_name = {v.name: v for v in variables}
    discrete = set(w.assigned(tuple(ctx.whens)))
    for name, span in ctx.evaluator.events.pre_uses:
        v = by_name.get(name)
        if v is not None and v.variability == "continuous" and name not in discrete:
            raise FlattenError(
                f"pre({name}) of a continuous variable outside a when-clause", span,
                [Note(f"'{name}' is declared here", v.span)],
                hint="pre() gives the value before an event: use it inside a when-clause "
                "(reinit(v, -e*pre(v))), or make the variable discrete (assign it in a "
                "when-clause or declare it Integer, Boolean or discrete)")
    for clause in ctx.whens:
        for branch in clause.branches:
            for c in branch.conditions:
                name = c.name if isinstance(c, x.Var) else ""
                v = by_name.get(name)
                if v is not None and v.type != "Boolean":
                    raise FlattenError(
                        f"the condition of a when-clause must be Boolean, but '{name}' "
                        f"is {v.type}", branch.span,
                        hint="compare it, e.g. 'when x > 0 then'")
            for r in branch.reinits:
                v = by_name.get(r.name)
                if v is not None and (v.type != "Real" or v.variability != "continuous"):
                    raise FlattenError(f"reinit({r.name}, ...) needs a continuous Real "
                                       f"variable; '{r.name}' is {v.variability} {v.type}",
                                       r.span, hint="assign discrete variables with "
                                       "'v = expression' in the when-clause")
