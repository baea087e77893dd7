"""The step loop of a simulation: the generated functions wrapped for scipy
(:class:`Problem`: counting, timing, checking, limits) and the output grid filled step
by step by one integrator after another (:class:`StepLoop`, which ``auto``'s race of
:mod:`springc.simulation.race` drives).

On scipy's engine the integrators are ``scipy.integrate``'s solver classes (``RK45``,
``DOP853``, ``Radau``, ``BDF``, ``LSODA``) stepped one by one, so that springc can show
progress, stop at the first non-finite value, and name the time and the states at
fault; on the compiled engine they are :class:`Stepper` handles run in stretches by
:func:`springc.simulation.compiled.advance_compiled`.
Output is interpolated with each step's dense output exactly on the grid. Implicit
methods get the generated analytic Jacobian: dense for small systems, ``scipy.sparse``
CSC beyond :data:`DENSE_JACOBIAN_LIMIT`.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TextIO

import numpy as np

from ..errors import Note, SimulationError, describe_failure
from ..ir.dae import derivative_name
from ..pipeline import CompiledModel, announce_functions, jacobian_apart
from .assertions import AssertionCheck
from .failures import Stop, code_location, format_time, remedy, state_notes
from .limits import CHECK_EVERY, HOPELESS, Limits, OverBudget, OverLimit, projected_steps
from .solver_names import (
    COMPILED_SOLVERS,
    FIXED_STEP,
    IMPLICIT_SOLVERS,
    RACE_IMPLICIT,
    SOLVERS,
)
from .step_cost import StepCosts, Work, step_costs

DENSE_JACOBIAN_LIMIT = 64
COMPILED_METHODS = frozenset(COMPILED_SOLVERS) - frozenset(FIXED_STEP)
"""Solvers whose integrators ``StepLoop.finish`` runs in a compiled loop."""


class Progress:
    """A progress bar on ``stream``, shown once a run has taken about a second."""

    def __init__(self, stream: TextIO | None, start: float, stop: float,
                 budget: float = math.inf) -> None:
        self.stream, self.start, self.stop = stream, start, stop
        self.began = time.perf_counter()
        self.end = self.began + budget  # past it, an update raises OverBudget
        watched = stream is not None or math.isfinite(budget)
        self.next = self.began + 1.0 if watched else math.inf
        self.shown = False

    def update(self, t: float) -> None:
        now = time.perf_counter()
        if now < self.next:
            return
        self.next = now + 0.1
        if now > self.end:
            raise OverBudget
        if self.stream is None:
            return
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


def warm_slots(module: Any) -> int:
    """How many leading slots of ``z`` hold the Newton warm starts of ``module``."""
    return len(getattr(module, "GUESSES", ()))


class Problem:
    """The generated functions wrapped for scipy: counting, timing, checking.

    The Newton warm starts (the first :func:`warm_slots` slots of ``z``) carry from
    evaluation to evaluation, but only those of an accepted point are kept
    (:attr:`accepted`: the end of an accepted step, the event iteration's consistent
    point): a point a step only tries (its first step's probe, a step rejected or not
    yet cut at an event) may lie on a held branch past an event, where the block has a
    solution far from the one after the event (HeatingNPN_NORGate: the probe of the
    step after the 85 s event at 99.9 s, on V2's falling ramp held past its end at
    90 s, left ``C3.v`` = -11.9 V, from which Newton diverged at 85.01 s). A Newton
    block that does not converge from another warm start is solved again from the
    accepted one (:meth:`retry_warm`)."""

    def __init__(self, model: CompiledModel, p: np.ndarray, solver: str,
                 progress: Progress, limits: Limits | None = None) -> None:
        mod = model.module
        announce_functions(mod, model.path, model.cached)  # before their first call
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
        self.asserts = AssertionCheck(mod, p, self.names)
        self.loop_library: Any = None  # the C loop's, loaded once per run (.native)
        self.trial: np.ndarray | None = None  # z before the step being tried (try_step)
        self.rejected: Stop | None = None
        self.warm = warm_slots(mod)
        self.accepted = self.z[:self.warm].copy()  # warm starts of the last accepted point
        self.step_start = self.accepted  # those of the last accepted step's start

    def accept(self) -> None:
        """The warm starts in ``z`` are those of an accepted point."""
        self.accepted = self.z[:self.warm].copy()

    def restore(self, warm: np.ndarray | None = None) -> None:
        """The warm starts ``warm`` (default: the last accepted point's) back in ``z``."""
        self.z[:self.warm] = self.accepted if warm is None else warm

    def retry_warm(self, warm: np.ndarray) -> bool:
        """After a Newton block did not converge (the flag ``z[-1]`` set): ``z`` gets the
        warm starts ``warm`` and a clear flag, to be evaluated again; False where those
        are the ones that just failed (a block that does not converge keeps its warm
        start: nothing else to try)."""
        n = self.warm
        if not n or np.array_equal(self.z[:n], warm):
            return False
        self.z[:n] = warm
        self.z[-1] = 0.0
        return True

    def fail(self, err: BaseException, t: float, x: np.ndarray, what: str) -> Stop:
        where = code_location(err, self.path)
        message = (f"{describe_failure(err)} while computing {where or what} at time "
                   f"{format_time(t)}")
        if "singular" in str(err).lower():
            message = f"{where or 'a linear system'} is singular at time {format_time(t)}"
        return Stop(SimulationError(
            message, notes=state_notes(self.names, x, None),
            hint="the model leaves the domain of an operation there; check the "
                 "parameters (--set) and start values, or guard the expression"))

    def newton_failure(self, t: float, x: np.ndarray) -> Stop:
        step = int(self.z[-1])
        names = self.mod.NEWTON_SYSTEMS.get(step, ("?",))
        self.z[-1] = 0.0
        return Stop(SimulationError(
            f"the nonlinear system for {', '.join(names)} did not converge at time "
            f"{format_time(t)}", notes=state_notes(self.names, x, None),
            hint="the model may have reached a singular configuration (a rod or "
                 "pendulum at the end of its range?); check the start values"))

    def evaluate(self, t: float, x: np.ndarray) -> Any:
        """The generated ``rhs`` at ``(t, x)``; a Newton block that does not converge
        from the warm starts in ``z`` is solved again from the last accepted point's,
        then from those of the start of the last accepted step (:meth:`retry_warm`):
        an accepted step may end past an event not yet located, on a held branch whose
        solution is far from the one inside the step (HeatingNPN_NORGate: ``C1.v`` =
        -1.39 V at 81.16 s, V1's falling ramp held past its end at 80 s, from which
        Newton cycles at 78.11 s, a stage of the step's dense output)."""
        return self.solved(self.mod.rhs, t, x)

    def solved(self, function: Callable[..., Any], t: float, x: np.ndarray) -> Any:
        """``function(t, x, p, z)`` (the generated ``rhs`` or a Jacobian), evaluated
        again from the accepted warm starts where a Newton block did not converge
        (see :meth:`evaluate`)."""
        out = function(t, x, self.p, self.z)
        for warm in (self.accepted, self.step_start):
            if self.z[-1] == 0.0 or not self.retry_warm(warm):
                continue
            out = function(t, x, self.p, self.z)
        return out

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        self.nfev += 1
        began = time.perf_counter()
        try:
            dx = self.evaluate(t, x)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            failure = self.fail(err, t, x, "the derivatives")
            if self.trial is None:
                raise failure from err
            self.z[:] = self.trial  # the step is rejected (see try_step)
            self.rejected = self.rejected or failure
            return np.full(len(x), math.nan)
        now = time.perf_counter()
        self.model_time += now - began
        if now > self.deadline:
            raise OverLimit(f"{self.limits.time_limit:g} s of wall clock reached the time "
                            "limit (--time-limit)", t, np.array(x), self.solver)
        if self.z[-1] != 0.0:
            failure = self.newton_failure(t, x)
            if self.trial is None:
                raise failure
            # at a point a step tries: the step is rejected (NaN), the guesses restored
            self.z[:] = self.trial
            self.rejected = failure
            return np.full(len(x), math.nan)
        # a sum is finite if every term is (a finite sum that overflows is checked again)
        if not math.isfinite(dx.sum()) and not np.isfinite(dx).all():
            if self.trial is not None:  # the step is rejected (see try_step)
                self.z[:] = self.trial
                if self.rejected is None:
                    self.rejected = self.explain(t, np.array(x))
                return np.asarray(dx)
            raise self.explain(t, np.asarray(x))
        if now >= self.progress.next:
            self.progress.update(t)
        return np.asarray(dx)

    def try_step(self, integrator: Any) -> str | None:
        """``integrator.step()`` (scipy's), where a nonlinear system that does not
        converge or derivatives that are not finite at a point the step tries reject
        the step, which scipy retries smaller (a semiconductor's thermal loop has no
        solution, a transistor's held exponential branch overflows, far past the point
        where it switches), as established tools do; where the step then fails, the
        run stops with that failure."""
        start = self.trial = np.array(self.z)
        self.rejected = None
        try:
            message: str | None = integrator.step()
        finally:
            self.trial = None
        if integrator.status == "failed" and self.rejected is not None:
            raise self.rejected
        if integrator.status != "failed":  # z holds the accepted end's warm starts
            self.step_start = start[:self.warm]
            self.accept()
        return message

    def dense_output(self, integrator: Any) -> Any:
        """``integrator.dense_output()`` (DOP853's evaluates three more stages inside
        the step), with ``z`` keeping the accepted end's warm starts."""
        dense = integrator.dense_output()
        self.restore()
        return dense

    def start(self, make: Callable[[], Any], t: float, x: np.ndarray) -> Any:
        """scipy's integrator ``make()`` from the accepted point ``(t, x)``: the probe
        its first step size takes (``select_initial_step`` evaluates at ``t + h0``, up
        to the next event, far from ``t`` where the states barely move) is a point a
        step tries, as in :meth:`try_step`: where it fails, the probe is NaN, the
        step size comes from ``t`` alone and the first step is rejected smaller (a
        transistor's Newton system, warm started 20 s before, has no converging
        iterate there). The evaluation at ``(t, x)`` itself must succeed. Whatever the
        probe's Newton blocks converged to, ``z`` keeps the accepted warm starts (the
        event iteration's, :meth:`accept`)."""
        self.trial, self.rejected = np.array(self.z), None
        try:
            integrator = make()
            failed = self.rejected is not None
        finally:
            self.trial, self.rejected = None, None
            self.restore()  # the probe's warm starts are not an accepted point's
        if failed:  # the probe or (t, x) itself (scipy's BDF and LSODA keep no f)
            self.rhs(t, np.asarray(x))  # raises the located failure at (t, x)
        return integrator

    def non_finite(self, t: float, x: np.ndarray, dx: np.ndarray) -> Stop:
        """The error of derivatives ``dx`` that are NaN or infinite at ``(t, x)``."""
        bad = [self.names[i] for i in np.flatnonzero(~np.isfinite(dx))]
        shown = ", ".join(derivative_name(n) for n in bad[:3])
        shown += ", ..." if len(bad) > 3 else ""
        what = "NaN" if np.isnan(dx).any() else "infinite"
        return Stop(SimulationError(
            f"{shown} {'is' if len(bad) == 1 else 'are'} {what} at time {format_time(t)}",
            notes=state_notes(self.names, x, dx), hint=remedy(self.solver)))

    def locate(self, function: Any, t: float, x: np.ndarray, what: str) -> Stop | None:
        """The error of ``function``'s Python original (``py_func`` of a numba function,
        a python module's function itself: the C loop's model) at ``(t, x)`` on Python
        floats, where it raises (a division by zero, a square root of a negative
        number...), naming the line; ``None`` where it does not."""
        original = getattr(function, "py_func", None)
        # (a python module's function takes arrays and computes on Python floats itself)
        args = (x.tolist(), self.p.tolist()) if original is not None \
            else (np.array(x, dtype=float), np.array(self.p, dtype=float))
        try:
            with np.errstate(all="ignore"):
                (original or function)(t, *args, np.array(self.z))
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            return self.fail(err, t, x, what)
        except TypeError:  # vectorised code needs arrays: no location then
            return None
        return None

    def explain(self, t: float, x: np.ndarray) -> Stop:
        """The error of a compiled evaluation at ``(t, x)`` that returned a non-finite
        derivative: where the numba function has a Python original (``py_func``), it is
        run on Python floats, as the python backend runs, so that an operation leaving
        its domain is named with its source line; otherwise the derivatives at fault."""
        located = self.locate(self.mod.rhs, t, x, "the derivatives")
        if located is not None:
            return located
        with np.errstate(all="ignore"):
            dx = np.asarray(self.mod.rhs(t, x, self.p, np.array(self.z)), dtype=float)
        return self.non_finite(t, x, dx)

    def jacobian(self, t: float, x: np.ndarray) -> Any:
        """The Jacobian for diagnostics: not counted, no failure checks."""
        jacobian_apart(self.mod)  # at its first use, compiled apart (springc simulate)
        z = np.array(self.z)
        return self.mod.jacobian_dense(t, x, self.p, z) if len(x) <= DENSE_JACOBIAN_LIMIT \
            else self.mod.jacobian(t, x, self.p, z)

    def jac(self, t: float, x: np.ndarray) -> Any:
        self.njev += 1
        jacobian_apart(self.mod)  # at its first use, compiled apart (springc simulate)
        began = time.perf_counter()
        try:
            dense = len(x) <= DENSE_JACOBIAN_LIMIT or self.solver == "lsoda"
            out = self.solved(self.mod.jacobian_dense if dense else self.mod.jacobian, t, x)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            raise self.fail(err, t, x, "the Jacobian") from err
        self.model_time += time.perf_counter() - began
        if self.z[-1] != 0.0:
            raise self.newton_failure(t, x)
        return out


def integrate(problem: Problem, grid: np.ndarray, x0: np.ndarray, rtol: float,
              atol: float, finish: Finish | None = None) -> StepLoop:
    """The step loop run over ``grid`` (solve_ivp's loop, or the compiled one with
    ``finish``: see :class:`StepLoop`): its states on the grid and its steps."""
    run = StepLoop(problem, grid, x0, rtol, atol, finish)
    if len(x0):
        run.advance(run.start(problem.solver, float(grid[0]), x0))
    return run


@dataclass(frozen=True)
class Stretch:
    """What :meth:`StepLoop.advance` counted (its :class:`Work`: steps, evaluations...)
    and the last step sizes (no wall time: ``auto`` decides from counts)."""

    work: Work
    sizes: tuple[float, ...]

    @property
    def steps(self) -> int:
        """Accepted steps."""
        return self.work.steps


@dataclass
class Stepper:
    """An integrator of the compiled engine: its method, where it is and its next step
    size (each :meth:`StepLoop.advance` runs the compiled loop from there and moves it)."""

    method: str  # one of COMPILED_METHODS
    t: float
    y: np.ndarray
    h_abs: float  # 0: the compiled loop selects the first step (as scipy does)


Finish = Callable[["StepLoop", Stepper, "int | None"], Stretch]
"""``finish(loop, stepper, max_steps)``: run ``stepper`` in its compiled loop until the
end of ``loop``'s grid or ``max_steps`` steps (rejected ones included), filling the grid
(``springc.simulation.compiled.advance_compiled``)."""


class StepLoop:
    """The output grid filled step by step, by one integrator after another (the
    ``auto`` race of :mod:`springc.simulation.race` hands the state from one to the next).

    With ``finish`` (the compiled engine) the integrators of methods with a compiled loop
    are :class:`Stepper` handles that ``finish`` runs; without it, scipy's integrators
    stepped from Python.
    """

    failure = Stop

    def __init__(self, problem: Problem, grid: np.ndarray, x0: np.ndarray, rtol: float,
                 atol: float, finish: Finish | None = None) -> None:
        self.problem, self.grid, self.rtol, self.atol = problem, grid, rtol, atol
        self.limits = problem.limits
        self.states = np.empty((len(grid), len(x0)))
        self.states[0] = x0
        self.k, self.steps = 1, 0
        self.finish = finish
        self.compiled_steps = 0
        self.loop_time = 0.0  # seconds in the compiled loop
        self._costs: StepCosts | None = None

    @property
    def done(self) -> bool:
        return self.k >= len(self.grid)

    def costs(self) -> StepCosts:
        """The prices of ``auto``'s cost model for this model on this loop
        (:mod:`springc.simulation.step_cost`)."""
        if self._costs is None:
            self._costs = step_costs(self.problem.mod, self.compiled)
        return self._costs

    @property
    def compiled(self) -> bool:
        """Whether the loop runs its integrators compiled (``auto`` probes differently)."""
        return self.finish is not None

    def start(self, solver: str, t: float, y: np.ndarray, first_step: float | None = None
              ) -> Any:
        """An integrator of ``solver`` from ``(t, y)`` to the end of the grid: scipy's, or
        on the compiled engine a :class:`Stepper` (whose first call selects the first
        step as scipy does, where ``first_step`` is None)."""
        self.problem.solver = solver
        first = None if first_step is None else min(first_step, float(self.grid[-1]) - t)
        if self.finish is not None and solver in COMPILED_METHODS:
            self.problem.rhs(t, y)  # a start state the model cannot evaluate fails here,
            # as scipy's integrators fail on their first evaluation (auto tries no other)
            return Stepper(solver, float(t), np.array(y, dtype=float), first or 0.0)
        return self.scipy_start(solver, t, y, first)

    def scipy_start(self, solver: str, t: float, y: np.ndarray, first: float | None = None
                    ) -> Any:
        """scipy's integrator of ``solver`` from ``(t, y)`` (also where the compiled loop
        finds no first step, at extreme values: scipy's steps word that failure)."""
        import scipy.integrate

        self.problem.solver = solver
        kwargs: dict[str, Any] = {"jac": self.problem.jac} if solver in IMPLICIT_SOLVERS else {}
        if first is not None:
            kwargs["first_step"] = first
        cls = getattr(scipy.integrate, SOLVERS[solver])
        return cls(self.problem.rhs, t, y, self.grid[-1], rtol=self.rtol, atol=self.atol,
                   **kwargs)

    @staticmethod
    def both_failed(first: Stop, second: Stop) -> Stop:
        """``first``'s error, with ``second`` (the implicit solver's retry) as a note."""
        error = first.error
        return Stop(SimulationError(
            error.message, notes=(*error.notes, Note(f"{RACE_IMPLICIT}, tried next by auto, failed "
                                                     f"too: {second.error.message}")),
            hint=remedy(RACE_IMPLICIT)))

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
        """Step ``integrator`` until the grid is full (or ``max_steps``), filling it (a
        :class:`Stepper` in its compiled loop, see :attr:`finish`)."""
        if isinstance(integrator, Stepper):
            self.problem.solver = integrator.method
            if self.done or self.finish is None:
                return Stretch(Work(0, 0, 0), ())
            return self.finish(self, integrator, max_steps)
        problem, grid, states = self.problem, self.grid, self.states
        problem.solver = next((name for name, cls in SOLVERS.items()
                               if cls == type(integrator).__name__), problem.solver)
        taken, nfev, njev = 0, problem.nfev, problem.njev
        nlu = int(getattr(integrator, "nlu", 0))
        sizes: deque[float] = deque(maxlen=10)
        while not self.done and taken != max_steps:
            before = integrator.t
            try:
                message = problem.try_step(integrator)
            except ValueError as err:  # LU of I - h*J with an overflowing Jacobian
                if "infs or NaNs" not in str(err):
                    raise
                raise Stop(solver_failure(problem, float(integrator.t), np.asarray(integrator.y),
                                          "the Newton matrix is not finite (the "
                                          "Jacobian overflows)")) from None
            taken += 1
            if integrator.status == "failed":
                raise Stop(solver_failure(problem, float(integrator.t),
                                          np.asarray(integrator.y), message))
            sizes.append(integrator.t - before)
            if problem.asserts:
                problem.asserts.step(float(integrator.t), integrator.y, problem.z,
                                     float(before), integrator.dense_output)
            if taken % CHECK_EVERY == 0 or self.steps + taken >= self.limits.max_steps:
                self.check_limits(integrator, self.steps + taken, sizes)
            j = int(np.searchsorted(grid, integrator.t, side="right"))
            if j > self.k:
                dense = problem.dense_output(integrator)
                states[self.k:j] = dense(grid[self.k:j]).T
                if grid[j - 1] == integrator.t:
                    states[j - 1] = integrator.y
                self.k = j
            if integrator.status == "finished" and not self.done:
                states[self.k:] = integrator.y
                self.k = len(grid)
        self.steps += taken
        # (scipy's step() retries a rejected step inside: its attempts are its steps)
        work = Work(taken, taken, problem.nfev - nfev, problem.njev - njev,
                    int(getattr(integrator, "nlu", 0)) - nlu)
        return Stretch(work, tuple(sizes))


def solver_failure(problem: Problem, t: float, x: np.ndarray, message: str | None
                   ) -> SimulationError:
    """The error of a solver that failed at ``(t, x)`` (its last accepted state)."""
    dx = np.asarray(problem.mod.rhs(t, x, problem.p, problem.z))
    collapse = message is not None and "step size" in message.lower()
    text = (f"the step size of {problem.solver} collapsed at time {format_time(t)}" if collapse
            else f"the {problem.solver} solver failed at time {format_time(t)}: {message}")
    notes = [Note("fastest-changing states:"), *state_notes(problem.names, x, dx)]
    return SimulationError(text, notes=notes, hint=remedy(problem.solver))
