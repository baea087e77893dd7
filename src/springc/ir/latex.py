"""Expressions and equations -> LaTeX, through sympy: ``springc flatten --latex`` and the
``_repr_latex_`` of :class:`~springc.ir.flat.FlatModel` and :class:`~springc.ir.ode.ODE`.

springc's own tree (:mod:`springc.ir.expr`) is converted to sympy only here, and sympy is
imported only when something is rendered, so that ``import springc`` and ``springc
check`` stay free of it. sympy evaluates while converting (``x + x`` shows as ``2 x``,
constants fold): the rendering is for reading, the Modelica text stays the reference.

Names: a flat name is set upright with its last subscript lowered,
``mass.pos[1]`` -> ``\\mathrm{mass.pos}_{1}``; one-letter names stay italic (``x``);
``der(x)``, as written in the flat model or named so by simplification, is ``\\dot{x}``;
``time`` is ``t``.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from typing import Any

from . import expr as x
from .builtins import BUILTINS

__all__ = ["NOTEBOOK_ROWS", "align", "latex_name", "notebook", "to_latex", "to_sympy"]

NOTEBOOK_ROWS = 500
"""A notebook shows models of at most this many equations as LaTeX (larger ones as
text: converting and typesetting them would take minutes)."""

_DERIVATIVE = re.compile(r"der\((.*)\)\Z", re.S)
_DOTS = {1: r"\dot", 2: r"\ddot", 3: r"\dddot"}
_LAST_SUBSCRIPT = re.compile(r"(.*?)\[([^\[\]]*)\]\Z", re.S)
_LATEX_SPECIAL = {
    "\\": r"\textbackslash{}", "{": r"\{", "}": r"\}", "$": r"\$", "&": r"\&",
    "#": r"\#", "%": r"\%", "_": r"\_", "^": r"\hat{}", "~": r"\tilde{}",
}


def _escape(text: str) -> str:
    return "".join(_LATEX_SPECIAL.get(c, c) for c in text)


def _upright(text: str) -> str:
    if len(text) == 1 and text.isalpha() and text.isascii():
        return text
    return r"\mathrm{" + _escape(text) + "}"


def latex_name(name: str) -> str:
    """LaTeX for a flat name: ``mass.pos[1]`` -> ``\\mathrm{mass.pos}_{1}``,
    ``der(mass.v[1])`` -> ``\\dot{\\mathrm{mass.v}}_{1}``, ``der(der(x))`` -> ``\\ddot{x}``,
    ``x`` -> ``x``."""
    order, base = 0, name  # der(x), der(der(x)): the names simplification gives x', x''
    while derivative := _DERIVATIVE.match(base):
        order, base = order + 1, derivative.group(1)
    indexed = _LAST_SUBSCRIPT.match(base)
    stem, index = (indexed.group(1), indexed.group(2)) if indexed else (base, None)
    text = _upright(stem) if stem else ""
    if order:
        text = (_DOTS[order] + "{" + text + "}" if order in _DOTS
                else "{" + text + "}^{(" + str(order) + ")}")
    if index is not None:
        text += "_{" + _escape(index.replace(" ", "")) + "}"
    return text


class _Converter:
    """Builds sympy expressions from :mod:`springc.ir.expr` trees, sharing symbols."""

    def __init__(self) -> None:
        import sympy  # type: ignore[import-untyped]

        self.sp = sympy
        self.time = sympy.Dummy("t")
        self.names: dict[Any, str] = {self.time: "t"}
        self.symbols: dict[str, Any] = {}
        relations = {"<": sympy.Lt, "<=": sympy.Le, ">": sympy.Gt, ">=": sympy.Ge,
                     "==": sympy.Eq, "<>": sympy.Ne}
        self.binary: dict[str, Any] = {
            "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
            "/": lambda a, b: a / b, "^": lambda a, b: a**b,
            "and": sympy.And, "or": sympy.Or, **relations,
        }

    def symbol(self, name: str) -> Any:
        if name not in self.symbols:
            sym = self.symbols[name] = self.sp.Symbol(name)
            self.names[sym] = latex_name(name)
        return self.symbols[name]

    def convert(self, e: x.Expr) -> Any:
        """The sympy expression of ``e`` (iterative: expressions may be thousands deep)."""
        done: dict[int, Any] = {}
        stack: list[tuple[x.Expr, bool]] = [(e, False)]
        while stack:
            node, ready = stack.pop()
            if id(node) in done:
                continue
            kids = x.children(node)
            if not ready and kids:
                stack.append((node, True))
                stack.extend((k, False) for k in kids)
                continue
            done[id(node)] = self.node(node, [done[id(k)] for k in kids])
        return done[id(e)]

    def node(self, e: x.Expr, args: list[Any]) -> Any:
        sp = self.sp
        if isinstance(e, x.Const):
            if isinstance(e.value, bool):
                return sp.true if e.value else sp.false
            return sp.Integer(e.value) if isinstance(e.value, int) else sp.Float(e.value)
        if isinstance(e, x.Var):
            return self.symbol(e.name)
        if isinstance(e, x.Time):
            return self.time
        if isinstance(e, x.Der):
            if isinstance(e.arg, x.Var):
                return self.symbol(x.to_text(e))  # der(name), as the DAE names it
            return sp.Derivative(args[0], self.time, evaluate=False)
        if isinstance(e, x.Neg):
            return -args[0]
        if isinstance(e, x.Not):
            return sp.Not(args[0])
        if isinstance(e, x.BinOp):
            return self.binary[e.op](*args)
        if isinstance(e, x.If):
            return sp.Piecewise((args[1], args[0]), (args[2], True))
        builtin = BUILTINS.get(e.name)
        if builtin is not None and builtin.sympy is not None:
            return builtin.sympy(sp, tuple(args))
        return sp.Function(e.name)(*args)

    def latex(self, value: Any) -> str:
        return str(self.sp.latex(value, symbol_names=self.names))


def to_sympy(e: x.Expr) -> Any:
    """``e`` as a sympy expression; variables are ``Symbol(flat name)``, ``der(x)`` is
    ``Symbol("der(x)")`` (a derivative of an expression is an unevaluated
    ``Derivative`` in a ``Dummy`` for time)."""
    return _Converter().convert(e)


def to_latex(e: x.Expr) -> str:
    """The LaTeX of one expression."""
    converter = _Converter()
    return converter.latex(converter.convert(e))


def align(rows: Iterable[tuple[x.Expr, x.Expr, str]]) -> str:
    """``\\begin{align} lhs &= rhs \\\\ ... \\end{align}`` of ``(lhs, rhs, note)`` rows;
    a note (``initial``) is set as ``\\quad\\text{(initial)}`` after its row."""
    converter = _Converter()
    lines = []
    for lhs, rhs, note in rows:
        text = (f"{converter.latex(converter.convert(lhs))} &= "
                f"{converter.latex(converter.convert(rhs))}")
        if note:
            text += r" \quad\text{(" + _escape(note) + ")}"
        lines.append(text)
    return "\\begin{align}\n" + " \\\\\n".join(lines) + "\n\\end{align}\n"


def notebook(rows: Sequence[tuple[x.Expr, x.Expr, str]]) -> str | None:
    """What ``_repr_latex_`` returns: the aligned equations for a notebook, or ``None``
    (text instead) past :data:`NOTEBOOK_ROWS` rows."""
    if len(rows) > NOTEBOOK_ROWS:
        return None
    body = align(rows).replace("{align}", "{aligned}")
    return "$$" + body.strip() + "$$"
