"""The compiled engine: springc's runs with no Python per step, on the C loop library
(:mod:`.native`, DOP853, RK45, Radau IIA and BDF of continuous models where a C
compiler is found) or on :mod:`springc.integrate`'s numba loops.

- :func:`c_loop_available`: whether the C loop runs (a C compiler found, or
  ``SPRINGC_LOOP`` forcing ``c`` or ``numba``); the one rule of the choice;
- :func:`choose_engine`: ``--engine auto|compiled|scipy`` and the solver -> the engine
  of a run (``compiled`` needs numba, a solver with a compiled loop and the numba
  backend's functions; errors name the option).
- :func:`advance_compiled`: the step loop's integrators run compiled, to the end of the
  grid or for a number of steps (``auto``'s probes): DOP853 and RK45 take scipy's steps
  (same start, same controller) with plain-loop sums (equal to the scipy run within
  rounding, faster than numpy's BLAS calls on small systems: the seed 2.7 ms against
  3.6 ms); Radau IIA and BDF with the generated sparse Jacobian in a banded LU.
- :func:`run_fixed_compiled`: the fixed-step solvers, compiled.

Failures come back as :class:`springc.integrate.Status` codes and become the scipy
path's errors here: the step size collapse, a non-finite derivative (located in the
generated code where the Python semantics of the same function raise), a non-finite
state, the model's Newton failure flag, and the step and time limits.
"""

from __future__ import annotations

import importlib.util
import os
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import SimulationError, UsageError
from ..native import FIRST_STRETCH, STRETCH_GROWTH
from ..status_line import say
from .failures import Stop
from .limits import HOPELESS, OverLimit
from .solver_names import AUTO, COMPILED_SOLVERS, ENGINES, EXPLICIT, FIXED_STEP, RACE_IMPLICIT
from .solvers import detect_pairs, non_finite_states
from .step_cost import Work
from .steps import Problem, StepLoop, Stepper, Stretch, solver_failure

if TYPE_CHECKING:
    from springc.integrate import Run

COMPILED, SCIPY = "compiled", "scipy"
FIRST_CHUNK = FIRST_STRETCH
"""Steps (accepted and rejected) of the first compiled stretch: a longer run goes on
from where the stretch stopped (its time, state and next step size: the explicit
methods take the same steps as one uninterrupted run) in stretches
:data:`~springc.native.STRETCH_GROWTH` times longer (the policy of
:mod:`springc.native.runner`, which the warm replay follows too), so that a run whose
step size is hopeless stops early and the wall-clock limit is checked between
stretches. The step limit counts accepted steps, as scipy's loop does."""
FIXED_CHUNK = 200_000
"""Steps of a fixed-step stretch between two checks of the wall clock."""
C_LOOP_VARIABLE = "SPRINGC_LOOP"
"""The environment variable that forces the compiled engine's loop: ``c`` (the C loop
library, a C compiler needed) or ``numba``; unset or empty: C where
:func:`springc.pipeline.find_compiler` finds a compiler, else numba."""
C_SOLVERS = ("dop853", "rk45", "radau", "bdf")
"""The methods the C loop runs (continuous models; ``auto``'s explicit method and the
radau its race may hand over to too)."""
C_LOOP, NUMBA_LOOP = "c", "numba"
SCIPY_COLLAPSE = "Required step size is less than spacing between numbers."
"""scipy's message for the same failure (the step loop words both alike)."""


def numba_available() -> bool:
    """Whether numba can be imported (without importing it)."""
    return importlib.util.find_spec("numba") is not None


def c_loop_available() -> bool:
    """Whether the compiled engine runs the C loop (:mod:`.native`) for ``auto``,
    ``dop853``, ``rk45``, ``radau`` and ``bdf`` on continuous models: ``SPRINGC_LOOP`` says ``c`` or
    ``numba``; unset, where a C compiler is found (compiler presence, never timing).
    Imports neither numba nor the compiler's output."""
    choice = os.environ.get(C_LOOP_VARIABLE, "").strip().lower()
    if choice not in ("", C_LOOP, NUMBA_LOOP):
        raise UsageError(f"{C_LOOP_VARIABLE} must be {C_LOOP} or {NUMBA_LOOP} (or unset), "
                         f"not {choice!r}", option=C_LOOP_VARIABLE)
    if choice:
        return choice == C_LOOP
    from ..pipeline import CCompilerMissing, find_compiler

    try:
        find_compiler()
    except CCompilerMissing:
        return False
    return True


