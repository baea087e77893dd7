"""The observed variables at a run's output rows, each one a solution of the model's
equations at its row: generated module + times, states (and each row's ``z``) ->
observed values.

A torn nonlinear system (Newton on its tearing variables) starts from the warm start
in the first ``len(GUESSES)`` slots of ``z``. The right-hand side keeps those slots
from call to call, so during a run each Newton iteration starts from the solution at
the last step, a few microseconds away. An output row evaluated with another warm
start may not converge: a row of a hybrid run once took the ``z`` of its kernel run's
end (0.05 s later, on the other half-wave of a Zener clamp), and its Newton iteration
stopped after 50 steps 1e10 away from the solution; the row was written as it was
(``CL.i`` 5.3e5 A where ``C*der(CL.v)`` is 3e-5 A). So here:

- the rows are solved in time order, each warm started from the previous row's
  solution, whatever ``z`` its row carries (its discrete or delay slots are its own);
- a row whose Newton iteration does not converge is solved again by continuation
  from the previous row: its time and states reached in 2, 4, ...,
  ``2**CONTINUATION_LEVELS`` equal steps, each warm started from the step before;
- a row that still does not converge is never written: the run stops with the
  nonlinear-system error at its time (the failure flag, ``z[-1]``, is always checked).

:func:`observed_on_rows` serves continuous runs (on the compiled grid kernel, with one
``z``), :func:`observed_at_rows` runs whose rows each carry their own ``z`` (hybrid
models, delays).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .compiled import observed_on_grid
from .steps import Problem, warm_slots

CONTINUATION_LEVELS = 8
"""At most 2**8 = 256 steps of continuation from the previous row to a failing one."""

_ERRORS = (ArithmeticError, ValueError, np.linalg.LinAlgError)


def continuation(module: Any, p: np.ndarray, before: tuple[float, np.ndarray, np.ndarray],
                 t: float, x: np.ndarray, z: np.ndarray) -> np.ndarray | None:
    """The observed row at ``(t, x)`` reached from the solved row ``before`` (its time,
    states and warm starts) in ever more equal steps (see the module docstring), with
    the other slots of ``z`` throughout; on success ``z`` holds the row's warm starts
    and a clear flag. None where no path of at most ``2**CONTINUATION_LEVELS`` steps
    converges (``z`` unchanged)."""
    n = warm_slots(module)
    t0, x0, w0 = before
    for level in range(1, CONTINUATION_LEVELS + 1):
        steps = 2 ** level
        work = z.copy()
        work[:n] = w0
        row = None
        for k in range(1, steps + 1):
            s = k / steps
            work[-1] = 0.0
            try:
                row = np.asarray(module.observed(t0 + s * (t - t0), x0 + s * (x - x0), p,
                                                 work))
            except _ERRORS:
                row = None
            if row is None or work[-1] != 0.0:
                row = None
                break
        if row is not None:
            z[:] = work
            return row
    return None


def observed_at_rows(module: Any, problem: Problem, times: np.ndarray, states: np.ndarray,
                     zs: np.ndarray, keep: bool = False) -> np.ndarray:
    """The observed variables at every row ``(times[i], states[i], zs[i])``, rows in
    time order, each warm started from the row before (see the module docstring);
    raises the located error of an expression, or the nonlinear-system error of a row
    that does not converge. ``keep``: each row's solved warm starts are written into
    ``zs[i]`` (for later evaluations at the row: the assertions)."""
    n = warm_slots(module)
    p = problem.p
    out = np.empty((len(times), len(module.OBSERVED)))
    before: tuple[float, np.ndarray, np.ndarray] | None = None
    for i in range(len(times)):
        t, x = float(times[i]), states[i]
        z = np.array(zs[i], dtype=float)
        if before is not None:
            z[:n] = before[2]
        z[-1] = 0.0
        try:
            row: np.ndarray | None = np.asarray(module.observed(t, x, p, z))
        except _ERRORS as err:
            raise problem.fail(err, t, x, "an observed variable") from err
        if z[-1] != 0.0:
            flag = z[-1]
            row = continuation(module, p, before, t, x, z) if before is not None else None
            if row is None:
                problem.z[-1] = flag
                raise problem.newton_failure(t, x)
        out[i] = row
        before = (t, x, z[:n].copy())
        if keep:
            zs[i, :n] = z[:n]
    return out


ROWS_PER_CALL = 16
"""Output rows computed per call of the grid loop: the observed values of a large scene
go straight into the result, through a buffer of this many rows (the 50x50 cloth's
120,000 observed variables: 15 MB), never a second array of every row."""


def observed_on_rows(module: Any, ts: np.ndarray, states: np.ndarray, p: np.ndarray,
                     z: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """:func:`.compiled.observed_on_grid` (one ``z`` carried from row to row), with each
    row whose Newton iteration does not converge solved again by continuation from the
    row before; from the first row that still does not, the rows are NaN and ``z[-1]``
    holds the failure flag, as ``observed_on_grid`` leaves them. The rows are written
    into ``out`` (a view of the result's observed columns, for example) where given."""
    n = warm_slots(module)
    if out is None:
        out = np.empty((len(ts), len(module.OBSERVED)))
    k = 0
    while k < len(ts):
        start = z.copy()
        _fill(module, ts, states, p, z, out, k)
        if z[-1] == 0.0:
            break
        failed = k + int(np.flatnonzero(np.isnan(out[k:]).all(axis=1))[0])
        if failed == 0:
            break
        before = start.copy()  # the warm starts of row failed - 1: solved again
        if failed - 1 >= k:
            observed_on_grid(module, ts[k:failed], states[k:failed], p, before)
        flag, retry = z[-1], before.copy()
        row = continuation(module, p, (float(ts[failed - 1]), states[failed - 1],
                                       before[:n].copy()),
                           float(ts[failed]), states[failed], retry)
        if row is None:
            z[-1] = flag
            break
        out[failed] = row
        z[:] = retry
        k = failed + 1
    return out


def _fill(module: Any, ts: np.ndarray, states: np.ndarray, p: np.ndarray, z: np.ndarray,
          out: np.ndarray, k: int) -> None:
    """Rows ``k:`` of ``out`` from the grid loop, :data:`ROWS_PER_CALL` at a time with
    ``z`` carried over (the same rows as one call); after a row that fails (``z[-1]``
    set) the rest are NaN, as one call leaves them."""
    for begin in range(k, len(ts), ROWS_PER_CALL):
        end = min(begin + ROWS_PER_CALL, len(ts))
        out[begin:end] = observed_on_grid(module, ts[begin:end], states[begin:end], p, z)
        if z[-1] != 0.0:
            out[end:] = np.nan
            return
