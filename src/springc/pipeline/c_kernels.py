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
import re
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..codegen import JACOBIAN_LIMIT, CodegenBug
from ..errors import CodegenError
from ..integrate import locked, loop_text
from ..native import LIBRARY_FILE, LoopLibrary
from ..status_line import say
from .c_build import ZIG_MODULE, CompilerRefused, build_library, c_source, find_compiler
from .cache import add_to_entry, note, read_addition
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


LOOP_NOTE = "compiling the C loop of {model} for this machine (once), about {seconds} s"
"""The status line before a model's loop library is built (it is not in the cache)."""


C_LOOP_CODE_CHARS = 1_000_000
"""The most characters of C functions (``SPRINGC_CODE_CHARS``) of a model the C loop
takes: the C compiler's time grows faster than the code of one function (scalar
statements: the 100-mass chain's 0.5 MB took gcc -O2 3 s of CPU, the 1,000-mass
chain's 5 MB over 3 minutes). Large scenes in the vector layout stay far below (the
10,000-mass chain: loops over index tables, gcc 3 s); a model beyond runs on numba."""
C_LOOP_STACK_BYTES = 2 * 1024 * 1024
"""The most bytes the C loop's model functions keep on the stack of the thread that
runs them: the work arrays of the vector layout (``SPRINGC_WORK_DOUBLES``) and the
loop's row of observed values (``SPRINGC_N_OBSERVED``); a quarter of Linux's usual
8 MiB (the 10,000-mass chain: 1.3 MB); a model beyond runs on numba."""


C_LOOP_DIFFERENCED_STATES = 2_000
"""The most states of a model whose C model has no Jacobian (``SPRINGC_HAS_JACOBIAN``
0: over ``codegen.JACOBIAN_LIMIT`` non-zeros) the C loop takes. Its radau and bdf
(asked for, or run by ``auto``'s race) difference the Jacobian by groups of columns
on the generated module's pattern (``integrate.native_loop.pattern_prelude``; the
1,000-mass chain: a few evaluations per Jacobian, banded LU), so the limit is not
theirs (it was 256 while they differenced a dense one): it is the largest such model
measured on the C loop, the 1,000-mass chain's 2,000 states (warm, 0.9-1.1x the
hand-written loop's time). Larger ones (the 10,000-mass chain's 12 MB of C printed
cold, the 50x50 cloth's 14 MB and its memory) stay on numba until measured there."""


class CLoopRefused(CodegenError):
    """The C loop cannot run a model: it exceeds what the loop takes
    (:func:`loop_refusal`), or the C compiler refused its text (``failed_build``:
    a bug of springc's C printer or a broken compiler, worth a note)."""

    def __init__(self, message: str, failed_build: bool = False) -> None:
        super().__init__(message)
        self.failed_build = failed_build


def note_refused(error: CodegenError, instead: str) -> None:
    """The one-line note on stderr of a C loop the compiler refused (``error``),
    saying which loop runs ``instead``; nothing for a model the loop does not take."""
    if isinstance(error, CLoopRefused) and error.failed_build:
        note(f"{error.message}; running on {instead}")


def loop_refusal(text: str) -> str | None:
    """Why the C loop does not take the model of the C file ``text`` (its size
    macros against :data:`C_LOOP_CODE_CHARS`, :data:`C_LOOP_STACK_BYTES` and
    :data:`C_LOOP_DIFFERENCED_STATES`), or
    None where it does. The loop runs continuous models only: the caller checks."""
    sizes = _sizes(text)
    code = sizes["SPRINGC_CODE_CHARS"]
    if code > C_LOOP_CODE_CHARS:
        return (f"its C functions take {code:,} characters (the C loop takes at most "
                f"{C_LOOP_CODE_CHARS:,})")
    stack = 8 * (sizes["SPRINGC_WORK_DOUBLES"] + sizes["SPRINGC_N_OBSERVED"])
    if stack > C_LOOP_STACK_BYTES:
        return (f"its C functions need {stack:,} bytes of stack (the C loop takes at "
                f"most {C_LOOP_STACK_BYTES:,})")
    states = sizes["SPRINGC_N_STATES"]
    if not sizes["SPRINGC_HAS_JACOBIAN"] and states > C_LOOP_DIFFERENCED_STATES:
        return _differenced_refusal(states)
    return None