def c_loop_runs(solver: str, backend: str | None) -> bool:
    """Whether a run of ``solver`` on a module of ``backend`` (None: not chosen yet)
    may take the C loop: a solver it runs (or ``auto``), a python module (the C loop
    needs no numba functions) and :func:`c_loop_available`. The model decides the
    rest: a continuous one whose loop library builds
    (:func:`springc.pipeline.loop_library`: printable in C, within
    :data:`springc.pipeline.c_kernels.C_LOOP_CODE_CHARS` and ``C_LOOP_STACK_BYTES``)."""
    return (solver == AUTO or solver in C_SOLVERS) and backend in (None, "python") \
        and c_loop_available()


def default_backend(engine: str = AUTO, solver: str = AUTO) -> str:
    """The generated module's backend when the user names none (``--backend`` left out):
    ``python`` where the run takes the C loop (:func:`c_loop_runs`: its numba-free
    module serves the Python side; ``engine`` not ``scipy``); else ``numba`` where the
    run can take the compiled loop (numba importable, ``engine`` not ``scipy``,
    ``solver`` with a compiled loop or ``auto``), else ``python``: a run on scipy's loop
    calls the model's functions from Python, where numba's compilation of a new model
    (seconds) costs more than it saves on most runs. (A model with delays or switching
    states compiled for the C loop is generated again for numba: see
    :func:`springc.api.compile_model`; one with events stays on python, its runs
    between events in the C loop.)"""
    name = engine.lower() if isinstance(engine, str) else engine
    if name != SCIPY and c_loop_runs(solver, None):
        return "python"
    has_loop = solver == AUTO or solver in COMPILED_SOLVERS
    return "numba" if name != SCIPY and has_loop and numba_available() else "python"


def choose_engine(engine: str, solver: str, backend: str | None = None,
                  option: str = "--engine", backend_option: str = "--backend") -> str:
    """:data:`COMPILED` or :data:`SCIPY` for a run of ``solver``.

    ``backend`` is the generated module's backend if already chosen (``None``: springc
    chooses, :func:`default_backend`). ``auto`` (the default) is compiled where numba
    is importable, the solver has a compiled loop (``auto`` counts: it finishes on
    dop853 or radau compiled) and the module is (or will be) generated with the numba
    backend; otherwise scipy, and the run's summary says why (:func:`engine_reason`).
    A ``compiled`` request that cannot be met is a :class:`UsageError` naming
    ``option``.
    """
    name = engine.lower() if isinstance(engine, str) else engine
    if name not in ENGINES:
        raise UsageError(f"{option} must be one of {', '.join(ENGINES)}, not {engine!r}",
                         option=option)
    has_loop = solver == AUTO or solver in COMPILED_SOLVERS
    if name == SCIPY:
        return SCIPY
    if name == AUTO:
        numba_module = backend in (None, "numba")
        numba_loop = has_loop and numba_module and numba_available()
        return COMPILED if numba_loop or c_loop_runs(solver, backend) else SCIPY
    if not has_loop:
        raise UsageError(f"{option} compiled: the {solver} solver has no compiled loop",
                         option=option,
                         hint=f"use {option} scipy (or auto), or a solver with a compiled "
                              f"loop: {', '.join((AUTO, *COMPILED_SOLVERS))}")
    if c_loop_runs(solver, backend):
        return COMPILED
    if not numba_available():
        raise UsageError(f"{option} compiled needs numba, which is not installed",
                         option=option, hint=f"install numba, or use {option} scipy")
    if backend == "python":
        raise UsageError(f"{option} compiled runs the numba backend's functions, not "
                         f"{backend_option} python", option=option,
                         hint=f"leave out {backend_option} (the compiled engine uses "
                              f"numba), or use {option} scipy")
    return COMPILED


def jitted(module: Any) -> bool:
    """Whether the generated module's functions are numba's (the compiled loops call
    ``rhs`` and ``jacobian_values`` through function pointers); a python module's are
    not (numba is not imported for it)."""
    if getattr(module, "BACKEND", "") != "numba":
        return False
    from numba.core.dispatcher import Dispatcher

    return all(isinstance(getattr(module, name, None), Dispatcher)
               for name in ("rhs", "jacobian_values"))


def observed_on_grid(module: Any, ts: np.ndarray, states: np.ndarray, p: np.ndarray,
                     z: np.ndarray) -> np.ndarray:
    """The module's observed variables at ``states`` on ``ts`` (its ``observed_grid``):
    for a numba module springc's compiled loop over its ``observed`` (compiled once per
    machine, where the module's own loop is Python), for others the module's own."""
    if getattr(module, "BACKEND", "") == "numba" and numba_available():
        from numba.core.dispatcher import Dispatcher

        if isinstance(module.observed, Dispatcher):
            from springc.integrate import observed_grid

            return observed_grid(module.observed, ts, states, p, z)
    return np.asarray(module.observed_grid(ts, states, p, z))


