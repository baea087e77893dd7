"""DOP853, compiled: the method's hooks of the shared loop (:mod:`.loop`), its stage
sums, error norm and dense output.

The explicit Runge-Kutta method of Dormand and Prince, order 8 with 5th- and 3rd-order
error estimates and a 7th-order dense output (Hairer, Norsett, Wanner, *Solving ODEs I*,
Sec. II.10). The step-size controller, the error norm and the initial step are those of
``scipy.integrate.solve_ivp(method="DOP853")``; with ``blas`` the sums are scipy's too
(numpy's BLAS calls), and both runs agree bit for bit (the tests check this); without
it, plain loops (faster on small systems, the same method within rounding).

numba keys its disk cache on this file's modification time only: the constants taken
from ``dop853_tableau`` and ``status`` are frozen into the cached code, so touch this file
after editing those.
"""

import math

import numpy as np
from numba import njit

from . import dop853_tableau as tableau
from .arrays import copy
from .signatures import ModelFunction
from .status import REJECTED, RHS_CALLS, Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
NON_FINITE_DERIVATIVE = int(Status.NON_FINITE_DERIVATIVE)
MODEL_FAILED = int(Status.MODEL_FAILED)

STAGES = tableau.STAGES
STAGES_EXTENDED = tableau.STAGES_EXTENDED
INTERPOLANT_ROWS = tableau.INTERPOLANT_ROWS
A, B, C, D, E3, E5 = tableau.A, tableau.B, tableau.C, tableau.D, tableau.E3, tableau.E5
ERROR_ORDER = 7  # of the error estimator: the initial step's exponent is 1 / 8
SAFETY = 0.9  # factor on the step size predicted from the error estimate
MIN_FACTOR = 0.2  # largest decrease of the step size after a rejection
MAX_FACTOR = 10.0  # largest increase after an accepted step
ERROR_EXPONENT = -1.0 / 8.0  # -1 / (error estimator order 7 + 1)


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
def shrinks(status: int, h_abs: float, min_step: float) -> bool:
    """Whether a failed evaluation rejects the attempt rather than ending the run: a
    non-finite derivative while a step MIN_FACTOR times shorter is still allowed (the
    stage left the model's domain, as scipy's NaN error norm rejects the step; at the
    smallest step the non-finite value is the run's error)."""
    return status == NON_FINITE_DERIVATIVE and h_abs * MIN_FACTOR >= min_step


@njit(cache=True, error_model="numpy", nogil=True)
def weighted_sum(K: np.ndarray, s: int, w: np.ndarray, out: np.ndarray, blas: bool | None) -> None:
    """``out = sum_{j<s} w[j] K[j]``.

    With ``blas`` True, by the BLAS call numpy makes for ``np.dot(K[:s].T, w[:s])`` (a
    dot product when there is one state), so that the sums, and with them the error
    estimates (which cancel down to rounding noise on tiny steps), equal scipy's bit for
    bit; with ``blas`` None by plain loops (faster for small systems, same values within
    rounding). A None argument prunes the BLAS branch when numba compiles (a False one
    would not: numba prunes branches on constants and on None arguments only), so that
    a loop of plain sums never compiles numpy's BLAS calls.
    """
    if blas is not None:
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
                out: np.ndarray, blas: bool | None) -> None:
    """The state of stage ``s``: ``y + (sum_j A[s, j] K[j]) * h``."""
    weighted_sum(K, s, A[s], sums, blas)
    for i in range(y.size):
        out[i] = y[i] + sums[i] * h


@njit(cache=True, error_model="numpy", nogil=True)
def sum_of_squares(x: np.ndarray, blas: bool | None) -> float:
    """``x . x``, by BLAS's dot product as numpy's ``norm`` (squared), or by a loop."""
    if blas is not None:
        return math.sqrt(np.dot(x, x)) ** 2
    total = 0.0
    for value in x:
        total += value * value
    return total


@njit(cache=True, error_model="numpy", nogil=True)
def rms(x: np.ndarray, blas: bool | None) -> float:
    """Root mean square, as numpy's ``norm(x) / x.size ** 0.5``."""
    root_size: float = float(x.size) ** 0.5  # as numpy: pow, not sqrt
    if blas is not None:
        return math.sqrt(np.dot(x, x)) / root_size
    return math.sqrt(sum_of_squares(x, blas)) / root_size


@njit(cache=True, error_model="numpy", nogil=True)
def error_norm(y: np.ndarray, y_new: np.ndarray, K: np.ndarray, h: float, rtol: float,
               atol: np.ndarray, scale: np.ndarray, err5: np.ndarray, err3: np.ndarray,
               blas: bool | None) -> float:
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
                F: np.ndarray, blas: bool | None) -> None:
    """The 7 coefficient rows of the dense output over the step (needs K[13:16])."""
    if blas is not None:
        high = np.dot(D, K)
    else:
        high = np.zeros((INTERPOLANT_ROWS - 3, y.size))
        for r in range(INTERPOLANT_ROWS - 3):
            weighted_sum(K, STAGES_EXTENDED, D[r], high[r], None)
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


# The hooks of the shared loop (see :mod:`.loop` for their contract).

Work = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
             np.ndarray]


@njit(cache=True, error_model="numpy", nogil=True)
def setup(n: int, layout: tuple[np.ndarray, int, int, np.ndarray, np.ndarray]) -> Work:
    """The stages ``K``, the dense output's rows ``F`` and five work vectors."""
    return (np.empty((STAGES_EXTENDED, n)), np.empty((INTERPOLANT_ROWS, n)), np.empty(n),
            np.empty(n), np.empty(n), np.empty(n), np.empty(n))


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
         rtol: float, atol: np.ndarray,
         layout: tuple[np.ndarray, int, int, np.ndarray, np.ndarray], work: Work,
         counts: np.ndarray, y_new: np.ndarray, end: np.ndarray, blas: bool | None
         ) -> tuple[int, float, float, float, float]:
    """One accepted step of DOP853 from ``(t, y)`` (rejected ones before it)."""
    K, _, stage, sums, scale, err5, err3 = work
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
            stage_state(y, K, s, h, sums, stage, blas)
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
        error = error_norm(y, y_new, K, h, rtol, atol, scale, err5, err3, blas)
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
    """The three extra stages of the dense output and its rows ``F``."""
    K, F, stage, sums = work[0], work[1], work[2], work[3]
    for s in range(STAGES + 1, STAGES_EXTENDED):
        stage_state(y, K, s, h, sums, stage, blas)
        d = rhs(t + C[s] * h, stage, p, z)
        counts[RHS_CALLS] += 1
        status = verdict(d, z)
        if status != SUCCESS:
            copy(end, stage)
            return status, t + C[s] * h
        copy(K[s], d)
    interpolant(y, y_new, K, h, F, blas)
    return SUCCESS, t


@njit(cache=True, error_model="numpy", nogil=True)
def dense(work: Work, t: float, h: float, y: np.ndarray, at: float, out: np.ndarray,
          blas: bool | None) -> None:
    """The 7th-order dense output of the step at time ``at``."""
    interpolate(work[1], y, (at - t) / h, out)
