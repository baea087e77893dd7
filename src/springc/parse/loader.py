"""Load source files and libraries into one class tree, and look classes up in it.

Input: ``.mdl`` files named by the user, library folders (``-L``, ``SPRINGC_PATH``,
the bundled ``models/``). Output: a :class:`ClassTree` whose root holds every
top-level class; a file's ``within`` clause places its classes inside a package.
Files named by the user take precedence over library folders, and earlier folders
over later ones, like ``MODELICAPATH``.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import (
    ErrorGroup,
    FlattenError,
    LoadError,
    Note,
    Span,
    SpringcError,
    remember_source,
)
from ..ir import syntax as s
from ..resources import models_dir
from .parser import parse_file, parse_text


@dataclass(eq=False)
class ClassEntry:
    """A class definition placed in the tree: its enclosing class and nested classes."""

    defn: s.ClassDef
    parent: ClassEntry | None
    classes: dict[str, ClassEntry] = field(default_factory=dict)
    from_user: bool = False

    @property
    def name(self) -> str:
        return self.defn.name

    @property
    def full_name(self) -> str:
        if self.parent is None or self.parent.parent is None:
            return self.defn.name
        return f"{self.parent.full_name}.{self.defn.name}"


def _place(defn: s.ClassDef, parent: ClassEntry) -> ClassEntry:
    entry = ClassEntry(defn, parent)
    for element in defn.elements:
        if isinstance(element, s.ClassDef):
            entry.classes[element.name] = _place(element, entry)
    return entry


_ROOT_SPAN = Span("<root>", 1, 1, 1, 1)
_ROOT_DEF = s.ClassDef("", "package", False, False, "", (), (), (), (), None, None, False,
                       _ROOT_SPAN)


class ClassTree:
    """All loaded classes under one unnamed root package."""

    def __init__(self) -> None:
        self.root = ClassEntry(_ROOT_DEF, None)
        self.files: list[s.StoredDefinition] = []

    def add(self, stored: s.StoredDefinition, override: bool) -> list[SpringcError]:
        """Insert a file's classes; user files (``override``) clash with each other only."""
        self.files.append(stored)
        errors: list[SpringcError] = []
        package = self.root
        if stored.within:
            try:
                package = self.resolve(stored.within, self.root, stored.classes[0].span
                                       if stored.classes else None)
            except FlattenError as e:
                return [e]
        for defn in stored.classes:
            existing = package.classes.get(defn.name)
            if existing is not None and override and existing.from_user:
                errors.append(FlattenError(
                    f"class '{defn.name}' is defined twice", defn.span,
                    [Note("first defined here", existing.defn.span)],
                    "rename one of the classes or load only one of the files"))
                continue
            if existing is not None and not override:
                continue
            entry = _place(defn, package)
            entry.from_user = override
            package.classes[defn.name] = entry
        return errors

    def resolve(self, path: Sequence[str], scope: ClassEntry, span: Span | None) -> ClassEntry:
        """Look up a dotted class name from ``scope`` (Modelica lexical lookup)."""
        entry = lookup_class(path[0], scope)
        if entry is None:
            raise FlattenError(f"unknown class '{'.'.join(path)}'", span,
                               hint=_unknown_class_hint(path[0], scope))
        for part in path[1:]:
            member = member_class(entry, part)
            if member is None:
                raise FlattenError(
                    f"class '{entry.full_name}' has no member class '{part}'", span,
                    [Note(f"'{entry.full_name}' is defined here", entry.defn.span)])
            entry = member
        return entry


def member_class(entry: ClassEntry, name: str) -> ClassEntry | None:
    """A class named ``name`` declared in ``entry`` or inherited by it."""
    if name in entry.classes:
        return entry.classes[name]
    for element in entry.defn.elements:
        if isinstance(element, s.Extends):
            try:
                base = _resolve_quiet(element.base, entry.parent or entry)
            except FlattenError:
                continue
            if base is not None and base is not entry:
                found = member_class(base, name)
                if found is not None:
                    return found
    return None


def _resolve_quiet(ref: s.Ref, scope: ClassEntry) -> ClassEntry | None:
    entry = lookup_class(ref.parts[0].name, scope)
    for part in ref.parts[1:]:
        if entry is None:
            return None
        entry = member_class(entry, part.name)
    return entry


