"""BDF's arithmetic, compiled: the difference array's rescaling, the Newton iteration of
the implicit step and the dense output.

The pieces of :func:`.bdf_kernel.bdf_run`, following scipy's ``BDF`` (the variable-order
NDF/BDF formulas of Shampine and Reichelt's ``ode15s`` in backward-difference form):
``D[j]`` holds the j-th backward difference of the solution scaled to the current step.

numba keys its disk cache on this file's modification time only: touch ``bdf_kernel.py``
after editing this file (or ``banded_lu``, ``status``), and remove its cache files.
"""

import math

import numpy as np
from numba import njit

from .radau_steps import solve_in_order
from .signatures import ModelFunction
from .status import Status

SUCCESS = int(Status.SUCCESS)
MODEL_FAILED = int(Status.MODEL_FAILED)
MAX_ORDER = 5
NEWTON_MAXITER = 4
KAPPA = np.array([0.0, -0.1850, -1 / 9, -0.0823, -0.0415, 0.0])
GAMMA = np.concatenate((np.zeros(1), np.cumsum(1 / np.arange(1, MAX_ORDER + 1))))
ALPHA = (1 - KAPPA) * GAMMA
ERROR_CONST = KAPPA * GAMMA + 1 / np.arange(1, MAX_ORDER + 2)


@njit(cache=True, error_model="numpy", nogil=True)
def step_ratio_matrix(order: int, factor: float) -> np.ndarray:
    """The matrix that rescales the differences of ``order`` to a step ``factor`` times
    longer (scipy's ``compute_R``)."""
    M = np.zeros((order + 1, order + 1))
    for j in range(order + 1):
        M[0, j] = 1.0
    for i in range(1, order + 1):
        for j in range(1, order + 1):
            M[i, j] = (i - 1 - factor * j) / i
    for i in range(1, order + 1):
        for j in range(order + 1):
            M[i, j] *= M[i - 1, j]
    return M


@njit(cache=True, error_model="numpy", nogil=True)
def change_differences(D: np.ndarray, order: int, factor: float) -> None:
    """``D[:order + 1]`` rescaled to a step ``factor`` times longer (scipy's ``change_D``)."""
    RU = step_ratio_matrix(order, factor) @ step_ratio_matrix(order, 1.0)
    D[:order + 1] = RU.T @ D[:order + 1]


@njit(cache=True, error_model="numpy", nogil=True)
def scaled_rms(x: np.ndarray, weight: float, scale: np.ndarray) -> float:
    """``rms(weight * x / scale)``."""
    total = 0.0
    for j in range(x.size):
        value = weight * x[j] / scale[j]
        total += value * value
    result: float = math.sqrt(total) / float(x.size) ** 0.5
    return result


@njit(cache=True, error_model="numpy", nogil=True)
def newton_bdf(rhs: ModelFunction, t_new: float, y_predict: np.ndarray, c: float,
               psi: np.ndarray, factors: np.ndarray, kl: int, ku: int, pivots: np.ndarray,
               order: np.ndarray, scale: np.ndarray, tol: float, p: np.ndarray,
               z: np.ndarray, y: np.ndarray, d: np.ndarray) -> tuple[bool, int, int, int]:
    """The Newton iteration of the BDF step from ``y_predict``: the new state in ``y``,
    its correction in ``d``. Returns (converged, iterations, evaluations, status)."""
    n = y.size
    y[:] = y_predict
    d[:] = 0.0
    dy = np.empty(n)
    work = np.empty(n)
    dy_norm_old, rate = -1.0, -1.0
    iterations, evaluations = 0, 0
    for k in range(NEWTON_MAXITER):
        iterations = k + 1
        f = rhs(t_new, y, p, z)
        evaluations += 1
        if z.size > 0 and z[z.size - 1] != 0.0:
            return False, iterations, evaluations, MODEL_FAILED
        finite = True
        for j in range(n):
            if not math.isfinite(f[j]):
                finite = False
            dy[j] = c * f[j] - psi[j] - d[j]
        if not finite:
            break
        solve_in_order(factors, kl, ku, pivots, order, dy, work)
        dy_norm = scaled_rms(dy, 1.0, scale)
        rate = dy_norm / dy_norm_old if dy_norm_old >= 0 else -1.0
        if rate >= 0 and (rate >= 1 or rate ** (NEWTON_MAXITER - k) / (1 - rate) * dy_norm
                          > tol):
            break
        for j in range(n):
            y[j] += dy[j]
            d[j] += dy[j]
        if dy_norm == 0 or (rate >= 0 and rate / (1 - rate) * dy_norm < tol):
            return True, iterations, evaluations, SUCCESS
        dy_norm_old = dy_norm
    return False, iterations, evaluations, SUCCESS


@njit(cache=True, error_model="numpy", nogil=True)
def bdf_dense_state(D: np.ndarray, order: int, t: float, h: float, at: float,
                    out: np.ndarray) -> None:
    """The interpolating polynomial of the last step (ending at ``t``, current step
    ``h``) at time ``at``."""
    out[:] = D[0]
    product = 1.0
    for j in range(order):
        product *= (at - (t - h * j)) / (h * (1 + j))
        for i in range(out.size):
            out[i] += D[j + 1, i] * product
