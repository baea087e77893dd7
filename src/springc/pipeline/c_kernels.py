"""A compiled kernel around a model's C file: a translation unit (the model's C text
with the caller's code, e.g. :mod:`springc.integrate.native_ensemble`'s ensemble
kernel) built once per cache entry by the system C compiler.

The library is an addition to the model's cache entry (:func:`.cache.add_to_entry`),
named by the SHA-256 of its text and compiler arguments, and is returned as bytes only
when they match their hash record (the caller loads those bytes from a private folder,
as :class:`.c_build.CLibrary` does). The compiler and its flags are
:func:`.c_build.build_library`'s. OpenMP is a capability of the compiler found, tested
once per compiler and flags in this process (:func:`openmp_flags`): ``zig cc`` accepts
``-fopenmp`` but brings no OpenMP runtime, and a kernel without it runs its serial loop.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import hashlib
import tempfile
from collections.abc import Sequence
from pathlib import Path

from ..codegen import CodegenBug
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


OPENMP_PROBE = """#ifdef _OPENMP
#include <omp.h>
#endif
int springc_openmp_probe(int n) {
    int s = 0;
#pragma omp parallel for reduction(+:s) num_threads(2)
    for (int i = 0; i < n; i++) s += i;
#ifdef _OPENMP
    return omp_get_max_threads() > 0 ? s : -1;
#else
    return -2;
#endif
}
"""
"""A parallel loop that sums 0..n-1: OpenMP works where it compiles, loads (its runtime
resolved) and returns the sum with ``_OPENMP`` defined."""


def openmp_flags(flags: Sequence[str]) -> tuple[str, ...]:
    """``flags`` (the compiler's OpenMP arguments) where the compiler found builds and
    loads :data:`OPENMP_PROBE` with them, else none (the kernel's serial path)."""
    wanted = tuple(flags)
    return wanted if _openmp_works(tuple(find_compiler()), wanted) else ()


@functools.cache
def _openmp_works(compiler: tuple[str, ...], flags: tuple[str, ...]) -> bool:
    # ``compiler`` is the cache key: build_library runs the compiler find_compiler names
    del compiler
    with tempfile.TemporaryDirectory(prefix="springc-omp-") as folder:
        try:
            data = build_library(OPENMP_PROBE, Path(folder), flags)
        except CodegenBug:  # the compiler refused the flags or has no omp.h
            return False
        path = Path(folder) / "probe.so"
        path.write_bytes(data)
        try:
            probe = ctypes.CDLL(str(path)).springc_openmp_probe
        except OSError:  # no OpenMP runtime: unresolved symbols
            return False
        probe.restype, probe.argtypes = ctypes.c_int, [ctypes.c_int]
        return bool(probe(100) == 4950)
