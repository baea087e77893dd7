"""An ensemble, compiled: model functions + a parameter matrix -> per-run summaries.

Every row of ``P`` (and of ``X0``, ``Z``) is one run: :func:`ensemble_run` integrates
the runs in a ``numba.prange`` loop over the rows, each by :func:`.dop853_kernel.dop853_run`
(the same steps, error control and dense output as a single compiled DOP853 run) with
its own adaptive steps and its own status code. A failed run (non-finite derivative
at the smallest step, step too small, too many steps, the model's failure flag) writes
its status and NaN summaries and never stops the others; a non-finite stage with room
for a shorter step only rejects its attempt, as in ``ensemble_dop853.c``.

Per run and chosen column (an index into ``[states | observed]`` on the output grid):
the final value, the minimum, the maximum, the time-weighted mean (the trapezoidal
rule on the output grid divided by its length; the value itself on a one-point grid)
and the first output time where the maximum is reached. Each run writes only its own
rows of the outputs and no value is reduced across runs, so the results are the same
bytes whatever the number of threads.

numba keys its disk cache on this file's modification time only: touch this file after
editing ``dop853_kernel`` or ``status``.
"""

import numpy as np
from numba import njit, prange, types

from .dop853_kernel import dop853_run
from .signatures import INDICES, MATRIX, MODEL_FUNCTION, VECTOR, ModelFunction
from .status import Status

SUCCESS = int(Status.SUCCESS)
STATISTICS = ("final", "min", "max", "mean", "argmax")
"""The summaries of a chosen column, in the order of the kernel's ``summary`` axis 2."""

@njit(cache=True, error_model="numpy", nogil=True)
def summarise(grid: np.ndarray, states: np.ndarray, obs: np.ndarray, columns: np.ndarray,
             out: np.ndarray) -> None:
    """``out[c] = final, min, max, mean, argmax`` of each chosen column ``columns[c]``."""
    m, n = grid.size, states.shape[1]
    span = grid[m - 1] - grid[0]
    for c in range(columns.size):
        j = columns[c]
        first = states[0, j] if j < n else obs[0, j - n]
        low, high, t_high, area, previous = first, first, grid[0], 0.0, first
        for k in range(1, m):
            value = states[k, j] if j < n else obs[k, j - n]
            if value < low:
                low = value
            if value > high:
                high, t_high = value, grid[k]
            area += 0.5 * (value + previous) * (grid[k] - grid[k - 1])
            previous = value
        out[c, 0] = previous
        out[c, 1] = low
        out[c, 2] = high
        out[c, 3] = area / span if m > 1 else first
        out[c, 4] = t_high


@njit(cache=True, error_model="numpy", nogil=True)
def keep_rows(states: np.ndarray, obs: np.ndarray, filled: int, kept: np.ndarray,
              columns: np.ndarray, out: np.ndarray) -> None:
    """``out[s, c]`` = column ``columns[c]`` at output time ``kept[s]`` (rows the run
    filled; the others stay as they are)."""
    n = states.shape[1]
    for s in range(kept.size):
        k = kept[s]
        if k >= filled:
            break
        for c in range(columns.size):
            j = columns[c]
            out[s, c] = states[k, j] if j < n else obs[k, j - n]


@njit(types.void(MODEL_FUNCTION, MODEL_FUNCTION, types.int64, MODEL_FUNCTION, VECTOR, MATRIX,
                 MATRIX, MATRIX, types.float64, VECTOR, types.float64, types.int64, INDICES,
                 MATRIX, types.float64[:, :, ::1], INDICES, types.int64[:, ::1], VECTOR,
                 INDICES, INDICES, types.float64[:, :, ::1]),
      cache=True, error_model="numpy", nogil=True, parallel=True)
def ensemble_run(rhs: ModelFunction, observed: ModelFunction, n_observed: int,
                 no_crossing: ModelFunction, grid: np.ndarray, X0: np.ndarray,
                 P: np.ndarray, Z: np.ndarray, rtol: float, atol: np.ndarray,
                 max_step: float, max_steps: int, columns: np.ndarray, finals: np.ndarray,
                 summary: np.ndarray, status: np.ndarray, counts: np.ndarray,
                 failure_time: np.ndarray, traj_columns: np.ndarray, kept: np.ndarray,
                 traj: np.ndarray) -> None:
    """Integrate run ``r`` from ``(grid[0], X0[r])`` with parameters ``P[r]`` and work
    array ``Z[r]`` (copied) for every row ``r``, in parallel over the rows.

    Writes, per run: ``finals[r]`` (the states at the end, or where the run failed),
    ``summary[r, c]`` (:data:`STATISTICS` of ``columns[c]``; NaN unless the run
    succeeded), ``status[r]`` (a :class:`Status`), ``counts[r]`` (accepted steps,
    rejected steps, right-hand-side evaluations, and the failure flag ``z[-1]`` as an
    integer), ``failure_time[r]`` (the end time, or where the run failed) and
    ``traj[r, s, c]``: column ``traj_columns[c]`` at output time ``kept[s]`` (where the
    run got there).
    ``no_crossing`` is any model function (no crossings are located).
    """
    runs = P.shape[0]
    empty = np.empty(0)
    for r in prange(runs):
        z = Z[r].copy()
        result = dop853_run(rhs, observed, n_observed, no_crossing, empty, empty, grid,
                            X0[r].copy(), P[r].copy(), z, rtol, atol, max_step, 0.0,
                            max_steps, False, np.inf)
        code = result[0]
        status[r] = code
        counts[r, 0] = result[4]
        counts[r, 1] = result[5]
        counts[r, 2] = result[6]
        counts[r, 3] = int(z[z.size - 1]) if z.size > 0 else 0
        failure_time[r] = result[7]
        finals[r] = result[8]
        if traj_columns.size > 0:
            keep_rows(result[1], result[2], result[3], kept, traj_columns, traj[r])
        if code == SUCCESS:
            summarise(grid, result[1], result[2], columns, summary[r])
        else:
            summary[r] = np.nan
