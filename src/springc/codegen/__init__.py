"""Codegen: ``ir.ode.ODE`` -> the text of a standalone Python/numba module."""

from .context import BACKENDS, CodegenBug, CodegenOptions, GeneratedModel
from .generator import generate
from .module_api import HYBRID_NAMES, MODULE_NAMES, GeneratedModule, HybridModule
from .module_text import CODEGEN_VERSION

__all__ = ["BACKENDS", "CODEGEN_VERSION", "HYBRID_NAMES", "MODULE_NAMES", "CodegenBug",
           "CodegenOptions", "GeneratedModel", "GeneratedModule", "HybridModule", "generate"]
