"""Array operations beyond the values of :mod:`springc.flatten.arrays`: the chapter-10
built-ins (``array_builtins``), deduced ``for`` ranges, dimensions named by a type and the
loop cap."""

from __future__ import annotations

from .array_builtins import ArrayBuiltins
from .dimensions import typed_dimension, typed_index
from .loops import check_loop_nest
from .ranges import type_range, typed_range, typed_range_bounds, with_range

__all__ = [
    "ArrayBuiltins", "check_loop_nest", "type_range", "typed_dimension", "typed_index",
    "typed_range", "typed_range_bounds", "with_range",
]
