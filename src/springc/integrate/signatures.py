"""numba types of the model functions the kernels call through a function pointer.

A model function has the signature of the generated module's ``rhs``:
``f(t: float, x: float64[::1], p: float64[::1], z: float64[::1]) -> float64[::1]``.
The kernels take it as a first-class function value (``types.FunctionType``), so they are
compiled once (and cached on disk) for every model, not once per model.
"""

from collections.abc import Callable

import numpy as np
from numba import types

#: a model function as Python sees it (a numba dispatcher)
ModelFunction = Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
#: what the kernels return, as Python sees it (see RUN_RESULT)
RunTuple = tuple[int, np.ndarray, np.ndarray, int, int, int, int, float, np.ndarray,
                 np.ndarray, float]
#: the implicit kernels' result: RunTuple and the Jacobian evaluations
ImplicitTuple = tuple[int, np.ndarray, np.ndarray, int, int, int, int, float, np.ndarray,
                      np.ndarray, float, int]

VECTOR = types.float64[::1]
MATRIX = types.float64[:, ::1]
MODEL_FUNCTION_SIGNATURE = VECTOR(types.float64, VECTOR, VECTOR, VECTOR)
MODEL_FUNCTION = types.FunctionType(MODEL_FUNCTION_SIGNATURE)

INDICES = types.int64[::1]

#: status, states (grid x n), observed (grid x m), rows filled, accepted steps,
#: rejected steps, right-hand-side evaluations, end time, end state (where a failure or
#: an event stopped the run), fired crossings (+1 rising, -1 falling, 0 not), next step
RUN_RESULT = types.Tuple((types.int64, MATRIX, MATRIX, types.int64,  # type: ignore[no-untyped-call]
                          types.int64, types.int64, types.int64, types.float64, VECTOR,
                          INDICES, types.float64))
#: RUN_RESULT and the Jacobian evaluations (the implicit kernels)
IMPLICIT_RESULT = types.Tuple((*RUN_RESULT.types, types.int64))  # type: ignore[no-untyped-call]

#: the band of the implicit methods' Newton matrices: order, kl, ku, positions, diagonal
LAYOUT = types.Tuple((INDICES, types.int64, types.int64, INDICES, INDICES))  # type: ignore[no-untyped-call]
#: the shared adaptive loop of :mod:`.loop`, whatever the method
LOOP_SIGNATURE = IMPLICIT_RESULT(MODEL_FUNCTION, MODEL_FUNCTION, MODEL_FUNCTION, types.int64,
                                 MODEL_FUNCTION, VECTOR, VECTOR, VECTOR, VECTOR, VECTOR,
                                 VECTOR, types.float64, VECTOR, types.float64, types.float64,
                                 types.int64, types.float64, LAYOUT)
#: :func:`.fixed_step_kernel.fixed_step_run`
FIXED_STEP_SIGNATURE = RUN_RESULT(types.int64, MODEL_FUNCTION, MODEL_FUNCTION, types.int64,
                                  MODEL_FUNCTION, VECTOR, VECTOR, VECTOR, VECTOR, VECTOR,
                                  VECTOR, types.float64, INDICES, INDICES, types.float64)
