"""A hybrid run on the compiled kernels: the kernel stops at each event, Python updates
the state and the held signs, the kernel restarts (the reference driver of the event
interface; springc's simulation wires the generated module's event functions the same way).

Each kernel call integrates from the last event to the next one (or to the end) and
fills the output rows before it; at an event the driver calls
``update(t, x_left, fired) -> (x_right, signs)`` (``fired``: +1/-1/0 per indicator;
``None`` at a time event), stores nothing at the event time itself unless it is an
output time (then the right limit, the value from which the run goes on), and restarts
with a fresh initial step after a state event, with the method's proposed step after a
time event (the solution is smooth across it unless ``update`` changed it).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .engine import Crossings, ModelFunction, Run, dop853, fixed_step
from .status import Status

Update = Callable[[float, np.ndarray, "np.ndarray | None"], tuple[np.ndarray, np.ndarray]]


@dataclass
class HybridRun:
    """States on the grid, the events met (time, fired), and the last kernel run."""

    t: np.ndarray
    states: np.ndarray
    events: list[tuple[float, np.ndarray | None]] = field(default_factory=list)
    last: Run | None = None
    accepted_steps: int = 0
    rhs_evaluations: int = 0

    @property
    def ok(self) -> bool:
        return self.last is not None and self.last.ok


def run_hybrid(rhs: ModelFunction, grid: Any, x0: Any, p: Any, z: np.ndarray,
               crossing: ModelFunction | None, signs: Sequence[float], update: Update, *,
               method: str = "dop853", directions: Sequence[float] | None = None,
               time_events: Sequence[float] = (), max_events: int = 10_000,
               **options: Any) -> HybridRun:
    """Integrate with events on ``method`` (``dop853`` with ``rtol``/``atol`` options, or a
    fixed-step method with ``step``/``pairs``); stops at a failure or after
    ``max_events`` events (the last run's status says which)."""
    grid = np.array(grid, dtype=float)
    states = np.full((grid.size, np.size(x0)), np.nan)
    result = HybridRun(grid, states)
    t, x, k = float(grid[0]), np.array(x0, dtype=float), 0
    held = np.array(signs, dtype=float)
    pending = sorted(float(s) for s in time_events if grid[0] < s < grid[-1])
    first_step: float | None = None
    while True:
        times = np.concatenate(([t], grid[k:][grid[k:] > t]))
        stop = pending[0] if pending else np.inf
        crossings = None if crossing is None else Crossings(crossing, held, directions)
        if method == "dop853":
            run = dop853(rhs, times, x, p, z, crossings=crossings, t_stop=stop,
                         first_step=first_step, **options)
        else:
            run = fixed_step(method, rhs, times, x, p, z, crossings=crossings, t_stop=stop,
                             **options)
        result.last = run
        result.accepted_steps += run.accepted_steps
        result.rhs_evaluations += run.rhs_evaluations
        # the rows of `times` the kernel filled (row 0 is the restart state itself, an
        # output row only when the restart is at an output time)
        skip = 0 if grid[k] == t else 1
        rows = max(run.filled - skip, 0)
        states[k:k + rows] = run.states[skip:skip + rows]
        k += rows
        if not run.event or len(result.events) >= max_events:
            return result
        t = run.event_time
        fired = run.fired.copy() if run.status == Status.STATE_EVENT else None
        while pending and pending[0] <= t:
            pending.pop(0)
        x, held = update(t, np.array(run.event_state), fired)
        x, held = np.array(x, dtype=float), np.array(held, dtype=float)
        result.events.append((t, fired))
        first_step = None if fired is not None else min(run.next_step, grid[-1] - t)
