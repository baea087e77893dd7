"""Causalization: reduce.Reduced -> ordered solve steps (ode.Step).

With the states known, match every remaining equation to the variable it computes,
sort into BLT blocks, and solve each block: a single variable explicitly when it
appears linearly, a linear loop as a (sparse) linear system, any other loop by
tearing, with Newton's method on the tearing variables in the generated code.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import Note, SimplifyError, Span
from ..ir import expr as x
from ..ir import ode
from ..structure import Matching, blt, dulmage_mendelsohn, maximum_matching, tear
from .index_reduction import Reduced
from .isolate import fold, free_variables, linear_split, partial, solve_for


def causalize(reduced: Reduced) -> list[ode.Step]:
    """The evaluation order of all non-state variables, as solve steps."""
    # Step 1: unknowns are all variables except the states.
    state_vars = {s for s, _ in reduced.states}
    unknown_ids = [i for i in range(len(reduced.names)) if i not in state_vars]
    local = {v: k for k, v in enumerate(unknown_ids)}
    rows = [[local[v] for v in row if v in local] for row in reduced.incidence]
    # Step 2: match equations to unknowns; a deficiency is a structural error.
    matching = maximum_matching(rows, len(unknown_ids))
    if not matching.is_perfect or len(rows) != len(unknown_ids):
        raise _unmatched(reduced, rows, unknown_ids)
    # Step 3: BLT order, then solve each block.
    steps: list[ode.Step] = []
    for block in blt(rows, matching):
        names = [reduced.names[unknown_ids[matching.eq_to_var[e]]] for e in block]
        steps.append(_solve_block(reduced, list(block), names, rows, matching, unknown_ids))
    return steps


def _solve_block(reduced: Reduced, block: list[int], names: list[str],
                 rows: Sequence[Sequence[int]], matching: Matching, unknown_ids: list[int]
                 ) -> ode.Step:
    exprs = [reduced.equations[e] for e in block]
    spans = tuple(reduced.sources[e].span for e in block)
    if len(block) == 1:
        value = solve_for(exprs[0], names[0])
        if value is not None:
            return ode.Assign(names[0], value, spans[0])
        return _nonlinear(exprs, names, [], spans)
    linear = _linear_system(exprs, names)
    if linear is not None:
        matrix, rhs = linear
        return ode.LinearBlock(tuple(names), matrix, rhs, spans)
    return _torn(reduced, block, names, rows, matching, unknown_ids, spans)


def _linear_system(exprs: list[x.Expr], names: list[str]
                   ) -> tuple[tuple[tuple[int, int, x.Expr], ...], tuple[x.Expr, ...]] | None:
    """``A v = b`` when every residual is linear in the block's variables."""
    block = set(names)
    zero = dict.fromkeys(names, x.ZERO)
    entries: list[tuple[int, int, x.Expr]] = []
    rhs: list[x.Expr] = []
    for i, r in enumerate(exprs):
        present = free_variables(r) & block
        for j, name in enumerate(names):
            if name not in present:
                continue
            coeff = partial(r, name)
            if free_variables(coeff) & block:
                return None
            if coeff != x.ZERO:
                entries.append((i, j, coeff))
        rhs.append(fold(x.neg(fold(x.substitute(r, zero)))))
    return tuple(entries), tuple(rhs)


def _torn(reduced: Reduced, block: list[int], names: list[str],
          rows: Sequence[Sequence[int]], matching: Matching, unknown_ids: list[int],
          spans: tuple[Span, ...]) -> ode.Step:
    exprs = {e: reduced.equations[e] for e in block}
    varying = frozenset(reduced.names) | {"time"}

    def can_solve(eq: int, var: int) -> bool:
        # as Dymola and OpenModelica do, an inner equation never divides by a
        # time-varying coefficient (``LossPower = i*v`` for ``i`` divides by zero where
        # ``v = 0``): such a pair is left to Newton, through a residual
        split = linear_split(exprs[eq], reduced.names[unknown_ids[var]])
        return split is not None and not free_variables(split[0]) & varying

    tearing = tear(block, rows, matching, can_solve)
    inner = []
    for eq, var in tearing.inner:
        name = reduced.names[unknown_ids[var]]
        value = solve_for(exprs[eq], name)
        assert value is not None
        inner.append((name, value, reduced.sources[eq].span))
    tear_names = [reduced.names[unknown_ids[v]] for v in tearing.tearing_variables]
    residuals = [exprs[e] for e in tearing.residual_equations]
    return _nonlinear(residuals, tear_names, inner, spans)


def _nonlinear(residuals: list[x.Expr], tearing: list[str],
               inner: list[tuple[str, x.Expr, Span]], spans: tuple[Span, ...]
               ) -> ode.NonlinearBlock:
    """Newton data: the Jacobian of the residuals with respect to the tearing variables,
    through the inner assignments (forward sensitivities ``d(a)/d(t)``)."""
    sensitivities: list[ode.Assign] = []
    sens: dict[tuple[str, str], x.Expr] = {}
    inner_names = [name for name, _, _ in inner]
    for name, value, span in inner:
        for t in tearing:
            total = partial(value, t)
            for prev in inner_names:
                if prev == name:
                    break
                if prev in free_variables(value) and (prev, t) in sens:
                    total = fold(x.add(total, x.mul(partial(value, prev), sens[prev, t])))
            if total != x.ZERO:
                sens_name = f"d({name})/d({t})"
                sensitivities.append(ode.Assign(sens_name, total, span))
                sens[name, t] = x.Var(sens_name)
    jacobian: list[tuple[int, int, x.Expr]] = []
    for i, r in enumerate(residuals):
        used = free_variables(r)
        for j, t in enumerate(tearing):
            total = partial(r, t)
            for prev in inner_names:
                if prev in used and (prev, t) in sens:
                    total = fold(x.add(total, x.mul(partial(r, prev), sens[prev, t])))
            if total != x.ZERO:
                jacobian.append((i, j, total))
    assigns = tuple(ode.Assign(n, v, s) for n, v, s in inner)
    return ode.NonlinearBlock(tuple(tearing), assigns, tuple(residuals),
                              tuple(sensitivities), tuple(jacobian), spans)


def _unmatched(reduced: Reduced, rows: list[list[int]], unknown_ids: list[int]
               ) -> SimplifyError:
    matching = maximum_matching(rows, len(unknown_ids))
    parts = dulmage_mendelsohn(rows, len(unknown_ids), matching)
    notes = [Note(f"equation: {reduced.sources[e].describe()}", reduced.sources[e].span)
             for e in parts.over_equations[:10]]
    notes += [Note(f"'{reduced.names[unknown_ids[v]]}' is not determined")
              for v in parts.under_variables[:10]]
    return SimplifyError("after choosing the states, the remaining equations do not "
                         "determine the remaining variables", None, notes,
                         "the chosen states may be over-constrained by the equations "
                         "listed; check the constraints and initial conditions")
