"""``return`` and ``break`` (sections 11.2.4, 11.2.5) as flags, for the symbolic
execution of functions (:mod:`.functions`).

A function's statements run while flattening; a ``return`` or ``break`` under an
``if`` whose condition is known only during the simulation cannot be decided then.
:func:`lowered` rewrites a function's algorithm so that no jump is left: a ``return``
sets the flag ``$return``, a ``break`` the flag of its loop (``$break1`` for the
outermost loop, ``$break2`` inside it, ...); the statements after one that may jump
run under ``if not <flags> then``, and a loop that may jump runs each iteration under
the same guard (a ``while`` takes it into its condition). The existing execution of an
``if`` then merges the values of both paths with if-expressions, and where the
conditions are known while flattening the flags fold to constants and the guards
vanish: the same values as jumping out. The ``$`` names cannot clash with a
Modelica identifier.
"""

from __future__ import annotations

from functools import lru_cache

from ...errors import Span
from ...ir import expr as x
from ...ir import syntax as s

RETURN = "$return"


def flags(body: tuple[s.Statement, ...]) -> tuple[str, ...]:
    """The flags :func:`lowered` ``body`` uses (each starts false)."""
    found: list[str] = [RETURN]
    depth = _loop_depth(body)
    found += [_break_flag(k) for k in range(1, depth + 1)]
    return tuple(found)


@lru_cache(maxsize=512)
def lowered(body: tuple[s.Statement, ...]) -> tuple[s.Statement, ...]:
    """``body`` (a function's algorithm, without stray jumps) with its jumps turned
    into flags (module docstring); ``body`` itself when it has no jump."""
    if not _has_jump(body):
        return body
    return _lower(body, None, 0)


def is_flag(name: str) -> bool:
    """Whether ``name`` is one of the flags of :func:`lowered`."""
    return name.startswith("$")


def merged_flag(cond: x.Expr, then: object, otherwise: object) -> x.Expr:
    """A flag's value after an if on ``cond`` (``then`` where it holds, else
    ``otherwise``), with the Boolean constants folded."""
    assert isinstance(then, x.Expr) and isinstance(otherwise, x.Expr)
    true, false = _truth(then), _truth(otherwise)
    if then == otherwise:
        return then
    if true is True:
        return cond if false is False else x.BinOp("or", cond, otherwise)
    if false is False:
        return x.BinOp("and", cond, then) if true is None else x.Not(cond)
    if true is False and false is True:
        return x.Not(cond)
    return x.If(cond, then, otherwise)


def _truth(e: x.Expr) -> bool | None:
    if isinstance(e, x.Const) and isinstance(e.value, bool):
        return e.value
    return None


def _lower(body: tuple[s.Statement, ...], brk: str | None, depth: int
           ) -> tuple[s.Statement, ...]:
    out: list[s.Statement] = []
    for k, stmt in enumerate(body):
        if isinstance(stmt, s.Jump):
            flag = RETURN if stmt.kind == "return" else brk
            assert flag is not None  # check_jumps rejected a break outside a loop
            out.append(_set(flag, True, stmt.span))
            return tuple(out)  # the statements after it never run
        out += _lower_statement(stmt, brk, depth)
        leaves = tuple(brk if kind == "break" and brk else kind
                       for kind in _leaves(stmt, brk is not None))
        rest = _lower(body[k + 1:], brk, depth) if leaves else ()
        if rest:
            out.append(s.IfStatement(((_none_of(leaves, stmt.span), rest),), (),
                                     stmt.span))
        if leaves:
            return tuple(out)
    return tuple(out)


