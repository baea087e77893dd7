"""RK45 (Dormand-Prince 5(4)), compiled: model function + output grid + start -> states.

scipy's ``RK45`` method (same controller, error norm, initial step and, with ``blas``,
the same sums: the runs agree with ``solve_ivp(method="RK45")`` step for step) with the
whole loop in numba; output on the grid from Shampine's 4th-order dense output;
observed variables, zero crossings and time events as in :mod:`.dop853_kernel`.

numba keys its disk cache on this file's modification time only: after editing
``rk45_tableau``, ``dop853_steps``, ``crossings``, ``signatures`` or ``status``, touch
this file and remove its cache files (``__pycache__/rk45_kernel.*``).
"""

import numpy as np
from numba import njit, types

from . import rk45_tableau as tableau
from .crossings import crossings, time_tolerance
from .dop853_steps import flagged, rms, sum_of_squares, verdict, weighted_sum
from .signatures import MODEL_FUNCTION, RUN_RESULT, VECTOR, ModelFunction, RunTuple
from .status import Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
MAX_STEPS = int(Status.MAX_STEPS)
MODEL_FAILED = int(Status.MODEL_FAILED)
STATE_EVENT = int(Status.STATE_EVENT)
TIME_EVENT = int(Status.TIME_EVENT)
A, B, C, E, P = tableau.A, tableau.B, tableau.C, tableau.E, tableau.P
STAGES = tableau.STAGES
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
ERROR_EXPONENT = -1.0 / (tableau.ERROR_ESTIMATOR_ORDER + 1)


@njit(cache=True, error_model="numpy", nogil=True)
def dense_state(Q: np.ndarray, y_old: np.ndarray, h: float, x: float, out: np.ndarray,
                blas: bool) -> None:
    """The dense output ``y_old + h Q [x, x^2, x^3, x^4]`` at the step fraction ``x``
    (with ``blas``, by the BLAS product numpy makes, as scipy's)."""
    powers = np.empty(Q.shape[1])
    power = 1.0
    for r in range(Q.shape[1]):
        power *= x
        powers[r] = power
    if blas:
        values = np.dot(Q, powers)
        for i in range(y_old.size):
            out[i] = h * values[i] + y_old[i]
        return
    for i in range(y_old.size):
        value = 0.0
        for r in range(Q.shape[1]):
            value += Q[i, r] * powers[r]
        out[i] = h * value + y_old[i]


@njit(RUN_RESULT(MODEL_FUNCTION, MODEL_FUNCTION, types.int64, MODEL_FUNCTION, VECTOR, VECTOR,
                 VECTOR, VECTOR, VECTOR, VECTOR, types.float64, VECTOR, types.float64,
                 types.float64, types.int64, types.boolean, types.float64),
      cache=True, error_model="numpy", nogil=True)
