"""lark tokens and rule positions -> spans, names and located errors: what every rule group
of :mod:`springc.build_syntax` shares.

:class:`RuleBase` holds the builder's state (file, collected errors, ``end``s awaiting a
subscript) and the helpers the rule methods call; the intermediate results defined here
(:class:`Rejected`, :class:`Subs`, :class:`ClassMod`, :class:`Annotation`) pass between rules
of different groups and never leave the builder.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, TypeVar

from lark import Token
from lark.tree import Meta

from ..errors import Note, ParseError, Span
from ..ir.syntax import ElementModification, End, Expr, Modification, Ref, RefPart

T = TypeVar("T")

LATER = "springc supports a subset of Modelica; see \"Not supported yet\" in docs/language.md"

KEYWORDS = frozenset(
    [
        "algorithm", "and", "annotation", "block", "break", "class", "connect", "connector",
        "constant", "constrainedby", "der", "discrete", "each", "else", "elseif", "elsewhen",
        "encapsulated", "end", "enumeration", "equation", "expandable", "extends", "external",
        "false", "final", "flow", "for", "function", "if", "import", "impure", "in", "initial",
        "inner", "input", "loop", "model", "not", "operator", "or", "outer", "output", "package",
        "parameter", "partial", "protected", "public", "pure", "record", "redeclare",
        "replaceable", "return", "stream", "then", "true", "type", "when", "while", "within",
    ]
)
# `der` and `initial` are also called as ordinary functions (see the grammar).
_FUNCTION_WORDS = frozenset({"der", "initial"})

_ESCAPES = {"'": "'", '"': '"', "?": "?", "\\": "\\", "a": "\a", "b": "\b", "f": "\f",
            "n": "\n", "r": "\r", "t": "\t", "v": "\v"}
_ESCAPE = re.compile(r"\\(.)", re.S)


# ------------------------------------------- intermediate results shared by rule groups


@dataclass(frozen=True, slots=True)
class Rejected:
    """Stands in for an unsupported construct; its error is already recorded."""

    span: Span


@dataclass(frozen=True, slots=True)
class Subs:
    """Array subscripts ``[...]``."""

    items: tuple[Expr, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class ClassMod:
    """A class modification ``(...)``."""

    arguments: tuple[ElementModification, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Annotation:
    modification: Modification


# ------------------------------------------------------------------- helpers


def tokens(children: list[Any]) -> list[Token]:
    return [c for c in children if isinstance(c, Token)]


def of(children: list[Any], kind: type[T]) -> T | None:
    """The first child of type ``kind``, or ``None``."""
    return next((c for c in children if isinstance(c, kind)), None)


def _within(inner: Span, outer: Span) -> bool:
    return (outer.line, outer.column) <= (inner.line, inner.column) \
        and (inner.end_line, inner.end_column) <= (outer.end_line, outer.end_column)


def join(a: Span, b: Span) -> Span:
    return Span(a.file, a.line, a.column, b.end_line, b.end_column)


class RuleBase:
    """State and helpers of the rule methods (see :class:`springc.build_syntax.SyntaxBuilder`)."""

    file: str
    errors: list[ParseError]
    defer: bool  # keep `not supported yet` errors with their class (see take_deferred)
    deferred: list[ParseError]
    loose_ends: list[End]  # `end`s not yet known to sit in a subscript

    def span_of(self, meta: Meta) -> Span:
        return Span(self.file, meta.line, meta.column, meta.end_line, meta.end_column)

    def token_span(self, tok: Token) -> Span:
        # Tokens from the parser always carry positions (propagate_positions).
        return Span(self.file, tok.line or 1, tok.column or 1, tok.end_line or 1,
                    tok.end_column or 1)

    def keyword_span(self, meta: Meta, word: str) -> Span:
        """The span of the keyword ``word`` that starts the rule at ``meta``."""
        return Span(self.file, meta.line, meta.column, meta.line, meta.column + len(word))

    def error(self, message: str, span: Span, hint: str | None = None,
               notes: Iterable[Note] = ()) -> None:
        self.errors.append(ParseError(message, span, notes, hint))

    def reject(self, what: str, span: Span, hint: str | None = LATER) -> Rejected:
        self.error(f"{what} not supported yet", span, hint)
        if self.defer:
            self.deferred.append(self.errors[-1])
        return Rejected(span)

    def take_deferred(self, span: Span) -> tuple[ParseError, ...]:
        """The ``not supported yet`` errors inside ``span``, moved from the file's errors
        to the class written there (reported when a model uses that class)."""
        inside = tuple(e for e in self.deferred if e.span is not None and _within(e.span, span))
        if inside:
            self.deferred = [e for e in self.deferred if e not in inside]
            self.errors = [e for e in self.errors if e not in inside]
        return inside

    def ident(self, tok: Token, function: bool = False) -> str:
        """The name written by ``tok`` (without quotes); reserved words are errors,
        except ``der``/``initial`` as the ``function`` name of a call."""
        if tok.startswith("'"):
            return self.unescape(tok[1:-1], tok)
        if tok in KEYWORDS and not (function and tok in _FUNCTION_WORDS):
            self.error(f"'{tok}' is a reserved word and cannot be used as a name",
                        self.token_span(tok))
        return str(tok)

    def make_ref(self, toks: tuple[Token, ...]) -> Ref:
        parts = tuple(RefPart(self.ident(t), (), self.token_span(t)) for t in toks)
        return Ref(parts, join(parts[0].span, parts[-1].span))

    def unescape(self, body: str, token: Token) -> str:
        """Resolve Modelica's escapes (``\\n``, ``\\"``, ...) in a string or quoted name."""
        if "\\" not in body:
            return body

        def one(m: re.Match[str]) -> str:
            if m.group(1) in _ESCAPES:
                return _ESCAPES[m.group(1)]
            self.error(f"invalid escape '\\{m.group(1)}'", self.token_span(token),
                        hint="Modelica knows \\' \\\" \\? \\\\ \\a \\b \\f \\n \\r \\t \\v")
            return str(m.group(1))

        return _ESCAPE.sub(one, body)
