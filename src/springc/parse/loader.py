"""One class tree for source files and libraries, and class lookup in it.

Input: ``.mo``/``.mdl`` files named by the user and the library path (``library.py``).
Output: a :class:`ClassTree` whose root holds the top-level classes; a file's
``within`` clause places its classes inside a package. The user's files are parsed at
once; a library file only when lookup first needs a class it stores (a top-level name
-> its ``package.mo`` or ``.mo`` file; ``P.Sub.A`` -> ``P/Sub/package.mo``, then
``P/Sub/A.mo``). Files named by the user take precedence over the library path, and
earlier roots over later ones.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import (
    ErrorGroup,
    FlattenError,
    LoadError,
    Note,
    Span,
    SpringcError,
    close_names,
)
from ..ir import syntax as s
from .library import LibraryRoot, is_package_file
from .lookups import Lookups
from .parse_cache import parse_cached


@dataclass(eq=False)
class ClassEntry:
    """A class definition placed in the tree: its enclosing class and nested classes."""

    defn: s.ClassDef
    parent: ClassEntry | None
    classes: dict[str, ClassEntry] = field(default_factory=dict)
    from_user: bool = False
    #: The folder of a package stored as ``P/package.mo``: its other classes load lazily.
    folder: Path | None = None
    #: The tree this entry belongs to (set on the root and on package folders).
    tree: ClassTree | None = None

    def member_names(self) -> list[str]:
        """The names of the classes declared in this class, loaded or not: for a package
        folder in ``package.order`` order, then the other loaded classes, then the other
        files and folders of the package (sorted)."""
        names = list(self.classes)
        if self.folder is None or self.tree is None:
            return names
        stored = self.tree.lookups.stored_names(self.folder)
        ordered = [n for n in self.tree.lookups.package_order(self.folder)
                   if n in names or n in stored]
        return list(dict.fromkeys(ordered + names + stored))

    def child(self, name: str) -> ClassEntry | None:
        """The class ``name`` declared in this class, loading its file if needed."""
        found = self.classes.get(name)
        if found is None and self.tree is not None:
            found = self.tree.load_member(self, name)
        return found

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


#: Names no library may define: looking them up never reads a file.
PREDEFINED_TYPES = frozenset({"Real", "Integer", "Boolean", "String"})

_ROOT_SPAN = Span("<root>", 1, 1, 1, 1)
_ROOT_DEF = s.ClassDef("", "package", False, False, "", (), (), (), (), None, None, False,
                       _ROOT_SPAN)


class ClassTree:
    """All loaded classes under one unnamed root package, and the library path that
    supplies further top-level classes on demand."""

    def __init__(self, roots: Sequence[LibraryRoot] = ()) -> None:
        self.root = ClassEntry(_ROOT_DEF, None, tree=self)
        self.roots = list(roots)
        #: Every parsed file, in the order it was added.
        self.files: list[s.StoredDefinition] = []
        #: The user's own files (not ``package.mo``): where the default model comes from.
        self.user_files: list[s.StoredDefinition] = []
        #: The ``package.mo`` files the user named.
        self.named_packages: list[s.StoredDefinition] = []
        #: Paths (resolved) of the files parsed so far, user's and library's.
        self.parsed_paths: list[Path] = []
        self._loose_done: set[Path] = set()
        self._missing: set[tuple[ClassEntry, str]] = set()
        #: What :func:`member_class` found (a class declared or inherited, or none),
        #: until a class is added to the tree: a warm ``check`` of a MultiBody example
        #: asks 400,000 such lookups, most of them the same.
        self.members: dict[tuple[ClassEntry, str], ClassEntry | None] = {}
        #: Diagnostics that are not errors (a top-level class hiding another one).
        self.notes: list[str] = []
        #: What this load asked the file system, with the answers (a cache checks them).
        self.lookups = Lookups()

    def add(self, stored: s.StoredDefinition, override: bool,
            folder: Path | None = None) -> list[SpringcError]:
        """Insert a file's classes; user files (``override``) clash with each other only.
        ``folder`` is the package folder of a ``package.mo`` file."""
        self.files.append(stored)
        self.members.clear()
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
            if folder is not None and defn.kind == "package":
                entry.folder, entry.tree = folder, self
            package.classes[defn.name] = entry
        return errors

    def load_member(self, package: ClassEntry, name: str) -> ClassEntry | None:
        """Parse the file that stores class ``name`` of ``package`` (a package folder,
        or the root: the first library root that has it); ``None`` if none does."""
        if (package, name) in self._missing:
            return None
        found = self._find_member(package, name)
        if found is None:
            self._missing.add((package, name))
        return found

    def _find_member(self, package: ClassEntry, name: str) -> ClassEntry | None:
        if package is self.root:
            if name in PREDEFINED_TYPES:
                return None
            for root in self.roots:
                path = self.lookups.class_file(root.folder, name)
                if path is not None:
                    self._load_library_file(path, (), name)
                elif root.folder not in self._loose_done:
                    self._loose_done.add(root.folder)
                    for loose in self.lookups.loose_files(root.folder):
                        self._load_library_file(loose, None, None)
                if name in self.root.classes:
                    found = self.root.classes[name]
                    self._note_shadowed(found, root)
                    return found
            return None
        if package.folder is None:
            return None
        path = self.lookups.class_file(package.folder, name)
        if path is None:
            return None
        self._load_library_file(path, tuple(package.full_name.split(".")), name)
        return package.classes.get(name)

    def _note_shadowed(self, found: ClassEntry, taken: LibraryRoot) -> None:
        """A note for each later root that also stores the top-level class ``found``
        (taken from ``taken``): the library path's order hides it."""
        name, first = found.defn.name, found.defn.span.file
        for root in self.roots[self.roots.index(taken) + 1:]:
            other = self.lookups.class_file(root.folder, name)
            if other is not None and Path(first).resolve() != other.resolve():
                self.notes.append(f"note: the top-level class '{name}' is taken from "
                                  f"{first}; it hides {other} ({root.describe()})")

    def _load_library_file(self, path: Path, within: tuple[str, ...] | None,
                           name: str | None) -> None:
        """Parse and place a library file; ``within`` (unless ``None``) is the package
        its place in the folders implies and ``name`` the class it must hold."""
        resolved = self.lookups.read(path)  # (its bytes' hash taken before the parse)
        real = Path(resolved) if resolved is not None else path.resolve()
        if real in self.parsed_paths:
            return
        self.parsed_paths.append(real)
        stored = parse_cached(path)
        span = stored.classes[0].span if stored.classes else Span(str(path), 1, 1, 1, 1)
        if within is not None and (stored.within or ()) != within:
            where = "the top level" if not within else f"package '{'.'.join(within)}'"
            said = f"within {'.'.join(stored.within)};" if stored.within else "no `within`"
            raise LoadError(
                f"'{path}' is stored in {where} but says {said}", span,
                hint=f"start the file with `within {'.'.join(within)};` or move it to "
                "the folder of the package it names")
        names = [d.name for d in stored.classes]
        # An older-style .mdl file at the top of a root may hold more classes than one.
        lenient = within == () and path.suffix == ".mdl"
        if name is not None and (name not in names if lenient else names != [name]):
            found = ", ".join(f"'{d.name}'" for d in stored.classes) or "no class"
            raise LoadError(
                f"'{path}' must hold exactly the class '{name}' (its file name), "
                f"found {found}", span,
                hint=f"rename the class or the file so that both are '{name}'")
        folder = path.parent if is_package_file(path) else None
        errors = self.add(stored, override=False, folder=folder)
        if errors:
            raise errors[0] if len(errors) == 1 else ErrorGroup(errors)

    def searched(self) -> str:
        """The library path, in the words of an error message."""
        return ", then ".join(["the files named"] + [r.describe() for r in self.roots])

    def resolve(self, path: Sequence[str], scope: ClassEntry, span: Span | None,
                extends_in: ClassEntry | None = None) -> ClassEntry:
        """Look up a dotted class name from ``scope`` (Modelica lexical lookup); for the
        base class of an ``extends`` clause of ``extends_in``, see :func:`base_lookup`."""
        entry = (lookup_class(path[0], scope) if extends_in is None
                 else base_lookup(path[0], extends_in))
        if entry is None:
            raise FlattenError(f"unknown class '{'.'.join(path)}'", span,
                               hint=_unknown_class_hint(path[0], scope))
        for part in path[1:]:
            member = member_class(entry, part)
            if member is None:
                searched = [] if entry.folder is None else [
                    Note(f"searched the package folder {entry.folder} for {part}.mo, "
                         f"{part}.mdl and {part}/package.mo")]
                raise FlattenError(
                    f"class '{entry.full_name}' has no member class '{part}'", span,
                    [Note(f"'{entry.full_name}' is defined here", entry.defn.span),
                     *searched])
            entry = member
        return entry


