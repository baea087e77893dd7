"""The global error a run reached on its output grid: two results -> :class:`ErrorEstimate`.

A run is compared with a *companion* run of the same model and start (:mod:`.error_control`
runs it): an adaptive run with one at a tolerance
:data:`.error_rules.COMPANION_FACTOR` times tighter (``dop853``, or the run's own
implicit method), whose error is then about a thousandth
of the run's, so ``|x_run - x_companion|`` is the run's error; a fixed-step run of order
``q`` with the same method at half the step (Richardson:
``error ~ (x_h - x_h/2) 2^q / (2^q - 1)``).

The comparison is per output variable (states and observed variables alike), at the
output times both runs reached, never at the extra rows ``event_rows`` adds. A hybrid
run and its companion locate the same state event at slightly different times; an
output time between the two (widened by their distance on both sides) compares values
of two different modes, so it is left out; at every other output time the difference
is the run's error, the effect of its event times included. The event times are one
more quantity of the estimate (:data:`EVENT_TIMES`): their largest shift against the
companion's, on the scale of the largest event time. For each variable: the largest
``|error|``, where it occurs, and that divided by the variable's largest magnitude over
the run (the relative error).
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np

EVENT_TIMES = "(event times)"
"""The estimate's name for the times of a hybrid run's state events."""


class Run(Protocol):
    """What a comparison reads of a run (a ``SimulationResult``)."""

    time: np.ndarray
    names: tuple[str, ...]
    values: np.ndarray
    events: tuple[Any, ...]


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated global error of each output variable over the output grid, and
    (:mod:`.error_control`) the error allowed to each (``tolerance``; None: no rule)."""

    names: tuple[str, ...]
    absolute: np.ndarray  # largest |error| over the grid, per variable
    relative: np.ndarray  # absolute / the variable's largest |value| (1 where that is 0)
    times: np.ndarray  # where the largest |error| occurs, per variable
    method: str  # how it was estimated, in words
    seconds: float  # what estimating cost
    scales: np.ndarray  # the largest |value| of each variable over the run
    tolerance: np.ndarray | None = None  # the error allowed to each variable

    @property
    def worst(self) -> int:
        """The variable furthest from its tolerance (without one: the largest relative
        error); -1 without variables."""
        if not len(self.names):
            return -1
        if self.tolerance is not None:
            return int(np.argmax(self.absolute / self.tolerance))
        return int(np.argmax(self.relative))

    @property
    def error(self) -> float:
        """The largest relative error of any variable (0 without variables)."""
        return float(self.relative.max()) if len(self.relative) else 0.0

    @property
    def met(self) -> bool | None:
        """Whether every variable's error is within its tolerance (None: no rule)."""
        if self.tolerance is None:
            return None
        return bool((self.absolute <= self.tolerance).all())

    def rows(self) -> list[list[str]]:
        """The side file's table: a header, then one row per variable."""
        allowed = self.tolerance if self.tolerance is not None else \
            np.full(len(self.names), np.nan)
        return [["variable", "max_abs_error", "relative_error", "at_time", "method",
                 "tolerance"],
                *([name, repr(float(a)), repr(float(r)), repr(float(t)), self.method,
                   "" if np.isnan(tol) else repr(float(tol))]
                  for name, a, r, t, tol in zip(self.names, self.absolute, self.relative,
                                                self.times, allowed))]


