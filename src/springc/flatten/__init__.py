"""Flatten: ``parse.ClassTree`` -> ``ir.flat.FlatModel`` (modifications, inheritance,
arrays, connections, functions)."""

from .flattener import flatten
from .names import select_model

__all__ = ["flatten", "select_model"]
