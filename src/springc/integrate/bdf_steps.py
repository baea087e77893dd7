"""BDF (variable order 1-5), compiled: the method's hooks of the shared loop
(:mod:`.loop`), the difference array's rescaling, the Newton iteration of the implicit
step and the dense output.

scipy's ``BDF`` (the variable-order NDF/BDF formulas of Shampine and Reichelt's
``ode15s`` in backward-difference form, with its controller, order selection, Newton
iteration and Jacobian reuse; the tests compare steps and errors with scipy's), the
generated sparse Jacobian in the banded LU of :mod:`.banded_lu` (``I - c J``: one real
matrix per step size). ``D[j]`` holds the j-th backward difference of the solution
scaled to the current step.

numba keys its disk cache on this file's modification time only: touch this file after
editing ``bdf_tableau``, ``banded_lu``, ``radau_steps`` or ``status``.
"""

import math

import numpy as np
from numba import njit

from . import bdf_tableau as tableau
from .arrays import copy, internal
from .banded_lu import band_factor
from .dop853_steps import verdict
from .radau_steps import solve_in_order
from .signatures import ModelFunction
from .status import JACOBIAN_CALLS, REJECTED, RHS_CALLS, Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
MODEL_FAILED = int(Status.MODEL_FAILED)
MIN_FACTOR, MAX_FACTOR = 0.2, 10.0
EPS = float(np.finfo(float).eps)
ERROR_ORDER = 1  # of the error estimator (at the first step): the initial exponent 1 / 2
MAX_ORDER, NEWTON_MAXITER = tableau.MAX_ORDER, tableau.NEWTON_MAXITER
KAPPA, GAMMA, ALPHA = tableau.KAPPA, tableau.GAMMA, tableau.ALPHA
ERROR_CONST = tableau.ERROR_CONST


@internal
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
    R = step_ratio_matrix(order, factor)
    U = step_ratio_matrix(order, 1.0)
    RU = np.zeros((order + 1, order + 1))
    for i in range(order + 1):
        for k in range(order + 1):
            for j in range(order + 1):
                RU[i, j] += R[i, k] * U[k, j]
    rescaled = np.zeros((order + 1, D.shape[1]))
    for k in range(order + 1):
        for i in range(order + 1):
            for j in range(D.shape[1]):
                rescaled[i, j] += RU[k, i] * D[k, j]
    for i in range(order + 1):
        copy(D[i], rescaled[i])


@internal
def scaled_rms(x: np.ndarray, weight: float, scale: np.ndarray) -> float:
    """``rms(weight * x / scale)``."""
    total = 0.0
    for j in range(x.size):
        value = weight * x[j] / scale[j]
        total += value * value
    result: float = math.sqrt(total) / float(x.size) ** 0.5
    return result


@internal
def newton_bdf(rhs: ModelFunction, t_new: float, y_predict: np.ndarray, c: float,
               psi: np.ndarray, factors: np.ndarray, kl: int, ku: int, pivots: np.ndarray,
               order: np.ndarray, scale: np.ndarray, tol: float, p: np.ndarray,
               z: np.ndarray, y: np.ndarray, d: np.ndarray, dy: np.ndarray, work: np.ndarray
               ) -> tuple[bool, int, int, int]:
    """The Newton iteration of the BDF step from ``y_predict``: the new state in ``y``,
    its correction in ``d`` (``dy``, ``work``: work space). Returns (converged,
    iterations, evaluations, status)."""
    n = y.size
    copy(y, y_predict)
    for j in range(n):
        d[j] = 0.0
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


@internal
def bdf_dense_state(D: np.ndarray, order: int, t: float, h: float, at: float,
                    out: np.ndarray) -> None:
    """The interpolating polynomial of the last step (ending at ``t``, current step
    ``h``) at time ``at``."""
    copy(out, D[0])
    product = 1.0
    for j in range(order):
        product *= (at - (t - h * j)) / (h * (1 + j))
        for i in range(out.size):
            out[i] += D[j + 1, i] * product


# The hooks of the shared loop (see :mod:`.loop` for their contract).

Layout = tuple[np.ndarray, int, int, np.ndarray, np.ndarray]
Work = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
             np.ndarray]
#: the rows of the vectors ``work[1]``: the predictor, its ``psi``, the correction, the
#: error weights, and the Newton iteration's work space (its step, its solve's vector)
PREDICT, PSI, CORRECTION, SCALE, DY, SOLVE = 0, 1, 2, 3, 4, 5
#: the method's scalars (``work[5]``): the Newton tolerance, the end and the step size of
#: the differences (the last step's, after its order and step-size change)
NEWTON_TOL, T_NEW, H_NOW = 0, 1, 2
#: its integers (``work[6]``): the order, the steps taken at this size and order, whether
#: the iteration matrix is factorised, whether the Jacobian was evaluated in this step
ORDER, N_EQUAL, FACTORED, CURRENT_JAC = 0, 1, 2, 3


