"""One algebraic loop (a BLT block) -> tearing variables, residuals and inner order.

The loop's unknowns are the variables matched to its equations; every other variable
an equation contains was computed by an earlier block and counts as known. Tearing
picks *tearing variables* (iterated by a solver) so that the other unknowns can be
computed one by one, each explicitly from one *inner* equation; the equations left
over are the *residuals* the solver drives to zero.

The heuristic follows Cellier's (as described for Dymola and OpenModelica):

1. variables that no equation can be solved for are torn first (they must be);
2. causalize: while an equation has a single unknown left and is solvable for it,
   compute that unknown from it; an equation with no unknowns left is a residual;
3. when stuck, tear the unknown that would make the most equations causalizable at
   once (equations with two unknowns, solvable for the other), then the one in the
   most equations, then the smallest index; go to 2.

Cost: O(nnz log n) heap work plus O(sum of squared equation sizes) bookkeeping, and
at most a few ``solvable`` calls per (equation, variable) pair (results are cached).
"""

from __future__ import annotations

import heapq
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from .graph import Incidence
from .matching import UNMATCHED, Matching

Solvable = Callable[[int, int], bool]
"""``solvable(eq, var)``: whether ``var`` can be computed explicitly from ``eq``."""


@dataclass(frozen=True, slots=True)
class Tearing:
    """The tearing of one loop, in global equation and variable indices.

    ``inner`` lists (equation, variable) pairs in computation order: each variable is
    computed from its equation given the tearing variables and the earlier pairs.
    ``residual_equations`` has as many entries as ``tearing_variables``.
    """

    tearing_variables: tuple[int, ...]
    residual_equations: tuple[int, ...]
    inner: tuple[tuple[int, int], ...]


def tear(
    block_equations: Sequence[int],
    incidence: Incidence,
    matching: Matching,
    solvable: Solvable,
) -> Tearing:
    """Tear the loop formed by ``block_equations``.

    ``matching`` must match each block equation to a variable it contains (e.g. the
    perfect matching BLT was computed with); those variables are the loop's unknowns.
    Inner pairs are always solvable pairs and the inner order is acyclic.
    """
    equations = list(block_equations)
    unknowns = [_matched_variable(e, incidence, matching) for e in equations]
    state = _State(equations, unknowns, incidence, solvable)
    state.run()
    return Tearing(
        tearing_variables=tuple(unknowns[v] for v in state.tearing),
        residual_equations=tuple(equations[e] for e in state.residuals),
        inner=tuple((equations[e], unknowns[v]) for e, v in state.inner),
    )


def _matched_variable(eq: int, incidence: Incidence, matching: Matching) -> int:
    var = matching.eq_to_var[eq]
    if var == UNMATCHED or var not in incidence[eq]:
        raise ValueError(f"equation {eq} is not matched to a variable it contains")
    return var


class _State:
    """Mutable bookkeeping of one tearing run, in local indices (position in the block)."""

    def __init__(
        self,
        equations: list[int],
        unknowns: list[int],
        incidence: Incidence,
        solvable: Solvable,
    ) -> None:
        local = {var: j for j, var in enumerate(unknowns)}
        if len(local) != len(unknowns):
            raise ValueError("two block equations are matched to the same variable")
        self.equations = equations
        self.unknowns = unknowns
        self.eq_vars = [
            list(dict.fromkeys(local[v] for v in incidence[e] if v in local)) for e in equations
        ]
        self.var_eqs: list[list[int]] = [[] for _ in unknowns]
        for i, vars_ in enumerate(self.eq_vars):
            for j in vars_:
                self.var_eqs[j].append(i)
        self._solvable = solvable
        self._cache: dict[tuple[int, int], bool] = {}
        self.remaining = [len(vars_) for vars_ in self.eq_vars]
        self.known = [False] * len(unknowns)
        self.done = [False] * len(equations)
        self.credits: list[list[int]] = [[] for _ in equations]
        self.enabling = [0] * len(unknowns)
        self.heap: list[tuple[int, int, int]] = []
        self.queue: deque[int] = deque()
        self.tearing: list[int] = []
        self.residuals: list[int] = []
        self.inner: list[tuple[int, int]] = []

    def solvable(self, i: int, j: int) -> bool:
        """Cached ``solvable`` in local indices."""
        key = (i, j)
        if key not in self._cache:
            self._cache[key] = bool(self._solvable(self.equations[i], self.unknowns[j]))
        return self._cache[key]

    def run(self) -> None:
        """Fill ``tearing``, ``residuals`` and ``inner``."""
        # Step 1: tear every variable that no equation can be solved for.
        for j, eqs in enumerate(self.var_eqs):
            if not any(self.solvable(i, j) for i in eqs):
                self.tearing.append(j)
                self.known[j] = True
        for i in range(len(self.equations)):
            self.remaining[i] = sum(not self.known[j] for j in self.eq_vars[i])
            self._on_remaining_changed(i)
        for j in range(len(self.unknowns)):
            self._push(j)
        # Step 2: alternate causalization and choosing a tearing variable.
        while True:
            self._causalize()
            torn = self._pop_candidate()
            if torn is None:
                break
            self.tearing.append(torn)
            self._mark_known(torn)
        assert len(self.tearing) == len(self.residuals), "tearing left equations unassigned"

    def _causalize(self) -> None:
        """Solve equations with one unknown left while any is solvable for it."""
        while self.queue:
            i = self.queue.popleft()
            if self.done[i] or self.remaining[i] != 1:
                continue
            j = next(j for j in self.eq_vars[i] if not self.known[j])
            if self.solvable(i, j):
                self.done[i] = True
                self.inner.append((i, j))
                self._mark_known(j)

    def _mark_known(self, j: int) -> None:
        self.known[j] = True
        for i in self.var_eqs[j]:
            if not self.done[i]:
                self.remaining[i] -= 1
                self._on_remaining_changed(i)

    def _on_remaining_changed(self, i: int) -> None:
        """Update the queue, residuals and tearing scores after equation ``i`` changed."""
        for j in self.credits[i]:
            self.enabling[j] -= 1
            self._push(j)
        self.credits[i] = []
        if self.remaining[i] == 0:
            self.done[i] = True
            self.residuals.append(i)
        elif self.remaining[i] == 1:
            self.queue.append(i)
        elif self.remaining[i] == 2:
            first, second = (j for j in self.eq_vars[i] if not self.known[j])
            for torn, other in ((first, second), (second, first)):
                if self.solvable(i, other):
                    self.credits[i].append(torn)
                    self.enabling[torn] += 1
                    self._push(torn)

    def _push(self, j: int) -> None:
        if not self.known[j]:
            heapq.heappush(self.heap, (-self.enabling[j], -len(self.var_eqs[j]), j))

    def _pop_candidate(self) -> int | None:
        """The best unknown to tear, skipping stale heap entries; None when all are known."""
        while self.heap:
            score, _, j = heapq.heappop(self.heap)
            if not self.known[j] and -score == self.enabling[j]:
                return j
        return None
