"""Radau IIA (order 5), compiled: model + analytic Jacobian + output grid -> states.

The implicit method for stiff scenes, as scipy's ``Radau`` runs it (same controller,
Newton iteration, Jacobian reuse and error estimate; the tests compare steps and errors
with scipy's on the same problems), with the whole loop in numba and the generated
sparse Jacobian (``jacobian_values`` in CSC order) assembled into a banded LU
(:mod:`.banded_lu`: dense for small systems, reverse Cuthill-McKee ordered for large).
Grid filling, observed variables, zero crossings and time events work as in
:mod:`.dop853_kernel`, on the step's collocation polynomial.

numba keys its disk cache on this file's modification time only: touch it after editing
``radau_steps``, ``crossings``, ``signatures`` or ``status``.
"""

import math

import numpy as np
from numba import njit, types

from .crossings import crossings, time_tolerance
from .radau_steps import (
    NEWTON_MAXITER,
    C,
    E,
    dense_coefficients,
    dense_state,
    factor_newton_matrices,
    newton,
    predict_factor,
    rms,
    solve_in_order,
)
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
NON_FINITE_DERIVATIVE = int(Status.NON_FINITE_DERIVATIVE)
MAX_STEPS = int(Status.MAX_STEPS)
MODEL_FAILED = int(Status.MODEL_FAILED)
STATE_EVENT = int(Status.STATE_EVENT)
TIME_EVENT = int(Status.TIME_EVENT)
MIN_FACTOR, MAX_FACTOR = 0.2, 10.0
EPS = float(np.finfo(float).eps)


@njit(cache=True, error_model="numpy", nogil=True)
def verdict(d: np.ndarray, z: np.ndarray) -> int:
    if z.size > 0 and z[z.size - 1] != 0.0:
        return MODEL_FAILED
    for value in d:
        if not math.isfinite(value):
            return NON_FINITE_DERIVATIVE
    return SUCCESS


@njit(IMPLICIT_RESULT(MODEL_FUNCTION, MODEL_FUNCTION, MODEL_FUNCTION, types.int64,
                      MODEL_FUNCTION, VECTOR, VECTOR, VECTOR, VECTOR, VECTOR, VECTOR,
                      types.float64, VECTOR, types.float64, types.float64, types.int64,
                      types.float64, INDICES, types.int64, types.int64, INDICES, INDICES),
      cache=True, error_model="numpy", nogil=True)
