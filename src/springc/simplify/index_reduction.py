"""Index reduction and state selection: dae.DAE -> Reduced.

Numbers the unknowns and their derivative variables, runs Pantelides' algorithm
(differentiating equations symbolically when it asks), then the dummy-derivative
method to choose the states. The result is the augmented equation list and the
states; everything else is algebraic.

By default the dummy derivatives are the greedy structural choice in priority order,
vetted numerically at the start values. With ``at`` (values of the variables, e.g.
during a simulation) every block is instead chosen numerically at those values by
:func:`pivoted_choice`: the best-conditioned columns within each priority class, so
that the choice stays valid for a while (dynamic state selection,
:mod:`springc.simplify.state_choice`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import Note, SimplifyError, Span
from ..ir import dae
from ..ir import expr as x
from ..structure import (
    NumericallySingular,
    StructurallySingular,
    dummy_derivatives,
    pantelides,
    state_priority,
)
from .isolate import free_variables, partial
from .lower import differentiate
from .ode_eval import evaluate_with, parameter_values, start_values
from .static_choice import static_block

START_BONUS = 0.25
"""Priority added for a (non-fixed) start value: below the fixed-start bonus (0.5)."""

PIVOT_RTOL = 1e-8
"""A column whose residual is below this times the largest column norm is dependent."""
PIVOT_TIE = 1e-6
"""Relative margin by which a later column of a class must beat an earlier one."""


@dataclass(frozen=True)
class DummyBlock:
    """One block of the dummy-derivative choice, by name: ``equations`` (residuals of
    the augmented system) are solved for ``dummies``, chosen among ``candidates``
    (priority order; ``tiers`` numbers their priority classes). ``static``: the choice
    holds for the whole run (:mod:`.static_choice`); ``span``: where the block's first
    equation was written (None: unknown)."""

    level: int
    equations: tuple[x.Expr, ...]
    dummies: tuple[str, ...]
    candidates: tuple[str, ...]
    tiers: tuple[int, ...]
    static: bool = False
    span: Span | None = None

    @property
    def switchable(self) -> bool:
        """May the states of this block have to change during a run (dynamic state
        selection)? Only with a choice among candidates that is not static."""
        return len(self.candidates) > len(self.dummies) and not self.static


@dataclass(frozen=True)
class Reduced:
    """The augmented system: ``names[i]`` is variable i; ``equations[k]`` a residual
    (differentiated ones have ``order > 0``); ``states`` pairs (state, derivative)."""

    names: tuple[str, ...]
    equations: tuple[x.Expr, ...]
    sources: tuple[dae.Residual, ...]
    orders: tuple[int, ...]
    incidence: tuple[tuple[int, ...], ...]
    states: tuple[tuple[int, int], ...]
    blocks: tuple[DummyBlock, ...] = field(default=())


def _number_variables(system: dae.DAE, prefer: bool = False
                      ) -> tuple[list[str], dict[str, int], list[int]]:
    names = [u.name for u in system.unknowns]
    index = {n: i for i, n in enumerate(names)}
    derivative = [-1] * len(names)
    pending = sorted({n for r in system.equations for n in r.variables
                      if dae.is_derivative(n)} | forced_derivatives(system, prefer),
                     key=lambda n: (len(n), n))
    for name in pending:
        base = dae.derivative_base(name)
        if base is None or base not in index:
            raise SimplifyError(f"'{base}' is differentiated but is not an unknown",
                                system.span)
        index[name] = len(names)
        derivative[index[base]] = len(names)
        names.append(name)
        derivative.append(-1)
    return names, index, derivative


def forced_derivatives(system: dae.DAE, prefer: bool = False) -> set[str]:
    """The derivative variables of the unknowns declared ``StateSelect.always``
    (Modelica 3.6, section 4.8.7.1: "always: do use it as a state"), and with ``prefer``
    those declared ``StateSelect.prefer`` ("use it preferably as a state") that are the
    derivative of another variable (:func:`_preferred_velocities`), whether or not an
    equation differentiates them. Where none does, ``der(v)`` enters with no
    equation: ``v`` becomes a candidate state, Pantelides differentiates the equations
    that determine it, and the dummy-derivative choice keeps ``v`` where the structure
    allows (it ranks above default variables; ``always`` first), as OpenModelica and
    Dymola make such a variable a state: a spring's ``v_rel = der(s_rel)`` between two
    masses keeps ``s_rel`` and ``v_rel`` rather than a mass's ``s`` and ``v``, which
    decides what a ``reinit`` of the other mass's velocity leaves unchanged."""
    forced = {dae.derivative_name(u.name) for u in system.unknowns
              if u.state_select == "always"}
    return forced | _preferred_velocities(system) if prefer else forced


