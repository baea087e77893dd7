"""Scalar expressions of the flat model and later stages.

A deliberately small, fast tree: flattening builds hundreds of thousands of these, so
they are plain frozen dataclasses rather than sympy objects (rendering as LaTeX converts
to sympy on demand, :mod:`springc.ir.latex`).

Depth: the stages recurse over these trees, so their depth is bounded. The parser
rejects source expressions nested deeper than :data:`MAX_DEPTH` (a sum of n terms is
n - 1 deep), and the CLI and API run inside :func:`recursion_room`, which gives Python
the stack that depth needs.
"""

from __future__ import annotations

import math
import sys
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, TypeVar

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


@dataclass(frozen=True, slots=True)
class Const:
    value: float | int | bool


@dataclass(frozen=True, slots=True)
class Var:
    """A flat scalar variable or parameter, by its flat name (``mass.pos[1]``)."""

    name: str


@dataclass(frozen=True, slots=True)
class Time:
    """The built-in variable ``time``."""


@dataclass(frozen=True, slots=True)
class Der:
    """``der(arg)``; after flattening ``arg`` may be any expression of variables."""

    arg: Expr


@dataclass(frozen=True, slots=True)
class Neg:
    arg: Expr


@dataclass(frozen=True, slots=True)
class Not:
    arg: Expr


@dataclass(frozen=True, slots=True)
class BinOp:
    """``op`` is one of ``+ - * / ^ < <= > >= == <> and or`` (scalar semantics)."""

    op: str
    left: Expr
    right: Expr


@dataclass(frozen=True, slots=True)
class Call:
    """A built-in scalar function (``sqrt``, ``atan2``, ``noEvent``, ...)."""

    name: str
    args: tuple[Expr, ...]


@dataclass(frozen=True, slots=True)
class If:
    cond: Expr
    then: Expr
    otherwise: Expr


Expr = Const | Var | Time | Der | Neg | Not | BinOp | Call | If

ZERO = Const(0)
ONE = Const(1)
TIME = Time()

RELATIONS = frozenset({"<", "<=", ">", ">=", "==", "<>"})

MATH: dict[str, Callable[..., float]] = {
    "sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "tan": math.tan,
    "asin": math.asin, "acos": math.acos, "atan": math.atan, "atan2": math.atan2,
    "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh, "exp": math.exp,
    "log": math.log, "log10": math.log10, "abs": abs,
    "sign": lambda x: (x > 0) - (x < 0), "min": min, "max": max,
    "floor": math.floor, "ceil": math.ceil, "integer": math.floor,
    "mod": lambda x, y: x - math.floor(x / y) * y, "rem": lambda x, y: math.fmod(x, y),
    "div": lambda x, y: math.trunc(x / y),
    "noEvent": lambda x: x, "smooth": lambda p, x: x, "homotopy": lambda a, s: a,
}

_BINARY: dict[str, Callable[[Any, Any], Any]] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "^": lambda a, b: a**b,
    "<": lambda a, b: a < b, "<=": lambda a, b: a <= b, ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b, "==": lambda a, b: a == b, "<>": lambda a, b: a != b,
    "and": lambda a, b: bool(a) and bool(b), "or": lambda a, b: bool(a) or bool(b),
}

# ------------------------------------------------------------------ traversal


def children(e: Expr) -> tuple[Expr, ...]:
    """The direct sub-expressions of ``e``."""
    if isinstance(e, BinOp):
        return (e.left, e.right)
    if isinstance(e, (Neg, Not, Der)):
        return (e.arg,)
    if isinstance(e, Call):
        return e.args
    if isinstance(e, If):
        return (e.cond, e.then, e.otherwise)
    return ()


def map_children(e: Expr, f: Callable[[Expr], Expr]) -> Expr:
    """``e`` with ``f`` applied to each direct sub-expression; ``e`` itself where every
    child comes back unchanged (unchanged subtrees are shared, not copied)."""
    old = children(e)
    new = tuple(f(c) for c in old)
    if all(a is b for a, b in zip(new, old)):
        return e
    if isinstance(e, BinOp):
        return BinOp(e.op, new[0], new[1])
    if isinstance(e, (Neg, Not, Der)):
        return type(e)(new[0])
    if isinstance(e, Call):
        return Call(e.name, new)
    assert isinstance(e, If)
    return If(new[0], new[1], new[2])


def walk(e: Expr) -> Iterator[Expr]:
    """All nodes of ``e``, parents before children."""
    stack = [e]
    while stack:
        node = stack.pop()
        yield node
        stack.extend(children(node))


def variables(e: Expr) -> set[str]:
    """Names of all variables referenced in ``e`` (inside ``der`` too)."""
    return {n.name for n in walk(e) if isinstance(n, Var)}