def rk45_run(rhs: ModelFunction, observed: ModelFunction, n_observed: int,
             crossing: ModelFunction, signs: np.ndarray, directions: np.ndarray,
             grid: np.ndarray, x0: np.ndarray, p: np.ndarray, z: np.ndarray, rtol: float,
             atol: np.ndarray, max_step: float, first_step: float, max_steps: int,
             blas: bool, t_stop: float) -> RunTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` over ``grid`` (arguments as ``dop853_run``).
    Returns ``RUN_RESULT``."""
    n, m, n_g = x0.size, grid.size, signs.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    K = np.empty((STAGES + 1, n))
    Q = np.empty((n, P.shape[1]))
    y, y_new, work, sums = x0.copy(), np.empty(n), np.empty(n), np.empty(n)
    scale, err = np.empty(n), np.empty(n)
    fired = np.zeros(n_g, dtype=np.int64)
    trial = np.zeros(n_g, dtype=np.int64)
    t, t_end = grid[0], grid[m - 1]
    limit = min(t_end, t_stop)
    accepted, rejected, nfev = 0, 0, 0
    h_abs = 0.0

    # Step 1: the start and its outputs.
    states[0] = y
    filled = 1
    if n_observed > 0:
        obs[0] = observed(t, y, p, z)
        if flagged(z):
            return MODEL_FAILED, states, obs, 0, 0, 0, 0, t, y.copy(), fired, h_abs
    g_start = crossing(t, y, p, z) if n_g > 0 else np.empty(0)
    if m == 1 or n == 0:
        for k in range(1, m):
            states[k] = y
        return SUCCESS, states, obs, m, 0, 0, 0, t, y.copy(), fired, h_abs
    d = rhs(t, y, p, z)
    nfev += 1
    status = verdict(d, z)
    if status != SUCCESS:
        return status, states, obs, filled, 0, 0, nfev, t, y.copy(), fired, h_abs
    K[0] = d

    # Step 2: the initial step (scipy's select_initial_step, error estimator order 4).
    interval = limit - t
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
            return status, states, obs, filled, 0, 0, nfev, t + h0, work.copy(), fired, h_abs
        d2 = rms((d - K[0]) / scale, blas) / h0
        h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 \
            else (0.01 / max(d1, d2)) ** (1 / (tableau.ERROR_ESTIMATOR_ORDER + 1))
        h_abs = min(100 * h0, h1, interval, max_step)
        if not h_abs > 0.0:  # underflowed (or NaN) at extreme values: no step
            return (STEP_TOO_SMALL, states, obs, filled, 0, 0, nfev, t, y.copy(), fired,
                    h_abs)

    # Step 3: steps until the end (or an event).
    while t < limit:
        if max_steps > 0 and accepted + rejected >= max_steps:
            return (MAX_STEPS, states, obs, filled, accepted, rejected, nfev, t, y.copy(),
                    fired, h_abs)
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        step_rejected = False
        while True:
            if h_abs < min_step:
                return (STEP_TOO_SMALL, states, obs, filled, accepted, rejected, nfev, t,
                        y.copy(), fired, h_abs)
            t_new = t + h_abs
            if t_new - limit > 0:
                t_new = limit
            h = t_new - t
            h_abs = abs(h)
            for s in range(1, STAGES):
                weighted_sum(K, s, A[s], sums, blas)
                for i in range(n):
                    work[i] = y[i] + sums[i] * h
                d = rhs(t + C[s] * h, work, p, z)
                nfev += 1
                status = verdict(d, z)
                if status != SUCCESS:
                    return (status, states, obs, filled, accepted, rejected, nfev,
                            t + C[s] * h, work.copy(), fired, h_abs)
                K[s] = d
            weighted_sum(K, STAGES, B, sums, blas)
            for i in range(n):
                y_new[i] = y[i] + h * sums[i]
            d = rhs(t + h, y_new, p, z)
            nfev += 1
            status = verdict(d, z)
            if status != SUCCESS:
                return (status, states, obs, filled, accepted, rejected, nfev, t + h,
                        y_new.copy(), fired, h_abs)
            K[STAGES] = d
            weighted_sum(K, STAGES + 1, E, err, blas)
            for i in range(n):
                scale[i] = atol[i] + max(abs(y[i]), abs(y_new[i])) * rtol
                err[i] = err[i] * h / scale[i]
            error = (sum_of_squares(err, blas) / n) ** 0.5 if not blas else rms(err, blas)
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
        if blas:  # the dense output: Q = K^T P
            Q[:] = np.dot(K.T, P)
        else:
            for i in range(n):
                for r in range(P.shape[1]):
                    acc = 0.0
                    for s in range(STAGES + 1):
                        acc += K[s, i] * P[s, r]
                    Q[i, r] = acc

        # Step 4: the earliest crossing in (t, t_new], by bisection on the dense output.
        event = False
        t_event = t_new
        g_end = g_start
        if n_g > 0:
            g_end = crossing(t_new, y_new, p, z)
            event = crossings(g_start, g_end, signs, directions, fired)
        if event:
            low, high = t, t_new
            tolerance = time_tolerance(t, t_new)
            while high - low > tolerance:
                middle = low + 0.5 * (high - low)
                if middle <= low or middle >= high:
                    break
                dense_state(Q, y, h, (middle - t) / h, work, blas)
                if crossings(g_start, crossing(middle, work, p, z), signs, directions,
                             trial):
                    high = middle
                    fired[:] = trial
                else:
                    low = middle
            t_event = high
            if high < t_new:
                dense_state(Q, y, h, (high - t) / h, y_new, blas)

        # Step 5: the output times in (t, t_new] (before an event: before it).
        stops = event or t_new == t_stop < t_end
        while filled < m and (grid[filled] < t_event
                              or (grid[filled] == t_event and not stops)):
            if grid[filled] == t_new:
                states[filled] = y_new
            else:
                dense_state(Q, y, h, (grid[filled] - t) / h, states[filled], blas)
            if n_observed > 0:
                obs[filled] = observed(grid[filled], states[filled], p, z)
                if flagged(z):
                    return (MODEL_FAILED, states, obs, filled, accepted, rejected, nfev,
                            grid[filled], states[filled].copy(), fired, h_abs)
            filled += 1
        if event:
            return (STATE_EVENT, states, obs, filled, accepted, rejected, nfev, t_event,
                    y_new.copy(), fired, h_abs)
        t = t_new
        y[:] = y_new
        K[0] = K[STAGES]
        g_start = g_end
    final = TIME_EVENT if limit < t_end else SUCCESS
    return final, states, obs, filled, accepted, rejected, nfev, t, y.copy(), fired, h_abs