@internal
def factor_iteration_matrix(c: float, J: np.ndarray, positions: np.ndarray,
                            diagonal: np.ndarray, kl: int, ku: int, factors: np.ndarray,
                            pivots: np.ndarray) -> bool:
    """``I - c J`` assembled in its band and factorised; False if singular."""
    width = factors.shape[1]  # (positions: flat indices into the band)
    for i in range(factors.shape[0]):
        for j in range(width):
            factors[i, j] = 0.0
    for k in range(diagonal.size):
        factors[diagonal[k] // width, diagonal[k] % width] = 1.0
    for k in range(positions.size):
        factors[positions[k] // width, positions[k] % width] -= c * J[k]
    return band_factor(factors, kl, ku, pivots)


@internal
def setup(n: int, layout: Layout) -> Work:
    """The differences ``D``, the predictor and its ``psi``, the correction, the
    iteration matrix's band and pivots, the Jacobian's non-zeros and the scalars."""
    _, kl, ku, positions, _ = layout
    return (np.zeros((MAX_ORDER + 3, n)), np.empty((6, n)), np.empty(positions.size),
            np.zeros((n, 2 * kl + ku + 1)), np.empty(n, dtype=np.int64), np.zeros(3),
            np.zeros(4, dtype=np.int64))


@internal
def begin(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray, f: np.ndarray,
          h_abs: float, p: np.ndarray, z: np.ndarray, rtol: float, work: Work,
          counts: np.ndarray, end: np.ndarray) -> tuple[int, float]:
    """The Newton tolerance, the Jacobian at the start, the differences of order 1."""
    D, reals, ints = work[0], work[5], work[6]
    reals[NEWTON_TOL] = max(10 * EPS / rtol, min(0.03, rtol ** 0.5))
    J = jac(t, y, p, z)
    counts[JACOBIAN_CALLS] += 1
    status = verdict(J, z)
    if status != SUCCESS:
        copy(end, y)
        return status, t
    copy(work[2], J)
    copy(D[0], y)
    for i in range(y.size):
        D[1, i] = f[i] * h_abs
    ints[ORDER], ints[N_EQUAL], ints[FACTORED] = 1, 0, 0
    return SUCCESS, t


@internal
def converge(rhs: ModelFunction, jac: ModelFunction, t_new: float, c: float, p: np.ndarray,
             z: np.ndarray, layout: Layout, work: Work, counts: np.ndarray,
             y_new: np.ndarray, end: np.ndarray) -> tuple[bool, int, int]:
    """Newton's iteration of the step to ``t_new`` from the predictor, the matrix
    factorised again (and the Jacobian evaluated again once) where needed: (converged,
    iterations, status; a failure's state in ``end``)."""
    order_of, kl, ku, positions, diagonal = layout
    vectors, J, factors, pivots, reals, ints = work[1], work[2], work[3], work[4], work[5], \
        work[6]
    y_predict, psi, d, scale = vectors[PREDICT], vectors[PSI], vectors[CORRECTION], \
        vectors[SCALE]
    converged, n_iter = False, 0
    while True:
        if not ints[FACTORED]:
            ints[FACTORED] = factor_iteration_matrix(c, J, positions, diagonal, kl, ku,
                                                     factors, pivots)
        if ints[FACTORED]:
            converged, n_iter, used, status = newton_bdf(
                rhs, t_new, y_predict, c, psi, factors, kl, ku, pivots, order_of, scale,
                reals[NEWTON_TOL], p, z, y_new, d, vectors[DY], vectors[SOLVE])
            counts[RHS_CALLS] += used
            if status != SUCCESS:
                copy(end, y_new)
                return False, n_iter, status
        if converged or ints[CURRENT_JAC]:
            return converged, n_iter, SUCCESS
        values = jac(t_new, y_predict, p, z)
        counts[JACOBIAN_CALLS] += 1
        status = verdict(values, z)
        if status != SUCCESS:
            copy(end, y_predict)
            return False, n_iter, status
        copy(J, values)
        ints[FACTORED], ints[CURRENT_JAC] = 0, 1


@internal
def step(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray, h_proposed: float,
         h_abs: float, min_step: float, limit: float, p: np.ndarray, z: np.ndarray,
         rtol: float, atol: np.ndarray, layout: Layout, work: Work, counts: np.ndarray,
         y_new: np.ndarray, end: np.ndarray, blas: bool | None
         ) -> tuple[int, float, float, float, float]:
    """One accepted step of BDF from ``(t, y)`` (rejected ones before it), then the
    differences, and maybe another order and step size."""
    D, vectors, ints = work[0], work[1], work[6]
    y_predict, psi, d, scale = vectors[PREDICT], vectors[PSI], vectors[CORRECTION], \
        vectors[SCALE]
    n = y.size
    if h_abs != h_proposed:  # clamped: the differences rescaled to the step
        change_differences(D, ints[ORDER], h_abs / h_proposed)
        ints[N_EQUAL] = 0
    ints[CURRENT_JAC] = 0
    while True:
        order = ints[ORDER]
        if h_abs < min_step:
            copy(end, y)
            return STEP_TOO_SMALL, t, 0.0, h_abs, t
        t_new = t + h_abs
        if t_new - limit > 0:
            t_new = limit
            change_differences(D, order, abs(t_new - t) / h_abs)
            ints[N_EQUAL], ints[FACTORED] = 0, 0
        h = t_new - t
        h_abs = abs(h)
        for i in range(n):
            total = 0.0
            for j in range(order + 1):
                total += D[j, i]
            y_predict[i] = total
            scale[i] = atol[i] + rtol * abs(total)
            acc = 0.0
            for j in range(1, order + 1):
                acc += D[j, i] * GAMMA[j]
            psi[i] = acc / ALPHA[order]
        converged, n_iter, status = converge(rhs, jac, t_new, h / ALPHA[order], p, z, layout,
                                             work, counts, y_new, end)
        if status != SUCCESS:
            return status, t, h, h_abs, t_new
        if not converged:
            h_abs *= 0.5
            change_differences(D, order, 0.5)
            ints[N_EQUAL], ints[FACTORED] = 0, 0
            counts[REJECTED] += 1
            continue
        safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
        for i in range(n):
            scale[i] = atol[i] + rtol * abs(y_new[i])
        error_norm = scaled_rms(d, ERROR_CONST[order], scale)
        if error_norm > 1:
            factor = max(MIN_FACTOR, safety * error_norm ** (-1 / (order + 1)))
            h_abs *= factor
            change_differences(D, order, factor)
            ints[N_EQUAL] = 0
            counts[REJECTED] += 1
            continue
        return SUCCESS, t_new, h, new_differences(work, t_new, h_abs, safety, error_norm), t


@internal
def new_differences(work: Work, t_new: float, h_abs: float, safety: float,
                    error_norm: float) -> float:
    """The differences after an accepted step, and maybe another order and step size
    (scipy's choice among the orders one below, equal and one above): the next step
    size."""
    D, reals, ints = work[0], work[5], work[6]
    d, scale = work[1][CORRECTION], work[1][SCALE]
    order = ints[ORDER]
    ints[N_EQUAL] += 1
    for i in range(d.size):
        D[order + 2, i] = d[i] - D[order + 1, i]
        D[order + 1, i] = d[i]
    for k in range(order, -1, -1):
        for i in range(d.size):
            D[k, i] += D[k + 1, i]
    if ints[N_EQUAL] >= order + 1:
        error_m = scaled_rms(D[order], ERROR_CONST[order - 1], scale) if order > 1 \
            else math.inf
        error_p = scaled_rms(D[order + 2], ERROR_CONST[order + 1], scale) \
            if order < MAX_ORDER else math.inf
        best, delta = -1.0, 0
        for k, norm in enumerate((error_m, error_norm, error_p)):
            grow = math.inf if norm == 0 else norm ** (-1 / (order + k))
            if grow > best:
                best, delta = grow, k - 1
        order += delta
        factor = min(MAX_FACTOR, safety * best)
        h_abs *= factor
        change_differences(D, order, factor)
        ints[ORDER], ints[N_EQUAL], ints[FACTORED] = order, 0, 0
    reals[T_NEW], reals[H_NOW] = t_new, h_abs
    return h_abs


@internal
def prepare_dense(rhs: ModelFunction, t: float, h: float, y: np.ndarray, y_new: np.ndarray,
                  p: np.ndarray, z: np.ndarray, work: Work, counts: np.ndarray,
                  end: np.ndarray, blas: bool | None) -> tuple[int, float]:
    """Nothing: the differences are the dense output."""
    return SUCCESS, t


@internal
def dense(work: Work, t: float, h: float, y: np.ndarray, at: float, out: np.ndarray,
          blas: bool | None) -> None:
    """The interpolating polynomial of the last step at time ``at``."""
    reals = work[5]
    bdf_dense_state(work[0], work[6][ORDER], reals[T_NEW], reals[H_NOW], at, out)
