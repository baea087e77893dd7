"""``while``, ``break`` and ``return`` (sections 11.2.3-11.2.5) in the symbolic
execution of functions (:mod:`.functions`) and algorithm sections (:mod:`.algorithms`).

Statements run while flattening, so control flow must be decided then: a ``while``
condition, and the conditions that guard a ``break`` or ``return``, must have values
known before the simulation (constants, or values computed from them). Otherwise the
statement is a located "not supported yet" error. :class:`Jumped` carries a ``break``
or ``return`` up to the loop or call it leaves.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...errors import FlattenError, Span
from ...ir import expr as x
from ...ir import syntax as s
from ..scopes import ExpressionEvaluator


class Jumped(Exception):
    """A ``break`` or ``return`` leaving the statements that run it."""

    def __init__(self, jump: s.Jump) -> None:
        super().__init__(jump.kind)
        self.jump = jump


def folded(e: x.Expr) -> x.Expr:
    """``e`` as a constant when it holds no variable (``100 / 2 > 1``), so that
    control flow on it is decided while flattening."""
    if isinstance(e, x.Const) or any(isinstance(n, (x.Var, x.Time, x.Der))
                                     for n in x.walk(e)):
        return e
    try:
        return x.Const(x.evaluate(e, {}))
    except (ArithmeticError, ValueError, KeyError, TypeError):
        return e


def run_while(ev: ExpressionEvaluator, stmt: s.WhileStatement,
              condition: Callable[[], x.Expr], body: Callable[[], None],
              at_run_time: Callable[[], bool] | None = None) -> None:
    """Run ``body`` while ``condition()`` (re-evaluated each time) is true; where the
    condition is known only during the simulation, ``at_run_time()`` runs the rest of
    the loop if it can (a counted search in a function: :mod:`.counted`)."""
    done = 0
    while True:
        value = folded(condition())
        if not isinstance(value, x.Const) and ev.flattener.is_parameter_expression(value):
            # decided by the parameters' values, as an if-equation's condition is
            value = x.Const(ev.fold(value))
            ev.flattener.parameter_decisions += 1  # (calls.parameter_calls)
        if isinstance(value, x.Const) and not isinstance(value.value, (bool, np.bool_)):
            raise FlattenError("the condition of a while loop must be a Boolean expression",
                               stmt.condition.span)
        if not isinstance(value, x.Const):
            if at_run_time is not None and at_run_time():
                return
            raise FlattenError("`while` loops whose condition is known only during the "
                               "simulation are not supported yet", stmt.condition.span,
                               hint="loop over a range (for i in 1:n) with break")
        if not value.value:
            return
        ev.flattener.limits.while_iteration(done, stmt.span)
        done += 1
        try:
            body()
        except Jumped as jumped:
            if jumped.jump.kind == "break":
                return
            raise


def run_loop_body(body: Callable[[], None]) -> bool:
    """Run one iteration of a for loop's body; False after a ``break``."""
    try:
        body()
    except Jumped as jumped:
        if jumped.jump.kind == "break":
            return False
        raise
    return True


def branch_jumps(run: Callable[[], None], span: Span) -> None:
    """Run a branch of an if on a condition known only during the simulation: a
    ``break`` or ``return`` there is not supported."""
    try:
        run()
    except Jumped as jumped:
        raise FlattenError(f"`{jumped.jump.kind}` under a condition known only during the "
                           "simulation is not supported yet", jumped.jump.span,
                           hint="springc decides control flow while flattening; the "
                           f"condition of the if-statement at {span} must be known "
                           "before the simulation") from None


def check_jumps(body: tuple[s.Statement, ...], in_function: bool, in_loop: bool = False
                ) -> None:
    """Every ``return`` inside a function and every ``break`` inside a loop, whatever
    the conditions around them (sections 11.2.4 and 11.2.5)."""
    for stmt in body:
        if isinstance(stmt, s.Jump):
            allowed = in_loop if stmt.kind == "break" else in_function
            if not allowed:
                raise stray(Jumped(stmt))
        elif isinstance(stmt, (s.ForStatement, s.WhileStatement)):
            check_jumps(stmt.body, in_function, True)
        elif isinstance(stmt, s.IfStatement):
            for _cond, branch in stmt.branches:
                check_jumps(branch, in_function, in_loop)
            check_jumps(stmt.otherwise, in_function, in_loop)
        elif isinstance(stmt, s.WhenStatement):
            for _cond, branch in stmt.branches:
                check_jumps(branch, in_function, in_loop)


def stray(jumped: Jumped) -> FlattenError:
    """The error of a ``break`` outside a loop or a ``return`` outside a function."""
    where = "inside a loop" if jumped.jump.kind == "break" else "in a function"
    return FlattenError(f"`{jumped.jump.kind}` is only allowed {where}", jumped.jump.span)
