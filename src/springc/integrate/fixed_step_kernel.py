"""Fixed-step scene integrators, compiled: model function + grid + start -> states on the grid.

The same methods, step rule and arithmetic as ``springc.simulation.integrators`` (the
tests check equality within rounding): each output interval is cut into
``max(1, ceil(span / step - 1e-9))`` equal steps (see :mod:`.fixed_step_methods`).
Compiled once per machine, whatever the model, on first use (:mod:`.kernels`).

Events: after every step the zero-crossing function is checked against the held signs
(:mod:`.crossings`); a crossing is located by bisection on steps of the method itself
from the step's start (a split step), so the event state is the method's own. A time
event ``t_stop`` ends the output interval that holds it there (the interval's steps are
cut to end on it).

numba keys its disk cache on this file's modification time only: the constants taken
from ``fixed_step_methods``, ``crossings``, ``signatures`` and ``status`` are frozen into
the cached code, so touch this file after editing those.
"""

import math

import numpy as np
from numba import njit

from .crossings import crossings, time_tolerance
from .fixed_step_methods import METHOD_CODES, VERLET, advance, verdict
from .signatures import ModelFunction, RunTuple
from .status import Status

__all__ = ["METHOD_CODES", "fixed_step_run"]

SUCCESS = int(Status.SUCCESS)
NON_FINITE_STATE = int(Status.NON_FINITE_STATE)
MODEL_FAILED = int(Status.MODEL_FAILED)
STATE_EVENT = int(Status.STATE_EVENT)
TIME_EVENT = int(Status.TIME_EVENT)


@njit(cache=True, error_model="numpy", nogil=True)  # FIXED_STEP_SIGNATURE, on first use
def fixed_step_run(method: int, rhs: ModelFunction, observed: ModelFunction, n_observed: int,
                   crossing: ModelFunction, signs: np.ndarray, directions: np.ndarray,
                   grid: np.ndarray, x0: np.ndarray, p: np.ndarray, z: np.ndarray, step: float,
                   positions: np.ndarray, velocities: np.ndarray, t_stop: float) -> RunTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` over ``grid`` with ``method`` (a METHOD_CODES
    value) and the nominal ``step``; ``positions[i]``/``velocities[i]`` pair the states
    of the symplectic methods; ``crossing``/``signs``/``directions``/``t_stop`` as for
    ``dop853_run``. Returns ``RUN_RESULT`` (no rejected steps)."""
    n, m, n_g = x0.size, grid.size, signs.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    x, x_new = x0.copy(), np.empty(n)
    fired = np.zeros(n_g, dtype=np.int64)
    trial = np.zeros(n_g, dtype=np.int64)
    d = np.empty(n)
    have_d = False  # verlet: d holds the derivative at the current x
    steps, nfev = 0, 0
    t_end = grid[m - 1]
    states[0] = x
    if n_observed > 0:
        obs[0] = observed(grid[0], x, p, z)
        if z.size > 0 and z[z.size - 1] != 0.0:
            return MODEL_FAILED, states, obs, 0, 0, 0, 0, grid[0], x.copy(), fired, step
    g_start = crossing(grid[0], x, p, z) if n_g > 0 else np.empty(0)
    for k in range(1, m):
        end = grid[k]
        time_event = grid[k - 1] < t_stop <= end and t_stop < t_end
        if time_event:
            end = t_stop
        span = end - grid[k - 1]
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
                    return status, states, obs, k, steps, 0, nfev, t, x.copy(), fired, step
            # Step 2: the method's step.
            status, used, d_end, t_fail = advance(method, rhs, t, x, d, h, p, z, positions,
                                                  velocities, x_new)
            nfev += used
            if status != SUCCESS:
                return status, states, obs, k, steps, 0, nfev, t_fail, x_new.copy(), fired, step
            steps += 1
            # Step 3: a crossing in (t, t + h]? Located on split steps from (t, x).
            if n_g > 0:
                g_end = crossing(t + h, x_new, p, z)
                if crossings(g_start, g_end, signs, directions, fired):
                    low, high = 0.0, h
                    tolerance = time_tolerance(t, t + h)
                    while high - low > tolerance:
                        middle = low + 0.5 * (high - low)
                        if middle <= low or middle >= high:
                            break
                        status, used, _, t_fail = advance(method, rhs, t, x, d, middle, p,
                                                          z, positions, velocities, x_new)
                        nfev += used
                        if status != SUCCESS:
                            return (status, states, obs, k, steps, 0, nfev, t_fail,
                                    x_new.copy(), fired, step)
                        if crossings(g_start, crossing(t + middle, x_new, p, z), signs,
                                     directions, trial):
                            high = middle
                            fired[:] = trial
                        else:
                            low = middle
                    if high < h:
                        _, used, _, _ = advance(method, rhs, t, x, d, high, p, z, positions,
                                                velocities, x_new)
                        nfev += used
                    # t += h may have rounded past the output time that ends the interval
                    return (STATE_EVENT, states, obs, k, steps, 0, nfev, min(t + high, end),
                            x_new.copy(), fired, step)
                g_start = g_end
            x[:] = x_new
            if method == VERLET:
                d = d_end
                have_d = True
            t += h
        # Step 4: the state at the output time (or the time event), checked.
        for value in x:
            if not math.isfinite(value):
                return NON_FINITE_STATE, states, obs, k, steps, 0, nfev, end, x.copy(), fired, step
        if time_event:
            return TIME_EVENT, states, obs, k, steps, 0, nfev, end, x.copy(), fired, step
        states[k] = x
        if n_observed > 0:
            obs[k] = observed(grid[k], x, p, z)
            if z.size > 0 and z[z.size - 1] != 0.0:
                return MODEL_FAILED, states, obs, k, steps, 0, nfev, grid[k], x.copy(), fired, step
    return SUCCESS, states, obs, m, steps, 0, nfev, grid[m - 1], x.copy(), fired, step
