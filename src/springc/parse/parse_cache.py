"""Parsed files kept while they are unchanged: path -> ``ir.syntax.StoredDefinition``."""

from __future__ import annotations

from pathlib import Path

from ..ir import syntax as s
from .parser import parse_file

_PARSED: dict[tuple[str, int, int], s.StoredDefinition] = {}


def parse_cached(path: Path) -> s.StoredDefinition:
    """Parse a file, reusing the syntax tree while the file is unchanged (syntax trees
    are immutable, so a process that flattens many models parses each library once)."""
    try:
        stat = path.stat()
    except OSError:
        return parse_file(path, defer=True)
    key = (str(path), stat.st_mtime_ns, stat.st_size)
    stored = _PARSED.get(key)
    if stored is None:
        stored = _PARSED[key] = parse_file(path, defer=True)
    return stored


def clear_parse_cache() -> None:
    """Forget every parsed file (benchmarks measure loading from scratch with it)."""
    _PARSED.clear()