def engine_reason(engine: str, solver: str, module: Any, compiled: bool,
                  states: int = 1) -> str:
    """Why a run of ``solver`` ran on the engine it did, in plain words (``engine``: the
    ``--engine`` option, ``module``: the generated module, ``states``: how many)."""
    if compiled and not jitted(module):
        return (f"{solver} ran in the compiled loop (C, no Python per step: a C compiler "
                f"was found; {C_LOOP_VARIABLE}=numba runs numba's)")
    if compiled:
        return f"{solver} ran in the compiled loop (numba, no Python per step)"
    where = "springc's Python loop" if solver in FIXED_STEP else "scipy's loop"
    if engine == SCIPY:
        return f"{solver} ran in {where}, as --engine scipy asks"
    if solver not in COMPILED_SOLVERS:
        return f"{solver} ran in {where}: springc has no compiled loop for it"
    if not states:
        return "no loop ran: the model has no states to integrate"
    if not numba_available():
        return (f"{solver} ran in {where}: numba is not installed (pip install "
                "numba: the compiled loop runs it)")
    if getattr(module, "BACKEND", "python") != "numba":
        return (f"{solver} ran in {where}: the model was generated for the python "
                "backend (asked for, or springc's choice for code too long for numba to "
                "compile quickly)")
    # every numba module springc generates has jitted functions (the vector layout's
    # too); a module whose functions are not reaches here
    return (f"{solver} ran in {where}: the module's rhs and jacobian_values are not "
            "numba functions")


def explained(engine: str, reason: str, compiled: bool) -> bool:
    """Whether a run's summary says why it ran on its engine: ``auto``'s runs always
    (``reason``: why auto chose its solver), others where the default engine fell back
    to scipy's loop."""
    return bool(reason) or (not compiled and engine.lower() == AUTO)


def advance_compiled(loop: StepLoop, stepper: Stepper, max_steps: int | None = None
                     ) -> Stretch:
    """Run ``stepper`` in the compiled loop of its method from where it is, with its next
    step size, filling ``loop``'s grid from ``loop.k``: to the end of the grid, or for
    ``max_steps`` steps (rejected ones included), after which ``stepper`` is where the
    run stopped and goes on from there as one uninterrupted run would (the explicit
    methods take the same steps; Radau and BDF restart their Jacobian and step-size
    history). The stretch's ``sizes`` hold its mean accepted step size. A failure moves
    ``stepper`` to its last accepted state before raising the scipy path's error."""
    kernel = _kernel(loop, stepper.method)
    load_kernel(stepper.method)  # (numba's cache, once per process: not the stretch's time)
    return advance_with(loop, stepper, max_steps, kernel)


Kernel = Callable[[np.ndarray, np.ndarray, float, int, "np.ndarray | None"], "Run"]
"""``run(times, y, first_step, max_steps, out)``: a compiled loop of a method on a run's
model and tolerances (``first_step`` 0: the loop selects it), a
:class:`springc.integrate.Run`; ``out``, where not None, are rows (C-contiguous) the loop
may write its states into, row 0 the stretch's start (the C loop does: its
``Run.states`` are then a view of them; numba's allocates its own)."""


