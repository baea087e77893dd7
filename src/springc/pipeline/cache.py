"""The on-disk cache of generated modules: where it lives, its key, verified reads.

Entries live in ``$SPRINGC_CACHE_DIR``, else ``$XDG_CACHE_HOME/springc``, else
``~/.cache/springc``: one folder per key holding ``model.py`` and ``model.sha256``, the
SHA-256 of the module recorded when it was written, and for a model whose runs need more
than the module (an initial problem, dynamic state selection) ``system.pickle`` with
``system.sha256``, read only after its hash matched, as the module is. A module's key is
that of the model combined with the observed variables it computes (:func:`selection_key`).
The model's key (:func:`model_key_for`) is made of what the compile was asked
(:func:`request_key`: options, files and library path as named, springc's code) and of
what loading read to answer it: the lookups record (``parse.Lookups``: each file read
with its SHA-256, each class file found or not found, each listing that decided a
name), kept in the request's own entry (:data:`LOOKUPS_FILE`). A compile checks that
record again (:func:`read_lookups`: the files it names hashed again, the lookups asked
again), so that it reads only the files the model used, not every file of the library
path; any edit of one of them, or a new file that a lookup would now find, misses. The
model's key also names an entry holding ``names.json``
(with ``names.sha256``), its states and observed variables, so that a new ``--vars`` is
resolved to those variables without flattening the model again. The cache folder is
private (created 0700, whatever the umask; a shared sticky folder is used through a
private subfolder, and no folder springc finds has its mode changed or its files
removed: :func:`springc.resources.private_folder`). A module is imported only from the
bytes whose hash matched the record: an edited, planted, truncated or unreadable entry
is regenerated with a one-line note on stderr, never executed. A cache folder that
cannot be used (not a folder, not writable, owned by another user) gives a note, and
the model is compiled in a private temporary folder instead. The least recently used
entries beyond ``CACHE_ENTRIES`` are removed when a new one is written.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import shutil
import sys
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import ModuleType
from typing import cast

from ..codegen import CODEGEN_VERSION, MODULE_NAMES, GeneratedModule
from ..fileio import replace_private
from ..parse import library_folders, still_hold
from ..resources import PACKAGE_ROOT, CacheUnusable, grammar_path, user_cache_dir

CACHE_ENTRIES = 200
"""Generated modules kept in the cache; the least recently used beyond this are removed."""

MODULE_FILE = "model.py"
HASH_FILE = "model.sha256"
NAMES_FILE = "names.json"
"""The record of a model's output names (states, observed), in an entry of its own."""
LOOKUPS_FILE = "lookups.json"
"""What the last compile of a request read (``parse.Lookups.record``), in the request's
entry of its own (:func:`request_key`), with its hash record."""
SYSTEM_FILE = "system.pickle"
"""What a run needs beyond the module (:class:`springc.pipeline.closed.RunSystem`), next
to ``model.py`` in a module's entry when the model has one, with its hash record."""


def note(text: str) -> None:
    """A one-line note on stderr (the cache never fails a compilation)."""
    print("note: " + " ".join(text.splitlines()), file=sys.stderr)


def cache_dir() -> Path:
    """Where generated modules are kept (:class:`CacheUnusable` without a home)."""
    folder = user_cache_dir()
    if folder is None:
        raise CacheUnusable("no home folder")
    return folder


def touch(path: Path) -> None:
    """Mark a cache entry as used (its modification time orders the pruning)."""
    with contextlib.suppress(OSError):  # a read-only cache still works
        os.utime(path)


def prune_cache(folder: Path, keep: str, limit: int | None = None) -> list[Path]:
    """Remove the least recently used entries beyond ``limit`` (never ``keep``): module
    entries and names records are counted apart. Only folders that look like entries
    (a key's name, holding the file and its hash record) are counted or removed."""
    limit = CACHE_ENTRIES if limit is None else limit
    removed = []
    for name in (MODULE_FILE, NAMES_FILE, LOOKUPS_FILE):
        entries = []
        for entry in folder.iterdir() if folder.is_dir() else ():
            if not _is_key(entry.name) or not (entry / _hash_file(name)).is_file():
                continue
            try:
                entries.append(((entry / name).stat().st_mtime, entry))
            except OSError:  # not such an entry, or being written
                continue
        entries.sort(reverse=True)
        removed += [e for _, e in entries[limit:] if e.name != keep]
    for entry in removed:
        shutil.rmtree(entry, ignore_errors=True)
    return removed