def _lower_statement(stmt: s.Statement, brk: str | None, depth: int) -> list[s.Statement]:
    if isinstance(stmt, s.IfStatement):
        return [s.IfStatement(tuple((c, _lower(b, brk, depth)) for c, b in stmt.branches),
                              _lower(stmt.otherwise, brk, depth), stmt.span)]
    if not isinstance(stmt, (s.ForStatement, s.WhileStatement)) or \
            not _has_jump(stmt.body):
        return [stmt]
    own = _break_flag(depth + 1)
    body = _lower(stmt.body, own, depth + 1)
    guard = [*([own] if _breaks(stmt.body) else []),
             *([RETURN] if _returns(stmt.body) else [])]
    init = [_set(own, False, stmt.span)] if _breaks(stmt.body) else []
    if isinstance(stmt, s.WhileStatement):
        cond = s.Binary("and", _none_of(tuple(guard), stmt.span), stmt.condition,
                        stmt.condition.span)
        return [*init, s.WhileStatement(cond, body, stmt.span)]
    guarded = s.IfStatement(((_none_of(tuple(guard), stmt.span), body),), (), stmt.span)
    return [*init, s.ForStatement(stmt.indices, (guarded,), stmt.span)]


def _leaves(stmt: s.Statement, in_loop: bool) -> tuple[str, ...]:
    """The flags ``stmt`` may set that leave the statements after it: ``$return``,
    and the enclosing loop's break flag (named ``""`` here, resolved by the caller)."""
    if isinstance(stmt, s.IfStatement):
        bodies = [b for _c, b in stmt.branches] + [stmt.otherwise]
        kinds: set[str] = set()
        for b in bodies:
            if _returns(b):
                kinds.add(RETURN)
            if in_loop and _breaks(b):
                kinds.add("break")
        return tuple(sorted(kinds))
    if isinstance(stmt, (s.ForStatement, s.WhileStatement)) and _returns(stmt.body):
        return (RETURN,)
    return ()


def _none_of(names: tuple[str, ...], span: Span) -> s.Expr:
    """``not (f1 or f2 ...)`` of the flags ``names``."""
    expr: s.Expr = _flag(names[0], span)
    for name in names[1:]:
        expr = s.Binary("or", expr, _flag(name, span), span)
    return s.Unary("not", expr, span)


def _flag(name: str, span: Span) -> s.Ref:
    return s.Ref((s.RefPart(name, (), span),), span)


def _set(flag: str, value: bool, span: Span) -> s.Assign:
    return s.Assign((_flag(flag, span),), s.Bool(value, span), span)


def _break_flag(depth: int) -> str:
    return f"$break{depth}"


def _has_jump(body: tuple[s.Statement, ...]) -> bool:
    return _returns(body) or _breaks(body) or any(
        isinstance(st, (s.ForStatement, s.WhileStatement)) and _has_jump(st.body)
        for st in body)


def _returns(body: tuple[s.Statement, ...]) -> bool:
    """Whether ``body`` holds a ``return``, at any depth."""
    return _holds(body, "return", into_loops=True)


def _breaks(body: tuple[s.Statement, ...]) -> bool:
    """Whether ``body`` holds a ``break`` of its own loop (not of a loop inside)."""
    return _holds(body, "break", into_loops=False)


def _holds(body: tuple[s.Statement, ...], kind: str, into_loops: bool) -> bool:
    """Whether ``body`` holds a jump of ``kind``, inside if-statements and, where
    ``into_loops``, inside the loops it holds."""
    for st in body:
        if isinstance(st, s.Jump) and st.kind == kind:
            return True
        if isinstance(st, s.IfStatement) and (
                any(_holds(b, kind, into_loops) for _c, b in st.branches)
                or _holds(st.otherwise, kind, into_loops)):
            return True
        if into_loops and isinstance(st, (s.ForStatement, s.WhileStatement)) \
                and _holds(st.body, kind, into_loops):
            return True
    return False


def _loop_depth(body: tuple[s.Statement, ...]) -> int:
    deepest = 0
    for st in body:
        if isinstance(st, (s.ForStatement, s.WhileStatement)):
            deepest = max(deepest, 1 + _loop_depth(st.body))
        elif isinstance(st, s.IfStatement):
            for b in [*(b for _c, b in st.branches), st.otherwise]:
                deepest = max(deepest, _loop_depth(b))
    return deepest