def lookup_class(name: str, scope: ClassEntry) -> ClassEntry | None:
    """Find the class a simple name denotes from ``scope``: local and inherited classes,
    imports, then enclosing classes (stopping at ``encapsulated``, except for the root)."""
    entry: ClassEntry | None = scope
    while entry is not None:
        found = member_class(entry, name) or _imported(entry, name)
        if found is not None:
            return found
        if entry.defn.encapsulated:
            root = entry
            while root.parent is not None:
                root = root.parent
            return root.classes.get(name)
        entry = entry.parent
    return None


def _imported(entry: ClassEntry, name: str) -> ClassEntry | None:
    for element in entry.defn.elements:
        if not isinstance(element, s.Import):
            continue
        target: tuple[str, ...] | None = None
        if element.alias == name:
            target = element.path + element.names
        elif (name in element.names and element.alias is None) or element.wildcard:
            target = (*element.path, name)
        if target is None:
            continue
        root = entry
        while root.parent is not None:
            root = root.parent
        found: ClassEntry | None = root
        for part in target:
            found = member_class(found, part) if found is not None else None
        if found is not None:
            return found
    return None


def _unknown_class_hint(name: str, scope: ClassEntry) -> str:
    visible: set[str] = set()
    entry: ClassEntry | None = scope
    while entry is not None:
        visible.update(entry.classes)
        for e in entry.defn.elements:
            if isinstance(e, s.Import):
                visible.update([e.alias] if e.alias else e.names)
        entry = entry.parent
    close = difflib.get_close_matches(name, sorted(visible), 1)
    if close:
        return f"did you mean '{close[0]}'?"
    return (f"no class '{name}' is visible here: check the spelling, add an `import`, "
            "or load the file that defines it (name it on the command line or pass "
            "its folder with -L)")


def library_folders(extra: Iterable[str | Path] = ()) -> list[Path]:
    """Library folders in precedence order: ``-L`` folders, ``SPRINGC_PATH``, bundled."""
    folders = [Path(p) for p in extra]
    env = os.environ.get("SPRINGC_PATH", "")
    folders += [Path(p) for p in env.split(os.pathsep) if p]
    folders.append(models_dir())
    return folders


def load(files: Sequence[str | Path], libraries: Iterable[str | Path] = (),
         texts: Sequence[tuple[str, str]] = ()) -> ClassTree:
    """Parse the user's files, the user's ``texts`` (``(pseudo file name, text)``
    pairs, such as ``("<string>", ...)``: their excerpts are kept for error messages)
    and every ``.mdl`` file of the library folders.

    All files are parsed first; classes are then placed in precedence order, files
    without ``within`` before those placed inside a package (shallow packages first).
    """
    errors: list[SpringcError] = []
    parsed: list[tuple[s.StoredDefinition, bool]] = []
    seen: set[Path] = set()
    sources = [(Path(p), True) for p in files]
    for folder in library_folders(libraries):
        if not folder.is_dir():
            errors.append(LoadError(f"library folder '{folder}' does not exist",
                                    hint="check the -L option and SPRINGC_PATH"))
            continue
        sources += [(p, False) for p in sorted(folder.rglob("*.mdl"))]
    for path, from_user in sources:
        if path.resolve() in seen:
            continue
        seen.add(path.resolve())
        try:
            parsed.append((_parse_cached(path), from_user))
        except ErrorGroup as group:
            errors += group.errors
        except SpringcError as error:
            errors.append(error)
    for name, text in texts:
        remember_source(name, text)
        try:
            parsed.append((parse_text(text, name), True))
        except ErrorGroup as group:
            errors += group.errors
        except SpringcError as error:
            errors.append(error)
    tree = ClassTree()
    for stored, from_user in sorted(parsed, key=lambda p: len(p[0].within or ())):
        errors += tree.add(stored, override=from_user)
    if errors:
        raise errors[0] if len(errors) == 1 else ErrorGroup(errors)
    return tree


_PARSED: dict[tuple[str, int, int], s.StoredDefinition] = {}


def _parse_cached(path: Path) -> s.StoredDefinition:
    """Parse a file, reusing the syntax tree while the file is unchanged (syntax trees
    are immutable, so a process that flattens many models parses each library once)."""
    try:
        stat = path.stat()
    except OSError:
        return parse_file(path)
    key = (str(path), stat.st_mtime_ns, stat.st_size)
    stored = _PARSED.get(key)
    if stored is None:
        stored = _PARSED[key] = parse_file(path)
    return stored
