"""Dynamic state selection: flat.FlatModel + current values -> a new ODE and its states.

Index reduction (:mod:`springc.simplify.index_reduction`) turns some derivatives into
algebraic *dummy* derivatives; the choice is valid while the Jacobian blocks it solves stay regular.
For a rod between two masses the coordinate solved from ``|p2 - p1| = l`` can be
``p2.x`` only while the rod is not vertical: any static choice fails somewhere.
Modelica tools then switch states during the simulation; this module does it:

1. :func:`select_states` simplifies the model, by default as ``simplify`` does, or
   with ``at=values`` for the best-conditioned choice at those values, and wraps the
   ODE with what the monitor needs (:class:`StateChoice`).
2. :func:`conditioning` measures the current choice at given values: for each
   dummy-derivative block with alternatives, the smallest singular value of the
   Jacobian block of the current dummies divided by that of the best choice at these
   values (:func:`springc.simplify.index_reduction.pivoted_choice`); the minimum over
   blocks. It is about 1 right after a (re)selection and falls to 0 at the singularity.
   :func:`needs_switch` compares it with a threshold (:data:`THRESHOLD`).
3. :func:`switch` reselects at the current values and :func:`state_vector` maps the
   values (which satisfy all constraints, since the old ODE solved them) onto the new
   states: the restart is consistent without any projection.

The driver that integrates with these (``solve_ivp`` and a conditioning event) is
:mod:`springc.simulation.switching`.

Hysteresis: the new choice has conditioning about 1 (it is the best one) and the
threshold is well below the ratio at which
:func:`~springc.simplify.index_reduction.pivoted_choice` prefers another choice, so a
switch never triggers another at once.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..ir import expr as x
from ..ir import flat, ode
from .index_reduction import DummyBlock, pivoted_choice
from .isolate import free_variables, partial
from .passes import simplify
from .static_choice import THRESHOLD


@dataclass(frozen=True)
class MonitoredBlock:
    """A dummy-derivative block prepared for :func:`conditioning`: ``entries`` are
    the non-zero ``(row, candidate, d(equation)/d(candidate))``; ``chosen`` the
    candidate positions of the current dummies."""

    size: int
    candidates: tuple[str, ...]
    tiers: tuple[int, ...]
    entries: tuple[tuple[int, int, x.Expr], ...]
    chosen: tuple[int, ...]


@dataclass(frozen=True)
class StateChoice:
    """An ODE together with the blocks its choice of states relies on."""

    ode: ode.ODE
    blocks: tuple[MonitoredBlock, ...]

    @property
    def states(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.ode.states)


def select_states(model: flat.FlatModel, at: Mapping[str, float] | None = None
                  ) -> StateChoice:
    """``simplify(model, at)`` with the monitor data of its dummy-derivative blocks."""
    simplified = simplify(model, at)
    return StateChoice(simplified.ode, tuple(_monitored(b) for b in simplified.blocks
                                             if b.switchable))


def _monitored(block: DummyBlock) -> MonitoredBlock:
    entries = []
    for i, e in enumerate(block.equations):
        present = free_variables(e)
        for j, name in enumerate(block.candidates):
            if name in present:
                d = partial(e, name)
                if d != x.ZERO:
                    entries.append((i, j, d))
    position = {name: j for j, name in enumerate(block.candidates)}
    return MonitoredBlock(len(block.equations), block.candidates, block.tiers,
                          tuple(entries), tuple(position[d] for d in block.dummies))


def conditioning(choice: StateChoice, values: Mapping[str, float], time: float = 0.0
                 ) -> float:
    """How well the current states suit ``values`` (see step 2 of the module
    docstring): 1 for the best choice, towards 0 near its singularity; 1 when there is
    nothing to choose. ``values`` must hold the variables the ODE's steps compute
    (e.g. :meth:`OdeEvaluator.values`); names missing from it count as 0."""
    worst = 1.0
    for block in choice.blocks:
        jac = np.zeros((block.size, len(block.candidates)))
        for i, j, e in block.entries:
            jac[i, j] = _evaluate(e, values, time)
        if not np.all(np.isfinite(jac)):
            return 0.0
        best = pivoted_choice(jac, block.tiers)
        if best is None:
            return 0.0
        reference = _smallest_singular_value(jac[:, best])
        if reference > 0.0:
            current = _smallest_singular_value(jac[:, list(block.chosen)])
            worst = min(worst, current / reference)
    return worst


def needs_switch(choice: StateChoice, values: Mapping[str, float],
                 threshold: float = THRESHOLD, time: float = 0.0) -> bool:
    """Is the current choice of states too badly conditioned at ``values``?"""
    return conditioning(choice, values, time) < threshold


def switch(model: flat.FlatModel, values: Mapping[str, float]) -> StateChoice:
    """The best-conditioned choice of states at ``values`` (use with :func:`state_vector`)."""
    return select_states(model, at=values)


def state_vector(choice: StateChoice, values: Mapping[str, float]) -> np.ndarray:
    """The values of ``choice``'s states, in the order of ``choice.ode.states``."""
    return np.array([float(values[s.name]) for s in choice.ode.states])


def _evaluate(e: x.Expr, values: Mapping[str, float], time: float) -> float:
    try:
        return float(x.evaluate(e, values, time))
    except KeyError:
        return float(x.evaluate(e, _Defaulting(values), time))


class _Defaulting(dict):  # type: ignore[type-arg]
    def __missing__(self, key: str) -> float:
        return 0.0


def _smallest_singular_value(a: np.ndarray) -> float:
    if a.shape == (1, 1):
        return abs(float(a[0, 0]))
    return float(np.linalg.svd(a, compute_uv=False)[-1])
