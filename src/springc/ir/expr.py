"""Scalar expressions of the flat model and later stages: the face of the tree.

A deliberately small, fast tree: flattening builds hundreds of thousands of these, so
they are plain frozen dataclasses rather than sympy objects (rendering as LaTeX converts
to sympy on demand, :mod:`springc.ir.latex`). The nodes, their traversal, construction
and text live in :mod:`springc.ir.nodes` and are re-exported here with evaluation and
differentiation, which read the built-ins' values and derivatives from the registry
(:mod:`springc.ir.builtins`).

Depth: the stages recurse over these trees, so their depth is bounded. The parser
rejects source expressions nested deeper than :data:`MAX_DEPTH` (a sum of n terms is
n - 1 deep), and the CLI and API run inside :func:`recursion_room`, which gives Python
the stack that depth needs.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from typing import Any

from .builtins import BUILTINS
from .nodes import (
    FOLD_CHUNK,
    ONE,
    RELATIONS,
    TIME,
    ZERO,
    BinOp,
    Call,
    Const,
    Der,
    Expr,
    If,
    Neg,
    Not,
    Time,
    Var,
    add,
    calls_named,
    children,
    derivatives,
    div,
    fold_chunked,
    format_number,
    map_children,
    mul,
    neg,
    power,
    sub,
    substitute,
    substitute_at_event,
    to_text,
    variables,
    walk,
)

__all__ = [
    "FOLD_CHUNK", "INITIAL", "MATH", "MAX_DEPTH", "ONE", "RELATIONS", "TIME", "ZERO",
    "BinOp", "Call", "Const", "Der", "Expr", "If", "Neg", "Not", "NotEvaluable", "Time",
    "Var", "add", "calls_named", "children", "derivatives", "diff", "div", "evaluate",
    "fold_chunked", "format_number", "map_children", "mul", "neg", "power", "recursion_limit",
    "recursion_room", "sub", "substitute", "substitute_at_event", "time_derivative", "to_text",
    "variables", "walk",
]

# ------------------------------------------------------------------------ depth

MAX_DEPTH = 3000
"""Deepest source expression accepted (docs/language.md, "Limits"). Measured: the
deepest stage (lowering, index reduction and code generation for ``simulate``) takes
about 4.5 Python calls per level, so 3,000 levels need about 13,500 of the 16,384
calls :func:`recursion_limit` allows on an 8 MiB stack."""

# Python 3.11 counts every call against one recursion limit, and calls made from C
# (== and hash of these frozen dataclasses, generator expressions, map) take C stack
# too: on an 8 MiB stack == of two 12,500-deep trees (37,500 calls) and a recursion
# through map 14,000 deep (28,000 calls) overflowed it, about 300 bytes a call, and
# compile() of generated code recurses 3 times the limit at about 145 bytes a level.
# An overflow is a segmentation fault, so the limit leaves 512 bytes a call.
_STACK_BYTES_PER_CALL = 512
_DEFAULT_STACK = 8 << 20
_RECURSION_CAP = 20_000


def recursion_limit() -> int:
    """The recursion limit this thread's stack can afford (at least Python's current
    one): the stack size over 512 bytes a call, at most 20,000."""
    return max(sys.getrecursionlimit(), _affordable())


def _affordable() -> int:
    """The recursion limit this thread's stack can afford, whatever the current one."""
    size = _DEFAULT_STACK
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_STACK)[0]
        if 0 < soft != resource.RLIM_INFINITY:
            size = soft  # the main thread's, and the default of new threads
    except (ImportError, OSError, ValueError):
        pass
    if threading.current_thread() is not threading.main_thread():
        configured = threading.stack_size()
        threading.stack_size(configured)  # reading it also set it (to 0): put it back
        size = configured or size
    return min(_RECURSION_CAP, size // _STACK_BYTES_PER_CALL)


class _RecursionRoom:
    """The one owner of Python's recursion limit while springc runs. The limit belongs
    to the interpreter, not to a thread, so the runs inside :func:`recursion_room`
    (nested calls, threads) share it: it is what the smallest stack among them affords
    (a deeper recursion than a thread's stack holds is a crash, not an error), never
    below the limit found before the first entered, which is put back when the last
    leaves."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._inside: list[int] = []  # what the stack of each run inside affords
        self._before = 0

    def enter(self) -> int:
        affordable = _affordable()
        with self._lock:
            if not self._inside:
                self._before = sys.getrecursionlimit()
            self._inside.append(affordable)
            self._apply()
        return affordable

    def leave(self, affordable: int) -> None:
        with self._lock:
            self._inside.remove(affordable)
            self._apply()

    def _apply(self) -> None:
        sys.setrecursionlimit(max(self._before, min(self._inside, default=0)))


_ROOM = _RecursionRoom()


@contextmanager
def recursion_room() -> Iterator[None]:
    """Run the body with :func:`recursion_limit` as Python's recursion limit, so that
    expressions up to :data:`MAX_DEPTH` deep pass every stage; the limit found before
    is put back when the last run inside leaves (see :class:`_RecursionRoom`)."""
    affordable = _ROOM.enter()
    try:
        yield
    finally:
        _ROOM.leave(affordable)


MATH: Mapping[str, Callable[..., Any]] = {
    name: b.evaluate for name, b in BUILTINS.items() if b.evaluate is not None}
"""The built-ins with a value for constant arguments (the registry's ``evaluate``)."""

_BINARY: dict[str, Callable[[Any, Any], Any]] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "^": lambda a, b: a**b,
    "<": lambda a, b: a < b, "<=": lambda a, b: a <= b, ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b, "==": lambda a, b: a == b, "<>": lambda a, b: a != b,
    "and": lambda a, b: bool(a) and bool(b), "or": lambda a, b: bool(a) or bool(b),
}

INITIAL = "initial()"
"""The key of an environment whose value says whether ``initial()`` holds (during
initialization); absent, it does not (the continuous phase)."""


class NotEvaluable(ValueError):
    """An operator that :func:`evaluate` has no value for (callers locate it)."""


def evaluate(e: Expr, env: Mapping[str, object], time: float = 0.0,
             initial: bool | None = None) -> Any:
    """Numeric value of ``e``; raises ``KeyError`` for a variable missing from ``env``
    and :class:`NotEvaluable` for an operator without a value here.

    The event operators take the values of the instant ``env`` describes: ``initial()``
    is ``initial`` (else ``env[INITIAL]``, else false), ``terminal()`` false, ``pre(v)``
    is ``env["pre(v)"]`` if given, else ``v`` (away from an event a variable equals its
    left limit), ``edge`` and ``change`` follow from ``pre``, and ``sample(start,
    interval)`` holds at ``start + k interval``."""
    return _evaluate(e, env, time, initial, {})


def _evaluate(e: Expr, env: Mapping[str, object], time: float, initial: bool | None,
              memo: dict[int, tuple[Expr, Any]]) -> Any:
    """:func:`evaluate`, each node shared by several parents once (``memo``)."""
    if isinstance(e, Const):
        return e.value
    if isinstance(e, Var):
        return env[e.name]
    found = memo.get(id(e))
    if found is not None and found[0] is e:
        return found[1]
    value = _evaluate_node(e, env, time, initial, memo)
    memo[id(e)] = (e, value)
    return value


def _evaluate_node(e: Expr, env: Mapping[str, object], time: float, initial: bool | None,
                   memo: dict[int, tuple[Expr, Any]]) -> Any:
    if isinstance(e, BinOp):
        return _BINARY[e.op](_evaluate(e.left, env, time, initial, memo),
                             _evaluate(e.right, env, time, initial, memo))
    if isinstance(e, Neg):
        return -_evaluate(e.arg, env, time, initial, memo)
    if isinstance(e, Not):
        return not _evaluate(e.arg, env, time, initial, memo)
    if isinstance(e, Call):
        function = MATH.get(e.name)
        if function is None:
            return _event_call(e, env, time, initial)
        return function(*(_evaluate(a, env, time, initial, memo) for a in e.args))
    if isinstance(e, If):
        branch = e.then if _evaluate(e.cond, env, time, initial, memo) else e.otherwise
        return _evaluate(branch, env, time, initial, memo)
    if isinstance(e, Time):
        return time
    assert isinstance(e, Der)
    raise KeyError(f"der({to_text(e.arg)})")


def _event_call(e: Call, env: Mapping[str, object], time: float,
                initial: bool | None) -> Any:
    """The value of the event operator ``e`` at the instant ``env`` describes."""
    def value(a: Expr) -> Any:
        return evaluate(a, env, time, initial)

    def previous(a: Expr) -> Any:
        key = f"pre({a.name})" if isinstance(a, Var) else None
        return env[key] if key is not None and key in env else value(a)

    name, args = e.name, e.args
    if name == "initial" and not args:
        return bool(env.get(INITIAL, False)) if initial is None else initial
    if name == "terminal" and not args:
        return False
    if name == "pre" and len(args) == 1:
        return previous(args[0])
    if name == "edge" and len(args) == 1:
        return bool(value(args[0])) and not bool(previous(args[0]))
    if name == "change" and len(args) == 1:
        return value(args[0]) != previous(args[0])
    if name == "sample" and len(args) >= 2:
        start, interval = float(value(args[0])), float(value(args[1]))
        k = round((time - start) / interval) if interval > 0 else -1
        return k >= 0 and abs(start + k * interval - time) <= 1e-12 * max(1.0, abs(time))
    raise NotEvaluable(f"{name}(...) has no value here")


# ------------------------------------------------------------ differentiation


def diff(e: Expr, name: str) -> Expr:
    """Partial derivative of ``e`` with respect to the variable ``name``."""
    return _diff(e, lambda v: ONE if v.name == name else ZERO, ZERO)


def time_derivative(e: Expr, varying: Callable[[str], bool] | None = None) -> Expr:
    """Total time derivative: ``x`` becomes ``der(x)``, ``time`` becomes 1.

    Variables for which ``varying(name)`` is false (parameters) have derivative 0.
    """
    if varying is None:
        return _diff(e, Der, ONE)
    return _diff(e, lambda v: Der(v) if varying(v.name) else ZERO, ONE)


def _diff(e: Expr, dvar: Callable[[Var], Expr], dtime: Expr) -> Expr:
    def d(x: Expr) -> Expr:
        return _diff(x, dvar, dtime)

    if isinstance(e, Const):
        return ZERO
    if isinstance(e, Var):
        return dvar(e)
    if isinstance(e, Time):
        return dtime
    if isinstance(e, Neg):
        return neg(d(e.arg))
    if isinstance(e, BinOp):
        return _diff_binop(e, d)
    if isinstance(e, Call):
        return _diff_call(e, d)
    if isinstance(e, If):
        return If(e.cond, d(e.then), d(e.otherwise))
    if isinstance(e, Not):
        return ZERO
    if isinstance(e, Der) and dtime == ONE:
        raise ValueError(f"second derivative der({to_text(e)}) is not supported")
    raise ValueError(f"cannot differentiate {to_text(e)}")


def _diff_binop(e: BinOp, d: Callable[[Expr], Expr]) -> Expr:
    a, b = e.left, e.right
    if e.op == "+":
        return add(d(a), d(b))
    if e.op == "-":
        return sub(d(a), d(b))
    if e.op == "*":
        return add(mul(d(a), b), mul(a, d(b)))
    if e.op == "/":
        return sub(div(d(a), b), div(mul(a, d(b)), mul(b, b)))
    if e.op == "^":
        db = d(b)
        base = mul(mul(b, power(a, sub(b, ONE))), d(a))
        if db == ZERO:
            return base
        return add(base, mul(mul(e, Call("log", (a,))), db))
    return ZERO  # relations and logic are piecewise constant


def _diff_call(e: Call, d: Callable[[Expr], Expr]) -> Expr:
    builtin = BUILTINS.get(e.name)
    if builtin is None or builtin.derivative is None:
        raise ValueError(f"cannot differentiate {e.name}(...)")
    return builtin.derivative(e, d)
