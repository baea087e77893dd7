"""The statements of generated functions, the names they use, and dead-code removal.

The code generator describes each generated function as a list of small statements
over flat names (:class:`Let`, :class:`Store`, :class:`Load`, :class:`Raw`, grouped in
:class:`Block`, :class:`Loop` and :class:`Guard`); :mod:`.printer` prints them. Model names become
Python identifiers only through :class:`Namer` and reach comments only through
:func:`escaped`: model text is data, never code.
"""

from __future__ import annotations

import builtins
import keyword
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from ..ir.builtins import BUILTINS
from ..ir.expr import BinOp, Call, Der, Expr, If, Neg, Not, variables

# ------------------------------------------------------------------ statements


@dataclass
class Let:
    """``name = expr`` (``name`` a flat or internal name), with a trailing comment."""

    name: str
    expr: Expr
    comment: str = ""


@dataclass
class Load:
    """``name = source`` where ``source`` is Python text such as ``x[3]``."""

    name: str
    source: str
    comment: str = ""


@dataclass
class Store:
    """``target = expr`` where ``target`` is Python text such as ``dx[3]``."""

    target: str
    expr: Expr
    comment: str = ""


@dataclass
class Raw:
    """A line of Python that refers only to internal names (``_A1 = np.zeros(...)``)."""

    text: str


@dataclass
class Loop:
    """``header`` (e.g. ``for _it in range(50):``) with an indented body."""

    header: str
    body: list[Stmt]


@dataclass
class Block:
    """Statements kept or dropped together (a linear or nonlinear system)."""

    body: list[Stmt]
    comment: str = ""
    defines: set[str] = field(default_factory=set)
    uses: set[str] = field(default_factory=set)


@dataclass
class Guard:
    """``if cond:`` with an indented body: statements that run only where ``cond``
    holds (a when-clause's branch: its assignments under one condition, the values
    they share computed once inside it). A name the body assigns keeps its value
    before the guard where ``cond`` is false."""

    cond: Expr
    body: list[Stmt]


Stmt = Let | Load | Store | Raw | Loop | Block | Guard


def guarded(cond: Expr, lets: Sequence[Let]) -> Guard:
    """``lets`` (run in order) where ``cond`` holds, as one :class:`Guard`; a run of
    them whose values are if-expressions on one condition that none of them assigns
    becomes two guards, that condition's and its negation's, each holding its
    branches (recursively): the values the branches share (the amplitudes an FFT's
    phases all compare with) are then computed once instead of once per value."""
    return Guard(cond, _split(lets))


def _split(lets: Sequence[Let]) -> list[Stmt]:
    out: list[Stmt] = []
    i = 0
    while i < len(lets):
        first = _test(lets[i].expr)
        end = i
        if isinstance(first, If):
            while end < len(lets) and _same_test(_test(lets[end].expr), first.cond):
                end += 1
        if end - i > 1:  # the run ends before a value of the test is assigned
            reads = variables(first.cond)  # type: ignore[union-attr]
            end = next((k for k in range(i, end) if lets[k].name in reads), end)
        if end - i < 2:
            out.append(lets[i])
            i += 1
            continue
        run = [(let, e) for let in lets[i:end] if isinstance(e := _test(let.expr), If)]
        test = run[0][1].cond
        out.append(Guard(test, _split([Let(let.name, e.then, let.comment) for let, e in run])))
        out.append(Guard(Not(test), _split(
            [Let(let.name, e.otherwise, let.comment) for let, e in run])))
        i = end
    return out


def _test(e: Expr) -> Expr:
    """``e`` without the calls printed as their argument (``noEvent``) and the
    if-expressions whose branches are one node."""
    while True:
        if isinstance(e, Call) and e.name in BUILTINS \
                and BUILTINS[e.name].transparent is not None:
            e = e.args[BUILTINS[e.name].transparent]  # type: ignore[index]
        elif isinstance(e, If) and e.then is e.otherwise:
            e = e.then
        else:
            return e


