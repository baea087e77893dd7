"""One compile of a kernel at a time on a machine: a file lock beside numba's cache.

Worker processes of a sweep, a tradeoff study or a Dask cluster that need a kernel numba
has not cached would each compile it at once (minutes of CPU each, on every core). The
first to take the lock compiles and writes numba's cache; the others wait, then load it.
Where file locks are unavailable (no ``fcntl``, a read-only folder) each compiles alone,
as numba would.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any


@contextlib.contextmanager
def locked(folder: Path, name: str) -> Iterator[None]:
    """Hold the exclusive lock ``folder/name.lock`` inside the block (waiting for it)."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    try:
        folder.mkdir(parents=True, exist_ok=True)
        handle = open(folder / f"{name}.lock", "a+b")  # noqa: SIM115 (closed below)
    except OSError:
        yield
        return
    with handle:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle.fileno(), fcntl.LOCK_UN)


def cache_folder(dispatcher: Any) -> Path | None:
    """The folder of numba's on-disk cache of a ``cache=True`` dispatcher."""
    cache = getattr(dispatcher, "_cache", None)
    folder = getattr(cache, "_cache_path", None)
    return Path(folder) if folder else None


def index_file(dispatcher: Any) -> Path | None:
    """numba's cache index of a ``cache=True`` dispatcher (present once it compiled)."""
    cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    index = getattr(cache_file, "_index_path", None)
    return Path(index) if index else None


def compile_once(dispatcher: Any, signature: Any) -> None:
    """Compile ``dispatcher`` for ``signature`` (or load it from numba's cache) under the
    lock of its cache folder, then freeze it to that signature."""
    if tuple(signature.args) in dispatcher.overloads:
        return
    folder = cache_folder(dispatcher)
    name = dispatcher.py_func.__qualname__
    lock = locked(folder, name) if folder is not None else contextlib.nullcontext()
    with lock:
        dispatcher.compile(signature)
    dispatcher.disable_compile()
