"""``when`` statements in algorithm sections (Modelica 3.6, section 11.2.7).

:mod:`.algorithms` executes a section's statements symbolically; at a ``when``
statement it calls :func:`when_statement`, which runs each branch's statements on a
copy of the section's values so far and turns what the branch assigns into a
:class:`springc.ir.when.When` (the machinery of when-equations: the assigned
variables are discrete, held between the events that activate a branch; a branch
that does not assign a variable leaves its value). ``terminate`` and ``assert`` (on
``initial()``/``terminal()``, see :func:`.when.phase_guard`) inside a branch are
collected in :class:`WhenParts`. The restrictions of 11.2.7: no when statement in
another, in a ``for``/``while`` loop, in an ``if`` on a condition known only during
the simulation, in an initial algorithm (or in a function: :mod:`.functions`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

from ...errors import FlattenError, Span
from ...ir import expr as x
from ...ir import syntax as s
from ...ir import when as w
from ..calls import condition_value
from ..scopes import ExpressionEvaluator, Scope
from .when import phase_guard, when_conditions

_WHERE = {"when": "inside another when statement", "for": "inside a for loop",
          "while": "inside a while loop",
          "if": "inside an if statement whose condition is known only during the simulation"}
_HINTS = {"when": "combine the conditions ('when a and b then') or use elsewhen",
          "for": "put the loop inside the when statement",
          "while": "put the loop inside the when statement",
          "if": "put the if statement inside the when statement"}


@dataclass
class WhenParts:
    """What a branch holds besides assignments: its ``terminate`` calls and the guard
    of the assertions in it (None: an ``assert`` there is not supported)."""

    guard: x.Expr | None
    terminates: list[w.Terminate] = field(default_factory=list)


def check_place(stmt: s.WhenStatement, context: list[str], initial: bool) -> None:
    """The places where 11.2.7 forbids a when statement."""
    if initial:
        raise FlattenError("a when statement is not allowed in an initial algorithm "
                           "section", stmt.span, hint="move it to the algorithm section "
                           "(Modelica 3.6, section 11.2.7)")
    for kind in reversed(context):
        if kind in _WHERE:
            raise FlattenError(f"a when statement is not allowed {_WHERE[kind]}",
                               stmt.span, hint=f"{_HINTS[kind]} (Modelica 3.6, section "
                               "11.2.7)")


def when_statement(ev: ExpressionEvaluator, stmt: s.WhenStatement, where: Scope,
                   env: dict[str, x.Expr], held: set[str],
                   read: Callable[[x.Expr | object, Span], object],
                   run_branch: Callable[[tuple[s.Statement, ...], WhenParts],
                                        dict[str, tuple[x.Expr, Span]]],
                   component: str) -> w.When:
    """The when-clause of ``stmt``. ``run_branch(body, parts)`` runs a branch on a copy
    of the section's values and gives the (value, span) of each variable it assigned;
    ``held`` collects the variables when statements assign."""
    uses = ev.events
    uses.in_when += 1
    try:
        branches = []
        earlier: list[x.Expr] = []
        for cond_expr, body in stmt.branches:
            value = read(condition_value(ev, cond_expr, where), cond_expr.span)
            conditions = when_conditions(value, cond_expr)  # type: ignore[arg-type]
            parts = WhenParts(phase_guard(conditions, earlier))
            earlier += conditions
            assigned = run_branch(body, parts)
            assignments = []
            for name, (item, span) in assigned.items():
                if name in env:
                    raise FlattenError(f"'{name}' is assigned both in a when statement and "
                                       "outside of it in this algorithm section", span,
                                       hint="a variable a when statement assigns is "
                                       "discrete: assign it only in when statements")
                held.add(name)
                assignments.append(w.Assignment(name, item, span))
            branches.append(w.WhenBranch(tuple(conditions), tuple(assignments), (),
                                         tuple(parts.terminates), cond_expr.span))
    finally:
        uses.in_when -= 1
    return w.When(tuple(branches), stmt.span, component)


def terminate_of(ev: ExpressionEvaluator, stmt: s.CallStatement, where: Scope) -> w.Terminate:
    """The ``terminate("why")`` statement ``stmt``."""
    call = stmt.call
    message = ev.value(call.args[0], where) if len(call.args) == 1 else None
    if not isinstance(message, str) or call.named:
        raise FlattenError("terminate takes one string: terminate(\"why\")", stmt.span)
    return w.Terminate(message, stmt.span)


def check_nesting(body: tuple[s.Statement, ...], initial: bool,
                  context: tuple[str, ...] = ()) -> None:
    """The when statements of a section in loops or in other when statements, wherever
    they are (also where the statements never run); an ``if`` is checked when it runs,
    as only a condition known during the simulation forbids it."""
    for stmt in body:
        if isinstance(stmt, s.WhenStatement):
            check_place(stmt, list(context), initial)
            for _, branch in stmt.branches:
                check_nesting(branch, initial, (*context, "when"))
        elif isinstance(stmt, (s.ForStatement, s.WhileStatement)):
            kind = "for" if isinstance(stmt, s.ForStatement) else "while"
            check_nesting(stmt.body, initial, (*context, kind))
        elif isinstance(stmt, s.IfStatement):
            for _, branch in stmt.branches:
                check_nesting(branch, initial, context)
            check_nesting(stmt.otherwise, initial, context)


def reads_before_assignment(when: w.When, names: set[str]) -> w.When:
    """``when`` with its assignments' reads of ``names`` as ``pre(name)``: the
    variables when statements of the section assign that had not been assigned where
    this one runs. An algorithm runs in order and such a variable still holds its
    value from before the event there (11.1.2: a discrete variable starts from its
    ``pre`` value), while the when-equation ``v = name`` would read its new value."""
    memo: dict[int, x.Expr] = {}

    def held(e: x.Expr) -> x.Expr:
        if isinstance(e, x.Var):
            return x.Call("pre", (e,)) if e.name in names else e
        if isinstance(e, x.Call) and e.name in ("pre", "edge", "change"):
            return e
        found = memo.get(id(e))
        if found is None:
            found = memo[id(e)] = x.map_children(e, held)
        return found

    branches = tuple(
        replace(b, assignments=tuple(replace(a, value=held(a.value))
                                     for a in b.assignments))
        for b in when.branches)
    return replace(when, branches=branches)