def _same_test(e: Expr, cond: Expr) -> bool:
    """Whether ``e`` is an if-expression on ``cond``: the same node, or an equal one
    of a few nodes (an equality of large shared trees would walk them as trees)."""
    return isinstance(e, If) and (e.cond is cond or (
        _small(cond) and _small(e.cond) and e.cond == cond))


def _small(e: Expr, limit: int = 64) -> bool:
    stack = [e]
    while stack:
        limit -= 1
        if limit < 0:
            return False
        node = stack.pop()
        if isinstance(node, If):
            stack += (node.cond, node.then, node.otherwise)
        elif isinstance(node, Call):
            stack += node.args
        elif isinstance(node, BinOp):
            stack += (node.left, node.right)
        elif isinstance(node, (Neg, Not, Der)):
            stack.append(node.arg)
    return True


def guarded_solve(result: str, matrix: str, rhs: str, shape: str) -> str:
    """``result = np.linalg.solve(matrix, rhs)``, or NaN where an entry is NaN or
    infinite: numba's solve raises on those inside the compiled loop, while NaN
    derivatives are a failure the loops report with the time and the states."""
    return (f"{result} = np.linalg.solve({matrix}, {rhs}) if np.isfinite({matrix}).all() "
            f"and np.isfinite({rhs}).all() else np.full({shape}, np.nan)")


# ------------------------------------------------------------------ names

# Every identifier the module templates define or use (locals, loop variables, module
# functions, constants and imports): model names must never shadow them.
_RESERVED = frozenset({
    "t", "x", "p", "z", "dx", "jv", "np", "math", "njit", "out", "abs", "min", "max",
    "float", "int", "range", "len", "bool", "values", "numba", "scipy", "base64", "zlib",
    "json", "fixed",
    "x0", "n", "i", "j", "k", "v", "ts", "given", "unknown", "name", "X",
    "parameters", "start", "guesses", "rhs", "observed", "observed_grid", "jacobian",
    "jacobian_values", "jacobian_dense", "sparsity", "MODEL", "BACKEND", "CODEGEN_VERSION",
    "STATES", "STATE_UNITS", "DERIVATIVES", "PARAMETERS", "PARAMETER_UNITS",
    "PARAMETER_TYPES", "STRUCTURAL", "OBSERVED", "OBSERVED_UNITS", "GUESSES",
    "NEWTON_SYSTEMS", "EXPERIMENT", "INITIAL_CONDITIONS", "SWITCHABLE", "WARNINGS", "KIND",
    "DESCRIPTIONS", "JAC_ROWS", "JAC_COLS", "JAC_INDICES", "JAC_INDPTR", "ASSERTIONS",
    "assertions", "ok",
}) | frozenset(keyword.kwlist) | frozenset(dir(builtins))


# Internal names of the generated code (``_A3``, ``_r2_0``, ``_it``, ``_FS``): ASCII
# identifiers that start with ``_``, used verbatim.
_INTERNAL = re.compile(r"_[A-Za-z]+[0-9]*(?:_[0-9]+)?\Z")
# The internal names that statements bind through the namer (Newton residuals, steps,
# convergence flags, pivots; the Newton search's base points, step lengths, norms and
# flags): a model variable of the same name would be the same string in the
# statements, so such model names are refused (see reserved_name).
_BOUND_INTERNAL = re.compile(r"_(?:r|d|done|J|base|warm|lam|nr|ls)[0-9]+(?:_[0-9]+)?\Z")


def reserved_name(names: Iterable[str]) -> str | None:
    """The first of ``names`` that the generated code binds itself, if any."""
    return next((n for n in sorted(names) if _BOUND_INTERNAL.match(n)), None)


def escaped(text: str) -> str:
    """``text`` as one line of ASCII that cannot end a comment or a docstring: control
    and non-ASCII characters, backslashes and double quotes escaped as in a literal."""
    return text.encode("unicode_escape").decode("ascii").replace('"', '\\"')


