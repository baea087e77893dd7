"""Parse: Modelica text -> ``ir.syntax``; files and library folders -> ``ClassTree``.

The library path and its file walk (:mod:`.library`, which parses nothing) and the
record of what a load read (:mod:`.lookups`) load with the package; the parser (lark)
and the class tree load on first use (PEP 562), so that the cache key of a cached
model is checked without importing lark.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .library import library_folders, library_roots
from .lookups import Lookups, still_hold

if TYPE_CHECKING:
    from .loader import ClassEntry, ClassTree, imported_element, lookup_class, member_class
    from .parse_cache import clear_parse_cache
    from .parser import parse_expression, parse_file, parse_text
    from .user_sources import load

__all__ = ["ClassEntry", "ClassTree", "Lookups", "clear_parse_cache", "imported_element",
           "library_folders", "library_roots",
           "load", "lookup_class", "member_class", "parse_expression", "parse_file", "parse_text",
           "still_hold"]


def __getattr__(name: str) -> Any:
    # Lazy (see the docstring): lark loads with the first name of the parser.
    if name in ("ClassEntry", "ClassTree", "imported_element", "lookup_class",
                "member_class"):
        from . import loader

        return getattr(loader, name)
    if name == "clear_parse_cache":
        from . import parse_cache

        return parse_cache.clear_parse_cache
    if name in ("parse_expression", "parse_file", "parse_text"):
        from . import parser

        return getattr(parser, name)
    if name == "load":
        from . import user_sources

        return user_sources.load
    raise AttributeError(f"module 'springc.parse' has no attribute {name!r}")
