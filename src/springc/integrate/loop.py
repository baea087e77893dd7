"""The adaptive step loop, written once: DOP853, RK45, Radau IIA and BDF are this loop
specialised on a method (model functions + output grid + start -> states on the grid).

:func:`adaptive_loop` holds what the adaptive methods share: the start and its outputs,
the initial step (scipy's ``select_initial_step``: :func:`initial_step`), the step-limit
check, the clamp of the step size to ``[10 ulp, max_step]``, the zero crossings (checked
after each accepted step, located by bisection on the method's dense output), the output
times filled from the dense output, and the one result record (``IMPLICIT_RESULT`` of
:mod:`.signatures`: status, states, observed, rows filled, accepted, rejected, rhs
evaluations, stop time, stop state, fired crossings, next step, Jacobian evaluations).

A method is a module of compiled hooks, read through the global name ``method``:

- ``setup(n, layout) -> work``: the method's work arrays (a tuple);
- ``begin(rhs, jac, t, y, f, h_abs, p, z, rtol, work, counts, end) -> (status, t_fail)``:
  after the initial step (``f`` the derivative at the start);
- ``step(rhs, jac, t, y, h_proposed, h_abs, min_step, limit, p, z, rtol, atol, layout,
  work, counts, y_new, end, blas) -> (status, t_new, h, h_abs, t_fail)``: one accepted
  step from ``(t, y)`` (rejections inside), ``h_abs`` clamped from ``h_proposed``; the new
  state in ``y_new``, the next step size out;
- ``prepare_dense(rhs, t, h, y, y_new, p, z, work, counts, end, blas) -> (status, t_fail)``:
  what the dense output of the step needs, only where it is needed;
- ``dense(work, t, h, y, at, out, blas)``: the dense output at time ``at``.

A failing hook leaves the state of the failure in ``end`` and returns its time; the
counters (:data:`.status.COUNTERS`) are updated in place. ``ERROR_ORDER`` of the module is
the order of its error estimator (the initial step's exponent).

:func:`specialize` makes the loop of a method: a copy of :func:`adaptive_loop` whose
globals name that method's module (and ``BLAS``: scipy's summation order, a constant the
compiler prunes on), compiled by numba with ``cache=True`` under a name that carries a
digest of the package's compiled sources, so that an edited hook recompiles (numba keys
its cache on this file's modification time only). The numba types of the model functions
make one loop per method for every model (see :mod:`.signatures`).
"""

from __future__ import annotations

import hashlib
import types as pytypes
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from . import dop853_steps as method
from .arrays import copy, internal
from .crossings import crossings, time_tolerance
from .dop853_steps import flagged, rms, verdict
from .signatures import ImplicitTuple, ModelFunction
from .status import ACCEPTED, COUNTERS, JACOBIAN_CALLS, REJECTED, RHS_CALLS, Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
MAX_STEPS = int(Status.MAX_STEPS)
MODEL_FAILED = int(Status.MODEL_FAILED)
STATE_EVENT = int(Status.STATE_EVENT)
TIME_EVENT = int(Status.TIME_EVENT)
BLAS = None
"""The arithmetic flag the loop hands its hooks: None for plain-loop sums, True for
scipy's (numpy's BLAS calls); each specialisation sets its own. A None argument makes
numba prune the other branch when it compiles (see :func:`.dop853_steps.weighted_sum`)."""

Layout = tuple[np.ndarray, int, int, np.ndarray, np.ndarray]
"""The band of the implicit methods' Newton matrices (``order, kl, ku, positions,
diagonal``: :func:`.banded_lu.band_layout`); the explicit methods ignore it."""


