"""Solver choice and fixed-step runs: generated module + start state -> solver / states.

Two additions to the adaptive scipy solvers of :mod:`springc.simulation`:

- **Fixed-step scene integrators** (``springc.simulation.FIXED_STEP``): ``verlet`` (velocity Verlet)
  and ``symplectic-euler`` (semi-implicit Euler) for second-order mechanical systems,
  and the classical ``rk4``, run by :mod:`springc.integrators` with ``--step H``.
  The position/velocity pairs they need (``der(q) = v`` with ``v`` a state) are found
  from the generated module: a state whose derivative depends structurally on one
  other state only, with slope 1 and no offset (:func:`detect_pairs`; on the ODE
  itself, :func:`pairs_from_ode` reads the ``der(q) := v`` steps directly).
- **``auto``** (the default): explicit ``dop853`` or implicit ``radau`` from a cheap
  stiffness estimate at the start state (:func:`choose`): the spectral radius ``rho``
  of the analytic Jacobian times the span ``T`` (:mod:`springc.stiffness`). For
  small systems (dense eigen-decomposition) the fast modes are also checked for
  *excitation*: an undamped fast oscillation that is actually moving must be resolved
  by any method, so the cheaper explicit steps win even when ``rho * T`` is large;
  only fast modes that are at rest (or die out early in the span) make a problem
  stiff.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
import scipy.sparse as sp

from .errors import Note, SimulationError
from .integrators import NonFiniteState, Pairs, integrate

AUTO = "auto"
EXPLICIT, IMPLICIT = "dop853", "radau"
MAX_FIXED_STEPS = 20_000_000
"""More fixed steps than this are refused up front (minutes of Python loop)."""
FIXED_REMEDY = "reduce --step or use --solver radau"


# ------------------------------------------------------------------ pairs

def pairs_from_ode(system: object) -> list[tuple[str, str]]:
    """``(q, v)`` for every step ``der(q) := v`` of an :class:`springc.ode.ODE` where
    ``v`` is a state too."""
    from .expr import Var
    from .ode import Assign

    states = {s.name for s in system.states}  # type: ignore[attr-defined]
    out = []
    for step in system.steps:  # type: ignore[attr-defined]
        if (isinstance(step, Assign) and step.name.startswith("der(")
                and isinstance(step.expr, Var) and step.expr.name in states):
            q = step.name[4:-1]
            if q in states:
                out.append((q, step.expr.name))
    return _disjoint(out)


def _disjoint(pairs: list[tuple[str, str]] | list[tuple[int, int]]) -> list:
    """Drop chains (``der(a) = b``, ``der(b) = c``): a state is a position or a
    velocity, not both."""
    positions = {q for q, _ in pairs}
    velocities = {v for _, v in pairs}
    return [(q, v) for q, v in pairs if v not in positions and q not in velocities]


def detect_pairs(module: ModuleType, p: np.ndarray, x0: np.ndarray, t0: float) -> Pairs:
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
    good = [(q, v) for q, v in candidates
            if checks and all(d[q] == x[v] for d, x in checks)]
    return Pairs.of(_disjoint(good))


# ------------------------------------------------------------------ auto

@dataclass(frozen=True)
class AutoChoice:
    """The solver ``auto`` picked and why (for the summary line)."""

    solver: str
    reason: str
    spectral_radius: float
    excited_radius: float  # fastest mode that is excited and persists (= rho if unknown)
    span: float


def _modal_excitation(jac: np.ndarray, f0: np.ndarray, span: float, tol: float
                      ) -> float | None:
    """Largest ``|lambda|`` among modes whose amplitude at the start exceeds ``tol``
    and that do not die out before the end of ``span``; ``None`` if undecidable."""
    try:
        lam, vec = np.linalg.eig(jac)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(lam)) or np.linalg.cond(vec) > 1e10:
        return None
    coeff = np.linalg.solve(vec, f0.astype(complex))  # f0 = sum c_i lam_i v_i ...
    size = np.abs(lam)
    # ... so mode i's displacement from its equilibrium is c_i / lam_i (|v_i| = 1).
    with np.errstate(divide="ignore", invalid="ignore"):
        amplitude = np.where(size > 0, np.abs(coeff) / np.where(size > 0, size, 1.0), 0.0)
    decay = np.minimum(lam.real, 0.0) * span
    survives = amplitude * np.exp(np.maximum(decay, -700.0)) > tol
    active = size[survives & (amplitude > tol)]
    return float(active.max()) if active.size else 0.0


def choose(jac: np.ndarray | sp.spmatrix, f0: np.ndarray, x0: np.ndarray, span: float,
           rtol: float, atol: float) -> AutoChoice:
    """``dop853`` or ``radau`` for a run over ``span`` from ``x0`` (``f0 = rhs(x0)``)."""
    from .stiffness import DENSE_LIMIT, STIFF_THRESHOLD, choose_solver

    n = jac.shape[0]
    if n == 0 or span <= 0:
        return AutoChoice(EXPLICIT, "no dynamics to integrate", 0.0, 0.0, span)
    base = choose_solver(jac, span, EXPLICIT, IMPLICIT)
    rho = base.spectral_radius
    if base.solver == EXPLICIT or not math.isfinite(rho) or n > DENSE_LIMIT \
            or not np.all(np.isfinite(f0)):
        return AutoChoice(base.solver, base.reason, rho, rho, span)
    dense = jac.toarray() if sp.issparse(jac) else np.asarray(jac, dtype=float)
    tol = atol + rtol * float(np.max(np.abs(x0), initial=0.0))
    excited = _modal_excitation(dense, f0, span, tol)
    if excited is None or excited * span <= STIFF_THRESHOLD:
        return AutoChoice(IMPLICIT, base.reason, rho, rho if excited is None else excited,
                          span)
    reason = (f"oscillatory: a fast mode (1/{excited:.3g} s) is excited and must be "
              f"resolved over the {span:g} s span by any method; explicit steps are "
              "cheaper")
    return AutoChoice(EXPLICIT, reason, rho, excited, span)


def choose_for(jacobian: Callable[[float, np.ndarray], object],
               rhs: Callable[[float, np.ndarray], np.ndarray], x0: np.ndarray,
               start: float, stop: float, rtol: float, atol: float) -> AutoChoice:
    """:func:`choose` with the generated Jacobian and RHS at the start state (their
    failures there propagate: the integration would stop at the same point)."""
    return choose(jacobian(start, x0), np.asarray(rhs(start, x0), dtype=float), x0,
                  stop - start, rtol, atol)


# ------------------------------------------------------------------ fixed step

def check_step(solver: str, step: float | None, start: float, stop: float,
               intervals: int) -> float:
    """The step of a fixed-step run, validated; errors name the option."""
    if step is None:
        raise SimulationError(f"the fixed-step solver {solver} needs a step size",
                              hint="pass --step H (e.g. a twentieth of the fastest "
                              "period), or use --solver auto")
    if not (math.isfinite(step) and step > 0):
        raise SimulationError(f"the step must be positive and finite, not {step:g}",
                              hint="pass --step H with H > 0")
    steps = intervals + (stop - start) / step
    if steps > MAX_FIXED_STEPS:
        raise SimulationError(f"--step {step:g} over {stop - start:g} s takes {steps:.3g} "
                              f"steps, more than {MAX_FIXED_STEPS:.0e}",
                              hint="use a larger --step, a shorter span, or an adaptive "
                              "solver (--solver auto)")
    return float(step)


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
        result = integrate(problem.solver, problem.rhs, grid, x0, step, pairs)
    except NonFiniteState as err:
        names = [problem.names[i] for i in err.indices]
        notes = [Note(f"{name} is not finite") for name in names[:4]]
        if len(names) > 4:
            notes.append(Note(f"... and {len(names) - 4} more states"))
        raise SimulationError(f"the states became non-finite by time {err.time:.9g} "
                              f"({problem.solver}, --step {step:g})", notes=notes,
                              hint=FIXED_REMEDY) from None
    return result.x, result.steps
