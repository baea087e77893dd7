"""Fixed-step scene integrators, compiled: model function + grid + start -> states on the grid.

The same methods, step rule and arithmetic as ``springc.simulation.integrators`` (the
tests check equality within rounding): each output interval is cut into
``max(1, ceil(span / step - 1e-9))`` equal steps. ``symplectic-euler`` (kick then drift)
and ``verlet`` (velocity Verlet, reusing the last acceleration) treat the
(position, velocity) index pairs; other states advance with explicit Euler. ``rk4`` is the
classical fourth-order method. Compiled once per machine, whatever the model.

numba keys its disk cache on this file's modification time only: the constants taken
from ``signatures`` and ``status`` are frozen into the cached code, so touch this file
after editing those.
"""

import math

import numpy as np
from numba import njit, types

from .signatures import MODEL_FUNCTION, RUN_RESULT, VECTOR, ModelFunction, RunTuple
from .status import Status

SUCCESS = int(Status.SUCCESS)
NON_FINITE_DERIVATIVE = int(Status.NON_FINITE_DERIVATIVE)
NON_FINITE_STATE = int(Status.NON_FINITE_STATE)
MODEL_FAILED = int(Status.MODEL_FAILED)

#: method codes of :func:`fixed_step_run`
EULER, SYMPLECTIC_EULER, VERLET, RK4 = 0, 1, 2, 3
METHOD_CODES = {"euler": EULER, "symplectic-euler": SYMPLECTIC_EULER, "verlet": VERLET,
                "rk4": RK4}

INDICES = types.int64[::1]


@njit(cache=True, error_model="numpy", nogil=True)
def verdict(d: np.ndarray, z: np.ndarray) -> int:
    """SUCCESS, or why the evaluation that returned ``d`` (and set ``z``) is unusable."""
    if z.size > 0 and z[z.size - 1] != 0.0:
        return MODEL_FAILED
    for value in d:
        if not math.isfinite(value):
            return NON_FINITE_DERIVATIVE
    return SUCCESS


@njit(RUN_RESULT(types.int64, MODEL_FUNCTION, MODEL_FUNCTION, types.int64, VECTOR, VECTOR,
                 VECTOR, VECTOR, types.float64, INDICES, INDICES),
      cache=True, error_model="numpy", nogil=True)
def fixed_step_run(method: int, rhs: ModelFunction, observed: ModelFunction, n_observed: int,
                   grid: np.ndarray, x0: np.ndarray, p: np.ndarray, z: np.ndarray, step: float,
                   positions: np.ndarray, velocities: np.ndarray) -> RunTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` over ``grid`` with ``method`` (a METHOD_CODES
    value) and the nominal ``step``; ``positions[i]``/``velocities[i]`` pair the states
    of the symplectic methods. Returns ``RUN_RESULT`` (no rejected steps)."""
    n, m = x0.size, grid.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    x = x0.copy()
    stage = np.empty(n)
    half = np.empty(velocities.size)
    moved = np.empty(positions.size)
    d = np.empty(n)
    have_d = False  # verlet: d holds the derivative at the current x
    steps, nfev = 0, 0
    states[0] = x
    if n_observed > 0:
        obs[0] = observed(grid[0], x, p, z)
        if z.size > 0 and z[z.size - 1] != 0.0:
            return MODEL_FAILED, states, obs, 0, 0, 0, 0, grid[0], x.copy()
    for k in range(1, m):
        span = grid[k] - grid[k - 1]
        count = max(1, math.ceil(span / step - 1e-9))
        h = span / count
        t = grid[k - 1]
        for _ in range(count):
            # Step 1: the derivative at the start of the step (verlet reuses the last one).
            if method != VERLET or not have_d:
                d = rhs(t, x, p, z)
                nfev += 1
                status = verdict(d, z)
                if status != SUCCESS:
                    return status, states, obs, k, steps, 0, nfev, t, x.copy()
            # Step 2: the method's update of x.
            if method == EULER:
                for i in range(n):
                    x[i] = x[i] + h * d[i]
            elif method == SYMPLECTIC_EULER:
                for i in range(n):
                    stage[i] = x[i] + h * d[i]
                for i in range(positions.size):
                    moved[i] = x[positions[i]] + h * stage[velocities[i]]
                for i in range(positions.size):
                    stage[positions[i]] = moved[i]
                x[:] = stage
            elif method == VERLET:
                for i in range(n):
                    stage[i] = x[i] + h * d[i]
                for i in range(velocities.size):
                    half[i] = x[velocities[i]] + 0.5 * h * d[velocities[i]]
                for i in range(positions.size):
                    stage[positions[i]] = x[positions[i]] + h * half[i]
                for i in range(velocities.size):
                    stage[velocities[i]] = half[i]
                d = rhs(t + h, stage, p, z)
                nfev += 1
                status = verdict(d, z)
                if status != SUCCESS:
                    return status, states, obs, k, steps, 0, nfev, t + h, stage.copy()
                for i in range(velocities.size):
                    stage[velocities[i]] = half[i] + 0.5 * h * d[velocities[i]]
                x[:] = stage
                have_d = True
            else:
                k1 = d
                for i in range(n):
                    stage[i] = x[i] + h / 2 * k1[i]
                k2 = rhs(t + h / 2, stage, p, z)
                status = verdict(k2, z)
                if status != SUCCESS:
                    return status, states, obs, k, steps, 0, nfev + 1, t + h / 2, stage.copy()
                for i in range(n):
                    stage[i] = x[i] + h / 2 * k2[i]
                k3 = rhs(t + h / 2, stage, p, z)
                status = verdict(k3, z)
                if status != SUCCESS:
                    return status, states, obs, k, steps, 0, nfev + 2, t + h / 2, stage.copy()
                for i in range(n):
                    stage[i] = x[i] + h * k3[i]
                k4 = rhs(t + h, stage, p, z)
                nfev += 3
                status = verdict(k4, z)
                if status != SUCCESS:
                    return status, states, obs, k, steps, 0, nfev, t + h, stage.copy()
                for i in range(n):
                    x[i] = x[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
            t += h
        steps += count
        # Step 3: the state at the output time, checked, and the observed variables.
        for value in x:
            if not math.isfinite(value):
                return NON_FINITE_STATE, states, obs, k, steps, 0, nfev, grid[k], x.copy()
        states[k] = x
        if n_observed > 0:
            obs[k] = observed(grid[k], x, p, z)
            if z.size > 0 and z[z.size - 1] != 0.0:
                return MODEL_FAILED, states, obs, k, steps, 0, nfev, grid[k], x.copy()
    return SUCCESS, states, obs, m, steps, 0, nfev, grid[m - 1], x.copy()