# ------------------------------------------------------------------ key


@functools.cache
def springc_digest() -> bytes:
    """SHA-256 of the text of every module and C source below ``PACKAGE_ROOT`` and of
    the grammar: any change to springc's code moves every key (the C loop library of
    an entry, ``cloop.so``, is built from springc's C sources)."""
    h = hashlib.sha256()
    for path in sorted([*PACKAGE_ROOT.glob("**/*.py"), *PACKAGE_ROOT.glob("**/*.c")]):
        h.update(str(path.relative_to(PACKAGE_ROOT)).encode() + b"\0")
        h.update(hashlib.sha256(path.read_bytes()).digest())
    h.update(hashlib.sha256(grammar_path().read_bytes()).digest())
    return h.digest()


def selection_key(model_key: str, observed: object) -> str:
    """The key of the module of ``model_key`` that computes the ``observed`` variables
    (the names, or ``"all"``): ``--vars`` that select the same observed variables,
    whatever states they select, share one module."""
    return hashlib.sha256(repr((model_key, observed)).encode()).hexdigest()[:24]


def request_key(settings: object, files: Sequence[str], libraries: Sequence[str]) -> str:
    """A digest of what a compile is asked, before any file is read: ``settings`` (by
    ``repr``: model, backend, outputs, modifications), the files as named, the library
    path (``-L``, ``SPRINGC_PATH``, ``MODELICAPATH``, the bundled models) and springc's
    own code. Its entry holds the lookups record of the last compile (:data:`LOOKUPS_FILE`),
    whose answers, checked again, complete the model's key (:func:`model_key_for`)."""
    h = hashlib.sha256()
    h.update(repr((CODEGEN_VERSION, settings, tuple(files), tuple(libraries),
                   [str(p) for p in library_folders(libraries)])).encode())
    h.update(springc_digest())
    return h.hexdigest()[:24]


