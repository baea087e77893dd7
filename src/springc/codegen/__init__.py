"""Codegen: ``ir.ode.ODE`` -> the text of a standalone Python/numba module."""

from .context import BACKENDS, CodegenBug, CodegenOptions, GeneratedModel
from .generator import generate
from .module_api import MODULE_NAMES, GeneratedModule
from .module_text import CODEGEN_VERSION

__all__ = ["BACKENDS", "CODEGEN_VERSION", "MODULE_NAMES", "CodegenBug", "CodegenOptions",
           "GeneratedModel", "GeneratedModule", "generate"]
