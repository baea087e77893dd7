"""Unit warnings kept with a compiled model: :class:`springc.errors.UnitError` <-> the
JSON text a generated module keeps (``WARNINGS``), so that a module loaded from the
cache reports them without flattening again."""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from typing import Any

from ..errors import Note, SourceName, Span, UnitError


def _span(span: Span | None) -> list[object] | None:
    if span is None:
        return None
    return [span.file, span.line, span.column, span.end_line, span.end_column]


def _unspan(data: Any, texts: Mapping[str, str]) -> Span | None:
    if data is None:
        return None
    file, line, column, end_line, end_column = data
    name = SourceName(file, texts[file]) if file in texts else str(file)
    return Span(name, int(line), int(column), int(end_line), int(end_column))


def encode_warnings(warnings: Iterable[UnitError]) -> tuple[str, ...]:
    """Each warning as one JSON text."""
    return tuple(json.dumps({"message": w.message, "span": _span(w.span),
                             "notes": [[n.message, _span(n.span)] for n in w.notes],
                             "hint": w.hint}) for w in warnings)


def decode_warnings(texts: Iterable[str], sources: Mapping[str, str] | None = None
                    ) -> tuple[UnitError, ...]:
    """The warnings :func:`encode_warnings` wrote; those located in a model given as
    text (``sources``: pseudo file name -> text) show excerpts of it."""
    known = sources or {}
    out = []
    for text in texts:
        data = json.loads(text)
        notes = [Note(message, _unspan(span, known)) for message, span in data["notes"]]
        out.append(UnitError(data["message"], _unspan(data["span"], known), notes,
                             data["hint"]))
    return tuple(out)