class _LookupCycle(Exception):
    """Looking up a member needs that same member (a package extending a class of its
    own missing subpackage)."""


def member_class(entry: ClassEntry, name: str,
                 active: frozenset[tuple[ClassEntry, str]] = frozenset()) -> ClassEntry | None:
    """A class named ``name`` declared in ``entry`` or inherited by it. ``active``: the
    (class, name) lookups in progress, to stop a lookup that would need itself."""
    key = (entry, name)
    root = entry
    while root.parent is not None:
        root = root.parent
    tree = root.tree
    if tree is not None and key in tree.members:  # (never one in progress: not known yet)
        return tree.members[key]
    found = _member_class(entry, name, active)
    if tree is not None:
        tree.members[key] = found
    return found


def _member_class(entry: ClassEntry, name: str,
                  active: frozenset[tuple[ClassEntry, str]]) -> ClassEntry | None:
    found = entry.child(name)
    if found is not None:
        return found
    key = (entry, name)
    if key in active:
        raise _LookupCycle
    short = entry.defn.short
    if short is not None and not short.dims and entry.parent is not None:
        # `package Medium = Base`: the classes of Base, and those its modification
        # redeclares: `package P2 = P(redeclare model A = B)` (section 7.3). Not when
        # it modifies constants (`= Base(n = 3)`): its classes would see them.
        for arg in short.modification.arguments if short.modification else ():
            new = arg.redeclare
            if not isinstance(new, s.ClassDef):
                return None
            if isinstance(new, s.ClassDef) and new.name == name and new.short is not None:
                if new.short.modification is not None:
                    return None  # with a modification of its own: not a plain class
                return _resolve_quiet(new.short.base, entry.parent, active | {key})
        target = _resolve_quiet(short.base, entry.parent, active | {key})
        return member_class(target, name, active | {key}) \
            if target is not None and target is not entry else None
    for element in entry.defn.elements:
        if isinstance(element, s.Extends):
            try:
                base = _resolve_quiet(element.base, entry, active | {key}, extends=True)
            except _LookupCycle:
                dotted = ".".join(part.name for part in element.base.parts)
                raise FlattenError(
                    f"class '{entry.full_name}' extends '{dotted}', whose lookup "
                    f"needs the class '{name}' of '{entry.full_name}' itself, and "
                    f"'{entry.full_name}' has no class '{name}'", element.span,
                    hint=f"define '{name}' in '{entry.full_name}' (in the package or, "
                    f"for a package folder, as {name}.mo or {name}/package.mo), or "
                    "correct the extends clause") from None
            if base is not None and base is not entry:
                found = member_class(base, name, active)
                if found is not None:
                    return found
    return None


