"""Diagnostics shared by every stage: source spans, errors with notes, and rendering.

Each stage raises its own subclass of :class:`SpringcError`; the CLI renders them as
``file:line:col: error: message``, the source line, a caret under the span, then notes.
"""

from __future__ import annotations

import unicodedata
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from .source_files import read_regular


@dataclass(frozen=True, slots=True)
class Span:
    """A region of source text; lines and columns are 1-based, ``end_column`` exclusive."""

    file: str
    line: int
    column: int
    end_line: int
    end_column: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"

    def width(self, default: int = 1) -> int:
        """The columns it covers on its first line; ``default`` where it spans lines."""
        if self.end_line == self.line and self.end_column > self.column:
            return self.end_column - self.column
        return default

    def __reduce__(self) -> tuple[type[Span], tuple[str, int, int, int, int]]:
        # a call, not dataclass's generic state of slots (a fields() walk per span)
        return Span, (self.file, self.line, self.column, self.end_line, self.end_column)


@dataclass(frozen=True, slots=True)
class Note:
    """A secondary message, optionally pointing at its own location."""

    message: str
    span: Span | None = None


class SpringcError(Exception):
    """A user-facing error: a message, where it happened, notes, and what to do."""

    def __init__(
        self,
        message: str,
        span: Span | None = None,
        notes: Iterable[Note] = (),
        hint: str | None = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.span = span
        self.notes = tuple(notes)
        self.hint = hint

    def __str__(self) -> str:
        """The rendered text, as the command line shows it (location, notes, help)."""
        return render(self)


class UsageError(SpringcError):
    """A value given to springc (a command-line option or an API argument) that it
    cannot use; ``option`` names it. The command line exits with code 2."""

    def __init__(self, message: str, *, option: str | None = None,
                 notes: Iterable[Note] = (), hint: str | None = None) -> None:
        super().__init__(message, None, notes, hint)
        self.option = option


class UnknownNameError(UsageError, KeyError):
    """A name that a result does not hold: springc's own error, and a ``KeyError`` too,
    as a mapping's lookup raises."""

    def __str__(self) -> str:
        return render(self)


class OutputError(SpringcError):
    """An output file that springc refuses to write or cannot write."""


class ParseError(SpringcError):
    """Lexical or syntax error, or a construct that is not supported yet."""


class LoadError(SpringcError):
    """A file or library folder could not be read."""


class FlattenError(SpringcError):
    """Name lookup, modification, array or connection error while flattening."""


class FollowUpError(FlattenError):
    """A use of a component whose instantiation failed: not shown itself, the original
    error (``original``) is reported once instead."""

    def __init__(self, original: SpringcError) -> None:
        super().__init__(original.message, original.span, original.notes, original.hint)
        self.original = original


class BalanceError(SpringcError):
    """The flat model is not balanced or is structurally singular."""


class SimplifyError(SpringcError):
    """Structural simplification or initialization failed."""


class SimulationError(SpringcError):
    """The solver failed; the message names the time and the quantity at fault."""


class UnknownParameterError(SimulationError):
    """A value given for ``name``, which is neither a parameter nor a start value of
    the model. The command line reports it as a misuse of the option that gave the
    value (:meth:`given_as`, exit 2)."""

    def __init__(self, message: str, *, name: str = "", hint: str | None = None) -> None:
        super().__init__(message, hint=hint)
        self.name = name

    def given_as(self, option: str) -> UsageError:
        return UsageError(f"{option} {self.name}: {self.message}", option=option,
                          hint=self.hint)


class CodegenError(SpringcError):
    """The model uses something the code generator cannot translate."""


class UnitError(SpringcError):
    """Units that do not agree: a warning (:func:`render` with ``kind="warning"``),
    an error with ``--strict-units``."""


class ErrorGroup(Exception):
    """Several independent errors reported together, in source order."""

    def __init__(self, errors: Iterable[SpringcError]) -> None:
        self.errors = tuple(errors)
        super().__init__(f"{len(self.errors)} errors")

    def __str__(self) -> str:
        return render_all(self)


def describe_failure(err: BaseException) -> str:
    """An arithmetic failure in words: ``division by zero``, ``overflow`` or the error's
    own text (the reference evaluator and the simulator word them alike)."""
    if isinstance(err, ZeroDivisionError):
        return "division by zero"
    if isinstance(err, OverflowError):
        return "overflow"
    return str(err) or type(err).__name__


def errors_of(exc: SpringcError | ErrorGroup) -> tuple[SpringcError, ...]:
    """The individual errors carried by ``exc``."""
    return exc.errors if isinstance(exc, ErrorGroup) else (exc,)


SourceLookup = Callable[[str], "str | None"]


class SourceName(str):
    """The name of a pseudo file (``<string>``: a model given as text) that carries its
    text. Spans located in it hold it as their ``file``, so the excerpts of their errors
    come from the text they point into (two texts under one name stay apart), and the
    text lives as long as something points into it: no table of the process keeps it.
    It is equal to, and hashes as, its name."""

    text: str

    def __new__(cls, name: str, text: str) -> SourceName:
        self = super().__new__(cls, name)
        self.text = text
        return self

    def __reduce__(self) -> tuple[type[SourceName], tuple[str, str]]:
        return SourceName, (str(self), self.text)


def read_source(path: str) -> str | None:
    """Default source lookup: the text a pseudo file (``<string>``) carries, never read
    from disk (:class:`SourceName`), else the file read from disk; ``None`` if
    unreadable."""
    if path.startswith("<") and path.endswith(">"):
        return path.text if isinstance(path, SourceName) else None
    try:
        return read_regular(path).decode("utf-8", "replace")
    except OSError:
        return None


def printable(text: str) -> str:
    """``text`` safe to print on one line: control characters and line or paragraph
    separators (a newline in a quoted name, U+2028 in a comment) escaped as Python
    writes them, so that model text never forges a line of springc's output."""
    return "".join(_escaped(c) for c in text)


def _escaped(c: str) -> str:
    if c.isprintable() or c == " ":
        return c
    return repr(c)[1:-1] if unicodedata.category(c) == "Cc" else f"\\u{ord(c):04x}"


def _excerpt(span: Span, lookup: SourceLookup) -> list[str]:
    text = lookup(span.file)
    if text is None:
        return []
    lines = text.split("\n")  # lines as the lexer counts them (\n only, not U+2028)
    if not 1 <= span.line <= len(lines):
        return []
    raw = lines[span.line - 1].removesuffix("\r").expandtabs(1)
    pieces = [_escaped(c) for c in raw]
    starts = [0]
    for piece in pieces:
        starts.append(starts[-1] + len(piece))
    line = "".join(pieces)

    def at(column: int) -> int:  # 0-based position of a 1-based column in the shown line
        return starts[min(max(column - 1, 0), len(pieces))]

    start = at(span.column)
    end = at(span.end_column) if span.end_line == span.line else len(line)
    width = max(1, end - start)
    if len(line) > EXCERPT_WIDTH:  # a window around the caret, not 40,000 columns
        lo = max(0, min(start - EXCERPT_BEFORE, len(line) - EXCERPT_WIDTH))
        hi = lo + EXCERPT_WIDTH
        line = ("..." if lo else "") + line[lo:hi] + ("..." if hi < len(line) else "")
        width = max(1, min(width, hi - start))
        start += 3 - lo if lo else 0
    gutter = f"{span.line:>5} | "
    return [gutter + line, " " * (len(gutter) - 2) + "| " + " " * start + "^" * width]


EXCERPT_WIDTH = 160
"""The columns of a source line shown under a message; a longer line is shown around
the caret, from :data:`EXCERPT_BEFORE` columns before it, with ``...`` where cut."""
EXCERPT_BEFORE = 40


def _located(kind: str, message: str, span: Span | None, lookup: SourceLookup) -> list[str]:
    where = printable(str(span)) if span else ""
    head = f"{where}: {kind}: {printable(message)}" if span else f"{kind}: {printable(message)}"
    return [head] + (_excerpt(span, lookup) if span else [])


def render(error: SpringcError, lookup: SourceLookup = read_source,
           kind: str = "error") -> str:
    """Render one error in the ``file:line:col: error: ...`` format with caret and notes
    (``kind="warning"``: a diagnostic that is not an error, in the same format); names
    and source text are shown :func:`printable`."""
    lines = _located(kind, error.message, error.span, lookup)
    for note in error.notes:
        lines += _located("note", note.message, note.span, lookup)
    if error.hint:
        lines.append(f"help: {printable(error.hint)}")
    return "\n".join(lines)


def edit_distance(a: str, b: str) -> int:
    """The Damerau-Levenshtein distance of ``a`` and ``b`` (insertions, deletions,
    substitutions and swaps of neighbours, each 1; the optimal-string-alignment form)."""
    previous2: list[int] = []
    previous = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        row = [i] + [0] * len(b)
        for j, cb in enumerate(b, 1):
            row[j] = min(previous[j] + 1, row[j - 1] + 1, previous[j - 1] + (ca != cb))
            if i > 1 and j > 1 and ca == b[j - 2] and a[i - 2] == cb:
                row[j] = min(row[j], previous2[j - 2] + 1)
        previous2, previous = previous, row
    return previous[-1]


def close_names(name: str, candidates: Iterable[str], limit: int = 3) -> list[str]:
    """The ``candidates`` nearest to ``name``, nearest first: within an edit distance
    (ignoring case) of a third of the length of the name's last part, rounded (none for
    a one-letter name, one for a dotted name whose prefix holds); a dotted candidate
    also matches by its last part (``Wall`` finds ``Mech.Wall``)."""
    allowed = max((len(name.rsplit(".", 1)[-1]) + 1) // 3, int("." in name))
    scored = []
    for candidate in dict.fromkeys(candidates):
        if candidate == name:
            continue
        last = candidate.rsplit(".", 1)[-1] if "." not in name else candidate
        distance = min(edit_distance(name.lower(), candidate.lower()),
                       edit_distance(name.lower(), last.lower()))
        if distance <= allowed:
            scored.append((distance, candidate))
    return [candidate for _, candidate in sorted(scored)[:limit]]


def did_you_mean(name: str, candidates: Iterable[str]) -> str | None:
    """``did you mean 'a' or 'b'?`` for the :func:`close_names` of ``name``, if any."""
    close = close_names(name, candidates)
    if not close:
        return None
    quoted = [f"'{c}'" for c in close]
    listed = ", ".join(quoted[:-1]) + " or " + quoted[-1] if len(quoted) > 1 else quoted[0]
    return f"did you mean {listed}?"


def render_all(exc: SpringcError | ErrorGroup, lookup: SourceLookup = read_source) -> str:
    """Render every error of ``exc``, separated by blank lines, with a count at the end."""
    errors = errors_of(exc)
    text = "\n\n".join(render(e, lookup) for e in errors)
    if len(errors) > 1:
        text += f"\n\n{len(errors)} errors"
    return text
