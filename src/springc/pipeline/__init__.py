"""Pipeline: source files -> ``CompiledModel`` (flatten, simplify, generate, cache, import).

The compiled model and the cache lookup load with the package; the compile path
(``derive_system``, ``generate_source``: :mod:`.generation`) and ``flatten_files`` load
on first use (PEP 562), so that a model found in the cache is simulated without
importing the parser, lark, the flattener, simplify or codegen's generator.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..collector import collector_paused
from .apart import compiled_apart, functions_apart, jacobian_apart
from .compiler import (
    CompiledModel,
    ModuleKind,
    check_parameter_names,
    compile_files,
    modification_value,
    split_values,
)
from .notes import announce_functions
from .options import CompileOptions, Derived
from .selection import select_names

if TYPE_CHECKING:
    from .c_build import CCompilerMissing, CLibrary, c_library, c_source, find_compiler
    from .c_kernels import CLoopRefused, kernel_library, loop_library, note_refused, openmp_flags
    from .files import flatten_files
    from .generation import derive_system, generate_source

__all__ = ["CCompilerMissing", "CLibrary", "CLoopRefused", "CompileOptions", "CompiledModel",
           "Derived", "ModuleKind",
           "announce_functions", "c_library", "c_source", "check_parameter_names",
           "collector_paused", "compile_files", "compiled_apart", "derive_system",
           "find_compiler", "flatten_files", "functions_apart", "generate_source",
           "jacobian_apart", "kernel_library", "loop_library", "modification_value",
           "note_refused", "openmp_flags", "select_names", "split_values"]


def __getattr__(name: str) -> Any:
    # Lazy (see the docstring): the compile path loads with its first name.
    if name in ("derive_system", "generate_source"):
        from . import generation

        return getattr(generation, name)
    if name in ("c_library", "c_source", "CLibrary", "CCompilerMissing", "find_compiler"):
        from . import c_build

        return getattr(c_build, name)
    if name in ("kernel_library", "loop_library", "openmp_flags", "CLoopRefused",
                "note_refused"):
        from . import c_kernels

        return getattr(c_kernels, name)
    if name == "flatten_files":
        from . import files

        return files.flatten_files
    raise AttributeError(f"module 'springc.pipeline' has no attribute {name!r}")
