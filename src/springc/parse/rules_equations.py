"""Equation and statement rules -> :mod:`springc.syntax` equations and statements.

:class:`EquationRules` has one method per equation or statement rule of
``grammar/modelica.lark``; the constructs of docs/language.md's "Not supported yet" list among them
(``when`` statements, ``while``, ``break``, ``return``, call statements) become located
``... not supported yet`` errors.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from lark.tree import Meta

from ..ir.syntax import (
    Assign,
    Call,
    CallEquation,
    CallStatement,
    Connect,
    Equality,
    ForEquation,
    ForIndex,
    ForStatement,
    IfEquation,
    IfStatement,
    Jump,
    Ref,
    WhenEquation,
    WhenStatement,
    WhileStatement,
)
from .rules_base import Rejected, RuleBase, T, join


class EquationRules(RuleBase):
    """The equation and statement rules."""

    def equation(self, meta: Meta, ch: list[Any]) -> Any:
        return ch[0]

    def equations(self, meta: Meta, ch: list[Any]) -> Any:
        return tuple(c for c in ch if not isinstance(c, Rejected))

    statements = equations

    def simple_equation(self, meta: Meta, ch: list[Any]) -> CallEquation | Equality | Rejected:
        span = self.span_of(meta)
        if len(ch) == 2:
            return Equality(ch[0], ch[1], span)
        if isinstance(ch[0], Call):
            return CallEquation(ch[0], span)
        self.error("this expression is not an equation", span,
                    hint="write 'lhs = rhs'; only a function call may stand alone")
        return Rejected(span)

    def _branches(self, meta: Meta, ch: list[Any], make: Callable[..., T]) -> T:
        branches = [(ch[0], ch[1])]
        otherwise: tuple[Any, ...] = ()
        for extra in ch[2:]:
            if extra[0] == "elseif":
                branches.append((extra[1], extra[2]))
            else:
                otherwise = extra[1]
        return make(tuple(branches), otherwise, self.span_of(meta))

    def if_equation(self, meta: Meta, ch: list[Any]) -> IfEquation:
        return self._branches(meta, ch, IfEquation)

    def if_statement(self, meta: Meta, ch: list[Any]) -> IfStatement:
        return self._branches(meta, ch, IfStatement)

    def elseif_equation(self, meta: Meta, ch: list[Any]) -> Any:
        return ("elseif", ch[0], ch[1])

    elseif_statement = elseif_equation

    def else_equation(self, meta: Meta, ch: list[Any]) -> Any:
        return ("else", ch[0])

    else_statement = else_equation

    def for_equation(self, meta: Meta, ch: list[Any]) -> ForEquation:
        return ForEquation(ch[0], ch[1], self.span_of(meta))

    def for_statement(self, meta: Meta, ch: list[Any]) -> ForStatement:
        return ForStatement(ch[0], ch[1], self.span_of(meta))

    def connect_clause(self, meta: Meta, ch: list[Any]) -> Connect:
        return Connect(ch[0], ch[1], self.span_of(meta))

    def when_equation(self, meta: Meta, ch: list[Any]) -> WhenEquation:
        branches = tuple((ch[i], ch[i + 1]) for i in range(0, len(ch), 2))
        return WhenEquation(branches, self.span_of(meta))

    def for_indices(self, meta: Meta, ch: list[Any]) -> Any:
        return tuple(ch)

    def for_index(self, meta: Meta, ch: list[Any]) -> ForIndex:
        return ForIndex(self.ident(ch[0]), ch[1] if len(ch) > 1 else None, self.span_of(meta))

    # --------------------------------------------------------------- statements

    def statement(self, meta: Meta, ch: list[Any]) -> Any:
        return ch[0]

    def assign_statement(self, meta: Meta, ch: list[Any]) -> Assign:
        return Assign((ch[0],), ch[1], self.span_of(meta))

    def call_statement(self, meta: Meta, ch: list[Any]) -> CallStatement:
        func, args = ch
        span = self.span_of(meta)
        return CallStatement(Call(func, args.args, args.named, span), span)

    def multi_assign(self, meta: Meta, ch: list[Any]) -> Assign:
        *targets, func, args = ch
        for target in targets:
            if target is not None and not isinstance(target, Ref):
                self.error("only a component reference can be assigned to", target.span)
        call = Call(func, args.args, args.named, join(func.span, self.span_of(meta)))
        return Assign(tuple(targets), call, self.span_of(meta))

    def output_item(self, meta: Meta, ch: list[Any]) -> Any:
        return ch[0] if ch else None

    def break_statement(self, meta: Meta, ch: list[Any]) -> Jump:
        return Jump("break", self.span_of(meta))

    def return_statement(self, meta: Meta, ch: list[Any]) -> Jump:
        return Jump("return", self.span_of(meta))

    def while_statement(self, meta: Meta, ch: list[Any]) -> WhileStatement:
        return WhileStatement(ch[0], ch[1], self.span_of(meta))

    def when_statement(self, meta: Meta, ch: list[Any]) -> WhenStatement:
        branches = tuple((ch[i], ch[i + 1]) for i in range(0, len(ch), 2))
        return WhenStatement(branches, self.span_of(meta))