@internal
def initial_step(rhs: ModelFunction, t: float, y: np.ndarray, f: np.ndarray, limit: float,
                 p: np.ndarray, z: np.ndarray, rtol: float, atol: np.ndarray,
                 max_step: float, exponent: float, blas: bool | None, scale: np.ndarray,
                 end: np.ndarray, counts: np.ndarray) -> tuple[int, float, float]:
    """scipy's ``select_initial_step`` (Hairer's algorithm) from ``(t, y)`` with the
    derivative ``f`` there: (status, step size, time of a failed evaluation, whose state
    is left in ``end``). ``exponent``: 1 / (error estimator order + 1)."""
    n = y.size
    interval = limit - t
    for i in range(n):
        scale[i] = atol[i] + abs(y[i]) * rtol
        end[i] = y[i] / scale[i]
    d0 = rms(end, blas)
    for i in range(n):
        end[i] = f[i] / scale[i]
    d1 = rms(end, blas)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, interval)
    for i in range(n):
        end[i] = y[i] + h0 * f[i]
    d = rhs(t + h0, end, p, z)
    counts[RHS_CALLS] += 1
    status = verdict(d, z)
    if status != SUCCESS:
        return status, 0.0, t + h0
    for i in range(n):
        scale[i] = (d[i] - f[i]) / scale[i]
    d2 = rms(scale, blas) / h0
    h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 \
        else (0.01 / max(d1, d2)) ** exponent
    h_abs = min(100 * h0, h1, interval, max_step)
    if not h_abs > 0.0:  # underflowed (or NaN) at extreme values: no step
        copy(end, y)
        return STEP_TOO_SMALL, h_abs, t
    return SUCCESS, h_abs, t


