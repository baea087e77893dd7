"""Simulation: CompiledModel + SimulationOptions -> SimulationResult.

The step loop is that of ``scipy.integrate.solve_ivp`` (its solver classes ``RK45``,
``DOP853``, ``Radau``, ``BDF``, ``LSODA``, stepped one by one), so that springc can
show progress, stop at the first non-finite value, and name the time and the states
at fault. Output is interpolated with each step's dense output exactly at
``t0, t0 + dt, ..., stop``. Implicit methods get the generated analytic Jacobian:
dense for small systems, ``scipy.sparse`` CSC beyond :data:`DENSE_JACOBIAN_LIMIT`.

Defaults: start 0 s, stop 10 s, 500 output intervals, unless the model's
``experiment`` annotation says otherwise (its Interval applies even when the start or
stop time is given); rtol 1e-6 (or the experiment's Tolerance),
atol = rtol / 1000; solver :data:`DEFAULT_SOLVER`; at most
:data:`~springc.simulation.limits.DEFAULT_MAX_STEPS` steps and
:data:`~springc.simulation.limits.DEFAULT_TIME_LIMIT` seconds (:mod:`.limits`).

(The module is not named ``simulate``: ``springc.simulate`` is the API function, and a
submodule of that name would replace it on the package once imported.)
"""

from __future__ import annotations

import linecache
import math
import time
import traceback
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, TextIO

import numpy as np

from ..errors import Note, SimulationError
from ..ir.dae import derivative_name
from ..pipeline import CompiledModel, check_parameter_names
from ..simplify import describe_failure as _kind
from . import solvers
from .limits import (
    CHECK_EVERY,
    DEFAULT_MAX_STEPS,
    DEFAULT_TIME_LIMIT,
    HOPELESS,
    Limits,
    OverLimit,
    check_outputs,
    check_parameters,
    over_limit,
    projected_steps,
)
from .race import auto
from .results import SimulationResult, SimulationStats
from .solver_names import (
    ALL_SOLVERS,
    AUTO,
    DEFAULT_SOLVER,
    EXPLICIT,
    FIXED_STEP,
    IMPLICIT_SOLVERS,
    SOLVERS,
)

DEFAULT_START, DEFAULT_STOP, DEFAULT_INTERVALS = 0.0, 10.0, 500
DEFAULT_RTOL = 1e-6
DENSE_JACOBIAN_LIMIT = 64
MAX_OUTPUT_BYTES = 4_000_000_000
LSODA_LIMIT = 2000


@dataclass(frozen=True)
class SimulationOptions:
    """``None`` means: from the experiment annotation, else the documented default."""

    start: float | None = None
    stop: float | None = None
    interval: float | None = None
    solver: str = DEFAULT_SOLVER
    rtol: float | None = None
    atol: float | None = None
    parameters: Mapping[str, float] = field(default_factory=dict)
    progress: TextIO | None = None
    step: float | None = None  # fixed-step solvers only
    max_steps: int = DEFAULT_MAX_STEPS
    time_limit: float = DEFAULT_TIME_LIMIT  # seconds of wall clock


def output_grid(start: float, stop: float, interval: float) -> np.ndarray:
    """``start, start + interval, ..., stop``; the last point is ``stop`` exactly."""
    if not (math.isfinite(start) and math.isfinite(stop)) or stop <= start:
        raise SimulationError(f"the stop time {stop:g} must be after the start time "
                              f"{start:g}")
    if not interval > 0:
        raise SimulationError(f"the output interval must be positive, not {interval:g}")
    count = (stop - start) / interval
    n = max(1, round(count)) if abs(count - round(count)) < 1e-9 * max(1.0, count) \
        else math.ceil(count)
    if n > 10_000_000:
        raise SimulationError(f"{n} output intervals are too many",
                              hint="use a larger --interval")
    grid = start + interval * np.arange(n + 1, dtype=float)
    grid[-1] = stop
    return grid


