"""The cost model of ``--solver auto``: what a stretch of steps counted -> its work, in
equivalent evaluations of the model's right-hand side.

``auto`` (:mod:`springc.simulation.race`) compares ``dop853`` and ``radau`` by this model,
never by the clock, so that the same files and options choose the same solver in every
run, in any process (and, up to the rounding of step sizes, on any machine). A stretch
reports what its loop counted (:class:`Work`: accepted steps, attempts, right-hand side
and Jacobian evaluations, factorizations where the loop counts them); the model prices
each item in operations and divides by the price of one right-hand side evaluation:

- a right-hand side evaluation: a call (:attr:`Overheads.call`) plus
  :data:`ENTRY_OPERATIONS` per state and per non-zero of the Jacobian (the generated
  code's work grows with the dependencies it computes);
- a Jacobian evaluation: a call plus :data:`ENTRY_OPERATIONS` per non-zero;
- a factorization of radau's two Newton matrices: a call plus
  :func:`springc.integrate.newton_flops` (the band the compiled loop uses; a dense
  LU, ``n^3``-like, for up to 64 states). The compiled loops do not count their
  factorizations: scipy's ``Radau`` factors at most once per attempted step and once
  more after each Jacobian update inside a step, so that sum is the count (an upper
  bound); scipy's loop reports its own (``nlu``);
- the solves of a Newton iteration (radau's evaluations less one per attempt, over
  its 3 stages): a call plus :func:`springc.integrate.newton_solve_flops`;
- each attempted step: the method's vector arithmetic (:data:`EXPLICIT_STEP`,
  :data:`IMPLICIT_STEP` operations per state) and its fixed cost in calls.

The constants were fitted once on the compiled loops (CPython 3.11, numba, the shared
2-core VM, at about 5e9 of these operations per second): they predicted the time of
dop853 and radau on the harmonic oscillator at m = 1e-6 (27 and 320 ms predicted, 28
and 377 measured), the uneven stiff pair at k = 1e8 (290 and 20 ms; 359 and 18), a
10x10 cloth (194 ms and 41 s; 193 ms and 13 s: the bound on factorizations is high
there, which only favours dop853) and a chain of 100 masses (1 ms; 0.98). They are
fixed in the code: a faster machine scales every price alike. On scipy's loop every
call goes through Python (:data:`SCIPY`: some 10 microseconds a call).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

ENTRY_OPERATIONS = 20.0
"""Operations of a right-hand side (or Jacobian) evaluation per state and per non-zero
of the Jacobian."""
EXPLICIT_STEP = 300.0
"""Operations per state of one attempted dop853 step besides its evaluations (12 stages'
weighted sums, the error estimate)."""
IMPLICIT_STEP = 100.0
"""Operations per state of one attempted radau step besides evaluations and solves."""


@dataclass(frozen=True)
class Overheads:
    """The fixed costs of a loop, in operations: ``call`` for each evaluation,
    factorization or solve; ``explicit_step`` and ``implicit_step`` for each attempted
    step (in calls)."""

    call: float
    explicit_step: float
    implicit_step: float


COMPILED = Overheads(1_000.0, 0.0, 5.0)
"""The compiled loops: a model function called through its address (~0.2 us), radau's
step bookkeeping about five such calls."""
SCIPY = Overheads(50_000.0, 3.0, 10.0)
"""scipy's loop: each call and each step is Python (~10 us a call)."""


@dataclass(frozen=True)
class Work:
    """What a stretch of steps counted: accepted ``steps``, ``attempts`` (accepted and
    rejected), right-hand side and Jacobian evaluations, and ``factorizations`` of the
    Newton matrices where the loop counts them (``None``: it does not)."""

    steps: int
    attempts: int
    rhs: int
    jacobians: int = 0
    factorizations: int | None = None


@dataclass(frozen=True)
class StepCosts:
    """The prices of one model on one loop, in operations (see the module text)."""

    states: int
    rhs: float
    jacobian: float
    factorization: float
    solve: float
    overheads: Overheads

    def factorizations(self, work: Work) -> int:
        """The stretch's factorizations: counted, or attempts plus Jacobian updates."""
        if work.factorizations is not None:
            return work.factorizations
        return work.attempts + work.jacobians

    def operations(self, implicit: bool, work: Work) -> float:
        """The operations of ``work`` done by radau (``implicit``) or dop853."""
        calls = self.overheads
        total = work.rhs * self.rhs
        if not implicit:
            return total + work.attempts * (calls.explicit_step * calls.call
                                            + EXPLICIT_STEP * self.states)
        iterations = max(work.rhs - work.attempts, 0) / 3.0
        return (total + work.jacobians * self.jacobian
                + self.factorizations(work) * self.factorization + iterations * self.solve
                + work.attempts * (calls.implicit_step * calls.call
                                   + IMPLICIT_STEP * self.states))

    def evaluations(self, implicit: bool, work: Work) -> float:
        """:meth:`operations` in equivalent right-hand side evaluations."""
        return self.operations(implicit, work) / self.rhs

    def factorization_evaluations(self) -> float:
        """One factorization of radau's Newton matrices, in right-hand side evaluations."""
        return self.factorization / self.rhs


def step_costs(module: Any, compiled: bool) -> StepCosts:
    """The prices for the generated ``module`` (its Jacobian's sparsity) on the compiled
    loop or scipy's."""
    from springc.integrate import newton_flops, newton_solve_flops

    indptr, indices = module.JAC_INDPTR, module.JAC_INDICES
    states, nonzeros = len(indptr) - 1, len(indices)
    overheads = COMPILED if compiled else SCIPY
    call = overheads.call
    return StepCosts(states, call + ENTRY_OPERATIONS * (states + nonzeros),
                     call + ENTRY_OPERATIONS * nonzeros,
                     call + newton_flops(indptr, indices),
                     call + newton_solve_flops(indptr, indices), overheads)
