"""What a load read from the file system, recorded so that a cache can tell, without
loading again, whether a load now would read the same: :class:`Lookups` and
:func:`still_hold`. Standard library only (the warm path and the run records use it).

A load (:class:`~springc.parse.loader.ClassTree`) asks the file system questions
through a :class:`Lookups`: which file stores class ``A`` in folder ``F``
(:func:`~.library.class_file`, answered "none" too: a file added later that would be
found first moves the answer), the ``.mdl`` files at the top of a root, the classes a
package folder stores and its ``package.order``, whether a root is a folder, the bytes
of each file it parses (their SHA-256, taken before the parse: a file edited during
the parse is recorded as it was before, so the next check finds it changed), and, for
an external function's C code, every C file below the folders it was looked for in.
The record (:meth:`Lookups.record`) is plain JSON data, each question with its
answer; :func:`still_hold` asks every question again and compares. Files are compared
by their bytes' SHA-256, never by size and modification time alone: a same-size edit
within the file system's time granularity, or a copy that keeps the modification time
(``cp -p``, ``rsync -t``, an archive), would pass such a check unseen. Hashing only the
files a model read (the 33 files of ``Rotational.Examples.CoupledClutches``, not the
3,000 of the library) costs a few milliseconds.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..source_files import read_regular
from .library import class_file, loose_files, package_order, stored_names

FORMAT = 1
"""The version of a record's layout: a record of another is no record."""

Record = dict[str, Any]
"""A JSON object: ``{"format": FORMAT, "lookups": [[kind, *question, answer], ...]}``."""


def digest(path: Path) -> str | None:
    """The SHA-256 of a file's bytes (hex), None if it cannot be read."""
    try:
        return hashlib.sha256(read_regular(path)).hexdigest()
    except OSError:
        return None


def _resolved(path: Path) -> str | None:
    try:
        return str(path.resolve())
    except (OSError, RuntimeError):
        return None


def _is_dir(path: Path) -> bool:
    try:
        return path.is_dir()
    except OSError:
        return False


def _c_tree(folder: Path) -> list[list[str | None]]:
    """Every ``.c``/``.h`` file below ``folder`` (symbolic links to folders not
    followed), with its SHA-256, sorted by path."""
    found: list[list[str | None]] = []
    pending = [folder]
    while pending:
        current = pending.pop()
        try:
            children = sorted(current.iterdir())
        except OSError:
            continue
        for child in children:
            if child.suffix in (".c", ".h") and child.is_file():
                found.append([str(child), digest(child)])
            elif child.is_dir() and not child.is_symlink():
                pending.append(child)
    return sorted(found, key=lambda item: str(item[0]))


def _answer(kind: str, question: list[Any]) -> Any:
    """The answer the file system gives now to a recorded question (``ValueError`` for
    a question of an unknown kind or shape)."""
    if kind == "file" and len(question) == 1:
        path = Path(question[0])
        return [_resolved(path), digest(path)]
    if kind == "class" and len(question) == 2:
        found = class_file(Path(question[0]), str(question[1]))
        return None if found is None else str(found)
    if kind == "dir" and len(question) == 1:
        return _is_dir(Path(question[0]))
    simple: dict[str, Callable[[Path], Any]] = {
        "loose": lambda p: [str(f) for f in loose_files(p)],
        "stored": stored_names, "order": package_order, "c": _c_tree}
    if kind in simple and len(question) == 1:
        return simple[kind](Path(question[0]))
    raise ValueError(kind)


class Lookups:
    """The questions one load asked the file system, with their answers, each asked
    once (a repeated question gets the first answer, as a load that remembers it)."""

    def __init__(self) -> None:
        self._answers: dict[tuple[str, ...], Any] = {}

    def _ask(self, kind: str, *question: str) -> Any:
        key = (kind, *question)
        if key not in self._answers:
            self._answers[key] = _answer(kind, list(question))
        return self._answers[key]

    def class_file(self, folder: Path, name: str) -> Path | None:
        found = self._ask("class", str(folder), name)
        return None if found is None else Path(found)

    def loose_files(self, root: Path) -> list[Path]:
        return [Path(p) for p in self._ask("loose", str(root))]

    def stored_names(self, folder: Path) -> list[str]:
        return list(self._ask("stored", str(folder)))

    def package_order(self, folder: Path) -> list[str]:
        return list(self._ask("order", str(folder)))

    def is_dir(self, path: Path) -> bool:
        return bool(self._ask("dir", str(path)))

    def read(self, path: Path) -> str | None:
        """Note that ``path`` is read (parsed) now: its resolved path and SHA-256 are
        taken first; the resolved path (None where it cannot be resolved)."""
        return self._ask("file", str(path))[0]  # type: ignore[no-any-return]

    def c_sources(self, folder: Path) -> None:
        """Note that the C files below ``folder`` may be compiled (an external
        function's include directory or ``Resources/C-Sources``)."""
        self._ask("c", str(folder))

    def record(self) -> Record:
        """The questions and answers as JSON data (:func:`still_hold` checks them)."""
        return {"format": FORMAT,
                "lookups": [[*key, answer] for key, answer in self._answers.items()]}


def still_hold(record: object) -> bool:
    """Whether every question of ``record`` (:meth:`Lookups.record`, read back as data:
    nothing in it is trusted) gets its recorded answer from the file system now; False
    for anything that is not such a record."""
    if not isinstance(record, dict) or record.get("format") != FORMAT:
        return False
    lookups = record.get("lookups")
    if not isinstance(lookups, list):
        return False
    for item in lookups:
        if not (isinstance(item, list) and len(item) >= 2
                and all(isinstance(part, str) for part in item[:-1])):
            return False
        try:
            if _answer(item[0], item[1:-1]) != item[-1]:
                return False
        except (ValueError, OSError):
            return False
    return True


__all__ = ["FORMAT", "Lookups", "Record", "digest", "still_hold"]
