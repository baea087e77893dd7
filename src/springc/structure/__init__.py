"""Structural analysis on integer-indexed equation/variable graphs (no sympy).

Input: an incidence (for each equation, the indices of the variables it contains).
Output: matchings, Dulmage-Mendelsohn parts, BLT blocks and tearings of loops.
"""

from .dummy import (
    NumericallySingular,
    StateSelection,
    dummy_derivatives,
    kept_by_preference,
    state_priority,
)
from .graph import Incidence, biadjacency, to_incidence, transpose
from .index import IndexReduction, StructurallySingular, pantelides
from .matching import (
    DMParts,
    Matching,
    dulmage_mendelsohn,
    maximum_matching,
    perfectly_matchable,
    validate_matching,
)
from .sorting import blt
from .tearing import Tearing, tear

__all__ = [
    "DMParts",
    "Incidence",
    "IndexReduction",
    "Matching",
    "NumericallySingular",
    "StateSelection",
    "StructurallySingular",
    "Tearing",
    "biadjacency",
    "blt",
    "dulmage_mendelsohn",
    "dummy_derivatives",
    "kept_by_preference",
    "maximum_matching",
    "pantelides",
    "perfectly_matchable",
    "state_priority",
    "tear",
    "to_incidence",
    "transpose",
    "validate_matching",
]
