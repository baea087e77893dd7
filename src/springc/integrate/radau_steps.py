"""Radau IIA's arithmetic, compiled: the Newton matrices, the simplified Newton iteration
of the collocation system, the step-size predictor and the dense output.

The pieces of :func:`.radau_kernel.radau_run`, following scipy's ``Radau`` (Hairer and
Wanner's ``radau5``): the 3n x 3n Newton system is transformed by ``T`` into one real and
one complex n x n system, factorised by :mod:`.banded_lu` in the ordering of
:func:`.banded_lu.band_layout` (``order``: position -> state).

numba keys its disk cache on this file's modification time only: touch it after editing
``radau_tableau``, ``banded_lu``, ``status``.
"""

import math

import numpy as np
from numba import njit

from . import radau_tableau as tableau
from .banded_lu import band_factor, band_solve
from .signatures import ModelFunction
from .status import Status

SUCCESS = int(Status.SUCCESS)
MODEL_FAILED = int(Status.MODEL_FAILED)
C, E, T, TI, P = tableau.C, tableau.E, tableau.T, tableau.TI, tableau.P
TI_REAL, TI_COMPLEX = tableau.TI_REAL, tableau.TI_COMPLEX
MU_REAL, MU_COMPLEX = tableau.MU_REAL, tableau.MU_COMPLEX
NEWTON_MAXITER = tableau.NEWTON_MAXITER


@njit(cache=True, error_model="numpy", nogil=True)
def rms(x: np.ndarray) -> float:
    """Root mean square (scipy's ``norm(x) / sqrt(x.size)``), over all entries."""
    flat = x.reshape(x.size)
    total = 0.0
    for value in flat:
        total += value * value
    result: float = math.sqrt(total) / float(x.size) ** 0.5
    return result


@njit(cache=True, error_model="numpy", nogil=True)
def factor_newton_matrices(h: float, jacobian: np.ndarray, positions: np.ndarray,
                           diagonal: np.ndarray, kl: int, ku: int, real: np.ndarray,
                           complex_: np.ndarray, pivots_real: np.ndarray,
                           pivots_complex: np.ndarray) -> bool:
    """``MU_REAL / h I - J`` and ``MU_COMPLEX / h I - J`` assembled in their bands and
    factorised; False if either is singular."""
    flat_real = real.reshape(real.size)
    flat_complex = complex_.reshape(complex_.size)
    flat_real[:] = 0.0
    flat_complex[:] = 0.0
    for k in range(diagonal.size):
        flat_real[diagonal[k]] = MU_REAL / h
        flat_complex[diagonal[k]] = MU_COMPLEX / h
    for k in range(positions.size):
        flat_real[positions[k]] -= jacobian[k]
        flat_complex[positions[k]] -= jacobian[k]
    return (band_factor(real, kl, ku, pivots_real)
            and band_factor(complex_, kl, ku, pivots_complex))


@njit(cache=True, error_model="numpy", nogil=True)
def solve_in_order(factors: np.ndarray, kl: int, ku: int, pivots: np.ndarray,
                   order: np.ndarray, b: np.ndarray, work: np.ndarray) -> None:
    """Solve with band factors of the reordered matrix, ``b`` in state order, in place."""
    for i in range(order.size):
        work[i] = b[order[i]]
    band_solve(factors, kl, ku, pivots, work)
    for i in range(order.size):
        b[order[i]] = work[i]


@njit(cache=True, error_model="numpy", nogil=True)
def predict_factor(h_abs: float, h_abs_old: float, error_norm: float,
                   error_norm_old: float) -> float:
    """Gustafsson's predictive step-size factor (``h_abs_old < 0``: no history)."""
    if error_norm_old < 0 or h_abs_old < 0 or error_norm == 0:
        multiplier = 1.0
    else:
        multiplier = h_abs / h_abs_old * (error_norm_old / error_norm) ** 0.25
    if error_norm == 0:
        return math.inf
    factor: float = min(1.0, multiplier) * error_norm ** -0.25
    return factor


