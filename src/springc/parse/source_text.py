"""Source file -> its bytes and text: the parser's read of a file (a regular file,
:mod:`springc.source_files`), with a located error for text that is not UTF-8."""

from __future__ import annotations

from pathlib import Path

from ..errors import LoadError, Span
from ..source_files import read_regular


def read_source_file(path: str | Path) -> tuple[bytes, str]:
    """The bytes and text of the source file ``path``: :class:`LoadError` where it
    cannot be read, is not a regular file, or is not UTF-8 (located at the first byte
    that is not: Modelica 3.6, section 13.4)."""
    try:
        data = read_regular(path)
    except OSError as exc:
        raise LoadError(f"cannot read '{path}': {exc.strerror or exc}") from None
    try:
        return data, data.decode("utf-8")
    except UnicodeDecodeError as exc:
        start = data.rfind(b"\n", 0, exc.start) + 1
        line = data.count(b"\n", 0, exc.start) + 1
        column = len(data[start:exc.start].decode("utf-8", "replace")) + 1
        raise LoadError(f"'{path}' is not UTF-8 text: byte 0x{data[exc.start]:02x} "
                        f"{exc.reason}", Span(str(path), line, column, line, column + 1),
                        hint="Modelica files are UTF-8 (Modelica 3.6, section 13.4); "
                        "convert it, e.g. iconv -f latin1 -t utf-8") from None
