"""DOP853's arithmetic, compiled: stage sums, the error norm and the dense output.

The pieces of :func:`springc.integrate.dop853_kernel.dop853_run` (the loop), kept here so
that the loop's module stays short. The sums follow scipy's order when asked (``blas``),
so that the compiled runs equal ``solve_ivp(method="DOP853")`` bit for bit.

numba keys its disk cache on this file's modification time only: the constants taken
from ``dop853_tableau`` and ``status`` are frozen into the cached code, so touch this file
after editing those.
"""

import math

import numpy as np
from numba import njit

from . import dop853_tableau as tableau
from .status import Status

SUCCESS = int(Status.SUCCESS)
NON_FINITE_DERIVATIVE = int(Status.NON_FINITE_DERIVATIVE)
MODEL_FAILED = int(Status.MODEL_FAILED)

STAGES = tableau.STAGES
STAGES_EXTENDED = tableau.STAGES_EXTENDED
INTERPOLANT_ROWS = tableau.INTERPOLANT_ROWS
A, B, C, D, E3, E5 = tableau.A, tableau.B, tableau.C, tableau.D, tableau.E3, tableau.E5


@njit(cache=True, error_model="numpy", nogil=True)
def flagged(z: np.ndarray) -> bool:
    """Whether the model set its failure flag (the last entry of ``z``)."""
    return z.size > 0 and z[z.size - 1] != 0.0


@njit(cache=True, error_model="numpy", nogil=True)
def verdict(d: np.ndarray, z: np.ndarray) -> int:
    """SUCCESS, or why the evaluation that returned ``d`` (and set ``z``) is unusable."""
    if flagged(z):
        return MODEL_FAILED
    for value in d:
        if not math.isfinite(value):
            return NON_FINITE_DERIVATIVE
    return SUCCESS


@njit(cache=True, error_model="numpy", nogil=True)
def weighted_sum(K: np.ndarray, s: int, w: np.ndarray, out: np.ndarray, blas: bool) -> None:
    """``out = sum_{j<s} w[j] K[j]``.

    With ``blas``, by the BLAS call numpy makes for ``np.dot(K[:s].T, w[:s])`` (a dot
    product when there is one state), so that the sums, and with them the error
    estimates (which cancel down to rounding noise on tiny steps), equal scipy's bit for
    bit; otherwise by plain loops (faster for small systems, same values within rounding).
    """
    if blas:
        if K.shape[1] == 1:
            out[0] = np.dot(K.reshape(K.shape[0])[:s], w[:s])
        else:
            np.dot(K[:s].T, w[:s], out)
        return
    for i in range(K.shape[1]):
        acc = 0.0
        for j in range(s):
            acc += K[j, i] * w[j]
        out[i] = acc


@njit(cache=True, error_model="numpy", nogil=True)
def stage_state(y: np.ndarray, K: np.ndarray, s: int, h: float, sums: np.ndarray,
                out: np.ndarray, blas: bool) -> None:
    """The state of stage ``s``: ``y + (sum_j A[s, j] K[j]) * h``."""
    weighted_sum(K, s, A[s], sums, blas)
    for i in range(y.size):
        out[i] = y[i] + sums[i] * h


@njit(cache=True, error_model="numpy", nogil=True)
def sum_of_squares(x: np.ndarray, blas: bool) -> float:
    """``x . x``, by BLAS's dot product as numpy's ``norm`` (squared), or by a loop."""
    if blas:
        return math.sqrt(np.dot(x, x)) ** 2
    total = 0.0
    for value in x:
        total += value * value
    return total


@njit(cache=True, error_model="numpy", nogil=True)
def rms(x: np.ndarray, blas: bool) -> float:
    """Root mean square, as numpy's ``norm(x) / x.size ** 0.5``."""
    root_size: float = float(x.size) ** 0.5  # as numpy: pow, not sqrt
    if blas:
        return math.sqrt(np.dot(x, x)) / root_size
    return math.sqrt(sum_of_squares(x, blas)) / root_size


@njit(cache=True, error_model="numpy", nogil=True)
def error_norm(y: np.ndarray, y_new: np.ndarray, K: np.ndarray, h: float, rtol: float,
               atol: np.ndarray, scale: np.ndarray, err5: np.ndarray, err3: np.ndarray,
               blas: bool) -> float:
    """DOP853's scaled error: the 5th-order estimate damped by the 3rd-order one
    (``scale``, ``err5``, ``err3``: work arrays)."""
    n = y.size
    for i in range(n):
        scale[i] = atol[i] + max(abs(y[i]), abs(y_new[i])) * rtol
    weighted_sum(K, STAGES + 1, E5, err5, blas)
    weighted_sum(K, STAGES + 1, E3, err3, blas)
    for i in range(n):
        err5[i] /= scale[i]
        err3[i] /= scale[i]
    err5_norm_2 = sum_of_squares(err5, blas)
    err3_norm_2 = sum_of_squares(err3, blas)
    if err5_norm_2 == 0.0 and err3_norm_2 == 0.0:
        return 0.0
    denominator = err5_norm_2 + 0.01 * err3_norm_2
    return abs(h) * err5_norm_2 / math.sqrt(denominator * n)


@njit(cache=True, error_model="numpy", nogil=True)
def interpolant(y: np.ndarray, y_new: np.ndarray, K: np.ndarray, h: float,
                F: np.ndarray, blas: bool) -> None:
    """The 7 coefficient rows of the dense output over the step (needs K[13:16])."""
    if blas:
        high = np.dot(D, K)
    else:
        high = np.zeros((INTERPOLANT_ROWS - 3, y.size))
        for r in range(INTERPOLANT_ROWS - 3):
            weighted_sum(K, STAGES_EXTENDED, D[r], high[r], False)
    for i in range(y.size):
        delta = y_new[i] - y[i]
        F[0, i] = delta
        F[1, i] = h * K[0, i] - delta
        F[2, i] = 2 * delta - h * (K[STAGES, i] + K[0, i])
        for r in range(INTERPOLANT_ROWS - 3):
            F[3 + r, i] = h * high[r, i]


@njit(cache=True, error_model="numpy", nogil=True)
def interpolate(F: np.ndarray, y: np.ndarray, theta: float, out: np.ndarray) -> None:
    """The dense output at the fraction ``theta`` of the step into ``out``."""
    for i in range(y.size):
        value = 0.0
        for r in range(INTERPOLANT_ROWS - 1, -1, -1):
            value += F[r, i]
            if (INTERPOLANT_ROWS - 1 - r) % 2 == 0:
                value *= theta
            else:
                value *= 1 - theta
        out[i] = value + y[i]
