"""``while`` loops of functions whose condition is known only during the simulation,
when the loop is a counted search (section 11.2.3; TimeTable's
``getInterpolationCoefficients``: ``while next < nrow and tp >= table[next, 1] loop
next := next + 1; end while``).

Such a loop is unrolled symbolically, soundly, where its shape bounds it:

- its body raises a counter ``i`` by a constant step ``c > 0`` in one unconditional
  statement ``i := i + c`` (no other statement assigns ``i``); a ``break`` or
  ``return`` in it has become a flag before (:mod:`.jumps`), read by the condition
  as one more conjunct;
- its condition is a conjunction (``p and q and ...``) one of whose conjuncts
  compares a subscript ``A[..., i, ...]`` of an array whose dimension there has
  ``n`` elements known while flattening.

Each check that lets the loop go on evaluates that subscript, which must lie in
``1..n`` (an index out of range is an error, section 10.5), with a counter value
larger than at every earlier check: at most ``n`` checks let the loop go on. The
``k``-th iteration therefore runs where ``running_k = c_0 and ... and c_(k-1)``
holds, with the counter at ``i0 + c*k`` there (so each condition reads the start
value, not the value of the iteration before: the expressions grow linearly), and
the counter leaves the loop as ``i0 + c*(number of iterations run)``. Any other
loop whose condition is known only during the simulation stays a located error.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

from ...errors import FlattenError
from ...ir import expr as x
from ...ir import syntax as s
from .. import arrays as a
from ..scopes import ExpressionEvaluator, FunctionScope
from .control import folded


def run_counted(ev: ExpressionEvaluator, stmt: s.WhileStatement, scope: FunctionScope,
                guard: x.Expr | None, run_body: Callable[[x.Expr], None]) -> bool:
    """Unroll ``stmt`` from the values in ``scope`` if it is a counted search (module
    docstring); False (nothing done) if it is not. ``run_body(guard)`` runs the body
    once, its assertions under ``guard``."""
    counter = _counter(stmt.body)
    if counter is None:
        return False
    name, step_expr = counter
    start = scope.names.get(name)
    try:
        step = ev.fold(ev.value(step_expr, scope))
    except (KeyError, ArithmeticError, ValueError, TypeError):
        return False
    if not isinstance(start, x.Expr) or isinstance(step, bool) or step != int(step) \
            or step <= 0:
        return False
    bound = _bound(ev, stmt.condition, name, scope)
    if bound is None:
        return False
    ev.flattener.limits.add_iterations(bound, stmt.span)
    running: x.Expr = x.Const(True)
    runs: list[x.Expr] = []
    for k in range(bound):
        scope.names[name] = start if k == 0 else \
            folded(x.BinOp("+", start, x.Const(int(step) * k)))
        cond = _simplified(folded(ev.scalar(stmt.condition, scope)))
        if isinstance(cond, x.Const) and not cond.value:
            break
        running = _both(running, cond)
        before = dict(scope.names)
        run_body(running if guard is None else x.BinOp("and", guard, running))
        _merge(scope, before, running, name, stmt)
        runs.append(running)
    count: x.Expr | None = None
    for ran in runs:
        once = x.If(ran, x.Const(int(step)), x.ZERO)
        count = once if count is None else x.BinOp("+", count, once)
    scope.names[name] = start if count is None else folded(x.BinOp("+", start, count))
    return True


def _both(p: x.Expr, q: x.Expr) -> x.Expr:
    """``p and q``, without a constant operand."""
    if isinstance(p, x.Const):
        return q if p.value else p
    if isinstance(q, x.Const):
        return p if q.value else q
    return x.BinOp("and", p, q)


def _simplified(cond: x.Expr) -> x.Expr:
    """``cond`` with the constant conjuncts of its top-level ``and`` dropped."""
    if isinstance(cond, x.BinOp) and cond.op == "and":
        return _both(_simplified(cond.left), _simplified(cond.right))
    return cond


def _merge(scope: FunctionScope, before: dict[str, a.Value], running: x.Expr,
           counter: str, stmt: s.WhileStatement) -> None:
    """The values the body assigned, where ``running`` holds; the old ones elsewhere."""
    for name, value in list(scope.names.items()):
        old = before.get(name)
        if name == counter or value is old:
            continue
        if old is None or value is None:
            raise FlattenError(f"'{name}' is assigned only inside this while loop, whose "
                               "condition is known only during the simulation", stmt.span,
                               hint="assign it before the loop too")
        scope.names[name] = a.elementwise(lambda new, kept: x.If(running, new, kept),
                                          value, old)


def _counter(body: tuple[s.Statement, ...]) -> tuple[str, s.Expr] | None:
    """``(i, c)`` where ``body`` raises ``i`` by ``c`` once, unconditionally, assigns
    ``i`` nowhere else and has no ``break`` or ``return``."""
    found: tuple[str, s.Expr] | None = None
    for stmt in body:
        if isinstance(stmt, s.Assign) and len(stmt.targets) == 1 \
                and _simple(stmt.targets[0]) is not None \
                and isinstance(stmt.value, s.Binary) and stmt.value.op == "+" \
                and _simple(stmt.value.left) == _simple(stmt.targets[0]):
            if found is not None:
                return None
            found = (_simple(stmt.targets[0]) or "", stmt.value.right)
    if found is None:
        return None
    assigned = [n for n in _assigned(body)]
    if assigned.count(found[0]) != 1 or any(isinstance(j, s.Jump) for j in _walk(body)):
        return None
    return found


def _simple(e: object) -> str | None:
    """The name of a reference ``i`` without subscripts or fields."""
    if isinstance(e, s.Ref) and len(e.parts) == 1 and not e.parts[0].subscripts:
        return e.parts[0].name
    return None


def _walk(body: tuple[s.Statement, ...]) -> Iterator[s.Statement]:
    for stmt in body:
        yield stmt
        if isinstance(stmt, (s.ForStatement, s.WhileStatement)):
            yield from _walk(stmt.body)
        elif isinstance(stmt, s.IfStatement):
            for _cond, branch in stmt.branches:
                yield from _walk(branch)
            yield from _walk(stmt.otherwise)


def _assigned(body: tuple[s.Statement, ...]) -> Iterator[str]:
    for stmt in _walk(body):
        if isinstance(stmt, s.Assign):
            yield from (t.parts[0].name for t in stmt.targets if t is not None)
        elif isinstance(stmt, s.ForStatement):
            yield from (index.name for index in stmt.indices)


def _bound(ev: ExpressionEvaluator, cond: s.Expr, counter: str, scope: FunctionScope
           ) -> int | None:
    """The least size ``n`` of an array dimension that a conjunct of ``cond`` compares
    a subscript ``A[..., counter, ...]`` of (module docstring); None if there is none."""
    sizes: list[int] = []
    for conjunct in _conjuncts(cond):
        if not (isinstance(conjunct, s.Binary)
                and conjunct.op in ("<", "<=", ">", ">=", "==", "<>")):
            continue
        for side in (conjunct.left, conjunct.right):
            if not (isinstance(side, s.Ref) and len(side.parts) == 1):
                continue
            part = side.parts[0]
            for axis, sub in enumerate(part.subscripts):
                if _simple(sub) != counter:
                    continue
                whole = s.Ref((s.RefPart(part.name, (), part.span),), side.span)
                try:
                    shape = a.shape(ev.value(whole, scope))
                except FlattenError:
                    continue
                if axis < len(shape):
                    sizes.append(shape[axis])
    return min(sizes) if sizes else None


def _conjuncts(cond: s.Expr) -> Iterator[s.Expr]:
    if isinstance(cond, s.Binary) and cond.op == "and":
        yield from _conjuncts(cond.left)
        yield from _conjuncts(cond.right)
    else:
        yield cond
