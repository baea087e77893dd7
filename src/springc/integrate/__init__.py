"""Compiled integration loops: no Python per step (imports nothing from springc).

Input: a model's numba functions ``rhs(t, x, p, z) -> dx`` (and optionally
``observed(t, x, p, z) -> y``), an output grid, start states, parameters ``p`` and the
work array ``z``. Output: a :class:`Run` with the states (and observed variables) on the
grid, step counts and a :class:`Status`.

The step loop, error control, dense output on the grid and the observed variables all
run in numba. The model functions are passed as first-class function values
(``numba.types.FunctionType``), so the kernels compile once per machine and load from
numba's disk cache afterwards; a new model only compiles its own functions.

How ``springc.simulate`` uses it (with ``mod`` a generated numba module)::

    from springc.integrate import Status, dop853, fixed_step
    run = dop853(mod.rhs, grid, x0, p, z, rtol=rtol, atol=atol, observed=mod.observed)
    run = fixed_step("verlet", mod.rhs, grid, x0, p, z, step=h, pairs=[(0, 2), (1, 3)])
    if not run.ok:   # build the message from run.status, run.failure_time/_state
        ...

- ``dop853`` takes the same steps as ``scipy.integrate.solve_ivp(method="DOP853")``
  within rounding (same controller, error norm and initial step) and fills the grid from
  the 7th-order dense output (a grid time equal to a step's end gets that step's state).
- ``fixed_step`` runs ``euler``, ``symplectic-euler``, ``verlet`` or ``rk4`` exactly as
  ``springc.simulation``'s integrators do.
- Events: ``crossings=Crossings(g, signs, directions)`` stops a run at the earliest
  zero crossing of ``g(t, x, p, z) -> float64[::1]`` against the held ``signs``
  (status STATE_EVENT; located on DOP853's dense output or on split fixed steps to about
  1e-12 relative in time; ``run.event_time``, ``run.event_state`` (the left limit) and
  ``run.fired`` say where and which), ``t_stop`` stops it exactly at a time (TIME_EVENT).
  The caller updates the state and the held signs and restarts from the event;
  :func:`run_hybrid` is that loop with a Python ``update(t, x_left, fired)``.
- ``observed_grid(observed, ts, states, p, z)``: the observed variables at states on a
  grid (a run's states after the fact), compiled once per machine like the loops.
- ``ensemble(rhs, grid, X0, P, Z, rtol=..., atol=..., columns=...)``: many runs (a row
  of ``P`` each) with compiled DOP853 in parallel over the rows (``numba.prange``), each
  with its own steps and status; the final states and per-run statistics (final, min,
  max, time-weighted mean, time of the max) of chosen columns (:mod:`.batch`).
- ``NativeEnsemble`` (:mod:`.native_ensemble`): the same ensemble as one C kernel text
  (``ensemble_dop853.c``, numba's DOP853 arithmetic in the same order) around a model's
  C file, compiled by the system compiler (OpenMP over the runs, loaded with ctypes);
  each run's parameters and start values computed in the kernel (:class:`Runs`), with
  trajectories of chosen columns. ``GpuEnsemble`` (:mod:`.gpu_ensemble`): that text as
  a CUDA kernel through CuPy's NVRTC, one thread per run (:class:`NoCudaDevice`
  without CuPy or a device).
- Failures never raise inside the loop: :class:`Status` says what happened
  (step too small, NaN/inf derivative or state, max steps, the model's failure flag
  ``z[-1]``) and the run carries the time and the state where it happened.
- Bad arguments (a grid that does not increase, a function that is not jitted or
  returns the wrong length) raise ``ValueError``/``TypeError`` before the loop starts.
"""

from typing import Any

from .batch import Ensemble, ensemble
from .compile_lock import locked
from .engine import (
    Crossings,
    Run,
    band_order,
    bdf,
    dop853,
    fixed_step,
    newton_flops,
    newton_solve_flops,
    observed_grid,
    radau,
    rk45,
)
from .gpu_ensemble import GpuEnsemble, NoCudaDevice
from .hybrid import HybridRun, run_hybrid
from .kernels import FIXED_STEP_METHODS, compile_seconds, kernel_cached, load
from .native_ensemble import OPENMP, NativeEnsemble, Outputs, Runs, kernel_text
from .native_loop import loop_text
from .status import Status

__all__ = [
    "FIXED_STEP_METHODS",
    "MODEL_FUNCTION_SIGNATURE",
    "OPENMP",
    "Crossings",
    "Ensemble",
    "GpuEnsemble",
    "HybridRun",
    "NativeEnsemble",
    "NoCudaDevice",
    "Outputs",
    "Run",
    "Runs",
    "Status",
    "band_order",
    "bdf",
    "compile_seconds",
    "dop853",
    "ensemble",
    "fixed_step",
    "kernel_cached",
    "kernel_text",
    "load",
    "locked",
    "loop_text",
    "newton_flops",
    "newton_solve_flops",
    "observed_grid",
    "radau",
    "rk45",
    "run_hybrid",
]


def __getattr__(name: str) -> Any:
    """``MODEL_FUNCTION_SIGNATURE`` on first use: it is numba's type, and importing
    this package must not import numba (a warm run on the C loop never does)."""
    if name == "MODEL_FUNCTION_SIGNATURE":
        from .signatures import MODEL_FUNCTION_SIGNATURE

        return MODEL_FUNCTION_SIGNATURE
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
