"""Statements of generated functions (:mod:`.statements`) -> Python source lines.

After dead-code removal (``statements.prune``) this module finds common
subexpressions by hash-consing the frozen expression trees, and prints everything as
Python that runs unchanged under plain CPython (``math``/numpy) and under
``numba.njit``.

Printing follows sympy's printers: one ``_print_<Node>`` method per expression class,
helpers collected while printing, unsupported nodes refused explicitly.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence

from ..ir.builtins import BUILTINS, PYTHON_HELPERS
from ..ir.expr import BinOp, Call, Const, Expr, If, Neg, Not, Time, Var, variables
from ..native.foreign_calls import HELPER, OUTPUT, REFUSAL, function_of, is_foreign
from .linear_cache import LINEAR_FACTORS
from .locate import untranslatable
from .newton_step import NEWTON_SOLVE
from .statements import (
    Block,
    Guard,
    Let,
    Load,
    Loop,
    Raw,
    Stmt,
    Store,
    defines_inside,
    escaped,
    prune,
)

# ------------------------------------------------------------------ printing

_PREC = {"or": 1, "and": 2, "<": 4, "<=": 4, ">": 4, ">=": 4, "==": 4, "<>": 4,
         "+": 5, "-": 5, "*": 6, "/": 6, "^": 8}
_PY_OP = {"<>": "!=", "^": "**"}
HELPERS = {**PYTHON_HELPERS, "_newton_solve": NEWTON_SOLVE, "_linear_factors": LINEAR_FACTORS,
           "_foreign": HELPER}
"""The helper functions a generated module defines when it calls them (the registry's
and the Newton correction of torn blocks, which a :class:`Raw` line calls)."""


def _spelled(spelling: str, args: str) -> str:
    """A call in a printer's spelling: ``math.sqrt`` or a ``{}`` template."""
    return spelling.format(args) if "{}" in spelling else f"{spelling}({args})"


def _trivial(e: Expr) -> bool:
    return isinstance(e, (Const, Var, Time)) or (
        isinstance(e, Neg) and isinstance(e.arg, (Const, Var)))