def model_key_for(request: str, lookups: Mapping[str, object]) -> str:
    """The key of a model: its :func:`request_key` and what loading read for it (the
    lookups record, ``parse.Lookups.record``: every file with its SHA-256, every class
    file found or not found, every folder listing that decided a name)."""
    text = json.dumps(lookups, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(f"{request}\0{text}".encode()).hexdigest()[:24]


def read_lookups(folder: Path | None, request: str) -> dict[str, object] | None:
    """The lookups record of the last compile of ``request`` if its hash matches its
    record and the file system still answers every question of it as then (a file read
    changed, or a file added that lookup would find first: None); None without one."""
    data = read_addition(folder / request, LOOKUPS_FILE) if folder is not None else None
    if data is None:
        return None
    try:
        record = json.loads(data)
    except ValueError:
        return None
    return record if still_hold(record) else None


def write_lookups(folder: Path | None, request: str, lookups: Mapping[str, object]) -> None:
    """Keep the lookups record of a compile of ``request`` (replacing the last one);
    silently nothing where the cache cannot hold it."""
    if folder is None:
        return
    with contextlib.suppress(OSError):
        with contextlib.suppress(FileExistsError):
            (folder / request).mkdir(mode=0o700)
        add_to_entry(folder / request, LOOKUPS_FILE,
                     json.dumps(lookups, separators=(",", ":")).encode("utf-8"))


# ------------------------------------------------------------------ entries


def _is_key(name: str) -> bool:
    return len(name) == 24 and all(c in "0123456789abcdef" for c in name)


def _hash_file(name: str) -> str:
    return HASH_FILE if name == MODULE_FILE else name.rsplit(".", 1)[0] + ".sha256"


def read_entry(entry: Path, name: str = MODULE_FILE) -> bytes | None:
    """The text of file ``name`` (the module) of ``entry`` if its hash matches the
    record; ``None`` (with a note, the entry removed) if the entry is damaged or was
    changed; ``None`` silently if there is no entry."""
    module, record = entry / name, entry / _hash_file(name)
    if not module.exists() and not record.exists():
        return None
    try:
        data = module.read_bytes()
        expected = record.read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        expected, data = "", b""
    if hashlib.sha256(data).hexdigest() != expected:
        discard(entry, "does not match its recorded hash")
        return None
    return data


def discard(entry: Path, reason: str) -> None:
    """Remove a damaged cache entry, saying so on stderr."""
    note(f"cache entry {entry} {reason}; regenerating it")
    shutil.rmtree(entry, ignore_errors=True)


def write_entry(entry: Path, text: str, name: str = MODULE_FILE,
                extra: Mapping[str, bytes] | None = None) -> Path:
    """Write ``text`` as file ``name`` (the module) of ``entry`` with its hash record,
    and each file of ``extra`` (name: bytes, e.g. :data:`SYSTEM_FILE`) with its own;
    the path of file ``name``.

    All files are written in a private temporary folder that is then renamed to
    ``entry``, so a reader sees a complete entry or none. If another process wrote the
    entry first, its entry is kept.
    """
    files = {name: text.encode("utf-8"), **(extra or {})}
    new = Path(tempfile.mkdtemp(dir=entry.parent, prefix=".new-"))  # created 0700
    try:
        for file, data in files.items():
            (new / file).write_bytes(data)
            (new / _hash_file(file)).write_text(hashlib.sha256(data).hexdigest() + "\n",
                                                encoding="ascii")
        os.rename(new, entry)
    except OSError:
        shutil.rmtree(new, ignore_errors=True)
        if not entry.is_dir():
            raise
    return entry / name


def add_to_entry(entry: Path, name: str, data: bytes) -> Path:
    """Add file ``name`` (e.g. the C library of the entry's model) to an existing
    ``entry`` with its hash record: both written under temporary names and renamed, the
    record first, so that a reader sees the old file, the new one with its record, or
    a mismatch that it rebuilds; the path of the file."""
    for target, content in ((entry / _hash_file(name),
                             (hashlib.sha256(data).hexdigest() + "\n").encode("ascii")),
                            (entry / name, data)):
        replace_private(target, content)
    return entry / name


def read_addition(entry: Path, name: str) -> bytes | None:
    """The bytes of file ``name`` added to ``entry`` (:func:`add_to_entry`) if its hash
    matches the record; None if there is none, or (with a note) if it is damaged: then
    only that file and its record are removed, and the caller builds it again."""
    path, record = entry / name, entry / _hash_file(name)
    if not path.exists() and not record.exists():
        return None
    try:
        data = path.read_bytes()
        expected = record.read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        expected, data = "", b""
    if hashlib.sha256(data).hexdigest() != expected:
        note(f"{path} does not match its recorded hash; building it again")
        for stale in (path, record):
            with contextlib.suppress(OSError):
                stale.unlink()
        return None
    return data


def import_module(data: bytes, path: Path, name: str) -> GeneratedModule:
    """Execute the module text ``data`` (already verified) as module ``name`` located at
    ``path``; raises ``ImportError`` if it is not a complete generated module."""
    module = ModuleType(name)
    module.__file__ = str(path)
    code = compile(data, str(path), "exec")
    # numba's on-disk cache finds the module again by name when loading.
    sys.modules[name] = module
    try:
        exec(code, module.__dict__)
    except BaseException:
        del sys.modules[name]
        raise
    missing = MODULE_NAMES - set(vars(module))
    if missing:
        del sys.modules[name]
        raise ImportError(f"{path} is not a generated module of this springc: it does "
                          f"not define {sorted(missing)[0]}")
    return cast(GeneratedModule, module)


Names = tuple[tuple[str, ...], tuple[str, ...]]
"""A model's states and observed variables, in model order."""


def read_names(folder: Path | None, model_key: str) -> Names | None:
    """The names record (states, observed) of ``model_key``; None without a cache, a
    record or with a damaged one. The names are data: they select outputs and enter
    keys, never code (a module is generated from the model, not from the record)."""
    data = read_entry(folder / model_key, NAMES_FILE) if folder is not None else None
    if data is None:
        return None
    try:
        record = json.loads(data)
        states, observed = record["states"], record["observed"]
        if all(isinstance(n, str) for n in [*states, *observed]):
            return tuple(states), tuple(observed)
    except (ValueError, TypeError, KeyError):
        pass
    return None


def write_names(folder: Path | None, model_key: str, names: Names) -> None:
    """Record the names of ``model_key`` (once; a read-only cache is left alone)."""
    if folder is None or (folder / model_key / NAMES_FILE).exists():
        return
    text = json.dumps({"states": list(names[0]), "observed": list(names[1])})
    with contextlib.suppress(OSError):
        write_entry(folder / model_key, text, NAMES_FILE)
