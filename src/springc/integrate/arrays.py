"""Vector copies, compiled: ``copy(dst, src)`` for the kernels' ``dst[:] = src``.

numba compiles a slice assignment of an array (``a[:] = b``, ``K[s] = d``) with a shape
check whose error path it compiles anew at every such statement (about half a second
of CPU each on the development machine): the loops copy through this one function
instead, compiled once per element type, and check nothing (the shapes are the
kernels' own).
"""

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy", nogil=True)
def copy(dst: np.ndarray, src: np.ndarray) -> None:
    """``dst[i] = src[i]`` for every ``i`` of the 1-D ``src``."""
    for i in range(src.size):
        dst[i] = src[i]
