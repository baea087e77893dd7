"""Parse: Modelica text -> ``ir.syntax``; files and library folders -> ``ClassTree``."""

from .library import library_folders, library_roots, source_files
from .loader import ClassEntry, ClassTree, imported_element, lookup_class, member_class
from .parse_cache import clear_parse_cache
from .parser import parse_expression, parse_file, parse_text
from .user_sources import load

__all__ = ["ClassEntry", "ClassTree", "clear_parse_cache", "imported_element",
           "library_folders", "library_roots",
           "load", "lookup_class", "member_class", "parse_expression", "parse_file", "parse_text",
           "source_files"]
