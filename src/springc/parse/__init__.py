"""Parse: Modelica text -> ``ir.syntax``; files and library folders -> ``ClassTree``."""

from .library import library_folders, library_roots, source_files
from .loader import (
    ClassEntry,
    ClassTree,
    clear_parse_cache,
    imported_element,
    load,
    lookup_class,
    member_class,
)
from .parser import parse_expression, parse_file, parse_text

__all__ = ["ClassEntry", "ClassTree", "clear_parse_cache", "imported_element",
           "library_folders", "library_roots",
           "load", "lookup_class", "member_class", "parse_expression", "parse_file", "parse_text",
           "source_files"]
