"""The observed variables on an output grid, compiled once per machine for every model.

A generated module's own ``observed_grid`` is a Python loop (numba would compile a jitted
one with the model's ``observed`` inlined: seconds per model). This kernel takes
``observed`` as a first-class function value instead, like the integration kernels, so
it loads from numba's disk cache whatever the model.
"""

import numpy as np
from numba import njit, types

from .signatures import MATRIX, MODEL_FUNCTION, VECTOR, ModelFunction


@njit(MATRIX(MODEL_FUNCTION, types.int64, VECTOR, MATRIX, VECTOR, VECTOR), cache=True,
      error_model="numpy", nogil=True)
def observed_grid_run(observed: ModelFunction, n_observed: int, ts: np.ndarray,
                      states: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``observed(ts[i], states[i], p, z)`` as row ``i``; from the first row whose call
    sets the model's failure flag (the last entry of ``z``) on, the rows are NaN."""
    out = np.empty((ts.shape[0], n_observed))
    last = z.size - 1  # the failure flag (none in an empty z)
    for i in range(ts.shape[0]):
        row = observed(ts[i], states[i], p, z)
        if last >= 0 and z[last] != 0.0:
            out[i:, :] = np.nan
            break
        for j in range(n_observed):
            out[i, j] = row[j]
    return out
