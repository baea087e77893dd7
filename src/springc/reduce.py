"""Index reduction and state selection: dae.DAE -> Reduced.

Numbers the unknowns and their derivative variables, runs Pantelides' algorithm
(differentiating equations symbolically when it asks), then the dummy-derivative
method to choose the states. The result is the augmented equation list and the
states; everything else is algebraic.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from . import dae
from . import expr as x
from .errors import Note, SimplifyError
from .lower import differentiate
from .structure import (
    StructurallySingular,
    dummy_derivatives,
    pantelides,
    state_priority,
)


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


def _number_variables(system: dae.DAE) -> tuple[list[str], dict[str, int], list[int]]:
    names = [u.name for u in system.unknowns]
    index = {n: i for i, n in enumerate(names)}
    derivative = [-1] * len(names)
    pending = sorted({n for r in system.equations for n in x.variables(r.expr)
                      if n.startswith("der(")}, key=len)
    for name in pending:
        base = name[4:-1]
        if base not in index:
            raise SimplifyError(f"'{base}' is differentiated but is not an unknown",
                                system.span)
        index[name] = len(names)
        derivative[index[base]] = len(names)
        names.append(name)
        derivative.append(-1)
    return names, index, derivative


def index_reduce(system: dae.DAE) -> Reduced:
    names, index, derivative = _number_variables(system)
    exprs = [r.expr for r in system.equations]
    sources = list(system.equations)
    orders = [0] * len(exprs)
    incidence = [tuple(sorted(index[n] for n in x.variables(e) if n in index)) for e in exprs]

    def varying(name: str) -> bool:
        return name in index or name.startswith("der(")

    def hook(eq: int, var_derivative: Sequence[int]) -> list[int]:
        # Name the derivative variables Pantelides created, then differentiate.
        for v in range(len(var_derivative)):
            d = var_derivative[v]
            if d != -1 and d >= len(names):
                while len(names) <= d:
                    names.append("")
                names[d] = dae.der_name(names[v])
                index[names[d]] = d
        new = differentiate(exprs[eq], varying)
        exprs.append(new)
        sources.append(sources[eq])
        orders.append(orders[eq] + 1)
        return [index[n] for n in x.variables(new) if n in index]

    try:
        reduction = pantelides(incidence, derivative, [-1] * len(exprs), len(names),
                               differentiate_equation=hook)
    except StructurallySingular as err:
        raise _singular(system, err, names) from None
    unknowns = {u.name: u for u in system.unknowns}
    priority = [state_priority(unknowns[n].state_select, unknowns[n].fixed)
                if n in unknowns else state_priority() for n in names]
    selection = dummy_derivatives(reduction, priority)
    states = tuple(zip(selection.states, selection.state_derivatives))
    return Reduced(tuple(names), tuple(exprs), tuple(sources), tuple(orders),
                   reduction.incidence, states)


def _singular(system: dae.DAE, err: StructurallySingular, names: list[str]) -> SimplifyError:
    notes = [Note(f"equation: {system.equations[e].describe()}", system.equations[e].span)
             for e in err.equations[:10] if e < len(system.equations)]
    involved = ", ".join(f"'{names[v]}'" for v in err.variables[:10] if v < len(names))
    return SimplifyError(f"the system is structurally singular: these equations cannot "
                         f"determine {involved or 'their variables'}", system.span, notes,
                         "check for redundant or missing equations among those listed")
