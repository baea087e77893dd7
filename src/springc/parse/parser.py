"""source text -> syntax.StoredDefinition: the Modelica parser.

The LALR grammar lives in ``grammar/modelica.lark`` (found by
:func:`springc.resources.grammar_path`); lark turns text into a parse tree and
:mod:`springc.build_syntax` maps each rule to a :mod:`springc.syntax` node with its
:class:`~springc.errors.Span`.

Errors: lark's syntax errors become a :class:`~springc.errors.ParseError` at the offending
token (``unexpected 'end', expected one of: ';', '('``). Constructs of docs/language.md's
"Not supported yet" list are parsed and then rejected by name (```when` equations are not
supported yet``); all of them in a file are reported together as an
:class:`~springc.errors.ErrorGroup`.
"""

from __future__ import annotations

import hashlib
import os
import re
import stat
import sys
from collections.abc import Iterable
from pathlib import Path

import lark
from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from ..errors import ParseError, Span
from ..ir.syntax import Expr, StoredDefinition
from ..resources import CacheUnusable, grammar_path, private_folder, user_cache_dir
from .builder import build
from .source_text import read_source_file

__all__ = ["parse_expression", "parse_file", "parse_text"]

# ------------------------------------------------------------------ lark setup

_STRICT_STRING = re.compile(r'"(?:[^"\\]|\\[\s\S])*"')


class _LexProblem(Exception):
    """Raised from a lexer callback; turned into a ParseError once the file is known."""

    def __init__(self, message: str, token: Token, hint: str) -> None:
        super().__init__(message)
        self.message, self.token, self.hint = message, token, hint


def _check_string(token: Token) -> Token:
    if not _STRICT_STRING.fullmatch(token):
        raise _LexProblem("unterminated string", token, "a string ends with '\"'")
    return token


def _check_comment(token: Token) -> Token:
    if len(token) < 4 or not token.endswith("*/"):
        raise _LexProblem("unterminated comment", token, "a '/*' comment ends with '*/'")
    return token


_parser: Lark | None = None


def _lark() -> Lark:
    """The grammar, loaded once. The parser tables are cached as a pickle, which saves
    about 0.15 s per process, but only in springc's own per-user cache folder: lark's
    default (``cache=True``) is a predictable file in the shared temporary folder, which
    another user could plant (:func:`parser_cache_file`)."""
    global _parser
    if _parser is None:
        path = grammar_path()
        cache = parser_cache_file(path)
        _parser = Lark.open(
            str(path),
            parser="lalr",
            lexer="contextual",
            propagate_positions=True,
            maybe_placeholders=False,
            start=["start", "expression_start"],
            lexer_callbacks={"STRING": _check_string, "BLOCK_COMMENT": _check_comment},
            cache=str(cache) if cache is not None else False,
        )
    return _parser


def parser_cache_file(grammar: Path) -> Path | None:
    """Where the parser tables of ``grammar`` are cached: a file named by the grammar's
    digest and the lark and Python versions, in ``<user cache>/parser``, created 0700.
    None (build the parser without a cache) unless the cache folder and that folder are
    usable private folders of this user (:func:`private_folder`: nothing is created in
    a refused one, no mode is changed) and the file, if present, is a regular file
    owned by this user (one that others may write is removed)."""
    try:
        home = user_cache_dir()
        if home is None:
            return None
        folder = private_folder(private_folder(home, quiet=True) / "parser", quiet=True)
        if os.path.islink(folder):
            return None
        digest = hashlib.sha256(grammar.read_bytes()).hexdigest()[:32]
        version = f"lark{lark.__version__}-py{sys.version_info[0]}{sys.version_info[1]}"
        file = folder / f"modelica-{digest}-{version}.pickle"
        if os.path.lexists(file):
            info = os.lstat(file)
            if not stat.S_ISREG(info.st_mode) or info.st_uid != os.getuid():
                return None
            if info.st_mode & 0o022:
                file.unlink()
        return file
    except (OSError, CacheUnusable):
        return None


# -------------------------------------------------------------------- public API


def parse_text(text: str, file: str, defer: bool = False) -> StoredDefinition:
    """Parse the Modelica source ``text`` of ``file`` (used in spans only). With
    ``defer``, constructs outside the subset are kept with their classes, to be
    reported only where a model uses them (the loader's mode)."""
    tree = _parse(text, file, "start")
    stored = build(tree, file, defer)
    assert isinstance(stored, StoredDefinition)
    return stored


def parse_file(path: str | Path, defer: bool = False) -> StoredDefinition:
    """Read and parse one ``.mo``/``.mdl`` file; :class:`LoadError` if it cannot be read."""
    return parse_text(read_source_file(path)[1], str(path), defer)


def parse_expression(text: str, file: str = "<expr>") -> Expr:
    """Parse a single expression, e.g. the value of ``--set mass.m=2``."""
    tree = _parse(text, file, "expression_start")
    expression: Expr = build(tree, file)
    return expression


