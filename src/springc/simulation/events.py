"""The event loop of a hybrid model: generated module (with ``EVENTS``) + start state
-> states on the output grid, the discrete values there, and the events.

Between events the integrator sees a smooth right-hand side: every relation keeps the
value of the last event (held in ``z``, see codegen/event_layout.py). After each
accepted step the zero-crossing functions are checked against the held relations; a
relation that would now differ is a state event, located on the step's dense output
(or, for the fixed-step integrators, by bisection of the step) to
:data:`LOCATE_TOLERANCE` relative, taking the first time at which the relation has
switched. Time events (``time >= t0``, ``sample``) end the integration exactly at
their time (the solver's ``t_bound``, or a split fixed step). At every event the
module's ``event_update`` runs the event iteration, and the integration restarts.

Chattering and Zeno behaviour (a ball coming to rest, a relation that switches at
every step) stop the run with an error: at most :data:`EVENT_BURST` events may fall
within :data:`ZENO_FRACTION` of the simulated span.
"""

from __future__ import annotations

import functools
import math
import operator
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from ..errors import Note, SimulationError
from .failures import Stop, format_time
from .limits import OverLimit
from .solver_names import IMPLICIT_SOLVERS, SOLVERS
from .steps import Problem, solver_failure

LOCATE_TOLERANCE = 1e-12
"""Times within this times max(1, |t|) are the same event time (a time event and a state
event, the end of a split step)."""
LOCATE_RELATIVE = 1e-12
"""State events are located to a bracket this times max(|t|, step) wide (at least four
rounding units of ``t``), as the compiled engine's kernels
(:func:`springc.integrate.crossings.time_tolerance`): relative to the time, not to
max(1, |t|), so that a model on a nanosecond scale (NandGate's 1 ns edges) gets its
events to 1e-12 of its own scale, not 1e-12 s late."""
STEP_PROBES = 3
"""Inner points of each accepted step where the relations are checked too."""
EVENT_BURST = 100
ZENO_FRACTION = 1e-6
"""More than EVENT_BURST events within ZENO_FRACTION x (stop - start) is chattering."""


def _bracket_width(ta: float, tb: float) -> float:
    """The bracket width at which a state event in ``(ta, tb]`` counts as located."""
    width = LOCATE_RELATIVE * max(abs(ta), abs(tb), tb - ta)
    return max(width, 4.0 * (math.nextafter(abs(tb), math.inf) - abs(tb)))


