"""``assert(...)`` during a simulation: the generated ``assertions`` function checked
at the start and after every accepted step (section 8.3.7).

A failing ``AssertionLevel.error`` assertion stops the run with ``assertion failed at
t = ...: <message>`` at the ``assert``'s location; one whose condition reads only
parameters fails before the integration starts. A failing ``AssertionLevel.warning``
assertion is reported once on standard error and the run goes on. The scipy engine
and the Python fixed-step integrators check after every step; the compiled engine's
loops have no Python per step, so its runs are checked at every output time.
"""

from __future__ import annotations

import sys
from typing import Any, TextIO

import numpy as np

from ..errors import SimulationError, Span
from .failures import format_time, state_notes


def _span(location: str) -> Span | None:
    file, _, rest = location.rpartition(":")
    file, _, line = file.rpartition(":")
    try:
        row, column = int(line), int(rest)
    except ValueError:
        return None
    return Span(file, row, column, row, column + len("assert"))


class AssertionCheck:
    """The assertions of one run: which failed as warnings already, and the checks."""

    def __init__(self, module: Any, p: np.ndarray, names: tuple[str, ...],
                 stream: TextIO | None = None) -> None:
        self.table: tuple[tuple[str, str, str, bool], ...] = tuple(
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

    def step(self, t: float, x: np.ndarray, z: np.ndarray) -> None:
        """Check the assertions that depend on time or the states after a step."""
        if self.varying:
            self._check(t, x, z, first=False)

    def grid(self, times: np.ndarray, states: np.ndarray, z: np.ndarray) -> None:
        """Check at every output time (the compiled engine's runs)."""
        if self.varying:
            for t, x in zip(times, states):
                self._check(float(t), x, z, first=False)

    def _check(self, t: float, x: np.ndarray, z: np.ndarray, first: bool) -> None:
        assert self.function is not None
        try:
            with np.errstate(all="ignore"):
                held = np.asarray(self.function(t, np.asarray(x, dtype=float), self.p,
                                                np.array(z)))
        except (ArithmeticError, ValueError):
            return  # the same computation fails in the step loop, which names it
        for i in map(int, np.flatnonzero(held == 0.0)):
            message, level, location, constant = self.table[i]
            if constant and not first:
                continue
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
            raise SimulationError(f"assertion failed {when}: {message}", _span(location),
                                  notes, hint="the model left the range its author "
                                  "allowed; check the parameters (--set) and start values")
