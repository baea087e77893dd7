"""The compiled engine on the C loop library: a continuous model's DOP853, RK45, Radau
IIA and BDF runs with no Python per step and no numba (:func:`advance_native`), and its
observed variables on the grid (:func:`native_observed`).

The library (:func:`springc.pipeline.loop_library`: the model's C functions with
``integrate/single_loop.c``, built once into the model's cache entry) keeps the numba
loop's contract: stretches of steps resumable from (time, state, next step), scipy's
start, initial step and controller, the dense output on the grid, the status codes
and counters, so :func:`.compiled.advance_with` runs it as it runs numba's loop, with
the same step and time limits and the same errors (a non-finite derivative located
where the model's Python code raises). Radau and BDF use the C model's analytic
Jacobian (its forward differences where the C model has none) in the band LU of the
numba loops, in the same ordering of the states (:func:`band_order`), so that they take
the numba loops' steps.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import CodegenError, SimulationError
from .compiled import Kernel, advance_with
from .steps import StepLoop, Stepper, Stretch

if TYPE_CHECKING:
    from springc.integrate import Run
    from springc.native import LoopLibrary, LoopRun

    from .steps import Problem

IMPLICIT = ("radau", "bdf")
"""The implicit methods of the C loop (they take the band ordering)."""


def advance_native(loop: StepLoop, stepper: Stepper, max_steps: int | None = None
                   ) -> Stretch:
    """:func:`.compiled.advance_compiled` on the C loop library (``finish`` of the
    step loop)."""
    return advance_with(loop, stepper, max_steps, _kernel(loop, stepper.method))


def loop_ready(problem: Problem) -> bool:
    """Whether ``problem``'s model has its loop library (built now where needed);
    False where its C model cannot be printed: a model unpickled in another process,
    or loaded from the cache, whose files changed since (it then runs on scipy's loop,
    as a python module did before the C loop), or a function the C printer cannot
    spell (a model compiled with ``--backend python``; springc's own choice of backend
    regenerates such a model for numba)."""
    try:
        library(problem)
    except CodegenError as error:
        from ..pipeline import note_refused

        note_refused(error, "scipy's loop")
        return False
    except SimulationError:
        return False
    return True


def library(problem: Problem) -> LoopLibrary:
    """The loop library of ``problem``'s model (built once per cache entry)."""
    from ..pipeline import loop_library

    if problem.loop_library is None:
        problem.loop_library = loop_library(problem.model)
    lib: LoopLibrary = problem.loop_library
    return lib


def band_order(module: Any) -> list[int] | None:
    """The ordering of the states in the implicit methods' band LU, the numba loops'
    (:func:`springc.integrate.band_order` of the generated module's Jacobian sparsity:
    reverse Cuthill-McKee above 64 states, None at or below: state order)."""
    from springc.integrate import band_order as order_of

    return order_of(module.JAC_INDPTR, module.JAC_INDICES)


def _kernel(loop: StepLoop, method: str) -> Kernel:
    problem = loop.problem
    lib = library(problem)
    order = band_order(problem.mod) if method in IMPLICIT else None

    def run(times: np.ndarray, y: np.ndarray, first: float, steps: int,
            out: np.ndarray | None) -> Run:
        done = lib.run(method, times, np.ascontiguousarray(y, dtype=float), problem.p,
                       problem.z, rtol=loop.rtol, atol=loop.atol, first_step=first or 0.0,
                       max_steps=steps, order=order, out=out)
        return as_run(done, times)
    return run



def event_run(problem: Problem, method: str, times: np.ndarray, x: np.ndarray, rtol: float,
              atol: Any, first_step: float | None, signs: np.ndarray | None,
              t_stop: float, max_steps: int) -> Run:
    """One run of a hybrid model between events in the C loop (``method``: dop853,
    rk45, radau, bdf): from ``(times[0], x)`` over ``times``, stopping at the first
    crossing of a zero-crossing indicator against its held sign ``signs`` (None: the
    model has none) or at the time event ``t_stop`` (inf: none), as the numba kernel
    :func:`.compiled.adaptive_run` with ``crossings`` and ``t_stop`` does."""
    lib = library(problem)
    order = band_order(problem.mod) if method in IMPLICIT else None
    done = lib.run(method, times, np.ascontiguousarray(x, dtype=float), problem.p, problem.z,
                   rtol=rtol, atol=atol, first_step=first_step or 0.0, max_steps=max_steps,
                   order=order, signs=None if signs is None else signs.tolist(),
                   t_stop=t_stop)
    return as_run(done, times)


def as_run(done: LoopRun, times: np.ndarray) -> Run:
    """The C loop's outcome as :class:`springc.integrate.Run` (numpy views, no copy: of
    the ``out`` rows where the run wrote its states there)."""
    from springc.integrate import Run, Status

    n = len(done.failure_state)
    states = np.frombuffer(done.states, dtype=float)[:len(times) * n].reshape(len(times), n)
    return Run(Status(done.status), times, states, np.empty((len(times), 0)), done.filled,
               done.accepted_steps, done.rejected_steps, done.rhs_evaluations,
               done.failure_time, np.frombuffer(done.failure_state, dtype=float).copy(),
               np.asarray(done.fired, dtype=np.int64), done.next_step,
               done.jacobian_evaluations)


def native_observed(problem: Problem, grid: np.ndarray, states: np.ndarray,
                    z: np.ndarray, out: np.ndarray) -> bool:
    """The observed variables at the rows ``(grid[k], states[k])`` into ``out`` by the
    C model's ``springc_observed`` (``z`` carried from row to row); False (``out``
    partly written) where a row sets the model's failure flag or a value is not
    finite: the Python path (:func:`.observed_rows.observed_on_rows`) then computes
    them and words the failure."""
    lib = library(problem)
    row, values = lib.observed(np.ascontiguousarray(grid, dtype=float),
                               np.ascontiguousarray(states, dtype=float), problem.p, z)
    if row >= 0:
        return False
    computed = np.frombuffer(values, dtype=float)[:out.size].reshape(out.shape)
    out[...] = computed
    return bool(np.isfinite(computed).all())
