"""BDF (variable order 1-5), compiled: model + analytic Jacobian + output grid -> states.

scipy's ``BDF`` method (the NDF/BDF formulas in backward-difference form, with its
controller, order selection, Newton iteration and Jacobian reuse; the tests compare
steps and errors with scipy's) with the whole loop in numba and the generated sparse
Jacobian in the banded LU of :mod:`.banded_lu` (``I - c J``: one real matrix per step
size). Grid filling, observed variables, zero crossings and time events as in
:mod:`.radau_kernel`, on the step's interpolating polynomial.

numba keys its disk cache on this file's modification time only: after editing
``bdf_steps``, ``crossings``, ``signatures`` or ``status``, touch this file and remove
its cache files (``__pycache__/bdf_kernel.*``).
"""

import math

import numpy as np
from numba import njit, types

from .banded_lu import band_factor
from .bdf_steps import (
    ALPHA,
    ERROR_CONST,
    GAMMA,
    MAX_ORDER,
    NEWTON_MAXITER,
    bdf_dense_state,
    change_differences,
    newton_bdf,
    scaled_rms,
)
from .crossings import crossings, time_tolerance
from .radau_kernel import verdict
from .radau_steps import rms
from .signatures import (
    IMPLICIT_RESULT,
    INDICES,
    MODEL_FUNCTION,
    VECTOR,
    ImplicitTuple,
    ModelFunction,
)
from .status import Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
MAX_STEPS = int(Status.MAX_STEPS)
STATE_EVENT = int(Status.STATE_EVENT)
TIME_EVENT = int(Status.TIME_EVENT)
MODEL_FAILED = int(Status.MODEL_FAILED)
MIN_FACTOR, MAX_FACTOR = 0.2, 10.0
EPS = float(np.finfo(float).eps)


@njit(cache=True, error_model="numpy", nogil=True)
def factor_iteration_matrix(c: float, J: np.ndarray, positions: np.ndarray,
                            diagonal: np.ndarray, kl: int, ku: int, factors: np.ndarray,
                            pivots: np.ndarray) -> bool:
    """``I - c J`` assembled in its band and factorised; False if singular."""
    flat = factors.reshape(factors.size)
    flat[:] = 0.0
    for k in range(diagonal.size):
        flat[diagonal[k]] = 1.0
    for k in range(positions.size):
        flat[positions[k]] -= c * J[k]
    return band_factor(factors, kl, ku, pivots)


@njit(IMPLICIT_RESULT(MODEL_FUNCTION, MODEL_FUNCTION, MODEL_FUNCTION, types.int64,
                      MODEL_FUNCTION, VECTOR, VECTOR, VECTOR, VECTOR, VECTOR, VECTOR,
                      types.float64, VECTOR, types.float64, types.float64, types.int64,
                      types.float64, INDICES, types.int64, types.int64, INDICES, INDICES),
      cache=True, error_model="numpy", nogil=True)