def derivatives(e: Expr) -> set[str]:
    """Names ``x`` of all ``der(x)`` in ``e`` whose argument is a plain variable."""
    return {n.arg.name for n in walk(e) if isinstance(n, Der) and isinstance(n.arg, Var)}


def substitute(e: Expr, mapping: Mapping[str, Expr]) -> Expr:
    """Replace variables by expressions; unchanged subtrees are shared, not copied."""
    if isinstance(e, Var):
        return mapping.get(e.name, e)
    if isinstance(e, (Const, Time)):
        return e
    if isinstance(e, BinOp):
        left, right = substitute(e.left, mapping), substitute(e.right, mapping)
        return e if left is e.left and right is e.right else BinOp(e.op, left, right)
    if isinstance(e, (Neg, Not, Der)):
        arg = substitute(e.arg, mapping)
        return e if arg is e.arg else type(e)(arg)
    if isinstance(e, Call):
        args = tuple(substitute(a, mapping) for a in e.args)
        if all(a is b for a, b in zip(args, e.args)):
            return e
        if e.name in ("pre", "edge", "change") and len(args) == 1 \
                and isinstance(args[0], Const):  # a variable found to be a constant
            return args[0] if e.name == "pre" else Const(False)
        return Call(e.name, args)
    if isinstance(e, If):
        c, t, o = (substitute(x, mapping) for x in (e.cond, e.then, e.otherwise))
        return e if (c, t, o) == (e.cond, e.then, e.otherwise) else If(c, t, o)
    raise TypeError(f"not an expression: {e!r}")


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
    if isinstance(e, Const):
        return e.value
    if isinstance(e, Var):
        return env[e.name]
    if isinstance(e, BinOp):
        return _BINARY[e.op](evaluate(e.left, env, time, initial),
                             evaluate(e.right, env, time, initial))
    if isinstance(e, Neg):
        return -evaluate(e.arg, env, time, initial)
    if isinstance(e, Not):
        return not evaluate(e.arg, env, time, initial)
    if isinstance(e, Call):
        function = MATH.get(e.name)
        if function is None:
            return _event_call(e, env, time, initial)
        return function(*(evaluate(a, env, time, initial) for a in e.args))
    if isinstance(e, If):
        branch = e.then if evaluate(e.cond, env, time, initial) else e.otherwise
        return evaluate(branch, env, time, initial)
    if isinstance(e, Time):
        return time
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


# ------------------------------------------------------------- construction


FOLD_CHUNK = 64
"""Items folded left to right before chunks are combined pairwise (see :func:`fold_chunked`)."""

_Item = TypeVar("_Item")


def fold_chunked(items: Sequence[_Item], step: Callable[[Expr, _Item], Expr],
                 combine: Callable[[Expr, Expr], Expr], identity: Expr) -> Expr:
    """``step`` folded over ``items`` from ``identity``, shallow for long runs.

    Up to :data:`FOLD_CHUNK` items this is the left fold ``((a + b) + c) + ...`` that the
    flat text shows; longer runs are folded in chunks of that size whose results are
    joined pairwise with ``combine``, so the tree stays shallow (depth about
    64 + log2(n/64)) and every later stage, which recurses over expressions, handles a
    sum of thousands of terms."""
    chunks: list[Expr] = []
    for i in range(0, len(items), FOLD_CHUNK):
        value = identity
        for item in items[i:i + FOLD_CHUNK]:
            value = step(value, item)
        chunks.append(value)
    while len(chunks) > 1:
        pairs = [combine(chunks[i], chunks[i + 1]) for i in range(0, len(chunks) - 1, 2)]
        chunks = pairs + chunks[len(chunks) - len(chunks) % 2:]
    return chunks[0] if chunks else identity


def add(a: Expr, b: Expr) -> Expr:
    """``a + b`` with constant folding and zero elimination."""
    if isinstance(a, Const) and isinstance(b, Const):
        return Const(a.value + b.value)
    if a == ZERO:
        return b
    if b == ZERO:
        return a
    if isinstance(b, Neg):
        return BinOp("-", a, b.arg)
    return BinOp("+", a, b)


def sub(a: Expr, b: Expr) -> Expr:
    if isinstance(a, Const) and isinstance(b, Const):
        return Const(a.value - b.value)
    if b == ZERO:
        return a
    if a == ZERO:
        return neg(b)
    return BinOp("-", a, b)


def mul(a: Expr, b: Expr) -> Expr:
    if isinstance(a, Const) and isinstance(b, Const):
        return Const(a.value * b.value)
    if a == ZERO or b == ZERO:
        return ZERO
    if a == ONE:
        return b
    if b == ONE:
        return a
    return BinOp("*", a, b)


def div(a: Expr, b: Expr) -> Expr:
    if b == ONE:
        return a
    if a == ZERO:
        return ZERO
    return BinOp("/", a, b)


