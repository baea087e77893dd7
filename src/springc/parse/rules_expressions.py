"""Expression rules -> :mod:`springc.syntax` expressions (``Expr``), with operator precedence.

:class:`ExpressionRules` has one method per expression rule of ``grammar/modelica.lark``;
the grammar leaves binary and unary operators as a flat ``operand (op operand)*`` list
that :class:`Precedence` turns into a tree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from lark import Token
from lark.tree import Meta

from ..ir.syntax import (
    ArrayLit,
    Binary,
    Bool,
    Call,
    Colon,
    Comprehension,
    End,
    Expr,
    IfExpr,
    MatrixLit,
    NamedArg,
    Number,
    Range,
    Ref,
    RefPart,
    String,
    Tuple,
    Unary,
)
from .rules_base import RuleBase, Subs, join, of

_RELATIONS = frozenset({"<", "<=", ">", ">=", "==", "<>"})
_ADDITIVE = frozenset({"+", "-", ".+", ".-"})
_MULTIPLICATIVE = frozenset({"*", "/", ".*", "./"})
_POWER = frozenset({"^", ".^"})


@dataclass(frozen=True, slots=True)
class Args:
    """The arguments of a call (also read by ``(a, b) := f(x)`` statements)."""

    args: tuple[Expr, ...]
    named: tuple[NamedArg, ...]


class ExpressionRules(RuleBase):
    """The expression rules: literals, references, calls, arrays, operators."""

    def if_expression(self, meta: Meta, ch: list[Any]) -> IfExpr:
        pairs = tuple((ch[i], ch[i + 1]) for i in range(0, len(ch) - 1, 2))
        return IfExpr(pairs, ch[-1], self.span_of(meta))

    def range(self, meta: Meta, ch: list[Any]) -> Range:
        step = ch[1] if len(ch) == 3 else None
        return Range(ch[0], step, ch[-1], self.span_of(meta))

    def operation(self, meta: Meta, ch: list[Any]) -> Any:
        return Precedence(self, ch).build()

    def number(self, meta: Meta, ch: list[Any]) -> Number:
        text = str(ch[0])
        span = self.span_of(meta)
        value: int | float = float(text)
        if not math.isfinite(value):
            shown = text if len(text) <= 24 else f"{text[:12]}... ({len(text)} characters)"
            self.error(f"the number {shown} is too large", span,
                       hint="numbers must be below about 1.8e308 (the largest double)")
            value = 0.0
        elif text.isdigit():
            value = int(text)
        return Number(value, span)

    def string(self, meta: Meta, ch: list[Any]) -> String:
        return String(self.unescape(ch[0][1:-1], ch[0]), self.span_of(meta))

    def true(self, meta: Meta, ch: list[Any]) -> Bool:
        return Bool(True, self.span_of(meta))

    def false(self, meta: Meta, ch: list[Any]) -> Bool:
        return Bool(False, self.span_of(meta))

    def call(self, meta: Meta, ch: list[Any]) -> Call:
        func, args = ch
        if not isinstance(func, Ref):  # `end(...)`: the grammar reads `end` as a reference
            self.error(f"'{type(func).__name__.lower()}' cannot be called", func.span,
                       hint="call a function by its name, e.g. size(x, 1)")
            func = Ref((RefPart("end", (), func.span),), func.span)
        return Call(func, args.args, args.named, self.span_of(meta))

    def subscripted(self, meta: Meta, ch: list[Any]) -> Any:
        self.reject("subscripts on a parenthesized expression (`(e)[i]`) are",
                     self.span_of(meta))
        return ch[0]

    def tuple(self, meta: Meta, ch: list[Any]) -> Tuple:
        return Tuple(tuple(ch), self.span_of(meta))

    def matrix(self, meta: Meta, ch: list[Any]) -> MatrixLit:
        return MatrixLit(tuple(ch), self.span_of(meta))

    def matrix_row(self, meta: Meta, ch: list[Any]) -> Any:
        return tuple(ch)

    def array(self, meta: Meta, ch: list[Any]) -> ArrayLit:
        return ArrayLit(tuple(ch), self.span_of(meta))

    def array_comprehension(self, meta: Meta, ch: list[Any]) -> Comprehension:
        return Comprehension(ch[0], ch[1], self.span_of(meta))

    def component_reference(self, meta: Meta, ch: list[Any]) -> Any:
        first = ch[0]
        if first == "end" and len(ch) == 1:
            end = End(self.span_of(meta))
            self.loose_ends.append(end)
            return end
        subs = ch[1] if len(ch) > 1 and isinstance(ch[1], Subs) else None
        head = self.token_span(first)
        if subs:
            head = join(head, subs.span)
        parts = (RefPart(self.ident(first, len(ch) == 1), subs.items if subs else (), head),
                 *(c for c in ch if isinstance(c, RefPart)))
        return Ref(parts, self.span_of(meta))

    def global_reference(self, meta: Meta, ch: list[Any]) -> Any:
        ref = self.component_reference(meta, ch)
        return Ref(ref.parts, ref.span, is_global=True)

    def ref_part(self, meta: Meta, ch: list[Any]) -> RefPart:
        subs = of(ch, Subs)
        return RefPart(self.ident(ch[0]), subs.items if subs else (), self.span_of(meta))

    def array_subscripts(self, meta: Meta, ch: list[Any]) -> Subs:
        span = self.span_of(meta)
        if self.loose_ends:  # those inside these brackets are where they belong
            inside = (span.line, span.column), (span.end_line, span.end_column)
            self.loose_ends = [e for e in self.loose_ends
                                if not inside[0] <= (e.span.line, e.span.column) < inside[1]]
        return Subs(tuple(ch), span)

    def colon(self, meta: Meta, ch: list[Any]) -> Colon:
        return Colon(self.span_of(meta))

    def function_call_args(self, meta: Meta, ch: list[Any]) -> Args:
        named = tuple(c for c in ch if isinstance(c, NamedArg))
        args = tuple(c for c in ch if not isinstance(c, NamedArg))
        seen_named = False
        for c in ch:
            seen_named = seen_named or isinstance(c, NamedArg)
            if seen_named and not isinstance(c, NamedArg):
                self.error("positional argument after a named argument", c.span)
                break
        return Args(args, named)

    def call_comprehension(self, meta: Meta, ch: list[Any]) -> Args:
        body, indices = ch
        return Args((Comprehension(body, indices, join(body.span, indices[-1].span)),), ())

    def named_argument(self, meta: Meta, ch: list[Any]) -> NamedArg:
        return NamedArg(self.ident(ch[0]), ch[1], self.span_of(meta))

    def name(self, meta: Meta, ch: list[Any]) -> Any:
        return (ch[0],) if len(ch) == 1 else (*ch[0], ch[1])



class Precedence:
    """Builds the tree of a flat ``operand (op operand)*`` list by Modelica precedence.

    Follows appendix A: ``expr: or; or: and {or and}; and: not {and not};
    not: [not] rel; rel: arith [relop arith]; arith: [addop] term {addop term};
    term: factor {mulop factor}; factor: primary [^ primary]``.
    """

    def __init__(self, owner: RuleBase, items: list[Any]) -> None:
        self.owner, self.items, self.i = owner, items, 0

    def build(self) -> Expr:
        result = self.or_()
        if self.i < len(self.items):
            tok = self.items[self.i]
            hint = ("comparisons cannot be chained; combine them with `and`"
                    if tok in _RELATIONS else
                    "'^' is not associative; add parentheses: (a^b)^c or a^(b^c)")
            self.owner.error(f"unexpected '{tok}'", self.owner.token_span(tok), hint=hint)
        return result

    def _take(self, ops: frozenset[str]) -> Token | None:
        if self.i < len(self.items):
            item = self.items[self.i]
            if isinstance(item, Token) and item in ops:
                self.i += 1
                return item
        return None

    def _binary(self, left: Expr, op: Token, right: Expr) -> Binary:
        return Binary(str(op), left, right, join(left.span, right.span))

    def or_(self) -> Expr:
        left = self.and_()
        while op := self._take(frozenset({"or"})):
            left = self._binary(left, op, self.and_())
        return left

    def and_(self) -> Expr:
        left = self.not_()
        while op := self._take(frozenset({"and"})):
            left = self._binary(left, op, self.not_())
        return left

    def not_(self) -> Expr:
        if op := self._take(frozenset({"not"})):
            operand = self.relation()
            return Unary("not", operand, join(self.owner.token_span(op), operand.span))
        return self.relation()

    def relation(self) -> Expr:
        left = self.arithmetic()
        if op := self._take(_RELATIONS):
            left = self._binary(left, op, self.arithmetic())
        return left

    def arithmetic(self) -> Expr:
        if sign := self._take(_ADDITIVE):
            operand = self.term()
            left: Expr = Unary(str(sign), operand, join(self.owner.token_span(sign), operand.span))
        else:
            left = self.term()
        while op := self._take(_ADDITIVE):
            left = self._binary(left, op, self.term())
        return left

    def term(self) -> Expr:
        left = self.factor()
        while op := self._take(_MULTIPLICATIVE):
            left = self._binary(left, op, self.factor())
        return left

    def factor(self) -> Expr:
        base = self.primary()
        if op := self._take(_POWER):
            return self._binary(base, op, self.primary())
        return base

    def primary(self) -> Expr:
        item = self.items[self.i]
        self.i += 1
        if not isinstance(item, Token):
            operand: Expr = item
            return operand
        example = "a and (not b)" if item == "not" else f"a * ({item}b)"
        self.owner.error(
            f"unexpected '{item}'", self.owner.token_span(item),
            hint=f"a unary '{item}' may only start an expression or an operand of a "
                 f"comparison; put it in parentheses, e.g. {example}",
        )
        while isinstance(item, Token):  # one error for a run such as `- - - 1`
            item = self.items[self.i]
            self.i += 1
        rest: Expr = item
        return rest

