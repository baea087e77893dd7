"""The plain-Python arithmetic of the error estimate (:mod:`springc.simulation.error_rules`,
the command line's warm path) against the numpy pass of :mod:`.error_estimate`, and the
rule's numbers against hand-computed values."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from springc.simulation import error_estimate
from springc.simulation.error_rules import (
    FACTOR,
    allowed_errors,
    companion_tolerances,
    largest_differences,
    relative_errors,
    worst_column,
)


def test_largest_differences_equal_the_numpy_pass_row_for_row() -> None:
    rng = np.random.default_rng(7)
    ours = rng.normal(size=(301, 9)) * 10.0 ** rng.integers(-3, 4, size=9)
    theirs = ours + rng.normal(scale=1e-6, size=ours.shape)
    theirs[:, 4] = ours[:, 4]  # a column without error: row 0, error 0
    ours[:, 5] = 0.0  # a column without magnitude
    theirs[[17, 230], 2] = ours[[17, 230], 2] + 1.0  # a tie: the first row wins
    grid = np.linspace(0.0, 3.0, len(ours))
    names = tuple(f"v{j}" for j in range(ours.shape[1]))
    run = SimpleNamespace(time=grid, names=names, values=ours, events=())
    companion = SimpleNamespace(time=grid, names=names, values=theirs, events=())
    estimate = error_estimate.compare(run, companion, grid, "companion", 1.0, 0.0)
    scales, absolute, rows = largest_differences(ours.T.tolist(), theirs.T.tolist())
    assert (scales, absolute) == (estimate.scales.tolist(), estimate.absolute.tolist())
    assert grid[rows].tolist() == estimate.times.tolist()
    assert rows[2] == 17 and absolute[4] == 0.0 and rows[4] == 0
    assert relative_errors(absolute, scales) == estimate.relative.tolist()


def test_the_rule_and_the_companion_in_numbers() -> None:
    assert companion_tolerances(1e-6, 1e-9) == (1e-9, 1e-12)
    assert companion_tolerances(1e-11, 1e-14) == (1e-13, 1e-16)  # the companion's floor
    assert allowed_errors([0.0, 2.0], 1e-6, 1e-9) == [FACTOR * 1e-9,
                                                      FACTOR * (2e-6 + 1e-9)]
    assert worst_column([1e-9, 3e-6, 3e-6], [1e-8, 2e-5, 1e-5]) == 2
    assert worst_column([], []) == -1
