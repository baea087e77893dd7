"""Model functions the engine supplies itself (compiled for the model-function signature)."""

import numpy as np
from numba import njit

from .signatures import MODEL_FUNCTION_SIGNATURE


@njit(MODEL_FUNCTION_SIGNATURE, cache=True)
def no_observed(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The observed function of a run without observed variables: nothing."""
    return np.empty(0)
