"""Structural analysis on integer-indexed equation/variable graphs (no sympy).

Input: an incidence (for each equation, the indices of the variables it contains).
Output: matchings, Dulmage-Mendelsohn parts, BLT blocks and tearings of loops.
"""

from .blt import blt
from .graph import Incidence, biadjacency, to_incidence, transpose
from .matching import DMParts, Matching, dulmage_mendelsohn, maximum_matching, validate_matching
from .tearing import Tearing, tear

__all__ = [
    "DMParts",
    "Incidence",
    "Matching",
    "Tearing",
    "biadjacency",
    "blt",
    "dulmage_mendelsohn",
    "maximum_matching",
    "tear",
    "to_incidence",
    "transpose",
    "validate_matching",
]