def resolve(model: CompiledModel, options: SimulationOptions) -> tuple[float, float, float,
                                                                        float, float]:
    """start, stop, interval, rtol, atol from options, experiment and defaults."""
    exp = model.module.EXPERIMENT
    start = _first(options.start, exp.get("start"), DEFAULT_START)
    stop = _first(options.stop, exp.get("stop"), DEFAULT_STOP)
    if options.interval is not None:
        interval = options.interval
    elif exp.get("interval") is not None:
        interval = exp["interval"]
    else:
        interval = (stop - start) / DEFAULT_INTERVALS
    rtol = _first(options.rtol, exp.get("tolerance"), DEFAULT_RTOL)
    atol = _first(options.atol, None, rtol / 1000)
    return start, stop, interval, rtol, atol


def _first(*values: float | None) -> float:
    for v in values:
        if v is not None:
            return float(v)
    raise AssertionError("no default")


def initial_state(model: CompiledModel, p: np.ndarray, t0: float = 0.0) -> np.ndarray:
    """The states at the start time.

    States start at their ``start`` values, as Modelica tools do when nothing else
    fixes them. A model with ``initial equation``s or fixed start values on variables
    that are not states has an initial problem: it is solved by
    :func:`springc.initialize.initial_state` on the simplified system (derived again
    here, since the generated module holds only the ODE).
    """
    if not getattr(model.module, "INITIAL_CONDITIONS", 0):
        try:
            return np.asarray(model.module.start(p), dtype=float)
        except (ArithmeticError, ValueError) as err:
            where = _code_location(err, str(model.path))
            raise SimulationError(
                f"{_kind(err)} while computing the start value of {where or 'a state'}",
                hint="check the parameters the start values use (--set)") from None
    from ..pipeline import derive_system
    from ..simplify import initial_state as solve_initial

    system = derive_system(model.options).system
    values = dict(zip(model.parameter_names, (float(v) for v in p)))
    x0, _info = solve_initial(system, values, t0)
    order = {s.name: i for i, s in enumerate(system.states)}
    return np.array([x0[order[name]] for name in model.states], dtype=float)


# ------------------------------------------------------------------ failures

class _Stop(Exception):
    """Raised inside the right-hand side to end the integration with an error."""

    def __init__(self, error: SimulationError) -> None:
        super().__init__(error.message)
        self.error = error


def _fmt(t: float) -> str:
    return f"{t:.9g}"


def _remedy(solver: str) -> str:
    if solver in FIXED_STEP:
        return "reduce --step or use --solver radau"
    if solver in IMPLICIT_SOLVERS:
        return ("check the parameters and start values near that time (a spring of zero "
                "length? a mass of zero?), or try a tighter --rtol")
    return "the system looks stiff or unstable: try --solver radau (or bdf)"


def _state_notes(names: tuple[str, ...], x: np.ndarray, dx: np.ndarray | None,
                 limit: int = 4) -> list[Note]:
    bad = [i for i in range(len(x)) if not math.isfinite(x[i])]
    if dx is not None:
        bad += [i for i in range(len(dx)) if not math.isfinite(dx[i]) and i not in bad]
    if not bad and dx is not None:
        scale = np.abs(dx) / (1e-300 + np.abs(x) + 1.0)
        bad = [int(i) for i in np.argsort(-scale)[:limit]]
    elif not bad:
        bad = list(range(min(len(x), limit)))
    notes = [Note(f"{names[i]} = {x[i]:.6g}" + (f", {derivative_name(names[i])} = {dx[i]:.6g}"
                                                 if dx is not None else ""))
             for i in bad[:limit]]
    if len(bad) > limit:
        notes.append(Note(f"... and {len(bad) - limit} more states"))
    return notes


def _code_location(err: BaseException, path: str) -> str | None:
    """The flat name and source location of the generated line that raised ``err``."""
    frames = [f for f in traceback.extract_tb(err.__traceback__) if f.filename == path]
    if not frames:
        return None
    lineno = frames[-1].lineno or 0
    for n in range(lineno, max(0, lineno - 200), -1):
        line = linecache.getline(path, n).strip()
        if "  # " in line:
            name, _, where = line.split("  # ", 1)[1].strip().partition("  ")
            return f"{name} ({where})" if where else name
        if line.startswith("# "):
            return line[2:].strip()
        if line.startswith("def "):
            break
    return None


