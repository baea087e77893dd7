"""Parse: Modelica text -> ``ir.syntax``; files and library folders -> ``ClassTree``."""

from .loader import ClassEntry, ClassTree, library_folders, load, lookup_class, member_class
from .parser import parse_expression, parse_file, parse_text

__all__ = ["ClassEntry", "ClassTree", "library_folders", "load", "lookup_class", "member_class",
           "parse_expression", "parse_file", "parse_text"]
