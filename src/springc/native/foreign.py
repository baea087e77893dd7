"""A library's foreign C functions (``external "C"``, Modelica 12.9) compiled from the
C sources the library ships and loaded with ctypes. Standard library only.

:class:`ForeignBuild` is what one build compiles: the library's C files and headers
(read by the caller from inside the library's folder), and springc's glue, C text that
holds the ``Include`` annotation's text and the wrapper of each function. springc's own
ModelicaUtilities (``modelica_utilities.c``, and ``.h`` for sources that include
``ModelicaUtilities.h`` where the library ships none; ModelicaError jumps back to the wrapper,
which returns 1) is compiled with them. :func:`load` builds it once into
``<user cache>/foreign/<key>.so``, the key a digest of the compiler's command, the flags
and every byte compiled, with a hash record beside it; a library is loaded only from
bytes whose hash matched the record, copied first into a private temporary folder (the
file loaded is the file checked). The compiler runs from an argument list in a private
folder where every file has springc's name (``glue.c``, ``source0.c``...) or the name
of a header it copied (checked to be a plain file name): nothing from the model's text
reaches a command line, the annotation's C text only ``glue.c``.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

from ..errors import SpringcError
from ..fileio import keep_newest, replace_private
from ..resources import CacheUnusable, private_folder, user_cache_dir
from .compiler import find_compiler, first_error, run_compiler
from .runner import read_verified

FLAGS = ("-O2", "-g0", "-shared", "-fPIC", "-DNDEBUG", "-DHAVE_UNISTD_H",
         "-DHAVE_STDARG_H", "-DHAVE_HIDDEN", "-DHAVE_MEMCPY",
         "-Werror=implicit-function-declaration")
"""Those of the Modelica Standard Library's own gcc build project
(``Resources/BuildProjects/gcc/Makefile``), and a shared library's; a function called
without a declaration is an error (C would assume it returns ``int``, and springc
would read a wrong value: an ``Include`` that names a header without the prototype)."""
UTILITIES = Path(__file__).with_name("modelica_utilities.c")
UTILITIES_HEADER = Path(__file__).with_name("modelica_utilities.h")
"""``ModelicaUtilities.h`` for a library that includes it without shipping it."""
FOLDER = "foreign"
KEY_LENGTH = 32
KEEP = 256
"""Libraries kept in the cache's folder, the most recently built (a record left without
its library is harmless: the library is built again)."""
HEADER_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+-]*\.h")
SUBFOLDER_NAME = re.compile(r"[A-Za-z0-9_]+")


class ForeignBuildFailed(SpringcError):
    """The C compiler refused a library's sources with springc's glue."""


@dataclass(frozen=True)
class ForeignBuild:
    """``sources``: (folder, C text) of each of the library's C files, ``folder`` the
    subfolder of its sources folder (``""`` or a plain name, as MSL's ``zlib``);
    ``headers``: (folder, file name, text) of the headers they may include; ``glue``:
    springc's C text calling the functions."""

    sources: tuple[tuple[str, bytes], ...]
    headers: tuple[tuple[str, str, bytes], ...]
    glue: str

    def key(self, compiler: list[str]) -> str:
        h = hashlib.sha256()
        for part in (*compiler, *FLAGS):
            h.update(part.encode() + b"\0")
        h.update(UTILITIES.read_bytes() + UTILITIES_HEADER.read_bytes())
        h.update(self.glue.encode())
        for folder, data in self.sources:
            h.update(folder.encode() + b"\0" + hashlib.sha256(data).digest())
        for folder, name, data in self.headers:
            h.update(f"{folder}/{name}".encode() + b"\0" + hashlib.sha256(data).digest())
        return h.hexdigest()[:KEY_LENGTH]


class ForeignLibrary:
    """A loaded library of foreign functions: ``lib`` (ctypes), kept in a private
    temporary folder for as long as this object lives; ``key`` names it in the cache."""

    def __init__(self, data: bytes, key: str = "") -> None:
        self.key = key
        self._folder = tempfile.TemporaryDirectory(prefix="springc-foreign-")  # 0700
        path = Path(self._folder.name) / "foreign.so"
        path.write_bytes(data)
        try:
            self.lib = ctypes.CDLL(str(path))
        except OSError as failed:  # a symbol no source defines
            text = str(failed).replace(str(path), "the library")
            raise ForeignBuildFailed(f"it does not load: {text}") from None
        self.lib.springc_error_message.restype = ctypes.c_char_p
        self.lib.springc_error_message.argtypes = []

    def error_message(self) -> str:
        """The message of the last ModelicaError."""
        text: bytes = self.lib.springc_error_message()
        return text.decode("utf-8", "replace")


_LOADED: dict[str, ForeignLibrary] = {}
"""The libraries this process loaded, by key: a model's run-time calls
(:mod:`.foreign_calls`) find theirs here."""


def load(build: ForeignBuild) -> ForeignLibrary:
    """The library of ``build``: from springc's cache where a verified copy is there,
    else compiled (and kept there where the cache folder can be used)."""
    compiler = find_compiler()
    key = build.key(compiler)
    library = _LOADED[key] = ForeignLibrary(_built(build, compiler, key), key)
    return library


def loaded(key: str) -> ForeignLibrary | None:
    """The library of ``key`` this process loaded, else the verified copy in springc's
    cache (a compiled model loaded from the cache by another process), else None."""
    library = _LOADED.get(key)
    folder = _cache_folder() if library is None else None
    if folder is not None:
        data = read_verified(folder / f"{key}.so", folder / f"{key}.so.sha256")
        if data is not None:
            library = _LOADED[key] = ForeignLibrary(data, key)
    return library


def _built(build: ForeignBuild, compiler: list[str], key: str) -> bytes:
    folder = _cache_folder()
    if folder is not None:
        data = read_verified(folder / f"{key}.so", folder / f"{key}.so.sha256")
        if data is not None:
            return data
    data = _compile(build, compiler)
    if folder is not None:
        with contextlib.suppress(OSError):
            replace_private(folder / f"{key}.so.sha256",
                            (hashlib.sha256(data).hexdigest() + "\n").encode("ascii"))
            replace_private(folder / f"{key}.so", data)
        keep_newest(folder, ".so", KEY_LENGTH + 3, KEEP)  # their records: see KEEP
    return data


def _cache_folder() -> Path | None:
    root = user_cache_dir()
    if root is None:
        return None
    try:
        folder = private_folder(root, quiet=True) / FOLDER
        folder.mkdir(mode=0o700, exist_ok=True)
    except (CacheUnusable, OSError):
        return None
    return folder


def _compile(build: ForeignBuild, compiler: list[str]) -> bytes:
    with tempfile.TemporaryDirectory(prefix="springc-foreign-cc-") as name:
        root = Path(name)
        includes = {""}
        for folder, header, data in build.headers:
            _checked_folder(folder)
            if not HEADER_NAME.fullmatch(header):
                continue  # a name springc does not put on a command line
            (root / folder).mkdir(exist_ok=True)
            (root / folder / header).write_bytes(data)
            includes.add(folder)
        if all(header != "ModelicaUtilities.h" for _, header, _ in build.headers):
            (root / "ModelicaUtilities.h").write_bytes(UTILITIES_HEADER.read_bytes())
        files = ["glue.c", "utilities.c"]
        (root / "glue.c").write_text(build.glue, encoding="utf-8")
        (root / "utilities.c").write_bytes(UTILITIES.read_bytes())
        for k, (folder, data) in enumerate(build.sources):
            _checked_folder(folder)
            (root / folder).mkdir(exist_ok=True)
            path = f"{folder}/source{k}.c" if folder else f"source{k}.c"
            (root / path).write_bytes(data)
            files.append(path)
        flags = [f"-I{folder or '.'}" for folder in sorted(includes)]
        argv = [*compiler, *FLAGS, *flags, "-o", "foreign.so", *files, "-lm"]
        code, messages = run_compiler(argv, root, "the library's C sources")
        out = root / "foreign.so"
        if code != 0 or not out.is_file():
            raise ForeignBuildFailed(
                f"the C compiler refused the library's C sources ({argv[0]} exit "
                f"{code}): " + first_error(messages, 300))
        return out.read_bytes()


def _checked_folder(folder: str) -> None:
    if folder and not SUBFOLDER_NAME.fullmatch(folder):
        raise ForeignBuildFailed(f"'{folder}' is not a folder name springc builds in")
