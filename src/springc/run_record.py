"""Run records: what a warm ``springc simulate`` needs to replay a finished run without
the compile path, numpy or click (:mod:`springc.launcher`). Standard library only.

After a ``simulate`` that ran on the C loop library and wrote a CSV (or nothing but its
summary), the command line writes a record into springc's cache folder
(``runs/<key>.json``). Its **key** (:func:`lookup_key`) is a SHA-256 over the command
line after the program name, the working folder, the environment variables that can
change a run (:data:`RUN_ENVIRONMENT`, every ``SPRINGC_*``), the interpreter, and the
record format. Its **content** (a JSON object, :data:`FORMAT`):

- ``code``: the stamp of springc's code and C sources (:func:`code_stamp`: moved by any
  change of a module, ``CODEGEN_VERSION`` and the version included);
- ``files``, ``libraries``, ``inputs``: the model files and library folders of the
  command, and what the model's load read (:class:`springc.parse.Lookups`: each file
  with its SHA-256, each class file found or not found, each listing that decided a
  name), asked again by :func:`verified`;
- ``library``: the loop library's path in the model's cache entry and its SHA-256;
- ``run``: the run as it was resolved: the output grid, parameter vector, start state
  and ``z``, the answer run's solver and tolerances, its companion's (or none), the
  tolerances the error rule judges by, the output columns (a state or an observed
  variable each, in the CSV's order) and their names;
- ``output``: its kind (``csv``), the CSV file (or none: the CSV on stdout), the files
  it may never replace, the verbosity, and what the run printed, to check the replay
  against: the summary line without its time, and the SHA-256 of the CSV text.

Nothing in a record is trusted: :func:`verified` re-reads and re-hashes every input
(:func:`springc.parse.still_hold`) and the library, and a record that is missing,
unreadable, malformed, of another format or for other code is no record. The replay
itself is checked against the recorded CSV digest and summary before anything is
written (:mod:`springc.launcher`).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, TypeGuard

from .fileio import keep_newest, replace_private
from .parse import still_hold  # the face and its lookups: no parser, no lark
from .resources import PACKAGE_ROOT, CacheUnusable, grammar_path, private_folder, user_cache_dir

FORMAT = 2
"""The version of the record's layout: a record of another is no record."""
RECORDS_FOLDER = "runs"
"""The cache folder's subfolder of run records."""
KEEP = 200
"""Run records kept; the least recently written beyond this are removed."""
RUN_ENVIRONMENT = ("MODELICAPATH", "CC", "PATH", "HOME", "XDG_CACHE_HOME")
"""Environment variables (besides every ``SPRINGC_*``) that can change a run: the library
path, the C compiler (``$CC``, else one found on the PATH) and the cache folder."""
SOURCE_SUFFIXES = (".py", ".c", ".h", ".lark")


def lookup_key(argv: Sequence[str], cwd: str | None = None,
               environ: Mapping[str, str] | None = None) -> str:
    """The key of a run of ``springc ARGV`` in the folder ``cwd`` with ``environ``
    (defaults: this process's)."""
    env = os.environ if environ is None else environ
    relevant = sorted((name, value) for name, value in env.items()
                      if name.startswith("SPRINGC_") or name in RUN_ENVIRONMENT)
    text = json.dumps([FORMAT, list(argv), os.getcwd() if cwd is None else cwd, relevant,
                       sys.executable, sys.version])
    return hashlib.sha256(text.encode("utf-8", "surrogateescape")).hexdigest()


def code_stamp() -> str:
    """What a record's ``code`` must equal: the SHA-256 over the path, size and
    modification time of every source file of springc (``.py``, the C sources, the
    grammar), the check Python's own bytecode cache makes of a module (a change of any
    module, ``CODEGEN_VERSION`` and the version included, moves it)."""
    found = []
    root = str(PACKAGE_ROOT)
    for folder, subfolders, names in os.walk(root):
        subfolders[:] = [d for d in subfolders if d != "__pycache__"]
        for name in names:
            if name.endswith(SOURCE_SUFFIXES):
                path = folder + os.sep + name
                info = os.stat(path)
                found.append((path[len(root):], info.st_size, info.st_mtime_ns))
    info = os.stat(grammar_path())
    found.sort()
    found.append(("grammar", info.st_size, info.st_mtime_ns))
    return hashlib.sha256(repr(found).encode()).hexdigest()


def _records(create: bool) -> Path | None:
    folder = user_cache_dir()
    if folder is None or not (create or folder.is_dir()):
        return None
    try:
        base = private_folder(folder, quiet=True)
    except CacheUnusable:
        return None
    records = base / RECORDS_FOLDER
    if create:
        with contextlib.suppress(FileExistsError):
            records.mkdir(mode=0o700)
    return records if records.is_dir() else None


def write(key: str, content: Mapping[str, Any]) -> Path | None:
    """Write the record of ``key`` (a complete file or none: a private temporary file
    renamed into place), pruning the oldest beyond :data:`KEEP`; its path, or None where
    the cache cannot hold it (a run never fails for its record)."""
    try:
        records = _records(create=True)
        if records is None:
            return None
        target = records / f"{key}.json"
        text = json.dumps({"format": FORMAT, "key": key, **content})
        replace_private(target, text.encode("utf-8"))
        prune(records)
        return target
    except OSError:
        return None


def prune(records: Path, keep: int = KEEP) -> None:
    """Remove the least recently written records beyond ``keep``."""
    keep_newest(records, ".json", 69, keep)


def read(key: str) -> dict[str, Any] | None:
    """The record of ``key`` as written, or None (none, unreadable, not JSON, another
    format or key)."""
    records = _records(create=False)
    if records is None:
        return None
    try:
        content = json.loads((records / f"{key}.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(content, dict) or content.get("format") != FORMAT \
            or content.get("key") != key:
        return None
    return content


def verified(record: Mapping[str, Any]) -> bytes | None:
    """The loop library's bytes if ``record`` is for this code and every input it names
    (the same files, found the same way) and the library still have their recorded
    SHA-256; else None."""
    if record.get("code") != code_stamp():
        return None
    files, libraries = record.get("files"), record.get("libraries")
    if not (_strings(files) and _strings(libraries)):
        return None
    if not still_hold(record.get("inputs")):
        return None
    library = record.get("library")
    if not (isinstance(library, dict) and isinstance(library.get("path"), str)):
        return None
    try:
        data = Path(library["path"]).read_bytes()
    except OSError:
        return None
    return data if hashlib.sha256(data).hexdigest() == library.get("sha256") else None


def _strings(values: object) -> TypeGuard[list[str]]:
    return isinstance(values, list) and all(isinstance(v, str) for v in values)
