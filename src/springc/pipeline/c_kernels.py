"""A compiled kernel around a model's C file: a translation unit (the model's C text
with the caller's code, e.g. :mod:`springc.integrate.native_ensemble`'s ensemble
kernel) built once per cache entry by the system C compiler.

The library is an addition to the model's cache entry (:func:`.cache.add_to_entry`),
named by the SHA-256 of its text and compiler arguments, and is returned as bytes only
when they match their hash record (the caller loads those bytes from a private folder,
as :class:`.c_build.CLibrary` does). The compiler and its flags are
:func:`.c_build.build_library`'s.
"""

from __future__ import annotations

import contextlib
import hashlib
import tempfile
from collections.abc import Sequence
from pathlib import Path

from .c_build import build_library, find_compiler
from .cache import add_to_entry, read_addition
from .compiler import CompiledModel


def kernel_library(model: CompiledModel, text: str, extra: Sequence[str] = (),
                   tag: str = "kernel") -> bytes:
    """The shared library of ``text`` (built with ``extra`` compiler arguments), from
    ``model``'s cache entry when it holds a verified one, else built and added."""
    key = "\0".join((text, *find_compiler(), *extra))
    name = f"{tag}-{hashlib.sha256(key.encode()).hexdigest()[:24]}.so"
    entry = model.path.parent
    data = read_addition(entry, name)
    if data is None:
        with tempfile.TemporaryDirectory(prefix="springc-cc-") as folder:
            data = build_library(text, Path(folder), extra)
        with contextlib.suppress(OSError):  # a read-only cache: built again next time
            add_to_entry(entry, name, data)
    return data