def neg(a: Expr) -> Expr:
    if isinstance(a, Const):
        return Const(-a.value)
    if isinstance(a, Neg):
        return a.arg
    return Neg(a)


def power(a: Expr, b: Expr) -> Expr:
    if b == ONE:
        return a
    if b == ZERO:
        return ONE
    return BinOp("^", a, b)


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
    name, args = e.name, e.args
    if name in _PIECEWISE_CONSTANT:  # constant between events (section 3.7.5)
        return ZERO
    x = args[0]
    dx = d(x)
    rules: dict[str, Callable[[], Expr]] = {
        "sqrt": lambda: div(dx, mul(Const(2), e)),
        "sin": lambda: mul(Call("cos", (x,)), dx),
        "cos": lambda: neg(mul(Call("sin", (x,)), dx)),
        "tan": lambda: div(dx, power(Call("cos", (x,)), Const(2))),
        "asin": lambda: div(dx, Call("sqrt", (sub(ONE, mul(x, x)),))),
        "acos": lambda: neg(div(dx, Call("sqrt", (sub(ONE, mul(x, x)),)))),
        "atan": lambda: div(dx, add(ONE, mul(x, x))),
        "sinh": lambda: mul(Call("cosh", (x,)), dx),
        "cosh": lambda: mul(Call("sinh", (x,)), dx),
        "tanh": lambda: mul(sub(ONE, mul(e, e)), dx),
        "exp": lambda: mul(e, dx),
        "log": lambda: div(dx, x),
        "log10": lambda: div(dx, mul(x, Const(math.log(10)))),
        "abs": lambda: mul(Call("sign", (x,)), dx),
        "noEvent": lambda: Call("noEvent", (dx,)),
        "homotopy": lambda: dx,
    }
    if name in rules:
        return rules[name]()
    if name == "atan2":
        y, xx = args
        return div(sub(mul(xx, d(y)), mul(y, d(xx))), add(mul(xx, xx), mul(y, y)))
    if name in ("min", "max"):
        a, b = args
        cond = BinOp("<" if name == "min" else ">", a, b)
        return If(Call("noEvent", (cond,)), d(a), d(b))
    if name == "smooth":
        return Call("smooth", (args[0], d(args[1])))
    if name in ("sign", "floor", "ceil", "integer", "div"):
        return ZERO
    if name in ("mod", "rem"):
        return dx
    raise ValueError(f"cannot differentiate {name}(...)")


_PIECEWISE_CONSTANT = frozenset({"pre", "edge", "change", "initial", "terminal", "sample"})


# ------------------------------------------------------------------ printing

_PRECEDENCE = {
    "or": 1, "and": 2, "<": 4, "<=": 4, ">": 4, ">=": 4, "==": 4, "<>": 4,
    "+": 5, "-": 5, "*": 6, "/": 6, "^": 8,
}


def format_number(value: float | int | bool) -> str:
    """Modelica literal for a number; floats round-trip exactly (``repr``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if math.isinf(value):
        return "1e1000" if value > 0 else "-1e1000"
    return repr(value)


def to_text(e: Expr, name: Callable[[str], str] = lambda n: n) -> str:
    """Modelica text of ``e``; ``name`` renders variable names (e.g. quoting them)."""
    return _print(e, name, 0)


def _print(e: Expr, name: Callable[[str], str], outer: int) -> str:
    if isinstance(e, Const):
        text = format_number(e.value)
        return f"({text})" if text.startswith("-") and outer > 0 else text
    if isinstance(e, Var):
        return name(e.name)
    if isinstance(e, Time):
        return "time"
    if isinstance(e, Der):
        return f"der({_print(e.arg, name, 0)})"
    if isinstance(e, Call):
        return f"{e.name}({', '.join(_print(a, name, 0) for a in e.args)})"
    if isinstance(e, Neg):
        text = "-" + _print(e.arg, name, 6)
        return f"({text})" if outer > 5 else text
    if isinstance(e, Not):
        text = "not " + _print(e.arg, name, 3)
        return f"({text})" if outer > 3 else text
    if isinstance(e, If):
        text = (f"if {_print(e.cond, name, 0)} then {_print(e.then, name, 0)}"
                f" else {_print(e.otherwise, name, 0)}")
        return f"({text})" if outer > 0 else text
    prec = _PRECEDENCE[e.op]
    # Left-associative: the right operand needs parentheses at equal precedence
    # ("^" is non-associative in Modelica, so both sides do).
    left_prec = prec + 1 if e.op == "^" or prec == 4 else prec
    text = f"{_print(e.left, name, left_prec)} {e.op} {_print(e.right, name, prec + 1)}"
    return f"({text})" if prec < outer else text