# ------------------------------------------------------------------ progress

class Progress:
    """A progress bar on ``stream``, shown once a run has taken about a second."""

    def __init__(self, stream: TextIO | None, start: float, stop: float) -> None:
        self.stream, self.start, self.stop = stream, start, stop
        self.began = time.perf_counter()
        self.next = self.began + 1.0 if stream is not None else math.inf
        self.shown = False

    def update(self, t: float) -> None:
        now = time.perf_counter()
        if self.stream is None or now < self.next:
            return
        self.next = now + 0.1
        frac = min(1.0, max(0.0, (t - self.start) / (self.stop - self.start)))
        bar = "#" * int(30 * frac)
        self.stream.write(f"\r[{bar:<30}] {100 * frac:5.1f}%  t = {t:.4g} s  "
                          f"{now - self.began:.1f} s ")
        self.stream.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown and self.stream is not None:
            self.stream.write("\r" + " " * 70 + "\r")
            self.stream.flush()


# ------------------------------------------------------------------ the run

class _Problem:
    """The generated functions wrapped for scipy: counting, timing, checking."""

    def __init__(self, model: CompiledModel, p: np.ndarray, solver: str,
                 progress: Progress, limits: Limits | None = None) -> None:
        mod = model.module
        self.model, self.mod, self.p, self.solver = model, mod, p, solver
        self.z = np.asarray(mod.guesses(p), dtype=float)
        self.names = tuple(mod.STATES)
        self.path = str(model.path)
        self.nfev = self.njev = 0
        self.model_time = 0.0
        self.progress = progress
        self.t = 0.0
        self.limits = limits = limits or Limits()
        self.deadline = time.perf_counter() + limits.time_limit

    def _fail(self, err: BaseException, t: float, x: np.ndarray, what: str) -> _Stop:
        where = _code_location(err, self.path)
        message = f"{_kind(err)} while computing {where or what} at time {_fmt(t)}"
        if "singular" in str(err).lower():
            message = f"{where or 'a linear system'} is singular at time {_fmt(t)}"
        return _Stop(SimulationError(
            message, notes=_state_notes(self.names, x, None),
            hint="the model leaves the domain of an operation there; check the "
                 "parameters (--set) and start values, or guard the expression"))

    def _newton(self, t: float, x: np.ndarray) -> _Stop:
        step = int(self.z[-1])
        names = self.mod.NEWTON_SYSTEMS.get(step, ("?",))
        self.z[-1] = 0.0
        return _Stop(SimulationError(
            f"the nonlinear system for {', '.join(names)} did not converge at time "
            f"{_fmt(t)}", notes=_state_notes(self.names, x, None),
            hint="the model may have reached a singular configuration (a rod or "
                 "pendulum at the end of its range?); check the start values"))

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        self.nfev += 1
        began = time.perf_counter()
        try:
            dx = self.mod.rhs(t, x, self.p, self.z)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            raise self._fail(err, t, x, "the derivatives") from err
        now = time.perf_counter()
        self.model_time += now - began
        if now > self.deadline:
            raise OverLimit(f"{self.limits.time_limit:g} s of wall clock reached the time "
                            "limit (--time-limit)", t, np.array(x), self.solver)
        if self.z[-1] != 0.0:
            raise self._newton(t, x)
        # a sum is finite if every term is (a finite sum that overflows is checked again)
        if not math.isfinite(dx.sum()) and not np.isfinite(dx).all():
            bad = [self.names[i] for i in np.flatnonzero(~np.isfinite(dx))]
            shown = ", ".join(derivative_name(n) for n in bad[:3])
            shown += ", ..." if len(bad) > 3 else ""
            what = "NaN" if np.isnan(dx).any() else "infinite"
            raise _Stop(SimulationError(
                f"{shown} {'is' if len(bad) == 1 else 'are'} {what} at time {_fmt(t)}",
                notes=_state_notes(self.names, x, dx), hint=_remedy(self.solver)))
        if now >= self.progress.next:
            self.progress.update(t)
        return np.asarray(dx)

    def jacobian(self, t: float, x: np.ndarray) -> Any:
        """The Jacobian for diagnostics: not counted, no failure checks."""
        z = np.array(self.z)
        return self.mod.jacobian_dense(t, x, self.p, z) if len(x) <= DENSE_JACOBIAN_LIMIT \
            else self.mod.jacobian(t, x, self.p, z)

    def jac(self, t: float, x: np.ndarray) -> Any:
        self.njev += 1
        began = time.perf_counter()
        try:
            if len(x) <= DENSE_JACOBIAN_LIMIT or self.solver == "lsoda":
                out = self.mod.jacobian_dense(t, x, self.p, self.z)
            else:
                out = self.mod.jacobian(t, x, self.p, self.z)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            raise self._fail(err, t, x, "the Jacobian") from err
        self.model_time += time.perf_counter() - began
        if self.z[-1] != 0.0:
            raise self._newton(t, x)
        return out