def _resolve_quiet(ref: s.Ref, scope: ClassEntry, active: frozenset[tuple[ClassEntry, str]],
                   extends: bool = False) -> ClassEntry | None:
    first = ref.parts[0].name
    entry = (base_lookup(first, scope, active) if extends
             else lookup_class(first, scope, active))
    for part in ref.parts[1:]:
        if entry is None:
            return None
        entry = member_class(entry, part.name, active)
    return entry


def lookup_class(name: str, scope: ClassEntry,
                 active: frozenset[tuple[ClassEntry, str]] = frozenset()) -> ClassEntry | None:
    """Find the class a simple name denotes from ``scope``: local and inherited classes,
    imports, then enclosing classes (stopping at ``encapsulated``, except for the root)."""
    entry: ClassEntry | None = scope
    while entry is not None:
        found = member_class(entry, name, active) or _imported(entry, name, active)
        if found is not None:
            return found
        if entry.defn.encapsulated:
            root = entry
            while root.parent is not None:
                root = root.parent
            return root.child(name)
        entry = entry.parent
    return None


def base_lookup(name: str, entry: ClassEntry,
                active: frozenset[tuple[ClassEntry, str]] = frozenset()) -> ClassEntry | None:
    """The first name of an ``extends`` clause of ``entry`` (Modelica 3.6, section
    5.6.1): a class declared in ``entry`` itself (not inherited, so that the lookup
    does not need the base classes it is resolving) or imported into it, else the
    normal lookup from the enclosing class."""
    found = entry.child(name) or _imported(entry, name, active)
    if found is not None:
        return found
    if entry.parent is None:
        return None
    if entry.defn.encapsulated:
        root = entry
        while root.parent is not None:
            root = root.parent
        return root.child(name)
    return lookup_class(name, entry.parent, active)


