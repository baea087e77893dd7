"""Codegen: ``ir.ode.ODE`` -> the text of a standalone Python/numba module, or of a C
file (``generate_c``: :mod:`.c_model`).

The contract of a generated module (:mod:`.module_api`: ``GeneratedModule``,
``MODULE_NAMES``, ``CODEGEN_VERSION``) loads with the package; the generator and its
options load on first use (PEP 562), so that the cache can check a cached module
without importing the generator (a warm run never generates).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .module_api import (
    CODEGEN_VERSION,
    HYBRID_NAMES,
    JACOBIAN_LIMIT,
    MODULE_NAMES,
    GeneratedModule,
    HybridModule,
    ModuleKind,
)

if TYPE_CHECKING:
    from .c_model import CModelSource, generate_c
    from .context import BACKENDS, CodegenBug, CodegenOptions, GeneratedModel
    from .generator import generate

__all__ = ["BACKENDS", "CODEGEN_VERSION", "HYBRID_NAMES", "JACOBIAN_LIMIT", "MODULE_NAMES",
           "CModelSource", "CodegenBug", "CodegenOptions", "GeneratedModel", "GeneratedModule",
           "HybridModule", "ModuleKind", "generate", "generate_c"]


def __getattr__(name: str) -> Any:
    # Lazy (see the docstring): the generator loads with its first name.
    if name in ("BACKENDS", "CodegenBug", "CodegenOptions", "GeneratedModel"):
        from . import context

        return getattr(context, name)
    if name == "generate":
        from . import generator

        return generator.generate
    if name in ("generate_c", "CModelSource"):  # the C model (c_model.py)
        from . import c_model

        return getattr(c_model, name)
    raise AttributeError(f"module 'springc.codegen' has no attribute {name!r}")