def simulate_model(model: CompiledModel, options: SimulationOptions = SimulationOptions()
                   ) -> SimulationResult:
    """Integrate ``model`` and return the selected outputs on the output grid."""
    began = time.perf_counter()
    solver = options.solver.lower()
    if solver not in ALL_SOLVERS:
        raise SimulationError(f"unknown solver '{options.solver}'",
                              hint=f"choose one of {', '.join(ALL_SOLVERS)}")
    limits = Limits(options.max_steps, options.time_limit)
    limits.validate()
    start, stop, interval, rtol, atol = resolve(model, options)
    grid = output_grid(start, stop, interval)
    check_parameter_names(model, options.parameters)
    structural = [n for n in options.parameters if n in model.structural]
    if structural:
        raise SimulationError(f"'{structural[0]}' is a structural parameter: changing it "
                              "needs a new compilation",
                              hint="pass it to compile_model(parameters=...) or use "
                              "springc.simulate(files, parameters=...)")
    n = len(model.states)
    if solver == "lsoda" and n > LSODA_LIMIT:
        raise SimulationError(f"lsoda uses dense Jacobians, too large for {n} states",
                              hint="use --solver bdf or radau (sparse Jacobians)")
    size = len(grid) * (len(model.outputs) + n) * 8
    if size > MAX_OUTPUT_BYTES:
        raise SimulationError(
            f"{len(grid)} output times x {len(model.outputs)} variables need "
            f"{size / 1e9:.1f} GB", hint="select variables with --vars (outputs=[...]) or "
            "use a larger --interval")
    note = ""
    if solver in FIXED_STEP:
        step, note = solvers.check_step(solver, options.step, grid, limits.max_steps)
    p = parameter_vector(model, options.parameters)
    if getattr(model.module, "SWITCHABLE", False) and solver not in FIXED_STEP:
        from .switching import simulate_switching_model

        return simulate_switching_model(model, solver, grid, rtol, atol,
                                        dict(options.parameters), limits)
    x0 = initial_state(model, p, start)
    progress = Progress(options.progress, start, stop)
    problem = _Problem(model, p, solver, progress, limits)
    try:
        with np.errstate(all="ignore"):
            if not np.isfinite(x0).all():
                raise _Stop(SimulationError(
                    f"the start values are not finite at time {start}",
                    notes=_state_notes(problem.names, x0, None)))
            reason = ""
            if solver in FIXED_STEP:
                states, steps = solvers.run_fixed(problem, grid, x0, step)
            elif solver == AUTO and len(x0):
                run = _Run(problem, grid, x0, rtol, atol)
                solver, reason = auto(run, start, x0, stop, lambda t, x: solvers.choose(
                    problem.jac(t, x), stop - start))
                states, steps = run.states, run.steps
            else:
                if solver == AUTO:
                    solver, reason = EXPLICIT, "no states to integrate"
                problem.solver = solver
                states, steps = _integrate(problem, grid, x0, rtol, atol)
            outputs = _outputs(model, problem, grid, states)
    except _Stop as stop_:
        raise stop_.error from None
    except OverLimit as over:
        raise over_limit(over, start, stop, problem.jacobian) from None
    finally:
        progress.close()
    stats = SimulationStats(solver, steps, problem.nfev, problem.njev,
                            time.perf_counter() - began, problem.model_time,
                            model.compile_time, model.cached, reason, note)
    units = dict(zip(model.states, model.module.STATE_UNITS))
    units.update(zip(model.observed, model.module.OBSERVED_UNITS))
    names = model.outputs
    return SimulationResult(model.name, grid, names, outputs,
                            tuple(units.get(n, "") for n in names), stats,
                            dict(zip(model.parameter_names, p.tolist())))


