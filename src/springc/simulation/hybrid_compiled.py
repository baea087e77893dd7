"""The event loop of a hybrid model on the compiled engine: :class:`.events.EventLoop`
(its grid, event iteration, Zeno and terminate checks) driven by the kernels of
:mod:`springc.integrate` (dop853, rk45, radau, bdf, the fixed-step methods) instead of
scipy's step loop.

Each kernel run integrates from the last event with the generated ``zero_crossings``
as its zero-crossing function, the held relations as its signs and the next time event
(``next_time_event``) as its ``t_stop``; it stops at the earliest state event (located
on the method's dense output (or interpolant) or on split fixed steps, to about
1e-12 relative in time, the left limit there), at the time event, or at the end.
On a python module (``--backend python``) the adaptive methods run in the C loop
library instead (:func:`.native.event_run`: the same loop, its crossings and time event
in C, :func:`c_events` says where). Python then runs the same event update as the scipy path
(:meth:`.events.EventLoop.event`) and restarts the kernel from the state after the
event: the adaptive methods with a fresh initial step, as the scipy path starts a new
integrator; the fixed-step methods on the rest of the output interval, cut into equal
steps of at most the nominal one (the scipy path finishes the split step first).

Relations and signs: the kernel holds a sign per zero-crossing function ``g`` (the side
the model assumes); a relation ``g > 0`` or ``g >= 0`` held true is ``+1``, one held
false ``-1``, and the other way round for ``<`` and ``<=``. The kernel fires when ``g``
is strictly on the other side, the scipy path when the relation differs: the two differ
only when ``g`` is exactly 0 at a step's end.

A long stretch without events runs in chunks (:data:`ADAPTIVE_CHUNK` steps,
:data:`~.compiled.FIXED_CHUNK` fixed steps) so that the step and wall-clock limits and
the progress bar are checked between them. ``step_times`` records the steps that end a
kernel run (time events, chunk ends, the stop time), not every step.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np

from .compiled import (
    C_SOLVERS,
    FIXED_CHUNK,
    adaptive_run,
    c_loop_available,
    failure,
    jitted,
    load_kernel,
    time_limit_reached,
)
from .events import LOCATE_TOLERANCE, EventLoop
from .limits import OverLimit
from .native import event_run
from .solver_names import FIXED_STEP
from .solvers import detect_pairs

if TYPE_CHECKING:
    from .steps import Problem

ADAPTIVE_CHUNK = 100_000
"""Steps (accepted and rejected) of one adaptive kernel run between checks of the limits."""
_POSITIVE = (">", ">=")


def held_signs(loop: EventLoop) -> np.ndarray:
    """The kernel's sign of each zero-crossing function from the held relations."""
    mod: Any = loop.mod  # a hybrid module (codegen's HybridModule)
    held = loop.z[loop.first:loop.first + len(loop.ops)] != 0.0
    positive = np.array([op in _POSITIVE for op in mod.RELATION_OPS])
    return np.where(held == positive, 1.0, -1.0)


def c_events(problem: Problem, solver: str) -> bool:
    """Whether a hybrid run of ``solver`` on ``problem``'s module, compiled engine, takes
    the C loop: an adaptive method of the C loop (:data:`.compiled.C_SOLVERS`), a module
    whose functions are not numba's, and the model's loop library (built now where
    needed; a model C cannot spell runs on scipy's loop, as before)."""
    from .native import loop_ready

    return solver in C_SOLVERS and not jitted(problem.mod) and c_loop_available() \
        and loop_ready(problem)


