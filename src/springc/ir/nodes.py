"""The nodes of springc's scalar expressions, their traversal, construction and text.

A deliberately small, fast tree: flattening builds hundreds of thousands of these, so
they are plain frozen dataclasses rather than sympy objects. :mod:`springc.ir.expr` is
the face every stage imports (it re-exports these names with evaluation and
differentiation); this module sits below the registry of built-ins
(:mod:`springc.ir.builtins`), whose derivative rules build these nodes.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TypeVar

from .records import quick_init


@quick_init
@dataclass(frozen=True, slots=True)
class Const:
    value: float | int | bool


@quick_init
@dataclass(frozen=True, slots=True)
class Var:
    """A flat scalar variable or parameter, by its flat name (``mass.pos[1]``)."""

    name: str


@quick_init
@dataclass(frozen=True, slots=True)
class Time:
    """The built-in variable ``time``."""


@quick_init
@dataclass(frozen=True, slots=True)
class Der:
    """``der(arg)``; after flattening ``arg`` may be any expression of variables."""

    arg: Expr


@quick_init
@dataclass(frozen=True, slots=True)
class Neg:
    arg: Expr


@quick_init
@dataclass(frozen=True, slots=True)
class Not:
    arg: Expr


@quick_init
@dataclass(frozen=True, slots=True)
class BinOp:
    """``op`` is one of ``+ - * / ^ < <= > >= == <> and or`` (scalar semantics)."""

    op: str
    left: Expr
    right: Expr


@quick_init
@dataclass(frozen=True, slots=True)
class Call:
    """A built-in scalar function (``sqrt``, ``atan2``, ``noEvent``, ...)."""

    name: str
    args: tuple[Expr, ...]


@quick_init
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


def walk(e: Expr, seen: set[int] | None = None) -> Iterator[Expr]:
    """All nodes of ``e``, parents before children; a node object shared by several
    parents (inlined functions build such graphs, whose trees can be thousands of
    times larger) once, and not at all where its id is in ``seen`` (given: shared by
    several walks; variables and constants are yielded each time)."""
    stack = [e]
    seen = set() if seen is None else seen
    while stack:
        node = stack.pop()
        if type(node) is Const or type(node) is Var:
            yield node
            continue
        if id(node) in seen:
            continue
        seen.add(id(node))
        yield node
        stack.extend(children(node))


def variables(e: Expr, seen: set[int] | None = None) -> set[str]:
    """Names of all variables referenced in ``e`` (inside ``der`` too). One loop over
    the nodes, without :func:`walk`'s generator: code generation asks this of every
    binding and assignment of a large model (a third of the time it took). A node shared
    by several parents is visited once, as :func:`walk` does; ``seen`` (node ids) shared
    by several calls visits a node once over all of them (its variables counted at its
    first visit only)."""
    out: set[str] = set()
    if seen is None:
        seen = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if type(node) is Var:
            out.add(node.name)
            continue
        if type(node) is Const or type(node) is Time:
            continue
        if id(node) in seen:
            continue
        seen.add(id(node))
        if type(node) is BinOp:
            stack += (node.left, node.right)
        elif type(node) is Call:
            stack += node.args
        elif type(node) is If:
            stack += (node.cond, node.then, node.otherwise)
        elif type(node) is Neg or type(node) is Not or type(node) is Der:
            stack.append(node.arg)
    return out


def calls_named(roots: list[Expr], name: str, out: dict[Call, None] | None = None) -> bool:
    """Whether ``roots`` call the function ``name`` (stopping at the first call), or,
    with ``out``, every such call added to ``out`` in :func:`walk`'s order (and whether
    there was one). One loop without :func:`walk`'s generator: the stages ask this of
    every equation, and few hold a call. A node shared by several parents is visited
    once."""
    stack: list[Expr] = list(roots)
    seen: set[int] = set()
    found = False
    while stack:
        node = stack.pop()
        kind = type(node)
        if kind is Var or kind is Const or id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, BinOp):
            stack += (node.left, node.right)
            continue
        if isinstance(node, Call) and node.name == name:
            if out is None:
                return True
            out.setdefault(node, None)
            found = True
        stack.extend(children(node))
    return found


def derivatives(e: Expr) -> set[str]:
    """Names ``x`` of all ``der(x)`` in ``e`` whose argument is a plain variable."""
    return {n.arg.name for n in walk(e) if isinstance(n, Der) and isinstance(n.arg, Var)}


def substitute(e: Expr, mapping: Mapping[str, Expr]) -> Expr:
    """Replace variables by expressions; unchanged subtrees are shared, not copied, and
    a subtree shared by several parents is rewritten once (the result shares it too)."""
    return _substitute(e, mapping, {}, False)


def substitute_at_event(e: Expr, mapping: Mapping[str, Expr]) -> Expr:
    """:func:`substitute` of the values assigned so far at an event (an algorithm's
    statements): ``pre(v)`` is the value before the event and keeps ``v``; ``edge(v)``
    and ``change(v)`` of a replaced ``v`` are spelled out with it (spec 3.7.5)."""
    return _substitute(e, mapping, {}, True)


def _substitute(e: Expr, mapping: Mapping[str, Expr], memo: dict[int, tuple[Expr, Expr]],
                held: bool) -> Expr:
    if isinstance(e, Var):
        return mapping.get(e.name, e)
    if isinstance(e, (Const, Time)):
        return e
    found = memo.get(id(e))
    if found is not None and found[0] is e:
        return found[1]
    out = _substitute_node(e, mapping, memo, held)
    memo[id(e)] = (e, out)
    return out


def _substitute_node(e: Expr, mapping: Mapping[str, Expr],
                     memo: dict[int, tuple[Expr, Expr]], held: bool) -> Expr:
    if isinstance(e, BinOp):
        left = _substitute(e.left, mapping, memo, held)
        right = _substitute(e.right, mapping, memo, held)
        return e if left is e.left and right is e.right else BinOp(e.op, left, right)
    if isinstance(e, (Neg, Not, Der)):
        arg = _substitute(e.arg, mapping, memo, held)
        return e if arg is e.arg else type(e)(arg)
    if isinstance(e, Call):
        if held and e.name in ("pre", "edge", "change") and len(e.args) == 1 \
                and isinstance(e.args[0], Var):
            return _held_call(e, e.args[0], mapping)
        args = tuple(_substitute(a, mapping, memo, held) for a in e.args)
        if all(a is b for a, b in zip(args, e.args)):
            return e
        if e.name in ("pre", "edge", "change") and len(args) == 1 \
                and isinstance(args[0], Const):  # a variable found to be a constant
            return args[0] if e.name == "pre" else Const(False)
        return Call(e.name, args)
    if isinstance(e, If):
        c, t, o = (_substitute(x, mapping, memo, held) for x in (e.cond, e.then, e.otherwise))
        return e if (c, t, o) == (e.cond, e.then, e.otherwise) else If(c, t, o)
    raise TypeError(f"not an expression: {e!r}")


def _held_call(e: Call, v: Var, mapping: Mapping[str, Expr]) -> Expr:
    """``pre(v)``, ``edge(v)`` or ``change(v)`` where ``v`` may have a new value."""
    now = mapping.get(v.name)
    if e.name == "pre" or now is None:
        return e
    before = Call("pre", (v,))
    return BinOp("and", now, Not(before)) if e.name == "edge" else BinOp("<>", now, before)

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
    if a == ZERO and b != ZERO:  # 0/0 stays, to be refused where it is evaluated
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
