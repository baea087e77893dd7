"""Loop nests checked against the iteration cap before they run.

Input: a ``for`` equation or statement, with the loops nested directly in its body.
Output: nothing, or a located error when the nest is sure to run more iterations than
the cap allows. Counting as the loops run (:meth:`Limits.add_iterations`) would stop
them too, but only after running up to the cap, which can take a minute.
"""

from __future__ import annotations

import contextlib

from ...errors import FlattenError, Span
from ...ir import syntax as s
from ..scopes import ExpressionEvaluator, Scope

__all__ = ["check_loop_nest"]

Loop = s.ForEquation | s.ForStatement


def check_loop_nest(ev: ExpressionEvaluator, loop: Loop, scope: Scope) -> None:
    """Refuse ``loop`` if its iterations, with those of the loops nested directly in its
    body (``for i in 1:n loop for j in 1:m loop``, or ``for i in 1:n, j in 1:m``),
    exceed the cap. Ranges that use an enclosing loop's index, or cannot be evaluated
    before the loop runs, count as one iteration: the result is a lower bound."""
    count = _iterations(ev, loop, scope, frozenset())
    ev.flattener.limits.check_size(count, "this loop nest", loop.indices[0].span,
                                   "iterations")


def _iterations(ev: ExpressionEvaluator, loop: Loop, scope: Scope,
                outer: frozenset[str]) -> int:
    count = 1
    for index in loop.indices:
        if index.range is not None and not outer & _names_in(index.range):
            with contextlib.suppress(FlattenError):  # reported when the loop runs
                count *= len(ev.range_values(index, scope))
        outer |= {index.name}
    nested = [_iterations(ev, item, scope, outer) for item in loop.body
              if isinstance(item, s.ForEquation | s.ForStatement)]
    return count * max(1, sum(nested))


def _names_in(e: object) -> set[str]:
    """The first names of the references in a syntax expression."""
    if isinstance(e, s.Ref):
        return {e.parts[0].name} | {n for p in e.parts for sub in p.subscripts
                                    for n in _names_in(sub)}
    if isinstance(e, tuple):
        return {n for item in e for n in _names_in(item)}
    fields = getattr(e, "__dataclass_fields__", None)
    if fields is None or isinstance(e, Span):
        return set()
    return {n for name in fields for n in _names_in(getattr(e, name))}
