"""Parsed files kept on disk between processes: a file's bytes -> its
``ir.syntax.StoredDefinition``, pickled in ``<user cache>/parsed``.

Parsing is nearly all of checking a model of a large library: the 44 files of the
Modelica Standard Library that ``Modelica.Mechanics.Rotational.Examples.First`` reaches
take about 2.5 s of lark's time, loading their trees back about 0.3 s. An entry is
named by the SHA-256 of the parser's code stamp (:func:`parser_stamp`: the grammar, the
modules of ``parse`` and ``ir``, ``errors``, lark and the Python version), the file's
path (spans name it) and its bytes, so a changed file or a changed parser never meets
an old tree. The folder is a private folder of this user (``resources.private_folder``);
an entry that cannot be read back (damaged, another format) is parsed again and
replaced. The newest :data:`KEEP` entries are kept, the rest removed once per process
that stores one. Nothing here is required: where the folder is unusable every file is
parsed as before.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import os
import pickle
import sys
from pathlib import Path

from ..fileio import keep_newest, replace_private
from ..ir.expr import recursion_room
from ..ir.syntax import StoredDefinition
from ..resources import PACKAGE_ROOT, CacheUnusable, grammar_path, private_folder, user_cache_dir

FOLDER = "parsed"
"""The subfolder of the user's cache folder that holds the entries."""

KEEP = 8192
"""Entries kept (the Modelica Standard Library has about 1,400 files)."""


@functools.cache
def parser_stamp() -> bytes:
    """What every entry's name depends on besides the file: the size and modification
    time of the grammar, of every module of ``parse`` and ``ir`` and of ``errors``
    (their code builds the trees), lark's package and the Python version."""
    found = []
    for folder in (PACKAGE_ROOT / "parse", PACKAGE_ROOT / "ir"):
        for name in sorted(os.listdir(folder)):
            if name.endswith(".py"):
                found.append(folder / name)
    found.append(PACKAGE_ROOT / "errors.py")
    found.append(grammar_path())
    spec = importlib.util.find_spec("lark")  # found, not imported
    if spec is not None and spec.origin is not None:
        found.append(Path(spec.origin))
    stamp = [sys.version]
    for path in found:
        info = path.stat()
        stamp.append(f"{path.name}:{info.st_size}:{info.st_mtime_ns}")
    return "\n".join(stamp).encode()


class ParsedStore:
    """The entries of one folder: ``folder`` itself (made private), or with None the
    user's cache folder's ``parsed`` subfolder, resolved at each use (the environment
    may name another cache folder)."""

    def __init__(self, folder: Path | None = None) -> None:
        self.folder = folder
        self.pruned = False

    def where(self) -> Path | None:
        """The folder of the entries, None where none is usable."""
        try:
            if self.folder is not None:
                return private_folder(self.folder, quiet=True)
            home = user_cache_dir()
            if home is None:
                return None
            return private_folder(private_folder(home, quiet=True) / FOLDER, quiet=True)
        except (OSError, CacheUnusable):
            return None

    def load(self, path: Path, data: bytes) -> StoredDefinition | None:
        """The tree stored for file ``path`` holding ``data``; None if there is none or
        it cannot be read back."""
        entry = self._entry(path, data)
        if entry is None:
            return None
        try:
            stored = entry.read_bytes()
        except OSError:
            return None
        try:
            with recursion_room():
                tree = pickle.loads(stored)  # a private folder: this user's own entries
        except Exception:  # damaged, or of another format: parse again
            return None
        if not isinstance(tree, StoredDefinition) or tree.file != str(path):
            return None
        return tree

    def save(self, path: Path, data: bytes, tree: StoredDefinition) -> None:
        """Keep ``tree``, parsed from ``path`` holding ``data`` (silently nothing where
        the folder cannot hold it)."""
        entry = self._entry(path, data)
        if entry is None:
            return
        try:
            with recursion_room():
                pickled = pickle.dumps(tree, protocol=pickle.HIGHEST_PROTOCOL)
            replace_private(entry, pickled)
        except (OSError, RecursionError, pickle.PicklingError):
            return
        if not self.pruned:
            self.pruned = True
            prune(entry.parent)

    def _entry(self, path: Path, data: bytes) -> Path | None:
        folder = self.where()
        if folder is None:
            return None
        digest = hashlib.sha256(parser_stamp())
        digest.update(b"\0" + os.fsencode(str(path)) + b"\0")
        digest.update(data)
        return folder / f"{digest.hexdigest()}.pickle"


def prune(folder: Path, keep: int = KEEP) -> None:
    """Remove the least recently written entries of ``folder`` beyond ``keep``."""
    keep_newest(folder, ".pickle", 71, keep)
