"""Parsed files kept while they are unchanged: path -> ``ir.syntax.StoredDefinition``.

Syntax trees are immutable, so a process that flattens many models (a test run, a
sweep's worker, a notebook) parses each library file once. The cache is bounded: it
keeps the most recently used files up to :data:`MAX_SOURCE_BYTES` of source text
(a tree takes some tens of times its text in memory), one entry per path (a changed
file replaces its old tree), and forgets the least recently used ones beyond that.
Below it, :mod:`.parsed_store` keeps the trees on disk for the next process: a file
found there is not parsed (nor is lark imported for it).
"""

from __future__ import annotations

from collections import OrderedDict
from pathlib import Path

from ..ir import syntax as s
from .parsed_store import ParsedStore
from .source_text import read_source_file

MAX_SOURCE_BYTES = 32 << 20
"""Source text whose trees the shared cache keeps (32 MiB: the files of the Modelica
Standard Library that one model reaches, many times over)."""


class ParseCache:
    """Syntax trees of files by path, while the file holds the bytes it was parsed
    from (compared whole: a modification time and size can stay the same across an
    edit); least recently used first out beyond ``max_bytes`` of source text (a single
    larger file is parsed and not kept)."""

    def __init__(self, max_bytes: int = MAX_SOURCE_BYTES,
                 store: ParsedStore | None = None) -> None:
        self.max_bytes = max_bytes
        self.store = store
        self.size = 0  # source bytes of the files kept
        self._trees: OrderedDict[str, tuple[bytes, s.StoredDefinition]] = OrderedDict()

    def __len__(self) -> int:
        return len(self._trees)

    def parse(self, path: Path) -> s.StoredDefinition:
        """The tree of ``path``, parsed again only where the file changed."""
        name, (data, text) = str(path), read_source_file(path)
        found = self._trees.get(name)
        if found is not None and found[0] == data:
            self._trees.move_to_end(name)
            return found[1]
        stored = self._read(path, data, text)
        self._forget(name)
        if len(data) <= self.max_bytes:
            self._trees[name] = (data, stored)
            self.size += len(data)
            while self.size > self.max_bytes:
                self._forget(next(iter(self._trees)))
        return stored

    def _read(self, path: Path, data: bytes, text: str) -> s.StoredDefinition:
        """The tree of ``path`` holding ``data`` (``text``): from the store where it
        holds these bytes, else parsed (and stored)."""
        if self.store is not None:
            found = self.store.load(path, data)
            if found is not None:
                return found
        from .parser import parse_text  # lark: only for a file the store lacks

        # the newlines of a file read as text (Path.read_text), as spans count them
        stored = parse_text(text.replace("\r\n", "\n").replace("\r", "\n"), str(path),
                            defer=True)
        if self.store is not None:
            self.store.save(path, data, stored)
        return stored

    def clear(self) -> None:
        """Forget every parsed file."""
        self._trees.clear()
        self.size = 0

    def _forget(self, name: str) -> None:
        found = self._trees.pop(name, None)
        if found is not None:
            self.size -= len(found[0])


SHARED = ParseCache(store=ParsedStore())
"""The cache of this process, used by :func:`parse_cached`, over the trees of the user's
cache folder."""


def parse_cached(path: Path) -> s.StoredDefinition:
    """Parse a file through the process's :data:`SHARED` cache."""
    return SHARED.parse(path)


def clear_parse_cache() -> None:
    """Forget every parsed file (benchmarks measure loading from scratch with it)."""
    SHARED.clear()

