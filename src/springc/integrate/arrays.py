"""Vector copies, compiled: ``copy(dst, src)`` for the kernels' ``dst[:] = src``; and the
two ways the implicit methods compile their pieces (:func:`internal`, :func:`inlined`).

numba compiles a slice assignment of an array (``a[:] = b``, ``K[s] = d``) with a shape
check whose error path it compiles anew at every such statement (about half a second
of CPU each on the development machine): the loops copy through this one function
instead, compiled once per element type, and check nothing (the shapes are the
kernels' own).
"""

from collections.abc import Callable
from typing import Any, TypeVar, cast

import numpy as np
from numba import njit

Function = TypeVar("Function", bound=Callable[..., Any])

NO_WRAPPERS: dict[str, Any] = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True}
INTERNAL = njit(cache=True, error_model="numpy", nogil=True, **NO_WRAPPERS)
INLINED = njit(inline="always", error_model="numpy", nogil=True, **NO_WRAPPERS)


def internal(function: Function) -> Function:
    """A compiled function called only from compiled code: numba compiles it (once per
    argument types, cached on disk) without the wrappers that let Python or C call it,
    which it would otherwise build, optimise and link into every caller."""
    return cast(Function, INTERNAL(function))


def inlined(function: Function) -> Function:
    """A small compiled function that numba inlines where it is called (no function of
    its own to compile, cache and link: each costs a fixed share of compile time)."""
    return cast(Function, INLINED(function))


@internal
def copy(dst: np.ndarray, src: np.ndarray) -> None:
    """``dst[i] = src[i]`` for every ``i`` of the 1-D ``src``."""
    for i in range(src.size):
        dst[i] = src[i]
