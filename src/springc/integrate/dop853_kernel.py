"""DOP853, compiled: model function + output grid + start -> states on the grid.

The explicit Runge-Kutta method of Dormand and Prince, order 8 with 5th- and 3rd-order
error estimates and a 7th-order dense output (Hairer, Norsett, Wanner, *Solving ODEs I*,
Sec. II.10). The step-size controller, the error norm and the initial step are those of
``scipy.integrate.solve_ivp(method="DOP853")``; with the ``blas`` flag the sums are
scipy's too, and both runs agree bit for bit (the tests check this).

The whole loop runs in numba: steps, error control, the dense output on the output
grid, the observed variables at the output times and the zero crossings (located on the
dense output, see :mod:`.crossings`). The model functions arrive as first-class function
values, so this module is compiled once per machine (and cached on disk), whatever the
model. Failures and events return a status code, never raise.

numba keys its disk cache on this file's modification time only: the constants taken
from ``dop853_steps``, ``crossings``, ``signatures`` and ``status`` are frozen into the
cached code, so touch this file after editing those.
"""

import numpy as np
from numba import njit, types

from .crossings import crossings, time_tolerance
from .dop853_steps import (
    INTERPOLANT_ROWS,
    STAGES,
    STAGES_EXTENDED,
    C,
    error_norm,
    flagged,
    interpolant,
    interpolate,
    rms,
    stage_state,
    verdict,
    weighted_sum,
)
from .dop853_tableau import B
from .signatures import MODEL_FUNCTION, RUN_RESULT, VECTOR, ModelFunction, RunTuple
from .status import Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
MAX_STEPS = int(Status.MAX_STEPS)
MODEL_FAILED = int(Status.MODEL_FAILED)
STATE_EVENT = int(Status.STATE_EVENT)
TIME_EVENT = int(Status.TIME_EVENT)

SAFETY = 0.9  # factor on the step size predicted from the error estimate
MIN_FACTOR = 0.2  # largest decrease of the step size after a rejection
MAX_FACTOR = 10.0  # largest increase after an accepted step
ERROR_EXPONENT = -1.0 / 8.0  # -1 / (error estimator order 7 + 1)


@njit(RUN_RESULT(MODEL_FUNCTION, MODEL_FUNCTION, types.int64, MODEL_FUNCTION, VECTOR, VECTOR,
                 VECTOR, VECTOR, VECTOR, VECTOR, types.float64, VECTOR, types.float64,
                 types.float64, types.int64, types.boolean, types.float64),
      cache=True, error_model="numpy", nogil=True)
def dop853_run(rhs: ModelFunction, observed: ModelFunction, n_observed: int,
               crossing: ModelFunction, signs: np.ndarray, directions: np.ndarray,
               grid: np.ndarray, x0: np.ndarray, p: np.ndarray, z: np.ndarray, rtol: float,
               atol: np.ndarray, max_step: float, first_step: float, max_steps: int,
               blas: bool, t_stop: float) -> RunTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` from ``(grid[0], x0)`` to ``grid[-1]``.

    ``grid`` increases strictly; ``atol`` has one entry per state; ``first_step`` 0
    selects the initial step as scipy does; ``max_steps`` 0 means no limit (it counts
    accepted and rejected steps). ``observed`` is called at every output time when
    ``n_observed`` > 0; ``blas``: see :func:`.dop853_steps.weighted_sum`.

    Events: ``crossing`` is called after every accepted step when ``signs`` is not
    empty (see :mod:`.crossings`); the earliest crossing stops the run with STATE_EVENT.
    A ``t_stop`` before ``grid[-1]`` is a time event: a step ends on it exactly and the
    run stops there with TIME_EVENT. Returns ``RUN_RESULT`` (see :mod:`.signatures`).
    """
    n, m, n_g = x0.size, grid.size, signs.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    K = np.empty((STAGES_EXTENDED, n))
    F = np.empty((INTERPOLANT_ROWS, n))
    y, y_new, work, sums = x0.copy(), np.empty(n), np.empty(n), np.empty(n)
    scale, err5, err3 = np.empty(n), np.empty(n), np.empty(n)
    fired = np.zeros(n_g, dtype=np.int64)
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
    if flagged(z):
        return MODEL_FAILED, states, obs, 0, 0, 0, 0, t, y.copy(), fired, h_abs
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

    # Step 2: the initial step (Hairer's algorithm, as scipy's select_initial_step).
    interval = abs(limit - t)
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
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** 0.125
        h_abs = min(100 * h0, h1, interval, max_step)
        if not h_abs > 0.0:  # underflowed (or NaN) at extreme values: no step
            return (STEP_TOO_SMALL, states, obs, filled, 0, 0, nfev, t, y.copy(), fired,
                    h_abs)

    # Step 3: steps until the end (or an event), each filling the output times it passes.
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
                stage_state(y, K, s, h, sums, work, blas)
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

        # Step 4: a crossing in (t, t_new]?
        event = False
        if n_g > 0:
            g_end = crossing(t_new, y_new, p, z)
            if flagged(z):
                return (MODEL_FAILED, states, obs, filled, accepted, rejected, nfev, t_new,
                        y_new.copy(), fired, h_abs)
            event = crossings(g_start, g_end, signs, directions, fired)
        else:
            g_end = g_start

        # Step 5: the dense output, wherever it is needed.
        if event or (filled < m and grid[filled] <= t_new):
            for s in range(STAGES + 1, STAGES_EXTENDED):
                stage_state(y, K, s, h, sums, work, blas)
                d = rhs(t + C[s] * h, work, p, z)
                nfev += 1
                status = verdict(d, z)
                if status != SUCCESS:
                    return (status, states, obs, filled, accepted, rejected, nfev,
                            t + C[s] * h, work.copy(), fired, h_abs)
                K[s] = d
            interpolant(y, y_new, K, h, F, blas)

        # Step 6: the earliest crossing, by bisection on the dense output.
        t_event = t_new
        if event:
            low, high = t, t_new
            tolerance = time_tolerance(t, t_new)
            trial = np.empty(n_g, dtype=np.int64)
            while high - low > tolerance:
                middle = low + 0.5 * (high - low)
                if middle <= low or middle >= high:
                    break
                interpolate(F, y, (middle - t) / h, work)
                g_middle = crossing(middle, work, p, z)
                if crossings(g_start, g_middle, signs, directions, trial):
                    high = middle
                    fired[:] = trial
                else:
                    low = middle
            t_event = high
            if high < t_new:
                interpolate(F, y, (high - t) / h, y_new)

        # Step 7: the output times in (t, t_new] (before an event: in (t, t_event)).
        stops = event or t_new == t_stop < t_end
        while filled < m and (grid[filled] < t_event
                              or (grid[filled] == t_event and not stops)):
            if grid[filled] == t_new:
                states[filled] = y_new
            else:
                interpolate(F, y, (grid[filled] - t) / h, states[filled])
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
    if limit < t_end:
        return TIME_EVENT, states, obs, filled, accepted, rejected, nfev, t, y.copy(), fired, h_abs
    return SUCCESS, states, obs, filled, accepted, rejected, nfev, t, y.copy(), fired, h_abs