def advance_with(loop: StepLoop, stepper: Stepper, max_steps: int | None, kernel: Kernel
                 ) -> Stretch:
    """:func:`advance_compiled` on the loop ``kernel`` (numba's or the C loop's: the same
    contract, see :mod:`.native`)."""
    from springc.integrate import Status

    problem, grid = loop.problem, loop.grid
    t, y = stepper.t, stepper.y
    rest = grid[loop.k:]
    times = np.concatenate(([t], rest[rest > t]))
    started, first = t, stepper.h_abs
    began = time.perf_counter()
    allowed = loop.limits.max_steps - loop.steps  # accepted steps, as scipy's loop counts
    budget = np.inf if max_steps is None else max_steps
    chunk, accepted, taken, nfev, njev = FIRST_CHUNK, 0, 0, 0, 0
    while True:
        attempt = int(max(min(chunk, allowed - accepted, budget - taken), 1))
        # the rows from loop.k - 1 on as the loop's own (row 0, the start, is put back):
        # no buffer of the stretch's rows filled and copied where the loop writes there
        aligned = len(times) - 1 == len(grid) - loop.k
        out = loop.states[loop.k - 1:] if aligned else None
        before = loop.states[loop.k - 1].copy() if aligned else None
        run = kernel(times, y, min(first, float(times[-1] - t)), attempt, out)
        if before is not None:
            loop.states[loop.k - 1] = before
        problem.nfev += run.rhs_evaluations
        problem.njev += run.jacobian_evaluations
        nfev += run.rhs_evaluations
        njev += run.jacobian_evaluations
        accepted += run.accepted_steps
        taken += run.accepted_steps + run.rejected_steps
        rows = run.filled - 1  # row 0 is the stretch's start
        if out is None or not np.shares_memory(run.states, out):
            loop.states[loop.k:loop.k + rows] = run.states[1:run.filled]
        loop.k += rows
        if run.status != Status.MAX_STEPS or accepted >= allowed:
            break
        t, y, first = run.failure_time, np.array(run.failure_state), run.next_step
        times = np.concatenate(([t], times[run.filled:]))
        if taken >= budget:
            break
        projected = loop.steps + accepted * (float(grid[-1]) - started) / max(t - started,
                                                                               1e-300)
        if projected > HOPELESS * loop.limits.max_steps:
            raise OverLimit(f"at its current step size ({(t - started) / accepted:.3g} s "
                            f"on average) {stepper.method} needs ~{projected:.3g} steps to "
                            f"the stop time, far over the step limit (--max-steps "
                            f"{loop.limits.max_steps})", t, run.failure_state,
                            stepper.method)
        if time.perf_counter() > problem.deadline:
            raise time_limit_reached(problem, run)
        chunk *= STRETCH_GROWTH
    seconds = time.perf_counter() - began
    if run.status == Status.STEP_TOO_SMALL and not accepted and not stepper.h_abs > 0 \
            and not run.next_step > 0:  # no first step: scipy's steps word why
        integrator = loop.scipy_start(stepper.method, stepper.t, stepper.y)
        stretch = loop.advance(integrator, max_steps)
        stepper.t, stepper.y = float(integrator.t), np.array(integrator.y)
        stepper.h_abs = float(integrator.h_abs)
        return stretch
    loop.loop_time += seconds
    loop.compiled_steps += accepted
    loop.steps += accepted
    stepper.t, stepper.y = float(run.failure_time), np.array(run.failure_state)
    stepper.h_abs = float(run.next_step)
    if not run.ok and not (run.status == Status.MAX_STEPS and taken >= budget
                           and accepted < allowed):
        raise failure(problem, run, stepper.method, steps=loop.steps,
                      limit=loop.limits.max_steps)
    if time.perf_counter() > problem.deadline:
        raise time_limit_reached(problem, run)
    if run.ok:
        loop.k = len(grid)
    mean = (stepper.t - started) / accepted if accepted else 0.0
    # (the compiled loops count no factorizations: the cost model bounds them)
    return Stretch(Work(accepted, taken, nfev, njev), (mean,) if accepted else ())


KERNEL_NOTE = "compiling the {method} loop for this machine (once), about {seconds} s"
"""The status line before a kernel compiles (numba has not cached it on this machine);
``seconds``: :func:`springc.integrate.compile_seconds`, CPU seconds measured once."""


def load_kernel(method: str, cached: Callable[[str], bool] | None = None) -> None:
    """Load the compiled loop of ``method``, first saying on stderr that it compiles
    where numba's cache does not hold it (``cached``: the check, by default
    :func:`springc.integrate.kernel_cached`)."""
    from springc.integrate import compile_seconds, kernel_cached, load

    if not (cached or kernel_cached)(method):
        say(KERNEL_NOTE.format(method=method, seconds=compile_seconds(method)))
    load(method)


def _kernel(loop: StepLoop, method: str) -> Kernel:
    """``method``'s numba loop on ``loop``'s model and tolerances (:data:`Kernel`)."""
    problem = loop.problem

    def run(times: np.ndarray, y: np.ndarray, first: float, steps: int,
            out: np.ndarray | None) -> Run:  # (numba's loop allocates its rows)
        return adaptive_run(method, problem.mod, times, y, problem.p, problem.z,
                            rtol=loop.rtol, atol=loop.atol, first_step=first or None,
                            max_steps=steps)
    return run