def radau_run(rhs: ModelFunction, jac: ModelFunction, observed: ModelFunction,
              n_observed: int, crossing: ModelFunction, signs: np.ndarray,
              directions: np.ndarray, grid: np.ndarray, x0: np.ndarray, p: np.ndarray,
              z: np.ndarray, rtol: float, atol: np.ndarray, max_step: float,
              first_step: float, max_steps: int, t_stop: float, order: np.ndarray, kl: int,
              ku: int, positions: np.ndarray, diagonal: np.ndarray) -> ImplicitTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` over ``grid`` (arguments as ``dop853_run``;
    ``jac`` returns the Jacobian's non-zeros, which land at ``positions`` of the band
    ``kl``/``ku`` in the ordering ``order``; see :func:`.banded_lu.band_layout`).
    Returns ``IMPLICIT_RESULT``: ``RUN_RESULT`` and the Jacobian evaluations."""
    n, m, n_g = x0.size, grid.size, signs.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    fired = np.zeros(n_g, dtype=np.int64)
    trial = np.zeros(n_g, dtype=np.int64)
    y, y_new, work = x0.copy(), np.empty(n), np.empty(n)
    scale, error, ZE = np.empty(n), np.empty(n), np.empty(n)
    Z0, Z = np.zeros((3, n)), np.zeros((3, n))
    Q, y_old = np.zeros((n, 3)), np.empty(n)
    width = 2 * kl + ku + 1
    real = np.zeros((n, width))
    complex_ = np.zeros((n, width), dtype=np.complex128)
    pivots_real = np.empty(n, dtype=np.int64)
    pivots_complex = np.empty(n, dtype=np.int64)
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
            return MODEL_FAILED, states, obs, 0, 0, 0, 0, t, y.copy(), fired, h_abs, 0
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

    # Step 2: the initial step (scipy's select_initial_step, error estimator order 3).
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
        d = rhs(t + h0, work, p, z)
        nfev += 1
        status = verdict(d, z)
        if status != SUCCESS:
            return status, states, obs, filled, 0, 0, nfev, t + h0, work.copy(), fired, h_abs, 0
        d2 = rms((d - f) / scale) / h0
        h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 \
            else (0.01 / max(d1, d2)) ** 0.25
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
    current_jac, factored, have_dense = True, False, False
    h_abs_old, error_norm_old = -1.0, -1.0  # -1: none
    t_old, h_dense = t, 0.0
    n_iter, rate, error_norm, safety = 0, -1.0, 0.0, 0.9

    # Step 3: steps until the end (or an event).
    while t < limit:
        if max_steps > 0 and accepted + rejected >= max_steps:
            return (MAX_STEPS, states, obs, filled, accepted, rejected, nfev, t, y.copy(),
                    fired, h_abs, njev)
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        h_proposed = h_abs
        step_h_old, step_error_old = h_abs_old, error_norm_old
        if h_abs > max_step:
            h_abs, step_h_old, step_error_old = max_step, -1.0, -1.0
        elif h_abs < min_step:
            h_abs, step_h_old, step_error_old = min_step, -1.0, -1.0
        step_rejected = False
        while True:
            if h_abs < min_step:
                return (STEP_TOO_SMALL, states, obs, filled, accepted, rejected, nfev, t,
                        y.copy(), fired, h_abs, njev)
            t_new = t + h_abs
            if t_new - limit > 0:
                t_new = limit
            h = t_new - t
            h_abs = abs(h)
            for i in range(3):  # the last step's collocation polynomial, extrapolated
                if have_dense:
                    dense_state(Q, y_old, (t + h * C[i] - t_old) / h_dense, work)
                    for j in range(n):
                        Z0[i, j] = work[j] - y[j]
                else:
                    Z0[i] = 0.0
            for j in range(n):
                scale[j] = atol[j] + abs(y[j]) * rtol
            converged = False
            while not converged:
                if not factored:
                    factored = factor_newton_matrices(h, J, positions, diagonal, kl, ku, real,
                                                      complex_, pivots_real, pivots_complex)
                if factored:
                    converged, n_iter, rate, used, status = newton(
                        rhs, t, y, h, Z0, scale, newton_tol, real, complex_, pivots_real,
                        pivots_complex, kl, ku, order, p, z, Z)
                    nfev += used
                    if status != SUCCESS:
                        return (status, states, obs, filled, accepted, rejected, nfev, t,
                                y.copy(), fired, h_abs, njev)
                if converged or current_jac:
                    break
                J = jac(t, y, p, z)
                njev += 1
                status = verdict(J, z)
                if status != SUCCESS:
                    return (status, states, obs, filled, accepted, rejected, nfev, t,
                            y.copy(), fired, h_abs, njev)
                current_jac, factored = True, False
            if not converged:  # (scipy's Radau: not a rejection of the error test)
                h_abs *= 0.5
                factored = False
                rejected += 1
                continue
            for j in range(n):
                y_new[j] = y[j] + Z[2, j]
                ZE[j] = (Z[0, j] * E[0] + Z[1, j] * E[1] + Z[2, j] * E[2]) / h
                error[j] = f[j] + ZE[j]
            solve_in_order(real, kl, ku, pivots_real, order, error, work)
            for j in range(n):
                scale[j] = atol[j] + max(abs(y[j]), abs(y_new[j])) * rtol
            error_norm = rms(error / scale)
            safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
            if step_rejected and error_norm > 1:
                d = rhs(t, y + error, p, z)
                nfev += 1
                if z.size > 0 and z[z.size - 1] != 0.0:
                    return (MODEL_FAILED, states, obs, filled, accepted, rejected, nfev, t,
                            y + error, fired, h_abs, njev)
                for j in range(n):
                    error[j] = d[j] + ZE[j]
                solve_in_order(real, kl, ku, pivots_real, order, error, work)
                error_norm = rms(error / scale)
            if error_norm > 1:
                factor = predict_factor(h_abs, step_h_old, error_norm, step_error_old)
                h_abs *= max(MIN_FACTOR, safety * factor)
                factored = False
                step_rejected = True
                rejected += 1
                continue
            break
        accepted += 1

        # Step 4: the next step size, the derivative and (if slow to converge) Jacobian.
        recompute_jac = n_iter > 2 and rate > 1e-3
        factor = min(MAX_FACTOR, safety * predict_factor(h_abs, step_h_old, error_norm,
                                                           step_error_old))
        if not recompute_jac and factor < 1.2:
            factor = 1.0
        else:
            factored = False
        f = rhs(t_new, y_new, p, z)
        nfev += 1
        status = verdict(f, z)
        if status != SUCCESS:
            return (status, states, obs, filled, accepted, rejected, nfev, t_new,
                    y_new.copy(), fired, h_abs, njev)
        if recompute_jac:
            J = jac(t_new, y_new, p, z)
            njev += 1
            status = verdict(J, z)
            if status != SUCCESS:
                return (status, states, obs, filled, accepted, rejected, nfev, t_new,
                        y_new.copy(), fired, h_abs, njev)
            current_jac = True
        else:
            current_jac = False
        h_abs_old, error_norm_old = h_proposed, error_norm
        h_abs = h_abs * factor
        y_old[:] = y
        t_old, h_dense = t, h
        dense_coefficients(Z, Q)
        have_dense = True

        # Step 5: the earliest crossing in (t, t_new], by bisection on the dense output.
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
                dense_state(Q, y_old, (middle - t) / h, work)
                if crossings(g_start, crossing(middle, work, p, z), signs, directions,
                             trial):
                    high = middle
                    fired[:] = trial
                else:
                    low = middle
            t_event = high
            if high < t_new:
                dense_state(Q, y_old, (high - t) / h, y_new)

        # Step 6: the output times in (t, t_new] (before an event: in (t, t_event)).
        stops = event or t_new == t_stop < t_end
        while filled < m and (grid[filled] < t_event
                              or (grid[filled] == t_event and not stops)):
            if grid[filled] == t_new:
                states[filled] = y_new
            else:
                dense_state(Q, y_old, (grid[filled] - t) / h, states[filled])
            if n_observed > 0:
                obs[filled] = observed(grid[filled], states[filled], p, z)
                if z.size > 0 and z[z.size - 1] != 0.0:
                    return (MODEL_FAILED, states, obs, filled, accepted, rejected, nfev,
                            grid[filled], states[filled].copy(), fired, h_abs, njev)
            filled += 1
        if event:
            return (STATE_EVENT, states, obs, filled, accepted, rejected, nfev, t_event,
                    y_new.copy(), fired, h_abs, njev)
        t = t_new
        y[:] = y_new
        g_start = g_end
    final = TIME_EVENT if limit < t_end else SUCCESS
    return final, states, obs, filled, accepted, rejected, nfev, t, y.copy(), fired, h_abs, njev
