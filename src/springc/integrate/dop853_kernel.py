"""DOP853, compiled: model function + output grid + start -> states on the grid.

The explicit Runge-Kutta method of Dormand and Prince, order 8 with 5th- and 3rd-order
error estimates and a 7th-order dense output (Hairer, Norsett, Wanner, *Solving ODEs I*,
Sec. II.10). The step-size controller, the error norm and the initial step are those of
``scipy.integrate.solve_ivp(method="DOP853")``; with the ``blas`` flag the sums are
scipy's too, and both runs agree bit for bit (the tests check this).

The whole loop runs in numba: steps, error control, the dense output on the output
grid and the observed variables at the output times. The model functions arrive as
first-class function values, so this module is compiled once per machine (and cached
on disk), whatever the model. Failures return a status code, never raise.

numba keys its disk cache on this file's modification time only: the constants taken
from ``dop853_tableau``, ``signatures`` and ``status`` are frozen into the cached code,
so touch this file after editing those.
"""

import math

import numpy as np
from numba import njit, types

from . import dop853_tableau as tableau
from .signatures import MODEL_FUNCTION, RUN_RESULT, VECTOR, ModelFunction, RunTuple
from .status import Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
NON_FINITE_DERIVATIVE = int(Status.NON_FINITE_DERIVATIVE)
MAX_STEPS = int(Status.MAX_STEPS)
MODEL_FAILED = int(Status.MODEL_FAILED)

STAGES = tableau.STAGES
STAGES_EXTENDED = tableau.STAGES_EXTENDED
INTERPOLANT_ROWS = tableau.INTERPOLANT_ROWS
A, B, C, D, E3, E5 = tableau.A, tableau.B, tableau.C, tableau.D, tableau.E3, tableau.E5

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


@njit(RUN_RESULT(MODEL_FUNCTION, MODEL_FUNCTION, types.int64, VECTOR, VECTOR, VECTOR, VECTOR,
                 types.float64, VECTOR, types.float64, types.float64, types.int64,
                 types.boolean),
      cache=True, error_model="numpy", nogil=True)