def adaptive_run(solver: str, mod: Any, times: np.ndarray, x: np.ndarray, p: np.ndarray,
                 z: np.ndarray, **options: Any) -> Run:
    """One kernel run of the adaptive ``solver`` (dop853, rk45 with plain-loop sums;
    radau and bdf with the generated sparse Jacobian) on the generated module ``mod``."""
    from springc.integrate import bdf, dop853, radau, rk45

    try:
        if solver in (RACE_IMPLICIT, "bdf"):
            from ..pipeline import jacobian_apart

            jacobian_apart(mod)  # at its first use, compiled apart (springc simulate)
            implicit = radau if solver == RACE_IMPLICIT else bdf
            return implicit(mod.rhs, mod.jacobian_values, mod.JAC_INDPTR, mod.JAC_INDICES,
                            times, x, p, z, **options)
        explicit = dop853 if solver == EXPLICIT else rk45
        return explicit(mod.rhs, times, x, p, z, scipy_arithmetic=False, **options)
    except np.linalg.LinAlgError as err:  # numba's solve of a singular linear system
        raise Stop(SimulationError(
            f"a linear system of the model is singular ({err}) in the stretch from time "
            f"{float(times[0]):g}", hint="the model may have reached a singular "
            "configuration; check the parameters (--set) and start values")) from None


def run_fixed_compiled(problem: Problem, grid: np.ndarray, x0: np.ndarray, step: float
                       ) -> tuple[np.ndarray, int, float]:
    """The states on ``grid``, the steps and the loop's seconds of a fixed-step run of
    ``problem.solver``, compiled (the same arithmetic and errors as
    :func:`springc.simulation.solvers.run_fixed`).

    The grid is run in stretches of about :data:`FIXED_CHUNK` steps, each from the
    state the last one reached (the methods restart exactly at an output time; verlet
    evaluates the derivative there again, the same value up to the rounding of a
    time-dependent model's clock), with the wall-clock limit and the progress bar
    between stretches.
    """
    from springc.integrate import fixed_step

    if len(x0) == 0:
        return np.tile(x0, (len(grid), 1)), 0, 0.0
    load_kernel(problem.solver)
    pairs = detect_pairs(problem.mod, problem.p, x0, float(grid[0]))
    index_pairs = list(zip(pairs.positions.tolist(), pairs.velocities.tolist()))
    counts = np.maximum(1, np.ceil(np.diff(grid) / step - 1e-9))
    ends = np.searchsorted(np.cumsum(counts), FIXED_CHUNK * np.arange(1, counts.sum()
                                                                     // FIXED_CHUNK + 2))
    states = np.empty((len(grid), len(x0)))
    states[0] = x0
    began = time.perf_counter()
    first, steps = 0, 0
    for end in sorted({*(min(int(e) + 1, len(grid) - 1) for e in ends), len(grid) - 1}):
        if end <= first:
            continue
        run = fixed_step(problem.solver, problem.mod.rhs, grid[first:end + 1],
                         states[first], problem.p, problem.z, step=step, pairs=index_pairs)
        problem.nfev += run.rhs_evaluations
        steps += run.accepted_steps
        if not run.ok:
            raise failure(problem, run, problem.solver, step=step)
        states[first + 1:end + 1] = run.states[1:]
        first = end
        if end < len(grid) - 1 and time.perf_counter() > problem.deadline:
            raise time_limit_reached(problem, run)
        problem.progress.update(float(grid[end]))
    return states, steps, time.perf_counter() - began


def time_limit_reached(problem: Problem, run: Run) -> OverLimit:
    """The error of a compiled run that passed the wall-clock limit."""
    return OverLimit(f"{problem.limits.time_limit:g} s of wall clock reached the time "
                     "limit (--time-limit)", run.failure_time, run.failure_state,
                     problem.solver)


def failure(problem: Problem, run: Run, solver: str, *, steps: int = 0, limit: int = 0,
            step: float = 0.0) -> Exception:
    """The error (``Stop`` or ``OverLimit``) of a compiled run that did not finish,
    worded as the scipy path words it."""
    from springc.integrate import Status

    t, x = run.failure_time, np.asarray(run.failure_state)
    problem.solver = solver
    if run.status == Status.STEP_TOO_SMALL:
        return Stop(solver_failure(problem, t, x, SCIPY_COLLAPSE))
    if run.status == Status.NON_FINITE_DERIVATIVE:
        return problem.explain(t, x)
    if run.status == Status.MODEL_FAILED:
        return problem.newton_failure(t, x)
    if run.status == Status.MAX_STEPS:
        return OverLimit(f"{steps} steps of {solver} reached the step limit (--max-steps "
                         f"{limit})", t, x, solver)
    if run.status == Status.NON_FINITE_STATE and solver in FIXED_STEP:
        return Stop(non_finite_states(problem, t, np.flatnonzero(~np.isfinite(x)), step))
    raise AssertionError(f"the compiled {solver} loop returned {run.status.name}")
