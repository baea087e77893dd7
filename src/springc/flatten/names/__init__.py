"""Name lookup: classes, short class definitions, functions and package constants
(``lookup``), component references and subscripts (``references``), and lookup from the
class that declares an inherited element (``inherited_rules``)."""

from __future__ import annotations

from .lookup import ClassLookup, select_model
from .references import ReferenceResolver

__all__ = ["ClassLookup", "ReferenceResolver", "select_model"]
