"""Where an external function's C code is (Modelica 12.9.4): its clause's annotation
(``Include``, ``IncludeDirectory``, ``Library``), resolved in the folder of the library
that declares it, and the C files that make each named library.

A ``Library`` named ``L`` is built from ``L.c`` in the include directory or in
``Resources/C-Sources`` of the library's folder; the MSL's libraries from the files its
``Resources/C-Sources/readme.txt`` lists (``ModelicaExternalC`` is ModelicaFFT.c,
ModelicaInternal.c, ModelicaRandom.c and ModelicaStrings.c; ``ModelicaIO`` needs
``ModelicaMatIO`` and ``zlib``). Binaries in ``LibraryDirectory`` are never loaded:
springc compiles the sources itself. Every path comes from a ``modelica://Top/...``
URI of the library's own top-level class and must stay inside that library's folder.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...ir import syntax as s
from ...parse import ClassEntry

LIBRARY_FILES: dict[str, tuple[str, ...]] = {
    "ModelicaExternalC": ("ModelicaFFT.c", "ModelicaInternal.c", "ModelicaRandom.c",
                          "ModelicaStrings.c"),
    "ModelicaMatIO": ("ModelicaMatIO.c", "snprintf.c", "zlib/*.c"),
    "ModelicaIO": ("ModelicaIO.c", "ModelicaMatIO.c", "snprintf.c", "zlib/*.c"),
    "zlib": ("zlib/*.c",),
}
"""The MSL's libraries (``Resources/C-Sources/readme.txt``), with the libraries each
needs to load (a shared library springc builds resolves every symbol itself)."""
SOURCES_FOLDER = ("Resources", "C-Sources")
SYSTEM_LIBRARIES = frozenset({"m"})
"""Libraries every build links (the C math library, ``-lm``)."""


@dataclass(frozen=True)
class CSources:
    """An external function's C code: the ``Include`` text, the include directory and
    the C files of its libraries (empty where the annotation names none: the
    ``Include`` text holds the function itself)."""

    include: str
    include_folder: Path | None
    files: tuple[Path, ...]
    root: Path | None = None  # the folder the files are in (some in subfolders of it)


def annotation_strings(external: s.ExternalCall) -> dict[str, list[str]]:
    """The string values of the external clause's annotation, by name."""
    found: dict[str, list[str]] = {}
    for arg in external.annotation.arguments if external.annotation else ():
        value = arg.modification.value if arg.modification else None
        items = value.items if isinstance(value, s.ArrayLit) else (value,)
        found[".".join(arg.path)] = [i.value for i in items if isinstance(i, s.String)]
    return found


def top_class(entry: ClassEntry) -> ClassEntry:
    """The top-level class of ``entry``'s library (below the tree's root)."""
    top = entry
    while top.parent is not None and top.parent.parent is not None:
        top = top.parent
    return top


def include_uri(external: s.ExternalCall, top: ClassEntry) -> str:
    """The include directory's URI, ``modelica://Top/Resources/Include`` by default."""
    given = annotation_strings(external).get("IncludeDirectory")
    return given[0] if given else f"modelica://{top.defn.name}/Resources/Include"


def resolved(uri: str, top: ClassEntry) -> Path | None:
    """The path a ``modelica://Top/path`` URI names, where ``Top`` is the library
    ``top`` stored as a folder and the path stays inside it; None otherwise."""
    prefix = f"modelica://{top.defn.name}/"
    if not uri.startswith(prefix) or top.folder is None:
        return None
    parts = [p for p in uri[len(prefix):].split("/") if p not in ("", ".")]
    if ".." in parts:
        return None
    path = top.folder.joinpath(*parts)
    try:
        if not path.resolve().is_relative_to(top.folder.resolve()):
            return None  # a link out of the library
    except (OSError, RuntimeError):
        return None
    return path


def c_sources(entry: ClassEntry, external: s.ExternalCall) -> CSources | list[str]:
    """The C code of the external function ``entry``; where some library's files are
    not in this copy of the library, the names it looked for."""
    notes = annotation_strings(external)
    top = top_class(entry)
    include_folder = resolved(include_uri(external, top), top)
    if include_folder is not None and not include_folder.is_dir():
        include_folder = None
    folders = [f for f in (include_folder, resolved("/".join(
        (f"modelica://{top.defn.name}", *SOURCES_FOLDER)), top)) if f is not None]
    if top.tree is not None:  # what a cached compile's check must look at again
        for folder in folders:
            top.tree.lookups.c_sources(folder)
    files: list[Path] = []
    missing: list[str] = []
    root = None
    for library in notes.get("Library", []):
        if library in SYSTEM_LIBRARIES:
            continue
        found = _library_files(library, folders, top)
        if found is None:
            missing.append(library)
            continue
        root = root or found[0]
        files += [f for f in found[1] if f not in files]
    if missing:
        return missing
    if not files and not notes.get("Include"):
        return []  # nothing holds the function's code
    return CSources("\n".join(notes.get("Include", [])), include_folder, tuple(files), root)


def _library_files(library: str, folders: list[Path], top: ClassEntry
                   ) -> tuple[Path, list[Path]] | None:
    """The folder of the first of ``folders`` holding every file of ``library``, and
    those files."""
    patterns = LIBRARY_FILES.get(library, (f"{library}.c",))
    for folder in folders:
        found: list[Path] = []
        for pattern in patterns:
            matches = sorted(folder.glob(pattern)) if "/" not in library else []
            found += [m for m in matches if _inside(m, top) and m.is_file()]
            if not matches:
                break
        else:
            return folder, found
    return None


def _inside(path: Path, top: ClassEntry) -> bool:
    assert top.folder is not None
    return inside(path, top.folder)


def inside(path: Path, folder: Path) -> bool:
    """Whether ``path``, links followed, is inside ``folder`` (links followed): the one
    test that a file springc reads for a library's C code is the library's own."""
    try:
        return path.resolve().is_relative_to(folder.resolve())
    except (OSError, RuntimeError):
        return False
