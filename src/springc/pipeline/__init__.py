"""Pipeline: source files -> ``CompiledModel`` (flatten, simplify, generate, cache, import)."""

from .compiler import (
    CompiledModel,
    check_parameter_names,
    compile_files,
    generate_source,
    modification_value,
    split_values,
)
from .derive import CompileOptions, derive_system
from .files import flatten_files
from .selection import select_names

__all__ = ["CompileOptions", "CompiledModel", "check_parameter_names", "compile_files",
           "derive_system", "flatten_files", "generate_source", "modification_value",
           "select_names", "split_values"]
