"""Static state selection where the rules allow it: a dummy-derivative block -> whether
its choice of states can change during a run.

Index reduction (:mod:`.index_reduction`) leaves blocks of equations solved for dummy
derivatives chosen among more candidates. Such a block needs dynamic state selection
(:mod:`.state_choice`, a monitor and switches in scipy's loop) only when its choice may
turn singular during the run. It cannot, and the choice is kept for the whole run, when:

1. the block's Jacobian with respect to its candidates holds no variable and no time
   (only constants and parameters: ``s_rel = flange_b.s - flange_a.s`` gives 1 and -1)
   and its chosen part is nonsingular at the parameter values: a constant matrix
   stays regular; or
2. its ``StateSelect.prefer`` (or ``always``) candidates are exactly the states it
   keeps (:func:`springc.structure.kept_by_preference`), as OpenModelica and Dymola
   choose them statically (a relative position with ``stateSelect = prefer``).

A parameter changed at run time (``--set``) that makes a block of rule 1 singular, or
a preferred choice that turns singular, stops the run with the generated solve's error
instead of switching states.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..ir import expr as x
from ..structure import kept_by_preference
from .isolate import partial
from .ode_eval import evaluate_with

SINGULAR_RTOL = 1e-8
"""A constant block whose smallest singular value is below this (relative) is singular."""


def static_block(equations: Sequence[x.Expr], candidates: Sequence[str],
                 dummies: Sequence[str], priorities: Sequence[float],
                 parameters: Mapping[str, float] | None) -> bool:
    """Is this block's choice of ``dummies`` among ``candidates`` valid for the whole
    run (rule 1 or 2 of the module docstring)? ``priorities[k]``: that of the state of
    ``candidates[k]``; ``parameters``: values of every parameter (None: unknown)."""
    chosen = set(dummies)
    if kept_by_preference(priorities, [c in chosen for c in candidates]):
        return True
    if parameters is None:
        return False
    column = {name: j for j, name in enumerate(dummies)}
    jac = np.zeros((len(equations), len(dummies)))
    for i, e in enumerate(equations):
        for name in candidates:
            d = partial(e, name)
            if not _constant(d, parameters):
                return False
            if name in column:
                try:
                    jac[i, column[name]] = evaluate_with(d, parameters.__getitem__)
                except (ArithmeticError, ValueError, KeyError):
                    return False
    if not np.all(np.isfinite(jac)):
        return False
    values = np.linalg.svd(jac, compute_uv=False)
    return bool(values.size and values[-1] > SINGULAR_RTOL * max(1.0, values[0]))


def _constant(e: x.Expr, parameters: Mapping[str, float]) -> bool:
    """Does ``e`` hold only constants, parameters and arithmetic (no variable, time,
    derivative or function call)?"""
    for node in x.walk(e):
        if isinstance(node, (x.Time, x.Der, x.Call)):
            return False
        if isinstance(node, x.Var) and node.name not in parameters:
            return False
    return True
