"""Solver choice and fixed-step runs: generated module + start state -> solver / states.

Two additions to the adaptive scipy solvers of :mod:`springc.simulation`:

- **Fixed-step scene integrators** (``solver_names.FIXED_STEP``): ``verlet`` (velocity Verlet)
  and ``symplectic-euler`` (semi-implicit Euler) for second-order mechanical systems,
  and the classical ``rk4``, run by :mod:`springc.simulation.integrators` with ``--step H``.
  The position/velocity pairs they need (``der(q) = v`` with ``v`` a state) are found
  from the generated module: a state whose derivative depends structurally on one
  other state only, with slope 1 and no offset (:func:`detect_pairs`; on the ODE
  itself, :func:`pairs_from_ode` reads the ``der(q) := v`` steps directly).
- **``auto``** (the default, run by :mod:`springc.simulation.race`): ``dop853`` unless a run
  turns out long *and* a cheap stiffness estimate is large: the spectral radius
  ``rho`` of the analytic Jacobian times the remaining span ``T``
  (:mod:`springc.simulation.stiffness`, :func:`choose`). Even then the estimate alone cannot
  tell: a stiff spring whose fast mode stays at rest costs an explicit method
  nothing, an excited one costs every method, and per-step costs differ by solver;
  so the two methods race for a few steps and the one whose projected remaining
  work is lower finishes the run (work counted, not timed:
  :mod:`springc.simulation.step_cost`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from ..errors import Note, SimulationError
from ..ir import dae, ode
from ..ir.expr import Var
from .integrators import NonFiniteState, Pairs, integrate
from .solver_names import EXPLICIT, RACE, RACE_IMPLICIT

if TYPE_CHECKING:
    from scipy.sparse import spmatrix

T = TypeVar("T")

FIXED_REMEDY = "reduce --step or use --solver radau"


# ------------------------------------------------------------------ pairs

def pairs_from_ode(system: ode.ODE) -> list[tuple[str, str]]:
    """``(q, v)`` for every step ``der(q) := v`` of an :class:`springc.ode.ODE` where
    ``v`` is a state too."""
    states = {s.name for s in system.states}
    out = []
    for step in system.steps:
        if isinstance(step, ode.Assign) and isinstance(step.expr, Var) \
                and step.expr.name in states:
            q = dae.derivative_base(step.name)
            if q in states:
                out.append((q, step.expr.name))
    return _disjoint(out)


def _disjoint(pairs: list[tuple[T, T]]) -> list[tuple[T, T]]:
    """Drop chains (``der(a) = b``, ``der(b) = c``): a state is a position or a
    velocity, not both."""
    positions = {q for q, _ in pairs}
    velocities = {v for _, v in pairs}
    return [(q, v) for q, v in pairs if v not in positions and q not in velocities]


def detect_pairs(module: Any, p: np.ndarray, x0: np.ndarray, t0: float) -> Pairs:
    """Position/velocity pairs of a generated module, from its Jacobian sparsity.

    Row ``i`` qualifies if its only structural non-zero is column ``j != i`` and
    ``rhs_i == x_j`` at the start and at a perturbed state and time.
    """
    rows = np.asarray(module.JAC_ROWS, dtype=np.int64)
    cols = np.asarray(module.JAC_COLS, dtype=np.int64)
    n = len(x0)
    if n == 0:
        return Pairs.of([])
    count = np.bincount(rows, minlength=n)
    col_of = np.full(n, -1, dtype=np.int64)
    col_of[rows] = cols
    candidates = [(i, int(col_of[i])) for i in np.flatnonzero(count == 1)
                  if col_of[i] != i]
    if not candidates:
        return Pairs.of([])
    rng = np.random.default_rng(0)
    probe = x0 + (0.1 + np.abs(x0)) * rng.uniform(0.01, 0.02, n)
    checks = []
    for t, x in ((t0, x0), (t0 + 0.5, probe)):
        try:
            with np.errstate(all="ignore"):
                z = np.asarray(module.guesses(p), dtype=float)
                checks.append((np.asarray(module.rhs(t, x, p, z), dtype=float), x))
        except (ArithmeticError, ValueError, np.linalg.LinAlgError):
            continue
    good = [(int(q), v) for q, v in candidates
            if checks and all(d[q] == x[v] for d, x in checks)]
    return Pairs.of(_disjoint(good))


# ------------------------------------------------------------------ auto

@dataclass(frozen=True)
class AutoChoice:
    """What ``auto`` decided at the start state and why (for the summary line):
    ``dop853``, ``radau``, or :data:`RACE` (measure both, see :mod:`springc.simulation.race`)."""

    solver: str
    reason: str
    spectral_radius: float
    span: float


def choose(jac: np.ndarray | spmatrix, span: float) -> AutoChoice:
    """``dop853`` if ``rho * span`` is small, else a race (``radau`` outright if the
    Jacobian is not finite)."""
    from .stiffness import choose_solver

    if jac.shape[0] == 0 or span <= 0:
        return AutoChoice(EXPLICIT, "no dynamics to integrate", 0.0, span)
    base = choose_solver(jac, span, EXPLICIT, RACE_IMPLICIT)
    rho = base.spectral_radius
    if base.solver == EXPLICIT or not math.isfinite(base.stiffness):
        return AutoChoice(base.solver, base.reason, rho, span)
    return AutoChoice(RACE, base.reason, rho, span)


# ------------------------------------------------------------------ fixed step

def check_step(solver: str, step: float | None, grid: np.ndarray, max_steps: int
               ) -> tuple[float, str]:
    """The step of a fixed-step run, validated (errors name the option), and a note
    when the run cannot take it exactly.

    The fixed-step solvers land on every output time, so each output interval is
    split into whole steps: a step longer than the interval is refused, and one that
    does not divide it is shortened to the next divisor, which the note says.
    """
    if step is None:
        raise SimulationError(f"the fixed-step solver {solver} needs a step size",
                              hint="pass --step H (e.g. a twentieth of the fastest "
                              "period), or use --solver auto")
    if not (math.isfinite(step) and step > 0):
        raise SimulationError(f"the step must be positive and finite, not {step:g}",
                              hint="pass --step H with H > 0")
    spans = np.diff(grid)
    interval = float(spans[0])
    if step > float(spans.max()) * (1 + 1e-9):
        raise SimulationError(
            f"--step {step:g} is longer than the output interval {interval:g}: the "
            f"fixed-step solvers step to every output time",
            hint=f"use a step that divides the interval (--step {interval:g} or smaller), "
                 f"or an output interval that is a multiple of the step (--interval "
                 f"{step:g})")
    counts = np.maximum(1, np.ceil(spans / step - 1e-9))
    steps = float(counts.sum())
    if steps > max_steps:
        raise SimulationError(f"--step {step:g} over {float(grid[-1] - grid[0]):g} s takes "
                              f"{steps:.3g} steps, more than {max_steps:.0e} (--max-steps)",
                              hint="use a larger --step, a shorter span, or an adaptive "
                              "solver (--solver auto)")
    taken = spans / counts
    note = ""
    if np.any(np.abs(taken - step) > 1e-9 * step):
        note = (f"--step {step:g} does not divide the output interval {interval:g}; "
                f"{solver} took steps of {float(taken.min()):.6g} s"
                + (f" to {float(taken.max()):.6g} s" if taken.max() - taken.min()
                   > 1e-9 * step else "") + " to land on every output time")
    return float(step), note


def run_fixed(problem: Any, grid: np.ndarray, x0: np.ndarray, step: float
              ) -> tuple[np.ndarray, int]:
    """The states on ``grid`` and the number of steps of ``problem.solver``.

    ``problem`` is the simulation's wrapper (``rhs``, ``mod``, ``p``, ``names``): a
    non-finite derivative stops the run at that step (its ``rhs`` check); a state
    that overflows stops it at the next output time, naming the states at fault.
    """
    if len(x0) == 0:
        return np.tile(x0, (len(grid), 1)), 0
    pairs = detect_pairs(problem.mod, problem.p, x0, float(grid[0]))
    try:
        checks = problem.asserts
        after = (lambda t, x: checks.step(t, x, problem.z)) if checks else None
        result = integrate(problem.solver, problem.rhs, grid, x0, step, pairs, after)
    except NonFiniteState as err:
        raise non_finite_states(problem, err.time, err.indices, step) from None
    return result.x, result.steps


def non_finite_states(problem: Any, t: float, indices: Sequence[int] | np.ndarray,
                      step: float) -> SimulationError:
    """The error of a fixed-step run whose states ``indices`` are not finite at the
    output time ``t``."""
    names = [problem.names[i] for i in indices]
    notes = [Note(f"{name} is not finite") for name in names[:4]]
    if len(names) > 4:
        notes.append(Note(f"... and {len(names) - 4} more states"))
    return SimulationError(f"the states became non-finite by time {t:.9g} "
                           f"({problem.solver}, --step {step:g})", notes=notes,
                           hint=FIXED_REMEDY)
