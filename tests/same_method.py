"""Two runs of one method that may differ in rounding (the compiled engine's plain-loop
sums against numpy's BLAS calls in scipy's): what "the same method" asserts."""

from __future__ import annotations

import numpy as np

import springc


def assert_same_method(a: springc.SimulationResult, b: springc.SimulationResult,
                       rtol: float, reference: springc.SimulationResult | None = None
                       ) -> None:
    """``a`` and ``b`` took the same number of steps (within 1 %) and agree within 10
    ``rtol`` of each variable's scale (an early step accepted by one and rejected by the
    other sends the two on paths that differ at the tolerance's size); against a
    ``reference`` far tighter than ``rtol``, their errors agree within 5 %."""
    assert a.names == b.names
    assert abs(a.stats.steps - b.stats.steps) <= 0.01 * b.stats.steps, \
        (a.stats.steps, b.stats.steps)
    scale = np.maximum(np.abs(b.values).max(axis=0), 1.0)
    assert (np.abs(a.values - b.values) <= 10 * rtol * scale).all()
    if reference is not None:
        errors = [float((np.abs(run.values - reference.values) / scale).max())
                  for run in (a, b)]
        assert abs(errors[0] - errors[1]) <= 0.05 * max(errors), errors