def _parse(text: str, file: str, start: str) -> Tree[Token]:
    text = text.removeprefix("\ufeff")
    try:
        return _lark().parse(text, start=start)
    except _LexProblem as exc:
        tok = exc.token
        width = 2 if tok.startswith("/*") else 1
        line, column = tok.line or 1, tok.column or 1
        span = Span(file, line, column, line, column + width)
        raise ParseError(exc.message, span, hint=exc.hint) from None
    except UnexpectedInput as exc:
        raise _syntax_error(exc, text, file) from None


# ---------------------------------------------------------------- syntax errors

_TOKEN_NAMES = {"IDENT": "identifier", "NUMBER": "number", "STRING": "string",
                "$END": "end of file"}
# Expected tokens are listed most-likely-first and cut after _MAX_EXPECTED.
_RANK = {"';'": 0, "')'": 1, "']'": 2, "'}'": 3, "','": 4, "'='": 5, "'('": 6, "'['": 7,
         "':='": 8, "'end'": 9, "identifier": 9.5}
_OPERATORS = frozenset(
    ["+", "-", ".+", ".-", "*", "/", ".*", "./", "^", ".^", "<", "<=", ">", ">=", "==", "<>",
     ":", ".", "and", "or", "not"]
)
_MAX_EXPECTED = 5
_IGNORED = frozenset({"WHITESPACE", "LINE_COMMENT", "BLOCK_COMMENT"})


def _display(terminal: str) -> str:
    if terminal in _TOKEN_NAMES:
        return _TOKEN_NAMES[terminal]
    try:
        pattern = _lark().get_terminal(terminal).pattern
    except KeyError:
        return terminal
    return f"'{pattern.value}'" if pattern.type == "str" else terminal.lower()


def _expected(terminals: Iterable[str]) -> str:
    shown = {_display(t) for t in terminals if t not in _IGNORED}
    operators = {s for s in shown if s.strip("'") in _OPERATORS}
    if len(operators) > 1:
        shown = (shown - operators) | {"an operator"}

    def rank(item: str) -> tuple[float, str]:
        if item in _RANK:
            return (_RANK[item], item)
        if not item.startswith("'"):
            return (13 if item == "an operator" else 12, item)
        return (11, item) if item.strip("'").isalpha() else (10, item)

    ordered = sorted(shown, key=rank)
    if not ordered:
        return ""
    if len(ordered) == 1:
        return f", expected {ordered[0]}"
    more = ", ..." if len(ordered) > _MAX_EXPECTED else ""
    return ", expected one of: " + ", ".join(ordered[:_MAX_EXPECTED]) + more


def _describe(token: Token) -> str:
    if token.type == "IDENT":
        return f"identifier '{token.value}'"
    if token.type == "NUMBER":
        return f"number {token.value}"
    if token.type == "STRING":
        return f"string {token.value}"
    return f"'{token.value}'"


def _previous_token(text: str, before: int) -> Token | None:
    """The last token that ends before offset ``before`` (for the missing-';' hint)."""
    try:
        tokens = list(_lark().lex(text[:before]))
    except Exception:  # the prefix may not lex on its own; then give no hint
        return None
    return tokens[-1] if tokens else None


def _syntax_error(exc: UnexpectedInput, text: str, file: str) -> ParseError:
    if isinstance(exc, UnexpectedCharacters):
        char = text[exc.pos_in_stream or 0]
        span = Span(file, exc.line, exc.column, exc.line, exc.column + 1)
        position = exc.pos_in_stream or 0
        if text.startswith("''", position):
            return ParseError("empty quoted identifier", Span(file, exc.line, exc.column,
                                                             exc.line, exc.column + 2),
                              hint="a quoted identifier has at least one character: 'x'")
        if char == "'":
            return ParseError("unterminated quoted identifier", span,
                              hint="a quoted identifier ends with ' on the same line")
        return ParseError(f"unexpected character {char!r}", span)
    if isinstance(exc, UnexpectedToken) and exc.token.type != "$END":
        tok = exc.token
        expected = exc.accepts or exc.expected
        span = Span(file, tok.line, tok.column, tok.end_line, tok.end_column)
        hint = None
        if "SEMICOLON" in expected:
            prev = _previous_token(text, tok.start_pos)
            if prev is not None and prev.end_line < tok.line:
                hint = f"a ';' may be missing at the end of line {prev.end_line}"
        return ParseError(f"unexpected {_describe(tok)}{_expected(expected)}", span, hint=hint)
    # The end of the input: lark's $END token borrows the position of the last token.
    expected = (exc.accepts or exc.expected) if isinstance(exc, UnexpectedToken) else set()
    tok = getattr(exc, "token", None)
    line = getattr(tok, "end_line", None) or 1
    column = getattr(tok, "end_column", None) or 1
    span = Span(file, line, column, line, column + 1)
    return ParseError(f"unexpected end of file{_expected(expected)}", span)