class FunctionWriter:
    """Prints one function body; shares subexpressions that occur more than once.

    Counting walks every statement's expressions once, on canonical (hash-consed)
    node ids, and never descends into the branches of ``if``-expressions, so shared
    values are only hoisted where they are evaluated anyway. A shared value is
    assigned to a temporary right before its first use; it is forgotten when a
    variable it reads is reassigned or when the loop that computed it ends.
    """

    def __init__(self, namer: Callable[[str], str], helpers: set[str],
                 indent: str = "    ") -> None:
        self.name = namer
        self.helpers = helpers
        self.lines: list[str] = []
        self._canon: dict[int, tuple[int, Expr]] = {}
        self._keys: dict[tuple[object, ...], int] = {}
        self._count: list[int] = []
        self._temps: dict[int, str] = {}
        # which remembered values read a name, which a local holds: forgetting them on
        # a reassignment costs what they are, not the number of temporaries
        self._readers: dict[str, set[int]] = {}
        self._holders: dict[str, set[int]] = {}
        self._scopes: list[set[int]] = [set()]
        self._in_branch = 0
        self._indent = indent
        self._calls: dict[int, str] = {}  # run-time foreign calls: their local functions

    # Step 1: canonical ids and use counts.
    def _id(self, e: Expr) -> int:
        hit = self._canon.get(id(e))
        if hit is not None:
            return hit[0]
        if isinstance(e, Const):
            key: tuple[object, ...] = ("C", type(e.value).__name__, repr(e.value))
        elif isinstance(e, Var):
            key = ("V", e.name)
        elif isinstance(e, Time):
            key = ("T",)
        elif isinstance(e, (Neg, Not)):
            key = (type(e).__name__, self._id(e.arg))
        elif isinstance(e, BinOp):
            key = ("B", e.op, self._id(e.left), self._id(e.right))
        elif isinstance(e, Call):
            key = ("F", e.name, *(self._id(a) for a in e.args))
        elif isinstance(e, If):
            key = ("I", self._id(e.cond), self._id(e.then), self._id(e.otherwise))
        else:
            raise untranslatable(f"cannot generate code for {type(e).__name__} expressions", e)
        cid = self._keys.get(key)
        if cid is None:
            cid = len(self._count)
            self._keys[key] = cid
            self._count.append(0)
        self._canon[id(e)] = (cid, e)
        return cid

    def _visit(self, e: Expr) -> None:
        stack = [e]
        while stack:
            node = stack.pop()
            cid = self._id(node)
            self._count[cid] += 1
            if self._count[cid] > 1:
                continue
            if isinstance(node, If):
                stack.append(node.cond)
            elif isinstance(node, BinOp):
                stack += (node.left, node.right)
            elif isinstance(node, (Neg, Not)):
                stack.append(node.arg)
            elif isinstance(node, Call):
                stack.extend(node.args)

    def count(self, stmts: Sequence[Stmt]) -> None:
        for e in _exprs(stmts):
            self._visit(e)

    # Step 2: printing.
    def write(self, stmts: Sequence[Stmt]) -> None:
        for stmt in stmts:
            self._stmt(stmt)

    # Hooks of the target language (a C writer overrides them: codegen/c_printer.py).
    block_end: str | None = None  # the line that closes a loop's body (C: "}")

    def _emit(self, text: str, comment: str = "") -> None:
        line = self._indent + text
        if comment:
            line += "  # " + escaped(comment)
        self.lines.append(line)

    def _assign(self, target: str, text: str, comment: str = "") -> None:
        self._emit(f"{target} = {text}", comment)

    def _comment(self, text: str) -> None:
        self._emit("# " + escaped(text))

    def _stmt(self, stmt: Stmt) -> None:
        if isinstance(stmt, Let):
            cid = self._id(stmt.expr)
            if (self._count[cid] > 1 and cid not in self._temps
                    and not _trivial(stmt.expr)):
                # The whole right-hand side is shared: the variable itself holds it.
                text, _ = self._print(stmt.expr)
                self._reassigned(stmt.name)
                ident = self.name(stmt.name)
                self._assign(ident, text, stmt.comment)
                self._remember(cid, ident, stmt.expr)
                return
            text = self.expr(stmt.expr)
            self._reassigned(stmt.name)
            self._assign(self.name(stmt.name), text, stmt.comment)
        elif isinstance(stmt, Load):
            self._reassigned(stmt.name)
            self._assign(self.name(stmt.name), stmt.source, stmt.comment)
        elif isinstance(stmt, Store):
            self._assign(stmt.target, self.expr(stmt.expr), stmt.comment)
        elif isinstance(stmt, Raw):
            if "_newton_solve(" in stmt.text:
                self.helpers.add("_newton_solve")
            if "_linear_factors(" in stmt.text:
                self.helpers.add("_linear_factors")
            for line in stmt.text.splitlines():
                self._emit(line)
        elif isinstance(stmt, Block):
            if stmt.comment:
                self._comment(stmt.comment)
            self.write(stmt.body)
        elif isinstance(stmt, Guard):
            self._nested(self.guard_header(self.expr(stmt.cond, 1)), stmt.body)
        else:
            for name in sorted(defines_inside(stmt.body)):  # set order varies by run
                self._reassigned(name)
            self._nested(stmt.header, stmt.body)

    def guard_header(self, cond: str) -> str:
        """The line that opens a :class:`Guard`'s body (C: ``if (cond) {``)."""
        return f"if {cond}:"

    def _nested(self, header: str, body: Sequence[Stmt]) -> None:
        """``header`` and ``body`` indented below it; the shared values computed in
        the body (and the run-time calls defined there) are forgotten after it."""
        self._emit(header)
        outer = self._indent
        self._indent += "    "
        self._scopes.append(set())
        self.write(body)
        for cid in self._scopes.pop():
            self._temps.pop(cid, None)
            self._calls.pop(cid, None)
        self._indent = outer
        if self.block_end is not None:
            self._emit(self.block_end)

    def _reassigned(self, name: str) -> None:
        ident = self.name(name)
        for cid in self._readers.pop(name, set()):
            self._temps.pop(cid, None)
            self._calls.pop(cid, None)
        for cid in self._holders.pop(ident, set()):
            if self._temps.get(cid) == ident:
                del self._temps[cid]

    def _remember(self, cid: int, name: str, e: Expr) -> None:
        self._temps[cid] = name
        for v in variables(e):
            self._readers.setdefault(v, set()).add(cid)
        self._holders.setdefault(name, set()).add(cid)
        self._scopes[-1].add(cid)

    def expr(self, e: Expr, outer: int = 0) -> str:
        """Python text of ``e``; shared subexpressions become temporaries."""
        text, prec = self._shared(e)
        return f"({text})" if prec < outer else text

    def _shared(self, e: Expr) -> tuple[str, int]:
        cid = self._id(e)
        if cid in self._temps:
            return self._temps[cid], 9
        text, prec = self._print(e)
        if self._count[cid] > 1 and not _trivial(e) and not self._in_branch:
            name = f"_c{cid}"
            self._assign(name, text)
            self._remember(cid, name, e)
            return name, 9
        return text, prec

    def _print(self, e: Expr) -> tuple[str, int]:
        method: Callable[[Expr], tuple[str, int]] | None = getattr(
            self, "_print_" + type(e).__name__, None)
        if method is None:
            raise untranslatable(f"cannot generate code for {type(e).__name__} expressions", e)
        return method(e)

    def _print_Const(self, e: Const) -> tuple[str, int]:
        v = e.value
        if isinstance(v, bool):
            return ("True" if v else "False"), 9
        if isinstance(v, float) and not math.isfinite(v):
            text = "math.nan" if math.isnan(v) else ("math.inf" if v > 0 else "-math.inf")
        else:
            text = repr(v)
        return text, (7 if text.startswith("-") else 9)

    def _print_Var(self, e: Var) -> tuple[str, int]:
        return self.name(e.name), 9

    def _print_Time(self, e: Time) -> tuple[str, int]:
        return "t", 9

    def _print_Neg(self, e: Neg) -> tuple[str, int]:
        return "-" + self.expr(e.arg, 7), 7

    def _print_Not(self, e: Not) -> tuple[str, int]:
        return "not " + self.expr(e.arg, 3), 3

    def _print_BinOp(self, e: BinOp) -> tuple[str, int]:
        op = e.op
        if op == "^" and not _integer_power(e.right):
            return f"math.pow({self.expr(e.left)}, {self.expr(e.right)})", 9
        prec = _PREC[op]
        if op == "^":
            left, right = self.expr(e.left, 9), self.expr(e.right, 9)
        elif prec == 4:
            left, right = self.expr(e.left, 5), self.expr(e.right, 5)
        else:
            left, right = self.expr(e.left, prec), self.expr(e.right, prec + 1)
        return f"{left} {_PY_OP.get(op, op)} {right}", prec

    foreign_calls = True
    """Whether this printer calls a library's C functions at run time (python only);
    where not, the refusal names ``writes``."""
    writes = "this printer"

    def _print_Call(self, e: Call) -> tuple[str, int]:
        if is_foreign(e.name):
            return self._foreign_output(e), 9
        builtin = BUILTINS.get(e.name)
        if builtin is not None and builtin.transparent is not None:
            return self._shared(e.args[builtin.transparent])
        spelling = self._spelling(e)
        args = ", ".join(self.expr(a) for a in self._operands(e, spelling))
        if spelling in HELPERS:
            self.helpers.add(spelling)
        return _spelled(spelling, args), 9

    def _operands(self, e: Call, spelling: str) -> list[Expr]:
        """The arguments of ``e``; Python's ``max``/``min`` of a left fold of the same
        call (``max(max(a, b), c)``) take its operands at once, in order (the same
        comparisons; a fold of 400 would pass Python's limit of nested parentheses)."""
        if spelling not in ("max", "min") or len(e.args) != 2:
            return list(e.args)
        out = [e.args[1]]
        head: Expr = e.args[0]
        while (isinstance(head, Call) and head.name == e.name and len(head.args) == 2
               and self._id(head) not in self._temps):
            out.append(head.args[1])
            head = head.args[0]
        out.append(head)
        out.reverse()
        return out

    def _foreign_output(self, e: Call) -> str:
        """``_fcallN()[slot][index]``: an element of a run-time foreign call's outputs.
        The call's arguments are computed by a local function defined before the
        statement, the values of the variables they read bound then (its default
        arguments): they are printed once, whichever elements are read, and computed
        only where an element is (a when-clause's branch), once per definition; it is
        defined again after the loop that defined it ends or one of those variables is
        assigned."""
        call = e.args[2] if e.name == OUTPUT else e
        assert isinstance(call, Call), call
        if not self.foreign_calls:
            raise untranslatable(REFUSAL.format(self.writes, function_of(call.name)), e)
        slot, index = (e.args[0], e.args[1]) if e.name == OUTPUT else (Const(0), Const(0))
        cid = self._id(call)
        function = self._calls.get(cid)
        if function is None:
            function = self._calls[cid] = f"_fcall{cid}"
            inner = type(self)(self.name, self.helpers, self._indent + "    ")
            for arg in call.args:
                inner._visit(arg)
            texts = [inner.expr(arg) for arg in call.args]
            read = sorted(variables(call))
            for v in read:  # defined again after any of them is assigned
                self._readers.setdefault(v, set()).add(cid)
            bound = [f"{n}={n}" for n in map(self.name, read) if n.isidentifier()]
            # its arguments are fixed when it is defined: computed once (_memo)
            self._emit(f"def {function}({', '.join([*bound, '_memo=[]'])}):")
            self._emit("    if _memo:")
            self._emit("        return _memo[0]")
            self.lines += inner.lines
            self._emit(f"    _memo.append(_foreign({call.name!r}, "
                       f"({''.join(text + ', ' for text in texts)})))")
            self._emit("    return _memo[0]")
            self.helpers.add("_foreign")
            self._scopes[-1].add(cid)
        return f"{function}()[{slot.value!r}][{index.value!r}]" \
            if isinstance(slot, Const) and isinstance(index, Const) else function + "()"

    def _spelling(self, e: Call) -> str:
        """How this printer calls the built-in of ``e`` (the registry's ``python``)."""
        builtin = BUILTINS.get(e.name)
        if builtin is None or builtin.python is None:
            raise untranslatable(f"cannot generate code for the function '{e.name}'", e)
        return builtin.python

    def _print_If(self, e: If) -> tuple[str, int]:
        cond = self.expr(e.cond, 1)
        self._in_branch += 1
        try:
            then, other = self.expr(e.then, 1), self.expr(e.otherwise, 1)
        finally:
            self._in_branch -= 1
        return f"{then} if {cond} else {other}", 0