def parameter_vector(model: CompiledModel, values: Mapping[str, float]) -> np.ndarray:
    """The generated module's parameter vector with ``values``; every entry finite."""
    try:
        p = np.asarray(model.module.parameters(dict(values)), dtype=float)
    except (ArithmeticError, ValueError) as err:
        where = _code_location(err, str(model.path))
        raise SimulationError(f"{_kind(err)} while computing the parameter "
                              f"{where or 'values'}",
                              hint="check the parameters its binding uses (--set)") from None
    check_parameters(model.parameter_names, p)
    return p


def _integrate(problem: _Problem, grid: np.ndarray, x0: np.ndarray, rtol: float,
               atol: float) -> tuple[np.ndarray, int]:
    """The states on ``grid`` and the number of steps taken (solve_ivp's loop)."""
    run = _Run(problem, grid, x0, rtol, atol)
    if len(x0):
        run.advance(run.start(problem.solver, float(grid[0]), x0))
    return run.states, run.steps


@dataclass(frozen=True)
class Stretch:
    """What :meth:`_Run.advance` measured: steps, wall time, last step sizes."""

    steps: int
    seconds: float
    sizes: tuple[float, ...]


class _Run:
    """The output grid filled step by step, by one integrator after another (the
    ``auto`` race of :mod:`springc.race` hands the state from one to the next)."""

    failure = _Stop

    def __init__(self, problem: _Problem, grid: np.ndarray, x0: np.ndarray, rtol: float,
                 atol: float) -> None:
        self.problem, self.grid, self.rtol, self.atol = problem, grid, rtol, atol
        self.limits = problem.limits
        self.states = np.empty((len(grid), len(x0)))
        self.states[0] = x0
        self.k, self.steps = 1, 0

    @property
    def done(self) -> bool:
        return self.k >= len(self.grid)

    def start(self, solver: str, t: float, y: np.ndarray, first_step: float | None = None
              ) -> Any:
        """A scipy integrator of ``solver`` from ``(t, y)`` to the end of the grid."""
        import scipy.integrate

        self.problem.solver = solver
        kwargs: dict[str, Any] = {"jac": self.problem.jac} if solver in IMPLICIT_SOLVERS else {}
        if first_step is not None:
            kwargs["first_step"] = min(first_step, float(self.grid[-1]) - t)
        cls = getattr(scipy.integrate, SOLVERS[solver])
        return cls(self.problem.rhs, t, y, self.grid[-1], rtol=self.rtol, atol=self.atol,
                   **kwargs)

    @staticmethod
    def both_failed(first: _Stop, second: _Stop) -> _Stop:
        """``first``'s error, with ``second`` (the implicit solver's retry) as a note."""
        error = first.error
        return _Stop(SimulationError(
            error.message, notes=(*error.notes, Note(f"radau, tried next by auto, failed "
                                                     f"too: {second.error.message}")),
            hint=_remedy("radau")))

    def check_limits(self, integrator: Any, steps: int, sizes: deque[float]) -> None:
        """Stop at ``max_steps``, or at once when the current step size would need
        :data:`~springc.simulation.limits.HOPELESS` times as many."""
        limit, t = self.limits.max_steps, float(integrator.t)
        stop = float(self.grid[-1])
        if steps >= limit and t < stop:
            raise OverLimit(f"{steps} steps of {self.problem.solver} reached the step "
                            f"limit (--max-steps {limit})", t, np.array(integrator.y),
                            self.problem.solver)
        projected = projected_steps(steps, t, stop, tuple(sizes))
        if projected > HOPELESS * limit:
            raise OverLimit(f"at its current step size ({float(np.median(sizes)):.3g} s) "
                            f"{self.problem.solver} needs ~{projected:.3g} steps to the "
                            f"stop time, far over the step limit (--max-steps {limit})",
                            t, np.array(integrator.y), self.problem.solver)

    def advance(self, integrator: Any, max_steps: int | None = None) -> Stretch:
        """Step ``integrator`` until the grid is full (or ``max_steps``), filling it."""
        problem, grid, states = self.problem, self.grid, self.states
        began, taken = time.perf_counter(), 0
        sizes: deque[float] = deque(maxlen=10)
        while not self.done and taken != max_steps:
            before = integrator.t
            try:
                message = integrator.step()
            except ValueError as err:  # LU of I - h*J with an overflowing Jacobian
                if "infs or NaNs" not in str(err):
                    raise
                raise _Stop(_solver_failure(problem, integrator, "the Newton matrix is "
                                            "not finite (the Jacobian overflows)")) from None
            taken += 1
            if integrator.status == "failed":
                raise _Stop(_solver_failure(problem, integrator, message))
            sizes.append(integrator.t - before)
            if taken % CHECK_EVERY == 0 or self.steps + taken >= self.limits.max_steps:
                self.check_limits(integrator, self.steps + taken, sizes)
            j = int(np.searchsorted(grid, integrator.t, side="right"))
            if j > self.k:
                dense = integrator.dense_output()
                states[self.k:j] = dense(grid[self.k:j]).T
                if grid[j - 1] == integrator.t:
                    states[j - 1] = integrator.y
                self.k = j
            if integrator.status == "finished" and not self.done:
                states[self.k:] = integrator.y
                self.k = len(grid)
        self.steps += taken
        return Stretch(taken, time.perf_counter() - began, tuple(sizes))


