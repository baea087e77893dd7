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
   choose them statically (a relative position with ``stateSelect = prefer``);
3. its Jacobian with respect to the dummies alone (the matrix the generated code
   solves) is block triangular with constant, regular diagonal blocks: the blocks of
   the equations' BLT ordering on the dummies (:func:`springc.structure.blt`). A
   triangular matrix is regular where its diagonal blocks are, whatever the entries
   below them: a MultiBody joint's ``der(R_rel.T[i,j]) = f(phi)*der(phi)`` has the
   coefficient 1 on its dummy whatever ``phi`` (DoublePendulum: the damper's
   preferred ``phi_rel`` and the revolute's preferred ``phi`` are one state, so rule 2
   does not hold).

A parameter changed at run time (``--set``) that makes a block of rule 1 singular, or
a preferred choice that turns singular, stops the run with the generated solve's error
instead of switching states.

Other blocks may turn singular. Where every such block is one equation (a free body's
quaternion constraint ``2*Q*der(Q) = 0``, a rod's ``x*der(x) + y*der(y) = 0``), the
default choice is still the one the generated code runs first, *checked at run time*
(:func:`pivot_checks`): an assertion per block that its pivot stays at least
:data:`THRESHOLD` times every other candidate's coefficient of its priority class or a
higher one, the conditioning measure at which dynamic state selection would switch
(:func:`springc.simplify.state_choice.conditioning`). A run whose check holds to the
end is that of a static choice (MultiBody's free bodies that turn less than a quarter
turn: PointGravity, the spring-mass systems); one whose check fails is run again with
dynamic state selection (:mod:`springc.simulation.switching`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..errors import Span
from ..ir import expr as x
from ..ir import flat
from ..structure import blt, kept_by_preference, maximum_matching
from .isolate import free_variables, partial
from .ode_eval import evaluate_with

SINGULAR_RTOL = 1e-8
"""A constant block whose smallest singular value is below this (relative) is singular."""
THRESHOLD = 0.2
"""Switch when the current choice is this much worse conditioned than the best one
(dynamic state selection, and the run-time check of :func:`pivot_checks`)."""
CHECK_DETAIL = "static choice of states checked at run time"
"""The ``origin.detail`` of the assertions of :func:`pivot_checks`."""
CHECK_MESSAGE = "the states chosen at compile time turn singular"
"""The start of their messages (a run that fails one is run again with switching)."""


def static_block(equations: Sequence[x.Expr], candidates: Sequence[str],
                 dummies: Sequence[str], priorities: Sequence[float],
                 parameters: Mapping[str, float] | None) -> bool:
    """Is this block's choice of ``dummies`` among ``candidates`` valid for the whole
    run (rule 1, 2 or 3 of the module docstring)? ``priorities[k]``: that of the state of
    ``candidates[k]``; ``parameters``: values of every parameter (None: unknown)."""
    chosen = set(dummies)
    if kept_by_preference(priorities, [c in chosen for c in candidates]):
        return True
    if parameters is None:
        return False
    return _constant_jacobian(equations, candidates, dummies, parameters) or \
        _triangular(equations, dummies, parameters)


def _constant_jacobian(equations: Sequence[x.Expr], candidates: Sequence[str],
                       dummies: Sequence[str], parameters: Mapping[str, float]) -> bool:
    """Rule 1: every derivative with respect to a candidate constant, and the
    dummies' square part regular."""
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
    return _regular(jac)


def _triangular(equations: Sequence[x.Expr], dummies: Sequence[str],
                parameters: Mapping[str, float]) -> bool:
    """Rule 3: the BLT blocks of ``equations`` on ``dummies`` have constant, regular
    Jacobians."""
    column = {name: j for j, name in enumerate(dummies)}
    incidence = [sorted(column[n] for n in free_variables(e) if n in column)
                 for e in equations]
    matching = maximum_matching(incidence, len(dummies))
    if len(equations) != len(dummies) or not matching.is_perfect:
        return False
    for rows in blt(incidence, matching):
        cols = [matching.eq_to_var[r] for r in rows]
        jac = np.zeros((len(rows), len(cols)))
        for i, r in enumerate(rows):
            for j, c in enumerate(cols):
                if c not in incidence[r]:
                    continue
                d = partial(equations[r], dummies[c])
                if not _constant(d, parameters):
                    return False
                try:
                    jac[i, j] = evaluate_with(d, parameters.__getitem__)
                except (ArithmeticError, ValueError, KeyError):
                    return False
        if not _regular(jac):
            return False
    return True


def _regular(jac: np.ndarray) -> bool:
    """Is the constant matrix ``jac`` finite and well away from singular?"""
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


def pivot_checks(blocks: Sequence[tuple[Sequence[x.Expr], Sequence[str], Sequence[str],
                                        Sequence[int], Span]]
                 ) -> tuple[flat.Assertion, ...] | None:
    """The run-time checks of ``blocks`` (``(equations, candidates, dummies, tiers,
    span)`` of each block that may turn singular; see the module docstring), or None
    where a block has more than one equation (no scalar check: dynamic state selection
    from the start)."""
    checks = []
    for equations, candidates, dummies, tiers, span in blocks:
        if len(equations) != 1 or len(dummies) != 1:
            return None
        k = list(candidates).index(dummies[0])
        pivot = _magnitude(partial(equations[0], dummies[0]))
        terms = [x.BinOp(">=", pivot, x.mul(x.Const(THRESHOLD),
                                            _magnitude(partial(equations[0], c))))
                 for j, c in enumerate(candidates) if j != k and tiers[j] <= tiers[k]]
        if not terms:
            continue
        condition: x.Expr = terms[0]
        for term in terms[1:]:
            condition = x.BinOp("and", condition, term)
        others = ", ".join(c for c in candidates if c != dummies[0])
        message = (f"{CHECK_MESSAGE}: '{dummies[0]}' (solved from this equation) has a "
                   f"coefficient under {THRESHOLD:g} times that of one of {others}; "
                   "dynamic state selection switches here")
        checks.append(flat.Assertion(x.Call("noEvent", (condition,)), message, "error",
                                     span, flat.Origin("equation", "", CHECK_DETAIL)))
    return tuple(checks)


def _magnitude(e: x.Expr) -> x.Expr:
    return x.Call("abs", (e,))
