"""The event loop of the fixed-step scene integrators (verlet, symplectic-euler, rk4).

Each step runs from ``t`` to ``t + h``; a time event inside it splits the step at
the event time exactly; a state relation that switched during the step is located by
bisection on the step length (the same method over a shorter step) to
:data:`.events.LOCATE_TOLERANCE`, the step is split there, the event runs, and the
rest of the step follows from the states after the event.
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np

from .events import LOCATE_TOLERANCE, EventLoop
from .failures import Stop
from .integrators import STEPPERS, Pairs
from .limits import OverLimit
from .solvers import detect_pairs, non_finite_states


def run_fixed_events(loop: EventLoop, method: str, x0: np.ndarray, step: float) -> None:
    """Fill ``loop``'s grid with the fixed-step ``method`` of step about ``step``."""
    problem = loop.problem
    mod: Any = cast(Any, problem.mod)  # a hybrid module (codegen.module_api.HybridModule)
    advance = STEPPERS[method]
    grid = loop.grid
    t0 = float(grid[0])
    x = loop.initial(t0, np.asarray(x0, dtype=float))
    loop.fill(t0, None, t0, x, True)
    pairs = detect_pairs(problem.mod, problem.p, x, t0) if len(x) else Pairs.of([])
    cache: dict[str, np.ndarray] = {}

    def move(t: float, y: np.ndarray, h: float) -> np.ndarray:
        out: np.ndarray = advance(problem.rhs, t, y, h, pairs, {})
        return out

    limit = problem.limits.max_steps
    for k in range(1, len(grid)):
        a, b = float(grid[k - 1]), float(grid[k])
        n = max(1, int(np.ceil((b - a) / step - 1e-9)))
        h = (b - a) / n
        for i in range(n):
            if loop.stopped is not None:
                return
            end = b if i == n - 1 else a + (i + 1) * h
            t = a + i * h
            while t < end and loop.stopped is None:  # terminate() ends the run there
                te = loop.next_time(t, x)
                # a time event within rounding of the step's end is the step's end
                target = te if te <= end + LOCATE_TOLERANCE * max(1.0, abs(end)) else end
                y = advance(problem.rhs, t, x, target - t, pairs, cache)
                loop.steps += 1
                if loop.steps > limit:
                    raise OverLimit(f"{loop.steps} steps of {method} reached the step limit "
                                    f"(--max-steps {limit})", t, np.array(x), method)
                switched = loop.switched(target, y)
                if switched:
                    times = {j: _bisect(loop, move, t, x, target, j) for j in switched}
                    j = min(times, key=times.__getitem__)
                    t_e = times[j]
                    x = loop.event(t_e, move(t, x, t_e - t), "state",
                                   mod.ZERO_CROSSINGS[j])
                    cache.clear()
                    t = t_e
                    continue
                t, x = target, y
                loop.note_step(t)
                if t == te:  # a time event (at the stop time too, as the adaptive loop)
                    x = loop.event(t, x, "time", f"time = {t:.9g}")
                    cache.clear()
                bad = ~np.isfinite(x)
                if bad.any():
                    raise Stop(non_finite_states(problem, t, np.flatnonzero(bad), step))
        if loop.stopped is not None:
            return
        loop.fill(b, None, b, x, True)


def _bisect(loop: EventLoop, move: object, t: float, x: np.ndarray, end: float, k: int
            ) -> float:
    """The first time in ``(t, end]`` at which relation ``k`` has switched, stepping
    from ``(t, x)`` with the same method over shorter steps."""
    advance = move  # (t, x, h) -> states at t + h
    held = loop.z[loop.first + k] != 0.0
    op = loop.ops[k]
    lo, hi = t, end
    tol = LOCATE_TOLERANCE * max(1.0, abs(end))
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        y = advance(t, x, mid - t)  # type: ignore[operator]
        g = float(loop.mod.zero_crossings(mid, y, loop.p, loop.z)[k])  # loop.mod: Any
        if op(g, 0.0) != held:
            hi = mid
        else:
            lo = mid
    return hi