def _preferred_velocities(system: dae.DAE) -> set[str]:
    """``der(v)`` of each ``StateSelect.prefer`` variable ``v`` that an equation makes
    the derivative of another variable (``v = der(x)``: a preferred relative position's
    velocity). Only those: a preferred variable that is some algebraic function of the
    states (``y = g(x)``) stays algebraic, rather than a state whose equation must be
    solved backwards for ``x``."""
    preferred = {u.name for u in system.unknowns if u.state_select == "prefer"}
    found = set()
    for r in system.equations:
        names = r.incident
        if len(names) == 2:
            (a, b) = sorted(names, key=dae.is_derivative)
            if a in preferred and dae.is_derivative(b) and dae.derivative_base(b) != a:
                found.add(dae.derivative_name(a))
    return found


def index_reduce(system: dae.DAE, at: Mapping[str, float] | None = None) -> Reduced:
    """Pantelides, then dummy derivatives (see the module docstring for ``at``).
    ``StateSelect.prefer`` variables are candidate states (:func:`forced_derivatives`)
    unless that makes the reduction fail (an equation that determines one and cannot
    be differentiated, a singular choice): then they are candidates only where an
    equation differentiates them, as before."""
    written = {n for r in system.equations for n in r.variables if dae.is_derivative(n)}
    if forced_derivatives(system, prefer=True) <= written | forced_derivatives(system):
        return _index_reduce(system, at, False)
    try:
        return _index_reduce(system, at, True)
    except SimplifyError:
        return _index_reduce(system, at, False)


def _index_reduce(system: dae.DAE, at: Mapping[str, float] | None, prefer: bool) -> Reduced:
    names, index, derivative = _number_variables(system, prefer)
    exprs = [r.expr for r in system.equations]
    sources = list(system.equations)
    orders = [0] * len(exprs)
    incidence = [tuple(sorted(index[n] for n in r.incident if n in index))
                 for r in system.equations]

    def varying(name: str) -> bool:
        return name in index or dae.is_derivative(name)

    def hook(eq: int, var_derivative: Sequence[int]) -> list[int]:
        # Name the derivative variables Pantelides created, then differentiate.
        # Several may be new at once, in any order of their numbers: fill every gap
        # (a new variable numbers above its base, so the base is named first).
        for v in range(len(var_derivative)):
            d = var_derivative[v]
            if d == -1:
                continue
            while len(names) <= d:
                names.append("")
            if not names[d]:
                names[d] = dae.derivative_name(names[v])
                index[names[d]] = d
        new = differentiate(exprs[eq], varying)
        exprs.append(new)
        sources.append(sources[eq])
        orders.append(orders[eq] + 1)
        return sorted(index[n] for n in free_variables(new) if n in index)

    try:
        reduction = pantelides(incidence, derivative, [-1] * len(exprs), len(names),
                               differentiate_equation=hook)
    except StructurallySingular as err:
        raise _singular(system, err, names) from None
    unknowns = {u.name: u for u in system.unknowns}
    priority = [unknown_priority(unknowns[n]) if n in unknowns else state_priority() for n in names]
    try:
        if at is None:
            check = _nonsingular_at_start(system, names, exprs)
            selection = dummy_derivatives(reduction, priority, check)
        else:
            choose = _best_conditioned_at(system, names, exprs, at)
            selection = dummy_derivatives(reduction, priority, choose=choose)
    except NumericallySingular as err:
        raise _numerically_singular(system, err, names, sources, at is not None) from None
    states = tuple(zip(selection.states, selection.state_derivatives))
    base = {d: v for v, d in enumerate(reduction.var_derivative) if d != -1}
    known: list[dict[str, float] | None] = []  # evaluated for the first block asking
    blocks = []
    for b in selection.blocks:
        equations = tuple(exprs[e] for e in b.equations)
        dummies = tuple(names[v] for v in b.dummies)
        candidates = tuple(names[v] for v in b.candidates)
        static = False
        if at is None and len(candidates) > len(dummies):
            known += [] if known else [_parameters_or_none(system)]
            static = static_block(equations, candidates, dummies,
                                  [priority[base[v]] for v in b.candidates], known[0])
        span = sources[b.equations[0]].span if b.equations else None
        blocks.append(DummyBlock(b.level, equations, dummies, candidates, b.tiers, static,
                                 span))
    return Reduced(tuple(names), tuple(exprs), tuple(sources), tuple(orders),
                   reduction.incidence, states, tuple(blocks))