def _outputs(model: CompiledModel, problem: _Problem, grid: np.ndarray,
             states: np.ndarray) -> np.ndarray:
    names = model.outputs
    columns: dict[str, np.ndarray] = {s: states[:, i] for i, s in enumerate(model.states)}
    selected = set(names)
    wanted = [o for o in model.observed if o in selected]
    if wanted:
        z = np.asarray(model.module.guesses(problem.p), dtype=float)
        try:
            obs = model.module.observed_grid(grid, np.ascontiguousarray(states), problem.p, z)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            raise _first_failure(model, problem, grid, states, err) from err
        if z[-1] != 0.0:
            row = int(np.flatnonzero(np.isnan(obs).all(axis=1))[0])
            problem.z[-1] = z[-1]
            raise problem._newton(float(grid[row]), states[row])
        columns.update({o: obs[:, i] for i, o in enumerate(model.observed)})
    out = np.empty((len(grid), len(names)))
    for i, name in enumerate(names):
        out[:, i] = columns[name]
    check_outputs(names, grid, out)
    return out


def _first_failure(model: CompiledModel, problem: _Problem, grid: np.ndarray,
                   states: np.ndarray, err: BaseException) -> _Stop:
    """The failure of the observed variables at the first output time where it occurs
    (``observed_grid`` raised for the whole grid)."""
    z = np.asarray(model.module.guesses(problem.p), dtype=float)
    for row in range(len(grid)):
        try:
            model.module.observed(float(grid[row]), states[row], problem.p, z)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as first:
            return problem._fail(first, float(grid[row]), states[row], "an observed variable")
    return problem._fail(err, float(grid[-1]), states[-1], "an observed variable")


def _solver_failure(problem: _Problem, integrator: Any, message: str | None
                    ) -> SimulationError:
    t, x = float(integrator.t), np.asarray(integrator.y)
    dx = np.asarray(problem.mod.rhs(t, x, problem.p, problem.z))
    collapse = message is not None and "step size" in message.lower()
    text = (f"the step size of {problem.solver} collapsed at time {_fmt(t)}" if collapse
            else f"the {problem.solver} solver failed at time {_fmt(t)}: {message}")
    notes = [Note("fastest-changing states:"), *_state_notes(problem.names, x, dx)]
    return SimulationError(text, notes=notes, hint=_remedy(problem.solver))

