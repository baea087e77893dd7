"""The Python side of the compiled ensemble: checked arrays in, an :class:`Ensemble` out.

One call integrates a chunk of runs (rows of a parameter matrix) with compiled DOP853 in
parallel over the rows (:mod:`.ensemble_kernel`); memory is a few rows per run plus one
output grid per thread, so the caller bounds it by the chunk size.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .status import Status

if TYPE_CHECKING:  # numba loads with the first run, not with the face
    from .signatures import ModelFunction

STATISTICS = ("final", "min", "max", "mean", "argmax")
"""The summaries of each chosen column (see :mod:`.ensemble_kernel`)."""


@dataclass(frozen=True)
class Ensemble:
    """The outcome of a chunk of runs: one row per run.

    ``finals[r]``: the states at the end (or where run ``r`` stopped); ``summary[r, c,
    s]``: statistic ``STATISTICS[s]`` of chosen column ``c`` (NaN unless the run
    succeeded); ``status[r]``: a :class:`Status` code; ``steps[r]`` accepted plus
    rejected steps; ``rhs_evaluations[r]``; ``failure_time[r]``: where the run stopped;
    ``flag[r]``: the model's failure flag (the Newton system that failed, 0 if none);
    ``trajectories[r, s, c]``: trajectory column ``c`` at kept output time ``s`` (NaN
    where the run did not get there).
    """

    finals: np.ndarray
    summary: np.ndarray
    status: np.ndarray
    steps: np.ndarray
    rhs_evaluations: np.ndarray
    failure_time: np.ndarray
    flag: np.ndarray
    trajectories: np.ndarray

    def ok(self) -> np.ndarray:
        """Which runs reached the end of the grid."""
        return np.asarray(self.status == int(Status.SUCCESS))


def ensemble(rhs: ModelFunction, grid: Any, X0: Any, P: Any, Z: Any, *, rtol: float,
             atol: float | Sequence[float] | np.ndarray, observed: ModelFunction | None = None,
             columns: Sequence[int] = (), max_step: float = np.inf,
             max_steps: int = 0, traj_columns: Sequence[int] = (), every: int = 1
             ) -> Ensemble:
    """Integrate ``x' = rhs(t, x, P[r], z)`` from ``(grid[0], X0[r])`` for every row
    ``r``, each with compiled DOP853 (plain-loop sums) and its own steps.

    ``X0``, ``P`` and ``Z`` have one row per run (``Z``: the model's work array of the
    run, copied). ``columns`` and ``traj_columns`` index ``[states | observed]``;
    observed columns need ``observed``. The trajectories keep every ``every``-th output
    time and the last. ``max_steps`` (accepted and rejected, per run) 0 is no limit.
    """
    from numba.core.dispatcher import Dispatcher

    from .addresses import install
    from .ensemble_kernel import ensemble_run
    from .models import no_observed

    install()
    grid_ = np.array(grid, dtype=float)
    if grid_.ndim != 1 or grid_.size == 0 or not np.isfinite(grid_).all() \
            or (np.diff(grid_) <= 0).any():
        raise ValueError("the output grid must be a non-empty, finite, strictly "
                         "increasing 1-D array")
    X0_, P_, Z_ = (np.ascontiguousarray(a, dtype=float) for a in (X0, P, Z))
    if X0_.ndim != 2 or P_.ndim != 2 or Z_.ndim != 2 \
            or not X0_.shape[0] == P_.shape[0] == Z_.shape[0]:
        raise ValueError(f"X0, P and Z must be 2-D with a row per run: shapes {X0_.shape}, "
                         f"{P_.shape}, {Z_.shape}")
    runs, n = X0_.shape
    if not rtol > 0 or not max_step > 0:
        raise ValueError(f"rtol and max_step must be positive, got {rtol!r}, {max_step!r}")
    atol_ = np.array(np.broadcast_to(np.asarray(atol, dtype=float), (n,)))
    if not (atol_ >= 0).all():
        raise ValueError("atol must not be negative")
    for name, f in (("rhs", rhs), ("observed", observed)):
        if f is not None and not isinstance(f, Dispatcher):
            raise TypeError(f"{name} must be a numba-jitted function, got {type(f).__name__}")
    n_observed = 0
    if runs and observed is not None:
        n_observed = np.asarray(observed(grid_[0], X0_[0], P_[0], Z_[0].copy())).size
    if runs and np.asarray(rhs(grid_[0], X0_[0], P_[0], Z_[0].copy())).shape != (n,):
        raise ValueError(f"rhs does not return {n} derivatives")
    columns_ = np.array(columns, dtype=np.int64).ravel()
    traj_ = np.array(traj_columns, dtype=np.int64).ravel()
    for chosen in (columns_, traj_):
        if chosen.size and not 0 <= chosen.min() <= chosen.max() < n + n_observed:
            raise ValueError(f"a column is outside the {n} states and {n_observed} "
                             "observed variables")
    if every < 1:
        raise ValueError(f"every must be at least 1, got {every}")
    kept = np.arange(0, grid_.size, every)
    if kept[-1] != grid_.size - 1:
        kept = np.append(kept, grid_.size - 1)
    trajectories = np.full((runs, kept.size if traj_.size else 0, traj_.size), np.nan)
    finals = np.empty((runs, n))
    summary = np.empty((runs, columns_.size, len(STATISTICS)))
    status = np.empty(runs, dtype=np.int64)
    counts = np.empty((runs, 4), dtype=np.int64)
    failure_time = np.empty(runs)
    if runs:
        ensemble_run(rhs, observed if observed is not None and n_observed else no_observed,
                     n_observed, no_observed,
                     grid_, X0_, P_, Z_, float(rtol), atol_, float(max_step),
                     int(max_steps), columns_, finals, summary, status, counts, failure_time,
                     traj_, kept, trajectories)
    return Ensemble(finals, summary, status, counts[:, 0] + counts[:, 1], counts[:, 2],
                    failure_time, counts[:, 3], trajectories)