def bdf_run(rhs: ModelFunction, jac: ModelFunction, observed: ModelFunction,
            n_observed: int, crossing: ModelFunction, signs: np.ndarray,
            directions: np.ndarray, grid: np.ndarray, x0: np.ndarray, p: np.ndarray,
            z: np.ndarray, rtol: float, atol: np.ndarray, max_step: float,
            first_step: float, max_steps: int, t_stop: float, order_of: np.ndarray, kl: int,
            ku: int, positions: np.ndarray, diagonal: np.ndarray) -> ImplicitTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` over ``grid`` (arguments as ``radau_run``).
    Returns ``IMPLICIT_RESULT``."""
    n, m, n_g = x0.size, grid.size, signs.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    fired = np.zeros(n_g, dtype=np.int64)
    trial = np.zeros(n_g, dtype=np.int64)
    y, y_new, y_predict, work = x0.copy(), np.empty(n), np.empty(n), np.empty(n)
    scale, psi, d = np.empty(n), np.empty(n), np.empty(n)
    factors = np.zeros((n, 2 * kl + ku + 1))
    pivots = np.empty(n, dtype=np.int64)
    D = np.zeros((MAX_ORDER + 3, n))
    t, t_end = grid[0], grid[m - 1]
    limit = min(t_end, t_stop)
    accepted, rejected, nfev, njev = 0, 0, 0, 0
    h_abs = 0.0

    # Step 1: the start, its outputs, the derivative and the Jacobian there.
    states[0] = y
    filled = 1
    if n_observed > 0:
        obs[0] = observed(t, y, p, z)
        if z.size > 0 and z[z.size - 1] != 0.0:
            return MODEL_FAILED, states, obs, 0, 0, 0, 0, t, y.copy(), fired, 0.0, 0
    g_start = crossing(t, y, p, z) if n_g > 0 else np.empty(0)
    if m == 1 or n == 0:
        for k in range(1, m):
            states[k] = y
        return SUCCESS, states, obs, m, 0, 0, 0, t, y.copy(), fired, h_abs, 0
    f = rhs(t, y, p, z)
    nfev += 1
    status = verdict(f, z)
    if status != SUCCESS:
        return status, states, obs, filled, 0, 0, nfev, t, y.copy(), fired, h_abs, 0

    # Step 2: the initial step (scipy's select_initial_step, error estimator order 1).
    interval = limit - t
    if first_step > 0.0:
        h_abs = first_step
    else:
        for i in range(n):
            scale[i] = atol[i] + abs(y[i]) * rtol
        d0, d1 = rms(y / scale), rms(f / scale)
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, interval)
        for i in range(n):
            work[i] = y[i] + h0 * f[i]
        f1 = rhs(t + h0, work, p, z)
        nfev += 1
        status = verdict(f1, z)
        if status != SUCCESS:
            return status, states, obs, filled, 0, 0, nfev, t + h0, work.copy(), fired, h_abs, 0
        d2 = rms((f1 - f) / scale) / h0
        h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 \
            else (0.01 / max(d1, d2)) ** 0.5
        h_abs = min(100 * h0, h1, interval, max_step)
        if not h_abs > 0.0:  # underflowed (or NaN) at extreme values: no step
            return (STEP_TOO_SMALL, states, obs, filled, 0, 0, nfev, t, y.copy(), fired,
                    h_abs, 0)
    newton_tol = max(10 * EPS / rtol, min(0.03, rtol ** 0.5))
    J = jac(t, y, p, z)
    njev += 1
    status = verdict(J, z)
    if status != SUCCESS:
        return status, states, obs, filled, 0, 0, nfev, t, y.copy(), fired, h_abs, njev
    D[0] = y
    for i in range(n):
        D[1, i] = f[i] * h_abs
    order, n_equal_steps, factored = 1, 0, False

    # Step 3: steps until the end (or an event).
    while t < limit:
        if max_steps > 0 and accepted + rejected >= max_steps:
            return (MAX_STEPS, states, obs, filled, accepted, rejected, nfev, t, y.copy(),
                    fired, h_abs, njev)
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            change_differences(D, order, max_step / h_abs)
            h_abs, n_equal_steps = max_step, 0
        elif h_abs < min_step:
            change_differences(D, order, min_step / h_abs)
            h_abs, n_equal_steps = min_step, 0
        current_jac = False
        while True:
            if h_abs < min_step:
                return (STEP_TOO_SMALL, states, obs, filled, accepted, rejected, nfev, t,
                        y.copy(), fired, h_abs, njev)
            t_new = t + h_abs
            if t_new - limit > 0:
                t_new = limit
                change_differences(D, order, abs(t_new - t) / h_abs)
                n_equal_steps, factored = 0, False
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
            c = h / ALPHA[order]
            converged, n_iter = False, 0
            while True:
                if not factored:
                    factored = factor_iteration_matrix(c, J, positions, diagonal, kl, ku,
                                                       factors, pivots)
                if factored:
                    converged, n_iter, used, status = newton_bdf(
                        rhs, t_new, y_predict, c, psi, factors, kl, ku, pivots, order_of,
                        scale, newton_tol, p, z, y_new, d)
                    nfev += used
                    if status != SUCCESS:
                        return (status, states, obs, filled, accepted, rejected, nfev,
                                t_new, y_new.copy(), fired, h_abs, njev)
                if converged or current_jac:
                    break
                J = jac(t_new, y_predict, p, z)
                njev += 1
                status = verdict(J, z)
                if status != SUCCESS:
                    return (status, states, obs, filled, accepted, rejected, nfev, t_new,
                            y_predict.copy(), fired, h_abs, njev)
                factored, current_jac = False, True
            if not converged:
                h_abs *= 0.5
                change_differences(D, order, 0.5)
                n_equal_steps, factored = 0, False
                rejected += 1
                continue
            safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
            for i in range(n):
                scale[i] = atol[i] + rtol * abs(y_new[i])
            error_norm = scaled_rms(d, ERROR_CONST[order], scale)
            if error_norm > 1:
                factor = max(MIN_FACTOR, safety * error_norm ** (-1 / (order + 1)))
                h_abs *= factor
                change_differences(D, order, factor)
                n_equal_steps = 0
                rejected += 1
                continue
            break
        accepted += 1
        n_equal_steps += 1
        t_old = t

        # Step 4: the differences, and maybe another order and step size.
        D[order + 2] = d - D[order + 1]
        D[order + 1] = d
        for i in range(order, -1, -1):
            D[i] += D[i + 1]
        if n_equal_steps >= order + 1:
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
            n_equal_steps, factored = 0, False

        # Step 5: the earliest crossing in (t_old, t_new], on the interpolant.
        event = False
        t_event = t_new
        g_end = g_start
        if n_g > 0:
            g_end = crossing(t_new, y_new, p, z)
            event = crossings(g_start, g_end, signs, directions, fired)
        if event:
            low, high = t_old, t_new
            tolerance = time_tolerance(t_old, t_new)
            while high - low > tolerance:
                middle = low + 0.5 * (high - low)
                if middle <= low or middle >= high:
                    break
                bdf_dense_state(D, order, t_new, h_abs, middle, work)
                if crossings(g_start, crossing(middle, work, p, z), signs, directions,
                             trial):
                    high = middle
                    fired[:] = trial
                else:
                    low = middle
            t_event = high
            if high < t_new:
                bdf_dense_state(D, order, t_new, h_abs, high, y_new)

        # Step 6: the output times in (t_old, t_new] (before an event: before it).
        stops = event or t_new == t_stop < t_end
        while filled < m and (grid[filled] < t_event
                              or (grid[filled] == t_event and not stops)):
            if grid[filled] == t_new:
                states[filled] = y_new
            else:
                bdf_dense_state(D, order, t_new, h_abs, grid[filled], states[filled])
            if n_observed > 0:
                obs[filled] = observed(grid[filled], states[filled], p, z)
                if z.size > 0 and z[z.size - 1] != 0.0:
                    return (MODEL_FAILED, states, obs, filled, accepted,
                            rejected, nfev, grid[filled], states[filled].copy(), fired,
                            h_abs, njev)
            filled += 1
        if event:
            return (STATE_EVENT, states, obs, filled, accepted, rejected, nfev, t_event,
                    y_new.copy(), fired, h_abs, njev)
        t = t_new
        y[:] = y_new
        g_start = g_end
    final = TIME_EVENT if limit < t_end else SUCCESS
    return final, states, obs, filled, accepted, rejected, nfev, t, y.copy(), fired, h_abs, njev
