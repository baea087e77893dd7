"""The outcome of checking a model text, in one string: the balance summary of a valid
model, or each error as ``line:col: message`` and its help."""

from __future__ import annotations

from pathlib import Path

from springc.errors import ErrorGroup, SpringcError, errors_of
from springc.pipeline.files import flatten_files
from springc.simplify import check_balance


def outcome(folder: Path, text: str) -> str:
    path = folder / "m.mo"
    path.write_text(text)
    try:
        model = flatten_files([path])
    except (SpringcError, ErrorGroup) as err:
        return "\n".join(f"{e.span.line}:{e.span.column}: {e.message}\nhelp: {e.hint}"
                         if e.span else e.message for e in errors_of(err))
    return check_balance(model).summary()
