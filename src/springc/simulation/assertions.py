"""``assert(...)`` during a simulation: the generated ``assertions`` function checked
at the start and after every accepted step (section 8.3.7).

A failing ``AssertionLevel.error`` assertion stops the run with ``assertion failed at
t = ...: <message>`` at the ``assert``'s location; one whose condition reads only
parameters fails before the integration starts. A failing ``AssertionLevel.warning``
assertion is reported once on standard error and the run goes on. The scipy engine
and the Python fixed-step integrators check after every step (on scipy, the time of a
failure is then located inside the step on its interpolant, by bisection); the compiled
engine's loops have no Python per step, so its runs are checked at every output time,
and the output interval where one first fails is run again on scipy's loop, which
locates the time as above; runs that switch states are checked at every output time
(:func:`check_trajectory`, on the flat conditions).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TextIO

import numpy as np

from ..errors import SimulationError, Span
from ..ir import expr as x
from ..ir import flat
from .failures import format_time, state_notes


def _span(location: str, width: int) -> Span | None:
    file, _, rest = location.rpartition(":")
    file, _, line = file.rpartition(":")
    try:
        row, column = int(line), int(rest)
    except ValueError:
        return None
    return Span(file, row, column, row, column + width)


class AssertionCheck:
    """The assertions of one run: which failed as warnings already, and the checks."""

    def __init__(self, module: Any, p: np.ndarray, names: tuple[str, ...],
                 stream: TextIO | None = None) -> None:
        self.table: tuple[tuple[str, str, str, bool, int], ...] = tuple(
            getattr(module, "ASSERTIONS", ()))
        self.function = getattr(module, "assertions", None)
        self.p, self.names = p, names
        self.stream = stream if stream is not None else sys.stderr
        self.warned: set[int] = set()
        #: whether any assertion depends on time or the states (checked per step)
        self.varying = any(not row[3] for row in self.table)

    def __bool__(self) -> bool:
        return bool(self.table) and self.function is not None

    def start(self, t: float, x: np.ndarray, z: np.ndarray) -> None:
        """Check every assertion at the start time."""
        self._check(t, x, z, first=True)

    def step(self, t: float, x: np.ndarray, z: np.ndarray, before: float | None = None,
             dense: Callable[[], Any] | None = None) -> None:
        """Check the assertions that depend on time or the states after a step from
        ``before`` to ``t``; ``dense()`` (the step's interpolant) locates where in the
        step a failing condition first fails."""
        if self.varying:
            self._check(t, x, z, first=False, before=before, dense=dense)

    def grid(self, times: np.ndarray, states: np.ndarray, z: np.ndarray,
             locate: Callable[[int], None] | None = None) -> None:
        """Check at every output time (the compiled engine's runs). Where an assertion
        not yet reported fails at row ``k`` (held at ``k - 1``), ``locate(k)`` runs that
        interval again step by step (scipy's loop, whose checks find the time inside a
        step and report it); the output time is reported where it finds nothing."""
        if not self.varying:
            return
        for k, (t, row) in enumerate(zip(times, states)):
            if locate is not None and k > 0 and self._fails(float(t), row, z):
                locate(k)
            self._check(float(t), row, z, first=False)

    def _fails(self, t: float, x: np.ndarray, z: np.ndarray) -> bool:
        """Whether an assertion on time or the states, not yet reported, fails here."""
        held = self._held(t, x, z)
        return held is not None and any(
            not self.table[i][3] and i not in self.warned
            for i in map(int, np.flatnonzero(held == 0.0)))

    def _held(self, t: float, x: np.ndarray, z: np.ndarray) -> np.ndarray | None:
        assert self.function is not None
        try:
            with np.errstate(all="ignore"):
                return np.asarray(self.function(t, np.asarray(x, dtype=float), self.p,
                                                np.array(z)))
        except (ArithmeticError, ValueError):
            return None  # the same computation fails in the step loop, which names it

    def _first_failure(self, i: int, before: float, t: float, dense: Callable[[], Any],
                       z: np.ndarray) -> tuple[float, np.ndarray] | None:
        """The earliest time in ``(before, t]`` (to 1e-12 of the step) where assertion
        ``i`` fails, by bisection on the step's interpolant, and the states there."""
        interpolant = dense()
        lo, hi = before, t
        x_hi = None
        for _ in range(60):
            if hi - lo <= 1e-12 * max(1.0, abs(hi)):
                break
            mid = 0.5 * (lo + hi)
            x_mid = np.asarray(interpolant(mid), dtype=float)
            held = self._held(mid, x_mid, z)
            if held is None:
                return None
            if held[i] == 0.0:
                hi, x_hi = mid, x_mid
            else:
                lo = mid
        return (hi, x_hi) if x_hi is not None else None

    def _check(self, t: float, x: np.ndarray, z: np.ndarray, first: bool,
               before: float | None = None, dense: Callable[[], Any] | None = None) -> None:
        held = self._held(t, x, z)
        if held is None:
            return
        for i in map(int, np.flatnonzero(held == 0.0)):
            message, level, location, constant, width = self.table[i]
            if constant and not first:
                continue
            if before is not None and dense is not None and i not in self.warned:
                found = self._first_failure(i, before, t, dense, z)
                if found is not None:
                    t, x = found
            when = ("before the simulation started" if constant
                    else f"at t = {format_time(t)}")
            if level == "warning":
                if i not in self.warned:
                    self.warned.add(i)
                    self.stream.write(f"{location}: warning: assertion failed {when}: "
                                      f"{message}\n")
                continue
            notes = () if constant else state_notes(self.names, np.asarray(x), None)
            # not a solver failure (Stop): no other solver is tried
            raise SimulationError(f"assertion failed {when}: {message}",
                                  _span(location, width),
                                  notes, hint="the model left the range its author "
                                  "allowed; check the parameters (--set) and start values")


def check_trajectory(assertions: Sequence[flat.Assertion], times: np.ndarray,
                     values: Mapping[str, np.ndarray], parameters: Mapping[str, float],
                     stream: TextIO | None = None) -> None:
    """Check flat ``assertions`` at every output time of a run that has no generated
    ``assertions`` function (a run that switches states): ``values[name][k]`` holds the
    variables at ``times[k]``. A condition reading what the run does not record (a
    derivative) is skipped."""
    out = stream if stream is not None else sys.stderr
    warned: set[int] = set()
    for k, t in enumerate(times):
        env: dict[str, object] = dict(parameters)
        env.update((name, float(column[k])) for name, column in values.items())
        for i, item in enumerate(assertions):
            try:
                held = x.evaluate(item.condition, env, float(t))
            except (KeyError, ArithmeticError, ValueError):
                continue
            if held:
                continue
            location = str(item.span)
            if item.level == "warning":
                if i not in warned:
                    warned.add(i)
                    out.write(f"{location}: warning: assertion failed at t = "
                              f"{format_time(float(t))}: {item.message}\n")
                continue
            raise SimulationError(f"assertion failed at t = {format_time(float(t))}: "
                                  f"{item.message}",
                                  _span(location, item.span.width(len("assert"))),
                                  hint="the model left the range its author allowed; "
                                  "check the parameters (--set) and start values")