class Namer:
    """Flat names -> Python identifiers: ``mass.pos[1]`` -> ``mass_pos_1``.

    Internal names (``_INTERNAL``) are used verbatim. Model names are sanitized into
    ASCII identifiers that never start with ``_``, so the two never collide; a model
    name that looks internal (Modelica allows ``_x``) is sanitized too.
    """

    def __init__(self, model_names: Iterable[str] = (), reserved: Iterable[str] = (),
                 reserved_prefix: str = "") -> None:
        self.model_names = frozenset(model_names)
        self._ident: dict[str, str] = {}
        # ``reserved``: further identifiers of another target language (C's keywords);
        # a name starting with ``reserved_prefix`` (any case) gets ``v_`` in front
        self._used: set[str] = set(_RESERVED) | set(reserved)
        self._prefix = reserved_prefix.lower()

    def __call__(self, name: str) -> str:
        ident = self._ident.get(name)
        if ident is None:
            ident = name if self.internal(name) else self._fresh(name)
            self._ident[name] = ident
        return ident

    def internal(self, name: str) -> bool:
        """Whether ``name`` is one of the generator's own names (used verbatim)."""
        return name not in self.model_names and _INTERNAL.match(name) is not None

    def _fresh(self, name: str) -> str:
        base = re.sub(r"[^0-9A-Za-z]+", "_", name).strip("_") or "v"
        if base[0].isdigit() or (self._prefix and base.lower().startswith(self._prefix)):
            base = "v_" + base
        ident, n = base, 1
        while ident in self._used:
            n += 1
            ident = f"{base}_{n}"
        self._used.add(ident)
        return ident


# ------------------------------------------------------------------ dead code


def uses_of(stmt: Stmt) -> set[str]:
    """Flat and internal names read by ``stmt`` (minus those a block defines itself)."""
    if isinstance(stmt, (Let, Store)):
        return variables(stmt.expr)
    if isinstance(stmt, (Load, Raw)):
        return set()
    if isinstance(stmt, Guard):
        return variables(stmt.cond) | _sequential_uses(stmt.body)
    body = stmt.body
    used: set[str] = set()
    for s in body:
        used |= uses_of(s)
    extra = stmt.uses if isinstance(stmt, Block) else set()
    return (used - defines_inside(body)) | extra


def _sequential_uses(body: Sequence[Stmt]) -> set[str]:
    """Names ``body`` reads before it assigns them itself (in order). Its expressions
    share nodes (the values of one when-clause): each node is visited once, and the
    names a node reads count where it is first read (``bound`` only grows)."""
    used: set[str] = set()
    bound: set[str] = set()
    seen: set[int] = set()
    for s in body:
        read = variables(s.expr, seen) if isinstance(s, (Let, Store)) else uses_of(s)
        used |= read - bound
        if isinstance(s, (Let, Load)):
            bound.add(s.name)
    return used


def defines_inside(body: Sequence[Stmt]) -> set[str]:
    """Names bound anywhere inside ``body`` (nested loops and blocks included)."""
    out: set[str] = set()
    for s in body:
        if isinstance(s, (Let, Load)):
            out.add(s.name)
        elif isinstance(s, (Loop, Block, Guard)):
            out |= defines_inside(s.body)
    return out


def defines_of(stmt: Stmt) -> set[str]:
    """Names ``stmt`` makes available to the statements after it."""
    if isinstance(stmt, (Let, Load)):
        return {stmt.name}
    if isinstance(stmt, Block):
        return stmt.defines or defines_inside(stmt.body)
    if isinstance(stmt, (Loop, Guard)):
        return defines_inside(stmt.body)
    return set()


def prune(stmts: Sequence[Stmt]) -> list[Stmt]:
    """Drop top-level statements whose results are never read (stores are kept)."""
    live: set[str] = set()
    kept: list[Stmt] = []
    for stmt in reversed(stmts):
        defines = defines_of(stmt)
        if isinstance(stmt, (Let, Load, Block)) and not defines & live:
            continue
        if isinstance(stmt, Guard) and not defines & live and all(
                isinstance(s, (Let, Load)) for s in stmt.body):
            continue  # assigns only names nobody reads
        live -= defines if isinstance(stmt, (Let, Load)) else set()
        live |= uses_of(stmt)
        kept.append(stmt)
    kept.reverse()
    return kept