_OPS: dict[str, Callable[[float, float], bool]] = {
    "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}


@dataclass(frozen=True)
class Event:
    """An event: its time, ``state`` or ``time`` (``initial`` at the start), what
    caused it, and the states and ``z`` just before and after it."""

    time: float
    kind: str
    cause: str
    x_left: np.ndarray
    z_left: np.ndarray
    x_right: np.ndarray
    z_right: np.ndarray


KEPT_EVENTS = 10_000
"""Events (and step times) a run keeps for its result unless the output needs every
event (``event_rows``): the others are counted, so that memory follows the output grid,
not the number of events (``sample(0, 1e-6)`` over 10 s has 10 million)."""


class EventLoop:
    """One hybrid run over ``grid``: fills ``states`` and ``zs`` (the ``z`` vector
    in force at each output time), counts the events by kind (``counts``) and records
    the first :data:`KEPT_EVENTS` of them (``events``; all with ``keep_events``)."""

    def __init__(self, problem: Problem, grid: np.ndarray, keep_events: bool = False) -> None:
        self.problem, self.grid = problem, grid
        self.mod: Any = cast(Any, problem.mod)  # a hybrid module (codegen.module_api.HybridModule)
        self.p = problem.p
        self.z = problem.z  # the module's rhs reads the held values from here
        n = len(problem.names)
        self.states = np.empty((len(grid), n))
        self.zs = np.empty((len(grid), len(self.z)))
        self.k = 0  # next grid row to fill
        self.events: list[Event] = []
        self.keep_events = keep_events
        self.counts: dict[str, int] = {}
        self.last_event: Event | None = None
        self.steps = 0
        self.step_times: list[float] = []
        self.recent: deque[float] = deque(maxlen=EVENT_BURST)
        self.causes: deque[str] = deque(maxlen=EVENT_BURST)
        self.ops = [_OPS[op] for op in self.mod.RELATION_OPS]
        self.first = int(self.mod.Z_RELATIONS)
        self.stopped: tuple[float, str] | None = None  # terminate(): time, message

    # ---------------------------------------------------------------- checks

    def switched(self, t: float, x: np.ndarray) -> list[int]:
        """The state relations whose value at ``(t, x)`` differs from the held one."""
        if not self.ops:
            return []
        g = self.mod.zero_crossings(t, x, self.p, self.z)
        held = self.z[self.first:self.first + len(self.ops)]
        return [k for k, op in enumerate(self.ops) if op(float(g[k]), 0.0) != (held[k] != 0.0)]

    def first_switch(self, dense: Callable[[float], np.ndarray], ta: float, tb: float,
                     y: np.ndarray) -> tuple[float, list[int]]:
        """The relations switched at the first of :data:`STEP_PROBES` inner points
        of the step ``(ta, tb]`` (on its dense output) where some have, else at its
        end (``y`` at ``tb``): a relation that switches and switches back within
        one long step (a clutch's torque dipping under its breakaway limit while
        its states hardly move) is an event too, and it may come before another
        that has switched at the end. Returns that time and the relations."""
        if not self.ops:
            return tb, []
        for j in range(1, STEP_PROBES + 1):
            tm = ta + (tb - ta) * j / (STEP_PROBES + 1)
            switched = self.switched(tm, np.asarray(dense(tm), dtype=float))
            if switched:
                return tm, switched
        return tb, self.switched(tb, y)

    def locate(self, state: Callable[[float], np.ndarray], ta: float, tb: float,
               k: int) -> float:
        """The first time in ``(ta, tb]`` at which relation ``k`` has switched (to
        :data:`LOCATE_RELATIVE`), by regula falsi with the Illinois rule on its
        zero-crossing function, keeping a bracket. Where the function is exactly 0 at
        the bracket's left end (a velocity that starts from rest at the event before:
        a friction's ``v > 0`` after it starts forward) every secant point is that end,
        and halving the other end's value does not move it: the bracket is bisected
        instead (before, the time was the bracket's right end, a whole step late)."""
        op, held = self.ops[k], self.z[self.first + k] != 0.0

        def g(t: float) -> float:
            return float(self.mod.zero_crossings(t, state(t), self.p, self.z)[k])

        ga, gb = g(ta), g(tb)
        side = 0
        tol = _bracket_width(ta, tb)
        for _ in range(200):
            if tb - ta <= tol:
                break
            if math.isfinite(ga) and math.isfinite(gb) and ga != gb and ga != 0.0:
                tm = tb - gb * (tb - ta) / (gb - ga)
            else:
                tm = 0.5 * (ta + tb)
            low, high = ta + 0.01 * (tb - ta), tb - 0.01 * (tb - ta)
            if not low <= tm <= high:
                tm = min(max(tm, ta + tol / 2), tb - tol / 2)
            gm = g(tm)
            if op(gm, 0.0) != held:
                tb, gb = tm, gm
                if side == -1:
                    ga *= 0.5
                side = -1
            else:
                ta, ga = tm, gm
                if side == 1:
                    gb *= 0.5
                side = 1
        return tb

    # ---------------------------------------------------------------- events

    def event(self, t: float, x: np.ndarray, kind: str, cause: str) -> np.ndarray:
        """Run the event iteration at ``t`` and return the states after it."""
        x_left, z_left = np.array(x, dtype=float), self.z.copy()
        try:
            x_right = np.array(self.mod.event_update(t, x_left.copy(), self.p, self.z),
                               dtype=float)
        except (ArithmeticError, ValueError) as err:
            raise self.problem.fail(err, t, x_left, "the event update") from err
        if self.z[-1] != 0.0:
            raise self.problem.newton_failure(t, x_left)
        if self.z[int(self.mod.Z_STATUS)] != 0.0:
            raise Stop(self.unsettled(t, x_left, z_left))
        self.problem.accept()  # the consistent point: the next warm starts
        self.last_event = Event(t, kind, cause, x_left, z_left, x_right, self.z.copy())
        self.counts[kind] = self.counts.get(kind, 0) + 1
        if self.keep_events or len(self.events) < KEPT_EVENTS:
            self.events.append(self.last_event)
        if kind in ("state", "time"):
            self.check_zeno(t, cause)
        code = int(self.z[int(self.mod.Z_TERMINATE)])
        if code > 0 and self.stopped is None:
            self.stopped = (t, self.mod.TERMINATE_MESSAGES[code - 1])
        return x_right

    def note_step(self, t: float) -> None:
        """Record the time of an accepted step (the first :data:`KEPT_EVENTS`)."""
        if self.keep_events or len(self.step_times) < KEPT_EVENTS:
            self.step_times.append(t)

    def unsettled(self, t: float, x: np.ndarray, z_left: np.ndarray) -> SimulationError:
        """The error of an event iteration that does not settle, naming what keeps
        changing (the discrete variables and relations that differ between passes)."""
        z = self.z.copy()
        y = np.array(x)
        moved = np.zeros(len(z), dtype=bool)
        for _ in range(2):  # a cycle of period two shows in either pass
            before = z.copy()
            y = np.asarray(self.mod.event_pass(t, y, self.p, z))
            moved |= z != before
        names = [self.mod.DISCRETE[i] for i, slot in enumerate(self.mod.Z_DISCRETE)
                 if moved[slot]]
        names += [self.mod.ZERO_CROSSINGS[k] for k in range(len(self.ops))
                  if moved[self.first + k]]
        shown = ", ".join(names[:6]) or "the states (reinit)"
        return SimulationError(
            f"the event iteration at time {format_time(t)} did not settle in "
            f"{self.mod.EVENT_ITERATIONS} passes: {shown} keep changing",
            hint="a when-clause or relation feeds back on itself at the same instant; "
                 "use pre(v) for the value before the event")

    def check_zeno(self, t: float, cause: str) -> None:
        self.recent.append(t)
        self.causes.append(cause)
        span = float(self.grid[-1] - self.grid[0])
        if len(self.recent) == EVENT_BURST and t - self.recent[0] <= ZENO_FRACTION * span:
            common = max(set(self.causes), key=list(self.causes).count)
            raise Stop(SimulationError(
                f"chattering: {EVENT_BURST} events in {t - self.recent[0]:.3g} s up to time "
                f"{format_time(t)}, most of them of '{common}'",
                notes=[Note(f"springc stops when more than {EVENT_BURST} events fall within "
                            f"{ZENO_FRACTION:g} of the simulated span (Zeno behaviour)")],
                hint="the model switches faster than it can be simulated: a ball coming to "
                     "rest needs a minimum bounce velocity in its when-condition (when h <= "
                     "0 and v < -v_min), a switched force hysteresis or a smooth "
                     "transition"))

    def initial(self, t: float, x: np.ndarray) -> np.ndarray:
        """The event at the start (``initial()`` is true)."""
        self.z[int(self.mod.Z_INITIAL)] = 1.0
        x = self.event(t, x, "initial", "initial()")
        if getattr(self.mod, "AFTER_INITIAL", False):  # a sample at t, when not initial()
            x = self.event(t, x, "initial", "after initialization")
        return x

    def terminal(self) -> None:
        """The event at the end of a successful run where a when-condition uses
        ``terminal()``: the last row gets its discrete values."""
        if not self.mod.USES_TERMINAL or self.stopped is not None or self.k == 0:
            return
        row = self.k - 1
        self.z[int(self.mod.Z_TERMINAL)] = 1.0
        x = self.event(float(self.grid[row]), self.states[row], "terminal", "terminal()")
        self.states[row], self.zs[row] = x, self.z

    def next_time(self, t: float, x: np.ndarray) -> float:
        """The first time event after ``t`` at the states ``x`` (a sample may start
        at a constant state: a ``fixed = false`` parameter)."""
        return float(self.mod.next_time_event(t, x, self.p, self.z))

    # ---------------------------------------------------------------- output

    def fill(self, until: float, dense: Callable[[np.ndarray], np.ndarray] | None,
             t: float, x: np.ndarray, inclusive: bool) -> None:
        """Grid rows up to ``until`` (included if ``inclusive``) from ``dense`` (at
        ``t`` exactly: ``x``), with the current ``z``."""
        grid = self.grid
        j = int(np.searchsorted(grid, until, side="right" if inclusive else "left"))
        if j <= self.k:
            return
        rows = slice(self.k, j)
        if dense is not None:
            self.states[rows] = np.asarray(dense(grid[rows])).T.reshape(j - self.k, -1)
        else:
            self.states[rows] = x
        exact = grid[rows] == t
        if exact.any():
            self.states[rows][exact] = x
        self.zs[rows] = self.z
        self.k = j

    # ---------------------------------------------------------------- adaptive

    def run_adaptive(self, solver: str, x0: np.ndarray, rtol: float, atol: float,
                     max_steps: int) -> np.ndarray:
        """Integrate with the scipy ``solver`` from ``grid[0]``; returns the states at
        the last time reached."""
        import scipy.integrate

        cls = getattr(scipy.integrate, SOLVERS[solver])
        problem = self.problem
        kwargs: dict[str, Any] = {"jac": problem.jac} if solver in IMPLICIT_SOLVERS else {}
        t, stop = float(self.grid[0]), float(self.grid[-1])
        x = self.initial(t, np.asarray(x0, dtype=float))
        self.fill(t, None, t, x, True)
        while t < stop and self.stopped is None:
            bound = min(self.next_time(t, x), stop)
            if bound <= t:
                bound = stop
            if not len(x):
                t, x = self.stateless_step(t, bound, x, stop)
                continue
            integrator = problem.start(functools.partial(
                cls, problem.rhs, t, x, bound, rtol=rtol, atol=atol, **kwargs), t, x)
            while True:
                t_old = integrator.t
                message = problem.try_step(integrator)
                if integrator.status == "failed":
                    raise Stop(solver_failure(problem, float(integrator.t),
                                              np.asarray(integrator.y), message))
                self.steps += 1
                if self.steps >= max_steps:
                    raise OverLimit(f"{self.steps} steps of {solver} reached the step limit "
                                    f"(--max-steps {max_steps})", float(integrator.t),
                                    np.array(integrator.y), solver)
                t_new = float(integrator.t)
                self.note_step(t_new)
                dense = problem.dense_output(integrator)
                y = np.asarray(integrator.y, dtype=float)
                t_end, switched = self.first_switch(dense, t_old, t_new, y)
                if switched:
                    times = {k: self.locate(dense, t_old, t_end, k)
                             for k in switched}
                    k = min(times, key=times.__getitem__)
                    te = times[k]
                    xe = np.asarray(dense(te), dtype=float)
                    self.fill(te, dense, t_new, y, False)
                    t = te
                    # the event iteration starts from the step's start, not from its
                    # end past the event (on the held branch) nor a location probe
                    problem.restore(problem.step_start)
                    x = self.event(te, xe, "state", self.mod.ZERO_CROSSINGS[k])
                    self.fill(te, None, te, x, True)
                    break
                problem.restore()  # (the relations' probes may have moved them)
                if integrator.status == "finished":
                    self.fill(t_new, dense, t_new, y, False)
                    t, x = float(bound), y
                    x = self.time_event(t, x, stop)
                    break
                self.fill(t_new, dense, t_new, y, True)
        return x

    def stateless_step(self, t: float, bound: float, x: np.ndarray, stop: float
                       ) -> tuple[float, np.ndarray]:
        """Without states: on to the next output time or ``bound``; a relation on
        ``time`` that has switched there is a state event, located on it."""
        j = int(np.searchsorted(self.grid, t, side="right"))
        end = min(bound, float(self.grid[j])) if j < len(self.grid) else bound
        if bound - end <= LOCATE_TOLERANCE * max(1.0, abs(bound)):
            end = bound  # the same time (next_time_event would pass the event by from end)
        switched = self.switched(end, x)
        if switched:
            times = {k: self.locate(lambda _: x, t, end, k) for k in switched}
            k = min(times, key=times.__getitem__)
            self.fill(times[k], None, times[k], x, False)
            x = self.event(times[k], x, "state", self.mod.ZERO_CROSSINGS[k])
            self.fill(times[k], None, times[k], x, True)
            return times[k], x
        if end < bound:
            self.fill(end, None, end, x, True)
            return end, x
        self.fill(bound, None, bound, x, False)
        return bound, self.time_event(bound, x, stop)

    def time_event(self, t: float, x: np.ndarray, stop: float) -> np.ndarray:
        """At the end of an integration: the time event there, if any; the grid row."""
        if t < stop or self.next_time(t - 2 * LOCATE_TOLERANCE * max(1.0, abs(t)), x) == t:
            x = self.event(t, x, "time", f"time = {format_time(t)}")
        self.fill(t, None, t, x, True)
        return x
