"""The library path and how Modelica stores a library in folders and files.

The library path (specification section 13.3) is an ordered list of root folders:
the ``-L`` folders, then ``SPRINGC_PATH``, then ``MODELICAPATH`` (both separated by
``os.pathsep``), then the bundled ``models/``. A top-level class ``P`` is taken from the
first root that stores it, as ``P/package.mo`` (a package folder), ``P.mo`` or ``P.mdl``
(``.mdl`` is accepted wherever ``.mo`` is). Inside a package folder, class ``A`` of
``P`` is ``P/A/package.mo`` or ``P/A.mo``; ``P/package.order`` lists the order of the
package's classes. Files are located here; nothing is parsed.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from ..resources import models_dir
from ..source_files import read_regular

SUFFIXES = (".mo", ".mdl")
PACKAGE_FILES = tuple(f"package{suffix}" for suffix in SUFFIXES)
ORDER_FILE = "package.order"

# Only plain identifiers name files: a quoted Modelica name ('..', 'a/b') never does.
_FILE_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


@dataclass(frozen=True)
class LibraryRoot:
    """One folder of the library path and where it came from (``-L``, ``SPRINGC_PATH``,
    ``MODELICAPATH`` or ``bundled``)."""

    folder: Path
    origin: str

    def describe(self) -> str:
        return "the bundled models" if self.origin == "bundled" \
            else f"{self.folder} ({self.origin})"


def library_roots(extra: Iterable[str | Path] = ()) -> list[LibraryRoot]:
    """The library path in precedence order: ``-L`` folders, ``SPRINGC_PATH``,
    ``MODELICAPATH``, the bundled models."""
    roots = [LibraryRoot(Path(p), "-L") for p in extra]
    for variable in ("SPRINGC_PATH", "MODELICAPATH"):
        env = os.environ.get(variable, "")
        roots += [LibraryRoot(Path(p), variable) for p in env.split(os.pathsep) if p]
    roots.append(LibraryRoot(models_dir(), "bundled"))
    return roots


def library_folders(extra: Iterable[str | Path] = ()) -> list[Path]:
    """The folders of :func:`library_roots`, in the same order."""
    return [root.folder for root in library_roots(extra)]


def is_package_file(path: Path) -> bool:
    return path.name in PACKAGE_FILES


def package_file(folder: Path) -> Path | None:
    """``folder/package.mo`` (or ``package.mdl``) if ``folder`` stores a package."""
    for name in PACKAGE_FILES:
        candidate = folder / name
        if _is_file(candidate):
            return candidate
    return None


def class_file(folder: Path, name: str) -> Path | None:
    """The file that stores class ``name`` in ``folder``: ``name/package.mo``, else
    ``name.mo`` or ``name.mdl``; ``None`` if there is none."""
    if not _FILE_NAME.match(name):
        return None
    sub = folder / name
    if _is_dir(sub):
        found = package_file(sub)
        if found is not None:
            return found
    for suffix in SUFFIXES:
        candidate = folder / f"{name}{suffix}"
        if _is_file(candidate):
            return candidate
    return None


def package_order(folder: Path) -> list[str]:
    """The class names listed in ``folder/package.order`` (empty if there is none)."""
    try:
        text = read_regular(folder / ORDER_FILE).decode("utf-8")
    except (OSError, UnicodeDecodeError):
        return []
    return [line.strip() for line in text.splitlines() if _FILE_NAME.match(line.strip())]


def stored_names(folder: Path) -> list[str]:
    """The names of the classes a package folder stores in files and subfolders, sorted."""
    try:
        children = sorted(folder.iterdir())
    except OSError:
        return []
    names = [p.stem for p in children
             if p.suffix in SUFFIXES and not is_package_file(p) and _FILE_NAME.match(p.stem)]
    names += [p.name for p in children
              if _FILE_NAME.match(p.name) and _is_package_folder(p)]
    return sorted(set(names))


def loose_files(root: Path) -> list[Path]:
    """Files of a root that may not be found by class name: every ``.mdl`` file at the
    top of the root (springc's older layout, where ``parts.mdl`` may hold ``package
    Parts``). Subfolders are never searched for them: a file in a folder that is not a
    package is not part of the library, and ``.mo`` files are found by their names only,
    as the specification says."""
    return [p for p in _entries(root) if p.suffix == ".mdl" and _is_file(p)]


def _entries(folder: Path) -> list[Path]:
    """The entries of ``folder``, sorted; none if it cannot be read."""
    try:
        return sorted(folder.iterdir())
    except OSError:
        return []


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except OSError:  # a name too long for the file system, no permission
        return False


def _is_dir(path: Path) -> bool:
    try:
        return path.is_dir()
    except OSError:  # a name too long for the file system, no permission
        return False


def _is_package_folder(path: Path) -> bool:
    return _is_dir(path) and package_file(path) is not None