def grid_rows(times: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """The row of each output time in a result's ``times`` (the last row at that time:
    ``event_rows`` puts an event's limits before it), -1 where the run did not reach it."""
    rows = np.searchsorted(times, grid, side="right") - 1
    found = (rows >= 0) & (times[np.maximum(rows, 0)] == grid)
    return np.where(found, rows, -1)


def paired_events(run: Run, companion: Run) -> tuple[np.ndarray, np.ndarray]:
    """The times of the state events of the two runs, paired in order (the shorter
    list's length)."""
    ours = [e.time for e in run.events if e.kind == "state"]
    theirs = [e.time for e in companion.events if e.kind == "state"]
    n = min(len(ours), len(theirs))
    return np.asarray(ours[:n], dtype=float), np.asarray(theirs[:n], dtype=float)


def compare(run: Run, companion: Run, grid: np.ndarray,
            method: str, gain: float, began: float) -> ErrorEstimate:
    """The estimate of ``run``'s error from ``companion`` (see the module docstring);
    ``gain`` multiplies the difference (1, or Richardson's ``2^q / (2^q - 1)``)."""
    ours, theirs = grid_rows(run.time, grid), grid_rows(companion.time, grid)
    keep = (ours >= 0) & (theirs >= 0)
    a, b = paired_events(run, companion)
    for low, high in zip(np.minimum(a, b) - abs(a - b), np.maximum(a, b) + abs(a - b)):
        keep &= ~((grid >= low) & (grid <= high))
    columns = None
    if companion.names != run.names:  # the same selection: the same columns, in order
        where = {name: j for j, name in enumerate(companion.names)}
        columns = np.array([where[n] for n in run.names], dtype=np.intp)
    deferred = getattr(companion, "deferred", None)  # its rows computed as they are read
    differences = _differences(run.values, companion.values, ours[keep], theirs[keep],
                               columns, gain, len(run.names)) if deferred is None else \
        _streamed(run.values, deferred.blocks(), ours[keep], theirs[keep], columns, gain)
    estimate = measured(run.names, grid[keep], *differences, method, began)
    if not len(a):
        return estimate
    # the event times as one more quantity: their largest shift, on the scale of |t|
    worst = int(np.argmax(abs(a - b) * gain))
    shift, scale = float(abs(a - b)[worst] * gain), float(np.abs(a).max())
    return replace(estimate, names=(*estimate.names, EVENT_TIMES),
                   absolute=np.append(estimate.absolute, shift),
                   relative=np.append(estimate.relative, shift / scale if scale else shift),
                   times=np.append(estimate.times, a[worst]),
                   scales=np.append(estimate.scales, scale))


COLUMNS_PER_PASS = 1024
"""Output columns compared at a time: the differences of a large scene's runs never
take more than this many columns (the 50x50 cloth's 128,700 columns at once would be
three arrays as large as its result)."""


def _differences(ours: np.ndarray, theirs: np.ndarray, our_rows: np.ndarray,
                 their_rows: np.ndarray, columns: np.ndarray | None, gain: float,
                 width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The scale of each column of ``ours`` (its largest magnitude over every row), and
    the largest magnitude of ``(ours - theirs) * gain`` on the paired rows with the
    index of its row (:func:`.error_rules.largest_differences` on numpy arrays),
    :data:`COLUMNS_PER_PASS` columns at a time (``columns``: the
    columns of ``theirs`` in the order of ``ours``; None: the same; ``width``: the
    number of columns)."""
    scales = np.zeros(width)
    absolute = np.zeros(width)
    rows = np.zeros(width, dtype=np.intp)
    for begin in range(0, width, COLUMNS_PER_PASS):
        end = min(begin + COLUMNS_PER_PASS, width)
        mine = ours[:, begin:end]
        other = theirs[:, begin:end] if columns is None else theirs[:, columns[begin:end]]
        if len(mine):
            scales[begin:end] = np.abs(mine).max(axis=0)
        if len(our_rows):
            error = np.abs((mine[our_rows] - other[their_rows]) * gain)
            absolute[begin:end] = error.max(axis=0)
            rows[begin:end] = error.argmax(axis=0)
    return scales, absolute, rows


def _streamed(ours: np.ndarray, blocks: Iterable[np.ndarray], our_rows: np.ndarray,
              their_rows: np.ndarray, columns: np.ndarray | None, gain: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_differences` with the companion's rows read block by block, in order
    (``blocks``: a deferred run's, never all of them at once; ``their_rows`` in
    increasing order): the same differences, and per column the largest with the first
    row where it occurs (NaN, as ``max`` and ``argmax`` take it, first)."""
    absolute = rows = None
    end = 0
    for block in blocks:  # every block is read: a failing row raises its error
        begin, end = end, end + len(block)
        lo, hi = (int(k) for k in np.searchsorted(their_rows, [begin, end]))
        if hi == lo:
            continue
        theirs = block[their_rows[lo:hi] - begin]
        error = ours[our_rows[lo:hi]]
        error -= theirs if columns is None else theirs[:, columns]
        error *= gain
        np.abs(error, out=error)
        top, where = error.max(axis=0), error.argmax(axis=0) + lo
        if absolute is None or rows is None:
            absolute, rows = top, where
            continue
        better = (top > absolute) | (np.isnan(top) & ~np.isnan(absolute))
        absolute, rows = np.where(better, top, absolute), np.where(better, where, rows)
    if absolute is None or rows is None:
        absolute, rows = np.zeros(ours.shape[1]), np.zeros(ours.shape[1], dtype=np.intp)
    return _scales(ours), absolute, rows


def _scales(ours: np.ndarray) -> np.ndarray:
    """The largest magnitude of each column over every row, :data:`COLUMNS_PER_PASS`
    columns at a time."""
    scales = np.zeros(ours.shape[1])
    if len(ours):
        for begin in range(0, ours.shape[1], COLUMNS_PER_PASS):
            scales[begin:begin + COLUMNS_PER_PASS] = np.abs(
                ours[:, begin:begin + COLUMNS_PER_PASS]).max(axis=0)
    return scales


def measured(names: tuple[str, ...], grid: np.ndarray, scales: np.ndarray,
             absolute: np.ndarray, rows: np.ndarray, method: str, began: float
             ) -> ErrorEstimate:
    """The estimate from the largest error of each variable on ``grid`` (``absolute``,
    at the rows ``rows`` of ``grid``), its largest magnitude over the run (``scales``)
    giving the relative error."""
    if not len(grid):
        zero = np.zeros(len(names))
        return ErrorEstimate(names, zero, zero, zero, method, time.perf_counter() - began,
                             scales)
    relative = absolute / np.where(scales > 0, scales, 1.0)
    return ErrorEstimate(names, absolute, relative, grid[rows], method,
                         time.perf_counter() - began, scales)