def _integer_power(e: Expr) -> bool:
    value = e.arg.value if isinstance(e, Neg) and isinstance(e.arg, Const) else (
        e.value if isinstance(e, Const) else None)
    return (isinstance(value, int) and not isinstance(value, bool)) or (
        isinstance(value, float) and value.is_integer() and abs(value) < 64)


def _exprs(stmts: Sequence[Stmt]) -> Iterator[Expr]:
    for s in stmts:
        if isinstance(s, (Let, Store)):
            yield s.expr
        elif isinstance(s, Guard):
            yield s.cond
            yield from _exprs(s.body)
        elif isinstance(s, (Loop, Block)):
            yield from _exprs(s.body)


def function_lines(namer: Callable[[str], str], helpers: set[str], stmts: Sequence[Stmt],
                   indent: str = "    ", writer_class: type[FunctionWriter] | None = None
                   ) -> list[str]:
    """The indented body of a function computing ``stmts`` (after dead-code removal)."""
    writer = (writer_class or FunctionWriter)(namer, helpers, indent)
    kept = prune(stmts)
    writer.count(kept)
    writer.write(kept)
    return writer.lines


class NumpyWriter(FunctionWriter):
    """Prints expressions over numpy arrays: ufuncs, ``np.where``, logical functions."""

    foreign_calls = False
    writes = "the vector layout"

    def _spelling(self, e: Call) -> str:
        builtin = BUILTINS.get(e.name)
        if builtin is None or builtin.numpy is None:
            raise untranslatable(f"cannot generate code for the function '{e.name}'", e)
        return builtin.numpy

    def _print_BinOp(self, e: BinOp) -> tuple[str, int]:
        if e.op in ("and", "or"):
            fn = "logical_and" if e.op == "and" else "logical_or"
            return f"np.{fn}({self.expr(e.left)}, {self.expr(e.right)})", 9
        if e.op == "^":
            return f"np.power({self.expr(e.left)}, {self.expr(e.right)})", 9
        return super()._print_BinOp(e)

    def _print_Not(self, e: Not) -> tuple[str, int]:
        return f"np.logical_not({self.expr(e.arg)})", 9

    def _print_If(self, e: If) -> tuple[str, int]:
        return (f"np.where({self.expr(e.cond)}, {self.expr(e.then)}, "
                f"{self.expr(e.otherwise)})", 9)