def dop853_run(rhs: ModelFunction, observed: ModelFunction, n_observed: int, grid: np.ndarray,
               x0: np.ndarray, p: np.ndarray, z: np.ndarray, rtol: float, atol: np.ndarray,
               max_step: float, first_step: float, max_steps: int, blas: bool) -> RunTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` from ``(grid[0], x0)`` to ``grid[-1]``.

    ``grid`` increases strictly; ``atol`` has one entry per state; ``first_step`` 0
    selects the initial step as scipy does; ``max_steps`` 0 means no limit (it counts
    accepted and rejected steps). ``observed`` is called at every output time when
    ``n_observed`` > 0; ``blas``: see :func:`weighted_sum`. Returns ``RUN_RESULT``
    (see :mod:`.signatures`).
    """
    n, m = x0.size, grid.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    K = np.empty((STAGES_EXTENDED, n))
    F = np.empty((INTERPOLANT_ROWS, n))
    y, y_new, work, sums = x0.copy(), np.empty(n), np.empty(n), np.empty(n)
    scale, err5, err3 = np.empty(n), np.empty(n), np.empty(n)
    t, t_end = grid[0], grid[m - 1]
    accepted, rejected, nfev = 0, 0, 0

    # Step 1: the start and its outputs.
    states[0] = y
    filled = 1
    if n_observed > 0:
        obs[0] = observed(t, y, p, z)
        if flagged(z):
            return MODEL_FAILED, states, obs, 0, 0, 0, 0, t, y.copy()
    if m == 1 or n == 0:
        for k in range(1, m):
            states[k] = y
        return SUCCESS, states, obs, m, 0, 0, 0, t, y.copy()
    d = rhs(t, y, p, z)
    nfev += 1
    status = verdict(d, z)
    if status != SUCCESS:
        return status, states, obs, filled, 0, 0, nfev, t, y.copy()
    K[0] = d

    # Step 2: the initial step (Hairer's algorithm, as scipy's select_initial_step).
    interval = abs(t_end - t)
    if first_step > 0.0:
        h_abs = first_step
    else:
        for i in range(n):
            scale[i] = atol[i] + abs(y[i]) * rtol
        d0, d1 = rms(y / scale, blas), rms(K[0] / scale, blas)
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, interval)
        for i in range(n):
            work[i] = y[i] + h0 * K[0, i]
        d = rhs(t + h0, work, p, z)
        nfev += 1
        status = verdict(d, z)
        if status != SUCCESS:
            return status, states, obs, filled, 0, 0, nfev, t + h0, work.copy()
        d2 = rms((d - K[0]) / scale, blas) / h0
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** 0.125
        h_abs = min(100 * h0, h1, interval, max_step)

    # Step 3: steps until the end, each filling the output times it passes.
    while t < t_end:
        if max_steps > 0 and accepted + rejected >= max_steps:
            return MAX_STEPS, states, obs, filled, accepted, rejected, nfev, t, y.copy()
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        step_rejected = False
        while True:
            if h_abs < min_step:
                return (STEP_TOO_SMALL, states, obs, filled, accepted, rejected, nfev, t,
                        y.copy())
            t_new = t + h_abs
            if t_new - t_end > 0:
                t_new = t_end
            h = t_new - t
            h_abs = abs(h)
            for s in range(1, STAGES):
                stage_state(y, K, s, h, sums, work, blas)
                d = rhs(t + C[s] * h, work, p, z)
                nfev += 1
                status = verdict(d, z)
                if status != SUCCESS:
                    return (status, states, obs, filled, accepted, rejected, nfev,
                            t + C[s] * h, work.copy())
                K[s] = d
            weighted_sum(K, STAGES, B, sums, blas)
            for i in range(n):
                y_new[i] = y[i] + h * sums[i]
            d = rhs(t + h, y_new, p, z)
            nfev += 1
            status = verdict(d, z)
            if status != SUCCESS:
                return (status, states, obs, filled, accepted, rejected, nfev, t + h,
                        y_new.copy())
            K[STAGES] = d
            error = error_norm(y, y_new, K, h, rtol, atol, scale, err5, err3, blas)
            if error < 1:
                factor = MAX_FACTOR if error == 0 else min(MAX_FACTOR,
                                                           SAFETY * error ** ERROR_EXPONENT)
                if step_rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            h_abs *= max(MIN_FACTOR, SAFETY * error ** ERROR_EXPONENT)
            step_rejected = True
            rejected += 1
        accepted += 1

        # Step 4: the output times in (t, t_new], from the dense output.
        if filled < m and grid[filled] <= t_new:
            for s in range(STAGES + 1, STAGES_EXTENDED):
                stage_state(y, K, s, h, sums, work, blas)
                d = rhs(t + C[s] * h, work, p, z)
                nfev += 1
                status = verdict(d, z)
                if status != SUCCESS:
                    return (status, states, obs, filled, accepted, rejected, nfev,
                            t + C[s] * h, work.copy())
                K[s] = d
            interpolant(y, y_new, K, h, F, blas)
            while filled < m and grid[filled] <= t_new:
                if grid[filled] == t_new:
                    states[filled] = y_new
                else:
                    interpolate(F, y, (grid[filled] - t) / h, states[filled])
                if n_observed > 0:
                    obs[filled] = observed(grid[filled], states[filled], p, z)
                    if flagged(z):
                        return (MODEL_FAILED, states, obs, filled, accepted, rejected, nfev,
                                grid[filled], states[filled].copy())
                filled += 1
        t = t_new
        y[:] = y_new
        K[0] = K[STAGES]
    return SUCCESS, states, obs, filled, accepted, rejected, nfev, t, y.copy()