def _parameters_or_none(system: dae.DAE) -> dict[str, float] | None:
    """The parameter values of ``system`` (None when one cannot be evaluated)."""
    try:
        return parameter_values(system.parameters)
    except (SimplifyError, ArithmeticError, ValueError):
        return None


def unknown_priority(u: dae.Unknown) -> float:
    """How strongly ``u`` should stay a state (the one ranking of simplify, built on
    :func:`springc.structure.state_priority`; alias elimination keeps the member of
    an alias class that ranks highest): ``stateSelect`` and a fixed start rank first;
    any start value breaks ties, so that a variable the user gave a start value stays
    a state when possible."""
    bonus = START_BONUS if u.start is not None and not u.fixed else 0.0
    return state_priority(u.state_select, u.fixed and u.start is not None) + bonus


def _nonsingular_at_start(system: dae.DAE, names: list[str], exprs: list[x.Expr]
                          ) -> Callable[[tuple[int, ...], tuple[int, ...]], bool]:
    """``is_nonsingular`` for the dummy-derivative method: the Jacobian block evaluated
    at the start values (0 where none is given) must be well conditioned, so that e.g.
    a rod that starts horizontal does not get its vertical position as a dummy."""
    env: dict[str, float] = {}

    def check(rows: tuple[int, ...], cols: tuple[int, ...]) -> bool:
        if not env:
            try:
                env.update(parameter_values(system.parameters))
                env.update(start_values(system.unknowns, env))
            except SimplifyError:
                env["$failed"] = 1.0
        if "$failed" in env:
            return True
        jac = np.zeros((len(rows), len(cols)))
        try:
            for i, e in enumerate(rows):
                for j, v in enumerate(cols):
                    jac[i, j] = evaluate_with(partial(exprs[e], names[v]),
                                              lambda n: env.get(n, 0.0))
        except (ArithmeticError, ValueError):
            return True
        sv = np.linalg.svd(jac, compute_uv=False)
        return bool(sv[-1] > 1e-8 * max(1.0, sv[0]))

    return check


