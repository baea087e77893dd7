"""Codegen: ``ir.ode.ODE`` -> the text of a standalone Python/numba module."""

from .generator import CodegenOptions, generate
from .module_text import CODEGEN_VERSION

__all__ = ["CODEGEN_VERSION", "CodegenOptions", "generate"]