@njit(cache=True, error_model="numpy", nogil=True)
def newton(rhs: ModelFunction, t: float, y: np.ndarray, h: float, Z0: np.ndarray,
           scale: np.ndarray, tol: float, real: np.ndarray, complex_: np.ndarray,
           pivots_real: np.ndarray, pivots_complex: np.ndarray, kl: int, ku: int,
           order: np.ndarray, p: np.ndarray, z: np.ndarray, Z: np.ndarray
           ) -> tuple[bool, int, float, int, int]:
    """The simplified Newton iteration of the collocation system from ``Z0``; the stage
    increments in ``Z``. Returns (converged, iterations, rate (-1: none), evaluations,
    status: MODEL_FAILED if the model flagged a failure)."""
    n = y.size
    m_real = MU_REAL / h
    m_complex = MU_COMPLEX / h
    W = np.zeros((3, n))
    for r in range(3):
        for c in range(3):
            W[r] += TI[r, c] * Z0[c]
    Z[:] = Z0
    F = np.empty((3, n))
    stage = np.empty(n)
    dW = np.empty((3, n))
    f_real = np.empty(n)
    f_complex = np.empty(n, dtype=np.complex128)
    work_real = np.empty(n)
    work_complex = np.empty(n, dtype=np.complex128)
    dW_norm_old, rate = -1.0, -1.0
    evaluations, iterations = 0, 0
    for k in range(NEWTON_MAXITER):
        iterations = k + 1
        finite = True
        for i in range(3):
            for j in range(n):
                stage[j] = y[j] + Z[i, j]
            d = rhs(t + h * C[i], stage, p, z)
            evaluations += 1
            if z.size > 0 and z[z.size - 1] != 0.0:
                return False, iterations, rate, evaluations, MODEL_FAILED
            for j in range(n):
                F[i, j] = d[j]
                if not math.isfinite(d[j]):
                    finite = False
        if not finite:
            break
        for j in range(n):
            f_real[j] = (F[0, j] * TI_REAL[0] + F[1, j] * TI_REAL[1] + F[2, j] * TI_REAL[2]
                         - m_real * W[0, j])
            f_complex[j] = (F[0, j] * TI_COMPLEX[0] + F[1, j] * TI_COMPLEX[1]
                            + F[2, j] * TI_COMPLEX[2] - m_complex * (W[1, j] + 1j * W[2, j]))
        solve_in_order(real, kl, ku, pivots_real, order, f_real, work_real)
        solve_in_order(complex_, kl, ku, pivots_complex, order, f_complex, work_complex)
        for j in range(n):
            dW[0, j] = f_real[j] / scale[j]
            dW[1, j] = f_complex[j].real / scale[j]
            dW[2, j] = f_complex[j].imag / scale[j]
        dW_norm = rms(dW)
        if dW_norm_old >= 0:
            rate = dW_norm / dW_norm_old
        if rate >= 0 and (rate >= 1 or rate ** (NEWTON_MAXITER - k) / (1 - rate) * dW_norm
                          > tol):
            break
        for j in range(n):
            W[0, j] += f_real[j]
            W[1, j] += f_complex[j].real
            W[2, j] += f_complex[j].imag
        for r in range(3):
            for j in range(n):
                Z[r, j] = T[r, 0] * W[0, j] + T[r, 1] * W[1, j] + T[r, 2] * W[2, j]
        if dW_norm == 0 or (rate >= 0 and rate / (1 - rate) * dW_norm < tol):
            return True, iterations, rate, evaluations, SUCCESS
        dW_norm_old = dW_norm
    return False, iterations, rate, evaluations, SUCCESS


@njit(cache=True, error_model="numpy", nogil=True)
def dense_coefficients(Z: np.ndarray, Q: np.ndarray) -> None:
    """The collocation polynomial of the step: ``Q = Z^T P`` (n x 3)."""
    for j in range(Z.shape[1]):
        for c in range(3):
            Q[j, c] = Z[0, j] * P[0, c] + Z[1, j] * P[1, c] + Z[2, j] * P[2, c]


@njit(cache=True, error_model="numpy", nogil=True)
def dense_state(Q: np.ndarray, y_old: np.ndarray, x: float, out: np.ndarray) -> None:
    """The dense output at the step fraction ``x`` (from ``y_old``)."""
    x2 = x * x
    x3 = x2 * x
    for j in range(y_old.size):
        out[j] = y_old[j] + Q[j, 0] * x + Q[j, 1] * x2 + Q[j, 2] * x3
