"""RK45 (Dormand-Prince 5(4)), compiled: the method's hooks of the shared loop
(:mod:`.loop`) and Shampine's 4th-order dense output.

scipy's ``RK45`` method: same controller, error norm, initial step and, with ``blas``,
the same sums (the runs agree with ``solve_ivp(method="RK45")`` step for step); the sums
and norms are DOP853's (:mod:`.dop853_steps`), with this tableau.

numba keys its disk cache on this file's modification time only: touch this file after
editing ``rk45_tableau``, ``dop853_steps`` or ``status``.
"""

import numpy as np
from numba import njit

from . import rk45_tableau as tableau
from .arrays import copy
from .dop853_steps import rms, shrinks, sum_of_squares, verdict, weighted_sum
from .signatures import ModelFunction
from .status import REJECTED, RHS_CALLS, Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
A, B, C, E, P = tableau.A, tableau.B, tableau.C, tableau.E, tableau.P
STAGES = tableau.STAGES
ERROR_ORDER = tableau.ERROR_ESTIMATOR_ORDER
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
ERROR_EXPONENT = -1.0 / (tableau.ERROR_ESTIMATOR_ORDER + 1)

Work = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
Layout = tuple[np.ndarray, int, int, np.ndarray, np.ndarray]


@njit(cache=True, error_model="numpy", nogil=True)
def dense_state(Q: np.ndarray, y_old: np.ndarray, h: float, x: float, out: np.ndarray,
                blas: bool | None) -> None:
    """The dense output ``y_old + h Q [x, x^2, x^3, x^4]`` at the step fraction ``x``
    (with ``blas``, by the BLAS product numpy makes, as scipy's)."""
    powers = np.empty(Q.shape[1])
    power = 1.0
    for r in range(Q.shape[1]):
        power *= x
        powers[r] = power
    if blas is not None:
        values = np.dot(Q, powers)
        for i in range(y_old.size):
            out[i] = h * values[i] + y_old[i]
        return
    for i in range(y_old.size):
        value = 0.0
        for r in range(Q.shape[1]):
            value += Q[i, r] * powers[r]
        out[i] = h * value + y_old[i]


@njit(cache=True, error_model="numpy", nogil=True)
def setup(n: int, layout: Layout) -> Work:
    """The stages ``K``, the dense output's ``Q`` and four work vectors."""
    return (np.empty((STAGES + 1, n)), np.empty((n, P.shape[1])), np.empty(n), np.empty(n),
            np.empty(n), np.empty(n))


@njit(cache=True, error_model="numpy", nogil=True)
def begin(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray, f: np.ndarray,
          h_abs: float, p: np.ndarray, z: np.ndarray, rtol: float, work: Work,
          counts: np.ndarray, end: np.ndarray) -> tuple[int, float]:
    """The derivative at the start as the last stage of a step before it (FSAL)."""
    copy(work[0][STAGES], f)
    return SUCCESS, t


@njit(cache=True, error_model="numpy", nogil=True)
def step(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray, h_proposed: float,
         h_abs: float, min_step: float, limit: float, p: np.ndarray, z: np.ndarray,
         rtol: float, atol: np.ndarray, layout: Layout, work: Work, counts: np.ndarray,
         y_new: np.ndarray, end: np.ndarray, blas: bool | None
         ) -> tuple[int, float, float, float, float]:
    """One accepted step of RK45 from ``(t, y)`` (rejected ones before it)."""
    K, _, stage, sums, scale, err = work
    n = y.size
    copy(K[0], K[STAGES])
    step_rejected = False
    while True:
        if h_abs < min_step:
            copy(end, y)
            return STEP_TOO_SMALL, t, 0.0, h_abs, t
        t_new = t + h_abs
        if t_new - limit > 0:
            t_new = limit
        h = t_new - t
        h_abs = abs(h)
        for s in range(1, STAGES):
            weighted_sum(K, s, A[s], sums, blas)
            for i in range(n):
                stage[i] = y[i] + sums[i] * h
            d = rhs(t + C[s] * h, stage, p, z)
            counts[RHS_CALLS] += 1
            status = verdict(d, z)
            if status != SUCCESS:
                copy(end, stage)
                if shrinks(status, h_abs, min_step):
                    break
                return status, t, h, h_abs, t + C[s] * h
            copy(K[s], d)
        if status != SUCCESS:  # a non-finite stage: rejected, as scipy's NaN error is
            h_abs *= MIN_FACTOR
            step_rejected = True
            counts[REJECTED] += 1
            continue
        weighted_sum(K, STAGES, B, sums, blas)
        for i in range(n):
            y_new[i] = y[i] + h * sums[i]
        d = rhs(t + h, y_new, p, z)
        counts[RHS_CALLS] += 1
        status = verdict(d, z)
        if status != SUCCESS:
            copy(end, y_new)
            if shrinks(status, h_abs, min_step):
                h_abs *= MIN_FACTOR
                step_rejected = True
                counts[REJECTED] += 1
                continue
            return status, t, h, h_abs, t + h
        copy(K[STAGES], d)
        weighted_sum(K, STAGES + 1, E, err, blas)
        for i in range(n):
            scale[i] = atol[i] + max(abs(y[i]), abs(y_new[i])) * rtol
            err[i] = err[i] * h / scale[i]
        error = (sum_of_squares(err, blas) / n) ** 0.5 if blas is None else rms(err, blas)
        if error < 1:
            factor = MAX_FACTOR if error == 0 else min(MAX_FACTOR,
                                                       SAFETY * error ** ERROR_EXPONENT)
            if step_rejected:
                factor = min(1.0, factor)
            return SUCCESS, t_new, h, h_abs * factor, t
        h_abs *= max(MIN_FACTOR, SAFETY * error ** ERROR_EXPONENT)
        step_rejected = True
        counts[REJECTED] += 1


@njit(cache=True, error_model="numpy", nogil=True)
def prepare_dense(rhs: ModelFunction, t: float, h: float, y: np.ndarray, y_new: np.ndarray,
                  p: np.ndarray, z: np.ndarray, work: Work, counts: np.ndarray,
                  end: np.ndarray, blas: bool | None) -> tuple[int, float]:
    """The dense output's coefficients ``Q = K^T P``."""
    K, Q = work[0], work[1]
    if blas is not None:
        Q[:] = np.dot(K.T, P)
        return SUCCESS, t
    for i in range(y.size):
        for r in range(P.shape[1]):
            acc = 0.0
            for s in range(STAGES + 1):
                acc += K[s, i] * P[s, r]
            Q[i, r] = acc
    return SUCCESS, t


@njit(cache=True, error_model="numpy", nogil=True)
def dense(work: Work, t: float, h: float, y: np.ndarray, at: float, out: np.ndarray,
          blas: bool | None) -> None:
    """The 4th-order dense output of the step at time ``at``."""
    dense_state(work[1], y, h, (at - t) / h, out, blas)