def _best_conditioned_at(system: dae.DAE, names: list[str], exprs: list[x.Expr],
                         at: Mapping[str, float]
                         ) -> Callable[[tuple[int, ...], tuple[int, ...], tuple[int, ...]],
                                       tuple[int, ...] | None]:
    """``choose`` for the dummy-derivative method: the Jacobian of the block with
    respect to all candidates, evaluated at ``at`` (over parameter and start values,
    0 where nothing is known), and :func:`pivoted_choice` on it."""
    env: dict[str, float] = {}
    try:
        env.update(parameter_values(system.parameters))
        env.update(start_values(system.unknowns, env))
    except SimplifyError:
        pass
    env.update(at)

    def choose(rows: tuple[int, ...], cols: tuple[int, ...], tiers: tuple[int, ...]
               ) -> tuple[int, ...] | None:
        jac = block_jacobian([exprs[e] for e in rows], [names[v] for v in cols], env)
        picked = pivoted_choice(jac, tiers)
        return None if picked is None else tuple(cols[k] for k in picked)

    return choose


def block_jacobian(equations: Sequence[x.Expr], columns: Sequence[str],
                   env: Mapping[str, float]) -> np.ndarray:
    """d(equations)/d(columns) at ``env`` (names missing from it count as 0)."""
    jac = np.zeros((len(equations), len(columns)))
    for i, e in enumerate(equations):
        present = free_variables(e)
        for j, v in enumerate(columns):
            if v in present:
                jac[i, j] = evaluate_with(partial(e, v), lambda n: env.get(n, 0.0))
    return jac


def pivoted_choice(jac: np.ndarray, tiers: Sequence[int], rtol: float = PIVOT_RTOL,
                   tie: float = PIVOT_TIE) -> list[int] | None:
    """Column indices of a well-conditioned square submatrix of ``jac`` (rows x
    candidates), or None when its rank is below the number of rows.

    Gram-Schmidt with column pivoting, one priority class (``tiers``, ascending) at a
    time: within a class the column with the largest residual (the best pivot) is taken
    next, an earlier column winning ties within ``tie``; classes are exhausted in order,
    so a lower-priority column is taken only when the higher ones are (numerically)
    dependent. On ``der(x)*x + der(y)*y`` this takes the coordinate with the larger
    gradient component, as a Modelica tool's dynamic state selection does.
    """
    m, n = jac.shape
    residual = np.array(jac, dtype=float)
    scale = float(np.max(np.linalg.norm(residual, axis=0), initial=0.0))
    if m == 0:
        return []
    if not np.isfinite(scale) or scale == 0.0:
        return None
    chosen: list[int] = []
    for tier in sorted(set(tiers)):
        available = [k for k in range(n) if tiers[k] == tier]
        while available and len(chosen) < m:
            norms = np.linalg.norm(residual[:, available], axis=0)
            best = float(norms.max())
            if best <= rtol * scale:
                break
            pick = next(k for k, nk in zip(available, norms) if nk * (1 + tie) >= best)
            chosen.append(pick)
            available.remove(pick)
            q = residual[:, pick] / np.linalg.norm(residual[:, pick])
            residual -= np.outer(q, q @ residual)
        if len(chosen) == m:
            return chosen
    return None


def _numerically_singular(system: dae.DAE, err: NumericallySingular, names: list[str],
                          sources: list[dae.Residual], at: bool = False) -> SimplifyError:
    notes = [Note(f"equation: {sources[e].describe()}", sources[e].span)
             for e in err.equations[:10]]
    involved = ", ".join(f"'{names[v]}'" for v in err.variables[:10])
    where = "the given values" if at else "the start values"
    return SimplifyError(f"no choice of states is valid at {where}: the "
                         f"constraints are singular with respect to {involved}",
                         system.span, notes, "check the start values of the constrained "
                         "variables against the constraints listed")


def _singular(system: dae.DAE, err: StructurallySingular, names: list[str]) -> SimplifyError:
    notes = [Note(f"equation: {system.equations[e].describe()}", system.equations[e].span)
             for e in err.equations[:10] if e < len(system.equations)]
    involved = ", ".join(f"'{names[v]}'" for v in err.variables[:10] if v < len(names))
    return SimplifyError(f"the system is structurally singular: these equations cannot "
                         f"determine {involved or 'their variables'}", system.span, notes,
                         "check for redundant or missing equations among those listed")