def run_compiled_events(loop: EventLoop, solver: str, x0: np.ndarray, rtol: float,
                        atol: float, step: float | None) -> float:
    """Fill ``loop``'s grid with ``solver`` (one of :data:`.solver_names.COMPILED_SOLVERS`;
    a fixed-step method of nominal ``step``) in the compiled kernels (on a python module:
    the C loop's, :func:`c_events`); returns the seconds spent in them."""
    from springc.integrate import Crossings, Status, fixed_step

    problem, grid = loop.problem, loop.grid
    mod: Any = loop.mod  # a hybrid module (codegen's HybridModule)
    native = not jitted(mod)
    if not native:
        load_kernel(solver)
    limit = problem.limits.max_steps
    t, stop = float(grid[0]), float(grid[-1])
    x = loop.initial(t, np.asarray(x0, dtype=float))
    loop.fill(t, None, t, x, True)
    pairs: list[tuple[int, int]] = []
    rows_per_run = len(grid)
    adaptive = solver not in FIXED_STEP
    if not adaptive:
        assert step is not None
        found = detect_pairs(mod, problem.p, x, t)
        pairs = list(zip(found.positions.tolist(), found.velocities.tolist()))
        per_interval = math.ceil(float(grid[1] - grid[0]) / step) if len(grid) > 1 else 1
        rows_per_run = max(1, FIXED_CHUNK // max(per_interval, 1))
    first_step: float | None = None
    seconds = 0.0
    while t < stop and loop.stopped is None:
        t_event = loop.next_time(t, x)
        t_stop = t_event if t < t_event < stop else math.inf
        last = min(loop.k + rows_per_run, len(grid))
        if last < len(grid) and grid[last - 1] == t_stop:
            last += 1  # a time event at the chunk's end: a TIME_EVENT, not its end
        snapped = not adaptive and snaps(grid, loop.k, t_event)
        if snapped:  # the run ends at the event instead of the output time just before
            last, t_stop = int(np.searchsorted(grid, t_event)), math.inf
        times = np.concatenate(([t], grid[loop.k:last]))
        if snapped:
            times[-1] = t_event
        signs = held_signs(loop) if loop.ops else None
        crossings = None if signs is None or native else Crossings(mod.zero_crossings, signs)
        began = time.perf_counter()
        steps = max(min(ADAPTIVE_CHUNK, limit - loop.steps), 1)
        if native:
            run = event_run(problem, solver, times, x, rtol, atol, first_step,
                            signs, t_stop, steps)
        elif adaptive:
            run = adaptive_run(solver, mod, times, x, problem.p, problem.z, rtol=rtol,
                               atol=atol, first_step=first_step, crossings=crossings,
                               t_stop=t_stop, max_steps=steps)
        else:
            assert step is not None
            run = fixed_step(solver, mod.rhs, times, x, problem.p, problem.z, step=step,
                             pairs=pairs, crossings=crossings, t_stop=t_stop)
        seconds += time.perf_counter() - began
        problem.nfev += run.rhs_evaluations
        problem.njev += run.jacobian_evaluations
        loop.steps += run.accepted_steps
        # kernel row 0 is the restart itself; its rows 1.. are the grid rows from loop.k
        filled = max(run.filled - 1, 0)
        loop.states[loop.k:loop.k + filled] = run.states[1:1 + filled]
        loop.zs[loop.k:loop.k + filled] = loop.z
        loop.k += filled
        first_step = None
        over = loop.steps > limit or (adaptive and loop.steps == limit
                                      and run.status != Status.SUCCESS)
        if over and (run.event or run.status in (Status.SUCCESS, Status.MAX_STEPS)):
            raise OverLimit(f"{loop.steps} steps of {solver} reached the step limit "
                            f"(--max-steps {limit})", run.failure_time,
                            np.array(run.failure_state), solver)
        if run.status == Status.STATE_EVENT:
            t = run.event_time
            k = int(np.flatnonzero(run.fired)[0])
            x = loop.event(t, np.array(run.event_state), "state", mod.ZERO_CROSSINGS[k])
            loop.fill(t, None, t, x, True)
        elif run.status == Status.TIME_EVENT:
            t = run.event_time
            loop.note_step(t)
            x = loop.time_event(t, np.array(run.event_state), stop)
        elif run.status == Status.SUCCESS:
            t, x = float(times[-1]), np.array(run.failure_state)
            loop.note_step(t)
            if t >= stop or snapped:  # the last row again, after its time event
                loop.k -= 1
                x = loop.time_event(t, x, stop)
        elif run.status == Status.MAX_STEPS:  # a chunk's end, within the step limit
            t, x = run.failure_time, np.array(run.failure_state)
            first_step = min(run.next_step, stop - t)  # the same steps go on
        else:
            raise failure(problem, run, solver, step=step or 0.0)
        if t < stop and time.perf_counter() > problem.deadline:
            raise time_limit_reached(problem, run)
        problem.progress.update(t)
    return seconds


def snaps(grid: np.ndarray, k: int, t_event: float) -> bool:
    """Whether a fixed-step run ends at the time event ``t_event`` in place of the output
    time ``grid[j] >= grid[k]`` just before it, within rounding (``0.1 * 3`` after 0.3),
    and that row shows the values after the event, as the scipy engine's fixed-step loop
    (:func:`.events_fixed.run_fixed_events`) does."""
    j = int(np.searchsorted(grid, t_event)) - 1  # grid[j] < t_event
    return j >= k and t_event <= grid[j] + LOCATE_TOLERANCE * max(1.0, abs(grid[j]))

