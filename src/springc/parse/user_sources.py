"""The user's files and texts, and the library path -> a new :class:`ClassTree`
(:func:`load`); library classes are parsed later, when lookup needs them."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

from ..errors import ErrorGroup, LoadError, SourceName, SpringcError
from ..ir import syntax as s
from .library import is_package_file, library_roots
from .loader import ClassTree
from .parse_cache import parse_cached


def load(files: Sequence[str | Path], libraries: Iterable[str | Path] = (),
         texts: Sequence[tuple[str, str]] = ()) -> ClassTree:
    """Parse the user's files and the user's ``texts`` (``(pseudo file name, text)``
    pairs, such as ``("<string>", ...)``: their excerpts are kept for error messages);
    library classes are parsed when lookup needs them.

    Classes of the user's files are placed in precedence order: files without
    ``within`` before those placed inside a package (shallow packages first). A
    ``package.mo`` named by the user is loaded as a library package (its other files on
    demand) and is not where the default model comes from.
    """
    errors: list[SpringcError] = []
    roots = library_roots(libraries)
    tree = ClassTree()
    for root in roots:
        if not tree.lookups.is_dir(root.folder) and root.origin != "MODELICAPATH":
            errors.append(LoadError(f"library folder '{root.folder}' does not exist",
                                    hint="check the -L option and SPRINGC_PATH"))
    tree.roots = [r for r in roots if tree.lookups.is_dir(r.folder)]
    parsed: list[tuple[s.StoredDefinition, Path | None]] = []
    for name in files:
        path = Path(name)
        resolved = tree.lookups.read(path)  # (its bytes' hash taken before the parse)
        real = Path(resolved) if resolved is not None else path.resolve()
        if real in tree.parsed_paths:
            continue
        tree.parsed_paths.append(real)
        try:
            parsed.append((parse_cached(path), path))
        except ErrorGroup as group:
            errors += group.errors
        except SpringcError as error:
            errors.append(error)
    for text_name, text in texts:
        from .parser import parse_text  # lark: the files may all come from the store

        try:  # its spans carry the text, for the excerpts of their errors
            parsed.append((parse_text(text, SourceName(text_name, text), defer=True), None))
        except ErrorGroup as group:
            errors += group.errors
        except SpringcError as error:
            errors.append(error)
    for stored, source in sorted(parsed, key=lambda p: len(p[0].within or ())):
        package = source is not None and is_package_file(source)
        try:
            errors += tree.add(stored, override=True,
                               folder=source.parent if source is not None and package else None)
        except ErrorGroup as group:
            errors += group.errors
        except SpringcError as error:
            errors.append(error)
        (tree.named_packages if package else tree.user_files).append(stored)
    # The default model is the last of the user's files as named.
    order = {id(stored): i for i, (stored, _) in enumerate(parsed)}
    tree.user_files.sort(key=lambda f: order[id(f)])
    if errors:
        raise errors[0] if len(errors) == 1 else ErrorGroup(errors)
    return tree