def adaptive_loop(rhs: ModelFunction, jac: ModelFunction, observed: ModelFunction,
                  n_observed: int, crossing: ModelFunction, signs: np.ndarray,
                  directions: np.ndarray, grid: np.ndarray, x0: np.ndarray, p: np.ndarray,
                  z: np.ndarray, rtol: float, atol: np.ndarray, max_step: float,
                  first_step: float, max_steps: int, t_stop: float, layout: Layout
                  ) -> ImplicitTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` from ``(grid[0], x0)`` to ``grid[-1]`` with
    ``method`` (``jac``: the Jacobian's non-zeros for the implicit methods).

    ``grid`` increases strictly; ``atol`` has one entry per state; ``first_step`` 0
    selects the initial step as scipy does; ``max_steps`` 0 means no limit (it counts
    accepted and rejected steps). ``observed`` is called at every output time when
    ``n_observed`` > 0. Events: ``crossing`` is called after every accepted step when
    ``signs`` is not empty (see :mod:`.crossings`); the earliest crossing stops the run
    with STATE_EVENT. A ``t_stop`` before ``grid[-1]`` is a time event: a step ends on
    it exactly and the run stops there with TIME_EVENT. Failures return a status code.
    """
    n, m, n_g = x0.size, grid.size, signs.size
    states = np.empty((m, n))
    obs = np.empty((m, n_observed))
    fired = np.zeros(n_g, dtype=np.int64)
    trial = np.zeros(n_g, dtype=np.int64)
    y, y_new, scratch, end = x0.copy(), np.empty(n), np.empty(n), x0.copy()
    counts = np.zeros(COUNTERS, dtype=np.int64)
    t, t_end = grid[0], grid[m - 1]
    limit = min(t_end, t_stop)
    t_fail, h_abs, status, filled = t, 0.0, SUCCESS, 1

    # Step 1: the start, its outputs and the derivative there.
    copy(states[0], y)
    if n_observed > 0:
        copy(obs[0], observed(t, y, p, z))
    g_start = crossing(t, y, p, z) if n_g > 0 and not flagged(z) else np.empty(0)
    if flagged(z):
        status, filled = MODEL_FAILED, 0
    running = status == SUCCESS and m > 1 and n > 0
    if status == SUCCESS and not running:
        for k in range(1, m):
            copy(states[k], y)
        filled = m
    work = method.setup(n, layout)
    if running:
        f = rhs(t, y, p, z)
        counts[RHS_CALLS] += 1
        status = verdict(f, z)

        # Step 2: the initial step, and the method's start.
        if status == SUCCESS:
            if first_step > 0.0:
                h_abs = first_step
            else:
                status, h_abs, t_fail = initial_step(
                    rhs, t, y, f, limit, p, z, rtol, atol, max_step,
                    1.0 / (method.ERROR_ORDER + 1), BLAS, scratch, end, counts)
        if status == SUCCESS:
            status, t_fail = method.begin(rhs, jac, t, y, f, h_abs, p, z, rtol, work,
                                          counts, end)

    # Step 3: steps until the end (or an event), each filling the output times it passes.
    while running and status == SUCCESS and t < limit:
        if max_steps > 0 and counts[ACCEPTED] + counts[REJECTED] >= max_steps:
            status, t_fail = MAX_STEPS, t
            copy(end, y)
            break
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        h_proposed = h_abs
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        status, t_new, h, h_abs, t_fail = method.step(
            rhs, jac, t, y, h_proposed, h_abs, min_step, limit, p, z, rtol, atol, layout,
            work, counts, y_new, end, BLAS)
        if status != SUCCESS:
            break
        counts[ACCEPTED] += 1

        # Step 4: a crossing in (t, t_new]?
        event = False
        g_end = g_start
        if n_g > 0:
            g_end = crossing(t_new, y_new, p, z)
            if flagged(z):
                status, t_fail = MODEL_FAILED, t_new
                copy(end, y_new)
                break
            event = crossings(g_start, g_end, signs, directions, fired)

        # Step 5: the dense output, wherever it is needed.
        if event or (filled < m and grid[filled] <= t_new):
            status, t_fail = method.prepare_dense(rhs, t, h, y, y_new, p, z, work, counts,
                                                  end, BLAS)
            if status != SUCCESS:
                break

        # Step 6: the earliest crossing, by bisection on the dense output.
        t_event = t_new
        if event:
            low, high = t, t_new
            tolerance = time_tolerance(t, t_new)
            while high - low > tolerance:
                middle = low + 0.5 * (high - low)
                if middle <= low or middle >= high:
                    break
                method.dense(work, t, h, y, middle, scratch, BLAS)
                if crossings(g_start, crossing(middle, scratch, p, z), signs, directions,
                             trial):
                    high = middle
                    copy(fired, trial)
                else:
                    low = middle
            t_event = high
            if high < t_new:
                method.dense(work, t, h, y, high, y_new, BLAS)

        # Step 7: the output times in (t, t_new] (before an event: in (t, t_event)).
        stops = event or t_new == t_stop < t_end
        while filled < m and (grid[filled] < t_event
                              or (grid[filled] == t_event and not stops)):
            if grid[filled] == t_new:
                copy(states[filled], y_new)
            else:
                method.dense(work, t, h, y, grid[filled], states[filled], BLAS)
            if n_observed > 0:
                copy(obs[filled], observed(grid[filled], states[filled], p, z))
                if flagged(z):
                    status, t_fail = MODEL_FAILED, grid[filled]
                    copy(end, states[filled])
                    break
            filled += 1
        if status != SUCCESS:
            break
        if event:
            status, t_fail = STATE_EVENT, t_event
            copy(end, y_new)
            break
        t = t_new
        copy(y, y_new)
        g_start = g_end

    # Step 8: the one result record.
    if status == SUCCESS:
        if running and limit < t_end:
            status = TIME_EVENT
        t_fail = t
        copy(end, y)
    return (status, states, obs, filled, counts[ACCEPTED], counts[REJECTED],
            counts[RHS_CALLS], t_fail, end, fired, h_abs, counts[JACOBIAN_CALLS])


def sources_digest() -> str:
    """A digest of the package's compiled sources (every module but the Python side),
    part of each specialised loop's name: numba's cache of a loop made by
    :func:`specialize` is found again exactly while none of them changed."""
    python_side = {"__init__.py", "engine.py", "hybrid.py", "batch.py", "ordering.py",
                   "addresses.py", "kernels.py", "compile_lock.py"}
    digest = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        if path.name not in python_side:
            digest.update(path.name.encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:12]


def specialize(name: str, hooks: pytypes.ModuleType, blas: bool) -> Any:
    """The loop of the method whose hooks are the module ``hooks``: a numba dispatcher
    (cached on disk, compiled at its first :meth:`compile`) named ``name``."""
    namespace = dict(adaptive_loop.__globals__)
    namespace.update(method=hooks, BLAS=True if blas else None)
    function = pytypes.FunctionType(adaptive_loop.__code__, namespace, name)
    function.__qualname__ = f"{name}_{sources_digest()}"
    function.__doc__ = adaptive_loop.__doc__
    return njit(cache=True, error_model="numpy", nogil=True)(function)
