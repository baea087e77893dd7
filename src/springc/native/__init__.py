"""Runs of a model's compiled C loop library with the standard library only (ctypes):
no numpy, numba or scipy is imported (:mod:`.runner`). The library is built by
:func:`springc.pipeline.loop_library` from the text of
:func:`springc.integrate.native_loop.loop_text`; see ``docs/c_model.md``."""

from .compiler import (
    COMPILERS,
    ZIG_MODULE,
    CCompilerMissing,
    CompilerOutOfTime,
    find_compiler,
    first_error,
    run_compiler,
)
from .runner import (
    FIRST_STRETCH,
    LIBRARY_FILE,
    MAX_STEPS,
    METHODS,
    STRETCH_GROWTH,
    LoopLibrary,
    LoopRun,
    cached_library,
    read_verified,
)

__all__ = [
    "COMPILERS",
    "FIRST_STRETCH",
    "LIBRARY_FILE",
    "MAX_STEPS",
    "METHODS",
    "STRETCH_GROWTH",
    "ZIG_MODULE",
    "CCompilerMissing",
    "CompilerOutOfTime",
    "LoopLibrary",
    "LoopRun",
    "cached_library",
    "find_compiler",
    "first_error",
    "read_verified",
    "run_compiler",
]