def _imported(entry: ClassEntry, name: str,
              active: frozenset[tuple[ClassEntry, str]]) -> ClassEntry | None:
    """The class ``name`` imported into ``entry``. An import whose package (or, for a
    qualified import of ``name``, whose class) is not loaded is an error at the import."""
    root = entry
    while root.parent is not None:
        root = root.parent
    for element in entry.defn.elements:
        if not isinstance(element, s.Import):
            continue
        named = (element.alias == name) or (name in element.names and element.alias is None)
        if not named and not element.wildcard:
            continue
        package = _import_path(root, element.path, element, active)
        target = element.names[0] if element.alias == name else name
        found = member_class(package, target, active)
        if found is not None:
            return found
        if named and _declares(package.defn, target):
            return None  # a constant, found by imported_element
        if named:
            raise FlattenError(
                f"the imported class '{'.'.join((*element.path, target))}' is not loaded: "
                f"'{package.full_name}' has no class '{target}'", element.span,
                [Note(f"'{package.full_name}' is defined here", package.defn.span)],
                hint="check the spelling of the import")
    return None


def _declares(defn: s.ClassDef, name: str) -> bool:
    return any(isinstance(e, s.Component) and e.name == name for e in defn.elements)


def imported_element(scope: ClassEntry, name: str) -> tuple[ClassEntry, str] | None:
    """``import Modelica.Constants.pi;`` seen from ``scope`` or an enclosing class: the
    package and the name of the imported component (a constant), or None."""
    entry: ClassEntry | None = scope
    while entry is not None:
        unqualified: list[tuple[ClassEntry, s.Import]] = []
        for element in entry.defn.elements:
            if not isinstance(element, s.Import):
                continue
            named = (element.alias == name) or (name in element.names and element.alias is None)
            if not named and not element.wildcard:
                continue
            root = entry
            while root.parent is not None:
                root = root.parent
            package = _import_path(root, element.path, element, frozenset())
            target = element.names[0] if element.alias == name else name
            if _declares(package.defn, target):
                if named:
                    return package, target
                unqualified.append((package, element))
        if len(unqualified) > 1:
            first, second = unqualified[0][0], unqualified[1][0]
            raise FlattenError(
                f"'{name}' is found by two unqualified imports, in '{first.full_name}' and "
                f"'{second.full_name}'", unqualified[1][1].span,
                [Note(f"'{first.full_name}.*' is imported here", unqualified[0][1].span)],
                "a name may be found in only one unqualified import; import it by name "
                "(Modelica 3.6, section 13.2.1.1)")
        if unqualified:
            return unqualified[0][0], name
        if entry.defn.encapsulated:
            return None
        entry = entry.parent
    return None


def _import_path(root: ClassEntry, path: Sequence[str], element: s.Import,
                 active: frozenset[tuple[ClassEntry, str]]) -> ClassEntry:
    found = root
    for depth, part in enumerate(path):
        member = member_class(found, part, active)
        if member is None:
            missing = ".".join(path[:depth + 1])
            tree = root.tree
            raise FlattenError(
                f"the imported package '{'.'.join(path)}' is not loaded"
                if depth == len(path) - 1 else
                f"the import names '{'.'.join(path)}', but '{missing}' is not loaded",
                element.span, hint="load the library that defines it (name its file, "
                "or pass its folder with -L or in MODELICAPATH)"
                + (f"; searched {tree.searched()}" if tree is not None else ""))
        if member.defn.kind != "package" and depth == len(path) - 1:
            raise FlattenError(
                f"'{'.'.join(path[:depth + 1])}' is a {member.defn.kind}, and an import "
                "takes classes and constants from packages only", element.span,
                [Note(f"'{member.full_name}' is defined here", member.defn.span)],
                hint="import from a package, or use the class by its full name (Modelica "
                "3.6, section 13.2.1)")
        found = member
    return found


def _unknown_class_hint(name: str, scope: ClassEntry) -> str:
    visible: set[str] = set()
    entry: ClassEntry | None = scope
    root = scope
    while entry is not None:
        visible.update(entry.classes)
        for e in entry.defn.elements:
            if isinstance(e, s.Import):
                visible.update([e.alias] if e.alias else e.names)
        root = entry
        entry = entry.parent
    searched = f"; searched {root.tree.searched()}" if root.tree is not None else ""
    close = close_names(name, sorted(visible), 1)
    if close:
        return f"did you mean '{close[0]}'? (searched {root.tree.searched()})" \
            if root.tree is not None else f"did you mean '{close[0]}'?"
    return (f"no class '{name}' is visible here: check the spelling, add an `import`, "
            "or load the file that defines it (name it on the command line or pass "
            f"its folder with -L){searched}")