def known_refusal(model: CompiledModel) -> str | None:
    """Why the C loop does not take ``model``, where its generated module tells without
    printing its C file (the 10,000-mass chain's is 12 MB, about 8 s of CPU, printed
    only to be refused): over :data:`C_LOOP_DIFFERENCED_STATES` states and Jacobian
    non-zeros
    in more than :data:`~springc.codegen.JACOBIAN_LIMIT` rows (``JAC_ROWS``). The C
    file then has no Jacobian: its scalar one has the module's pattern, its grouped one
    is not printed where more derivatives than the limit read a state
    (``codegen.c_vector.jacobian_floor``), and each row holding a non-zero is such a
    derivative. None where only the C file tells (:func:`loop_refusal`)."""
    states = len(model.states)
    if states <= C_LOOP_DIFFERENCED_STATES or len(model.module.JAC_ROWS) <= JACOBIAN_LIMIT:
        return None
    if len(set(model.module.JAC_ROWS.tolist())) <= JACOBIAN_LIMIT:
        return None
    return _differenced_refusal(states)


def _differenced_refusal(states: int) -> str:
    return (f"it has {states:,} states and no Jacobian in C (the C loop takes at most "
            f"{C_LOOP_DIFFERENCED_STATES:,} states without one)")


def _sizes(text: str) -> dict[str, int]:
    head = text[:text.find("#ifndef SPRINGC_NO_TABLES")]
    return {name: int(value) for name, value
            in re.findall(r"^#define (SPRINGC_\w+) (\d+)$", head, re.MULTILINE)}


def loop_library(model: CompiledModel) -> LoopLibrary:
    """The loop library of ``model`` (the compiled engine's DOP853 and RK45 in C around
    the model's C functions, :func:`springc.integrate.native_loop.loop_text`), loaded:
    from its cache entry (``cloop.so``, verified against ``cloop.sha256``), else built
    once (under a file lock in the entry, so that workers that need it at once build it
    once) and added there. The entry's key covers springc's C sources
    (:func:`.cache.springc_digest`), so the library's name needs no hash of its own.
    :class:`CLoopRefused` where the model exceeds what the loop takes or the compiler
    refuses its text; a :class:`CodegenError` where C cannot spell the model."""
    entry = model.path.parent
    data = read_addition(entry, LIBRARY_FILE)
    if data is None:
        refusal = known_refusal(model)
        text = "" if refusal is not None else c_source(model)
        refusal = refusal or loop_refusal(text)
        if refusal is not None:
            raise CLoopRefused(f"the C loop does not run {model.name}: {refusal}")
        with locked(entry, "cloop"):
            data = read_addition(entry, LIBRARY_FILE)  # built while this one waited
            if data is None:
                data = _build_loop(model, text)
                with contextlib.suppress(OSError):  # a read-only cache: built again
                    add_to_entry(entry, LIBRARY_FILE, data)
    return _loaded(hashlib.sha256(data).hexdigest(), data)


def _build_loop(model: CompiledModel, model_text: str) -> bytes:
    name, sizes = model.name, _sizes(model_text)
    pattern = None if sizes["SPRINGC_HAS_JACOBIAN"] else (
        np.asarray(model.module.JAC_INDPTR), np.asarray(model.module.JAC_INDICES))
    text = loop_text(model_text, pattern)
    loop_code = len(loop_text(""))  # the loop's own code (tables cost little)
    seconds = max(1, round((sizes["SPRINGC_CODE_CHARS"] + loop_code) / LOOP_CHARS_PER_SECOND))
    if seconds > 1 or ZIG_MODULE in find_compiler():
        say(LOOP_NOTE.format(model=name, seconds=seconds))
    with tempfile.TemporaryDirectory(prefix="springc-cc-") as folder:
        try:
            return build_library(text, Path(folder), LOOP_FLAGS)
        except CompilerRefused as bug:
            raise CLoopRefused(f"the C compiler refused the C loop of {name} "
                               f"({bug.first_error()})", failed_build=True) from None


LOOP_CHARS_PER_SECOND = 70_000
"""About the characters of C code (the model's functions, ``SPRINGC_CODE_CHARS``, and
the loop's; the name tables cost little) the compiler takes per CPU second (the seed's
loop library, about 98,000 characters with the implicit methods, GCC compiling those at
-O1, takes 1.1-1.6 s with gcc): the status line's estimate, said where the build may
take over a second."""
LOOP_FLAGS = ("-fvisibility=hidden",)
"""Only the loop library's ``springc_loop_*`` entries are exported (the model's
functions are static, inlined into the loop)."""


@functools.lru_cache(maxsize=64)
def _loaded(digest: str, data: bytes) -> LoopLibrary:
    """The library of ``data`` loaded once per process (keyed by its digest, the
    bytes already verified)."""
    del digest
    return LoopLibrary(data)
